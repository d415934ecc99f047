//! The door's pages of the reading models a fit evaluates (the geometric
//! model and what predicts one pose's readings), re-exported by
//! [`crate::diagnosis`]: kept here so the workflow module stays short.

/// The geometric model extended by terms: effects of the vocabulary and
/// generic terms, their parameters after the geometry's.
///
/// # Example
/// ```
/// use tricept_ident::advanced::ParameterSet;
/// use tricept_ident::diagnosis::{ExtendedModel, GeometricModel, ReadingModel};
/// use tricept_ident::effects::EffectName;
/// use tricept_ident::kinematics::GeometricMachine;
/// let geometric = GeometricModel::new(GeometricMachine::paper(), ParameterSet::paper15());
/// let model = ExtendedModel::new(geometric, &[EffectName::LegLead]);
/// assert_eq!(model.n_geometric(), 15);
/// assert_eq!(model.offsets(), [15]); // the three leads follow the geometry
/// assert_eq!(model.names().len(), 15 + 3);
/// assert_eq!(model.effects(), [EffectName::LegLead]);
/// ```
#[doc(inline)]
pub use tricept_diagnose::ExtendedModel;
/// One campaign's sensor zero offsets `[phi, theta, s]` (rad, rad, mm)
/// with their standard deviations, when a fit pools several campaigns.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// for id in result.batch().machines.iter().filter_map(|m| m.own.id.as_ref()) {
///     // one file, one campaign: its offsets are the fit's
///     assert_eq!(id.campaign_offsets.len(), 1);
///     assert_eq!(id.campaign_offsets[0].offsets, id.offsets);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::identify::CampaignOffsets;
/// The residuals of a fit: their RMS per channel (rad, rad, mm), the
/// chi-square with its degrees of freedom and their ratio, the largest
/// standardised residual.
///
/// # Example
/// ```no_run
/// use tricept_ident::fleet::{FleetRequest, fleet};
/// let result = fleet(FleetRequest::new(vec!["m1.csv".into(), "m2.csv".into(), "m3.csv".into()]))?;
/// for id in result.batch().machines.iter().filter_map(|m| m.own.id.as_ref()) {
///     let stats = &id.stats;
///     let ratio = stats.chi_square / stats.dof as f64;
///     assert!((stats.reduced_chi_square - ratio).abs() <= 1e-9 * ratio.max(1.0));
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::identify::ResidualStats;
/// The paper's geometric model of a machine over a parameter set: the
/// readings a pose gives as functions of the set's error parameters.
///
/// # Example
/// ```
/// use tricept_ident::advanced::ParameterSet;
/// use tricept_ident::diagnosis::{GeometricModel, ReadingModel};
/// use tricept_ident::kinematics::GeometricMachine;
/// let model = GeometricModel::new(GeometricMachine::paper(), ParameterSet::paper15());
/// assert_eq!(model.names().len(), 15);
/// assert_eq!(model.names()[0], "dxB1");
/// ```
#[doc(inline)]
pub use tricept_engine::model::GeometricModel;
/// The geometric model's predictor: a machine with the columns of a
/// parameter set ([`GeometricModel`] at given values is one).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{MeasuredPose, ParameterSet};
/// use tricept_ident::diagnosis::{GeometricModel, GeometricPredictor, PosePredictor, ReadingModel};
/// use tricept_ident::kinematics::GeometricMachine;
/// let set = ParameterSet::paper15();
/// let direct = GeometricPredictor::new(GeometricMachine::paper(), &set);
/// let model = GeometricModel::new(GeometricMachine::paper(), set.clone());
/// let pose = MeasuredPose { commands_mm: [800.0, 820.0, 790.0], ..Default::default() };
/// let (mut j1, mut j2) = ([0.0; 45], [0.0; 45]);
/// let a = direct.predict(&pose, &mut None, &mut j1)?;
/// let b = model.at(&[0.0; 15]).predict(&pose, &mut None, &mut j2)?;
/// assert!((0..3).all(|i| (a[i] - b[i]).abs() < 1e-12));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_engine::model::GeometricPredictor;
/// A reading model at given parameter values: one pose's readings
/// `[phi, theta, s]` (rad, rad, mm) and their derivatives (3 rows of one
/// column per parameter).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{MeasuredPose, ParameterSet};
/// use tricept_ident::diagnosis::{GeometricModel, PosePredictor, ReadingModel};
/// use tricept_ident::kinematics::GeometricMachine;
/// let model = GeometricModel::new(GeometricMachine::paper(), ParameterSet::paper15());
/// let predictor: Box<dyn PosePredictor + '_> = model.at(&[0.0; 15]);
/// let pose = MeasuredPose { commands_mm: [800.0, 820.0, 790.0], ..Default::default() };
/// let mut jacobian = [0.0; 45];
/// let readings = predictor.predict(&pose, &mut None, &mut jacobian)?;
/// assert!(readings.iter().chain(&jacobian).all(|v| v.is_finite()));
/// assert!(jacobian.iter().any(|d| *d != 0.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_engine::model::PosePredictor;
/// A model of the UP limb's readings over named parameters: evaluated at
/// parameter values it predicts poses ([`PosePredictor`]).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{MeasuredPose, ParameterSet};
/// use tricept_ident::diagnosis::{GeometricModel, ReadingModel};
/// use tricept_ident::kinematics::{GeometricMachine, Vector3};
/// let machine = GeometricMachine::paper();
/// let ik = machine.inverse(&Vector3::new(40.0, -30.0, 760.0))?;
/// let model: &dyn ReadingModel = &GeometricModel::new(machine, ParameterSet::paper15());
/// let pose = MeasuredPose { commands_mm: ik.legs_mm, ..Default::default() };
/// let mut jacobian = vec![0.0; 3 * model.names().len()];
/// let nominal = model.at(&vec![0.0; 15]).predict(&pose, &mut None, &mut jacobian)?;
/// assert!((nominal[0] - ik.up.phi_rad).abs() < 1e-9); // no error: the nominal joints
/// assert!((nominal[1] - ik.up.theta_rad).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_engine::model::ReadingModel;
/// A Gaussian prior on some of a model's parameters (a fleet's batch
/// prior): its mean and covariance over the parameters it covers.
///
/// # Example
/// ```
/// use tricept_ident::calibrate::DMatrix;
/// use tricept_ident::diagnosis::Prior;
/// let covariance = DMatrix::from_row_slice(2, 2, &[0.01, 0.0, 0.0, 0.04]);
/// let prior = Prior::new(vec![0.1, 0.0, 0.3], &[0, 2], &covariance)?;
/// assert_eq!((prior.dimension(), prior.parameters()), (2, 3));
/// // (0.2 - 0.1)^2 / 0.01 + (0.1 - 0.3)^2 / 0.04 = 1 + 1; parameter 1 not covered
/// assert!((prior.chi_square(&[0.2, 5.0, 0.1]) - 2.0).abs() < 1e-12);
/// let not_spd = DMatrix::from_row_slice(2, 2, &[0.01, 0.0, 0.0, -0.04]);
/// assert!(Prior::new(vec![0.1, 0.0, 0.3], &[0, 2], &not_spd).is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_engine::prior::Prior;
/// A prior's share of a fit: its chi-square at the estimate and its degrees
/// of freedom (the parameters it covers).
///
/// # Example
/// ```
/// use tricept_ident::calibrate::DMatrix;
/// use tricept_ident::diagnosis::{Prior, PriorFit};
/// let prior = Prior::new(vec![0.0; 2], &[0, 1], &DMatrix::identity(2, 2))?;
/// let estimate = [3.0, 4.0];
/// let share = PriorFit { chi_square: prior.chi_square(&estimate), dof: prior.dimension() };
/// assert_eq!(serde_json::to_value(share)?, serde_json::json!({"chi_square": 25.0, "dof": 2}));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_engine::prior::PriorFit;
