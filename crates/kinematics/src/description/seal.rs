//! The seal of a calibration record: a digest of every field a later verb
//! judges by, so that a hand edit of one (a larger `std_dev_mm` that would
//! hide a real change from `tricept check`, a quieter `sensors` noise, a
//! `temperature_c` moved to the campaign's) is refused when the file is
//! loaded, naming the field.
//!
//! Each field is digested (64-bit FNV-1a) over its compact JSON text as
//! serde_json writes it: the shortest text that reads back to the same
//! number, and, with serde_json's `float_roundtrip` parser (a workspace
//! feature), read back to exactly the same bits. A file that was loaded
//! and written again keeps its seal; any edited value breaks it.

use std::collections::BTreeMap;

use super::MachineDescription;

/// The fields a seal covers, as named in a machine file, and their values
/// in a description (`None` when the description has no calibration).
fn sealed_fields(d: &MachineDescription) -> Option<Vec<(&'static str, String)>> {
    let c = d.calibration.as_deref()?;
    let mut fields = vec![
        ("calibration.std_dev_mm", text(&c.std_dev_mm)),
        ("calibration.correlations", text(&c.correlations)),
        ("calibration.sensor_offsets", text(&c.sensor_offsets)),
        ("calibration.temperature_c", text(&c.temperature_c)),
        ("calibration.effects", text(&c.effects)),
        ("calibration.held", text(&c.held)),
        ("calibration.chi2_per_dof", text(&c.chi2_per_dof)),
        ("calibration.dof", text(&c.dof)),
        ("calibration.converged", text(&c.converged)),
        ("calibration.adequate", text(&c.adequate)),
        ("calibration.forced", text(&c.forced)),
        ("calibration.poses_used", text(&c.poses_used)),
        ("sensors", text(&d.sensors)),
        ("controller", text(&d.controller)),
    ];
    // The promise, in every record that has one or whose seal covers one
    // (a file written before records carried it keeps its seal; one whose
    // promise was removed by hand is refused).
    let sealed = |seal: &BTreeMap<String, String>| seal.contains_key(ACCURACY);
    if c.accuracy.is_some() || c.seal.as_ref().is_some_and(sealed) {
        fields.push((ACCURACY, text(&c.accuracy)));
    }
    Some(fields)
}

/// The sealed name of the promise.
const ACCURACY: &str = "calibration.accuracy";

/// The seal's digest of a value: 64-bit FNV-1a of its compact JSON text,
/// in hex. Other sealed files (a batch's prior) seal their fields with it.
///
/// # Example
/// ```
/// use tricept_kinematics::description::seal_digest;
/// assert_eq!(seal_digest(&1.5), seal_digest(&1.5));
/// assert_ne!(seal_digest(&1.5), seal_digest(&1.50001));
/// ```
pub fn seal_digest(value: &impl serde::Serialize) -> String {
    fnv1a(&text(value))
}

/// A value's compact JSON text (plain data cannot fail to serialise).
fn text(value: &impl serde::Serialize) -> String {
    serde_json::to_string(value).unwrap_or_default()
}

/// 64-bit FNV-1a of a text, in hex.
fn fnv1a(text: &str) -> String {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let hash = text
        .bytes()
        .fold(OFFSET, |h, b| (h ^ u64::from(b)).wrapping_mul(PRIME));
    format!("{hash:016x}")
}

impl MachineDescription {
    /// Seals the calibration record: digests of the fields a later verb
    /// judges by ([`CalibrationRecord::seal`](super::CalibrationRecord::seal)).
    /// Call it last, on the description as it is written; nothing happens
    /// without a calibration.
    ///
    /// # Example
    /// ```
    /// use tricept_kinematics::MachineDescription;
    /// let mut d = MachineDescription::paper();
    /// d.seal(); // no calibration: nothing to seal
    /// assert!(d.calibration.is_none());
    /// ```
    pub fn seal(&mut self) {
        let Some(fields) = sealed_fields(self) else {
            return;
        };
        let seal: BTreeMap<String, String> = fields
            .into_iter()
            .map(|(name, text)| (name.to_string(), fnv1a(&text)))
            .collect();
        if let Some(c) = self.calibration.as_mut() {
            c.seal = Some(seal);
        }
    }

