//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The plant simulator: measured-data files ([`tricept_data::Dataset`])
//! produced the way a real campaign would produce them, from an exact
//! Tricept with geometric errors, optional unmodelled effects, sensor zero
//! offsets and sensor noise.
//!
//! For every target pose of a [`Campaign`]:
//! 1. the drives are commanded with the *nominal* IK (what a controller that
//!    knows nothing better sends);
//! 2. the legs reach the commanded lengths plus the geometric leg errors and
//!    the effects' extra lengths ([`effects`]);
//! 3. the exact FK of the actual machine gives the UP limb's joints;
//! 4. the sensors read them with their zero offsets, the effects' reading
//!    errors, and noise (mean of `readings_per_pose` Gaussian draws);
//! 5. the logger writes time, temperature and approach directions.
//!
//! The actual machine also carries head errors ([`Plant::head_errors`], the
//! 13 parameters of [`tricept_model::head_errors::HeadParameterSet`]), which no internal
//! sensor sees, and external instruments ([`instruments`]: a laser tracker,
//! a ballbar, a touch probe on reference spheres and planes) measure the
//! exact spindle point of the actual machine ([`Plant::spindle_point`]).
//!
//! Nothing here uses the linearised model. Randomness is seeded (PCG-64 MCG).
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod campaign;
pub mod effects;
mod error;
pub mod instruments;

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;
use tricept_data::{Dataset, MeasuredPose, Readings};
use tricept_kinematics::{KinematicsError, Machine, up_limb::UpJoints};
use tricept_model::{
    GeometricErrors, actual::actual_machine, head_errors::Effector, head_errors::HeadParameterSet,
    head_errors::N_HEAD, head_errors::TYPICAL_HEAD_ERRORS,
};

pub use campaign::Campaign;
pub use effects::Effect;
pub use error::PlantError;

/// The simulated machine: nominal model, geometric errors and effects.
#[derive(Debug, Clone)]
pub struct Plant {
    /// The nominal machine (what the controller believes).
    pub nominal: Machine,
    /// The geometric (class 1) errors of the actual machine.
    pub errors: GeometricErrors,
    /// Unmodelled effects present in the actual machine and its sensors.
    pub effects: Vec<Effect>,
    /// Zero offsets of the sensors `[phi, theta, s]` (rad, rad, mm): the
    /// readings are joint value + offset.
    pub sensor_offsets: [f64; 3],
    /// Errors of the head: values of the 13 parameters of
    /// [`HeadParameterSet::head13`] of the nominal head (empty: the nominal
    /// head).
    pub head_errors: Vec<f64>,
}

/// Default sensor zero offsets: arbitrary, documented, and far from zero so
/// that no code can get away with ignoring them.
pub const DEFAULT_SENSOR_OFFSETS: [f64; 3] = [0.0123, -0.0187, -612.5];

/// The noise-free state of one simulated pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruePose {
    /// Commanded leg lengths, mm.
    pub commands_mm: [f64; 3],
    /// True UP joint values reached.
    pub up: UpJoints,
    /// True platform point reached, mm.
    pub position_mm: Vector3<f64>,
    /// Noise-free readings (with offsets and reading effects).
    pub readings: Readings,
    /// True structure temperature, °C.
    pub temp_c: f64,
    /// Time of the reading, s.
    pub time_s: f64,
    /// Sign of each leg's last motion.
    pub approach: [i8; 3],
}

/// Standard deviation of the temperature logger, K.
pub const TEMPERATURE_LOGGER_NOISE_K: f64 = 0.02;

impl Plant {
    /// A plant with geometric errors only and the default sensor offsets.
    pub fn geometric(nominal: Machine, errors: GeometricErrors) -> Plant {
        Plant {
            nominal,
            errors,
            effects: Vec::new(),
            sensor_offsets: DEFAULT_SENSOR_OFFSETS,
            head_errors: Vec::new(),
        }
    }

    /// The actual machine's exact kinematic model (geometric errors, head
    /// errors and the effects that change the machine's geometry, such as
    /// U-joint axis errors).
    pub fn actual_machine(&self) -> Machine {
        let mut m = actual_machine(&self.nominal, &self.errors);
        if !self.head_errors.is_empty() {
            m.head = HeadParameterSet::head13(&self.nominal.head).head_at(&self.head_errors);
        }
        for e in &self.effects {
            e.modify_machine(&mut m);
        }
        m
    }

