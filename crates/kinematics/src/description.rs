//! The machine description: the JSON file format and its validation.
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

/// The JSON text of the paper's Table 1 machine, embedded at compile time.
pub const PAPER_MACHINE_JSON: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/machines/tricept-paper.json"
));

/// The largest length (mm) any key of a description may hold: 100 m.
pub const MAX_LENGTH_MM: f64 = 1e5;

/// A complete machine description, as stored in JSON.
///
/// # Example
/// ```
/// use tricept_kinematics::MachineDescription;
/// let d = MachineDescription::paper();
/// assert_eq!(d.workspace.radius_mm, 400.0);
/// let m = d.build().unwrap();
/// assert!((m.base_joints_mm[2].x - 288.7).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineDescription {
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
    /// simulator and by the `compliance` leg effect.
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

fn is_zero3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| *x == 0.0)
}

/// Placement of the three UPS limbs' joint centres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// `B_i = b (cos a_i, sin a_i, 0)`, `A_i = a (cos a_i, sin a_i, 0)`.
    Circular(CircularPlacement),
    /// Joint centres given coordinate by coordinate.
    Explicit(ExplicitPlacement),
}

/// Joints on two circles, at the same angles on base and platform.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircularPlacement {
    /// Circumradius `b` of B1B2B3, mm.
    pub base_radius_mm: f64,
    /// Circumradius `a` of A1A2A3, mm.
    pub platform_radius_mm: f64,
    /// Angles `a_1, a_2, a_3` of the joints on their circles, degrees.
    pub joint_angles_deg: [f64; 3],
}

/// Joint centres given explicitly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplicitPlacement {
    /// B1, B2, B3 in the base frame Oxyz, mm.
    pub base_joints_mm: [[f64; 3]; 3],
    /// A1, A2, A3 in the platform frame O'x'y'z', mm.
    pub platform_joints_mm: [[f64; 3]; 3],
}

/// Which axis of the UP limb's base U joint is fixed to the base.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum AxisOrder {
    /// First axis along base x (angle `phi`), second along the moving y
    /// (angle `theta`): `R = Rx(phi) Ry(theta)` (the paper's eq. 8).
    #[default]
    #[serde(rename = "x-first")]
    XFirst,
    /// First axis along base y (angle `theta`), second along the moving x
    /// (angle `phi`): `R = Ry(theta) Rx(phi)`.
    #[serde(rename = "y-first")]
    YFirst,
}

impl std::fmt::Display for AxisOrder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            AxisOrder::XFirst => "x-first",
            AxisOrder::YFirst => "y-first",
        })
    }
}

/// The UP limb's U joint and prismatic guide, including "class 2" errors
/// that the paper's 15-parameter model leaves out (all zero by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct UpLimbDescription {
    /// Axis order of the base U joint.
    pub axis_order: AxisOrder,
    /// Non-orthogonality of the two U-joint axes: the second axis is rotated
    /// by this angle about their common normal, rad.
    pub axis_skew_rad: f64,
    /// Distance between the two U-joint axes along their common normal
    /// (non-intersecting axes), mm.
    pub axis_offset_mm: f64,
    /// Twist of the platform about the limb axis per mm of extension of the
    /// prismatic joint (twisted guide rails), rad/mm.
    pub twist_rad_per_mm: f64,
    /// Extension `q4` at which the twist is zero, mm.
    pub twist_reference_mm: f64,
}

/// The cylindrical workspace of the platform point O' (Table 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorkspaceDescription {
    /// Cylinder radius R, mm.
    pub radius_mm: f64,
    /// Cylinder height h, mm.
    pub height_mm: f64,
    /// Distance H of the cylinder's near face from the base plane, mm.
    pub distance_mm: f64,
}

/// Joint limits. The paper gives none; the defaults leave a margin of
/// 100 mm of stroke and several degrees of tilt around the Table 1 workspace.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LimitsDescription {
    /// Stroke of the three actuated legs `[min, max]`, mm.
    pub leg_stroke_mm: [f64; 2],
    /// Stroke of the UP limb's passive prismatic joint `[min, max]`, mm.
    pub up_stroke_mm: [f64; 2],
    /// Largest tilt of the UP limb from the base z axis, degrees.
    pub max_tilt_deg: f64,
}

