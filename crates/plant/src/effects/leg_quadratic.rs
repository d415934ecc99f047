//! `leg-quadratic`, outside the vocabulary: a leg-length error quadratic in
//! the leg length, `um_i ((q_i - centre) / half_width)^2`, described by the
//! generic family `leg-polynomial`.

use serde::{Deserialize, Serialize};
use tricept_kinematics::Machine;
use tricept_model::effects::{PoseState, Simulate, Simulation, parse_input};

use super::leg_power::{
    CENTRE, HALF_WIDTH, LegPower, UM_AT_HALF_WIDTH, default_centre_mm, default_half_width_mm,
};

/// A leg-length error quadratic in the leg length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegQuadratic {
    /// Error of each leg at `half_width_mm` from the centre, um.
    pub um: [f64; 3],
    /// Leg length of zero error, mm (default 845: the middle of the
    /// paper machine's workspace leg lengths).
    #[serde(default = "default_centre_mm")]
    pub centre_mm: f64,
    /// Distance from the centre at which the error is `um`, mm
    /// (default 250).
    #[serde(default = "default_half_width_mm")]
    pub half_width_mm: f64,
}

pub(super) const SIMULATION: Simulation = Simulation {
    tag: "leg-quadratic",
    cause: "leg-polynomial",
    keys: &[UM_AT_HALF_WIDTH, CENTRE, HALF_WIDTH],
    parse: parse_input::<LegQuadratic>,
    typical: || {
        Box::new(LegQuadratic {
            um: [30.0, -20.0, 25.0],
            centre_mm: 845.0,
            half_width_mm: 250.0,
        })
    },
};

impl Simulate for LegQuadratic {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    /// The power law of exponent 2.
    fn extra_leg_length(&self, nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        let power = LegPower {
            um: self.um,
            exponent: 2.0,
            centre_mm: self.centre_mm,
            half_width_mm: self.half_width_mm,
        };
        power.extra_leg_length(nominal, s, legs_mm);
    }
}
