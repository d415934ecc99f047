//! `encoder-eccentricity`: a once-per-revolution error `A sin(angle + psi)`
//! of each U-joint encoder, fitted as its sine and cosine parts (arcsec).

use tricept_kinematics::up_limb::UpJoints;
use tricept_kinematics::units::RAD_PER_ARCSEC;

use super::spec::{
    Basis, Deployment, EffectSpec, Entries, Judged, Kind, KnownAlias, Magnitude, Measure, Needs,
    Parameter, PlausibleRange, PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, PoseState, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

const ARCSEC: Parameter = Parameter {
    name: "",
    unit: "arcsec",
    typical: 5.0,
};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "encoder-eccentricity",
    physics: "once-per-revolution error `A sin(angle + psi)` of each encoder",
    quoted_in: "arcsec",
    parameters: &[
        Parameter {
            name: "phi_sin_arcsec",
            ..ARCSEC
        },
        Parameter {
            name: "phi_cos_arcsec",
            ..ARCSEC
        },
        Parameter {
            name: "theta_sin_arcsec",
            ..ARCSEC
        },
        Parameter {
            name: "theta_cos_arcsec",
            ..ARCSEC
        },
    ],
    kind: Kind::Reading(entries),
    needs: Needs::Nothing,
    deployment: Deployment::Sensor,
    fused: false,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "amplitude_arcsec",
            min: 0.0,
            max: 60.0,
            unit: "arcsec",
            why: "10 um of eccentricity on a 35-50 mm graduation radius",
            if_negated: "",
        },
        of: &[
            (Measure::Amplitude(0, 1), "eccentricity of the phi encoder"),
            (Measure::Amplitude(2, 3), "eccentricity of the theta encoder"),
        ],
    }],
    description: "once-per-revolution errors of the encoders",
    plot: PlotAxes {
        x: XAxis::Angle(0),
        y: YAxis::Reading(0),
    },
    realistic: |_| {
        vec![
            Magnitude {
                values: vec![5.0, 0.0, 5.0, 0.0],
                label: "5 arcsec, sine phase",
            },
            Magnitude {
                values: vec![0.0, 5.0, 0.0, 5.0],
                label: "5 arcsec, cosine phase",
            },
        ]
    },
    aliases: &[KnownAlias {
        with: "encoder-gain",
        why: "over the encoders' small angles (|angle| < 0.6 rad) a gain error and the sine part of an eccentricity are nearly the same curve",
        separate_by: "an external angle reference (autocollimator or inclinometer) at about +-30 deg of the U joint",
        structural: None,
    }],
    simulation: SIMULATION,
    common_part: None,
    check: None,
};

fn entries(up: &UpJoints) -> Entries {
    let a = RAD_PER_ARCSEC;
    let (sp, cp) = up.phi_rad.sin_cos();
    let (st, ct) = up.theta_rad.sin_cos();
    vec![
        (0, Basis::Reading(0), a * sp),
        (1, Basis::Reading(0), a * cp),
        (2, Basis::Reading(1), a * st),
        (3, Basis::Reading(1), a * ct),
    ]
}

/// Once-per-revolution encoder error at `angle_rad`, rad.
pub fn eccentricity_error_rad(amplitude_arcsec: f64, phase_deg: f64, angle_rad: f64) -> f64 {
    amplitude_arcsec * RAD_PER_ARCSEC * (angle_rad + phase_deg.to_radians()).sin()
}

/// The simulator's once-per-revolution encoder errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderEccentricity {
    /// Amplitude on the phi encoder, arcsec.
    pub phi_arcsec: f64,
    /// Phase on the phi encoder, deg.
    pub phi_phase_deg: f64,
    /// Amplitude on the theta encoder, arcsec.
    pub theta_arcsec: f64,
    /// Phase on the theta encoder, deg.
    pub theta_phase_deg: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "encoder-eccentricity",
    cause: "encoder-eccentricity",
        keys: &[
        EffectKey::new(
            "phi_arcsec",
            "arcsec",
            "once-per-revolution amplitude on the phi encoder",
        ),
        EffectKey::new("phi_phase_deg", "deg", "its phase"),
        EffectKey::new("theta_arcsec", "arcsec", "amplitude on the theta encoder"),
        EffectKey::new("theta_phase_deg", "deg", "its phase"),
    ],
    parse: parse_input::<EncoderEccentricity>,
    typical: || {
        Box::new(EncoderEccentricity {
            phi_arcsec: 10.0,
            phi_phase_deg: 30.0,
            theta_arcsec: 8.0,
            theta_phase_deg: -60.0,
        })
    },
};

impl Simulate for EncoderEccentricity {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn reading_error(&self, _s: &PoseState, up: &UpJoints, r: &mut [f64; 3]) {
        r[0] += eccentricity_error_rad(self.phi_arcsec, self.phi_phase_deg, up.phi_rad);
        r[1] += eccentricity_error_rad(self.theta_arcsec, self.theta_phase_deg, up.theta_rad);
    }
}
