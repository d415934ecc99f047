//! `scale-drift`, outside the vocabulary: the scale reading drifts linearly
//! with time, by `um` from the first to the last pose, whatever the
//! temperature; described by the generic family `reading-drift`.

use serde::{Deserialize, Serialize};
use tricept_kinematics::up_limb::UpJoints;
use tricept_model::effects::{
    EffectKey, PoseState, Simulate, Simulation, linear_drift, parse_input,
};

/// A drift of the scale reading over the campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaleDrift {
    /// Drift over the campaign, um.
    pub um: f64,
}

pub(super) const SIMULATION: Simulation = Simulation {
    tag: "scale-drift",
    cause: "reading-drift",
    keys: &[EffectKey::new(
        "um",
        "um",
        "drift of the scale reading from the first pose to the last, linear in time",
    )],
    parse: parse_input::<ScaleDrift>,
    typical: || Box::new(ScaleDrift { um: 4.0 }),
};

impl Simulate for ScaleDrift {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn reading_error(&self, s: &PoseState, _up: &UpJoints, r: &mut [f64; 3]) {
        r[2] += linear_drift(self.um * 1e-3, s.fraction);
    }
}
