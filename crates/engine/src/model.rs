//! Reading models: what the UP limb's sensors should read at a pose for
//! given parameter values, and the derivatives of those readings.
//!
//! [`GeometricModel`] is the paper's model: the exact FK of the nominal
//! machine plus `E p` (a [`ParameterSet`]) gives the UP joints, and the
//! analytic Jacobian `J E` of eq. 9 gives their derivatives. The trait is the
//! extension point used by `tricept-diagnose` to add unmodelled effects; its
//! extended models build on [`GeometricPredictor`], which solves the UP
//! joints and the geometric columns for any actual leg lengths.
//!
//! Readings are predicted *without* the sensors' zero offsets: the
//! identification adds three offset unknowns of its own.

use tricept_data::MeasuredPose;
use tricept_kinematics::{KinematicsError, Machine, machine::LegGeometry, up_limb::UpJoints};
use tricept_model::effects::static_leg_extra_per_mm;
use tricept_model::{
    ParameterSet, actual::actual_machine, jacobian::error_jacobian_at, params::N_FULL,
};

use crate::error::IdentError;
use crate::prior::Prior;

/// A parametric model of the UP limb's readings.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let set = ParameterSet::paper15();
let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&tricept_plant::Campaign::grid(&m, 1))
    .unwrap();
use tricept_engine::model::ReadingModel;
let predictor = model.at(&set.table2());
let mut jac = vec![0.0; 3 * 15];
let mut seed = None;
let g = predictor.predict(&data.poses[0], &mut seed, &mut jac).unwrap();
// The readings are the joints plus the sensor offsets (and noise).
let y = data.poses[0].readings.to_array();
assert!((y[2] - g[2] - tricept_plant::DEFAULT_SENSOR_OFFSETS[2]).abs() < 1e-2);
```
"#
)]
pub trait ReadingModel: Sync {
    /// Parameter names, in order.
    fn names(&self) -> &[String];

    /// The model evaluated at parameter values `p`, ready to predict poses.
    fn at<'a>(&'a self, p: &[f64]) -> Box<dyn PosePredictor + 'a>;

    /// The model whose design at zero decides which parameters the data can
    /// see, when that is not this model at the starting point: a model
    /// built on a calibrated machine keeps the rank rule of the nominal
    /// machine it was calibrated from (see
    /// [`GeometricModel::with_rank_reference`]). Default: none.
    fn rank_reference(&self) -> Option<&dyn ReadingModel> {
        None
    }

    /// A Gaussian prior on the parameters (a batch's, for a new machine of
    /// it): every fit of the model is then the maximum a posteriori
    /// estimate ([`Prior`]). Default: none.
    fn prior(&self) -> Option<Prior> {
        None
    }
}

/// A reading model at fixed parameter values.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
use tricept_engine::model::ReadingModel;
let pose = tricept_data::MeasuredPose { commands_mm: [800.0; 3], ..Default::default() };
let mut jac = vec![0.0; 45];
let mut seed = None;
let g = model.at(&[0.0; 15]).predict(&pose, &mut seed, &mut jac).unwrap();
assert_eq!(g, seed.unwrap().to_array());
```
"#
)]
pub trait PosePredictor: Sync {
    /// Readings `[phi, theta, s]` without offsets (rad, rad, mm) at `pose`,
    /// and their derivatives with respect to the parameters written
    /// row-major into `jacobian` (3 rows of `k`). `seed` is a nearby UP
    /// configuration when one is known (updated with the solution).
    fn predict(
        &self,
        pose: &MeasuredPose,
        seed: &mut Option<UpJoints>,
        jacobian: &mut [f64],
    ) -> Result<[f64; 3], KinematicsError>;
}

/// The paper's geometric model over a parameter set.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, model::ReadingModel};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let model = GeometricModel::new(Machine::paper(), ParameterSet::paper15());
assert_eq!(model.names()[0], "dxB1");
```
"#
)]
#[derive(Debug, Clone)]
pub struct GeometricModel {
    nominal: Machine,
    set: ParameterSet,
    rank_reference: Option<Box<GeometricModel>>,
    prior: Option<Prior>,
}

impl GeometricModel {
    /// The model of `nominal` with the errors of `set`.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::model::GeometricModel;
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let model = GeometricModel::new(Machine::paper(), ParameterSet::paper15());
assert_eq!(model.parameter_set().len(), 15);
```
"#
    )]
    pub fn new(nominal: Machine, set: ParameterSet) -> GeometricModel {
        GeometricModel {
            nominal,
            set,
            rank_reference: None,
            prior: None,
        }
    }

    /// The same model with a Gaussian prior on its parameters (its rank
    /// reference gets it too): every fit is then the maximum a posteriori
    /// estimate. A prior of another number of parameters is an
    /// [`IdentError::Invalid`].
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use nalgebra::DMatrix;
use tricept_engine::{model::GeometricModel, IdentifyOptions, prior::Prior, model::ReadingModel, identify};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant};
let m = Machine::paper();
let set = ParameterSet::paper15();
let data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&Campaign::random(&m, 8, 1))
    .unwrap();
