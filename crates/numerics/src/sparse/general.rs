//! The general solves: faer's sparse Cholesky of the scaled normal
//! equations (refined with `J`), faer's sparse QR of the scaled `J`, and
//! the dense streaming QR (`super`'s module docs).

use faer::linalg::solvers::{Solve, SolveLstsq};
use faer::sparse::linalg::solvers::{Llt, Qr, SymbolicLlt, SymbolicQr};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use super::problem::{BlockError, BlockProblem, DEPENDENT_COLUMN, Solved, column_norm};
use crate::linalg::{TriangularAccumulator, invert_upper, solve_upper};

/// Steps of iterative refinement after the sparse Cholesky solve.
const REFINEMENT_STEPS: usize = 2;

impl BlockProblem {
    pub(super) fn solve_dense(&self) -> Result<Solved, BlockError> {
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

    pub(super) fn solve_cholesky(&self) -> Result<Solved, BlockError> {
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

    pub(super) fn solve_qr(&self) -> Result<Solved, BlockError> {
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