impl Default for LimitsDescription {
    fn default() -> Self {
        LimitsDescription {
            leg_stroke_mm: [450.0, 1250.0],
            up_stroke_mm: [450.0, 1100.0],
            max_tilt_deg: 40.0,
        }
    }
}

/// A 2-DOF rotary head, in product-of-exponentials form: every vector is
/// expressed in the platform frame O'x'y'z' with both head angles at zero.
///
/// Tool tip: `p(h1, h2) = T1(h1) T2(h2) tool_tip_mm`, tool axis
/// `t(h1, h2) = Rot(axis1, h1) Rot(axis2, h2) tool_direction`, where `Tk` is
/// the rotation about the line through `axisk_point_mm` along
/// `axisk_direction`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HeadDescription {
    /// Direction of the first head axis (need not be unit).
    pub axis1_direction: [f64; 3],
    /// A point on the first head axis, mm.
    pub axis1_point_mm: [f64; 3],
    /// Direction of the second head axis at `h1 = 0`.
    pub axis2_direction: [f64; 3],
    /// A point on the second head axis at `h1 = 0`, mm.
    pub axis2_point_mm: [f64; 3],
    /// Tool tip at `h1 = h2 = 0`, mm.
    pub tool_tip_mm: [f64; 3],
    /// Tool axis direction at `h1 = h2 = 0` (need not be unit).
    pub tool_direction: [f64; 3],
    /// Zero offsets of the two head angles, rad: the kinematic angle about
    /// each axis is the commanded angle plus its offset (as the actual leg
    /// length is the command plus `leg_offsets_mm`). Zero on a nominal head;
    /// a calibrated head carries its identified angle zeros here. Omitted
    /// from the JSON when both are zero.
    #[serde(skip_serializing_if = "is_zero2")]
    pub angle_offsets_rad: [f64; 2],
}

fn is_zero2(v: &[f64; 2]) -> bool {
    v.iter().all(|x| *x == 0.0)
}

/// Largest head angle offset accepted, rad: an offset is a calibration of an
/// encoder's zero, not a change of the head's kinematics (a larger value is
/// most likely degrees, or a wrong sign convention).
pub const MAX_HEAD_ANGLE_OFFSET_RAD: f64 = 0.1;

impl Default for HeadDescription {
    /// An A/C head: C axis along z' through O', A axis along x' 150 mm
    /// further out, tool tip 200 mm beyond the A axis along z'.
    fn default() -> Self {
        HeadDescription {
            axis1_direction: [0.0, 0.0, 1.0],
            axis1_point_mm: [0.0, 0.0, 0.0],
            axis2_direction: [1.0, 0.0, 0.0],
            axis2_point_mm: [0.0, 0.0, 150.0],
            tool_tip_mm: [0.0, 0.0, 350.0],
            tool_direction: [0.0, 0.0, 1.0],
            angle_offsets_rad: [0.0, 0.0],
        }
    }
}

/// Sensor noise of the UP limb's encoders and linear scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorDescription {
    /// Standard deviation of one reading of either U-joint encoder, arcsec.
    pub angle_noise_arcsec: f64,
    /// Standard deviation of one reading of the linear scale, um.
    pub length_noise_um: f64,
    /// Readings averaged into one logged value.
    pub readings_per_pose: u32,
}

impl Default for SensorDescription {
    /// The paper's values: 0.8 arcsec, 0.5 um, mean of 3 readings.
    fn default() -> Self {
        SensorDescription {
            angle_noise_arcsec: 0.8,
            length_noise_um: 0.5,
            readings_per_pose: 3,
        }
    }
}

/// Masses and stiffness for gravity-induced leg deflection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LoadsDescription {
    /// Mass of the moving platform and the UP limb's tube, kg.
    pub platform_mass_kg: f64,
    /// Mass of the head and spindle, kg.
    pub head_mass_kg: f64,
    /// Axial stiffness of each actuated leg at 1 m length, N/um (stiffness
    /// scales as 1/length).
    pub leg_stiffness_n_per_um_at_1m: f64,
    /// Centre of mass of the head in the platform frame, mm (the platform's
    /// own is at O').
    pub head_com_mm: [f64; 3],
    /// Unit direction of gravity in the base frame. The default `[0, 0, 1]`
    /// is a Tricept hanging from its base with the tool pointing down.
    pub gravity_direction: [f64; 3],
}

