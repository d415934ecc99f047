//! `compliance`: the legs stretch under the weight of platform and head,
//! the axial tension `F = J1^-T Q` over a stiffness that scales as
//! 1/length (fitted as the compliance of a 1 m leg, um/kN).

use nalgebra::{Matrix3, Vector3};
use tricept_kinematics::description::LegEffectsDescription;
use tricept_kinematics::{KinematicsError, Machine, up_limb::UpJoints};

use super::spec::{
    Basis, Deployment, EffectSpec, Entries, Judged, Kind, LegContext, LegDeployment, Magnitude,
    Measure, Needs, Parameter, PlausibleRange, PlotAxes, XAxis, YAxis,
};
use super::simulation::{EffectKey, PoseState, Simulate, Simulation, parse_input};
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "compliance",
    physics: "the legs stretch under the weight of platform and head (`F = J1^-T Q`, stiffness ~ 1/length)",
    quoted_in: "N/um at 1 m",
    parameters: &[Parameter {
        name: "compliance_um_per_kn_at_1m",
        unit: "um/kN at 1 m",
        typical: 30.0,
    }],
    kind: Kind::Leg(entries),
    needs: Needs::Nothing,
    deployment: Deployment::LegEffects(LegDeployment { set, rate }),
    fused: true,
    plausible: &[Judged {
        range: PlausibleRange {
            quantity: "compliance_um_per_kn_at_1m",
            min: 0.0,
            max: 200.0,
            unit: "um/kN at 1 m",
            why: "tension stretches the legs; 5 N/um is a very soft leg",
            if_negated: "",
        },
        of: &[(Measure::Parameter(0), "")],
    }],
    description: "the legs stretch under the platform's weight",
    plot: PlotAxes {
        x: XAxis::Tilt,
        y: YAxis::MeanLegResidual,
    },
    realistic: |machine| {
        vec![Magnitude {
            values: vec![1000.0 / stiffness_for_platform_deflection(machine, 10.0)],
            label: "10 um at the platform",
        }]
    },
    aliases: &[],
    simulation: SIMULATION,
    common_part: None,
    check: None,
};

/// The tension on the nominal machine at the commands; compliance `c`
/// (um/kN at 1 m) = 1000 / stiffness (N/um at 1 m).
fn entries(at: &LegContext<'_>) -> Result<Entries, KinematicsError> {
    let q = at.commands_mm;
    let up = at.nominal.forward(&q)?.up;
    let f = gravity_leg_tension_n(at.nominal, &up);
    Ok((0..3)
        .map(|i| (0, Basis::Leg(i), compliance_extra_mm(1000.0, f[i], q[i])))
        .collect())
}

fn set(e: &mut LegEffectsDescription, _index: usize, value: f64) {
    e.compliance_um_per_kn_at_1m = value;
}

/// The tension needs the pose.
fn rate(machine: &Machine, up: Option<&UpJoints>) -> Option<[f64; 3]> {
    let c = machine.leg_effects.compliance_um_per_kn_at_1m;
    let up = up.filter(|_| c != 0.0)?;
    let tension = gravity_leg_tension_n(machine, up);
    Some(std::array::from_fn(|i| {
        c * compliance_extra_mm(1000.0, tension[i], 1.0)
    }))
}

/// Standard gravity, m/s^2.
pub const GRAVITY_M_PER_S2: f64 = 9.80665;

/// Axial tension in each leg (N) holding platform and head against gravity
/// with the UP limb at `up`: `F = J1^-T Q`, where `Q` is the generalised
/// gravity force on `(phi, theta, q4)`. The UP limb's passive prismatic
/// joint carries no axial load, so the legs carry all of it.
pub fn gravity_leg_tension_n(machine: &Machine, up: &UpJoints) -> [f64; 3] {
    let g = machine.legs_at(up);
    let loads = &machine.loads;
    let d = Vector3::from(loads.gravity_direction).normalize() * GRAVITY_M_PER_S2;
    let limb = &g.limb;
    let head_com = limb.position_mm + limb.rotation * Vector3::from(loads.head_com_mm);
    let q = limb.point_jacobian(&limb.position_mm).transpose() * (loads.platform_mass_kg * d)
        + limb.point_jacobian(&head_com).transpose() * (loads.head_mass_kg * d);
    let j1t: Matrix3<f64> = g.j1().transpose();
    match j1t.try_inverse() {
        Some(inv) => (inv * q).into(),
        None => [0.0; 3],
    }
}

/// Extra leg length (mm) of a leg of length `command_mm` under `tension_n`
/// with stiffness `stiffness_n_per_um_at_1m` at 1 m.
pub fn compliance_extra_mm(stiffness_n_per_um_at_1m: f64, tension_n: f64, command_mm: f64) -> f64 {
    let stiffness = stiffness_n_per_um_at_1m * 1000.0 / command_mm;
    tension_n / stiffness * 1e-3
}

/// The leg stiffness (N/um at 1 m) for which gravity moves the platform
/// point by `deflection_um` at the centre of the workspace's middle plane
/// (the magnitude in which the `compliance` effect is quoted).
pub fn stiffness_for_platform_deflection(machine: &Machine, deflection_um: f64) -> f64 {
    let r = Vector3::new(0.0, 0.0, machine.workspace.mid_plane_z_mm());
    let Ok(ik) = machine.inverse(&r) else {
        return f64::NAN;
    };
    let f = gravity_leg_tension_n(machine, &ik.up);
    // Deflection at unit stiffness (1 N/um at 1 m), through the exact FK.
    let legs: [f64; 3] =
        std::array::from_fn(|i| ik.legs_mm[i] + compliance_extra_mm(1.0, f[i], ik.legs_mm[i]));
    match machine.forward_from(&legs, &ik.up) {
        Ok(fk) => (fk.position_mm - r).norm() * 1e3 / deflection_um,
        Err(_) => f64::NAN,
    }
}

/// The simulator's axial leg deflection under gravity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Compliance {
    /// Axial stiffness of a leg of 1 m, N/um (scales as 1/length).
    pub stiffness_n_per_um_at_1m: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "compliance",
    cause: "compliance",
        keys: &[EffectKey::positive(
        "stiffness_n_per_um_at_1m",
        "N/um",
        "axial stiffness of a leg 1 m long (scales as 1/length); loads from the machine file's `loads`",
    )],
    parse: parse_input::<Compliance>,
    typical: || {
        Box::new(Compliance {
            stiffness_n_per_um_at_1m: 33.6,
        })
    },
};

impl Simulate for Compliance {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    fn extra_leg_length(&self, nominal: &Machine, s: &PoseState, legs_mm: &mut [f64; 3]) {
        let f = gravity_leg_tension_n(nominal, &s.nominal_up);
        for i in 0..3 {
            legs_mm[i] +=
                compliance_extra_mm(self.stiffness_n_per_um_at_1m, f[i], s.commands_mm[i]);
        }
    }
}
