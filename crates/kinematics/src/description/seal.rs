//! The seal of a calibration record: a digest of every field of the file,
//! so that a hand edit of any of them is refused when the file is loaded,
//! naming the field. A calibrated file is rebuilt from itself: the
//! geometry every `--machine` commands with, the estimates and the nominal
//! (or `relative_to_machine`) machine it is checked against, the UP limb
//! and the workspace the check and the export work over, the standard
//! deviations, noise and temperature a later check judges by. An edit of
//! one of them alone is caught by the rebuild
//! (`tricept_engine::record::check_calibration_record`); an edit of two that agree
//! (a leg offset and its estimate moved together) only by the seal, which
//! is why it covers every field, not a chosen list.
//!
//! The fields are the file's leaves: every member of a JSON object whose
//! value is not an object (a number, a string, an array), named by its
//! path (`leg_offsets_mm`, `calibration.estimates_mm.dq2`,
//! `calibration.nominal.up_limb.axis_skew_rad`; a key that is not a plain
//! word is quoted: `calibration.effects["leg-lead.ppm1"].value`); only the
//! seal itself is left out. Each is digested (64-bit FNV-1a) over a
//! canonical text: compact JSON, object keys sorted, every number as the
//! shortest text of its float64 value (so `0`, `0.0` and `0e0` are one
//! value, as they are one number: a tool that rewrites the file without
//! changing a value, as `jq .` does, keeps the seal; with serde_json's
//! `float_roundtrip` parser, a workspace feature, the value is exactly the
//! written one). A field added or removed is named as such.
//!
//! The file's `format_version` is a field like any other, sealed. A seal
//! written before files had versions does not name it; a file without the
//! key is version 1, so the key read back as 1 (at any depth: the nominal
//! machine inside the record has one too) is not an addition, and every
//! other value of it is.
//!
//! Files sealed before the seal covered every field (issue 45) carry the
//! digests of a chosen list (the standard deviations, correlations, sensor
//! offsets, temperature, effects, fit quality, noise, controller and
//! promise); they are still checked against that list and loaded, and
//! [`MachineDescription::seal_is_partial`] says so, for a warning.

use std::collections::BTreeMap;

use serde_json::Value;

use super::MachineDescription;

/// The seal's entry that says it covers every field (its value names the
/// scheme); absent in partial seals.
const SCHEME: &str = "sealed";

/// The value of [`SCHEME`].
const EVERY_FIELD: &str = "every field";

/// What a seal says of a description: [`MachineDescription::seal_check`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SealCheck {
    /// No calibration record: nothing to seal.
    NoRecord,
    /// A record without a seal.
    Unsealed,
    /// Every sealed field as it was written; `partial` for a seal written
    /// before it covered every field.
    Intact {
        /// The seal covers a chosen list of fields, not every field.
        partial: bool,
    },
    /// The fields whose value differs from the sealed one, by name (`
    /// (added)` or ` (removed)` after a field the seal does not or no
    /// longer finds).
    Edited(Vec<String>),
}

/// Every leaf of the description as it is written, the seal left out:
/// (name, canonical text).
fn leaves(d: &MachineDescription) -> Vec<(String, String)> {
    let mut value = serde_json::to_value(d).unwrap_or(Value::Null);
    if let Some(c) = value.get_mut("calibration").and_then(Value::as_object_mut) {
        c.remove("seal");
    }
    let mut out = Vec::new();
    walk(&value, String::new(), &mut out);
    out
}

/// The leaves under `value`, named from `path`.
fn walk(value: &Value, path: String, out: &mut Vec<(String, String)>) {
    match value {
        Value::Object(map) => {
            for (key, v) in map {
                walk(v, child(&path, key), out);
            }
        }
        leaf => {
            let mut text = String::new();
            canonical(leaf, &mut text);
            out.push((path, text));
        }
    }
}

/// The path of member `key` under `path`: `path.key` for a plain word,
/// `path["key"]` (JSON-quoted) for any other key.
fn child(path: &str, key: &str) -> String {
    let plain = !key.is_empty()
        && key
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
    match (plain, path.is_empty()) {
        (true, true) => key.to_string(),
        (true, false) => format!("{path}.{key}"),
        (false, _) => format!("{path}[{}]", serde_json::to_string(key).unwrap_or_default()),
    }
}

