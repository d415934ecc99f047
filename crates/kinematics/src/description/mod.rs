//! The machine description: the JSON file format and its validation.
//!
//! - `mod.rs`: [`MachineDescription`] (and the [`CalibrationRecord`] of a
//!   calibrated file, which carries its nominal machine's description),
//!   reading and writing;
//! - `geometry.rs`: the parts of the geometry (placement, UP limb,
//!   workspace, limits, head, sensors, loads);
//! - `record.rs`: what a calibrated file adds (static leg effects,
//!   controller parameters, the record's held parameters, sensor offsets,
//!   correlations and external sources);
//! - `validate.rs`: [`MachineDescription::validate`], the checks that refuse
//!   impossible geometry and implausible values;
//! - `identity.rs`: [`MachineDescription::calibration_digest`], the digest
//!   a calibration's check history and export name it by;
//! - `version.rs`: the file's `format_version` ([`FORMAT_VERSION`]) and
//!   the refusal of a file newer than this reader ([`NewerFormat`]).
//!
//! A description is what a user writes and what `--machine FILE` loads. It is
//! deliberately verbose: every key carries its unit in its name (`_mm`,
//! `_deg`, `_rad`, `_arcsec`, `_um`), unknown keys are rejected, and
//! [`MachineDescription::validate`] refuses impossible geometry before any
//! solver sees it. [`crate::Machine`] is the validated, computational form.
//!
//! The embedded default ([`MachineDescription::paper`]) is the machine of
//! Table 1 of Hong (2009), also committed as
//! `fixtures/machines/tricept-paper.json`.

use serde::{Deserialize, Serialize};

use crate::error::DescriptionError;

mod geometry;
mod identity;
mod record;
mod seal;
mod validate;
mod version;

use geometry::is_zero3;

pub use geometry::{
    AxisOrder, CircularPlacement, ExplicitPlacement, HeadDescription, LimitsDescription,
    LoadsDescription, MAX_HEAD_ANGLE_OFFSET_RAD, Placement, SensorDescription, UpLimbDescription,
    WorkspaceDescription,
};
pub use record::{
    AccuracyRecord, ControllerDescription, CorrelationsDescription, ExternalSourceRecord,
    HeldParameter, Interpolation, LegEffectsDescription, LegTableDescription,
    SensorOffsetsDescription,
};
pub use seal::{SealCheck, seal_digest};
pub use validate::{MAX_TABLE_EXTRA_UM, MAX_TABLE_POINTS, MAX_TABLE_SLOPE_UM_PER_MM};
pub use version::{
    FORMAT_VERSION, FORMAT_VERSION_KEY, NewerFormat, UNVERSIONED, check_version, newer_format,
};

/// The JSON text of the paper's Table 1 machine, embedded at compile time.
pub const PAPER_MACHINE_JSON: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/machines/tricept-paper.json"
));

/// The largest length (mm) any key of a description may hold: 100 m.
pub const MAX_LENGTH_MM: f64 = 1e5;

/// A complete machine description, as stored in JSON.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_kinematics::MachineDescription;
let d = MachineDescription::paper();
assert_eq!(d.workspace.radius_mm, 400.0);
let m = d.build().unwrap();
assert!((m.base_joints_mm[2].x - 288.7).abs() < 1e-12);
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineDescription {
    /// The file's format version: [`FORMAT_VERSION`] as this tricept
    /// writes it; a file without the key is version 1 ([`UNVERSIONED`]),
    /// and one newer than [`FORMAT_VERSION`] is refused on load.
    #[serde(default = "version::unversioned")]
    pub format_version: u32,
    /// Free-form name shown in reports.
    pub name: String,
    /// Free-form notes (provenance, assumptions); ignored by the solvers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub notes: Option<String>,
    /// Where the joint centres B1..B3 and A1..A3 are.
    pub placement: Placement,
    /// The UP limb: axis order of its base U joint and its "class 2" errors.
    #[serde(default)]
    pub up_limb: UpLimbDescription,
    /// Per-leg length offsets (actual length = command + offset), mm. Zero on
    /// a nominal machine; an identified machine carries its `dq` here.
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub leg_offsets_mm: [f64; 3],
    /// The cylindrical workspace of the platform point O'.
    pub workspace: WorkspaceDescription,
    /// Joint limits.
    #[serde(default)]
    pub limits: LimitsDescription,
    /// The 2-DOF head mounted on the platform.
    #[serde(default)]
    pub head: HeadDescription,
    /// Noise of the UP limb's sensors (used by identification).
    #[serde(default)]
    pub sensors: SensorDescription,
    /// Masses and stiffness, used by the compliance model of the plant
    /// simulator and by the gravity compliance of the leg effects.
    #[serde(default)]
    pub loads: LoadsDescription,
    /// Static leg effects a calibration found (ball-screw lead, gravity
    /// compliance), applied by the kinematics of `tricept-model`'s
    /// `ExtendedMachine`; zero (and not written) on a nominal machine.
    #[serde(default, skip_serializing_if = "LegEffectsDescription::is_zero")]
    pub leg_effects: LegEffectsDescription,
    /// Dynamic effects a CNC controller compensates itself (backlash,
    /// thermal expansion), exported as the parameters it takes; tricept's
    /// own kinematics do not apply them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerDescription>,
    /// Where a calibrated machine came from: estimates, uncertainties, fit
    /// quality and provenance. Absent on a nominal machine.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<Box<CalibrationRecord>>,
}

