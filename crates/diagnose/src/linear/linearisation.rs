//! The linearisation itself: the fit's weighted design evaluated at its
//! estimate a block of poses at a time, the legs' weighted directions, the
//! target, `R` of the basis columns (TSQR, never `Q`), and the sums over
//! poses every score is built from.

use std::ops::Range;

use nalgebra::{DMatrix, DVector, Matrix3};
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::model::ReadingModel;
use tricept_kinematics::up_limb::UpJoints;
use tricept_numerics::linalg::TriangularAccumulator;

use super::kernels::{axpy, dot3};
use super::score::{Score, Sums, score_from};
use crate::fit::Fit;
use crate::terms::Term;

/// Poses per block of the sums over poses (and of the period scan).
pub(super) const BLOCK: usize = 256;

/// Poses per block of the linearisation's evaluation and of its `R`.
const EVALUATION_BLOCK: usize = 4096;

/// The projections of the six directions of a block of poses on the
/// basis columns: `of[b]` holds `X_j^T d_jb`, `p x len` with the poses of a
/// basis column contiguous (empty for a direction not asked for).
pub(crate) struct Projections {
    /// Per direction, `p x len`, row-major.
    pub(crate) of: [Vec<f64>; 6],
}

/// The linearisation of a fit on its poses.
#[derive(Debug, Clone)]
pub(crate) struct Linearisation {
    /// Weighted design `[offsets | identifiable parameters]`, `3n x width`,
    /// row after row (a pose's three rows together).
    pub(super) rows: Vec<f64>,
    /// Columns of the design.
    pub(super) width: usize,
    /// Model parameter index of each design column after the three offsets.
    pub(crate) x_params: Vec<usize>,
    /// The design columns of the fitted model (all, or all but a term's).
    pub(super) basis: Vec<usize>,
    /// `R` of the basis columns (`X_B = Q R`, upper triangular).
    pub(super) r: DMatrix<f64>,
    /// The target: weighted residuals of the fit unless replaced.
    pub(crate) target: DVector<f64>,
    /// Solved UP joints of every pose at the estimate.
    pub(crate) ups: Vec<UpJoints>,
    /// Per pose, the weighted directions of the three legs (`W J1^-1 e_i`);
    /// those of the readings are `e_c / sigma_c` ([`Linearisation::direction`]).
    pub(super) directions: Vec<[[f64; 3]; 3]>,
    /// `1 / sigma_c` of the three readings.
    pub(super) weights: [f64; 3],
    /// `Q^T t`.
    pub(super) qtt: DVector<f64>,
    /// Weighted columns of extra terms at zero (`3n x m`).
    pub(crate) extra: DMatrix<f64>,
    /// Each extra term with its columns in `extra`.
    pub(crate) extra_terms: Vec<(Term, std::ops::Range<usize>)>,
}

/// One block of poses of the linearisation: their targets, UP joints,
/// directions, the extra columns when they are kept, and else the sums
/// the extra terms' scores need.
struct Block {
    target: Vec<f64>,
    ups: Vec<UpJoints>,
    directions: Vec<[[f64; 3]; 3]>,
    extra: Vec<f64>,
    /// `X^T E`, `E^T E` (every entry) and `E^T t` of the extra columns.
    sums: Sums,
}

impl Linearisation {
    /// Linearises `fit` on `data` (the poses it was fitted on), with the
    /// columns of `extra` terms (at zero) alongside. `None` when a pose
    /// cannot be solved at the estimate.
    pub(crate) fn at_fit(
        fit: &Fit,
        data: &Dataset,
        sigma: &[f64; 3],
        extra: &[Term],
    ) -> Option<Linearisation> {
        Self::build(fit, data, sigma, extra, true).map(|(lin, _)| lin)
    }

