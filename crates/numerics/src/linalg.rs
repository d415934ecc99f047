//! The dense linear-algebra core on `faer`: a streaming (TSQR) triangular
//! factorisation of weighted least-squares problems and the rank-revealing
//! steps built on it.
//!
//! Identification problems here are tall and thin: `3 n` rows (three readings
//! per pose) by `k + 4` columns (three sensor offsets, `k` parameters, the
//! right-hand side). [`TriangularAccumulator`] folds rows in blocks into the
//! `R` factor of a Householder QR, so memory does not grow with the number
//! of poses and the data are never squared into normal equations. Because
//! the offset columns come first, the trailing block of `R` is exactly the
//! `R` factor of the offset-projected ("centred") parameter columns: the
//! rank decision, the singular values and the solve all work on it.
//!
//! All factorisations run sequentially (`Par::Seq`): the matrices are small
//! and callers parallelise at a coarser level.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::{col_pivoting, no_pivoting};
use faer::linalg::svd::{self, ComputeSvdVectors};
use faer::{Mat, MatRef, Par};

/// Rows folded per QR update in [`TriangularAccumulator`].
const BLOCK_ROWS: usize = 512;

/// Householder QR of `a` in place (sequential); `R` is left in its upper triangle.
fn qr_in_place(a: faer::MatMut<'_, f64>) {
    let (m, n) = a.shape();
    let size = m.min(n);
    if size == 0 {
        return;
    }
    // Unblocked Householder is fastest for the narrow matrices here (measured).
    let block = if n <= 32 {
        1
    } else {
        no_pivoting::factor::recommended_block_size::<f64>(m, n).max(1)
    };
    let mut q_coeff = Mat::<f64>::zeros(block, size);
    let mut mem = MemBuffer::new(no_pivoting::factor::qr_in_place_scratch::<f64>(
        m,
        n,
        block,
        Par::Seq,
        Default::default(),
    ));
    no_pivoting::factor::qr_in_place(
        a,
        q_coeff.as_mut(),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    );
}

/// The `n x n` upper-triangular `R` of the QR of `a` (`m >= n` not required:
/// missing rows are zero).
///
/// # Example
/// ```
/// use faer::Mat;
/// let a = Mat::from_fn(5, 2, |i, j| (i + 2 * j) as f64);
/// let r = tricept_numerics::linalg::r_factor(a.as_ref());
/// // R^T R = A^T A.
/// let ata = a.transpose() * &a;
/// let rtr = r.transpose() * &r;
/// assert!((ata[(0, 1)] - rtr[(0, 1)]).abs() < 1e-10);
/// ```
pub fn r_factor(a: MatRef<'_, f64>) -> Mat<f64> {
    let mut work = a.to_owned();
    qr_in_place(work.as_mut());
    let n = a.ncols();
    Mat::from_fn(n, n, |i, j| {
        if i <= j && i < work.nrows() {
            work[(i, j)]
        } else {
            0.0
        }
    })
}

/// Column order chosen by column-pivoted QR (largest remaining norm first).
///
/// # Example
/// ```
/// use faer::Mat;
/// // The second column is the largest: it is chosen first.
/// let a = Mat::from_fn(4, 2, |i, j| if j == 1 { 10.0 * (i as f64 + 1.0) } else { 1.0 });
/// assert_eq!(tricept_numerics::linalg::pivot_order(a.as_ref())[0], 1);
/// ```
pub fn pivot_order(a: MatRef<'_, f64>) -> Vec<usize> {
    let (m, n) = a.shape();
    if n == 0 {
        return Vec::new();
    }
    let size = m.min(n).max(1);
    let mut work = a.to_owned();
    let mut q_coeff = Mat::<f64>::zeros(1, m.min(n));
    let mut perm = vec![0usize; n];
    let mut perm_inv = vec![0usize; n];
    let mut mem = MemBuffer::new(col_pivoting::factor::qr_in_place_scratch::<usize, f64>(
        m,
        n,
        1,
        Par::Seq,
        Default::default(),
    ));
    let _ = size;
    let (_, p) = col_pivoting::factor::qr_in_place(
        work.as_mut(),
        q_coeff.as_mut(),
        &mut perm,
        &mut perm_inv,
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    );
    p.arrays().0.to_vec()
}

