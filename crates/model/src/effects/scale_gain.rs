//! `scale-gain`: the UP limb's linear scale reads `(1 + g) q4` (`g` in
//! ppm).

use tricept_kinematics::up_limb::UpJoints;

use super::spec::{
    CheckColumns, CheckRole, CheckWhen,    Basis, Deployment, EffectSpec, Entries, Judged, Kind, KnownAlias, Magnitude, Measure, Needs,
    Parameter, PlausibleRange, PlotAxes, Structural, XAxis, YAxis,
};
use super::simulation::{EffectKey, PoseState, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "scale-gain",
    physics: "the linear scale reads `(1 + g) q4`",
    quoted_in: "ppm",
    parameters: &[Parameter {
        name: "scale_gain_ppm",
        unit: "ppm",
        typical: 100.0,
    }],
    kind: Kind::Reading(entries),
    needs: Needs::Nothing,
    deployment: Deployment::Sensor,
    fused: true,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "scale_gain_ppm",
            min: -300.0,
            max: 300.0,
            unit: "ppm",
            why: "glass scales and their mounting",
            if_negated: "",
        },
        of: &[(Measure::Parameter(0), "")],
    }],
    description: "gain error of the linear scale",
    plot: PlotAxes {
        x: XAxis::Extension,
        y: YAxis::ScaleResidual,
    },
    realistic: |_| {
        vec![Magnitude {
            values: vec![50.0],
            label: "50 ppm",
        }]
    },
    aliases: &[KnownAlias {
        with: "leg-lead",
        why: "a scale gain g reads exactly like the machine scaled by 1 + g with a lead g on every leg",
        separate_by: "one external length: a laser interferometer or gauge-block measurement of the UP-limb stroke or of one platform displacement fixes the gain; the machine's own sensors never can",
        structural: Some(Structural {
            common_of: "leg-lead",
            // The legs read 1 + g too long (a lead of g on every leg) and
            // the UP limb's scale 1 / (1 + g) (a gain of -g), in ppm.
            scaled_machine: (1e6, -1e6),
            says: |mean, sd| {
                format!(
                    "the mean lead {mean:.1} +- {sd:.1} ppm is indistinguishable from a scale gain of {mean:.1} ppm with every lead reduced by it"
                )
            },
        }),
    }],
    simulation: SIMULATION,
    common_part: None,
    check: Some(CheckRole {
        name: "scale gain",
        parameters: &["scale_gain_ppm"],
        when: CheckWhen::Always,
        columns: CheckColumns::Readings(entries),
    }),
};

fn entries(up: &UpJoints) -> Entries {
    vec![(0, Basis::Reading(2), scale_gain_error_mm(1.0, up.q4_mm))]
}

/// Reading error of a scale with gain error `ppm` at extension `q4_mm`, mm.
pub fn scale_gain_error_mm(ppm: f64, q4_mm: f64) -> f64 {
    ppm * 1e-6 * q4_mm
}

/// The simulator's `scale-gain`: gain error of the linear scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaleGain {
    /// Gain error, ppm.
    pub ppm: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "scale-gain",
    cause: "scale-gain",
        keys: &[EffectKey::new("ppm", "ppm", "gain error of the linear scale")],
    parse: parse_input::<ScaleGain>,
    typical: || Box::new(ScaleGain { ppm: 50.0 }),
};

impl Simulate for ScaleGain {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn reading_error(&self, _s: &PoseState, up: &UpJoints, r: &mut [f64; 3]) {
        r[2] += scale_gain_error_mm(self.ppm, up.q4_mm);
    }
}
