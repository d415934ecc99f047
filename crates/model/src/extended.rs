//! The machine a controller should run after a diagnosis: the exact
//! geometry (joints, leg offsets and the class-2 U-joint and guide-rail twist
//! errors of the description) plus the static leg effects the diagnosis
//! named (ball-screw lead, gravity compliance), with IK and FK that apply
//! them.
//!
//! For leg command `q_i` the actual leg length is `q_i + dq_i + r_i q_i`
//! (mm), where `r_i` sums the rates of every effect the registry deploys
//! into the machine's leg effects
//! ([`crate::effects::static_leg_extra_per_mm`]): today
//! `lead_i 1e-6 + c F_i 1e-9`, `lead_i` in ppm, `c` the compliance of a 1 m
//! leg in um/kN, `F_i` the gravity tension of leg `i` in N at the pose
//! reached; a leg with a compensation table
//! ([`tricept_kinematics::description::LegTableDescription`]: a pitch
//! error, a curved or worn screw) adds `T_i(q_i)`, read by linear
//! interpolation.
//! The diagnosis and the plant simulator evaluate `F` on the nominal machine
//! at the commands; here it is evaluated on this machine at the pose it
//! reaches. The two differ by the geometric errors (tenths of a mm), which
//! change a 10 um deflection by about 0.01 um.
//!
//! The dynamic effects (backlash, thermal expansion) depend on the approach
//! direction and the temperature, which a controller knows and tricept does
//! not; they are exported as controller parameters
//! ([`tricept_kinematics::description::ControllerDescription`]) and not
//! applied here.

use nalgebra::Vector3;
use tricept_kinematics::{
    KinematicsError, Machine, fk::FkSolution, head::HeadBranch, head::ToolIkSolution,
    machine::IkSolution, up_limb::UpJoints,
};

#[cfg(test)]
use crate::effects::{compliance_extra_mm, gravity_leg_tension_n, leg_lead_extra_mm};
use crate::effects::{pose_free_leg_extra_per_mm, static_leg_extra_per_mm};

