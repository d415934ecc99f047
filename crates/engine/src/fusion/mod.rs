//! Fusing the self-calibration with a few external measurements, and
//! calibrating the head.
//!
//! The UP limb's sensors cannot see the head at all, nor the machine's
//! scale when leg-lead and scale-gain are modelled, and they see one
//! combination (all three leg lengths together) only weakly. A laser
//! tracker, a ballbar or touch-offs on reference features measure the tool
//! (or a point in the spindle) from outside. [`identify_fused`] fits the
//! module's parameters, the effects a diagnosis named, the head's 13
//! parameters ([`tricept_model::head_errors::HeadParameterSet`]) and every instrument's
//! nuisance parameters in one weighted least-squares problem on the exact
//! model, each source with its own noise, and reports what each source and
//! their union can see ([`FusionReport`]) and how uncertain the tool tip
//! is.
//!
//! - [`FusedModel`]: the global parameters `[module | effects | head]`.
//! - [`Source`]: one data source; `Source::internal`, `Source::tracker`,
//!   `Source::ballbar`, `Source::touch`.
//! - [`identify_fused`] and its result [`Fusion`]: each source's
//!   redundancy and whether it can check the fit, the verdict, the records
//!   the gross-error screen rejected ([`ScreenOptions`]), the estimates
//!   outside their plausible range ([`FusionPlausibility`]) and the likely
//!   causes tested by refitting ([`FusionCause`]).
//!
//! Lengths in mm, angles in rad, instrument noise in um.
//!
//! The fusion lives in the engine rather than a crate of its own because
//! it *is* the identification with more row blocks: it shares the solver
//! core, the rank rule, the report type and the iteration, and with the
//! internal data alone it reproduces [`crate::identify`](fn@crate::identify) bit for bit
//! (tested; up to one evaluation block of 4096 poses, beyond which
//! `identify`'s parallel blocks merge the same rows in another order, equal
//! to rounding). A separate crate would have had to make those internals
//! public.

mod ballbar;
mod causes;
mod design;
mod estimate;
mod identify;
mod internal;
mod model;
mod options;
mod plausibility;
mod report;
mod result;
mod screen;
mod source;
mod touch;
mod tracker;

pub use ballbar::BallbarOptions;
pub use design::{DesignRows, design_rows, information, information_factor};
pub use identify::identify_fused;
pub use model::{FusedModel, fusable_effects};
pub use options::{FusionOptions, ScreenOptions, evaluation_poses, head_angle_poses};
pub use plausibility::{FusionPlausibility, HEAD_RANGE_TYPICAL_SIZES, Implausible};
pub use report::{
    FusionReport, HARMLESS_AXIS_ARCSEC, MadeVisible, NamedQuantity, SourceVisibility, TipImpact,
    ToolAxisPrediction, ToolTipPrediction,
};
pub use result::{Fusion, FusionCause, FusionVerdict, RejectedRecord, SourceFit};
pub use source::{Source, SourceKind, TrackerTarget};
pub use touch::TouchOptions;
pub use tracker::TrackerOptions;
