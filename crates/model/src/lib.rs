//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The geometric error model of the Tricept module (Hong 2009, section 1).
//!
//! - [`GeometricErrors`] and [`ParameterSet`]: the full 21-parameter vector
//!   `deps = [db_i; da_0i; dq_i]`, the paper's 15-parameter set
//!   ([`PAPER15_NAMES`](crate::params::PAPER15_NAMES)) and the linear map between them; Table 2 as a fixture.
//! - [`actual_machine`](crate::actual::actual_machine): nominal + errors, an exact [`tricept_kinematics::Machine`]
//!   from which simulated readings are computed.
//! - [`error_jacobian`](crate::jacobian::error_jacobian): the analytic `J = J1^{-1} J2` of eq. 9 for both
//!   U-joint conventions.
//! - [`point_error_jacobian`](crate::jacobian::point_error_jacobian): the same for any platform-fixed point (a
//!   tool tip, a tracker target).
//! - [`HeadParameterSet`](crate::head_errors::HeadParameterSet): the 13 error parameters of the 2-DOF head, exact
//!   and with the analytic Jacobian of any spindle point.
//! - [`volumetric_errors`](crate::volumetric::volumetric_errors): platform error maps (the paper's Fig. 3).
//! - [`residual_mu`](crate::params::residual_mu): the paper's residual error `mu` (Fig. 4).
//! - [`effects`]: the registry of the effects the geometric model leaves
//!   out (leg lead, backlash, thermal growth, sensor errors, class-2
//!   errors, compliance; one file and one spec each) and of the generic
//!   families, their names and their physics, shared by the simulator, the
//!   diagnosis and the fused identification.
//!
//! - [`ExtendedMachine`]: a calibrated machine's kinematics with the static
//!   leg effects (lead, compliance) a diagnosis named.
//! - [`plausibility`]: tables of plausible ranges with overrides, shared by
//!   the diagnosis and the fused identification.
//!
//! All lengths in mm, angles in rad.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

// Layers, bottom to top: a file imports only from its own layer or those
// below (`xtask/tests/tidy.rs` checks it).
// Layer 1: errors, parameters, plausible ranges
mod error;
pub mod params;
pub mod plausibility;
// Layer 2: the actual machine and the linearisations
pub mod actual;
pub mod head_errors;
pub mod jacobian;
pub mod volumetric;
// Layer 3: the effect registry
pub mod effects;
// Layer 4: a calibrated machine's kinematics with its effects
mod extended;

pub use error::ModelError;
pub use extended::ExtendedMachine;
pub use params::{GeometricErrors, ParameterSet};
