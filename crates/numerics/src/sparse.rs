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

use std::time::Instant;

use faer::linalg::solvers::{Solve, SolveLstsq};
use faer::sparse::linalg::solvers::{Llt, Qr, SymbolicLlt, SymbolicQr};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, MatRef, Side};

use crate::linalg::{TriangularAccumulator, invert_upper, r_factor, solve_upper};

/// Steps of iterative refinement after the sparse Cholesky solve.
const REFINEMENT_STEPS: usize = 2;

/// A pivot `|R_ii|` below this fraction of its column's norm means the
/// column is (to working precision) a combination of the columns before
/// it: the rows do not determine that unknown.
pub const DEPENDENT_COLUMN: f64 = 1e-10;

/// One block's weighted rows: `[local | global | rhs]`.
///
/// # Example
/// ```
/// use faer::Mat;
/// use tricept_numerics::sparse::RowBlock;
/// // Two rows, one local unknown, one global, the right-hand side.
/// let b = RowBlock::new(1, Mat::from_fn(2, 3, |i, j| [[1.0, 1.0, 3.0], [1.0, -1.0, 1.0]][i][j]));
/// assert_eq!(b.rows.nrows(), 2);
/// ```
#[derive(Debug, Clone)]
pub struct RowBlock {
    /// Number of local unknowns (the first columns).
    pub n_local: usize,
    /// The rows, `n_local + n_global + 1` columns.
    pub rows: Mat<f64>,
}

impl RowBlock {
    /// A block of `rows` whose first `n_local` columns are its own.
    pub fn new(n_local: usize, rows: Mat<f64>) -> RowBlock {
        RowBlock { n_local, rows }
    }
}

/// A block-arrow least-squares problem (module docs).
///
/// # Example
/// ```
/// use faer::Mat;
/// use tricept_numerics::sparse::{BlockProblem, RowBlock, SolverKind};
/// // y = a_b + m for two blocks b with offsets a_b, and the shared m seen
/// // alone by a third block of rows: a_1 = 1, a_2 = 2, m = 3.
/// let rows = |v: &[[f64; 3]]| Mat::from_fn(v.len(), 3, |i, j| v[i][j]);
/// let p = BlockProblem {
///     n_global: 1,
///     blocks: vec![
///         RowBlock::new(1, rows(&[[1.0, 1.0, 4.0], [1.0, 1.0, 4.0]])),
///         RowBlock::new(1, rows(&[[1.0, 1.0, 5.0]])),
///         RowBlock::new(0, Mat::from_fn(1, 2, |_, j| [1.0, 3.0][j])),
///     ],
/// };
/// for kind in SolverKind::ALL {
///     let s = p.solve(kind).unwrap();
///     assert!((s.global[0] - 3.0).abs() < 1e-12, "{kind:?}");
///     assert!((s.local[1][0] - 2.0).abs() < 1e-12, "{kind:?}");
/// }
/// ```
#[derive(Debug, Clone, Default)]
pub struct BlockProblem {
    /// Number of global unknowns.
    pub n_global: usize,
    /// The blocks, in order.
    pub blocks: Vec<RowBlock>,
}

/// Which factorisation solves a [`BlockProblem`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverKind {
    /// Block elimination (QR per block, then the globals): the fast path.
    Schur,
    /// faer's sparse Cholesky of the scaled normal equations.
    SparseCholesky,
    /// faer's sparse QR of the scaled Jacobian.
    SparseQr,
    /// Dense streaming QR: small problems only.
    Dense,
}

impl SolverKind {
    /// Every kind, the fast path first.
    pub const ALL: [SolverKind; 4] = [
        SolverKind::Schur,
        SolverKind::SparseCholesky,
        SolverKind::SparseQr,
        SolverKind::Dense,
    ];

    /// The kind's name in reports (`schur`, `sparse-cholesky`, `sparse-qr`,
    /// `dense`).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::sparse::SolverKind;
    /// assert_eq!(SolverKind::SparseCholesky.name(), "sparse-cholesky");
    /// assert_eq!("sparse-qr".parse::<SolverKind>(), Ok(SolverKind::SparseQr));
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::Schur => "schur",
            SolverKind::SparseCholesky => "sparse-cholesky",
            SolverKind::SparseQr => "sparse-qr",
            SolverKind::Dense => "dense",
        }
    }
}

