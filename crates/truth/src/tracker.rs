//! A laser tracker station, written from the documented conventions: it
//! measures a point `x` of the base frame in its own coordinates.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;

use crate::normal3;

/// A tracker station: `y = R^T (x - c)` in its own coordinates.
#[derive(Debug, Clone)]
pub struct TrueTracker {
    /// The station's axes in the base frame.
    pub rotation: Matrix3<f64>,
    /// The station's origin in the base frame, mm.
    pub position_mm: Vector3<f64>,
}

impl TrueTracker {
    /// A station 1-3 m from the workspace centre (0, 0, 1100) mm, in a
    /// random direction, turned by a random rotation.
    pub fn random(seed: u64) -> TrueTracker {
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x7ac4_0001);
        let dir = normal3(&mut rng, 1.0).normalize();
        let distance = 1000.0 + 2000.0 * rng.random::<f64>();
        let q: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
        let rotation =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
                .to_rotation_matrix()
                .into_inner();
        TrueTracker {
            rotation,
            position_mm: Vector3::new(0.0, 0.0, 1100.0) + dir * distance,
        }
    }

    /// A measurement of `x` (base frame) with 10 um noise per coordinate.
    pub fn measure(&self, x: &Vector3<f64>, rng: &mut Pcg64Mcg) -> [f64; 3] {
        let y = self.rotation.transpose() * (x - self.position_mm);
        std::array::from_fn(|c| {
            let z: f64 = StandardNormal.sample(rng);
            y[c] + 0.010 * z
        })
    }
}
