//! The fixed part of a study: machine, true errors, pose set, the plane of
//! the volumetric error map, and everything that does not depend on the
//! encoder grade (the exact noise-free readings, the "before" map, `mu_0`).

use nalgebra::Vector3;
use tricept_data::{MeasuredPose, Readings};
use tricept_kinematics::{Machine, up_limb::UpJoints};
use tricept_model::{ParameterSet, params::residual_mu, volumetric::volumetric_errors};
use tricept_plant::{Campaign, Plant};

use crate::StudyError;

/// One study scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The nominal machine.
    pub nominal: Machine,
    /// The parameter set identified.
    pub set: ParameterSet,
    /// True error values of the set, mm.
    pub truth: Vec<f64>,
    /// Target points of the pose set, mm.
    pub targets_mm: Vec<Vector3<f64>>,
    /// Points of the middle-plane map, mm.
    pub plane_mm: Vec<Vector3<f64>>,
    /// Linear-scale noise of one reading, mm.
    pub length_noise_mm: f64,
    /// Readings averaged per logged value.
    pub readings_per_pose: u32,
    /// The actual machine.
    pub actual: Machine,
    /// Poses with the exact noise-free readings (offsets included).
    pub clean: Vec<MeasuredPose>,
    /// True UP joints at each pose (FK seeds).
    pub true_up: Vec<UpJoints>,
    /// `mu` without calibration (`deps_e = 0`), mm.
    pub mu0_mm: f64,
    /// Mean `|dr|` over the plane before compensation, mm.
    pub before_plane_mean_mm: f64,
    /// Largest `|dr|` over the plane before compensation, mm.
    pub before_plane_max_mm: f64,
}

impl Scenario {
    /// Builds a scenario: `truth` in `set`, poses at `targets_mm`, the
    /// middle-plane map on a lattice of `plane_spacing_mm`.
    pub fn new(
        nominal: Machine,
        set: ParameterSet,
        truth: Vec<f64>,
        targets_mm: Vec<Vector3<f64>>,
        plane_spacing_mm: f64,
        length_noise_mm: f64,
        readings_per_pose: u32,
    ) -> Result<Scenario, StudyError> {
        if truth.len() != set.len() {
            return Err(StudyError::Invalid(format!(
                "{} true values for {} parameters",
                truth.len(),
                set.len()
            )));
        }
        let plant = Plant::geometric(nominal.clone(), set.to_errors(&truth));
        let campaign = Campaign::from_targets(&nominal, targets_mm.clone(), 0);
        let truth_poses = plant.true_poses(&campaign)?;
        let clean = truth_poses
            .iter()
            .map(|t| MeasuredPose {
                commands_mm: t.commands_mm,
                readings: t.readings,
                ..Default::default()
            })
            .collect();
        let true_up = truth_poses.iter().map(|t| t.up).collect();
        let actual = plant.actual_machine();
        let plane_mm = nominal
            .workspace
            .disc_grid(nominal.workspace.mid_plane_z_mm(), plane_spacing_mm);
        let before = volumetric_errors(&nominal, &actual, &plane_mm)?.stats();
        Ok(Scenario {
            mu0_mm: residual_mu(&truth, &vec![0.0; truth.len()]),
            nominal,
            set,
            truth,
            targets_mm,
            plane_mm,
            length_noise_mm,
            readings_per_pose,
            actual,
            clean,
            true_up,
            before_plane_mean_mm: before.mean_mm,
            before_plane_max_mm: before.max_mm,
        })
    }

    /// The paper's scenario on `nominal`: Table 2, 0.5 um, mean of 3, the
    /// given targets, the middle plane on a 100 mm lattice (49 points).
    pub fn paper(nominal: Machine, targets_mm: Vec<Vector3<f64>>) -> Result<Scenario, StudyError> {
        let set = ParameterSet::paper15();
        let truth = set.table2();
        Scenario::new(nominal, set, truth, targets_mm, 100.0, 0.5e-3, 3)
    }

    /// Standard deviations `[phi, theta, s]` of one logged reading for an
    /// encoder of `grade_arcsec`.
    pub fn logged_sigma(&self, grade_arcsec: f64) -> [f64; 3] {
        let k = f64::from(self.readings_per_pose.max(1)).sqrt();
        let a = grade_arcsec * tricept_kinematics::units::RAD_PER_ARCSEC / k;
        [a, a, self.length_noise_mm / k]
    }

    /// Number of readings (rows) of one trial.
    pub fn rows(&self) -> usize {
        3 * self.clean.len()
    }

    /// Noise-free readings with `noise` (per row, already scaled) added.
    pub fn noisy_poses(&self, noise: &[f64]) -> Vec<MeasuredPose> {
        self.clean
            .iter()
            .enumerate()
            .map(|(j, p)| {
                let r = p.readings.to_array();
                MeasuredPose {
                    readings: Readings::from_array([0, 1, 2].map(|c| r[c] + noise[3 * j + c])),
                    ..*p
                }
            })
            .collect()
    }
}
