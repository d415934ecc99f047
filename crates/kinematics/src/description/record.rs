//! What a calibrated machine file adds to a description: the static leg
//! effects its kinematics apply, the controller parameters of the dynamic
//! effects, and the parts of its calibration record (held parameters,
//! sensor offsets, correlations, external measurement files).

use serde::{Deserialize, Serialize};

use super::geometry::is_zero3;

/// Static effects of the actuated legs: the actual length of leg `i` for
/// command `q_i` is `q_i + dq_i + lead_i 1e-6 q_i + c F_i q_i 1e-9 +
/// T_i(q_i)` (mm), with `F_i` the gravity tension of the leg (N) at the
/// pose, `c` the compliance of a 1 m leg (um/kN; stiffness scales as
/// 1/length) and `T_i` leg `i`'s compensation table, when it has one
/// ([`LegTableDescription`]).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_kinematics::description::LegEffectsDescription;
let e = LegEffectsDescription { lead_ppm: [50.0, 0.0, 0.0], ..Default::default() };
assert!(!e.is_zero());
assert!(LegEffectsDescription::default().is_zero());
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct LegEffectsDescription {
    /// Ball-screw lead error of each leg, ppm of the command.
    pub lead_ppm: [f64; 3],
    /// Axial compliance of a leg of 1 m under its gravity tension, um/kN
    /// (1000 / stiffness in N/um).
    pub compliance_um_per_kn_at_1m: f64,
    /// Per-leg compensation tables (at most one per leg): the leg errors
    /// that are functions of the leg command (ball-screw pitch error, a
    /// curved or worn screw), the form a CNC controller's pitch-error
    /// compensation takes. Absent in files written before them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tables: Vec<LegTableDescription>,
}

impl LegEffectsDescription {
    /// No effect at all (what a nominal machine has).
    pub fn is_zero(&self) -> bool {
        is_zero3(&self.lead_ppm) && self.compliance_um_per_kn_at_1m == 0.0 && self.tables.is_empty()
    }

    /// The extra length of each leg (mm) from its compensation table at
    /// the commands `commands_mm` (zero for a leg without one).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::description::{LegEffectsDescription, LegTableDescription};
let e = LegEffectsDescription {
    tables: vec![LegTableDescription::new(2, 600.0, 10.0, vec![0.0, 4.0, 2.0])],
    ..Default::default()
};
let x = e.table_extra_mm(&[605.0, 605.0, 1000.0]);
assert_eq!(x[0], 0.0);
assert!((x[1] - 0.002).abs() < 1e-15); // halfway between 0 and 4 um
```
"#
    )]
    pub fn table_extra_mm(&self, commands_mm: &[f64; 3]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for t in &self.tables {
            if let Some(i) = t.leg_index() {
                out[i] += t.extra_mm(commands_mm[i]);
            }
        }
        out
    }

    /// A digest of the tables as written (64-bit FNV-1a over every field
    /// that is applied: leg, start and step to 1e-9 mm, the values to
    /// 1e-6 um, the interpolation), in hex; `None` without tables. A calibration record
    /// keeps it, so that a table edited after the calibration is seen when
    /// the file is loaded.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::description::{LegEffectsDescription, LegTableDescription};
let mut e = LegEffectsDescription {
    tables: vec![LegTableDescription::new(1, 600.0, 10.0, vec![0.0, 4.0, 2.0])],
    ..Default::default()
};
let written = e.tables_digest();
assert!(written.is_some());
e.tables[0].extra_length_um[1] = 4.5;
assert_ne!(e.tables_digest(), written);
assert_eq!(LegEffectsDescription::default().tables_digest(), None);
```
"#
    )]
    pub fn tables_digest(&self) -> Option<String> {
        if self.tables.is_empty() {
            return None;
        }
        const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
        const PRIME: u64 = 0x0000_0100_0000_01b3;
        let mut hash = OFFSET;
        let mut eat = |word: u64| {
            for byte in word.to_le_bytes() {
                hash = (hash ^ u64::from(byte)).wrapping_mul(PRIME);
            }
        };
        // Quantised (1e-9 mm, 1e-6 um: far below any machine's resolution)
        // so that a JSON round trip, whose parser may move a number by one
        // unit in its last place, keeps the digest.
        let quantised = |x: f64, unit: f64| (x / unit).round() as i64 as u64;
        for t in &self.tables {
            eat(u64::from(t.leg));
            eat(quantised(t.start_mm, 1e-9));
            eat(quantised(t.step_mm, 1e-9));
            eat(t.extra_length_um.len() as u64);
            t.extra_length_um
                .iter()
                .for_each(|&v| eat(quantised(v, 1e-6)));
            eat(match t.interpolation {
                Interpolation::Linear => 0,
            });
        }
        Some(format!("{hash:016x}"))
    }
}