    /// [`Linearisation::at_fit`] without keeping the extra terms' columns:
    /// each extra term's score against the fit's residuals instead (the
    /// linearised drop of chi-square of adding it), from sums over poses.
    pub(crate) fn scoring(
        fit: &Fit,
        data: &Dataset,
        sigma: &[f64; 3],
        extra: &[Term],
    ) -> Option<(Linearisation, Vec<(Term, Score)>)> {
        let (lin, sums) = Self::build(fit, data, sigma, extra, false)?;
        let m = sums.gtt.len();
        let width = lin.width;
        let scores = lin
            .extra_terms
            .iter()
            .map(|(t, r)| {
                let k = r.len();
                // The basis is every design column here.
                let xtg = DMatrix::from_fn(width, k, |i, a| sums.xtg[(r.start + a) * width + i]);
                let gtg = DMatrix::from_fn(k, k, |a, b| sums.gtg[(r.start + a) * m + r.start + b]);
                let gtt = DVector::from_fn(k, |a, _| sums.gtt[r.start + a]);
                (*t, score_from(&lin.qt(&xtg), &gtg, &gtt, &lin.qtt))
            })
            .collect();
        Some((lin, scores))
    }

    /// The linearisation with the extra columns kept (`dense`) or summed.
    fn build(
        fit: &Fit,
        data: &Dataset,
        sigma: &[f64; 3],
        extra: &[Term],
        dense: bool,
    ) -> Option<(Linearisation, Sums)> {
        let mut terms = fit.model.terms().to_vec();
        terms.extend_from_slice(extra);
        let model = fit.model.with(&terms);
        let k = fit.model.names().len();
        let kf = model.names().len();
        let mut p = fit.id.estimate.clone();
        p.resize(kf, 0.0);
        let predictor = model.at(&p);
        let machine = model.machine_at(&p);
        let identifiable = fit.id.design().identifiable().to_vec();
        let n = data.poses.len();
        let width = 3 + identifiable.len();
        let m = kf - k;
        let offsets = fit.id.offsets;
        let mut rows = vec![0.0; 3 * n * width];
        // Blocks of poses in parallel, each writing its design rows in
        // place; the rest is joined (and summed) in block order.
        let blocks: Vec<Option<Block>> = data
            .poses
            .par_chunks(EVALUATION_BLOCK)
            .zip(rows.par_chunks_mut(3 * EVALUATION_BLOCK * width))
            .map(|(poses, rows)| {
                let len = poses.len();
                let mut block = Block {
                    target: Vec::with_capacity(3 * len),
                    ups: Vec::with_capacity(len),
                    directions: Vec::with_capacity(len),
                    extra: Vec::with_capacity(if dense { 3 * len * m } else { 0 }),
                    sums: Sums::zero(width, if dense { 0 } else { m }),
                };
                let mut jac = vec![0.0; 3 * kf];
                let mut e = vec![0.0; m];
                for (t, pose) in poses.iter().enumerate() {
                    let mut seed = None;
                    let g = predictor.predict(pose, &mut seed, &mut jac).ok()?;
                    let up = seed?;
                    let legs = machine.legs_at(&up);
                    let j1_inv: Matrix3<f64> = legs.j1().try_inverse()?;
                    let y = pose.readings.to_array();
                    let mut directions = [[0.0; 3]; 3];
                    for c in 0..3 {
                        let w = 1.0 / sigma[c];
                        let row = &mut rows[(3 * t + c) * width..(3 * t + c + 1) * width];
                        row[c] = w;
                        for (t, &gi) in identifiable.iter().enumerate() {
                            row[3 + t] = w * jac[c * kf + gi];
                        }
                        let target = w * (y[c] - g[c] - offsets[c]);
                        for (i, e) in e.iter_mut().enumerate() {
                            *e = w * jac[c * kf + k + i];
                        }
                        if dense {
                            block.extra.extend_from_slice(&e);
                        } else {
                            let sums = &mut block.sums;
                            for (i, &ei) in e.iter().enumerate() {
                                if ei == 0.0 {
                                    continue;
                                }
                                let xte = &mut sums.xtg[i * width..(i + 1) * width];
                                xte.iter_mut()
                                    .zip(row.iter())
                                    .for_each(|(s, x)| *s += x * ei);
                                let ete = &mut sums.gtg[i * m..(i + 1) * m];
                                ete.iter_mut().zip(&e).for_each(|(s, el)| *s += ei * el);
                                sums.gtt[i] += ei * target;
                            }
                        }
                        block.target.push(target);
                        for i in 0..3 {
                            directions[i][c] = w * j1_inv[(c, i)];
                        }
                    }
                    block.ups.push(up);
                    block.directions.push(directions);
                }
                Some(block)
            })
            .collect();
        let mut target = Vec::with_capacity(3 * n);
        let mut ups = Vec::with_capacity(n);
        let mut directions = Vec::with_capacity(n);
        let mut sums = Sums::zero(width, if dense { 0 } else { m });
        let mut ext = DMatrix::zeros(if dense { 3 * n } else { 0 }, m);
        for block in blocks {
            // A pose the model cannot solve at the estimate.
            let block = block?;
            if dense {
                let first = target.len();
                for (i, row) in block.extra.chunks_exact(m.max(1)).enumerate() {
                    for (e, v) in row.iter().enumerate() {
                        ext[(first + i, e)] = *v;
                    }
                }
            } else {
                sums.add(&block.sums);
            }
            target.extend(block.target);
            ups.extend(block.ups);
            directions.extend(block.directions);
        }
        let target = DVector::from_vec(target);
        let mut at = 0;
        let extra_terms = extra
            .iter()
            .map(|t| {
                let len = t.param_count();
                let r = at..at + len;
                at += len;
                (*t, r)
            })
            .collect();
        let mut lin = Linearisation {
            rows,
            width,
            x_params: identifiable,
            basis: Vec::new(),
            r: DMatrix::zeros(0, 0),
            target,
            ups,
            directions,
            weights: sigma.map(|s| 1.0 / s),
            qtt: DVector::zeros(0),
            extra: ext,
            extra_terms,
        };
        lin.set_basis(&[]);
        Some((lin, sums))
    }

