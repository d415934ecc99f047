//! The fast path: each block reduced by its own QR, the tails stacked into
//! the globals' factor, every block by back substitution; its pivot tests
//! guard every kind (`super`'s module docs).

use faer::{Mat, MatRef};

use super::problem::{BlockError, BlockProblem, DEPENDENT_COLUMN, RowBlock, Solved, column_norm};
use crate::linalg::{TriangularAccumulator, invert_upper, r_factor, solve_upper};

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
    pub(super) fn solve_schur(&self) -> Result<Solved, BlockError> {
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
}
