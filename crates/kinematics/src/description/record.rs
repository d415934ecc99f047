//! What a calibrated machine file adds to a description: the static leg
//! effects its kinematics apply, the controller parameters of the dynamic
//! effects, and the parts of its calibration record (held parameters,
//! sensor offsets, correlations, external measurement files).

use serde::{Deserialize, Serialize};

use super::geometry::is_zero3;

/// Static effects of the actuated legs: the actual length of leg `i` for
/// command `q_i` is `q_i + dq_i + lead_i 1e-6 q_i + c F_i q_i 1e-9` (mm),
/// with `F_i` the gravity tension of the leg (N) at the pose and `c` the
/// compliance of a 1 m leg (um/kN; stiffness scales as 1/length).
///
/// # Example
/// ```
/// use tricept_kinematics::description::LegEffectsDescription;
/// let e = LegEffectsDescription { lead_ppm: [50.0, 0.0, 0.0], ..Default::default() };
/// assert!(!e.is_zero());
/// assert!(LegEffectsDescription::default().is_zero());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct LegEffectsDescription {
    /// Ball-screw lead error of each leg, ppm of the command.
    pub lead_ppm: [f64; 3],
    /// Axial compliance of a leg of 1 m under its gravity tension, um/kN
    /// (1000 / stiffness in N/um).
    pub compliance_um_per_kn_at_1m: f64,
}

impl LegEffectsDescription {
    /// No effect at all (what a nominal machine has).
    pub fn is_zero(&self) -> bool {
        is_zero3(&self.lead_ppm) && self.compliance_um_per_kn_at_1m == 0.0
    }
}

/// Parameters a CNC controller takes for its own compensation of the
/// dynamic leg effects: lost motion at each reversal of a leg axis, and
/// thermal expansion of the legs relative to a reference temperature.
///
/// # Example
/// ```
/// use tricept_kinematics::description::ControllerDescription;
/// let c = ControllerDescription::default();
/// assert_eq!(c.reference_temperature_c, 20.0);
/// ```
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
