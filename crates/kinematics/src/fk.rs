//! Forward kinematics of the parallel module: leg commands to the UP limb's
//! joint values, the platform point and orientation.
//!
//! The unknowns are the UP joints `x = (phi, theta, q4)`; the equations are
//! the three leg closures `f_i(x) = |A_i(x) - B_i| - (q_i + dq_i) = 0`. Their
//! Jacobian is the paper's `J1` (see [`crate::machine::LegGeometry::j1`]), so Newton's
//! method costs one 3x3 solve per iteration. The iteration is safeguarded by
//! a backtracking line search on `|f|^2`; it starts from a closed-form seed
//! (three-sphere trilateration with the platform level; if that fails, two
//! rounds extrapolated) unless the caller passes one.
//!
//! Every solution carries the condition number of `J1` made unit-free by
//! scaling its angle columns by `1/q4`, and the solver refuses (with an
//! error, never a wrong number) configurations where that number exceeds
//! [`crate::error::SINGULARITY_CONDITION_LIMIT`].

use nalgebra::{Matrix3, Vector3};

use crate::error::KinematicsError;
use crate::error::SINGULARITY_CONDITION_LIMIT;
use crate::machine::{LegGeometry, Machine};
use crate::up_limb::UpJoints;

/// Result of the forward kinematics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FkSolution {
    /// UP limb joint values.
    pub up: UpJoints,
    /// Platform point O' in the base frame, mm.
    pub position_mm: Vector3<f64>,
    /// Platform orientation `R`.
    pub rotation: Matrix3<f64>,
    /// Condition number of `J1 diag(1/q4, 1/q4, 1)` in the Frobenius norm
    /// (an upper bound on the 2-norm condition within a factor 3). It
    /// measures how much the leg-length errors are amplified into the UP
    /// joints; around 3-20 in the Table 1 workspace.
    pub condition: f64,
    /// Newton iterations used.
    pub iterations: u32,
    /// Euclidean norm of the leg-closure residual at the solution, mm.
    pub residual_mm: f64,
}

/// The cold-start seed of [`Machine::forward_seeded`].
///
/// Both place O' by three-sphere trilateration of the leg lengths; they
/// differ in what they assume about the platform's orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FkSeed {
    /// The platform level: cheap, about 20 times farther from the solution
    /// than `Extrapolated`, and Newton needs 3-4 iterations from it. If
    /// Newton fails from it (it can lead to the other assembly branch near
    /// and beyond the workspace's edges), FK is retried from
    /// `Extrapolated`. The default (the two take the same time).
    #[default]
    Level,
    /// A second trilateration at the tilt the first one implies, and the
    /// two extrapolated (see `extrapolated_seed` in `fk.rs`): Newton needs
    /// about 2 iterations, but the longer seed costs as much as that saves.
    Extrapolated,
}

const MAX_ITERATIONS: u32 = 60;
/// A step this small (mm) ends the line search whatever the merit does.
const STEP_TOLERANCE_MM: f64 = 1e-10;
/// When the predicted next Newton step is below this (mm), it is applied
/// without a new Jacobian and the iteration ends.
const FINAL_STEP_MM: f64 = 1e-6;
/// A converged solution must close the legs to this, mm.
const RESIDUAL_TOLERANCE_MM: f64 = 1e-8;

impl Machine {
    /// Forward kinematics from leg commands (mm), starting from a closed-form
    /// seed ([`FkSeed::Level`]).
    pub fn forward(&self, legs_mm: &[f64; 3]) -> Result<FkSolution, KinematicsError> {
        self.forward_seeded(legs_mm, FkSeed::Level)
    }