impl std::str::FromStr for SolverKind {
    type Err = String;

    fn from_str(s: &str) -> Result<SolverKind, String> {
        SolverKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                format!("unknown solver `{s}`: schur, sparse-cholesky, sparse-qr or dense")
            })
    }
}

/// Why a block problem has no solution to report.
#[derive(Debug, Clone, PartialEq)]
pub enum BlockError {
    /// The rows do not determine an unknown: local `column` of `block`, or
    /// global `column` when `block` is `None`.
    NotDetermined {
        /// The block (`None`: a global unknown).
        block: Option<usize>,
        /// The column within the block's locals, or the global's index.
        column: usize,
    },
    /// A factorisation failed or gave a non-finite solution.
    Factorisation(String),
    /// Blocks whose widths do not match the problem.
    Shape(String),
}

impl std::fmt::Display for BlockError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BlockError::NotDetermined {
                block: Some(b),
                column,
            } => write!(
                f,
                "local unknown {column} of block {b} is not determined by the rows"
            ),
            BlockError::NotDetermined {
                block: None,
                column,
            } => write!(f, "global unknown {column} is not determined by the rows"),
            BlockError::Factorisation(what) => write!(f, "the factorisation failed: {what}"),
            BlockError::Shape(what) => write!(f, "{what}"),
        }
    }
}

impl std::error::Error for BlockError {}

/// What a solve cost: the `solver` object of a pooled fit's report.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveStats {
    /// The factorisation used.
    pub kind: SolverKind,
    /// Unknowns (every block's locals and the globals).
    pub unknowns: usize,
    /// Non-zero entries of the weighted Jacobian `J`.
    pub nonzeros: usize,
    /// Rows of `J`.
    pub rows: usize,
    /// Wall time of the solve, s.
    pub seconds: f64,
}

/// The solution of a [`BlockProblem`].
#[derive(Debug, Clone)]
pub struct BlockSolution {
    /// The global unknowns.
    pub global: Vec<f64>,
    /// Each block's local unknowns.
    pub local: Vec<Vec<f64>>,
    /// Covariance of the globals, `(J^T J)^-1` restricted to them (`None`
    /// for the sparse QR, which gives solutions only).
    pub global_covariance: Option<Mat<f64>>,
    /// `|J x - b|^2` at the solution.
    pub residual_norm2: f64,
    /// What the solve cost.
    pub stats: SolveStats,
}

/// One block reduced by its QR: `[R11 R12 | r1]` over its locals and the
/// tail `[R22 | r2; 0 | rho]` over the globals (module docs).
///
/// # Example
/// ```
/// use faer::Mat;
/// use tricept_numerics::sparse::{ReducedBlock, RowBlock};
/// // x_local + x_global = 2 and x_local - x_global = 0, twice each.
/// let rows = Mat::from_fn(4, 3, |i, j| [[1.0, 1.0, 2.0], [1.0, -1.0, 0.0]][i % 2][j]);
/// let r = ReducedBlock::new(&RowBlock::new(1, rows), 1, 0).unwrap();
/// assert!((r.local_solution(&[1.0])[0] - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone)]
pub struct ReducedBlock {
    r11: Mat<f64>,
    r12: Mat<f64>,
    r1: Vec<f64>,
    tail: Mat<f64>,
}

impl ReducedBlock {
    /// Reduces `block` (block number `index`, for errors) of a problem with
    /// `n_global` globals; a local column the block's rows do not
    /// determine is [`BlockError::NotDetermined`].
    pub fn new(
        block: &RowBlock,
        n_global: usize,
        index: usize,
    ) -> Result<ReducedBlock, BlockError> {
        let l = block.n_local;
        let w = l + n_global + 1;
        if block.rows.ncols() != w {
            return Err(BlockError::Shape(format!(
                "block {index} has {} columns for {l} locals, {n_global} globals and the right-hand side",
                block.rows.ncols()
            )));
        }
        let r = r_factor(block.rows.as_ref());
        for j in 0..l {
            let norm = column_norm(block.rows.as_ref(), j);
            if !(r[(j, j)].abs() > DEPENDENT_COLUMN * norm && norm > 0.0) {
                return Err(BlockError::NotDetermined {
                    block: Some(index),
                    column: j,
                });
            }
        }
        Ok(ReducedBlock {
            r11: r.as_ref().submatrix(0, 0, l, l).to_owned(),
            r12: r.as_ref().submatrix(0, l, l, n_global).to_owned(),
            r1: (0..l).map(|i| r[(i, w - 1)]).collect(),
            tail: r.as_ref().submatrix(l, l, w - l, w - l).to_owned(),
        })
    }

