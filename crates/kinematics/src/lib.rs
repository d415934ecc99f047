//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! Exact kinematics of the Tricept: the 3-UPS + UP parallel module and its
//! 2-DOF head.
//!
//! ```text
//!            base  B1   B2   B3        B4 (origin: the UP limb's U joint)
//!                   \    |    /        |
//!   UPS legs 1..3    q1  q2  q3        q4   UP limb (passive, sensed:
//!                     \  |  /          |     encoders phi, theta; scale q4)
//!          platform    A1 A2 A3 ------ O'
//!                              2-DOF head -> tool tip, tool axis
//! ```
//!
//! The UP limb alone fixes the platform's orientation: `r = q4 R e_z` with
//! `R = Rx(phi) Ry(theta)` for the paper's x-first U joint (eq. 8). The legs
//! close the loops `r = b_i + q_i w_i - R a_0i` (eq. 1).
//!
//! - [`Machine::inverse`]: platform point to leg commands and UP joints (closed form).
//! - [`Machine::forward`]: leg commands to the UP joints, O' and `R` (safeguarded
//!   Newton on the paper's `J1`), with a condition number and typed errors.
//! - [`Machine::tool_inverse`] / [`Machine::tool_forward`]: the 5-DOF tool pose.
//! - [`Workspace`]: the Table 1 cylinder and seeded pose sampling.
//! - [`MachineDescription`]: the JSON file format (`fixtures/machines/*.json`).
//!
//! Units: mm and rad everywhere; names carry their unit.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod batch;
pub mod description;
pub mod error;
pub mod fk;
pub mod head;
pub mod machine;
pub mod units;
pub mod up_limb;
pub mod workspace;

pub use description::MachineDescription;
pub use error::KinematicsError;
pub use machine::Machine;
pub use workspace::Workspace;