/// The canonical text of a value: compact, keys sorted, numbers by value.
fn canonical(value: &Value, out: &mut String) {
    match value {
        Value::Number(n) => out.push_str(&number(n)),
        Value::Array(items) => {
            out.push('[');
            for (i, v) in items.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                canonical(v, out);
            }
            out.push(']');
        }
        Value::Object(map) => {
            let mut keys: Vec<&String> = map.keys().collect();
            keys.sort();
            out.push('{');
            for (i, k) in keys.into_iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                out.push_str(&serde_json::to_string(k).unwrap_or_default());
                out.push(':');
                canonical(&map[k], out);
            }
            out.push('}');
        }
        other => out.push_str(&serde_json::to_string(other).unwrap_or_default()),
    }
}

/// A number's canonical text: the shortest text of its float64 value when
/// that value is exact, the integer itself when it is not (beyond 2^53).
fn number(n: &serde_json::Number) -> String {
    let exact_integer = |f: f64| {
        n.as_u64().is_none_or(|u| f as u64 == u) && n.as_i64().is_none_or(|i| f as i64 == i)
    };
    match n.as_f64() {
        Some(f) if exact_integer(f) => format!("{f:?}"),
        _ => n.to_string(),
    }
}

/// The fields a partial seal (written before every field was sealed)
/// covers, with their values' compact JSON text as it digested them.
fn partial_fields(d: &MachineDescription) -> Option<Vec<(&'static str, String)>> {
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
    let sealed = |seal: &BTreeMap<String, String>| seal.contains_key(ACCURACY);
    if c.accuracy.is_some() || c.seal.as_ref().is_some_and(sealed) {
        fields.push((ACCURACY, text(&c.accuracy)));
    }
    Some(fields)
}

/// The sealed name of the promise in a partial seal.
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
    /// Seals the calibration record: the digest of every field of the
    /// file ([`CalibrationRecord::seal`](super::CalibrationRecord::seal),
    /// the module docs), the file's `format_version` set to this
    /// tricept's ([`FORMAT_VERSION`](super::FORMAT_VERSION)) first. Call
    /// it last, on the description as it is written; nothing happens
    /// without a calibration.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::MachineDescription;
