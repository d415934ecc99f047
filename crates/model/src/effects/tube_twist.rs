//! `tube-twist`: twisted guide rails of the UP limb turn the platform about
//! the limb axis as it extends, a class-2 error of its kinematics.

use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;

use super::spec::{
    Deployment, EffectSpec, Judged, Kind, Magnitude, Measure, Needs, Parameter, PlausibleRange,
    PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "tube-twist",
    physics: "twisted guide rails turn the platform about the limb axis as it extends",
    quoted_in: "arcsec per 100 mm",
    parameters: &[Parameter {
        name: "twist_arcsec_per_100mm",
        unit: "arcsec per 100 mm",
        typical: 10.0,
    }],
    kind: Kind::Kinematic(apply),
    needs: Needs::Nothing,
    deployment: Deployment::UpLimb,
    fused: false,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "twist_arcsec_per_100mm",
            min: -50.0,
            max: 50.0,
            unit: "arcsec per 100 mm",
            why: "guide-rail twist tolerances (150 arcsec over the stroke)",
            if_negated: "",
        },
        of: &[(Measure::Parameter(0), "")],
    }],
    description: "the platform twists about the UP limb as it extends",
    plot: PlotAxes {
        x: XAxis::Extension,
        y: YAxis::LegResidual(0),
    },
    realistic: |_| {
        vec![Magnitude {
            values: vec![30.0 / 2.9],
            label: "30 arcsec over the stroke",
        }]
    },
    aliases: &[],
    simulation: SIMULATION,
    common_part: None,
    check: None,
};

fn apply(machine: &mut Machine, p: &[f64]) {
    add_tube_twist(machine, p[0]);
}

/// Adds a twist of the UP limb's guide rails to `machine` (class 2): the
/// platform turns about the limb axis by `arcsec_per_100mm` per 100 mm of
/// extension from [`twist_reference_mm`].
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// tricept_model::effects::add_tube_twist(&mut m, 30.0);
/// assert_eq!(m.up_limb.twist_reference_mm, 750.0);
/// ```
pub fn add_tube_twist(machine: &mut Machine, arcsec_per_100mm: f64) {
    machine.up_limb.twist_rad_per_mm += arcsec_per_100mm * RAD_PER_ARCSEC / 100.0;
    machine.up_limb.twist_reference_mm = twist_reference_mm(machine);
}

/// Extension at which the tube twist is zero: the UP limb length at the
/// workspace's middle plane on the axis.
pub fn twist_reference_mm(machine: &Machine) -> f64 {
    machine.workspace.mid_plane_z_mm()
}

/// The simulator's platform twist about the limb axis, proportional to the
/// extension from the workspace's middle plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TubeTwist {
    /// Twist per 100 mm of extension, arcsec.
    pub arcsec_per_100mm: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "tube-twist",
    cause: "tube-twist",
        keys: &[EffectKey::new(
        "arcsec_per_100mm",
        "arcsec/100mm",
        "platform twist about the limb axis per 100 mm of extension from the middle plane",
    )],
    parse: parse_input::<TubeTwist>,
    typical: || {
        Box::new(TubeTwist {
            arcsec_per_100mm: 30.0,
        })
    },
};

impl Simulate for TubeTwist {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn modify_machine(&self, machine: &mut Machine) {
        add_tube_twist(machine, self.arcsec_per_100mm);
    }
}
