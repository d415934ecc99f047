//! `thermal`: the legs grow `alpha q_i dT` with the structure temperature,
//! referred to the metrology reference of 20 °C.

use tricept_kinematics::{KinematicsError, Machine};
use tricept_kinematics::description::ControllerDescription;

use super::spec::{
    CheckColumns, CheckRole, CheckWhen,    Basis, Deployment, EffectSpec, Entries, Judged, Kind, LegContext, Magnitude, Measure, Needs,
    Parameter, PlausibleRange, PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, PoseState, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

/// The reference temperature of dimensional metrology (ISO 1), °C: the
/// nominal lengths of the machine are taken to hold at it. (Referring the
/// thermal growth to the campaign's own mean temperature instead would leave
/// `alpha (mean - 20 °C) q_i`, a uniform lead error of all legs, unmodelled.)
pub const REFERENCE_TEMPERATURE_C: f64 = 20.0;

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "thermal",
    physics: "legs grow `alpha q_i dT`",
    quoted_in: "ppm/K",
    parameters: &[Parameter {
        name: "expansion_ppm_per_k",
        unit: "ppm/K",
        typical: 11.5,
    }],
    kind: Kind::Leg(entries),
    needs: Needs::Temperature,
    deployment: Deployment::Controller(set),
    fused: false,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "expansion_ppm_per_k",
            min: 8.0,
            max: 16.0,
            unit: "ppm/K",
            why: "steel or cast-iron legs",
            if_negated: "",
        },
        of: &[(Measure::Parameter(0), "")],
    }],
    description: "thermal growth of the legs with the logged temperature",
    plot: PlotAxes {
        x: XAxis::Temperature,
        y: YAxis::MeanLegResidual,
    },
    realistic: |_| {
        vec![Magnitude {
            values: vec![11.5],
            label: "11.5 ppm/K (steel)",
        }]
    },
    aliases: &[],
    simulation: SIMULATION,
    common_part: None,
    check: Some(CheckRole {
        name: "thermal growth",
        parameters: &["expansion_ppm_per_k"],
        when: CheckWhen::WithTemperatures,
        columns: CheckColumns::Legs(|command_mm, delta_k| thermal_extra_mm(1.0, command_mm, delta_k)),
    }),
};

/// Without a logged temperature the legs are at the reference.
fn entries(at: &LegContext<'_>) -> Result<Entries, KinematicsError> {
    let dt = at
        .temperature_c
        .map_or(0.0, |t| t - REFERENCE_TEMPERATURE_C);
    Ok((0..3)
        .map(|i| (0, Basis::Leg(i), thermal_extra_mm(1.0, at.commands_mm[i], dt)))
        .collect())
}

fn set(c: &mut ControllerDescription, _index: usize, value: f64) {
    c.thermal_expansion_ppm_per_k = value;
    c.reference_temperature_c = REFERENCE_TEMPERATURE_C;
}

/// Thermal growth of a leg of length `command_mm` warmed by `delta_k`, mm.
pub fn thermal_extra_mm(ppm_per_k: f64, command_mm: f64, delta_k: f64) -> f64 {
    ppm_per_k * 1e-6 * command_mm * delta_k
}

/// The simulator's `thermal`: a linear temperature drift over the campaign
/// and the legs' growth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thermal {
    /// Temperature change from the first to the last pose, K.
    pub drift_k: f64,
    /// Effective expansion coefficient of the legs, ppm/K (steel: 11.5).
    pub expansion_ppm_per_k: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "thermal",
    cause: "thermal",
        keys: &[
        EffectKey::new(
            "drift_k",
            "K",
            "temperature change from the first pose to the last",
        ),
        EffectKey::new(
            "expansion_ppm_per_k",
            "ppm/K",
            "the legs' expansion coefficient (steel 11.5; 0 for a temperature log alone)",
        ),
    ],
    parse: parse_input::<Thermal>,
    typical: || {
        Box::new(Thermal {
            drift_k: 3.0,
            expansion_ppm_per_k: 11.5,
        })
    },
};

impl Simulate for Thermal {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn temperature_drift_k(&self, fraction: f64) -> f64 {
        self.drift_k * fraction
    }

    fn extra_leg_length(&self, _nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        for i in 0..3 {
            legs_mm[i] +=
                thermal_extra_mm(self.expansion_ppm_per_k, s.commands_mm[i], s.delta_temp_k);
        }
    }
}