    /// The block's locals given the globals: `R11^-1 (r1 - R12 x_g)`.
    pub fn local_solution(&self, global: &[f64]) -> Vec<f64> {
        let rhs: Vec<f64> = (0..self.r1.len())
            .map(|i| {
                self.r1[i]
                    - (0..global.len())
                        .map(|j| self.r12[(i, j)] * global[j])
                        .sum::<f64>()
            })
            .collect();
        solve_upper(self.r11.as_ref(), &rhs)
    }

    /// `K = R11^-1 R12`: how the locals move against the globals.
    fn coupling(&self) -> Mat<f64> {
        let inv = invert_upper(self.r11.as_ref());
        &inv * &self.r12
    }

    /// Covariance of the block's locals with the globals' uncertainty
    /// `global_covariance` included: `R11^-1 R11^-T + K C_g K^T`.
    ///
    /// # Example
    /// ```
    /// use faer::Mat;
    /// use tricept_numerics::sparse::{ReducedBlock, RowBlock};
    /// // One row x_l + x_g = 1: x_l's variance is 1 plus the global's.
    /// let r = ReducedBlock::new(&RowBlock::new(1, Mat::from_fn(1, 3, |_, _| 1.0)), 1, 0).unwrap();
    /// let c = r.local_covariance(Mat::from_fn(1, 1, |_, _| 4.0).as_ref());
    /// assert!((c[(0, 0)] - 5.0).abs() < 1e-12);
    /// ```
    pub fn local_covariance(&self, global_covariance: MatRef<'_, f64>) -> Mat<f64> {
        let inv = invert_upper(self.r11.as_ref());
        let k = &inv * &self.r12;
        &inv * inv.transpose() + &k * global_covariance * k.transpose()
    }

    /// Covariance of the block's locals with the globals: `-K C_g`.
    pub fn cross_covariance(&self, global_covariance: MatRef<'_, f64>) -> Mat<f64> {
        let k = self.coupling();
        let c = &k * global_covariance;
        Mat::from_fn(c.nrows(), c.ncols(), |i, j| -c[(i, j)])
    }
}

