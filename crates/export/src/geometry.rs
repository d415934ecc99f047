//! The calibrated geometry as a plain table for the machine builder's PKM
//! transformation: the joint centres, the UP limb's parameters and each
//! leg axis' zero, in the machine's base frame, mm and rad (the same for
//! every control; the transformation's own format is the builder's).
//!
//! One `name,value,unit,meaning` row a line, `#` lines are comments. The
//! leg length is `|A_i - B_i|` with `A_i` the platform joint carried by the
//! UP limb's pose, and the axis position is that length minus the leg's
//! zero (`LEG<i>.zero`).

use tricept_kinematics::{Machine, MachineDescription};

use crate::AxisSummary;

/// The file's name.
pub const FILE: &str = "geometry.csv";

/// The table of the calibrated machine.
pub fn table(d: &MachineDescription, m: &Machine, axes: &[AxisSummary]) -> String {
    let mut s = String::from(
        "# tricept export: the calibrated geometry of the Tricept for the PKM transformation (docs/controllers.md)\n# machine base frame Oxyz (platform joints in the platform frame O'x'y'z'), mm and rad\n# leg length = |A_i - B_i|; axis position = leg length - LEG<i>.zero\nname,value,unit,meaning\n",
    );
    let mut row = |name: String, value: String, unit: &str, meaning: String| {
        // The meaning is free text: no comma may split its column.
        let meaning = meaning.replace(',', ";");
        s.push_str(&format!("{name},{value},{unit},{meaning}\n"));
    };
    for (label, joints, frame) in [
        ("B", &m.base_joints_mm, "base joint of leg"),
        ("A", &m.platform_joints_mm, "platform joint of leg"),
    ] {
        for (i, j) in joints.iter().enumerate() {
            for (c, v) in ["x", "y", "z"].iter().zip(j.iter()) {
                row(
                    format!("{label}{}.{c}", i + 1),
                    format!("{v:.6}"),
                    "mm",
                    format!("{frame} {}", i + 1),
                );
            }
        }
    }
    let u = &d.up_limb;
    let order = serde_json::to_value(u.axis_order)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default();
    row(
        "up_limb.axis_order".into(),
        order,
        "",
        "axis order of the UP limb's base U joint".into(),
    );
    for (name, v, unit, meaning) in [
        (
            "up_limb.axis_skew",
            u.axis_skew_rad,
            "rad",
            "non-orthogonality of the U-joint axes",
        ),
        (
            "up_limb.axis_offset",
            u.axis_offset_mm,
            "mm",
            "distance between the U-joint axes",
        ),
        (
            "up_limb.twist",
            u.twist_rad_per_mm,
            "rad/mm",
            "platform twist per mm of UP limb extension",
        ),
        (
            "up_limb.twist_reference",
            u.twist_reference_mm,
            "mm",
            "UP limb extension of zero twist",
        ),
    ] {
        row(name.into(), format!("{v:.9}"), unit, meaning.into());
    }
    for a in axes {
        row(
            format!("LEG{}.zero", a.leg),
            format!("{:.6}", a.zero_mm),
            "mm",
            format!(
                "axis {}: leg length at axis position 0 = the calibrated leg offset + the table's constant {:.6} mm - half the backlash",
                a.axis, a.offset_mm
            ),
        );
        row(
            format!("LEG{}.reference", a.leg),
            format!("{:.6}", a.reference_mm),
            "mm",
            format!(
                "axis {}: the reference point (its compensation reads zero)",
                a.axis
            ),
        );
    }
    s
}