/// A [`Machine`] whose kinematics include its static leg effects
/// ([`Machine::leg_effects`]). With no effects it is the machine itself,
/// to the last bit.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use nalgebra::Vector3;
use tricept_kinematics::Machine;
use tricept_model::ExtendedMachine;
let mut m = Machine::paper();
m.leg_effects.lead_ppm = [100.0, 0.0, 0.0];
m.leg_effects.compliance_um_per_kn_at_1m = 30.0;
let x = ExtendedMachine::new(m.clone());
let r = Vector3::new(50.0, -20.0, 750.0);
let ik = x.inverse(&r).unwrap();
// A leg that grows 100 ppm with its command needs a shorter command.
assert!(ik.legs_mm[0] < m.inverse(&r).unwrap().legs_mm[0] - 0.07);
// FK undoes IK with the effects applied.
assert!((x.forward(&ik.legs_mm).unwrap().position_mm - r).norm() < 1e-8);
```
"#
)]
#[derive(Debug, Clone, PartialEq)]
pub struct ExtendedMachine {
    machine: Machine,
}

impl ExtendedMachine {
    /// The machine with the leg effects it carries.
    pub fn new(machine: Machine) -> ExtendedMachine {
        ExtendedMachine { machine }
    }

    /// The geometric machine (its own IK and FK ignore the leg effects).
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// Whether any static leg effect is present.
    pub fn has_leg_effects(&self) -> bool {
        !self.machine.leg_effects.is_zero()
    }

    fn extra_per_mm(&self, up: &UpJoints) -> [f64; 3] {
        static_leg_extra_per_mm(&self.machine, up)
    }

    /// Extra leg lengths (mm) of the static effects for `commands_mm` with
    /// the UP limb at `up` (the rates' part and the compensation tables').
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::{Machine, up_limb::UpJoints};
use tricept_model::ExtendedMachine;
let mut m = Machine::paper();
m.leg_effects.lead_ppm = [50.0, -30.0, 0.0];
let up = m.forward(&[800.0; 3]).unwrap().up;
let extra = ExtendedMachine::new(m).leg_extra_mm(&[800.0; 3], &up);
assert!((extra[0] - 0.04).abs() < 1e-12 && (extra[1] + 0.024).abs() < 1e-12);
```
"#
    )]
    pub fn leg_extra_mm(&self, commands_mm: &[f64; 3], up: &UpJoints) -> [f64; 3] {
        let rate = self.extra_per_mm(up);
        let table = self.machine.leg_effects.table_extra_mm(commands_mm);
        std::array::from_fn(|i| rate[i] * commands_mm[i] + table[i])
    }

    /// Commands that put the legs at the geometric commands `geometric_mm`
    /// (the plain machine's IK) with the UP limb at `up`: the rates are
    /// linear in the command at a fixed pose, so without tables this is
    /// exact; a table's extra length is a function of the command, solved
    /// by fixed-point passes `q = (g - T(q)) / (1 + r)` (a contraction by
    /// the table's slope, at most 20 % by validation) to 1e-12 mm.
    fn commands_for(
        &self,
        geometric_mm: &[f64; 3],
        up: &UpJoints,
    ) -> Result<[f64; 3], KinematicsError> {
        let rate = self.extra_per_mm(up);
        let mut q: [f64; 3] = std::array::from_fn(|i| geometric_mm[i] / (1.0 + rate[i]));
        let effects = &self.machine.leg_effects;
        if effects.tables.is_empty() {
            return Ok(q);
        }
        let mut change = f64::INFINITY;
        for _ in 0..MAX_TABLE_PASSES {
            let table = effects.table_extra_mm(&q);
            let next: [f64; 3] =
                std::array::from_fn(|i| (geometric_mm[i] - table[i]) / (1.0 + rate[i]));
            change = (0..3).map(|i| (next[i] - q[i]).abs()).fold(0.0, f64::max);
            q = next;
            if change < TABLE_TOLERANCE_MM {
                return Ok(q);
            }
        }
        Err(KinematicsError::NotConverged {
            solver: "the leg commands through the compensation tables",
            iterations: MAX_TABLE_PASSES as u32,
            residual: change,
        })
    }

    /// Inverse kinematics with the leg effects: platform point `r` (mm) to
    /// leg commands and UP joints.
    pub fn inverse(&self, r: &Vector3<f64>) -> Result<IkSolution, KinematicsError> {
        let ik = self.machine.inverse(r)?;
        if !self.has_leg_effects() {
            return Ok(ik);
        }
        let legs_mm = self.commands_for(&ik.legs_mm, &ik.up)?;
        self.machine.check_commands(&legs_mm)?;
        Ok(IkSolution { legs_mm, up: ik.up })
    }

    /// 5-DOF tool-pose IK with the leg effects (see
    /// [`Machine::tool_inverse`]).
    pub fn tool_inverse(
        &self,
        tip_mm: &Vector3<f64>,
        axis: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<ToolIkSolution, KinematicsError> {
        let mut sol = self.machine.tool_inverse(tip_mm, axis, branch)?;
        if self.has_leg_effects() {
            sol.legs_mm = self.commands_for(&sol.legs_mm, &sol.up)?;
            self.machine.check_commands(&sol.legs_mm)?;
        }
        Ok(sol)
    }

    /// Forward kinematics with the leg effects: leg commands (mm) to the UP
    /// joints and O'. The tension depends on the pose and the pose on the
    /// tension: fixed-point passes, each an FK from the previous pose, until
    /// the effects' leg lengths change by less than 1e-9 mm.
    pub fn forward(&self, commands_mm: &[f64; 3]) -> Result<FkSolution, KinematicsError> {
        if !self.has_leg_effects() {
            return self.machine.forward(commands_mm);
        }
        // Start from the part of the effects that needs no pose.
        let first = self.machine.forward(&self.with_pose_free(commands_mm))?;
        self.refine(commands_mm, first)
    }

    /// [`ExtendedMachine::forward`] from a nearby UP configuration.
    pub fn forward_from(
        &self,
        commands_mm: &[f64; 3],
        seed: &UpJoints,
    ) -> Result<FkSolution, KinematicsError> {
        if !self.has_leg_effects() {
            return self.machine.forward_from(commands_mm, seed);
        }
        let first = self
            .machine
            .forward_from(&self.with_pose_free(commands_mm), seed)?;
        self.refine(commands_mm, first)
    }

    /// The commands plus the part of the effects that does not depend on
    /// the pose (the lead errors and the compensation tables).
    fn with_pose_free(&self, commands_mm: &[f64; 3]) -> [f64; 3] {
        let rate = pose_free_leg_extra_per_mm(&self.machine);
        let table = self.machine.leg_effects.table_extra_mm(commands_mm);
        std::array::from_fn(|i| commands_mm[i] + rate[i] * commands_mm[i] + table[i])
    }

    fn refine(
        &self,
        commands_mm: &[f64; 3],
        first: FkSolution,
    ) -> Result<FkSolution, KinematicsError> {
        let mut sol = first;
        let mut iterations = sol.iterations;
        let start = self.with_pose_free(commands_mm);
        let mut extra: [f64; 3] = std::array::from_fn(|i| start[i] - commands_mm[i]);
        for _ in 0..MAX_PASSES {
            let next = self.leg_extra_mm(commands_mm, &sol.up);
            let change = (0..3)
                .map(|i| (next[i] - extra[i]).abs())
                .fold(0.0, f64::max);
            if change < PASS_TOLERANCE_MM {
                break;
            }
            extra = next;
            let legs: [f64; 3] = std::array::from_fn(|i| commands_mm[i] + extra[i]);
            sol = self.machine.forward_from(&legs, &sol.up)?;
            iterations += sol.iterations;
        }
        sol.iterations = iterations;
        Ok(sol)
    }
}