/// The Euclidean norm of column `j` of `a`.
fn column_norm(a: MatRef<'_, f64>, j: usize) -> f64 {
    (0..a.nrows())
        .map(|i| a[(i, j)].powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Solves the globals from reduced blocks: the tails stacked and factored,
/// then `R_g x_g = r_g`. Returns the globals, their covariance and the
/// residual norm squared; `global_norms` are the globals' column norms in
/// `J` (for the pivot test).
///
/// # Example
/// ```
/// use faer::Mat;
/// use tricept_numerics::sparse::{ReducedBlock, RowBlock, solve_globals};
/// let rows = Mat::from_fn(2, 3, |i, j| [[1.0, 1.0, 3.0], [0.0, 1.0, 2.0]][i][j]);
/// let r = ReducedBlock::new(&RowBlock::new(1, rows), 1, 0).unwrap();
/// let (x, cov, res) = solve_globals(&[r], &[2f64.sqrt()]).unwrap();
/// assert!((x[0] - 2.0).abs() < 1e-12 && (cov[(0, 0)] - 1.0).abs() < 1e-12 && res < 1e-24);
/// ```
pub fn solve_globals(
    blocks: &[ReducedBlock],
    global_norms: &[f64],
) -> Result<(Vec<f64>, Mat<f64>, f64), BlockError> {
    let g = global_norms.len();
    let mut acc = TriangularAccumulator::with_rows_hint(g + 1, (g + 1) * blocks.len());
    let mut row = vec![0.0; g + 1];
    for b in blocks {
        if b.tail.ncols() != g + 1 {
            return Err(BlockError::Shape(format!(
                "a reduced block of {} globals for {g}",
                b.tail.ncols().saturating_sub(1)
            )));
        }
        for i in 0..b.tail.nrows() {
            row.iter_mut()
                .enumerate()
                .for_each(|(j, v)| *v = b.tail[(i, j)]);
            acc.push_row(&row);
        }
    }
    let r = acc.finish();
    for (j, norm) in global_norms.iter().enumerate() {
        if !(r[(j, j)].abs() > DEPENDENT_COLUMN * norm && *norm > 0.0) {
            return Err(BlockError::NotDetermined {
                block: None,
                column: j,
            });
        }
    }
    let rg = r.as_ref().submatrix(0, 0, g, g);
    let x = solve_upper(rg, &(0..g).map(|i| r[(i, g)]).collect::<Vec<_>>());
    let inv = invert_upper(rg);
    Ok((x, &inv * inv.transpose(), r[(g, g)].powi(2)))
}

impl BlockProblem {
    /// Unknowns: every block's locals, then the globals.
    pub fn unknowns(&self) -> usize {
        self.blocks.iter().map(|b| b.n_local).sum::<usize>() + self.n_global
    }

    /// Rows of `J`.
    pub fn rows(&self) -> usize {
        self.blocks.iter().map(|b| b.rows.nrows()).sum()
    }

    /// Non-zero entries of `J` (the right-hand side excluded).
    pub fn nonzeros(&self) -> usize {
        self.blocks
            .iter()
            .map(|b| {
                let n = b.rows.ncols().saturating_sub(1);
                (0..b.rows.nrows())
                    .map(|i| (0..n).filter(|&j| b.rows[(i, j)] != 0.0).count())
                    .sum::<usize>()
            })
            .sum()
    }

    /// The norm of every global column of `J`.
    pub fn global_norms(&self) -> Vec<f64> {
        (0..self.n_global)
            .map(|j| {
                self.blocks
                    .iter()
                    .map(|b| column_norm(b.rows.as_ref(), b.n_local + j).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect()
    }

    /// Solves the problem with `kind` (module docs).
    pub fn solve(&self, kind: SolverKind) -> Result<BlockSolution, BlockError> {
        let start = Instant::now();
        let w = self.n_global + 1;
        for (i, b) in self.blocks.iter().enumerate() {
            if b.rows.ncols() != b.n_local + w {
                return Err(BlockError::Shape(format!(
                    "block {i} has {} columns for {} locals, {} globals and the right-hand side",
                    b.rows.ncols(),
                    b.n_local,
                    self.n_global
                )));
            }
        }
        if kind != SolverKind::Schur {
            // faer's sparse factorisations do not pivot for rank: the block
            // elimination's pivot tests (cheap beside them) guard them.
            self.solve_schur()?;
        }
        let (global, local, global_covariance) = match kind {
            SolverKind::Schur => self.solve_schur()?,
            SolverKind::Dense => self.solve_dense()?,
            SolverKind::SparseCholesky => self.solve_cholesky()?,
            SolverKind::SparseQr => self.solve_qr()?,
        };
        let all_finite = global
            .iter()
            .chain(local.iter().flatten())
            .all(|v| v.is_finite());
        if !all_finite {
            return Err(BlockError::Factorisation(format!(
                "{}: the solution is not finite",
                kind.name()
            )));
        }
        let residual_norm2 = self.residual_norm2(&global, &local);
        Ok(BlockSolution {
            global,
            local,
            global_covariance,
            residual_norm2,
            stats: SolveStats {
                kind,
                unknowns: self.unknowns(),
                nonzeros: self.nonzeros(),
                rows: self.rows(),
                seconds: start.elapsed().as_secs_f64(),
            },
        })
    }

    /// `|J x - b|^2`.
    fn residual_norm2(&self, global: &[f64], local: &[Vec<f64>]) -> f64 {
        let g = self.n_global;
        self.blocks
            .iter()
            .zip(local)
            .map(|(b, x)| {
                let l = b.n_local;
                (0..b.rows.nrows())
                    .map(|i| {
                        let fitted = (0..l).map(|j| b.rows[(i, j)] * x[j]).sum::<f64>()
                            + (0..g).map(|j| b.rows[(i, l + j)] * global[j]).sum::<f64>();
                        (fitted - b.rows[(i, l + g)]).powi(2)
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    fn solve_schur(&self) -> Result<Solved, BlockError> {
        let reduced = self
            .blocks
            .iter()
            .enumerate()
            .map(|(i, b)| ReducedBlock::new(b, self.n_global, i))
            .collect::<Result<Vec<_>, _>>()?;
        let (global, cov, _) = solve_globals(&reduced, &self.global_norms())?;
        let local = reduced.iter().map(|r| r.local_solution(&global)).collect();
        Ok((global, local, Some(cov)))
    }

    /// Each unknown's column in `J`: block `b`'s locals from `offsets[b]`,
    /// the globals from `offsets[blocks]`.
    fn column_offsets(&self) -> Vec<usize> {
        let mut offsets = Vec::with_capacity(self.blocks.len() + 1);
        let mut at = 0;
        for b in &self.blocks {
            offsets.push(at);
            at += b.n_local;
        }
        offsets.push(at);
        offsets
    }

    /// Splits a solution vector in `J`'s column order into globals and
    /// locals.
    fn split(&self, x: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
        let offsets = self.column_offsets();
        let global = x[offsets[self.blocks.len()]..].to_vec();
        let local = self
            .blocks
            .iter()
            .zip(&offsets)
            .map(|(b, &o)| x[o..o + b.n_local].to_vec())
            .collect();
        (global, local)
    }

    fn solve_dense(&self) -> Result<Solved, BlockError> {
        let n = self.unknowns();
        let g = self.n_global;
        let offsets = self.column_offsets();
        let mut acc = TriangularAccumulator::with_rows_hint(n + 1, self.rows());
        let mut row = vec![0.0; n + 1];
        let mut norms = vec![0.0; n];
        for (b, &o) in self.blocks.iter().zip(&offsets) {
            let l = b.n_local;
            for i in 0..b.rows.nrows() {
                row.iter_mut().for_each(|v| *v = 0.0);
                for j in 0..l {
                    row[o + j] = b.rows[(i, j)];
                }
                for j in 0..g {
                    row[n - g + j] = b.rows[(i, l + j)];
                }
                row[n] = b.rows[(i, l + g)];
                for j in 0..n {
                    norms[j] += row[j] * row[j];
                }
                acc.push_row(&row);
            }
        }
        let r = acc.finish();
        for j in 0..n {
            if !(r[(j, j)].abs() > DEPENDENT_COLUMN * norms[j].sqrt() && norms[j] > 0.0) {
                let block = offsets
                    .iter()
                    .rposition(|&o| o <= j)
                    .filter(|&b| b < self.blocks.len());
                return Err(BlockError::NotDetermined {
                    column: j - block.map_or(n - g, |b| offsets[b]),
                    block,
                });
            }
        }
        let x = solve_upper(
            r.as_ref().submatrix(0, 0, n, n),
            &(0..n).map(|i| r[(i, n)]).collect::<Vec<_>>(),
        );
        let inv = invert_upper(r.as_ref().submatrix(n - g, n - g, g, g));
        let (global, local) = self.split(&x);
        Ok((global, local, Some(&inv * inv.transpose())))
    }

    /// The scale of every column of `J` (its norm), a zero column refused.
    fn column_scales(&self) -> Result<Vec<f64>, BlockError> {
        let offsets = self.column_offsets();
        let mut scales = vec![0.0; self.unknowns()];
        for (b, &o) in self.blocks.iter().zip(&offsets) {
            for j in 0..b.n_local {
                scales[o + j] = column_norm(b.rows.as_ref(), j);
            }
        }
        let g0 = offsets[self.blocks.len()];
        for (j, s) in self.global_norms().into_iter().enumerate() {
            scales[g0 + j] = s;
        }
        match scales.iter().position(|s| !(*s > 0.0 && s.is_finite())) {
            None => Ok(scales),
            Some(j) if j >= g0 => Err(BlockError::NotDetermined {
                block: None,
                column: j - g0,
            }),
            Some(j) => {
                let b = offsets.iter().rposition(|&o| o <= j).unwrap_or(0);
                Err(BlockError::NotDetermined {
                    block: Some(b),
                    column: j - offsets[b],
                })
            }
        }
    }

    /// The lower triangle of `J^T J` scaled by `1 / (s_i s_j)` as triplets,
    /// and `J^T b` scaled by `1 / s_i`.
    fn scaled_normal_equations(
        &self,
        scales: &[f64],
    ) -> (Vec<Triplet<usize, usize, f64>>, Vec<f64>) {
        let offsets = self.column_offsets();
        let n = self.unknowns();
        let g = self.n_global;
        let mut triplets = Vec::new();
        let mut rhs = vec![0.0; n];
        for (b, &o) in self.blocks.iter().zip(&offsets) {
            let l = b.n_local;
            let cols: Vec<usize> = (0..l)
                .map(|j| o + j)
                .chain((0..g).map(|j| n - g + j))
                .collect();
            let m = b.rows.nrows();
            let a = b.rows.as_ref().submatrix(0, 0, m, l + g);
            let ata = a.transpose() * a;
            for (p, &cp) in cols.iter().enumerate() {
                rhs[cp] += (0..m).map(|i| a[(i, p)] * b.rows[(i, l + g)]).sum::<f64>() / scales[cp];
                for (q, &cq) in cols.iter().enumerate() {
                    if cp >= cq && ata[(p, q)] != 0.0 {
                        triplets.push(Triplet::new(
                            cp,
                            cq,
                            ata[(p, q)] / (scales[cp] * scales[cq]),
                        ));
                    }
                }
            }
        }
        (triplets, rhs)
    }

    fn solve_cholesky(&self) -> Result<Solved, BlockError> {
        let n = self.unknowns();
        let g = self.n_global;
        let scales = self.column_scales()?;
        let (triplets, rhs) = self.scaled_normal_equations(&scales);
        let fail =
            |e: &dyn std::fmt::Debug| BlockError::Factorisation(format!("sparse Cholesky: {e:?}"));
        let normal = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| fail(&e))?;
        let symbolic =
            SymbolicLlt::try_new(normal.symbolic(), Side::Lower).map_err(|e| fail(&e))?;
        let llt = Llt::try_new_with_symbolic(symbolic, normal.as_ref(), Side::Lower)
            .map_err(|e| fail(&e))?;
        let mut x = Mat::from_fn(n, 1 + g, |i, j| match j {
            0 => rhs[i],
            j => f64::from(u8::from(i == n - g + j - 1)),
        });
        llt.solve_in_place(x.as_mut());
        let mut solution: Vec<f64> = (0..n).map(|i| x[(i, 0)] / scales[i]).collect();
        // The normal equations square the condition number: refine with
        // the residual of J itself (semi-normal equations), which gains
        // back the digits the squaring lost.
        for _ in 0..REFINEMENT_STEPS {
            let r = self.normal_residual(&solution);
            let mut d = Mat::from_fn(n, 1, |i, _| r[i] / scales[i]);
            llt.solve_in_place(d.as_mut());
            solution
                .iter_mut()
                .enumerate()
                .for_each(|(i, v)| *v += d[(i, 0)] / scales[i]);
        }
        let cov = Mat::from_fn(g, g, |a, b| {
            x[(n - g + a, 1 + b)] / (scales[n - g + a] * scales[n - g + b])
        });
        let (global, local) = self.split(&solution);
        Ok((global, local, Some(cov)))
    }

    /// `J^T (b - J x)` for `x` in `J`'s column order.
    fn normal_residual(&self, x: &[f64]) -> Vec<f64> {
        let n = self.unknowns();
        let g = self.n_global;
        let mut out = vec![0.0; n];
        for (b, &o) in self.blocks.iter().zip(&self.column_offsets()) {
            let l = b.n_local;
            let col = |j: usize| if j < l { o + j } else { n - g + j - l };
            for i in 0..b.rows.nrows() {
                let fitted: f64 = (0..l + g).map(|j| b.rows[(i, j)] * x[col(j)]).sum();
                let r = b.rows[(i, l + g)] - fitted;
                for j in 0..l + g {
                    out[col(j)] += b.rows[(i, j)] * r;
                }
            }
        }
        out
    }

    fn solve_qr(&self) -> Result<Solved, BlockError> {
        let n = self.unknowns();
        let g = self.n_global;
        let m = self.rows();
        if m < n {
            return Err(BlockError::NotDetermined {
                block: None,
                column: 0,
            });
        }
        let scales = self.column_scales()?;
        let offsets = self.column_offsets();
        let mut triplets = Vec::with_capacity(self.nonzeros());
        let mut rhs = Mat::<f64>::zeros(m, 1);
        let mut at = 0;
        for (b, &o) in self.blocks.iter().zip(&offsets) {
            let l = b.n_local;
            for i in 0..b.rows.nrows() {
                for j in 0..l + g {
                    let v = b.rows[(i, j)];
                    if v != 0.0 {
                        let col = if j < l { o + j } else { n - g + j - l };
                        triplets.push(Triplet::new(at, col, v / scales[col]));
                    }
                }
                rhs[(at, 0)] = b.rows[(i, l + g)];
                at += 1;
            }
        }
        let fail = |e: &dyn std::fmt::Debug| BlockError::Factorisation(format!("sparse QR: {e:?}"));
        let j = SparseColMat::<usize, f64>::try_new_from_triplets(m, n, &triplets)
            .map_err(|e| fail(&e))?;
        let symbolic = SymbolicQr::try_new(j.symbolic()).map_err(|e| fail(&e))?;
        let qr = Qr::try_new_with_symbolic(symbolic, j.as_ref()).map_err(|e| fail(&e))?;
        qr.solve_lstsq_in_place(rhs.as_mut());
        let solution: Vec<f64> = (0..n).map(|i| rhs[(i, 0)] / scales[i]).collect();
        let (global, local) = self.split(&solution);
        Ok((global, local, None))
    }
}

/// Globals, locals and the globals' covariance.
type Solved = (Vec<f64>, Vec<Vec<f64>>, Option<Mat<f64>>);

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::DenseSolveCore;

    /// A seeded problem of `blocks` blocks (`l` locals, `m` rows each) and
    /// `g` globals, with rows of very different scales.
    fn problem(blocks: usize, l: usize, g: usize, m: usize, seed: u64) -> BlockProblem {
        let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        BlockProblem {
            n_global: g,
            blocks: (0..blocks)
                .map(|_| {
                    let scale: Vec<f64> = (0..l + g + 1)
                        .map(|j| 10f64.powi((j % 5) as i32 - 2))
                        .collect();
                    RowBlock::new(l, Mat::from_fn(m, l + g + 1, |_, j| scale[j] * next()))
                })
                .collect(),
        }
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
    }

    #[test]
    fn every_kind_agrees_with_the_dense_reference_to_1e_9() {
        for (blocks, l, g, m) in [
            (1, 3, 2, 10),
            (7, 18, 15, 40),
            (25, 3, 14, 30),
            (4, 0, 5, 9),
        ] {
            let p = problem(blocks, l, g, m, blocks as u64);
            let dense = p.solve(SolverKind::Dense).unwrap();
            for kind in [
                SolverKind::Schur,
                SolverKind::SparseCholesky,
                SolverKind::SparseQr,
            ] {
                let s = p.solve(kind).unwrap();
                let worst = s
                    .global
                    .iter()
                    .zip(&dense.global)
                    .chain(s.local.iter().flatten().zip(dense.local.iter().flatten()))
                    .map(|(a, b)| (a - b).abs() / b.abs().max(1e-3 * norm_inf(&dense)))
                    .fold(0.0, f64::max);
                assert!(worst < 1e-9, "{kind:?} {blocks}x{l}+{g}: {worst:e}");
                assert!(
                    relative(s.residual_norm2, dense.residual_norm2) < 1e-9,
                    "{kind:?}"
                );
                if let (Some(c), Some(d)) = (&s.global_covariance, &dense.global_covariance) {
                    for a in 0..g {
                        for b in 0..g {
                            let tol = 1e-9 * (d[(a, a)] * d[(b, b)]).sqrt();
                            assert!((c[(a, b)] - d[(a, b)]).abs() < tol, "{kind:?} cov");
                        }
                    }
                }
                assert_eq!(s.stats.unknowns, blocks * l + g);
                assert_eq!(s.stats.rows, blocks * m);
            }
        }
    }

    fn norm_inf(s: &BlockSolution) -> f64 {
        s.global
            .iter()
            .chain(s.local.iter().flatten())
            .fold(0.0, |a, b| a.max(b.abs()))
    }

    #[test]
    fn the_local_covariance_is_the_dense_inverse_block() {
        let p = problem(3, 4, 2, 12, 9);
        let s = p.solve(SolverKind::Schur).unwrap();
        let cov = s.global_covariance.unwrap();
        // The dense inverse of J^T J, locals of block 1 at columns 4..8.
        let n = p.unknowns();
        let mut j = Mat::<f64>::zeros(p.rows(), n);
        let mut at = 0;
        for (b, block) in p.blocks.iter().enumerate() {
            for i in 0..block.rows.nrows() {
                for c in 0..4 {
                    j[(at, 4 * b + c)] = block.rows[(i, c)];
                }
                for c in 0..2 {
                    j[(at, n - 2 + c)] = block.rows[(i, 4 + c)];
                }
                at += 1;
            }
        }
        let jtj = j.transpose() * &j;
        let inv = jtj.as_ref().llt(Side::Lower).unwrap().inverse();
        let r = ReducedBlock::new(&p.blocks[1], 2, 1).unwrap();
        let local = r.local_covariance(cov.as_ref());
        let cross = r.cross_covariance(cov.as_ref());
        for a in 0..4 {
            for b in 0..4 {
                assert!(relative(local[(a, b)], inv[(4 + a, 4 + b)]) < 1e-9);
            }
            for b in 0..2 {
                assert!(relative(cross[(a, b)], inv[(4 + a, n - 2 + b)]) < 1e-9);
            }
        }
    }

    #[test]
    fn a_column_no_block_sees_is_refused_by_every_kind_never_filled() {
        // Global 1 has no entry in any row: no kind may return a number.
        let mut p = problem(5, 3, 3, 20, 4);
        for b in &mut p.blocks {
            for i in 0..b.rows.nrows() {
                b.rows[(i, 3 + 1)] = 0.0;
            }
        }
        for kind in SolverKind::ALL {
            assert_eq!(
                p.solve(kind).unwrap_err(),
                BlockError::NotDetermined {
                    block: None,
                    column: 1
                },
                "{kind:?}"
            );
        }
        // A global that is a combination of another (2 x global 0): every
        // kind says which (the sparse ones by the block elimination's test).
        let mut p = problem(5, 3, 3, 20, 5);
        for b in &mut p.blocks {
            for i in 0..b.rows.nrows() {
                b.rows[(i, 3 + 2)] = 2.0 * b.rows[(i, 3)];
            }
        }
        for kind in SolverKind::ALL {
            assert_eq!(
                p.solve(kind).unwrap_err(),
                BlockError::NotDetermined {
                    block: None,
                    column: 2
                },
                "{kind:?}"
            );
        }
        // A block's local that its rows do not see.
        let mut p = problem(3, 3, 2, 20, 6);
        for i in 0..p.blocks[2].rows.nrows() {
            p.blocks[2].rows[(i, 1)] = 0.0;
        }
        for kind in SolverKind::ALL {
            assert_eq!(
                p.solve(kind).unwrap_err(),
                BlockError::NotDetermined {
                    block: Some(2),
                    column: 1
                },
                "{kind:?}"
            );
        }
    }

    #[test]
    fn a_block_of_the_wrong_width_is_a_shape_error() {
        let mut p = problem(2, 3, 2, 10, 1);
        p.blocks[1].rows = Mat::zeros(10, 4);
        assert!(matches!(
            p.solve(SolverKind::Schur),
            Err(BlockError::Shape(_))
        ));
    }
}