// A batch that knows every parameter but dyA3 to 0.05 mm, centred on Table 2.
let covers: Vec<usize> = (0..15).filter(|&j| set.names()[j] != "dyA3").collect();
let prior = Prior::new(set.table2(), &covers, &DMatrix::from_diagonal_element(14, 14, 0.05f64.powi(2))).unwrap();
let model = GeometricModel::new(m.clone(), set.clone()).with_prior(prior).unwrap();
let id = identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
// Eight poses and the prior: the weak direction is known, dyA3 held.
assert_eq!(id.report.fixed, vec!["dyA3".to_string()]);
assert_eq!(id.prior_fit.unwrap().dof, 14);
```
"#
    )]
    pub fn with_prior(mut self, prior: Prior) -> Result<GeometricModel, IdentError> {
        if prior.parameters() != self.set.len() {
            return Err(IdentError::Invalid(format!(
                "a prior on {} parameters for a model of {}",
                prior.parameters(),
                self.set.len()
            )));
        }
        if let Some(r) = &mut self.rank_reference {
            r.prior = Some(prior.clone());
        }
        self.prior = Some(prior);
        Ok(self)
    }

    /// The same model, with the rank decision taken on `structural` (at
    /// zero errors) instead of on this model's machine at the starting
    /// point.
    ///
    /// A calibrated machine differs from its nominal one by the calibrated
    /// errors, and those break the symmetries that make a parameter
    /// invisible: on the x-first machine `dyA3` is invisible because B3
    /// lies on the fixed U-joint axis, and a calibrated `dyB3` of 0.27 mm
    /// moves it off that axis by just enough for `dyA3` to pass the rank
    /// tolerance with a standard deviation of metres. Identifying again
    /// against the calibrated machine must hold the same parameters as the
    /// first calibration did; the structure that decides it is the nominal
    /// machine's.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions, identify};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant};
let m = Machine::paper();
let set = ParameterSet::paper15();
let data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&Campaign::grid(&m, 1))
    .unwrap();
let options = IdentifyOptions::for_machine(&m);
let first = GeometricModel::new(m.clone(), set.clone());
let id = identify(&first, &data, &options).unwrap();
let calibrated = first.machine_at(&id.estimate);
// Against the calibrated machine, with the nominal one's rank rule:
let again = GeometricModel::new(calibrated, set.clone()).with_rank_reference(m.clone());
let id2 = identify(&again, &data, &options).unwrap();
assert_eq!(id2.report.fixed, vec!["dyA3".to_string()]);
```
"#
    )]
    pub fn with_rank_reference(mut self, structural: Machine) -> GeometricModel {
        let mut reference = GeometricModel::new(structural, self.set.clone());
        reference.prior = self.prior.clone();
        self.rank_reference = Some(Box::new(reference));
        self
    }

    /// The machine whose rank decision this model uses, when set by
    /// [`GeometricModel::with_rank_reference`].
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::model::GeometricModel;
use tricept_kinematics::Machine;
let model = GeometricModel::new(Machine::paper(), tricept_model::ParameterSet::paper15());
assert!(model.rank_reference_machine().is_none());
let model = model.with_rank_reference(Machine::paper());
assert!(model.rank_reference_machine().is_some());
```
"#
    )]
    pub fn rank_reference_machine(&self) -> Option<&Machine> {
        self.rank_reference.as_deref().map(|m| &m.nominal)
    }

    /// The nominal machine.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::model::GeometricModel;
use tricept_kinematics::Machine;
let model = GeometricModel::new(Machine::paper(), tricept_model::ParameterSet::paper15());
assert_eq!(model.nominal().leg_offsets_mm, [0.0; 3]);
```
"#
    )]
    pub fn nominal(&self) -> &Machine {
        &self.nominal
    }

    /// The parameter set.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::model::GeometricModel;
use tricept_model::ParameterSet;
let model = GeometricModel::new(tricept_kinematics::Machine::paper(), ParameterSet::full21());
assert_eq!(model.parameter_set().names()[0], "dxB1");
```
"#
    )]
    pub fn parameter_set(&self) -> &ParameterSet {
        &self.set
    }

    /// The machine described by parameter values `p`.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::model::GeometricModel;
use tricept_model::ParameterSet;
let set = ParameterSet::paper15();
let model = GeometricModel::new(tricept_kinematics::Machine::paper(), set.clone());
let m = model.machine_at(&set.table2());
// Table 2: the leg-length offsets dq1..dq3 are 0.45, 0.7, 0.5 mm.
assert_eq!(m.leg_offsets_mm, [0.45, 0.7, 0.5]);
```
"#
    )]
    pub fn machine_at(&self, p: &[f64]) -> Machine {
        actual_machine(&self.nominal, &self.set.to_errors(p))
    }
}