/// How a compensation table is read between its points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Interpolation {
    /// Straight lines between neighbouring points; beyond the first or the
    /// last point the end value holds.
    #[default]
    Linear,
}

/// A leg's compensation table: the extra length of the leg (um) at leg
/// commands `start_mm + k step_mm`, `k = 0 .. n-1`, equally spaced over
/// the stroke the calibration measured, read by linear interpolation
/// ([`Interpolation::Linear`]; the end values hold beyond the table). A
/// leg whose table reads `+3 um` at a command is 3 um longer there than
/// the geometry says: `ik` commands it 3 um shorter.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_kinematics::description::LegTableDescription;
let t = LegTableDescription::new(1, 700.0, 5.0, vec![1.0, -1.0]);
assert!((t.extra_mm(702.5) - 0.0).abs() < 1e-15);
assert_eq!(t.extra_mm(600.0), 0.001); // the first value holds before the table
assert_eq!(t.end_mm(), 705.0);
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegTableDescription {
    /// The leg, 1 to 3.
    pub leg: u8,
    /// The leg command of the first point, mm.
    pub start_mm: f64,
    /// The spacing of the points, mm (positive: the commands increase).
    pub step_mm: f64,
    /// The leg's extra length at each point, um.
    pub extra_length_um: Vec<f64>,
    /// How values between the points are read.
    #[serde(default)]
    pub interpolation: Interpolation,
    /// What the table carries (the diagnosis' terms), for people.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub source: String,
}

impl LegTableDescription {
    /// A linear table of leg `leg` (1-3) without a source note.
    pub fn new(leg: u8, start_mm: f64, step_mm: f64, extra_length_um: Vec<f64>) -> Self {
        LegTableDescription {
            leg,
            start_mm,
            step_mm,
            extra_length_um,
            interpolation: Interpolation::Linear,
            source: String::new(),
        }
    }

    /// The leg's index, 0 to 2 (`None` for a leg number outside 1-3, which
    /// validation refuses).
    pub fn leg_index(&self) -> Option<usize> {
        (1..=3)
            .contains(&self.leg)
            .then(|| usize::from(self.leg) - 1)
    }

    /// The command of the last point, mm.
    pub fn end_mm(&self) -> f64 {
        self.start_mm + self.step_mm * self.extra_length_um.len().saturating_sub(1) as f64
    }

    /// The extra length (mm) at command `command_mm`: linear between the
    /// points, the end values beyond them, zero for an empty table.
    pub fn extra_mm(&self, command_mm: f64) -> f64 {
        let v = &self.extra_length_um;
        let Some(last) = v.len().checked_sub(1) else {
            return 0.0;
        };
        let x = ((command_mm - self.start_mm) / self.step_mm).clamp(0.0, last as f64);
        if !x.is_finite() {
            return 0.0;
        }
        let k = (x.floor() as usize).min(last.saturating_sub(1));
        let f = x - k as f64;
        let um = if last == 0 {
            v[0]
        } else {
            v[k] + f * (v[k + 1] - v[k])
        };
        um * 1e-3
    }
}

