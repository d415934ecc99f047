//! The fitted model linearised at its estimate: what a further term could
//! still explain, without refitting.
//!
//! With `X` the weighted design of the fit (the three sensor offsets and
//! the identifiable parameters, `3n` rows in noise units), `X = Q R` its
//! thin QR and `t` a target (the weighted residuals, or a fitted term's
//! signature), the columns `G` of a candidate term explain
//!
//! ```text
//! S(G) = v^T M^+ v,   M = G^T G - (Q^T G)^T (Q^T G),   v = G^T t - (Q^T G)^T (Q^T t)
//! ```
//!
//! of `|t|^2`: the Rao score statistic, the linearised drop of chi-square
//! (its degrees of freedom the numerical rank of `M`). `Q` is never formed:
//! `Q^T G = R^-T (X^T G)`, with `R` folded from the design's rows a block
//! at a time (TSQR) and `X^T G` a sum over poses. What is kept per pose is
//! the design's three rows (`3 p` numbers), the three legs' weighted
//! directions and the target; every product above is accumulated over blocks of poses,
//! in parallel and summed in block order (the same bits at any thread
//! count). Generic terms are combinations of six per-pose directions (the
//! three legs through `W J1^-1 e_i`, the three readings through
//! `e_c / sigma_c`) times scalar functions of the pose, so every product
//! reduces to sums over poses of the directions' projections `X_j^T d`,
//! computed for a block of poses at a time ([`Linearisation::projections`]):
//! a period of the ball-screw scan costs a few hundred flops per pose.
//!
//! The files, bottom to top: the score from the three products and the
//! sums over poses it is built from (`score.rs`); the vector kernels that
//! sum element by element with the same bits at any vector width
//! (`kernels.rs`); the linearisation itself, its design, `R` and sums
//! over poses (`linearisation.rs`); a term's columns scored against it
//! (`columns.rs`); the one-pass scans of the period and step grids
//! (`scan.rs`); the comparison of column spaces (`subspace.rs`).

mod columns;
mod kernels;
mod linearisation;
mod scan;
mod score;
mod subspace;
#[cfg(test)]
mod tests;

pub(crate) use linearisation::Linearisation;
pub(crate) use subspace::{canonical_correlation, nested};
