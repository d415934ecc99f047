//! `leg-power`, outside the vocabulary (and of the dictionary's forms
//! unless `exponent` is 2): `um_i |(q_i - centre) / half_width|^exponent`,
//! described (approximately) by the generic family `leg-polynomial`; and
//! the power law `leg-quadratic` shares.

use serde::{Deserialize, Serialize};
use tricept_kinematics::Machine;
use tricept_model::effects::{
    EffectKey, PoseState, Simulate, Simulation, normalised_coordinate, parse_input,
};

pub(super) fn default_centre_mm() -> f64 {
    845.0
}

pub(super) fn default_half_width_mm() -> f64 {
    250.0
}

/// The error of each leg at `half_width_mm` from the centre (the key both
/// curved-leg shapes take).
pub(super) const UM_AT_HALF_WIDTH: EffectKey = EffectKey::new(
    "um",
    "um",
    "error of each leg [3] at half_width_mm from the centre",
);
/// The leg length of zero error.
pub(super) const CENTRE: EffectKey =
    EffectKey::new("centre_mm", "mm", "leg length of zero error (default 845)");
/// The distance from the centre at which the error is `um`.
pub(super) const HALF_WIDTH: EffectKey = EffectKey::positive(
    "half_width_mm",
    "mm",
    "distance from the centre at which the error is `um` (default 250)",
);

/// Adds `um_i |(q_i - centre) / half_width|^exponent` (um) to each leg (mm).
pub(super) fn add_power_law(
    legs: &mut [f64; 3],
    commands_mm: &[f64; 3],
    um: &[f64; 3],
    exponent: f64,
    centre_mm: f64,
    half_width_mm: f64,
) {
    for i in 0..3 {
        let x = normalised_coordinate(
            commands_mm[i],
            centre_mm - half_width_mm,
            centre_mm + half_width_mm,
        );
        legs[i] += um[i] * 1e-3 * x.abs().powf(exponent);
    }
}

/// A leg-length error of a power of the leg length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegPower {
    /// Error of each leg at `half_width_mm` from the centre, um.
    pub um: [f64; 3],
    /// Exponent of the shape.
    pub exponent: f64,
    /// Leg length of zero error, mm (default 845).
    #[serde(default = "default_centre_mm")]
    pub centre_mm: f64,
    /// Distance from the centre at which the error is `um`, mm (default 250).
    #[serde(default = "default_half_width_mm")]
    pub half_width_mm: f64,
}

pub(super) const SIMULATION: Simulation = Simulation {
    tag: "leg-power",
    cause: "leg-polynomial",
    keys: &[
        UM_AT_HALF_WIDTH,
        EffectKey::positive(
            "exponent",
            "-",
            "exponent of |x| (outside the dictionary unless 2)",
        ),
        CENTRE,
        HALF_WIDTH,
    ],
    parse: parse_input::<LegPower>,
    typical: || {
        Box::new(LegPower {
            um: [30.0, -20.0, 25.0],
            exponent: 1.5,
            centre_mm: 845.0,
            half_width_mm: 250.0,
        })
    },
};

impl Simulate for LegPower {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn extra_leg_length(&self, _nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        add_power_law(
            legs_mm,
            &s.commands_mm,
            &self.um,
            self.exponent,
            self.centre_mm,
            self.half_width_mm,
        );
    }
}
