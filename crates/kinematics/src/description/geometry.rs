//! The parts of a machine's geometry as stored in its description: where
//! the joints are, the UP limb with its class-2 errors, the workspace, the
//! joint limits, the head, the sensors' noise and the loads.

use serde::{Deserialize, Serialize};

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

pub(crate) fn is_zero3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| *x == 0.0)
}
