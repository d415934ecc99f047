//! A laser tracker (or a CMM) on a target in the spindle.

use nalgebra::{Isometry3, Vector3};
use rand_distr::{Distribution, StandardNormal};
use tricept_data::{external::ExternalPose, external::TrackerData, external::TrackerPoint};
use tricept_model::head_errors::Effector;

use super::{measure_each, spindle_point};
use crate::{Plant, PlantError};

/// Tag mixed into the seed, so that instruments measuring with the same
/// seed draw independent noise.
const TRACKER_TAG: u64 = 0x7ac4_e700;

/// A laser tracker (or a CMM) measuring a target mounted in the spindle.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracker {
    /// The tracker's frame: maps a point of the machine's base frame into
    /// the instrument's coordinates.
    pub frame: Isometry3<f64>,
    /// Offset of the target from the tool tip, mm, in the spindle frame at
    /// zero head angles (unknown to the identification unless stated).
    pub target_offset_mm: Vector3<f64>,
    /// Standard deviation of each measured coordinate, um.
    pub sigma_um: f64,
    /// Station number written to the records.
    pub setup: u32,
}

impl Tracker {
    /// Measures the target at each `(pose, extension_mm)`: the machine at
    /// the pose's commands and head angles, the target `extension_mm` along
    /// the tool beyond the tip plus the target offset.
    ///
    /// # Example
    /// ```
    /// use nalgebra::{Isometry3, Vector3};
    /// use tricept_data::external::ExternalPose;
    /// use tricept_kinematics::Machine;
    /// use tricept_plant::{Plant, instruments::Tracker};
    /// let m = Machine::paper();
    /// let plant = Plant::geometric(m.clone(), Default::default());
    /// let tracker = Tracker {
    ///     frame: Isometry3::translation(1500.0, 0.0, 0.0),
    ///     target_offset_mm: Vector3::zeros(),
    ///     sigma_um: 10.0,
    ///     setup: 1,
    /// };
    /// let q = m.inverse(&Vector3::new(0.0, 0.0, 750.0)).unwrap().legs_mm;
    /// let pose = ExternalPose { commands_mm: q, head_rad: [0.0, 0.0] };
    /// let data = tracker.measure(&plant, &[(pose, 0.0)], 1).unwrap();
    /// // The tool tip is 350 mm below O' = (0, 0, 750), seen from 1.5 m along x.
    /// let p = data.records[0].position_mm;
    /// assert!((p[0] - 1500.0).abs() < 0.1 && (p[2] - 1100.0).abs() < 0.1);
    /// ```
    pub fn measure(
        &self,
        plant: &Plant,
        poses: &[(ExternalPose, f64)],
        seed: u64,
    ) -> Result<TrackerData, PlantError> {
        let sigma_mm = self.sigma_um * 1e-3;
        let point = |actual: &_, j, (pose, extension_mm): &(ExternalPose, f64), rng: &mut _| {
            let effector = Effector {
                extension_mm: *extension_mm,
                offset_mm: self.target_offset_mm,
            };
            let x = spindle_point(plant, actual, j, pose, &effector)?;
            let y = self.frame * nalgebra::Point3::from(x);
            let position_mm: [f64; 3] = std::array::from_fn(|c| {
                let z: f64 = StandardNormal.sample(rng);
                y[c] + sigma_mm * z
            });
            Ok(TrackerPoint {
                pose: *pose,
                position_mm,
                sigma_um: Some(self.sigma_um),
                extension_mm: *extension_mm,
                setup: self.setup,
                temp_c: None,
                line: 0,
            })
        };
        measure_each(plant, poses, seed, TRACKER_TAG, "simulated tracker", point)
    }
}
