//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! Has the machine changed? A quick check of a calibrated Tricept from its
//! own sensors.
//!
//! Self-calibration needs no external instrument, so a machine can be
//! checked every day or every shift: a few poses, the UP limb's two
//! encoders and its scale, tested against what the calibrated machine
//! predicts, with the calibration's own uncertainty and the sensors'
//! noise. A crash, a slipped encoder or coupling, a loosened joint, a worn
//! screw segment or a machine that has not warmed up shows as readings the
//! calibrated model cannot explain; a re-referenced sensor (a power cycle)
//! does not, since the offsets are re-estimated at every check.
//!
//! - [`Reference`] (`reference.rs`): the calibrated machine with its
//!   covariance, offsets and temperature, from a machine file's
//!   `calibration` record;
//! - [`check`](fn@check) (`check.rs`): the test, the verdict, the most likely change
//!   with its size, uncertainty and effect on the platform, the shortlist
//!   of changes the campaign cannot tell apart;
//! - [`Candidate`](crate::candidates::Candidate) (`candidates.rs`): what can have changed;
//! - [`Change`](crate::changes::Change) (`changes.rs`): the smallest set of changes that explains
//!   the readings, by a forward search;
//! - [`history`] (`history.rs`): checks appended to a JSON-lines file, and
//!   the trend of the key quantities against their bands;
//! - `noise.rs`: noise is not a change (a candidate must stand out beyond
//!   the scatter the readings show; the `noisier-than-stated` verdict);
//! - `screen.rs`: gross readings set aside by their line, the verdict from
//!   the rest (`design.rs` keeps the whitened rows both need);
//! - `report.rs`: the report as text.
//!
//! What a check cannot see: the head (it moves none of the UP limb's
//! sensors; checking it needs an external measurement), and a change of
//! all three legs by the same length, which moves the platform along the
//! scale's axis and reads as a zero jump of the scale (the weak combination
//! of the self-calibration itself; docs/check.md).
//!
//! # Example
//! ```
//! use tricept_check::{CheckOptions, Reference, check};
//! use tricept_kinematics::Machine;
//! use tricept_model::ParameterSet;
//! use tricept_plant::{Campaign, Plant};
//! let m = Machine::paper();
//! let set = ParameterSet::paper15();
//! let reference = Reference::new(m.clone(), set.clone(), nalgebra::DMatrix::zeros(15, 15), [0.0; 3], None).unwrap();
//! let data = Plant::geometric(m.clone(), set.to_errors(&[0.0; 15]))
//!     .simulate(&Campaign::random(&m, 20, 3))
//!     .unwrap();
//! let report = check(&reference, &data, &CheckOptions::for_machine(&m)).unwrap();
//! assert!(!report.changed);
//! println!("{}", report.to_text());
//! ```
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod candidates;
pub mod changes;
pub mod check;
mod design;
mod error;
pub mod history;
pub mod noise;
pub mod parts;
mod reference;
mod report;
pub mod screen;

pub use check::{CheckOptions, CheckReport, CheckVerdict};
pub use error::CheckError;
pub use reference::Reference;
pub use screen::check;