    /// Simulates a campaign: one [`MeasuredPose`] per logged pose.
    ///
    /// # Example
    /// ```
    /// use tricept_kinematics::Machine;
    /// use tricept_model::ParameterSet;
    /// use tricept_plant::{Campaign, Plant};
    /// let m = Machine::paper();
    /// let set = ParameterSet::paper15();
    /// let plant = Plant::geometric(m.clone(), set.to_errors(&set.table2()));
    /// let campaign = Campaign::grid(&m, 7);
    /// let data = plant.simulate(&campaign).unwrap();
    /// assert_eq!(data.poses.len(), 75);
    /// ```
    pub fn simulate(&self, campaign: &Campaign) -> Result<Dataset, PlantError> {
        let truth = self.true_poses(campaign)?;
        let mut rng = Pcg64Mcg::seed_from_u64(campaign.seed);
        let k = campaign.noise.readings_per_pose.max(1);
        let single = [
            campaign.noise.angle_rad,
            campaign.noise.angle_rad,
            campaign.noise.length_mm,
        ]
        .map(|s| s * campaign.noise_factor);
        let mut poses = Vec::with_capacity(truth.len());
        for t in &truth {
            let clean = t.readings.to_array();
            let mut noisy = [0.0; 3];
            for c in 0..3 {
                // The mean of k readings, drawn one by one as on the machine.
                let mut sum = 0.0;
                for _ in 0..k {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    sum += z;
                }
                noisy[c] = clean[c] + single[c] * sum / f64::from(k);
            }
            let z: f64 = StandardNormal.sample(&mut rng);
            poses.push(MeasuredPose {
                commands_mm: t.commands_mm,
                readings: Readings::from_array(noisy),
                temp_c: Some(t.temp_c + TEMPERATURE_LOGGER_NOISE_K * z),
                time_s: Some(t.time_s),
                approach: Some(t.approach),
                line: 0,
                campaign: 0,
            });
        }
        let logged = campaign.noise.logged_sigma();
        for e in &self.effects {
            e.corrupt_readings(&mut poses, campaign.seed, &logged);
        }
        Ok(Dataset {
            poses,
            source: "simulated".into(),
        })
    }

    /// The noise-free poses of a campaign (commands, true joints, clean
    /// readings, logged context).
    pub fn true_poses(&self, campaign: &Campaign) -> Result<Vec<TruePose>, PlantError> {
        let actual = self.actual_machine();
        let commands = campaign.commands(&self.nominal)?;
        let context = campaign.context_for_commands(&commands);
        let n = commands.len();
        let mut out = Vec::with_capacity(n);
        for (j, (q, nominal_up)) in commands.iter().enumerate() {
            let fraction = if n > 1 {
                j as f64 / (n - 1) as f64
            } else {
                0.0
            };
            let delta_temp_k: f64 = self
                .effects
                .iter()
                .map(|e| e.temperature_drift_k(fraction))
                .sum();
            let state = effects::PoseState {
                commands_mm: *q,
                nominal_up: *nominal_up,
                delta_temp_k,
                approach: context.approach[j],
                fraction,
            };
            let mut legs = *q;
            for e in &self.effects {
                e.extra_leg_length(&self.nominal, &state, &mut legs);
            }
            let kinematics = |source| PlantError::Kinematics {
                index: j,
                target_mm: campaign.targets_mm[j.min(campaign.targets_mm.len().saturating_sub(1))]
                    .into(),
                source,
            };
            // The nominal configuration is within a few mm: Newton's seed.
            let fk = actual.forward_from(&legs, nominal_up).map_err(kinematics)?;
            let mut r = [
                fk.up.phi_rad + self.sensor_offsets[0],
                fk.up.theta_rad + self.sensor_offsets[1],
                fk.up.q4_mm + self.sensor_offsets[2],
            ];
            for e in &self.effects {
                e.reading_error(&state, &fk.up, &mut r);
            }
            out.push(TruePose {
                commands_mm: *q,
                up: fk.up,
                position_mm: fk.position_mm,
                readings: Readings::from_array(r),
                temp_c: context.temp_c[j] + delta_temp_k,
                time_s: context.time_s[j],
                approach: context.approach[j],
            });
        }
        Ok(out)
    }
}

impl Plant {
    /// Where the actual platform point goes for leg `commands_mm`, with the
    /// leg effects at the campaign's start (no temperature change, every leg
    /// approached extending), mm.
    pub fn reach(&self, commands_mm: &[f64; 3]) -> Result<Vector3<f64>, KinematicsError> {
        Ok(self
            .reach_on(&self.actual_machine(), commands_mm)?
            .position_mm)
    }

