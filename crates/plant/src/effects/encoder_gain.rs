//! `encoder-gain`, outside the vocabulary: gain errors of the encoders,
//! which read `(1 + g) angle`; described by the generic family
//! `encoder-gain`.

use serde::{Deserialize, Serialize};
use tricept_kinematics::up_limb::UpJoints;
use tricept_model::effects::{
    EffectKey, PoseState, Simulate, Simulation, encoder_gain_error_rad, parse_input,
};

/// Gain errors of the U-joint encoders.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderGain {
    /// Gain error of the phi encoder, ppm.
    pub phi_ppm: f64,
    /// Gain error of the theta encoder, ppm.
    pub theta_ppm: f64,
}

pub(super) const SIMULATION: Simulation = Simulation {
    tag: "encoder-gain",
    cause: "encoder-gain",
    keys: &[
        EffectKey::new("phi_ppm", "ppm", "gain error of the phi encoder"),
        EffectKey::new("theta_ppm", "ppm", "gain error of the theta encoder"),
    ],
    parse: parse_input::<EncoderGain>,
    typical: || {
        Box::new(EncoderGain {
            phi_ppm: 100.0,
            theta_ppm: -80.0,
        })
    },
};

impl Simulate for EncoderGain {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn reading_error(&self, _s: &PoseState, up: &UpJoints, r: &mut [f64; 3]) {
        r[0] += encoder_gain_error_rad(self.phi_ppm, up.phi_rad);
        r[1] += encoder_gain_error_rad(self.theta_ppm, up.theta_rad);
    }
}
