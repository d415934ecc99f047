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
//!   analytic Jacobian (`J E`, [`GeometricModel`](crate::model::GeometricModel)), with the three offsets as
//!   unknowns ([`identify`](fn@identify) explains why that beats the paper's differencing);
//! - reveals its rank with column scaling, column-pivoted QR and the SVD on
//!   `faer`, and writes what cannot be identified as named
//!   combinations ([`IdentifiabilityReport`](crate::report::IdentifiabilityReport)), with the observability
//!   indices O1-O5;
//! - refines on the exact model by Gauss-Newton ([`identify`](fn@identify)), with
//!   standard deviations from the covariance;
//! - says whether the result can be trusted ([`Verdict`](crate::verdict::Verdict): converged,
//!   adequate, warnings) and, for data that cannot come from the machine,
//!   which usual mistake explains them ([`likely_causes`](crate::suspects::likely_causes));
//! - compensates: corrected commands from the identified machine, the
//!   volumetric error before and after ([`compensation`](crate::compensate::compensation)), and a table of
//!   leg-command corrections for a controller ([`CompensationTable`](crate::table::CompensationTable));
//! - fuses the internal data with external measurements (laser tracker,
//!   ballbar, touch-offs) and calibrates the head ([`fusion`]);
//! - pools campaigns of one machine, each with its own sensor offsets
//!   ([`tricept_data::MeasuredPose::campaign`]), and takes a batch's
//!   Gaussian prior on the parameters ([`Prior`](crate::prior::Prior)): the same fit, more rows.
//!
//! Parameter names are those of [`tricept_model::ParameterSet`]; lengths in
//! mm, angles in rad.
//!
//! This is the engine; users depend on `tricept-ident`, the door above it
//! (the engine, the diagnosis, the check and the study behind one API).
//!
//! # Example: simulated data and the compensation they give
//! ```
//! use tricept_engine::{compensate::compensation, identify, model::GeometricModel, IdentifyOptions};
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
pub mod identify;
pub mod model;
mod options;
pub mod prior;
pub mod record;
pub mod report;
pub mod robust;
pub mod suspects;
pub mod table;
pub mod verdict;

pub use error::IdentError;
pub use identify::{Identification, identify};
pub use options::IdentifyOptions;
