//! `leg-step`, outside the vocabulary: a worn segment of a leg's ball
//! screw. Leg `i` is `um_i` longer wherever its command lies from `from_mm`
//! to `to_mm`, and as built elsewhere (a step in and out of the segment);
//! described by the generic family `leg-step`.

use serde::{Deserialize, Serialize};
use tricept_kinematics::Machine;
use tricept_model::effects::{
    EffectKey, PoseState, Simulate, Simulation, parse_input, segment_extra_mm,
};

/// A worn segment of the legs' ball screws.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegStep {
    /// Extra length of each leg inside the segment, um.
    pub um: [f64; 3],
    /// Start of the worn segment, mm of leg command.
    pub from_mm: f64,
    /// End of the worn segment, mm of leg command.
    pub to_mm: f64,
}

pub(super) const SIMULATION: Simulation = Simulation {
    tag: "leg-step",
    cause: "leg-step",
    keys: &[
        EffectKey::new(
            "um",
            "um",
            "extra length of each leg [3] inside the worn segment",
        ),
        EffectKey::new("from_mm", "mm", "start of the worn segment, leg command"),
        EffectKey::new("to_mm", "mm", "end of the worn segment, leg command"),
    ],
    parse: parse_input::<LegStep>,
    typical: || {
        Box::new(LegStep {
            um: [20.0, 0.0, 0.0],
            from_mm: 800.0,
            to_mm: 830.0,
        })
    },
};

impl Simulate for LegStep {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn extra_leg_length(&self, _nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        for i in 0..3 {
            legs_mm[i] += segment_extra_mm(self.um[i], self.from_mm, self.to_mm, s.commands_mm[i]);
        }
    }
}