/// Singular values (descending) and right singular vectors (columns) of `a`.
///
/// # Example
/// ```
/// use faer::Mat;
/// let a = Mat::from_fn(3, 2, |i, j| if i == j { (j + 1) as f64 } else { 0.0 });
/// let (s, _) = tricept_numerics::linalg::svd_values_and_vectors(a.as_ref()).unwrap();
/// assert!((s[0] - 2.0).abs() < 1e-14 && (s[1] - 1.0).abs() < 1e-14);
/// ```
pub fn svd_values_and_vectors(a: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let (m, n) = a.shape();
    // Work on a square-or-tall matrix: pad short ones with zero rows.
    let work = if m >= n {
        a.to_owned()
    } else {
        Mat::from_fn(n, n, |i, j| if i < m { a[(i, j)] } else { 0.0 })
    };
    let rows = work.nrows();
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut v = Mat::<f64>::zeros(n, n);
    let mut mem = MemBuffer::new(svd::svd_scratch::<f64>(
        rows,
        n,
        ComputeSvdVectors::No,
        ComputeSvdVectors::Full,
        Par::Seq,
        Default::default(),
    ));
    svd::svd(
        work.as_ref(),
        s.as_mut(),
        None,
        Some(v.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let values: Vec<f64> = (0..n).map(|i| s[i]).collect();
    Some((values, v))
}

/// Solves `R x = b` for upper-triangular `R` (back substitution).
///
/// # Example
/// ```
/// use faer::Mat;
/// let r = Mat::from_fn(2, 2, |i, j| [[2.0, 1.0], [0.0, 4.0]][i][j]);
/// let x = tricept_numerics::linalg::solve_upper(r.as_ref(), &[4.0, 8.0]);
/// assert_eq!(x, vec![1.0, 2.0]);
/// ```
pub fn solve_upper(r: MatRef<'_, f64>, b: &[f64]) -> Vec<f64> {
    let n = b.len();
    let mut x = b.to_vec();
    for i in (0..n).rev() {
        let mut acc = x[i];
        for j in i + 1..n {
            acc -= r[(i, j)] * x[j];
        }
        x[i] = acc / r[(i, i)];
    }
    x
}

/// Inverse of an upper-triangular matrix.
///
/// # Example
/// ```
/// use faer::Mat;
/// let r = Mat::from_fn(2, 2, |i, j| [[2.0, 1.0], [0.0, 4.0]][i][j]);
/// let inv = tricept_numerics::linalg::invert_upper(r.as_ref());
/// assert_eq!(inv[(0, 0)], 0.5);
/// assert_eq!(inv[(0, 1)], -0.125);
/// ```
pub fn invert_upper(r: MatRef<'_, f64>) -> Mat<f64> {
    let n = r.nrows();
    let mut inv = Mat::<f64>::zeros(n, n);
    for col in 0..n {
        let mut e = vec![0.0; n];
        e[col] = 1.0;
        let x = solve_upper(r, &e);
        for i in 0..n {
            inv[(i, col)] = x[i];
        }
    }
    inv
}

/// Folds the rows of a tall least-squares problem into the `R` factor of
/// its QR, a block at a time (TSQR).
///
/// # Example
/// ```
/// use tricept_numerics::linalg::TriangularAccumulator;
/// let mut acc = TriangularAccumulator::new(2);
/// for (x, y) in [(1.0, 2.0), (2.0, 4.1), (3.0, 5.9)] {
///     acc.push_row(&[x, y]);
/// }
/// let r = acc.finish();
/// // R^T R equals A^T A.
/// let ata00 = 1.0 + 4.0 + 9.0;
/// assert!((r[(0, 0)] * r[(0, 0)] - ata00).abs() < 1e-12);
/// ```
#[derive(Debug, Clone)]
pub struct TriangularAccumulator {
    n: usize,
    /// Rows 0..n hold the current R; rows n.. the pending block.
    work: Mat<f64>,
    pending: usize,
    rows: usize,
}

impl TriangularAccumulator {
    /// An accumulator for rows of `n` values.
    ///
    /// # Example
    /// ```
    /// let mut acc = tricept_numerics::linalg::TriangularAccumulator::new(2);
    /// acc.push_row(&[3.0, 4.0]);
    /// assert_eq!(acc.rows(), 1);
    /// assert_eq!(acc.finish().nrows(), 2);
    /// ```
    pub fn new(n: usize) -> TriangularAccumulator {
        Self::with_rows_hint(n, BLOCK_ROWS)
    }

    /// An accumulator sized for about `rows` rows (blocks of at most 512):
    /// small problems then allocate and factor no more than they need.
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// // 2000 rows are folded in blocks of 512; the result does not depend on it.
    /// let (mut a, mut b) = (TriangularAccumulator::new(2), TriangularAccumulator::with_rows_hint(2, 3));
    /// for i in 0..2000 {
    ///     let row = [1.0, (i as f64).sin()];
    ///     a.push_row(&row);
    ///     b.push_row(&row);
    /// }
    /// let (ra, rb) = (a.finish(), b.finish());
    /// // R is unique up to the signs of its rows: compare |R|.
    /// for i in 0..2 { for j in 0..2 { assert!((ra[(i, j)].abs() - rb[(i, j)].abs()).abs() < 1e-9); } }
    /// ```
    pub fn with_rows_hint(n: usize, rows: usize) -> TriangularAccumulator {
        let block = rows.clamp(1, BLOCK_ROWS);
        TriangularAccumulator {
            n,
            work: Mat::zeros(n + block, n),
            pending: 0,
            rows: 0,
        }
    }

    /// Adds one row (length `n`).
    ///
    /// # Example
    /// ```
    /// let mut acc = tricept_numerics::linalg::TriangularAccumulator::new(1);
    /// acc.push_row(&[3.0]);
    /// acc.push_row(&[4.0]);
    /// assert!((acc.finish()[(0, 0)].abs() - 5.0).abs() < 1e-12); // sqrt(9 + 16)
    /// ```
    pub fn push_row(&mut self, row: &[f64]) {
        let at = self.n + self.pending;
        for (j, v) in row.iter().enumerate().take(self.n) {
            self.work[(at, j)] = *v;
        }
        self.pending += 1;
        self.rows += 1;
        if self.n + self.pending == self.work.nrows() {
            self.flush();
        }
    }

    /// Rows pushed so far.
    ///
    /// # Example
    /// ```
    /// let mut acc = tricept_numerics::linalg::TriangularAccumulator::new(3);
    /// (0..1000).for_each(|i| acc.push_row(&[1.0, i as f64, 2.0]));
    /// assert_eq!(acc.rows(), 1000);
    /// ```
    pub fn rows(&self) -> usize {
        self.rows
    }

    fn flush(&mut self) {
        if self.pending == 0 {
            return;
        }
        let used = self.n + self.pending;
        qr_in_place(self.work.as_mut().subrows_mut(0, used));
        // Keep R (upper triangle of the first n rows); clear the rest.
        for i in 0..self.n.min(used) {
            for j in 0..i {
                self.work[(i, j)] = 0.0;
            }
        }
        for i in self.n..used {
            for j in 0..self.n {
                self.work[(i, j)] = 0.0;
            }
        }
        self.pending = 0;
    }

    /// The `n x n` upper-triangular factor with `R^T R = A^T A`.
    ///
    /// # Example
    /// ```
    /// let mut acc = tricept_numerics::linalg::TriangularAccumulator::new(2);
    /// acc.push_row(&[1.0, 2.0]);
    /// acc.push_row(&[0.0, 1.0]);
    /// let r = acc.finish();
    /// assert_eq!(r[(1, 0)], 0.0); // upper triangular
    /// // R^T R = A^T A: the (1, 1) entry is 2^2 + 1^2.
    /// assert!((r[(0, 1)].powi(2) + r[(1, 1)].powi(2) - 5.0).abs() < 1e-12);
    /// ```
    pub fn finish(mut self) -> Mat<f64> {
        self.flush();
        self.work.as_ref().subrows(0, self.n).to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_matrix(m: usize, n: usize) -> Mat<f64> {
        Mat::from_fn(m, n, |i, j| {
            let x = (i as f64 + 1.0) * 0.37 + (j as f64) * 1.3;
            x.sin() + if i % (j + 2) == 0 { 0.5 } else { 0.0 }
        })
    }

    #[test]
    fn streaming_r_matches_one_shot_r_up_to_signs() {
        let a = test_matrix(1300, 6);
        let mut acc = TriangularAccumulator::new(6);
        for i in 0..a.nrows() {
            let row: Vec<f64> = (0..6).map(|j| a[(i, j)]).collect();
            acc.push_row(&row);
        }
        assert_eq!(acc.rows(), 1300);
        let r1 = acc.finish();
        let r2 = r_factor(a.as_ref());
        for i in 0..6 {
            let s = r1[(i, i)].signum() * r2[(i, i)].signum();
            for j in 0..6 {
                assert!((r1[(i, j)] - s * r2[(i, j)]).abs() < 1e-9 * r2[(0, 0)].abs());
            }
        }
    }

    #[test]
    fn pivoting_puts_a_dependent_column_last() {
        let mut a = test_matrix(50, 4);
        for i in 0..50 {
            a[(i, 1)] = 2.0 * a[(i, 0)] - a[(i, 3)];
        }
        let order = pivot_order(a.as_ref());
        let (s, _) = svd_values_and_vectors(a.as_ref()).unwrap();
        assert!(s[3] < 1e-12 * s[0]);
        assert_eq!(order.len(), 4);
        // The last pivot is one of the three dependent columns.
        assert!([0, 1, 3].contains(&order[3]), "{order:?}");
    }

    #[test]
    fn triangular_solve_and_inverse() {
        let r = r_factor(test_matrix(10, 4).as_ref());
        let b = [1.0, -2.0, 0.5, 3.0];
        let x = solve_upper(r.as_ref(), &b);
        for i in 0..4 {
            let mut acc = 0.0;
            for j in 0..4 {
                acc += r[(i, j)] * x[j];
            }
            assert!((acc - b[i]).abs() < 1e-10);
        }
        let inv = invert_upper(r.as_ref());
        let prod = &r * &inv;
        for i in 0..4 {
            for j in 0..4 {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((prod[(i, j)] - e).abs() < 1e-10);
            }
        }
    }
}