    /// The sealed fields whose value differs from the one the seal was
    /// written with, by name (`calibration.std_dev_mm`, `sensors`, ...);
    /// `Err(())` when the record has no seal. Empty for a description
    /// without calibration.
    #[allow(clippy::result_unit_err)]
    pub fn edited_sealed_fields(&self) -> Result<Vec<&'static str>, ()> {
        let Some(fields) = sealed_fields(self) else {
            return Ok(Vec::new());
        };
        let Some(seal) = self.calibration.as_ref().and_then(|c| c.seal.as_ref()) else {
            return Err(());
        };
        Ok(fields
            .into_iter()
            .filter(|(name, text)| seal.get(*name) != Some(&fnv1a(text)))
            .map(|(name, _)| name)
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::{
        CalibrationRecord, CorrelationsDescription, SensorOffsetsDescription,
    };

    fn calibrated() -> MachineDescription {
        let mut d = MachineDescription::paper();
        let nominal = MachineDescription::paper();
        let mut std_dev_mm = serde_json::Map::new();
        std_dev_mm.insert("dq1".into(), 0.0012345678901234567.into());
        d.calibration = Some(Box::new(CalibrationRecord {
            method: "identify".into(),
            parameter_set: "paper15".into(),
            estimates_mm: serde_json::Map::new(),
            std_dev_mm,
            correlations: CorrelationsDescription::default(),
            effects: serde_json::Map::new(),
            sensor_offsets: SensorOffsetsDescription::default(),
            accuracy: None,
            applies: Vec::new(),
            records: Vec::new(),
            held: Vec::new(),
            chi2_per_dof: 0.95,
            dof: 208,
            converged: true,
            adequate: true,
            forced: false,
            warnings: Vec::new(),
            poses_used: 75,
            rejected_lines: Vec::new(),
            leg_tables_digest: None,
            seal: None,
            external_sources: Vec::new(),
            data_file: "data.csv".into(),
            data_sha256: "0".repeat(64),
            date: "2026-11-23T00:00:00Z".into(),
            tool_version: "0.1.0".into(),
            relative_to: nominal.name.clone(),
            relative_to_machine: None,
            temperature_c: Some(20.123456789012345),
            nominal: Box::new(nominal),
        }));
        d
    }

    #[test]
    fn a_sealed_record_read_back_from_its_text_keeps_its_seal() {
        let mut d = calibrated();
        assert_eq!(d.edited_sealed_fields(), Err(()));
        d.seal();
        assert_eq!(d.edited_sealed_fields(), Ok(vec![]));
        // Awkward numbers, written and read back: the same bits.
        for x in [0.1 + 0.2, 1e-7 / 3.0, 796.5 / 7.0, 2.0f64.sqrt() * 1e5] {
            d.sensors.angle_noise_arcsec = x;
            d.seal();
            let back: MachineDescription = serde_json::from_str(&d.to_json()).unwrap();
            assert_eq!(back.sensors.angle_noise_arcsec.to_bits(), x.to_bits());
            assert_eq!(back.edited_sealed_fields(), Ok(vec![]));
        }
    }

    #[test]
    fn each_edited_field_is_named() {
        let mut d = calibrated();
        d.seal();
        type Edit = fn(&mut MachineDescription);
        let edits: [(&str, Edit); 5] = [
            ("calibration.std_dev_mm", |d| {
                let c = d.calibration.as_mut().unwrap();
                c.std_dev_mm.insert("dq1".into(), 0.01.into());
            }),
            ("calibration.temperature_c", |d| {
                d.calibration.as_mut().unwrap().temperature_c = Some(24.0)
            }),
            ("calibration.sensor_offsets", |d| {
                d.calibration.as_mut().unwrap().sensor_offsets.s_mm += 1e-6
            }),
            ("sensors", |d| d.sensors.length_noise_um *= 1.5),
            ("calibration.correlations", |d| {
                d.calibration
                    .as_mut()
                    .unwrap()
                    .correlations
                    .names
                    .push("x".into())
            }),
        ];
        for (name, edit) in edits {
            let mut e = d.clone();
            edit(&mut e);
            assert_eq!(e.edited_sealed_fields(), Ok(vec![name]), "{name}");
        }
    }

    #[test]
    fn the_promise_is_sealed_once_a_record_has_one() {
        // A record without a promise (written before it existed) keeps its
        // seal; one with a promise names it when it is edited or removed.
        let mut d = calibrated();
        d.seal();
        assert_eq!(d.edited_sealed_fields(), Ok(vec![]));
        let c = d.calibration.as_mut().unwrap();
        c.accuracy = Some(crate::description::AccuracyRecord {
            rms_mm: 0.05,
            upper_mm: 0.1,
            point: "platform".into(),
            parts: serde_json::Map::new(),
        });
        d.seal();
        assert_eq!(d.edited_sealed_fields(), Ok(vec![]));
        let mut better = d.clone();
        better
            .calibration
            .as_mut()
            .unwrap()
            .accuracy
            .as_mut()
            .unwrap()
            .upper_mm = 0.05;
        assert_eq!(
            better.edited_sealed_fields(),
            Ok(vec!["calibration.accuracy"])
        );
        let mut removed = d.clone();
        removed.calibration.as_mut().unwrap().accuracy = None;
        assert_eq!(
            removed.edited_sealed_fields(),
            Ok(vec!["calibration.accuracy"])
        );
    }
}
