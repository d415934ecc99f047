//! Self-calibration of the Tricept from the UP limb's own sensors
//! (Hong 2009, sections 2-3), done as a numerical-software engineer would.
//!
//! The UP limb carries two encoders (`phi`, `theta`) and a linear scale
//! (`s`), each with an unknown zero offset. Given logged readings at known
//! leg commands ([`tricept_data::Dataset`]), this crate
//!
//! - builds the weighted identification matrix of eqs. 10-11 from the
//!   analytic Jacobian (`J E`, [`GeometricModel`]), with the three offsets as
//!   unknowns ([`identify`] explains why that beats the paper's differencing);
//! - reveals its rank with column scaling, column-pivoted QR and the SVD on
//!   `faer`, and writes what cannot be identified as named
//!   combinations ([`IdentifiabilityReport`]), with the observability
//!   indices O1-O5;
//! - refines on the exact model by Gauss-Newton ([`identify`]), with
//!   standard deviations from the covariance;
//! - says whether the result can be trusted ([`Verdict`]: converged,
//!   adequate, warnings) and, for data that cannot come from the machine,
//!   which usual mistake explains them ([`likely_causes`]);
//! - compensates: corrected commands from the identified machine, the
//!   volumetric error before and after ([`compensation`]), and a table of
//!   leg-command corrections for a controller ([`CompensationTable`]);
//! - fuses the internal data with external measurements (laser tracker,
//!   ballbar, touch-offs) and calibrates the head ([`fusion`]).
//!
//! Parameter names are those of [`tricept_model::ParameterSet`]; lengths in
//! mm, angles in rad.
//!
//! One dependency suffices: the crate re-exports the data reader
//! ([`read_path`], [`Dataset`]), the machine ([`Machine`],
//! [`MachineDescription`], [`ExtendedMachine`]) and the parameter sets
//! ([`ParameterSet`]); `examples/downstream` in the repository is a crate
//! built on it alone.
//!
//! # Example: calibrating from a measured file
//! ```
//! use tricept_ident::{GeometricModel, IdentifyOptions, Machine, ParameterSet, identify_robust, read_path};
//!
//! let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
//! let data = read_path(file.as_ref())?;
//! let machine = Machine::paper();
//! let model = GeometricModel::new(machine.clone(), ParameterSet::paper15());
//! let (id, rejected) = identify_robust(&model, &data, &IdentifyOptions::for_machine(&machine))?;
//! // Trust the result only if the fit converged and the model explains the
//! // data to the sensor noise; otherwise the warnings say why.
//! let verdict = id.verdict();
//! assert!(verdict.converged && verdict.adequate, "{:?}", verdict.warnings);
//! assert!(rejected.is_empty());
//! // The calibrated machine's leg commands for a target (mm).
//! let calibrated = model.machine_at(&id.estimate);
//! let q = calibrated.inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0))?.legs_mm;
//! assert!((q[1] - machine.inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0))?.legs_mm[1] + 0.6).abs() < 0.3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Example: simulated data and the compensation they give
//! ```
//! use tricept_ident::{compensation, identify, GeometricModel, IdentifyOptions};
//! use tricept_kinematics::Machine;
//! use tricept_model::ParameterSet;
//! use tricept_plant::{Campaign, Plant};
//!
//! let nominal = Machine::paper();
//! let set = ParameterSet::paper15();
//! // Data as a machine would log it (here simulated from Table 2's errors).
//! let plant = Plant::geometric(nominal.clone(), set.to_errors(&set.table2()));
//! let data = plant.simulate(&Campaign::grid(&nominal, 42)).unwrap();
//!
//! let model = GeometricModel::new(nominal.clone(), set.clone());
//! let id = identify(&model, &data, &IdentifyOptions::for_machine(&nominal)).unwrap();
//! println!("{}", id.report.to_text());
//!
//! let identified = model.machine_at(&id.estimate);
//! let targets = nominal.workspace.disc_grid(nominal.workspace.mid_plane_z_mm(), 50.0);
//! let c = compensation(&nominal, &identified, &plant.actual_machine(), &targets).unwrap();
//! assert!(c.after.stats().max_mm < 0.2 * c.before.stats().max_mm);
//! ```
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

mod accuracy;
mod compensate;
mod error;
pub mod fusion;
mod gauss_newton;
mod identify;
mod model;
mod record;
mod report;
mod robust;
mod suspects;
mod table;
mod verdict;

pub use accuracy::{AccuracyModel, DEFAULT_TOLERANCE_MM, PredictedAccuracy, WORTHWHILE_RATIO};
pub use compensate::{Compensation, compensation, corrected_commands};
pub use error::IdentError;
pub use identify::{
    Design, Identification, IdentifyOptions, ResidualStats, Start, design, identifiability,
    identify, identify_from,
};
pub use model::{GeometricModel, GeometricPredictor, PosePredictor, ReadingModel, solve_pose};
pub use record::{RECORD_METHODS, RecordError, check_calibration_record};
pub use report::{Combination, CorrelatedPair, IdentifiabilityReport, NamedValues, Observability};
pub use robust::{Rejection, identify_robust, residuals_at, screen_gross_errors};
pub use suspects::{LikelyCause, likely_causes};
pub use table::{CompensationTable, MAX_TABLE_NODES, SPACING_LADDER_MM};
pub use verdict::{
    ADEQUACY_ALPHA, BARELY_SEEN_STD_DEV_MM, INCONSISTENT_CHI2_PER_DOF, LARGE_ESTIMATE_MM, Verdict,
};

// What a downstream crate needs besides this crate's own types, so that one
// dependency suffices: the data set and its reader, the machine, the
// parameter sets.
pub use tricept_data::{DataError, Dataset, MeasuredPose, Readings, read_from, read_path};
pub use tricept_kinematics::{Machine, MachineDescription};
pub use tricept_model::{ExtendedMachine, ParameterSet};