/// What a calibrated machine file records about its calibration. The
/// parameter values are relative to `relative_to`, the machine the data
/// were identified against; `nominal` is the machine whose structure
/// decides which parameters the sensors can see (the rank rule), carried
/// from calibration to calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationRecord {
    /// The verb that wrote it (`identify` or `diagnose`).
    pub method: String,
    /// Parameter set (`paper15`, `full21`).
    pub parameter_set: String,
    /// Estimated geometric parameters, mm (held ones at their prior).
    pub estimates_mm: serde_json::Map<String, serde_json::Value>,
    /// Their standard deviations, mm (`null` where held).
    pub std_dev_mm: serde_json::Map<String, serde_json::Value>,
    /// Correlations of the estimated parameters.
    pub correlations: CorrelationsDescription,
    /// Parameters of the effects a diagnosis named, with standard deviations
    /// (`{name: {"value": v, "std_dev": s}}`, units in the names).
    #[serde(default, skip_serializing_if = "serde_json::Map::is_empty")]
    pub effects: serde_json::Map<String, serde_json::Value>,
    /// Sensor zero offsets.
    pub sensor_offsets: SensorOffsetsDescription,
    /// The accuracy the file promises (sealed; absent in files written
    /// before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<AccuracyRecord>,
    /// What the file applies, one line per deployed part (a diagnosis':
    /// leg effects, compensation tables, the UP limb, controller
    /// parameters), and where it goes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub applies: Vec<String>,
    /// What the file only records and does not apply: sensor corrections,
    /// time terms, terms seen but not worth deploying.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub records: Vec<String>,
    /// Parameters held at their prior, with the reason.
    pub held: Vec<HeldParameter>,
    /// Weighted chi-square per degree of freedom of the fit (1 when the
    /// model explains the data to the stated sensor noise).
    pub chi2_per_dof: f64,
    /// Degrees of freedom of the fit.
    pub dof: usize,
    /// Whether the fit converged.
    pub converged: bool,
    /// Whether the model explains the data (chi-square test at 0.001).
    pub adequate: bool,
    /// Written with `--force` although the fit is not to be trusted.
    #[serde(default)]
    pub forced: bool,
    /// Warnings of the fit, as printed.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Poses used by the fit.
    pub poses_used: usize,
    /// Mean logged structure temperature of the campaign, °C (when the
    /// data carry `temp_c`): the thermal state a later check compares with.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Lines of the data file rejected as gross errors.
    #[serde(default)]
    pub rejected_lines: Vec<u64>,
    /// [`LegEffectsDescription::tables_digest`] of the file's compensation
    /// tables as written (absent: the file has none, or it was written
    /// before tables existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leg_tables_digest: Option<String>,
    /// Digests of every field of the file (the geometry, the estimates,
    /// the nominal machine, the UP limb, the workspace, the standard
    /// deviations, noise and temperature a check judges by: every leaf but
    /// the seal), by field name: [`MachineDescription::seal`] writes it,
    /// [`MachineDescription::seal_check`] names a field edited since.
    /// Absent only on a record not yet written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seal: Option<std::collections::BTreeMap<String, String>>,
    /// External measurements fused with the UP limb's data (tracker,
    /// ballbar, touch-off files), when there were any.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub external_sources: Vec<ExternalSourceRecord>,
    /// The data file, as given on the command line.
    pub data_file: String,
    /// SHA-256 of the data file's bytes, hex.
    pub data_sha256: String,
    /// When the file was written, UTC (ISO 8601).
    pub date: String,
    /// `tricept` version that wrote it.
    pub tool_version: String,
    /// Name of the machine the estimates are relative to.
    pub relative_to: String,
    /// The machine the estimates are relative to, when it is not `nominal`
    /// (a recalibration of a calibrated machine: that machine, without its
    /// own record), so that the geometry can be rebuilt from the record.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relative_to_machine: Option<Box<MachineDescription>>,
    /// The nominal machine of the rank rule.
    pub nominal: Box<MachineDescription>,
}