    /// The actual machine `actual` (this plant's [`Plant::actual_machine`])
    /// at leg `commands_mm`, with the leg effects of [`Plant::reach`].
    fn reach_on(
        &self,
        actual: &Machine,
        commands_mm: &[f64; 3],
    ) -> Result<tricept_kinematics::fk::FkSolution, KinematicsError> {
        let nominal_up = self.nominal.forward(commands_mm)?.up;
        let state = effects::PoseState {
            commands_mm: *commands_mm,
            nominal_up,
            delta_temp_k: 0.0,
            approach: [1, 1, 1],
            fraction: 0.0,
        };
        let mut legs = *commands_mm;
        for e in &self.effects {
            e.extra_leg_length(&self.nominal, &state, &mut legs);
        }
        actual.forward_from(&legs, &nominal_up)
    }

    /// Where a point fixed to the spindle (`effector`: the tool tip, a
    /// tracker target, a ballbar ball) of the actual machine goes for leg
    /// `commands_mm` and commanded head angles `head_rad`, in the base
    /// frame, mm: exact FK of the actual module with the leg effects of
    /// [`Plant::reach`], then the actual head at the commanded angles plus
    /// its actual zero offsets. The effector's extension runs along the
    /// actual tool axis.
    ///
    /// # Example
    /// ```
    /// use tricept_kinematics::{head::HeadBranch, Machine};
    /// use tricept_model::head_errors::Effector;
    /// use tricept_plant::Plant;
    /// let m = Machine::paper();
    /// let mut plant = Plant::geometric(m.clone(), Default::default());
    /// let tip = nalgebra::Vector3::new(100.0, -50.0, 1100.0);
    /// let ik = m.tool_inverse(&tip, &nalgebra::Vector3::z(), HeadBranch::default()).unwrap();
    /// let at = |p: &Plant| p.spindle_point(&ik.legs_mm, ik.head_rad, &Effector::default()).unwrap();
    /// assert!((at(&plant) - tip).norm() < 1e-9);
    /// // A 0.3 mm longer tool, seen by no internal sensor, moves the tip.
    /// plant.head_errors = vec![0.0; 13];
    /// plant.head_errors[9] = 0.3;
    /// assert!(((at(&plant) - tip).norm() - 0.3).abs() < 1e-9);
    /// ```
    pub fn spindle_point(
        &self,
        commands_mm: &[f64; 3],
        head_rad: [f64; 2],
        effector: &Effector,
    ) -> Result<Vector3<f64>, KinematicsError> {
        self.spindle_point_on(&self.actual_machine(), commands_mm, head_rad, effector)
    }

    /// [`Plant::spindle_point`] on an actual machine computed once.
    pub(crate) fn spindle_point_on(
        &self,
        actual: &Machine,
        commands_mm: &[f64; 3],
        head_rad: [f64; 2],
        effector: &Effector,
    ) -> Result<Vector3<f64>, KinematicsError> {
        let fk = self.reach_on(actual, commands_mm)?;
        let head = &actual.head;
        let local = head.spindle_point(
            head_rad,
            &(head.tool_tip_mm + head.tool_direction * effector.extension_mm + effector.offset_mm),
        );
        Ok(fk.position_mm + fk.rotation * local)
    }
}

/// Head errors for a simulated machine: every parameter of
/// [`HeadParameterSet::head13`] `scale` times its typical size
/// ([`TYPICAL_HEAD_ERRORS`]) times a factor drawn uniformly in [0.5, 1],
/// with a random sign, from `seed` (PCG-64 MCG).
///
/// # Example
/// ```
/// let e = tricept_plant::random_head_errors(1.0, 7);
/// assert_eq!(e.len(), 13);
/// assert!(e.iter().zip(tricept_model::head_errors::TYPICAL_HEAD_ERRORS).all(|(v, s)| v.abs() >= 0.5 * s && v.abs() <= s));
/// assert_eq!(e, tricept_plant::random_head_errors(1.0, 7));
/// ```
pub fn random_head_errors(scale: f64, seed: u64) -> Vec<f64> {
    use rand::RngExt;
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x4ead_e770);
    (0..N_HEAD)
        .map(|j| {
            let size = 0.5 + 0.5 * rng.random::<f64>();
            let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
            scale * TYPICAL_HEAD_ERRORS[j] * size * sign
        })
        .collect()
}

/// `n` parameter values drawn uniformly in `[-magnitude_mm, magnitude_mm]`
/// from `seed` (PCG-64 MCG).
///
/// # Example
/// ```
/// let e = tricept_plant::random_errors(15, 2.0, 7);
/// assert_eq!(e.len(), 15);
/// assert!(e.iter().all(|v| v.abs() <= 2.0));
/// assert_eq!(e, tricept_plant::random_errors(15, 2.0, 7));
/// ```
pub fn random_errors(n: usize, magnitude_mm: f64, seed: u64) -> Vec<f64> {
    use rand::RngExt;
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|_| magnitude_mm * (2.0 * rng.random::<f64>() - 1.0))
        .collect()
}