/// [`GeometricModel`] at fixed parameters: an exact machine and the
/// parameter set whose Jacobian columns it writes.
///
/// Extended models reuse it: [`GeometricPredictor::solve`] takes the
/// *actual* leg lengths (commands plus whatever an effect adds) and writes
/// the geometric columns into a wider Jacobian row.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::model::GeometricPredictor;
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let set = ParameterSet::paper15();
let g = GeometricPredictor::new(Machine::paper(), &set);
// 15 geometric columns in a row of width 17 (two more for an effect).
let mut jac = vec![0.0; 3 * 17];
let mut seed = None;
let (up, _) = g.solve(&[800.0; 3], &mut seed, &mut jac, 17).unwrap();
assert!(up.phi_rad.abs() < 1e-12);
assert_eq!(jac[15], 0.0); // the extra columns are left alone
```
"#
)]
pub struct GeometricPredictor<'a> {
    machine: Machine,
    set: &'a ParameterSet,
}

impl<'a> GeometricPredictor<'a> {
    /// The predictor of `machine` with the columns of `set`.
    pub fn new(machine: Machine, set: &'a ParameterSet) -> GeometricPredictor<'a> {
        GeometricPredictor { machine, set }
    }

    /// The exact machine it predicts with.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::model::GeometricPredictor;
let set = tricept_model::ParameterSet::paper15();
let g = GeometricPredictor::new(tricept_kinematics::Machine::paper(), &set);
assert_eq!(g.machine().leg_offsets_mm, [0.0; 3]);
```
"#
    )]
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// UP joints at actual leg lengths `legs_mm` (from `seed` when given),
    /// their leg geometry, and `J E` written into the first `k` entries of
    /// each of the three rows of `jacobian` (row stride `stride >= k`).
    pub fn solve(
        &self,
        legs_mm: &[f64; 3],
        seed: &mut Option<UpJoints>,
        jacobian: &mut [f64],
        stride: usize,
    ) -> Result<(UpJoints, LegGeometry), KinematicsError> {
        let up = solve_pose(&self.machine, legs_mm, seed)?;
        let geometry = self.machine.legs_at(&up);
        let j21 = error_jacobian_at(&geometry)?;
        let k = self.set.len();
        let mut block = [0.0; 3 * N_FULL];
        self.set
            .project(3, |row, f| j21[(row, f)], &mut block[..3 * k]);
        for c in 0..3 {
            jacobian[c * stride..c * stride + k].copy_from_slice(&block[c * k..(c + 1) * k]);
        }
        Ok((up, geometry))
    }
}

impl ReadingModel for GeometricModel {
    fn names(&self) -> &[String] {
        self.set.names()
    }

    fn at<'a>(&'a self, p: &[f64]) -> Box<dyn PosePredictor + 'a> {
        Box::new(GeometricPredictor::new(self.machine_at(p), &self.set))
    }

    fn rank_reference(&self) -> Option<&dyn ReadingModel> {
        self.rank_reference
            .as_deref()
            .map(|m| m as &dyn ReadingModel)
    }

    fn prior(&self) -> Option<Prior> {
        self.prior.clone()
    }
}

/// UP joints of `machine` at `commands`, from `seed` when given (falling
/// back to a cold start), updating the seed.
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let mut seed = None;
/// let up = tricept_engine::model::solve_pose(&m, &[800.0; 3], &mut seed).unwrap();
/// assert_eq!(seed, Some(up));
/// assert!(up.phi_rad.abs() < 1e-12);
/// ```
pub fn solve_pose(
    machine: &Machine,
    commands_mm: &[f64; 3],
    seed: &mut Option<UpJoints>,
) -> Result<UpJoints, KinematicsError> {
    let fk = match seed {
        Some(s) => machine
            .forward_from(commands_mm, s)
            .or_else(|_| machine.forward(commands_mm))?,
        None => machine.forward(commands_mm)?,
    };
    *seed = Some(fk.up);
    Ok(fk.up)
}

impl PosePredictor for GeometricPredictor<'_> {
    fn predict(
        &self,
        pose: &MeasuredPose,
        seed: &mut Option<UpJoints>,
        jacobian: &mut [f64],
    ) -> Result<[f64; 3], KinematicsError> {
        let k = self.set.len();
        let legs = if self.machine.leg_effects.is_zero() {
            pose.commands_mm
        } else {
            // The machine's static leg effects (a calibrated machine that a
            // diagnosis wrote) are known: the legs are the commands plus
            // them, with the gravity tension at the pose the plain geometry
            // reaches (a few um away, which changes the effect by 1e-5 of
            // itself).
            let mut probe = *seed;
            let up = solve_pose(&self.machine, &pose.commands_mm, &mut probe)?;
            let rate = static_leg_extra_per_mm(&self.machine, &up);
            let table = self.machine.leg_effects.table_extra_mm(&pose.commands_mm);
            std::array::from_fn(|i| pose.commands_mm[i] * (1.0 + rate[i]) + table[i])
        };
        let (up, _) = self.solve(&legs, seed, jacobian, k)?;
        Ok(up.to_array())
    }
}