    /// Number of poses.
    pub(crate) fn poses(&self) -> usize {
        self.directions.len()
    }

    /// Weighted direction `b` at pose `j`: legs 1-3, readings phi, theta, s.
    #[inline]
    pub(super) fn direction(&self, j: usize, b: usize) -> [f64; 3] {
        match self.directions[j].get(b) {
            Some(d) => *d,
            None => {
                let mut d = [0.0; 3];
                let c = (b - 3).min(2);
                d[c] = self.weights[c];
                d
            }
        }
    }

    /// Design row `i` (of `3n`).
    pub(super) fn row(&self, i: usize) -> &[f64] {
        &self.rows[i * self.width..(i + 1) * self.width]
    }

    /// Uses the columns of the design except those of the model parameters
    /// `drop` as the fitted model.
    pub(crate) fn set_basis(&mut self, drop: &[usize]) {
        self.basis = (0..self.width)
            .filter(|&c| c < 3 || !drop.contains(&self.x_params[c - 3]))
            .collect();
        let p = self.basis.len();
        let rows = 3 * self.poses();
        // TSQR over blocks of rows in parallel, merged in block order.
        let factors: Vec<faer::Mat<f64>> = (0..rows)
            .step_by(3 * EVALUATION_BLOCK)
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&first| {
                let end = (first + 3 * EVALUATION_BLOCK).min(rows);
                let mut acc = TriangularAccumulator::with_rows_hint(p, end - first);
                let mut gathered = vec![0.0; p];
                for i in first..end {
                    let row = self.row(i);
                    for (g, &c) in gathered.iter_mut().zip(&self.basis) {
                        *g = row[c];
                    }
                    acc.push_row(&gathered);
                }
                acc.finish()
            })
            .collect();
        let r = match factors.as_slice() {
            [one] => one.clone(),
            _ => {
                let mut acc = TriangularAccumulator::with_rows_hint(p, p * factors.len());
                let mut row = vec![0.0; p];
                for f in &factors {
                    for i in 0..f.nrows() {
                        row.iter_mut().enumerate().for_each(|(j, v)| *v = f[(i, j)]);
                        acc.push_row(&row);
                    }
                }
                acc.finish()
            }
        };
        self.r = DMatrix::from_fn(p, p, |i, j| if i <= j { r[(i, j)] } else { 0.0 });
        let t = self.target.clone();
        self.set_target(t);
    }

    /// Replaces the target.
    pub(crate) fn set_target(&mut self, target: DVector<f64>) {
        let g = DMatrix::from_column_slice(target.len(), 1, target.as_slice());
        let q = self.qt(&self.xt_dense(&g));
        self.qtt = q.column(0).into_owned();
        self.target = target;
    }

    /// `Q^T G` from `X_B^T G` (`R^-T` applied; zero when `R` is singular).
    pub(super) fn qt(&self, xtg: &DMatrix<f64>) -> DMatrix<f64> {
        self.r
            .tr_solve_upper_triangular(xtg)
            .unwrap_or_else(|| DMatrix::zeros(xtg.nrows(), xtg.ncols()))
    }

    /// `X_B^T g` of dense columns (`3n x k`), summed over blocks of rows in
    /// block order.
    pub(super) fn xt_dense(&self, g: &DMatrix<f64>) -> DMatrix<f64> {
        let p = self.basis.len();
        let k = g.ncols();
        let rows = g.nrows().min(3 * self.poses());
        let starts: Vec<usize> = (0..rows).step_by(3 * BLOCK).collect();
        let partial: Vec<Vec<f64>> = starts
            .par_iter()
            .map(|&first| {
                let mut sum = vec![0.0; p * k];
                for i in first..(first + 3 * BLOCK).min(rows) {
                    let row = self.row(i);
                    for a in 0..k {
                        let v = g[(i, a)];
                        if v != 0.0 {
                            let out = &mut sum[a * p..(a + 1) * p];
                            for (o, &c) in out.iter_mut().zip(&self.basis) {
                                *o += row[c] * v;
                            }
                        }
                    }
                }
                sum
            })
            .collect();
        let mut total = vec![0.0; p * k];
        for part in partial {
            total.iter_mut().zip(&part).for_each(|(t, v)| *t += v);
        }
        DMatrix::from_vec(p, k, total)
    }

    /// `X_B y` for a `p x k` coefficient matrix (`3n x k`).
    fn x_times(&self, y: &DMatrix<f64>) -> DMatrix<f64> {
        let rows = 3 * self.poses();
        DMatrix::from_fn(rows, y.ncols(), |i, a| {
            let row = self.row(i);
            self.basis
                .iter()
                .enumerate()
                .map(|(r, &c)| row[c] * y[(r, a)])
                .sum()
        })
    }

    /// Columns of the design for the model parameters `params`, projected
    /// onto the complement of the current basis (the part the rest cannot
    /// absorb).
    pub(crate) fn projected_columns(&self, params: &[usize]) -> DMatrix<f64> {
        let cols: Vec<usize> = (0..self.x_params.len())
            .filter(|&c| params.contains(&self.x_params[c]))
            .map(|c| c + 3)
            .collect();
        let g = DMatrix::from_fn(3 * self.poses(), cols.len(), |i, a| self.row(i)[cols[a]]);
        self.project(&g)
    }

    /// Projects dense columns onto the complement of the basis.
    pub(crate) fn project(&self, g: &DMatrix<f64>) -> DMatrix<f64> {
        let qtg = self.qt(&self.xt_dense(g));
        let y = self
            .r
            .solve_upper_triangular(&qtg)
            .unwrap_or_else(|| DMatrix::zeros(qtg.nrows(), qtg.ncols()));
        g - self.x_times(&y)
    }

    /// The projections `X_j^T d_jb` of the directions `wanted` for the
    /// poses `range` (see [`Projections`]).
    pub(crate) fn projections(&self, range: Range<usize>, wanted: &[bool; 6]) -> Projections {
        let p = self.basis.len();
        let len = range.len();
        let mut of: [Vec<f64>; 6] = std::array::from_fn(|b| {
            if wanted[b] {
                vec![0.0; p * len]
            } else {
                Vec::new()
            }
        });
        // A tile of poses at a time, pose-major, then copied into rows.
        const TILE: usize = 8;
        let mut buffer = vec![0.0; p];
        let mut tile = vec![[0.0; TILE]; p];
        let first = range.start;
        for t0 in (0..len).step_by(TILE) {
            let width = TILE.min(len - t0);
            for b in (0..6).filter(|&b| wanted[b]) {
                tile.iter_mut().for_each(|v| *v = [0.0; TILE]);
                for tt in 0..width {
                    let j = first + t0 + tt;
                    for c in 0..3 {
                        let w = self.direction(j, b)[c];
                        if w == 0.0 {
                            continue;
                        }
                        let row = self.basis_row(3 * j + c, &mut buffer);
                        for (v, x) in tile.iter_mut().zip(row) {
                            v[tt] += x * w;
                        }
                    }
                }
                for (r, v) in tile.iter().enumerate() {
                    of[b][r * len + t0..r * len + t0 + width].copy_from_slice(&v[..width]);
                }
            }
        }
        Projections { of }
    }

    /// `d_ja . d_jb` at pose `j`.
    pub(super) fn gram(&self, j: usize, a: usize, b: usize) -> f64 {
        dot3(&self.direction(j, a), &self.direction(j, b))
    }

    /// `d_jb . t_j` at pose `j`.
    pub(super) fn target_product(&self, j: usize, b: usize) -> f64 {
        let t = &self.target.as_slice()[3 * j..3 * j + 3];
        let d = self.direction(j, b);
        d[0] * t[0] + d[1] * t[1] + d[2] * t[2]
    }

    /// The sums over the first `n` poses of `k` columns: column `a` at
    /// pose `j` is direction `directions[a]` times `values(j)[a]`. Blocks
    /// of poses in parallel, summed in block order.
    pub(super) fn sums(
        &self,
        n: usize,
        directions: &[usize],
        values: &(dyn Fn(usize, &mut [f64]) + Sync),
    ) -> Sums {
        let k = directions.len();
        let p = self.basis.len();
        let starts: Vec<usize> = (0..n).step_by(BLOCK).collect();
        let partial: Vec<Sums> = starts
            .par_iter()
            .map(|&start| {
                pulp::Arch::new().dispatch(SumsBlock {
                    lin: self,
                    poses: start..(start + BLOCK).min(n),
                    directions,
                    values,
                })
            })
            .collect();
        let mut total = Sums::zero(p, k);
        partial.iter().for_each(|s| total.add(s));
        total
    }

    /// Design row `i` on the basis columns (gathered into `buffer` when the
    /// basis leaves some out).
    pub(super) fn basis_row<'s>(&'s self, i: usize, buffer: &'s mut [f64]) -> &'s [f64] {
        let row = self.row(i);
        if self.basis.len() == self.width {
            return row;
        }
        for (o, &c) in buffer.iter_mut().zip(&self.basis) {
            *o = row[c];
        }
        buffer
    }

    /// The score from sums over poses of columns scaled by `scale`.
    pub(super) fn score_of(&self, sums: Sums, scale: f64) -> Score {
        let p = self.basis.len();
        let k = sums.gtt.len();
        let qtg = self.qt(&(DMatrix::from_vec(p, k, sums.xtg) * scale));
        let mut gtg = DMatrix::from_row_slice(k, k, &sums.gtg) * (scale * scale);
        for a in 0..k {
            for b in 0..a {
                gtg[(a, b)] = gtg[(b, a)];
            }
        }
        let gtt = DVector::from_vec(sums.gtt) * scale;
        score_from(&qtg, &gtg, &gtt, &self.qtt)
    }
}

