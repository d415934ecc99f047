//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The identification engine of tricept: self-calibration of the Tricept from the UP limb's own sensors
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
//!   ballbar, touch-offs) and calibrates the head ([`fusion`]);
//! - pools campaigns of one machine, each with its own sensor offsets
//!   ([`tricept_data::MeasuredPose::campaign`]), and takes a batch's
//!   Gaussian prior on the parameters ([`Prior`]): the same fit, more rows.
//!
//! Parameter names are those of [`tricept_model::ParameterSet`]; lengths in
//! mm, angles in rad.
//!
//! This is the engine; users depend on `tricept-ident`, the door above it
//! (the engine, the diagnosis, the check and the study behind one API).
//!
//! # Example: simulated data and the compensation they give
//! ```
//! use tricept_engine::{compensation, identify, GeometricModel, IdentifyOptions};
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

pub mod accuracy;
mod campaigns;
pub mod compensate;
mod error;
mod evaluate;
pub mod fusion;
mod gauss_newton;
mod identify;
mod model;
mod options;
mod prior;
mod record;
mod report;
mod robust;
mod suspects;
mod table;
mod verdict;

pub use accuracy::cross_validation::{CrossValidation, cross_validate};
pub use accuracy::{
    AccuracyModel, DEFAULT_TOLERANCE_MM, PredictedAccuracy, WORTHWHILE_RATIO, accuracy_points,
};
pub use compensate::{Compensation, compensation, corrected_commands};
pub use error::IdentError;
pub use identify::{
    CampaignOffsets, Design, Identification, ResidualStats, Start, design, identifiability,
    identify, identify_from,
};
pub use model::{GeometricModel, GeometricPredictor, PosePredictor, ReadingModel, solve_pose};
pub use options::IdentifyOptions;
pub use prior::{Prior, PriorFit};
pub use record::{RECORD_METHODS, RecordError, RecordNotes, check_calibration_record};
pub use report::{Combination, CorrelatedPair, IdentifiabilityReport, NamedValues, Observability};
pub use robust::{
    Rejection, identify_robust, residuals_at, screen_gross_errors, screen_gross_errors_with_fit,
};
pub use suspects::{LikelyCause, likely_causes};
pub use table::{CompensationTable, MAX_TABLE_NODES, SPACING_LADDER_MM};
pub use verdict::{
    ADEQUACY_ALPHA, BARELY_SEEN_STD_DEV_MM, INCONSISTENT_CHI2_PER_DOF, LARGE_ESTIMATE_MM, Verdict,
};

// What a downstream crate needs besides this crate's own types, so that one
// dependency suffices: every crate whose types the public API takes or
// returns, and those types at the root. Found from rustdoc's JSON of this
// crate (`RUSTC_BOOTSTRAP=1 cargo rustdoc -p tricept-engine --lib -- -Z
// unstable-options --output-format json`: every `resolved_path` in a public
// item whose crate is not std); recheck it when a signature changes.
pub use nalgebra;
pub use serde_json;
pub use tricept_data;
pub use tricept_data::{
    BallbarData, DataError, Dataset, ExternalPose, Features, MeasuredPose, Readings, TouchData,
    TrackerData, read_from, read_path,
};
pub use tricept_kinematics;
pub use tricept_kinematics::{
    HeadBranch, KinematicsError, LegGeometry, Machine, MachineDescription, UpJoints, Workspace,
};
pub use tricept_model;
pub use tricept_model::effects::EffectName;
pub use tricept_model::{
    Effector, ErrorMap, ExtendedMachine, HeadParameterSet, MapStats, ModelError, ParameterSet,
};