    /// Forward kinematics from leg commands (mm) with the cold-start seed
    /// chosen by `seed`. Both strategies give the same solutions; they
    /// differ in cost (see [`FkSeed`]).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::{fk::FkSeed, Machine};
let m = Machine::paper();
let legs = m.inverse(&nalgebra::Vector3::new(300.0, -200.0, 700.0)).unwrap().legs_mm;
let a = m.forward_seeded(&legs, FkSeed::Level).unwrap();
let b = m.forward_seeded(&legs, FkSeed::Extrapolated).unwrap();
assert!((a.position_mm - b.position_mm).norm() < 1e-9);
assert!(b.iterations <= a.iterations);
```
"#
    )]
    pub fn forward_seeded(
        &self,
        legs_mm: &[f64; 3],
        seed: FkSeed,
    ) -> Result<FkSolution, KinematicsError> {
        self.check_commands(legs_mm)?;
        let lengths = self.actual_lengths(legs_mm);
        let Some(r1) = self.level_trilateration(&lengths) else {
            let seed = self.level_joints();
            return self.newton(legs_mm, &lengths, seed);
        };
        let extrapolated = || {
            let seed = self.extrapolated_seed(&lengths, &r1);
            self.newton(legs_mm, &lengths, seed)
        };
        match seed {
            FkSeed::Level => {
                let seed = self.up_limb.inverse(&r1).unwrap_or(self.level_joints());
                self.newton(legs_mm, &lengths, seed)
                    .or_else(|_| extrapolated())
            }
            FkSeed::Extrapolated => extrapolated(),
        }
    }

    /// Forward kinematics from leg commands (mm), starting at `seed` (useful
    /// when a nearby solution is known, e.g. the nominal configuration when
    /// solving for an actual machine).
    pub fn forward_from(
        &self,
        legs_mm: &[f64; 3],
        seed: &UpJoints,
    ) -> Result<FkSolution, KinematicsError> {
        self.check_commands(legs_mm)?;
        for (what, v) in [
            ("seed phi", seed.phi_rad),
            ("seed theta", seed.theta_rad),
            ("seed q4", seed.q4_mm),
        ] {
            if !v.is_finite() {
                return Err(KinematicsError::NotFinite { what, value: v });
            }
        }
        let lengths = self.actual_lengths(legs_mm);
        self.newton(legs_mm, &lengths, *seed)
    }

    fn actual_lengths(&self, legs_mm: &[f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| legs_mm[i] + self.leg_offsets_mm[i])
    }

    /// The UP joints of the level platform at mid-height: the seed of last
    /// resort.
    fn level_joints(&self) -> UpJoints {
        UpJoints {
            phi_rad: 0.0,
            theta_rad: 0.0,
            q4_mm: 0.5 * (self.workspace.z_min_mm + self.workspace.z_max_mm),
        }
    }

    /// O' placed by trilateration with the platform joints at the
    /// orientation `rotation`.
    fn trilaterate_at(&self, rotation: &Matrix3<f64>, lengths: &[f64; 3]) -> Option<Vector3<f64>> {
        let centres: [Vector3<f64>; 3] =
            std::array::from_fn(|i| self.base_joints_mm[i] - rotation * self.platform_joints_mm[i]);
        trilaterate(&centres, lengths)
    }

    /// O' placed by trilateration with the platform level.
    fn level_trilateration(&self, lengths: &[f64; 3]) -> Option<Vector3<f64>> {
        self.trilaterate_at(&Matrix3::identity(), lengths)
    }

    /// A closer seed: trilateration again with the platform at the
    /// orientation the UP limb gives the level-platform point `r1`, and the
    /// two rounds extrapolated.
    ///
    /// The rounds form a fixed-point iteration on the limb direction
    /// `u = r / |r|`, started at the level platform (`u_0 = e_z`). It
    /// converges slowly and with alternating sign (on Table 1 its slope is
    /// about -0.6: the level-platform point overshoots the tilt by 60 %). The
    /// slope `s` is estimated from the two rounds' changes of `u` and the
    /// limit taken as `x_2 + s / (1 - s) (x_2 - x_1)` (Aitken's
    /// extrapolation) for the direction and the length `|r|`, which leaves
    /// an error of second order in the tilt: 11 mm on average over the
    /// workspace instead of 219 mm (`scaled_size`). Newton then needs 2.1
    /// iterations on average instead of 3.4, but the longer seed costs as
    /// much time as that saves, so it is the fallback, not the default.
    fn extrapolated_seed(&self, lengths: &[f64; 3], r1: &Vector3<f64>) -> UpJoints {
        let r2 = match self.up_limb.rotation_at_point(r1) {
            Ok(rotation) => self.trilaterate_at(&rotation, lengths),
            Err(_) => None,
        };
        let r = match r2 {
            Some(r2) => extrapolate(r1, &r2).unwrap_or(r2),
            None => *r1,
        };
        self.up_limb.inverse(&r).unwrap_or(self.level_joints())
    }

    /// Leg geometry at `x` written into `out`, and the closure residual.
    /// (In place: the geometry is a few hundred bytes and Newton's loop
    /// would otherwise spend a tenth of its time copying it.)
    fn closure_into(
        &self,
        x: &UpJoints,
        lengths: &[f64; 3],
        out: &mut LegGeometry,
    ) -> Vector3<f64> {
        self.legs_into(self.up_limb.pose(x), out);
        Vector3::from_fn(|i, _| out.lengths_mm[i] - lengths[i])
    }

    fn newton(
        &self,
        legs_mm: &[f64; 3],
        lengths: &[f64; 3],
        seed: UpJoints,
    ) -> Result<FkSolution, KinematicsError> {
        let mut x = seed;
        // Two geometry buffers: the current iterate's and the trial's.
        let mut buffers = [self.legs_at(&x); 2];
        let mut current = 0;
        let mut f = Vector3::from_fn(|i, _| buffers[0].lengths_mm[i] - lengths[i]);
        let mut merit = f.norm_squared();
        for iteration in 1..=MAX_ITERATIONS {
            let j1 = buffers[current].j1();
            let Some(j1_inv) = j1.try_inverse() else {
                return Err(KinematicsError::Singular {
                    condition: f64::INFINITY,
                    limit: SINGULARITY_CONDITION_LIMIT,
                });
            };
            let step = -(j1_inv * f);
            let step_mm = scaled_size(&step, x.q4_mm);
            // Backtracking line search on |f|^2 (Armijo with c = 1e-4).
            let mut t = 1.0;
            loop {
                let trial = UpJoints {
                    phi_rad: x.phi_rad + t * step.x,
                    theta_rad: x.theta_rad + t * step.y,
                    q4_mm: x.q4_mm + t * step.z,
                };
                let ft = self.closure_into(&trial, lengths, &mut buffers[1 - current]);
                let m = ft.norm_squared();
                if m <= (1.0 - 1e-4 * t) * merit || m == 0.0 || step_mm * t < STEP_TOLERANCE_MM {
                    x = trial;
                    current = 1 - current;
                    f = ft;
                    merit = m;
                    break;
                }
                t *= 0.5;
                if t < 1e-8 {
                    return Err(KinematicsError::NoAssembly {
                        residual_mm: merit.sqrt(),
                    });
                }
            }
            // The next Newton step, predicted with this iteration's inverse
            // Jacobian. Once it is small, applying it without a new Jacobian
            // leaves an error of order |next| |step| / L: below 1e-13 mm.
            let next = -(j1_inv * f);
            let next_mm = scaled_size(&next, x.q4_mm);
            if next_mm < FINAL_STEP_MM || merit == 0.0 {
                if merit != 0.0 {
                    x = UpJoints {
                        phi_rad: x.phi_rad + next.x,
                        theta_rad: x.theta_rad + next.y,
                        q4_mm: x.q4_mm + next.z,
                    };
                    f = self.closure_into(&x, lengths, &mut buffers[current]);
                    merit = f.norm_squared();
                }
                let residual_mm = merit.sqrt();
                if residual_mm > RESIDUAL_TOLERANCE_MM {
                    return Err(KinematicsError::NoAssembly { residual_mm });
                }
                return self.finish(legs_mm, x, &buffers[current], &j1, iteration, residual_mm);
            }
        }
        Err(KinematicsError::NotConverged {
            solver: "forward kinematics",
            iterations: MAX_ITERATIONS,
            residual: merit.sqrt(),
        })
    }

    fn finish(
        &self,
        legs_mm: &[f64; 3],
        x: UpJoints,
        geometry: &LegGeometry,
        j1: &Matrix3<f64>,
        iterations: u32,
        residual_mm: f64,
    ) -> Result<FkSolution, KinematicsError> {
        // `j1` is from the last iterate, less than 1e-10 mm away: the same
        // condition number for every purpose.
        let condition = unit_free_condition(j1, x.q4_mm);
        if condition > SINGULARITY_CONDITION_LIMIT {
            return Err(KinematicsError::Singular {
                condition,
                limit: SINGULARITY_CONDITION_LIMIT,
            });
        }
        self.check_limits(legs_mm, &x, &geometry.limb.limb_axis)?;
        Ok(FkSolution {
            up: x,
            position_mm: geometry.limb.position_mm,
            rotation: geometry.limb.rotation,
            condition,
            iterations,
            residual_mm,
        })
    }
}

/// Size of a step in `(phi, theta, q4)` in mm: angles times the limb length.
fn scaled_size(step: &Vector3<f64>, q4_mm: f64) -> f64 {
    step.z.abs() + q4_mm.abs() * (step.x.abs() + step.y.abs())
}

/// Frobenius condition number of `J1 diag(1/q4, 1/q4, 1)`.
pub(crate) fn unit_free_condition(j1: &Matrix3<f64>, q4_mm: f64) -> f64 {
    let mut scaled = *j1;
    for i in 0..3 {
        scaled[(i, 0)] /= q4_mm;
        scaled[(i, 1)] /= q4_mm;
    }
    match scaled.try_inverse() {
        Some(inv) => scaled.norm() * inv.norm(),
        None => f64::INFINITY,
    }
}

/// Aitken's extrapolation of the seed's fixed-point iteration from its
/// first two points `r1`, `r2` (the start being the level platform,
/// direction `e_z`); `None` when the iteration does not contract.
fn extrapolate(r1: &Vector3<f64>, r2: &Vector3<f64>) -> Option<Vector3<f64>> {
    let (n1, n2) = (r1.norm(), r2.norm());
    let (u1, u2) = (r1 / n1, r2 / n2);
    let d1 = u1 - Vector3::z();
    let d2 = u2 - u1;
    let d1d1 = d1.norm_squared();
    let slope = d1.dot(&d2) / d1d1;
    // Nothing to extrapolate on a level platform; a slope near or beyond
    // one is not a contraction.
    if !(d1d1 > 1e-14 && slope.abs() < 0.95) {
        return None;
    }
    let gain = slope / (1.0 - slope);
    let u = (u2 + gain * d2).normalize();
    Some(u * (n2 + gain * (n2 - n1)))
}

/// The intersection of three spheres on the side of larger z, if any.
fn trilaterate(c: &[Vector3<f64>; 3], r: &[f64; 3]) -> Option<Vector3<f64>> {
    let d_vec = c[1] - c[0];
    let d = d_vec.norm();
    let ex = d_vec / d;
    let c3 = c[2] - c[0];
    let i = ex.dot(&c3);
    let ey_raw = c3 - i * ex;
    let j = ey_raw.norm();
    if d < 1e-9 || j < 1e-9 {
        return None;
    }
    let ey = ey_raw / j;
    let mut ez = ex.cross(&ey);
    if ez.z < 0.0 {
        ez = -ez;
    }
    let x = (r[0] * r[0] - r[1] * r[1] + d * d) / (2.0 * d);
    let y = (r[0] * r[0] - r[2] * r[2] + i * i + j * j) / (2.0 * j) - i / j * x;
    let z2 = r[0] * r[0] - x * x - y * y;
    if z2.is_nan() || z2 < 0.0 {
        return None;
    }
    Some(c[0] + x * ex + y * ey + z2.sqrt() * ez)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trilateration_finds_a_known_point() {
        let c = [
            Vector3::new(-100.0, 170.0, 0.0),
            Vector3::new(-100.0, -170.0, 0.0),
            Vector3::new(190.0, 0.0, 0.0),
        ];
        let p = Vector3::new(30.0, -40.0, 700.0);
        let r = c.map(|ci| (p - ci).norm());
        let found = trilaterate(&c, &r).unwrap();
        assert!((found - p).norm() < 1e-9);
    }

    /// Distance in mm between two UP joint values (angles times `q4`).
    fn joint_distance_mm(a: &UpJoints, b: &UpJoints) -> f64 {
        let d = Vector3::new(
            a.phi_rad - b.phi_rad,
            a.theta_rad - b.theta_rad,
            a.q4_mm - b.q4_mm,
        );
        scaled_size(&d, b.q4_mm)
    }

    #[test]
    fn the_extrapolated_seed_is_many_times_closer_than_a_level_platform() {
        for m in [
            Machine::paper(),
            Machine::paper().with_axis_order(crate::description::AxisOrder::YFirst),
        ] {
            let (mut worst_level, mut worst_seed) = (0.0f64, 0.0f64);
            let (mut sum_level, mut sum_seed) = (0.0, 0.0);
            for r in m.workspace.random_poses(300, 5) {
                let ik = m.inverse(&r).unwrap();
                let lengths = m.actual_lengths(&ik.legs_mm);
                let r1 = m.level_trilateration(&lengths).unwrap();
                let level = m.up_limb.inverse(&r1).unwrap();
                let seed = m.extrapolated_seed(&lengths, &r1);
                let (e_level, e_seed) = (
                    joint_distance_mm(&level, &ik.up),
                    joint_distance_mm(&seed, &ik.up),
                );
                (sum_level, sum_seed) = (sum_level + e_level, sum_seed + e_seed);
                worst_level = worst_level.max(e_level);
                worst_seed = worst_seed.max(e_seed);
            }
            // Measured (x-first): worst 52 / 413 mm, mean 11 / 219 mm.
            assert!(
                worst_seed < 0.2 * worst_level && sum_seed < 0.1 * sum_level,
                "worst: seed {worst_seed} mm, level platform {worst_level} mm; \
                 sums {sum_seed} / {sum_level} mm"
            );
        }
    }

    #[test]
    fn fk_inverts_ik_at_the_workspace_corners() {
        let m = Machine::paper();
        for r in [
            Vector3::new(400.0, 0.0, 650.0),
            Vector3::new(-400.0, 0.0, 850.0),
            Vector3::new(0.0, 400.0, 650.0),
            Vector3::new(0.0, -400.0, 850.0),
            Vector3::new(0.0, 0.0, 750.0),
        ] {
            let ik = m.inverse(&r).unwrap();
            let fk = m.forward(&ik.legs_mm).unwrap();
            assert!(
                (fk.position_mm - r).norm() < 1e-9,
                "{r}: {}",
                fk.position_mm
            );
            assert!(fk.condition < 50.0, "{r}: condition {}", fk.condition);
        }
    }

    #[test]
    fn inconsistent_commands_are_an_error_not_a_number() {
        let m = Machine::paper();
        // Leg 1 far shorter than the other two: no assembly exists.
        let e = m.forward(&[460.0, 1200.0, 1200.0]).unwrap_err();
        assert!(
            matches!(
                e,
                KinematicsError::NoAssembly { .. }
                    | KinematicsError::OutOfReach { .. }
                    | KinematicsError::Singular { .. }
            ),
            "{e:?}"
        );
        assert!(matches!(
            m.forward(&[100.0, 800.0, 800.0]),
            Err(KinematicsError::OutOfStroke { leg: 1, .. })
        ));
    }
}