/// Parameters a CNC controller takes for its own compensation of the
/// dynamic leg effects: lost motion at each reversal of a leg axis, and
/// thermal expansion of the legs relative to a reference temperature.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_kinematics::description::ControllerDescription;
let c = ControllerDescription::default();
assert_eq!(c.reference_temperature_c, 20.0);
```
"#
)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControllerDescription {
    /// Backlash (lost motion at reversal) of each leg axis, um: the leg
    /// stops `backlash/2` short of the command in the direction it came from.
    pub backlash_um: [f64; 3],
    /// Effective thermal expansion coefficient of the legs, ppm/K: a leg of
    /// command `q` grows by `alpha q (T - T_ref)`.
    pub thermal_expansion_ppm_per_k: f64,
    /// The temperature `T_ref` at which the calibrated lengths hold, °C.
    pub reference_temperature_c: f64,
}

impl Default for ControllerDescription {
    /// No backlash, no expansion, the ISO 1 reference temperature of 20 °C.
    fn default() -> Self {
        ControllerDescription {
            backlash_um: [0.0; 3],
            thermal_expansion_ppm_per_k: 0.0,
            reference_temperature_c: 20.0,
        }
    }
}

/// The accuracy a calibrated machine file promises
/// (`docs/reliability.md`, "The accuracy block"): the predicted rms
/// positioning error over the workspace, a 95 % upper bound of it, the
/// point it is of, and the parts it is made of.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_kinematics::description::AccuracyRecord;
let a = AccuracyRecord { rms_mm: 0.004, upper_mm: 0.006, point: "platform".into(), parts: Default::default() };
assert!(a.upper_mm >= a.rms_mm);
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccuracyRecord {
    /// Predicted rms positioning error over the workspace, mm.
    pub rms_mm: f64,
    /// A 95 % upper bound of the rms error the file delivers, mm.
    pub upper_mm: f64,
    /// The point positioned: `platform` or `tool tip`.
    pub point: String,
    /// The parts of the promise (units in the names).
    #[serde(default, skip_serializing_if = "serde_json::Map::is_empty")]
    pub parts: serde_json::Map<String, serde_json::Value>,
}

/// A parameter held at its prior value, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldParameter {
    /// Parameter name.
    pub name: String,
    /// Why the fit did not estimate it.
    pub reason: String,
}

/// Estimated zero offsets of the UP limb's sensors with their standard
/// deviations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SensorOffsetsDescription {
    /// Encoder `phi` zero offset, rad.
    pub phi_rad: f64,
    /// Encoder `theta` zero offset, rad.
    pub theta_rad: f64,
    /// Linear scale zero offset, mm.
    pub s_mm: f64,
    /// Standard deviations `[phi rad, theta rad, s mm]`.
    pub std_dev: [f64; 3],
}

/// Correlation matrix of the estimated parameters (held ones left out).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CorrelationsDescription {
    /// Row and column names.
    pub names: Vec<String>,
    /// Row-major correlations, `names.len()` rows of `names.len()`.
    pub matrix: Vec<Vec<f64>>,
}

/// An external measurement file of a fused calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalSourceRecord {
    /// `tracker`, `ballbar` or `touch`.
    pub kind: String,
    /// The file, as given on the command line.
    pub file: String,
    /// SHA-256 of its bytes, hex.
    pub sha256: String,
    /// Records used.
    pub records: usize,
    /// Its weighted chi-square per degree of freedom in the fused fit
    /// (`null` when its rows leave less than one degree of freedom).
    #[serde(default)]
    pub chi2_per_dof: Option<f64>,
    /// Its degrees of freedom in the fused fit (`sum (1 - h_ii)` over its
    /// rows), and whether they were enough to check the fit.
    #[serde(default)]
    pub redundancy: f64,
    /// Whether its rows could check the fit (`redundancy` at least 6 per
    /// tracker station, 4 per ballbar setup or touched feature).
    #[serde(default = "checkable_default")]
    pub checkable: bool,
    /// Lines of the file rejected as gross errors.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rejected_lines: Vec<u64>,
    /// The instrument's fitted nuisance, `{name: {"value", "std_dev"}}`
    /// (units in the names): each tracker station's frame (`sN.rx_rad`,
    /// `.ry_rad`, `.rz_rad`: the rotation vector, and `sN.tx_mm` ...: the
    /// translation, of `y = R x + t` from the machine's base frame into the
    /// tracker's), its target offset, each ballbar setup's pivot and
    /// length error, each touched feature and the stylus radius.
    #[serde(default, skip_serializing_if = "serde_json::Map::is_empty")]
    pub nuisance: serde_json::Map<String, serde_json::Value>,
}

fn checkable_default() -> bool {
    true
}