let mut d = MachineDescription::paper();
d.seal(); // no calibration: nothing to seal
assert!(d.calibration.is_none());
```
"#
    )]
    pub fn seal(&mut self) {
        if self.calibration.is_none() {
            return;
        }
        // What this tricept writes is its own format.
        self.format_version = super::FORMAT_VERSION;
        let mut seal: BTreeMap<String, String> = leaves(self)
            .into_iter()
            .map(|(name, text)| (name, fnv1a(&text)))
            .collect();
        seal.insert(SCHEME.to_string(), EVERY_FIELD.to_string());
        if let Some(c) = self.calibration.as_mut() {
            c.seal = Some(seal);
        }
    }

    /// What the seal says of this description: no record, no seal, intact
    /// (whole or partial), or the fields edited since it was written.
    pub fn seal_check(&self) -> SealCheck {
        let Some(c) = self.calibration.as_deref() else {
            return SealCheck::NoRecord;
        };
        let Some(seal) = c.seal.as_ref() else {
            return SealCheck::Unsealed;
        };
        let edited: Vec<String> = if seal.get(SCHEME).map(String::as_str) == Some(EVERY_FIELD) {
            let now = leaves(self);
            let mut edited: Vec<String> = now
                .iter()
                .filter_map(|(name, text)| match seal.get(name) {
                    None if super::version::is_unversioned_leaf(name, text) => None,
                    None => Some(format!("{name} (added)")),
                    Some(d) if *d != fnv1a(text) => Some(name.clone()),
                    Some(_) => None,
                })
                .collect();
            edited.extend(
                seal.keys()
                    .filter(|k| *k != SCHEME && !now.iter().any(|(n, _)| n == *k))
                    .map(|k| format!("{k} (removed)")),
            );
            edited
        } else {
            let fields = partial_fields(self).unwrap_or_default();
            let edited: Vec<String> = fields
                .into_iter()
                .filter(|(name, text)| seal.get(*name) != Some(&fnv1a(text)))
                .map(|(name, _)| name.to_string())
                .collect();
            if edited.is_empty() {
                return SealCheck::Intact { partial: true };
            }
            edited
        };
        if edited.is_empty() {
            SealCheck::Intact { partial: false }
        } else {
            SealCheck::Edited(edited)
        }
    }

    /// Whether the record's seal covers a chosen list of fields only
    /// (written before every field was sealed): an edit of the geometry
    /// together with its estimates cannot be seen in such a file.
    pub fn seal_is_partial(&self) -> bool {
        self.seal_check() == SealCheck::Intact { partial: true }
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
        let mut estimates_mm = serde_json::Map::new();
        estimates_mm.insert("dq1".into(), 0.0.into());
        d.calibration = Some(Box::new(CalibrationRecord {
            method: "identify".into(),
            parameter_set: "paper15".into(),
            estimates_mm,
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

    /// `d` with the JSON value at `pointer` replaced by `edit` of it, read
    /// back as a file would be.
    fn edited(
        d: &MachineDescription,
        pointer: &str,
        edit: impl Fn(&Value) -> Value,
    ) -> MachineDescription {
        let mut v = serde_json::to_value(d).unwrap();
        let target = v.pointer_mut(pointer).unwrap();
        *target = edit(target);
        serde_json::from_value(v).unwrap()
    }

    #[test]
    fn a_sealed_record_read_back_from_its_text_keeps_its_seal() {
        let mut d = calibrated();
        assert_eq!(d.seal_check(), SealCheck::Unsealed);
        d.seal();
        assert_eq!(d.seal_check(), SealCheck::Intact { partial: false });
        // Awkward numbers, written and read back: the same bits.
        for x in [0.1 + 0.2, 1e-7 / 3.0, 796.5 / 7.0, 2.0f64.sqrt() * 1e5] {
            d.sensors.angle_noise_arcsec = x;
            d.seal();
            let back: MachineDescription = serde_json::from_str(&d.to_json()).unwrap();
            assert_eq!(back.sensors.angle_noise_arcsec.to_bits(), x.to_bits());
            assert_eq!(back.seal_check(), SealCheck::Intact { partial: false });
        }
        // A number rewritten without changing its value (`0.0` as `0`, as
        // `jq .` writes it) keeps the seal.
        let text = d.to_json().replace("\"dq1\": 0.0\n", "\"dq1\": 0\n");
        assert!(text.contains("\"dq1\": 0\n"));
        let back: MachineDescription = serde_json::from_str(&text).unwrap();
        assert_eq!(back.seal_check(), SealCheck::Intact { partial: false });
    }

    #[test]
    fn each_edited_field_is_named_and_edits_that_agree_are_caught() {
        let mut d = calibrated();
        d.seal();
        let nudge = |v: &Value| Value::from(v.as_f64().unwrap() + 1e-6);
        let cases: [(&str, &str); 7] = [
            ("/calibration/std_dev_mm/dq1", "calibration.std_dev_mm.dq1"),
            ("/calibration/temperature_c", "calibration.temperature_c"),
            (
                "/calibration/sensor_offsets/s_mm",
                "calibration.sensor_offsets.s_mm",
            ),
            ("/sensors/length_noise_um", "sensors.length_noise_um"),
            ("/workspace/radius_mm", "workspace.radius_mm"),
            ("/up_limb/axis_skew_rad", "up_limb.axis_skew_rad"),
            (
                "/calibration/nominal/placement/circular/base_radius_mm",
                "calibration.nominal.placement.circular.base_radius_mm",
            ),
        ];
        for (pointer, name) in cases {
            let e = edited(&d, pointer, nudge);
            assert_eq!(
                e.seal_check(),
                SealCheck::Edited(vec![name.into()]),
                "{name}"
            );
        }
        // A leg offset and its estimate moved together: both named.
        let mut e = edited(&d, "/calibration/estimates_mm/dq1", nudge);
        e.leg_offsets_mm[0] += 1e-6;
        assert_eq!(
            e.seal_check(),
            SealCheck::Edited(vec![
                "leg_offsets_mm (added)".into(),
                "calibration.estimates_mm.dq1".into()
            ])
        );
        // Added and removed keys of a free-form map.
        e = edited(
            &d,
            "/calibration/estimates_mm",
            |_| serde_json::json!({"dq9": 0.0}),
        );
        assert_eq!(
            e.seal_check(),
            SealCheck::Edited(vec![
                "calibration.estimates_mm.dq9 (added)".into(),
                "calibration.estimates_mm.dq1 (removed)".into()
            ])
        );
        // A key that is not a plain word is quoted.
        e = edited(
            &d,
            "/calibration/std_dev_mm",
            |_| serde_json::json!({"dq1": 0.0012345678901234567, "a.b": 1.0}),
        );
        assert_eq!(
            e.seal_check(),
            SealCheck::Edited(vec!["calibration.std_dev_mm[\"a.b\"] (added)".into()])
        );
    }

    #[test]
    fn a_partial_seal_is_still_checked_and_said_to_be_partial() {
        let mut d = calibrated();
        let legacy: BTreeMap<String, String> = partial_fields(&d)
            .unwrap()
            .into_iter()
            .map(|(n, t)| (n.to_string(), fnv1a(&t)))
            .collect();
        d.calibration.as_mut().unwrap().seal = Some(legacy);
        assert_eq!(d.seal_check(), SealCheck::Intact { partial: true });
        assert!(d.seal_is_partial());
        let e = edited(&d, "/sensors/length_noise_um", |v| {
            Value::from(v.as_f64().unwrap() * 2.0)
        });
        assert_eq!(e.seal_check(), SealCheck::Edited(vec!["sensors".into()]));
        // What the partial seal does not cover passes: the reason for the
        // warning.
        let e = edited(&d, "/workspace/radius_mm", |_| Value::from(300.0));
        assert!(e.seal_is_partial());
    }

    #[test]
    fn the_format_version_is_sealed_and_a_seal_older_than_it_still_holds() {
        let mut d = calibrated();
        d.format_version = 0;
        d.seal();
        assert_eq!(d.format_version, crate::description::FORMAT_VERSION);
        let seal = d.calibration.as_ref().unwrap().seal.clone().unwrap();
        assert!(seal.contains_key("format_version"));
        assert!(seal.contains_key("calibration.nominal.format_version"));
        let e = edited(&d, "/format_version", |_| Value::from(2));
        assert_eq!(
            e.seal_check(),
            SealCheck::Edited(vec!["format_version".into()])
        );
        // A file sealed before files had versions: neither the key nor its
        // digest. Read back, the key is version 1 and no edit.
        let mut old = serde_json::to_value(&d).unwrap();
        old.as_object_mut().unwrap().remove("format_version");
        old["calibration"]["nominal"]
            .as_object_mut()
            .unwrap()
            .remove("format_version");
        let seal = old["calibration"]["seal"].as_object_mut().unwrap();
        seal.remove("format_version");
        seal.remove("calibration.nominal.format_version");
        let back: MachineDescription = serde_json::from_value(old.clone()).unwrap();
        assert_eq!(back.format_version, 1);
        assert_eq!(back.seal_check(), SealCheck::Intact { partial: false });
        // Written back by this reader (the key as 1): still intact; any
        // other version is an addition the old seal names.
        let again: MachineDescription = serde_json::from_str(&back.to_json()).unwrap();
        assert_eq!(again.seal_check(), SealCheck::Intact { partial: false });
        old["format_version"] = 2.into();
        let two: MachineDescription = serde_json::from_value(old).unwrap();
        assert_eq!(
            two.seal_check(),
            SealCheck::Edited(vec!["format_version (added)".into()])
        );
    }

    #[test]
    fn the_promise_is_sealed_and_its_removal_named() {
        let mut d = calibrated();
        let c = d.calibration.as_mut().unwrap();
        c.accuracy = Some(crate::description::AccuracyRecord {
            rms_mm: 0.05,
            upper_mm: 0.1,
            point: "platform".into(),
            parts: serde_json::Map::new(),
        });
        d.seal();
        assert_eq!(d.seal_check(), SealCheck::Intact { partial: false });
        let better = edited(&d, "/calibration/accuracy/upper_mm", |_| Value::from(0.05));
        assert_eq!(
            better.seal_check(),
            SealCheck::Edited(vec!["calibration.accuracy.upper_mm".into()])
        );
        let mut removed = d.clone();
        removed.calibration.as_mut().unwrap().accuracy = None;
        let SealCheck::Edited(fields) = removed.seal_check() else {
            panic!("not refused");
        };
        assert!(fields.contains(&"calibration.accuracy.rms_mm (removed)".to_string()));
    }
}