/// Fixed-point passes of [`ExtendedMachine::forward`]: the leg effects
/// depend on the pose only through the gravity tension, a contraction by
/// a factor of about 1e-3, so three or four passes reach the tolerance.
const MAX_PASSES: usize = 8;

/// Change of the effects' leg lengths (mm) at which the passes stop: a
/// picometre, far below anything a leg or a sensor can tell.
const PASS_TOLERANCE_MM: f64 = 1e-9;

/// Fixed-point passes of the commands through the compensation tables: a
/// contraction by the table's slope (a pitch error's is below 0.01, the
/// steepest table validation allows 0.2), so 1e-12 mm is reached in 4 to
/// about 15 passes.
const MAX_TABLE_PASSES: usize = 40;

/// Change of the commands (mm) at which the table passes stop.
const TABLE_TOLERANCE_MM: f64 = 1e-12;

/// A batch of points solved with the leg effects applied
/// (`tricept_kinematics::batch`).
impl tricept_kinematics::batch::PointKinematics for ExtendedMachine {
    fn inverse(&self, r: &Vector3<f64>) -> Result<IkSolution, KinematicsError> {
        ExtendedMachine::inverse(self, r)
    }
    fn forward(&self, commands_mm: &[f64; 3]) -> Result<FkSolution, KinematicsError> {
        ExtendedMachine::forward(self, commands_mm)
    }
    fn tool_inverse(
        &self,
        tip_mm: &Vector3<f64>,
        axis: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<ToolIkSolution, KinematicsError> {
        ExtendedMachine::tool_inverse(self, tip_mm, axis, branch)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_effects() -> Machine {
        let mut m = Machine::paper();
        m.leg_effects.lead_ppm = [80.0, -50.0, 20.0];
        m.leg_effects.compliance_um_per_kn_at_1m = 30.0;
        m
    }

    #[test]
    fn without_effects_it_is_the_machine_bit_for_bit() {
        let m = Machine::paper();
        let x = ExtendedMachine::new(m.clone());
        for r in m.workspace.random_poses(50, 3) {
            let a = x.inverse(&r).unwrap();
            let b = m.inverse(&r).unwrap();
            assert_eq!(a, b);
            assert_eq!(
                x.forward(&a.legs_mm).unwrap(),
                m.forward(&b.legs_mm).unwrap()
            );
        }
    }

    #[test]
    fn fk_undoes_ik_and_the_legs_carry_the_physics() {
        let m = with_effects();
        let x = ExtendedMachine::new(m.clone());
        for r in m.workspace.random_poses(200, 5) {
            let ik = x.inverse(&r).unwrap();
            let fk = x.forward(&ik.legs_mm).unwrap();
            // The passes stop at 1e-9 mm of leg length.
            assert!(
                (fk.position_mm - r).norm() < 1e-8,
                "{r} {}",
                (fk.position_mm - r).norm()
            );
            // The actual legs, from the physics functions directly: the
            // commands plus lead plus compliance equal the geometric IK.
            let f = gravity_leg_tension_n(&m, &ik.up);
            let geometric = m.inverse(&r).unwrap().legs_mm;
            for i in 0..3 {
                let q = ik.legs_mm[i];
                let actual = q
                    + leg_lead_extra_mm(m.leg_effects.lead_ppm[i], q)
                    + compliance_extra_mm(1000.0 / 30.0, f[i], q);
                assert!((actual - geometric[i]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn a_compensation_table_is_undone_by_ik_and_applied_by_fk() {
        use tricept_kinematics::description::LegTableDescription;
        let mut m = with_effects();
        // A 4 um pitch error of period 10 mm on leg 2, tabulated every
        // 0.5 mm over the whole stroke, 450-1250 mm.
        let pitch = |q: f64| 4.0 * (std::f64::consts::TAU * q / 10.0).sin();
        let values: Vec<f64> = (0..=1600).map(|k| pitch(450.0 + 0.5 * k as f64)).collect();
        m.leg_effects.tables = vec![LegTableDescription::new(2, 450.0, 0.5, values)];
        let x = ExtendedMachine::new(m.clone());
        for r in m.workspace.random_poses(100, 7) {
            let ik = x.inverse(&r).unwrap();
            let fk = x.forward(&ik.legs_mm).unwrap();
            assert!((fk.position_mm - r).norm() < 1e-8);
            // The actual leg 2: its command plus lead, compliance and the
            // table's (linearly interpolated) pitch error is the geometry's.
            let f = gravity_leg_tension_n(&m, &ik.up);
            let q = ik.legs_mm[1];
            let geometric = m.inverse(&r).unwrap().legs_mm[1];
            let actual = q
                + leg_lead_extra_mm(m.leg_effects.lead_ppm[1], q)
                + compliance_extra_mm(1000.0 / 30.0, f[1], q)
                + m.leg_effects.tables[0].extra_mm(q);
            assert!((actual - geometric).abs() < 1e-9);
            // The table is the pitch error to its interpolation error
            // (h^2 / 8 A (2 pi / P)^2 = 0.05 um at 20 points per period).
            assert!((m.leg_effects.tables[0].extra_mm(q) * 1e3 - pitch(q)).abs() < 0.05);
        }
    }

    #[test]
    fn tool_ik_applies_the_same_correction() {
        let m = with_effects();
        let x = ExtendedMachine::new(m.clone());
        let tip = Vector3::new(100.0, 50.0, 1090.0);
        let axis = Vector3::new(0.1, 0.0, 1.0);
        let t = x.tool_inverse(&tip, &axis, HeadBranch::default()).unwrap();
        let fk = x.forward(&t.legs_mm).unwrap();
        assert!((fk.position_mm - t.platform_mm).norm() < 1e-8);
    }
}
