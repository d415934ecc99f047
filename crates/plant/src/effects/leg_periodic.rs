//! `leg-periodic`, outside the vocabulary: a leg-length error periodic in
//! the leg length (ball-screw pitch error), `um_i w(2 pi q_i / P + psi_i)`,
//! described by the generic family `leg-periodic`.

use serde::{Deserialize, Serialize};
use tricept_kinematics::Machine;
use tricept_model::effects::{
    EffectKey, PoseState, Simulate, Simulation, parse_input, periodic_extra_mm,
};

/// Shape of a periodic leg-length error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Waveform {
    /// `A sin(2 pi q / P + psi)`.
    #[default]
    Sine,
    /// A sawtooth of amplitude `A` (rising linearly from `-A` to `A` over
    /// each period, then dropping): a shape outside the dictionary, with
    /// harmonics.
    Sawtooth,
}

/// A leg-length error periodic in the leg length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegPeriodic {
    /// Amplitude of each leg, um.
    pub um: [f64; 3],
    /// Period (the screw lead), mm.
    pub period_mm: f64,
    /// Phase of each leg, deg.
    pub phase_deg: [f64; 3],
    /// Shape `w` (default sine).
    #[serde(default)]
    pub waveform: Waveform,
}

pub(super) const SIMULATION: Simulation = Simulation {
    tag: "leg-periodic",
    cause: "leg-periodic",
    keys: &[
        EffectKey::new("um", "um", "amplitude of each leg [3]"),
        EffectKey::positive("period_mm", "mm", "period: the screw lead"),
        EffectKey::new("phase_deg", "deg", "phase of each leg [3]"),
        EffectKey::new(
            "waveform",
            "-",
            "`sine` (default) or `sawtooth` (outside the dictionary)",
        ),
    ],
    parse: parse_input::<LegPeriodic>,
    typical: || {
        Box::new(LegPeriodic {
            um: [4.0, 4.0, 4.0],
            period_mm: 10.0,
            phase_deg: [0.0, 120.0, 240.0],
            waveform: Waveform::Sine,
        })
    },
};

impl Simulate for LegPeriodic {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn extra_leg_length(&self, _nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        let (um, period_mm, phase_deg) = (&self.um, self.period_mm, &self.phase_deg);
        for i in 0..3 {
            let q = s.commands_mm[i];
            legs_mm[i] += match self.waveform {
                Waveform::Sine => {
                    let (sp, cp) = phase_deg[i].to_radians().sin_cos();
                    periodic_extra_mm(um[i] * cp, um[i] * sp, period_mm, q)
                }
                Waveform::Sawtooth => {
                    let turns = q / period_mm + phase_deg[i] / 360.0;
                    um[i] * 1e-3 * (2.0 * (turns - turns.floor()) - 1.0)
                }
            };
        }
    }
}