impl Default for LoadsDescription {
    /// 60 kg platform and tube, 90 kg head hanging below the base: about
    /// 1.5 kN, carried along the legs (the UP limb's prismatic joint is
    /// passive). 50 N/um at 1 m gives leg deflections around 8 um.
    fn default() -> Self {
        LoadsDescription {
            platform_mass_kg: 60.0,
            head_mass_kg: 90.0,
            leg_stiffness_n_per_um_at_1m: 50.0,
            head_com_mm: [0.0, 0.0, 150.0],
            gravity_direction: [0.0, 0.0, 1.0],
        }
    }
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

    /// Parses and validates a description from JSON text.
    pub fn from_json(text: &str) -> Result<MachineDescription, DescriptionError> {
        // A byte-order mark, as some editors write, is not part of the JSON.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let d: MachineDescription = serde_json::from_str(text)?;
        d.validate()?;
        Ok(d)
    }

    /// Reads, parses and validates a description file.
    pub fn from_file(path: &std::path::Path) -> Result<MachineDescription, DescriptionError> {
        let text = std::fs::read_to_string(path).map_err(|source| DescriptionError::Io {
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

    /// The validated computational form.
    pub fn build(&self) -> Result<crate::Machine, DescriptionError> {
        self.validate()?;
        Ok(crate::Machine::from_validated(self))
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

    /// Checks that the description is a possible machine.
    pub fn validate(&self) -> Result<(), DescriptionError> {
        let invalid = |key: &str, reason: String| DescriptionError::Invalid {
            key: key.to_string(),
            reason,
        };
        let finite = |key: &str, values: &[f64]| -> Result<(), DescriptionError> {
            match values.iter().find(|v| !v.is_finite()) {
                Some(v) => Err(invalid(key, format!("{v} is not a finite number"))),
                None => Ok(()),
            }
        };
        let positive = |key: &str, v: f64| -> Result<(), DescriptionError> {
            finite(key, &[v])?;
            if v > 0.0 {
                Ok(())
            } else {
                Err(invalid(key, format!("must be positive, got {v}")))
            }
        };
        match &self.placement {
            Placement::Circular(c) => {
                positive("placement.circular.base_radius_mm", c.base_radius_mm)?;
                positive(
                    "placement.circular.platform_radius_mm",
                    c.platform_radius_mm,
                )?;
                finite("placement.circular.joint_angles_deg", &c.joint_angles_deg)?;
            }
            Placement::Explicit(e) => {
                finite(
                    "placement.explicit.base_joints_mm",
                    e.base_joints_mm.as_flattened(),
                )?;
                finite(
                    "placement.explicit.platform_joints_mm",
                    e.platform_joints_mm.as_flattened(),
                )?;
            }
        }
        // Finite is not enough: 1e200 mm would pass every check below and
        // overflow inside the solvers.
        let size = |key: &str, values: &[f64]| -> Result<(), DescriptionError> {
            finite(key, values)?;
            match values.iter().find(|v| v.abs() > MAX_LENGTH_MM) {
                Some(v) => Err(invalid(
                    key,
                    format!(
                        "{v} mm is not the size of a machine (lengths are limited to {MAX_LENGTH_MM} mm)"
                    ),
                )),
                None => Ok(()),
            }
        };
        match &self.placement {
            Placement::Circular(c) => size(
                "placement.circular",
                &[c.base_radius_mm, c.platform_radius_mm],
            )?,
            Placement::Explicit(e) => {
                size(
                    "placement.explicit.base_joints_mm",
                    e.base_joints_mm.as_flattened(),
                )?;
                size(
                    "placement.explicit.platform_joints_mm",
                    e.platform_joints_mm.as_flattened(),
                )?;
            }
        }
        size("leg_offsets_mm", &self.leg_offsets_mm)?;
        size(
            "up_limb",
            &[self.up_limb.axis_offset_mm, self.up_limb.twist_reference_mm],
        )?;
        size(
            "workspace",
            &[
                self.workspace.radius_mm,
                self.workspace.height_mm,
                self.workspace.distance_mm,
            ],
        )?;
        size("limits.leg_stroke_mm", &self.limits.leg_stroke_mm)?;
        size("limits.up_stroke_mm", &self.limits.up_stroke_mm)?;
        for (key, v) in [
            ("head.axis1_point_mm", self.head.axis1_point_mm),
            ("head.axis2_point_mm", self.head.axis2_point_mm),
            ("head.tool_tip_mm", self.head.tool_tip_mm),
            ("loads.head_com_mm", self.loads.head_com_mm),
        ] {
            size(key, &v)?;
        }
        let e = &self.leg_effects;
        finite("leg_effects.lead_ppm", &e.lead_ppm)?;
        finite(
            "leg_effects.compliance_um_per_kn_at_1m",
            &[e.compliance_um_per_kn_at_1m],
        )?;
        if let Some(v) = e.lead_ppm.iter().find(|v| v.abs() > 1e4) {
            return Err(invalid(
                "leg_effects.lead_ppm",
                format!("{v} ppm is not a lead error (limit 10000 ppm, 1 %)"),
            ));
        }
        if e.compliance_um_per_kn_at_1m.abs() > 1e4 {
            return Err(invalid(
                "leg_effects.compliance_um_per_kn_at_1m",
                format!(
                    "{} um/kN is not the compliance of a machine leg (limit 10000 um/kN)",
                    e.compliance_um_per_kn_at_1m
                ),
            ));
        }
        if let Some(c) = &self.controller {
            finite("controller.backlash_um", &c.backlash_um)?;
            finite(
                "controller",
                &[c.thermal_expansion_ppm_per_k, c.reference_temperature_c],
            )?;
            if !(-60.0..=200.0).contains(&c.reference_temperature_c) {
                return Err(invalid(
                    "controller.reference_temperature_c",
                    format!("{} °C is outside -60..200 °C", c.reference_temperature_c),
                ));
            }
        }
        if let Some(c) = &self.calibration {
            c.nominal.validate().map_err(|e| match e {
                DescriptionError::Invalid { key, reason } => DescriptionError::Invalid {
                    key: format!("calibration.nominal.{key}"),
                    reason,
                },
                e => e,
            })?;
        }

        let (base, platform) = self.joints_mm();
        check_triangle("base joints B1..B3", &base, Some([0.0; 3]))
            .map_err(|r| invalid("placement", r))?;
        check_triangle("platform joints A1..A3", &platform, None)
            .map_err(|r| invalid("placement", r))?;

        let up = &self.up_limb;
        finite(
            "up_limb",
            &[
                up.axis_skew_rad,
                up.axis_offset_mm,
                up.twist_rad_per_mm,
                up.twist_reference_mm,
            ],
        )?;
        if up.axis_skew_rad.abs() > 0.1 {
            return Err(invalid(
                "up_limb.axis_skew_rad",
                format!(
                    "{} rad is not a small manufacturing error (limit 0.1 rad)",
                    up.axis_skew_rad
                ),
            ));
        }
        finite("leg_offsets_mm", &self.leg_offsets_mm)?;

        let w = &self.workspace;
        positive("workspace.radius_mm", w.radius_mm)?;
        positive("workspace.height_mm", w.height_mm)?;
        positive("workspace.distance_mm", w.distance_mm)?;

        let l = &self.limits;
        for (key, [lo, hi]) in [
            ("limits.leg_stroke_mm", l.leg_stroke_mm),
            ("limits.up_stroke_mm", l.up_stroke_mm),
        ] {
            positive(key, lo)?;
            positive(key, hi)?;
            if lo >= hi {
                return Err(invalid(key, format!("min {lo} must be below max {hi}")));
            }
        }
        positive("limits.max_tilt_deg", l.max_tilt_deg)?;
        if l.max_tilt_deg >= 90.0 {
            return Err(invalid(
                "limits.max_tilt_deg",
                format!("{} deg must be below 90", l.max_tilt_deg),
            ));
        }

        let h = &self.head;
        for (key, v) in [
            ("head.axis1_direction", h.axis1_direction),
            ("head.axis2_direction", h.axis2_direction),
            ("head.tool_direction", h.tool_direction),
        ] {
            finite(key, &v)?;
            if norm3(v) < 1e-9 {
                return Err(invalid(key, "direction must not be the zero vector".into()));
            }
        }
        for (key, v) in [
            ("head.axis1_point_mm", h.axis1_point_mm),
            ("head.axis2_point_mm", h.axis2_point_mm),
            ("head.tool_tip_mm", h.tool_tip_mm),
        ] {
            finite(key, &v)?;
        }
        let (a1, a2) = (unit3(h.axis1_direction), unit3(h.axis2_direction));
        if norm3(cross3(a1, a2)) < 1e-6 {
            return Err(invalid(
                "head.axis2_direction",
                "the two head axes are parallel: the head would have one degree of freedom".into(),
            ));
        }
        if norm3(cross3(a2, unit3(h.tool_direction))) < 1e-6 {
            return Err(invalid(
                "head.tool_direction",
                "the tool lies along the second head axis: that axis could not turn it".into(),
            ));
        }
        finite("head.angle_offsets_rad", &h.angle_offsets_rad)?;
        if let Some(v) = h
            .angle_offsets_rad
            .iter()
            .find(|v| v.abs() > MAX_HEAD_ANGLE_OFFSET_RAD)
        {
            return Err(invalid(
                "head.angle_offsets_rad",
                format!(
                    "{v} rad is not a zero offset of a head encoder (limit {MAX_HEAD_ANGLE_OFFSET_RAD} rad; degrees?)"
                ),
            ));
        }

        let s = &self.sensors;
        positive("sensors.angle_noise_arcsec", s.angle_noise_arcsec)?;
        positive("sensors.length_noise_um", s.length_noise_um)?;
        if s.readings_per_pose == 0 {
            return Err(invalid(
                "sensors.readings_per_pose",
                "must be at least 1".into(),
            ));
        }
        let loads = &self.loads;
        finite(
            "loads",
            &[
                loads.platform_mass_kg,
                loads.head_mass_kg,
                loads.leg_stiffness_n_per_um_at_1m,
            ],
        )?;
        if loads.platform_mass_kg < 0.0 || loads.head_mass_kg < 0.0 {
            return Err(invalid("loads", "masses must not be negative".into()));
        }
        positive(
            "loads.leg_stiffness_n_per_um_at_1m",
            loads.leg_stiffness_n_per_um_at_1m,
        )?;
        finite("loads.head_com_mm", &loads.head_com_mm)?;
        finite("loads.gravity_direction", &loads.gravity_direction)?;
        if norm3(loads.gravity_direction) < 1e-9 {
            return Err(invalid(
                "loads.gravity_direction",
                "direction must not be the zero vector".into(),
            ));
        }
        Ok(())
    }
}

fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn unit3(v: [f64; 3]) -> [f64; 3] {
    let n = norm3(v);
    [v[0] / n, v[1] / n, v[2] / n]
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Joints must be distinct (1 mm apart) and not collinear; base joints must
/// also stay clear of the UP limb's joint B4 at the origin.
fn check_triangle(
    what: &str,
    p: &[[f64; 3]; 3],
    also_distinct_from: Option<[f64; 3]>,
) -> Result<(), String> {
    const MIN_SEPARATION_MM: f64 = 1.0;
    for i in 0..3 {
        for j in i + 1..3 {
            let d = norm3(sub3(p[i], p[j]));
            if d < MIN_SEPARATION_MM {
                return Err(format!(
                    "{what}: joints {} and {} coincide ({d:.3} mm apart)",
                    i + 1,
                    j + 1
                ));
            }
        }
        if let Some(q) = also_distinct_from {
            let d = norm3(sub3(p[i], q));
            if d < MIN_SEPARATION_MM {
                return Err(format!(
                    "{what}: joint {} coincides with the UP limb's joint B4 at the origin",
                    i + 1
                ));
            }
        }
    }
    let area2 = norm3(cross3(sub3(p[1], p[0]), sub3(p[2], p[0])));
    let longest = (0..3)
        .map(|i| norm3(sub3(p[i], p[(i + 1) % 3])))
        .fold(0.0, f64::max);
    if area2 < 1e-3 * longest * longest {
        return Err(format!("{what} are collinear"));
    }
    Ok(())
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
