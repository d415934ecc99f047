//! A measurement campaign: which poses, in which order, approached how,
//! with which sensors, logged when.
//!
//! The order of the targets fixes the approach direction of every leg (the
//! sign of its last motion), exactly as on a real machine; a campaign can
//! also visit every target twice, once approaching with all legs extending
//! and once with all legs retracting, which is what makes backlash visible.
//! It can revisit some targets at its end (the same commands logged again
//! on a separate visit: what lets a diagnosis measure the noise from the
//! data), and its sensors can be noisier than their data sheet says.

use nalgebra::Vector3;
use tricept_kinematics::{Machine, machine::SensorNoise, up_limb::UpJoints};

use crate::PlantError;

/// How targets are approached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PoseOrder {
    /// Targets visited once, in the given order; each leg's approach
    /// direction is the sign of its last move (the first pose is approached
    /// from the retracted home position: extending).
    #[default]
    AsGiven,
    /// Every target visited twice in a row: first from a point 2 mm shorter
    /// on every leg (all legs extending), then from 2 mm longer (retracting).
    BothDirections,
}

/// A campaign: targets, sensors, seed and logging.
#[derive(Debug, Clone, PartialEq)]
pub struct Campaign {
    /// Platform points to visit, mm (commanded through the nominal IK).
    pub targets_mm: Vec<Vector3<f64>>,
    /// Sensor noise of one reading and readings averaged per logged value.
    pub noise: SensorNoise,
    /// Seed of every random draw of the campaign.
    pub seed: u64,
    /// Approach strategy.
    pub order: PoseOrder,
    /// Time between logged poses, s.
    pub seconds_per_pose: f64,
    /// Structure temperature at the start, °C.
    pub start_temp_c: f64,
    /// The first `revisits` targets are visited again, in order, after the
    /// last one (separate visits of the same commands).
    pub revisits: usize,
    /// The true noise of every reading is `noise_factor` times `noise`
    /// (vibration, a sensor worse than its data sheet); the data sheet
    /// (`noise`) is what a diagnosis is told.
    pub noise_factor: f64,
}

/// Logged context of each pose: time, temperature, approach directions.
#[derive(Debug, Clone, PartialEq)]
pub struct Context {
    /// Time of each reading, s.
    pub time_s: Vec<f64>,
    /// Structure temperature before any drift (effects add theirs), °C.
    pub temp_c: Vec<f64>,
    /// Sign of each leg's last motion.
    pub approach: Vec<[i8; 3]>,
}

impl Campaign {
    /// The project's default pose set: a polar grid of 3 levels (650, 750,
    /// 850 mm) x (axis point + 3 rings x 8) = 75 poses, with the machine's
    /// sensors, ordered ring by ring.
    pub fn grid(machine: &Machine, seed: u64) -> Campaign {
        Campaign::from_targets(machine, machine.workspace.polar_grid(3, 8, 3), seed)
    }

    /// A campaign over the given targets with the machine's sensors.
    pub fn from_targets(machine: &Machine, targets_mm: Vec<Vector3<f64>>, seed: u64) -> Campaign {
        Campaign {
            targets_mm,
            noise: machine.sensors,
            seed,
            order: PoseOrder::AsGiven,
            seconds_per_pose: 30.0,
            start_temp_c: 20.0,
            revisits: 0,
            noise_factor: 1.0,
        }
    }

    /// `n` targets drawn uniformly in the workspace from `seed`.
    pub fn random(machine: &Machine, n: usize, seed: u64) -> Campaign {
        let targets = machine.workspace.random_poses(n, seed ^ 0x7f4a_7c15);
        Campaign::from_targets(machine, targets, seed)
    }

    /// Number of logged poses (the targets and the revisits; twice as many
    /// for [`PoseOrder::BothDirections`]).
    pub fn len(&self) -> usize {
        let visits = self.visits().count();
        match self.order {
            PoseOrder::AsGiven => visits,
            PoseOrder::BothDirections => 2 * visits,
        }
    }

    /// The targets in the order they are visited: every target, then the
    /// first `revisits` again.
    fn visits(&self) -> impl Iterator<Item = (usize, &Vector3<f64>)> {
        let again = self.revisits.min(self.targets_mm.len());
        self.targets_mm
            .iter()
            .enumerate()
            .chain(self.targets_mm.iter().enumerate().take(again))
    }

    /// True when there is nothing to log.
    pub fn is_empty(&self) -> bool {
        self.targets_mm.is_empty()
    }

    /// Commands (nominal IK) and nominal UP joints of every logged pose.
    pub fn commands(&self, nominal: &Machine) -> Result<Vec<([f64; 3], UpJoints)>, PlantError> {
        let mut out = Vec::with_capacity(self.len());
        for (index, r) in self.visits() {
            let ik = nominal
                .inverse(r)
                .map_err(|source| PlantError::Kinematics {
                    index,
                    target_mm: (*r).into(),
                    source,
                })?;
            out.push((ik.legs_mm, ik.up));
            if self.order == PoseOrder::BothDirections {
                out.push((ik.legs_mm, ik.up));
            }
        }
        Ok(out)
    }

    /// Time, base temperature and approach directions of every logged pose.
    pub fn context_for_commands(&self, commands: &[([f64; 3], UpJoints)]) -> Context {
        let n = commands.len();
        let time_s = (0..n).map(|j| j as f64 * self.seconds_per_pose).collect();
        let temp_c = vec![self.start_temp_c; n];
        let approach = match self.order {
            PoseOrder::AsGiven => {
                let mut prev: Option<[f64; 3]> = None;
                commands
                    .iter()
                    .map(|(q, _)| {
                        let dir = match prev {
                            None => [1, 1, 1],
                            Some(p) => std::array::from_fn(|i| if q[i] >= p[i] { 1 } else { -1 }),
                        };
                        prev = Some(*q);
                        dir
                    })
                    .collect()
            }
            PoseOrder::BothDirections => (0..n)
                .map(|j| if j % 2 == 0 { [1, 1, 1] } else { [-1, -1, -1] })
                .collect(),
        };
        Context {
            time_s,
            temp_c,
            approach,
        }
    }
}
