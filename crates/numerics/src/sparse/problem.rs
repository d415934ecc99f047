//! The block-arrow problem: its blocks of rows, the solver kinds, the
//! errors, the solution and what a solve cost (`super`'s module docs).

use faer::{Mat, MatRef};

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
    /// # use tricept_numerics::sparse::SolverKind;
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

/// The Euclidean norm of column `j` of `a`.
pub(super) fn column_norm(a: MatRef<'_, f64>, j: usize) -> f64 {
    (0..a.nrows())
        .map(|i| a[(i, j)].powi(2))
        .sum::<f64>()
        .sqrt()
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
}

impl BlockProblem {
    /// `|J x - b|^2`.
    pub(super) fn residual_norm2(&self, global: &[f64], local: &[Vec<f64>]) -> f64 {
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

    /// Each unknown's column in `J`: block `b`'s locals from `offsets[b]`,
    /// the globals from `offsets[blocks]`.
    pub(super) fn column_offsets(&self) -> Vec<usize> {
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
    pub(super) fn split(&self, x: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
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
}

/// Globals, locals and the globals' covariance.
pub(super) type Solved = (Vec<f64>, Vec<Vec<f64>>, Option<Mat<f64>>);
