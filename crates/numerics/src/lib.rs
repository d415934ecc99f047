//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The generic numerical kernels the tricept crates share, in the spirit of
//! rust-analyzer's `stdx`: nothing here knows about a Tricept, and nothing
//! here is a stable API (the crate is internal: `publish = false`; the
//! public crates expose their own types).
//!
//! - [`linalg`]: dense linear algebra on `faer` (a streaming TSQR
//!   accumulator, QR and column-pivoted QR, SVD, triangular solves).
//! - [`lsq`]: rank-revealing weighted least squares with nuisance
//!   parameters: column scaling, numerical rank by SVD, the parameters to
//!   hold chosen by column-pivoted QR, covariance.
//! - [`stats`]: chi-square tail probabilities and quantiles, test power,
//!   sample quantiles.
//! - [`sparse`]: least squares with a block-arrow structure (pooled
//!   campaigns and batches) on faer's sparse Cholesky and QR, with a
//!   block-elimination fast path.
//! - [`roots`]: the one bracketing-and-bisection search every threshold in
//!   the project (a quantile, a non-centrality, an encoder grade) uses.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod linalg;
pub mod lsq;
pub mod roots;
pub mod sparse;
pub mod stats;
