//! The identity of a calibration: [`MachineDescription::calibration_digest`],
//! which what a calibration's later files name (a check history's lines, an
//! export's summary) so that a report can tell whether they belong to it.
//!
//! The digest is the SHA-256 (lower-case hex) of the compact JSON text of
//! five fields of the `calibration` record, in this order:
//! `{"date":..,"data_sha256":..,"method":..,"estimates_mm":..,"seal":..}`.
//! They are plain values that read back and write again unchanged (strings,
//! numbers read back to the same bits, a map of digests), present in every
//! record this version writes, so the digest is the same whichever version
//! of tricept reads the file; any edit of them, and any edit of a sealed
//! field (through the seal), makes another calibration.

use sha2::{Digest, Sha256};

use super::MachineDescription;

impl MachineDescription {
    /// The digest that identifies this file's calibration (see the module
    /// docs); `None` for a description without a `calibration` record.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::MachineDescription;
assert_eq!(MachineDescription::paper().calibration_digest(), None);
```
"#
    )]
    pub fn calibration_digest(&self) -> Option<String> {
        let c = self.calibration.as_deref()?;
        let identity = serde_json::json!({
            "date": c.date,
            "data_sha256": c.data_sha256,
            "method": c.method,
            "estimates_mm": c.estimates_mm,
            "seal": c.seal,
        });
        let text = serde_json::to_string(&identity).ok()?;
        let digest = Sha256::digest(text.as_bytes());
        Some(digest.iter().map(|b| format!("{b:02x}")).collect())
    }
}

#[cfg(test)]
mod tests {
    use crate::MachineDescription;

    /// A calibrated description: the paper's machine with a record read
    /// from text, as a file is.
    fn calibrated(date: &str) -> MachineDescription {
        let nominal = MachineDescription::paper().to_json();
        let record = format!(
            r#"{{"method":"identify","parameter_set":"paper15","estimates_mm":{{"dq1":0.25,"dq2":-0.1}},
            "std_dev_mm":{{"dq1":0.001,"dq2":0.001}},"correlations":{{"names":[],"matrix":[]}},
            "sensor_offsets":{{"phi_rad":0.0,"theta_rad":0.0,"s_mm":0.0,"std_dev":[0.0,0.0,0.0]}},
            "held":[],"chi2_per_dof":1.0,"dof":10,"converged":true,"adequate":true,"poses_used":20,
            "data_file":"d.csv","data_sha256":"ab","date":"{date}","tool_version":"0.1.0",
            "relative_to":"n","nominal":{nominal}}}"#
        );
        let mut d = MachineDescription::paper();
        d.calibration = Some(Box::new(serde_json::from_str(&record).unwrap()));
        d.seal();
        d
    }

    #[test]
    fn the_digest_is_the_sha256_of_the_documented_fields() {
        let d = calibrated("2026-01-05T07:00:00Z");
        let c = d.calibration.as_deref().unwrap();
        // The text the module docs define, written out by hand.
        let seal = serde_json::to_string(c.seal.as_ref().unwrap()).unwrap();
        let text = format!(
            r#"{{"date":"2026-01-05T07:00:00Z","data_sha256":"ab","method":"identify","estimates_mm":{{"dq1":0.25,"dq2":-0.1}},"seal":{seal}}}"#
        );
        use sha2::Digest;
        let want: String = sha2::Sha256::digest(text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert_eq!(d.calibration_digest().unwrap(), want);
        assert_eq!(want.len(), 64);
    }

    #[test]
    fn a_file_read_back_keeps_its_digest_and_another_calibration_has_another() {
        let d = calibrated("2026-01-05T07:00:00Z");
        let back = MachineDescription::from_json(&d.to_json()).unwrap();
        assert_eq!(back.calibration_digest(), d.calibration_digest());
        let later = calibrated("2026-01-06T07:00:00Z");
        assert_ne!(later.calibration_digest(), d.calibration_digest());
        let mut edited = d.clone();
        edited.sensors.length_noise_um *= 2.0;
        edited.seal();
        assert_ne!(edited.calibration_digest(), d.calibration_digest());
    }
}
