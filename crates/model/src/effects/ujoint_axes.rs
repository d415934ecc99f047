//! `ujoint-axes`: the UP limb's U-joint axes are not orthogonal (skew) and
//! do not intersect (offset), class-2 errors of its kinematics.

use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;

use super::spec::{
    Deployment, EffectSpec, Judged, Kind, Magnitude, Measure, Needs, Parameter, PlausibleRange,
    PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "ujoint-axes",
    physics: "the UP limb's U-joint axes are not orthogonal (skew) and do not intersect (offset)",
    quoted_in: "arcsec, um",
    parameters: &[
        Parameter {
            name: "axis_skew_arcsec",
            unit: "arcsec",
            typical: 30.0,
        },
        Parameter {
            name: "axis_offset_um",
            unit: "um",
            typical: 20.0,
        },
    ],
    kind: Kind::Kinematic(apply),
    needs: Needs::Nothing,
    deployment: Deployment::UpLimb,
    fused: false,
    plausible: &[
        Judged {
            range: PlausibleRange {
                quantity: "axis_skew_arcsec",
                min: -300.0,
                max: 300.0,
                unit: "arcsec",
                why: "machining of the U-joint cross",
                if_negated: "",
            },
            of: &[(Measure::Parameter(0), "")],
        },
        Judged {
            range: PlausibleRange {
                quantity: "axis_offset_um",
                min: -100.0,
                max: 100.0,
                unit: "um",
                why: "bore and cross tolerances",
                if_negated: "",
            },
            of: &[(Measure::Parameter(1), "")],
        },
    ],
    description: "U-joint axes skewed or offset",
    plot: PlotAxes {
        x: XAxis::Angle(1),
        y: YAxis::Reading(0),
    },
    realistic: |_| {
        vec![
            Magnitude {
                values: vec![30.0, 0.0],
                label: "30 arcsec skew",
            },
            Magnitude {
                values: vec![0.0, 20.0],
                label: "20 um offset",
            },
        ]
    },
    aliases: &[],
    simulation: SIMULATION,
    common_part: None,
    check: None,
};

fn apply(machine: &mut Machine, p: &[f64]) {
    add_ujoint_axis_errors(machine, p[0], p[1]);
}

/// Adds U-joint axis errors to `machine`'s UP limb (class 2): the axes
/// skewed by `skew_arcsec` about their common normal and offset by
/// `offset_um` along it.
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// tricept_model::effects::add_ujoint_axis_errors(&mut m, 30.0, 20.0);
/// assert!((m.up_limb.axis_offset_mm - 0.02).abs() < 1e-15);
/// ```
pub fn add_ujoint_axis_errors(machine: &mut Machine, skew_arcsec: f64, offset_um: f64) {
    machine.up_limb.axis_skew_rad += skew_arcsec * RAD_PER_ARCSEC;
    machine.up_limb.axis_offset_mm += offset_um * 1e-3;
}

/// The simulator's U-joint axes that are not orthogonal and do not
/// intersect.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UjointAxes {
    /// Non-orthogonality, arcsec.
    pub skew_arcsec: f64,
    /// Distance between the axes, um.
    pub offset_um: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "ujoint-axes",
    cause: "ujoint-axes",
        keys: &[
        EffectKey::new(
            "skew_arcsec",
            "arcsec",
            "non-orthogonality of the UP limb's U-joint axes",
        ),
        EffectKey::new("offset_um", "um", "distance between the two axes"),
    ],
    parse: parse_input::<UjointAxes>,
    typical: || {
        Box::new(UjointAxes {
            skew_arcsec: 60.0,
            offset_um: 20.0,
        })
    },
};

impl Simulate for UjointAxes {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn modify_machine(&self, machine: &mut Machine) {
        add_ujoint_axis_errors(machine, self.skew_arcsec, self.offset_um);
    }
}
