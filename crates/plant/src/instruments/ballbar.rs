//! A ballbar from the tool-tip ball to a pivot on the table.

use nalgebra::Vector3;
use rand_distr::{Distribution, StandardNormal};
use tricept_data::{external::BallbarData, external::BallbarReading, external::ExternalPose};
use tricept_model::head_errors::Effector;

use super::{measure_each, spindle_point};
use crate::{Plant, PlantError};

/// Tag mixed into the seed, so that instruments measuring with the same
/// seed draw independent noise.
const BALLBAR_TAG: u64 = 0xba11_ba40;

/// A ballbar between a ball in the spindle and a pivot on the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Ballbar {
    /// Centre of the pivot ball, base frame, mm.
    pub pivot_mm: Vector3<f64>,
    /// The bar's reading minus the true centre distance, um (its length
    /// calibration error).
    pub length_error_um: f64,
    /// Offset of the spindle ball from the tool tip, mm (spindle frame at
    /// zero head angles).
    pub ball_offset_mm: Vector3<f64>,
    /// Standard deviation of one reading, um.
    pub sigma_um: f64,
    /// Setup number written to the records.
    pub setup: u32,
}

impl Ballbar {
    /// Reads the bar at each pose.
    ///
    /// # Example
    /// ```
    /// use nalgebra::Vector3;
    /// use tricept_data::external::ExternalPose;
    /// use tricept_kinematics::{head::HeadBranch, Machine};
    /// use tricept_plant::{instruments::Ballbar, Plant};
    /// let m = Machine::paper();
    /// let plant = Plant::geometric(m.clone(), Default::default());
    /// let bar = Ballbar { pivot_mm: Vector3::new(0.0, 0.0, 1250.0), length_error_um: 0.0,
    ///     ball_offset_mm: Vector3::zeros(), sigma_um: 1.0, setup: 1 };
    /// let ik = m.tool_inverse(&Vector3::new(150.0, 0.0, 1250.0), &Vector3::new(0.3, 0.0, 1.0),
    ///     HeadBranch::default()).unwrap();
    /// let pose = ExternalPose { commands_mm: ik.legs_mm, head_rad: ik.head_rad };
    /// let data = bar.measure(&plant, &[pose], 3).unwrap();
    /// assert!((data.records[0].length_mm - 150.0).abs() < 0.01);
    /// ```
    pub fn measure(
        &self,
        plant: &Plant,
        poses: &[ExternalPose],
        seed: u64,
    ) -> Result<BallbarData, PlantError> {
        let effector = Effector {
            extension_mm: 0.0,
            offset_mm: self.ball_offset_mm,
        };
        let reading = |actual: &_, j, pose: &ExternalPose, rng: &mut _| {
            let x = spindle_point(plant, actual, j, pose, &effector)?;
            let z: f64 = StandardNormal.sample(rng);
            Ok(BallbarReading {
                pose: *pose,
                length_mm: (x - self.pivot_mm).norm()
                    + 1e-3 * (self.length_error_um + self.sigma_um * z),
                sigma_um: Some(self.sigma_um),
                setup: self.setup,
                temp_c: None,
                line: 0,
            })
        };
        measure_each(
            plant,
            poses,
            seed,
            BALLBAR_TAG,
            "simulated ballbar",
            reading,
        )
    }
}
