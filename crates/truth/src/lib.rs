//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The truth the tests measure against: a Tricept, its sensors and its
//! instruments written from the documented conventions alone
//! (`docs/conventions.md`, `docs/data-format.md`, the Table 1 machine of
//! `fixtures/machines/tricept-paper.json` read as plain JSON), never through
//! the project's kinematics, error model or simulator. A test that hides an
//! effect in data from this crate and finds it again has checked the
//! project's code against an independent reading of its documentation.
//!
//! - `machine.rs`: [`TrueMachine`] (module errors, a general two-axis head,
//!   sensor offsets; forward kinematics by its own Newton iteration, from
//!   commands or from true leg lengths, so that a test adds any leg effect;
//!   a machine warmed as a whole) and [`SensorNoise`];
//! - `tracker.rs`: [`TrueTracker`], a laser tracker station;
//! - `instruments.rs`: [`TrueBallbar`] and [`TrueSphere`], a ballbar on a
//!   pivot and a touch probe latching its commands on a reference sphere;
//! - `campaign.rs`: [`Row`] and [`to_csv`], a campaign written as the
//!   documented data CSV;
//! - `legs.rs`: [`LegEffect`], leg effects added to the true leg lengths
//!   (backlash by the `dir` columns' sign, a lead, a quadratic leg, a pitch
//!   error, a worn segment, legs heating evenly or unevenly, legs warming
//!   through a campaign with no log, a slip), and where
//!   the platform goes with them.
//!
//! This is test support: it panics on a machine its Newton iteration
//! cannot close, and is not published.
//!
//! # Example
//! ```
//! use rand::SeedableRng;
//! use tricept_truth::{Row, SensorNoise, TrueMachine, to_csv};
//! let truth = TrueMachine::random(0.0, 7);
//! let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
//! let q = [800.0, 820.0, 810.0];
//! // Leg 2 slipped by 25 um.
//! let lengths = [q[0] + truth.leg_offsets_mm[0], q[1] + truth.leg_offsets_mm[1] + 0.025, q[2] + truth.leg_offsets_mm[2]];
//! let readings = truth.sensed(&truth.forward_lengths(&lengths), &SensorNoise::DOCUMENTED, &mut rng);
//! let csv = to_csv(&[Row { commands_mm: q, readings, temp_c: Some(20.0), directions: None }]);
//! assert!(csv.starts_with("q1,q2,q3,phi,theta,s,temp_c\n"));
//! ```

mod campaign;
mod instruments;
mod legs;
mod machine;
mod tracker;

pub use campaign::{Row, to_csv};
pub use instruments::{TrueBallbar, TrueSphere};
pub use legs::{DELIVERY_T, LegContext, LegEffect};
pub use machine::{HeadSizes, SensorNoise, TrueHead, TrueMachine};
pub use tracker::TrueTracker;

use nalgebra::{Matrix3, Vector3};
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;

/// Arcseconds per radian.
pub const ARCSEC_PER_RAD: f64 = 206_264.806_247_096_36;

/// Rotation about the unit axis `k` by `angle` (Rodrigues).
pub fn rot(k: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let kx = Matrix3::new(0.0, -k.z, k.y, k.z, 0.0, -k.x, -k.y, k.x, 0.0);
    Matrix3::identity() + kx * angle.sin() + kx * kx * (1.0 - angle.cos())
}

/// One standard normal draw.
pub fn normal(rng: &mut Pcg64Mcg) -> f64 {
    StandardNormal.sample(rng)
}

fn normal3(rng: &mut Pcg64Mcg, sigma: f64) -> Vector3<f64> {
    Vector3::from_fn(|_, _| sigma * normal(rng))
}