impl MachineDescription {
    /// The paper's Table 1 machine (the embedded default).
    pub fn paper() -> MachineDescription {
        // The embedded text is validated by a unit test; a failure here can
        // only come from editing the fixture, never from user input.
        match Self::from_json(PAPER_MACHINE_JSON) {
            Ok(d) => d,
            Err(e) => unreachable!("embedded paper machine is invalid: {e}"),
        }
    }

    /// Parses and validates a description from JSON text. A text whose
    /// `format_version` is newer than [`FORMAT_VERSION`] is refused first
    /// ([`DescriptionError::NewerFormat`]), whatever else it holds.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::{error::DescriptionError, MachineDescription};
let text = MachineDescription::paper().to_json().replace(
    "\"format_version\": 1,",
    "\"format_version\": 2, \"a_key_of_version_2\": true,",
);
let e = MachineDescription::from_json(&text).unwrap_err();
assert!(matches!(e, DescriptionError::NewerFormat(_)), "{e}");
```
"#
    )]
    pub fn from_json(text: &str) -> Result<MachineDescription, DescriptionError> {
        // A byte-order mark, as some editors write, is not part of the JSON.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        if let Some(newer) = version::newer_format(text, "machine file", FORMAT_VERSION) {
            return Err(newer.into());
        }
        let d: MachineDescription = serde_json::from_str(text)?;
        d.validate()?;
        Ok(d)
    }

    /// Reads, parses and validates a description file.
    pub fn from_file(path: &std::path::Path) -> Result<MachineDescription, DescriptionError> {
        let text =
            tricept_data::bounded::read_json_text(path).map_err(|source| DescriptionError::Io {
                path: path.display().to_string(),
                source,
            })?;
        Self::from_json(&text)
    }

    /// Pretty JSON text of this description.
    pub fn to_json(&self) -> String {
        // Serialising plain data with finite numbers cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// The joint centres `(B1..B3, A1..A3)` in mm.
    pub fn joints_mm(&self) -> ([[f64; 3]; 3], [[f64; 3]; 3]) {
        match &self.placement {
            Placement::Circular(c) => {
                let on_circle = |radius: f64| {
                    c.joint_angles_deg.map(|deg| {
                        let (s, co) = deg.to_radians().sin_cos();
                        [radius * co, radius * s, 0.0]
                    })
                };
                (on_circle(c.base_radius_mm), on_circle(c.platform_radius_mm))
            }
            Placement::Explicit(e) => (e.base_joints_mm, e.platform_joints_mm),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_paper_machine_is_table_1() {
        let d = MachineDescription::from_json(PAPER_MACHINE_JSON).unwrap();
        let Placement::Circular(c) = &d.placement else {
            panic!("paper machine must use the circular placement")
        };
        assert_eq!(c.base_radius_mm, 288.7);
        assert_eq!(c.platform_radius_mm, 100.0);
        assert_eq!(c.joint_angles_deg, [120.0, 240.0, 0.0]);
        assert_eq!(d.workspace.radius_mm, 400.0);
        assert_eq!(d.workspace.height_mm, 200.0);
        assert_eq!(d.workspace.distance_mm, 650.0);
        assert_eq!(d.up_limb.axis_order, AxisOrder::XFirst);
        assert_eq!(d.sensors, SensorDescription::default());
    }

    #[test]
    fn round_trips_through_json() {
        let d = MachineDescription::paper();
        let again = MachineDescription::from_json(&d.to_json()).unwrap();
        assert_eq!(d, again);
        // Zero head angle offsets are not written, so that nominal files stay as they were.
        assert!(!d.to_json().contains("angle_offsets_rad"));
        let mut calibrated = d.clone();
        calibrated.head.angle_offsets_rad = [1e-4, -2e-4];
        let text = calibrated.to_json();
        assert!(text.contains("angle_offsets_rad"));
        assert_eq!(MachineDescription::from_json(&text).unwrap(), calibrated);
    }

    #[test]
    fn rejects_unknown_keys_and_bad_geometry() {
        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["colour"] = "red".into();
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("unknown field `colour`"), "{e}");

        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["placement"]["circular"]["base_radius_mm"] = (-1.0).into();
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("base_radius_mm"), "{e}");

        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["placement"]["circular"]["joint_angles_deg"] = serde_json::json!([0.0, 0.0, 120.0]);
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("coincide"), "{e}");

        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["head"]["angle_offsets_rad"] = serde_json::json!([0.0, 5.0]);
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("head.angle_offsets_rad"), "{e}");

        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["head"]["tool_direction"] = serde_json::json!([2.0, 0.0, 0.0]);
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("second head axis"), "{e}");

        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["limits"] = serde_json::json!({"leg_stroke_mm": [900.0, 500.0]});
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("must be below"), "{e}");
    }

    #[test]
    fn compensation_tables_are_checked_on_load_by_field() {
        let table = |leg: u8, start: f64, step: f64, values: Vec<f64>| {
            serde_json::json!({"leg": leg, "start_mm": start, "step_mm": step,
                "extra_length_um": values, "interpolation": "linear"})
        };
        let with = |tables: Vec<serde_json::Value>| {
            let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
            v["leg_effects"] = serde_json::json!({ "tables": tables });
            MachineDescription::from_json(&v.to_string())
        };
        // A good table loads, and is read linearly.
        let d = with(vec![table(1, 600.0, 1.0, vec![0.0, 2.0, 4.0])]).unwrap();
        let m = d.build().unwrap();
        assert_eq!(m.leg_effects.table_extra_mm(&[601.5, 0.0, 0.0])[0], 0.003);
        for (tables, field) in [
            (vec![table(4, 600.0, 1.0, vec![0.0, 1.0])], "tables[0].leg"),
            (
                vec![
                    table(2, 600.0, 1.0, vec![0.0, 1.0]),
                    table(2, 700.0, 1.0, vec![0.0, 1.0]),
                ],
                "tables[1].leg",
            ),
            (
                vec![table(1, 600.0, 1.0, vec![0.0])],
                "tables[0].extra_length_um",
            ),
            (
                vec![table(1, 600.0, -1.0, vec![0.0, 1.0])],
                "tables[0].step_mm",
            ),
            (
                vec![table(1, 600.0, 0.0, vec![0.0, 1.0])],
                "tables[0].step_mm",
            ),
            (
                vec![table(1, 100.0, 1.0, vec![0.0, 1.0])],
                "tables[0].start_mm",
            ),
            (
                vec![table(1, 1249.5, 1.0, vec![0.0, 1.0])],
                "tables[0].start_mm",
            ),
            (
                vec![table(1, 600.0, 1.0, vec![0.0, 2000.0])],
                "tables[0].extra_length_um[1]",
            ),
            (
                vec![table(1, 600.0, 0.1, vec![0.0, 30.0])],
                "tables[0].extra_length_um[1]",
            ),
        ] {
            let e = with(tables).unwrap_err();
            assert!(
                e.to_string().contains(&format!("leg_effects.{field}")),
                "{field}: {e}"
            );
        }
        // Not a number at all: the parser says where.
        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["leg_effects"] = serde_json::json!({"tables": [{"leg": 1, "start_mm": 600.0,
            "step_mm": 1.0, "extra_length_um": [0.0, "x"]}]});
        assert!(MachineDescription::from_json(&v.to_string()).is_err());
    }

    #[test]
    fn rejects_sizes_no_machine_has() {
        for (key, value) in [
            ("/placement/circular/base_radius_mm", 1e200),
            ("/workspace/radius_mm", 2e5),
            ("/head/tool_tip_mm/2", -1e6),
        ] {
            let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
            *v.pointer_mut(key).unwrap() = value.into();
            let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
            assert!(
                e.to_string().contains("not the size of a machine"),
                "{key}: {e}"
            );
        }
        let mut v: serde_json::Value = serde_json::from_str(PAPER_MACHINE_JSON).unwrap();
        v["leg_effects"] = serde_json::json!({"lead_ppm": [5e4, 0.0, 0.0]});
        let e = MachineDescription::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("lead_ppm"), "{e}");
    }

    #[test]
    fn a_calibrated_description_round_trips_and_its_nominal_is_validated() {
        let mut d = MachineDescription::paper();
        d.leg_effects.compliance_um_per_kn_at_1m = 29.98;
        d.controller = Some(ControllerDescription {
            backlash_um: [6.0, 5.0, 8.0],
            ..ControllerDescription::default()
        });
        let mut nominal = MachineDescription::paper();
        d.calibration = Some(Box::new(CalibrationRecord {
            method: "identify".into(),
            parameter_set: "paper15".into(),
            estimates_mm: serde_json::Map::new(),
            std_dev_mm: serde_json::Map::new(),
            correlations: CorrelationsDescription::default(),
            effects: serde_json::Map::new(),
            sensor_offsets: SensorOffsetsDescription::default(),
            accuracy: None,
            applies: Vec::new(),
            records: Vec::new(),
            held: vec![HeldParameter {
                name: "dyA3".into(),
                reason: "unidentifiable".into(),
            }],
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
            temperature_c: None,
            nominal: Box::new(nominal.clone()),
        }));
        let again = MachineDescription::from_json(&d.to_json()).unwrap();
        assert_eq!(d, again);
        // A broken nominal machine inside is found and named.
        nominal.workspace.radius_mm = -1.0;
        if let Some(c) = &mut d.calibration {
            *c.nominal = nominal;
        }
        let e = MachineDescription::from_json(&d.to_json()).unwrap_err();
        assert!(
            e.to_string().contains("calibration.nominal.workspace"),
            "{e}"
        );
    }
}
