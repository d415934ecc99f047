//! Least squares with a block-arrow structure, on faer's sparse core.
//!
//! Pooled problems (the campaigns of one machine, the machines of a batch)
//! have two kinds of unknowns: each block's own (*local*: a machine's
//! parameters and sensor offsets) and those every block shares (*global*:
//! the batch mean). Block `b`'s weighted rows touch only its locals and the
//! globals:
//!
//! ```text
//!          locals 1   locals 2   ...   globals | rhs
//!        [   A_1                        G_1    | b_1 ]
//!        [             A_2              G_2    | b_2 ]
//!        [                        ...   ...    | ... ]
//! ```
//!
//! so `J^T J` is block-arrow: a dense square per block, the globals'
//! square, and their couplings. [`BlockProblem::solve`] solves it four
//! ways, which agree to rounding (the tests hold them to 1e-9 relative):
//!
//! - [`SolverKind::Schur`], the fast path: each block's rows are reduced by
//!   a dense QR to `[R11 R12 | r1]` over its locals and a tail `[R22 | r2]`
//!   over the globals (the Schur complement in square-root form, never the
//!   normal equations); the tails are stacked into the globals' factor,
//!   which is solved, then every block by back substitution. Work and
//!   memory are linear in the blocks ([`ReducedBlock`] keeps a block in
//!   `O((l + g)^2)`, whatever its rows).
//! - [`SolverKind::SparseCholesky`]: faer's sparse Cholesky (AMD ordering,
//!   supernodal or simplicial as faer decides) of `J^T J` scaled to a unit
//!   diagonal, then two steps of refinement with the residual of `J`
//!   itself (the normal equations square the condition number: on a
//!   batch's joint fit the plain solve differs from the QR-based ones by
//!   6e-4 of a parameter's value, refined by the QR's rounding).
//! - [`SolverKind::SparseQr`]: faer's sparse QR (COLAMD ordering) of `J`
//!   with unit-norm columns; it gives the solution, not the covariance.
//! - [`SolverKind::Dense`]: the streaming Householder QR
//!   ([`crate::linalg::TriangularAccumulator`]) of the dense `J`, locals
//!   first: the reference on problems small enough for it.
//!
//! **No silent fill.** A column that the rows do not determine (its part
//! independent of the columns before it, `|R_ii|`, below
//! [`DEPENDENT_COLUMN`] of its norm; a zero column) is an error naming the
//! block and column ([`BlockError::NotDetermined`]), never a number: the
//! caller decides which unknowns the data cannot see (a rank decision on
//! the pooled information, [`crate::lsq`]) and leaves them out. The Schur
//! and dense paths test every pivot; faer's sparse factorisations do not
//! pivot for rank (its QR returned -1.3e12 mm for a batch mean no reading
//! sees), so the sparse kinds run the block elimination's tests first
//! (a fraction of their own cost) and test for a factorisation that fails
//! or a solution that is not finite.

mod general;
mod problem;
mod schur;
mod solve;
#[cfg(test)]
mod tests;

pub use problem::{
    BlockError, BlockProblem, BlockSolution, DEPENDENT_COLUMN, RowBlock, SolveStats, SolverKind,
};
pub use schur::{ReducedBlock, solve_globals};
