//! `backlash`: lost motion of each actuated leg; the leg stops `b_i / 2`
//! short of the command in the direction it came from (`b_i` in um).

use tricept_kinematics::{KinematicsError, Machine};
use tricept_kinematics::description::ControllerDescription;

use super::spec::{
    Basis, Deployment, EffectSpec, Entries, Judged, Kind, LegContext, Magnitude, Measure, Needs,
    Parameter, PlausibleRange, PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, PoseState, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "backlash",
    physics: "lost motion: the leg stops `b_i/2` short of the command in the direction it came from",
    quoted_in: "um per leg",
    parameters: &[
        Parameter {
            name: "backlash1_um",
            unit: "um",
            typical: 5.0,
        },
        Parameter {
            name: "backlash2_um",
            unit: "um",
            typical: 5.0,
        },
        Parameter {
            name: "backlash3_um",
            unit: "um",
            typical: 5.0,
        },
    ],
    kind: Kind::Leg(entries),
    needs: Needs::ApproachDirections,
    deployment: Deployment::Controller(set),
    fused: false,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "backlash_um",
            min: 0.0,
            max: 50.0,
            unit: "um",
            why: "lost motion is positive: the nut lags",
            if_negated: "a backlash of the opposite sign is what the approach directions' sign convention flipped gives: `dir` must be +1 when the leg last extended (its command grew) and -1 when it retracted (docs/data-format.md)",
        },
        of: &[
            (Measure::Parameter(0), ""),
            (Measure::Parameter(1), ""),
            (Measure::Parameter(2), ""),
        ],
    }],
    description: "lost motion of the legs",
    plot: PlotAxes {
        x: XAxis::LegApproach(0),
        y: YAxis::LegResidual(0),
    },
    realistic: |_| {
        vec![Magnitude {
            values: vec![5.0, 5.0, 5.0],
            label: "5 um",
        }]
    },
    aliases: &[],
    simulation: SIMULATION,
    common_part: None,
    check: None,
};

/// Without logged directions every leg counts as extending.
fn entries(at: &LegContext<'_>) -> Result<Entries, KinematicsError> {
    let dir = at.approach.unwrap_or([1, 1, 1]);
    Ok((0..3)
        .map(|i| (i, Basis::Leg(i), backlash_extra_mm(1.0, dir[i])))
        .collect())
}

fn set(c: &mut ControllerDescription, index: usize, value: f64) {
    c.backlash_um[index] = value;
}

/// Extra leg length from backlash `um` approached in direction `dir`, mm:
/// the nut lags, so an extending leg stops short and a retracting one long.
pub fn backlash_extra_mm(um: f64, dir: i8) -> f64 {
    -f64::from(dir) * 0.5 * um * 1e-3
}

/// The simulator's `backlash`: lost motion `um_i` per leg.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Backlash {
    /// Backlash of each leg, um.
    pub um: [f64; 3],
}

const SIMULATION: Simulation = Simulation {
    tag: "backlash",
    cause: "backlash",
        keys: &[EffectKey::new(
        "um",
        "um",
        "lost motion of each leg [3]; with poses from both directions (both_directions) the data show it",
    )],
    parse: parse_input::<Backlash>,
    typical: || {
        Box::new(Backlash {
            um: [6.0, 5.0, 8.0],
        })
    },
};

impl Simulate for Backlash {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn extra_leg_length(&self, _nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        for i in 0..3 {
            legs_mm[i] += backlash_extra_mm(self.um[i], s.approach[i]);
        }
    }
}
