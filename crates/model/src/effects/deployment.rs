//! Deployment through the registry: a fitted effect parameter put where it
//! belongs in a calibrated machine ([`EffectName::deploy`]), and the static
//! leg effects a machine carries, read back for its kinematics
//! ([`static_leg_extra_per_mm`], [`pose_free_leg_extra_per_mm`]).

use tricept_kinematics::description::ControllerDescription;
use tricept_kinematics::{Machine, up_limb::UpJoints};

use super::{Deployment, EffectName};

impl EffectName {
    /// Puts the effect's fitted parameter `index` (in its unit) where it
    /// goes in a calibrated machine ([`super::EffectSpec::deployment`]):
    /// the machine's leg effects, the controller parameters (created on
    /// first use), or nowhere for the effects the machine's UP limb
    /// already carries and the sensor-side ones. `false` when the effect
    /// is not part of a machine file (outliers) or has no such parameter.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::Machine;
use tricept_model::effects::EffectName;
let mut m = Machine::paper();
let mut controller = None;
assert!(EffectName::LegLead.deploy(1, 40.0, &mut m, &mut controller));
assert!(EffectName::Backlash.deploy(0, 6.0, &mut m, &mut controller));
assert_eq!(m.leg_effects.lead_ppm, [0.0, 40.0, 0.0]);
assert_eq!(controller.unwrap().backlash_um, [6.0, 0.0, 0.0]);
assert!(!EffectName::Outliers.deploy(0, 1.0, &mut m, &mut None));
```
"#
    )]
    pub fn deploy(
        self,
        index: usize,
        value: f64,
        machine: &mut Machine,
        controller: &mut Option<ControllerDescription>,
    ) -> bool {
        if index >= self.parameter_count() {
            return false;
        }
        match self.spec().deployment {
            Deployment::LegEffects(d) => (d.set)(&mut machine.leg_effects, index, value),
            Deployment::Controller(set) => set(
                controller.get_or_insert_with(ControllerDescription::default),
                index,
                value,
            ),
            Deployment::UpLimb | Deployment::Sensor => {}
            Deployment::SetAside | Deployment::LegTable | Deployment::Recorded => return false,
        }
        true
    }
}

/// Extra length (mm) per mm of command of each leg of `machine` from its
/// static leg effects ([`Machine::leg_effects`]: every effect the registry
/// deploys there) with the UP limb at `up`: `lead_i 1e-6 + c F_i 1e-9`,
/// the lead error plus the compliance `c` (um/kN at 1 m) under the gravity
/// tension `F_i` (N). Zero without effects.
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// let up = m.forward(&[800.0; 3]).unwrap().up;
/// assert_eq!(tricept_model::effects::static_leg_extra_per_mm(&m, &up), [0.0; 3]);
/// m.leg_effects.lead_ppm = [50.0, 0.0, 0.0];
/// assert!((tricept_model::effects::static_leg_extra_per_mm(&m, &up)[0] - 5e-5).abs() < 1e-18);
/// ```
pub fn static_leg_extra_per_mm(machine: &Machine, up: &UpJoints) -> [f64; 3] {
    rates(machine, Some(up))
}

/// The part of [`static_leg_extra_per_mm`] that needs no pose (the lead:
/// the compliance depends on the pose through the gravity tension).
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let mut m = Machine::paper();
/// m.leg_effects.lead_ppm = [50.0, 0.0, 0.0];
/// m.leg_effects.compliance_um_per_kn_at_1m = 30.0;
/// assert_eq!(tricept_model::effects::pose_free_leg_extra_per_mm(&m)[0], 50.0 * 1e-6);
/// ```
pub fn pose_free_leg_extra_per_mm(machine: &Machine) -> [f64; 3] {
    rates(machine, None)
}

/// The sum of the registry's leg-effect rates, in registry order.
fn rates(machine: &Machine, up: Option<&UpJoints>) -> [f64; 3] {
    let mut total: Option<[f64; 3]> = None;
    for e in EffectName::ALL {
        let Deployment::LegEffects(d) = e.spec().deployment else {
            continue;
        };
        if let Some(rate) = (d.rate)(machine, up) {
            total = Some(match total {
                None => rate,
                Some(t) => std::array::from_fn(|i| t[i] + rate[i]),
            });
        }
    }
    total.unwrap_or([0.0; 3])
}