/// One block of poses of [`Linearisation::sums`] (with the widest vector
/// instructions the CPU has; the products are element by element, the
/// same bits at any width).
struct SumsBlock<'a> {
    lin: &'a Linearisation,
    poses: Range<usize>,
    directions: &'a [usize],
    values: &'a (dyn Fn(usize, &mut [f64]) + Sync),
}

impl pulp::WithSimd for SumsBlock<'_> {
    type Output = Sums;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Sums {
        let SumsBlock {
            lin,
            poses,
            directions,
            values,
        } = self;
        let k = directions.len();
        let p = lin.basis.len();
        let mut sums = Sums::zero(p, k);
        // The columns' values and 3-vectors at one pose.
        let mut v = vec![0.0; k];
        let mut g = vec![[0.0; 3]; k];
        let mut buffer = vec![0.0; p];
        for j in poses {
            values(j, &mut v);
            let t = &lin.target.as_slice()[3 * j..3 * j + 3];
            for a in 0..k {
                g[a] = lin.direction(j, directions[a]).map(|x| x * v[a]);
                sums.gtt[a] += g[a][0] * t[0] + g[a][1] * t[1] + g[a][2] * t[2];
                for b in 0..=a {
                    sums.gtg[b * k + a] += dot3(&g[a], &g[b]);
                }
            }
            for c in 0..3 {
                let row = lin.basis_row(3 * j + c, &mut buffer);
                for (a, ga) in g.iter().enumerate() {
                    let w = ga[c];
                    if w != 0.0 {
                        axpy(simd, &mut sums.xtg[a * p..(a + 1) * p], row, w);
                    }
                }
            }
        }
        sums
    }
}
