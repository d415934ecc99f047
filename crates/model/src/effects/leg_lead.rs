//! `leg-lead`: the ball-screw lead error of each actuated leg, an extra
//! length `k_i q_i` (`k_i` in ppm of the command).

use tricept_kinematics::description::LegEffectsDescription;
use tricept_kinematics::{KinematicsError, Machine, up_limb::UpJoints};

use super::spec::{
    CheckColumns, CheckRole, CheckWhen,    Basis, CommonPart, Deployment, EffectSpec, Entries, Judged, Kind, LegContext, LegDeployment, Magnitude,
    Measure, Needs, Parameter, PlausibleRange, PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, PoseState, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "leg-lead",
    physics: "ball-screw lead error: extra length `k_i q_i`",
    quoted_in: "ppm per leg",
    parameters: &[
        Parameter {
            name: "lead1_ppm",
            unit: "ppm",
            typical: 100.0,
        },
        Parameter {
            name: "lead2_ppm",
            unit: "ppm",
            typical: 100.0,
        },
        Parameter {
            name: "lead3_ppm",
            unit: "ppm",
            typical: 100.0,
        },
    ],
    kind: Kind::Leg(entries),
    needs: Needs::Nothing,
    deployment: Deployment::LegEffects(LegDeployment { set, rate }),
    fused: true,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "lead_ppm",
            min: -300.0,
            max: 300.0,
            unit: "ppm",
            why: "ball-screw lead deviations are tens of ppm",
            if_negated: "",
        },
        of: &[
            (Measure::Parameter(0), ""),
            (Measure::Parameter(1), ""),
            (Measure::Parameter(2), ""),
        ],
    }],
    description: "ball-screw lead errors",
    plot: PlotAxes {
        x: XAxis::LegCommand(0),
        y: YAxis::LegResidual(0),
    },
    realistic: |_| {
        vec![Magnitude {
            values: vec![50.0, -50.0, 50.0],
            label: "50 ppm",
        }]
    },
    aliases: &[],
    simulation: SIMULATION,
    common_part: Some(CommonPart {
        label: "leg-lead (equal on all legs)",
        as_alias: "leg-lead (common part)",
        parameter: "lead_ppm (every leg)",
    }),
    check: Some(CheckRole {
        name: "common leg lead",
        parameters: &["lead_ppm"],
        when: CheckWhen::WithoutTemperatures,
        columns: CheckColumns::Legs(|command_mm, _| leg_lead_extra_mm(1.0, command_mm)),
    }),
};

fn entries(at: &LegContext<'_>) -> Result<Entries, KinematicsError> {
    Ok((0..3)
        .map(|i| (i, Basis::Leg(i), leg_lead_extra_mm(1.0, at.commands_mm[i])))
        .collect())
}

fn set(e: &mut LegEffectsDescription, index: usize, value: f64) {
    e.lead_ppm[index] = value;
}

fn rate(machine: &Machine, _up: Option<&UpJoints>) -> Option<[f64; 3]> {
    let lead = machine.leg_effects.lead_ppm;
    Some(std::array::from_fn(|i| leg_lead_extra_mm(lead[i], 1.0)))
}

/// Extra leg length of a ball-screw lead error, mm.
pub fn leg_lead_extra_mm(ppm: f64, command_mm: f64) -> f64 {
    ppm * 1e-6 * command_mm
}

/// The simulator's `leg-lead`: extra leg length `ppm_i 1e-6 q_i`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegLead {
    /// Lead error of each leg, ppm.
    pub ppm: [f64; 3],
}

const SIMULATION: Simulation = Simulation {
    tag: "leg-lead",
    cause: "leg-lead",
        keys: &[EffectKey::new(
        "ppm",
        "ppm",
        "lead error of each leg [3]: the leg grows by ppm 1e-6 q",
    )],
    parse: parse_input::<LegLead>,
    typical: || {
        Box::new(LegLead {
            ppm: [50.0, -30.0, 40.0],
        })
    },
};

impl Simulate for LegLead {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn extra_leg_length(&self, _nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        for i in 0..3 {
            legs_mm[i] += leg_lead_extra_mm(self.ppm[i], s.commands_mm[i]);
        }
    }
}
