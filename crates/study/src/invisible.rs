//! The general rule for the platform-joint error that the UP limb's
//! sensors cannot see, stated from the geometry alone (no singular values),
//! so that it can be checked against the identifiability report.
//!
//! The UP limb's U joint has a first axis `u` fixed to the base (base x for
//! the x-first joint, base y for y-first) and a second axis `v` that turns
//! with the first angle and is always perpendicular to `u`. The plane
//! through `B4` (the origin) normal to `v` therefore always contains `u`,
//! the limb and the platform's axis `u'` (the platform axis that coincides
//! with `u` at the home pose); it turns with the first angle, and the only
//! base points it contains at every angle are those on the line of `u`.
//!
//! **Rule.** If a leg's base joint `B_i` lies on the line of the fixed axis
//! `u` and its platform joint `A_i` lies in the platform plane spanned by
//! `u'` and `z'` (as the circular placement gives whenever `B_i` does), the
//! leg never leaves that plane. Moving `A_i` along `v` (the platform's `y'`
//! for x-first, `x'` for y-first) moves it normal to the plane, which
//! changes the leg's length only at second order: `dyA_i` (x-first) or
//! `dxA_i` (y-first) is invisible to first order. The paper's machine
//! (x-first, `B3` at 0°) loses `dyA3`; a y-first machine with `B3` at 90°
//! or 270° loses `dxA3`; a machine with no base joint on the fixed axis
//! loses none.
//!
//! The rule is for an ideal U joint: with class-2 errors (axis skew or
//! offset) the limb no longer stays in one plane and the argument does not
//! apply (the error is then expected to be weakly visible; not measured).

use tricept_kinematics::{Machine, description::AxisOrder};

/// Relative tolerance of "lies on the axis" (rounding of the placement).
const ON_AXIS: f64 = 1e-9;

/// A platform-joint error that the rule says the sensors cannot see.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InvisibleError {
    /// The leg, 1-based.
    pub leg: usize,
    /// The parameter's name in the 21-parameter vocabulary (`dyA3`, ...).
    pub parameter: String,
}

/// The platform-joint errors of `machine` that its UP limb's sensors cannot
/// see to first order, by the rule of the module docs.
///
/// # Example
/// ```
/// use tricept_kinematics::{description::AxisOrder, Machine};
/// use tricept_study::invisible::invisible_platform_errors;
/// // The paper's machine: B3 at 0 degrees, on the x-first joint's fixed axis.
/// let m = Machine::paper();
/// let lost: Vec<String> = invisible_platform_errors(&m).into_iter().map(|e| e.parameter).collect();
/// assert_eq!(lost, ["dyA3"]);
/// // The same placement with a y-first joint has no base joint on base y.
/// assert!(invisible_platform_errors(&m.with_axis_order(AxisOrder::YFirst)).is_empty());
/// ```
pub fn invisible_platform_errors(machine: &Machine) -> Vec<InvisibleError> {
    // Index of the fixed axis u and of the second axis v at the home pose.
    let (u, v, name) = match machine.up_limb.axis_order {
        AxisOrder::XFirst => (0, 1, "dy"),
        AxisOrder::YFirst => (1, 0, "dx"),
    };
    let w = 3 - u - v; // z
    (0..3)
        .filter(|&i| {
            let b = &machine.base_joints_mm[i];
            let a = &machine.platform_joints_mm[i];
            let on_line = b[v].abs() <= ON_AXIS * b.norm() && b[w].abs() <= ON_AXIS * b.norm();
            let in_plane = a[v].abs() <= ON_AXIS * a.norm();
            on_line && in_plane
        })
        .map(|i| InvisibleError {
            leg: i + 1,
            parameter: format!("{name}A{}", i + 1),
        })
        .collect()
}
