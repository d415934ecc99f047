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

use std::ops::Range;

use nalgebra::{DMatrix, DVector, Matrix3};
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::ReadingModel;
use tricept_kinematics::UpJoints;
use tricept_numerics::linalg::TriangularAccumulator;

use tricept_model::effects::Basis;

use crate::fit::Fit;
use crate::terms::{Frame, GenericTerm, Term};

/// Numerical rank threshold of a term's projected columns: an eigenvalue of
/// `M` below this share of the largest squared column norm of `G` is a
/// direction the fitted model already absorbs.
const ABSORBED: f64 = 1e-10;

/// Poses per block of the sums over poses (and of the period scan).
const BLOCK: usize = 256;

/// Poses per block of the linearisation's evaluation and of its `R`.
const EVALUATION_BLOCK: usize = 4096;

/// Frequencies between exact evaluations of the scan's sines and cosines
/// (in between, a rotation: its rounding grows by about one unit in the
/// last place per frequency).
const SCAN_RESEED: usize = 32;

/// Blocks of the scan summed at a time.
const SCAN_PARALLEL_BLOCKS: usize = 16;

/// Sums over poses of the products a score needs, for `k` columns and `p`
/// basis columns: `X^T G` (`p x k`, column-major), the upper triangle of
/// `G^T G` (row-major) and `G^T t`.
struct Sums {
    xtg: Vec<f64>,
    gtg: Vec<f64>,
    gtt: Vec<f64>,
}

impl Sums {
    fn zero(p: usize, k: usize) -> Sums {
        Sums {
            xtg: vec![0.0; p * k],
            gtg: vec![0.0; k * k],
            gtt: vec![0.0; k],
        }
    }

    fn add(&mut self, other: &Sums) {
        for (a, b) in [
            (&mut self.xtg, &other.xtg),
            (&mut self.gtg, &other.gtg),
            (&mut self.gtt, &other.gtt),
        ] {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
    }
}

/// The projections of the six directions of a block of poses on the
/// basis columns: `of[b]` holds `X_j^T d_jb`, `p x len` with the poses of a
/// basis column contiguous (empty for a direction not asked for).
pub(crate) struct Projections {
    /// Per direction, `p x len`, row-major.
    pub(crate) of: [Vec<f64>; 6],
}

/// The products of a step column (`1e-3` times one leg's direction) over
/// the poses whose command lies between two cuts of the step scan:
/// `Q^T g` (before the `1e-3`), `g^T g` (before `1e-6`), `g^T t` (before
/// `1e-3`), and the number of poses.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StepSums {
    qtg: Vec<f64>,
    gtg: f64,
    gtt: f64,
    /// Poses summed.
    pub(crate) poses: usize,
}

impl StepSums {
    fn zero(p: usize) -> StepSums {
        StepSums {
            qtg: vec![0.0; p],
            gtg: 0.0,
            gtt: 0.0,
            poses: 0,
        }
    }

    /// `self - other`: the poses of `self` not in `other` (prefix sums).
    fn minus(&self, other: &StepSums) -> StepSums {
        StepSums {
            qtg: self
                .qtg
                .iter()
                .zip(&other.qtg)
                .map(|(a, b)| a - b)
                .collect(),
            gtg: self.gtg - other.gtg,
            gtt: self.gtt - other.gtt,
            poses: self.poses - other.poses,
        }
    }

    fn add(&mut self, other: &StepSums) {
        self.qtg
            .iter_mut()
            .zip(&other.qtg)
            .for_each(|(a, b)| *a += b);
        self.gtg += other.gtg;
        self.gtt += other.gtt;
        self.poses += other.poses;
    }
}

/// How much a term explains of a target.
#[derive(Debug, Clone)]
pub(crate) struct Score {
    /// Explained sum of squares (noise units squared).
    pub(crate) explained: f64,
    /// Numerical rank of the term's new directions.
    pub(crate) rank: usize,
    /// Least-squares coefficients of the term's columns (its parameters).
    pub(crate) coefficients: DVector<f64>,
    /// Their covariance in noise units (`M^+`).
    pub(crate) covariance: DMatrix<f64>,
}

impl Score {
    fn none(k: usize) -> Score {
        Score {
            explained: 0.0,
            rank: 0,
            coefficients: DVector::zeros(k),
            covariance: DMatrix::zeros(k, k),
        }
    }
}

/// The score from the three products (see the module docs).
pub(crate) fn score_from(
    qtg: &DMatrix<f64>,
    gtg: &DMatrix<f64>,
    gtt: &DVector<f64>,
    qtt: &DVector<f64>,
) -> Score {
    let k = gtg.nrows();
    let m = gtg - qtg.transpose() * qtg;
    let v = gtt - qtg.transpose() * qtt;
    let scale = (0..k).map(|i| gtg[(i, i)]).fold(0.0, f64::max);
    let mut out = Score::none(k);
    if !(scale > 0.0 && scale.is_finite()) {
        return out;
    }
    let m = (&m + m.transpose()) * 0.5;
    let eig = m.symmetric_eigen();
    for (i, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda > ABSORBED * scale {
            let u = eig.eigenvectors.column(i);
            let c = u.dot(&v);
            out.explained += c * c / lambda;
            out.rank += 1;
            out.coefficients += u * (c / lambda);
            out.covariance += u * u.transpose() / lambda;
        }
    }
    out
}

/// The linearisation of a fit on its poses.
#[derive(Debug, Clone)]
pub(crate) struct Linearisation {
    /// Weighted design `[offsets | identifiable parameters]`, `3n x width`,
    /// row after row (a pose's three rows together).
    rows: Vec<f64>,
    /// Columns of the design.
    width: usize,
    /// Model parameter index of each design column after the three offsets.
    pub(crate) x_params: Vec<usize>,
    /// The design columns of the fitted model (all, or all but a term's).
    basis: Vec<usize>,
    /// `R` of the basis columns (`X_B = Q R`, upper triangular).
    r: DMatrix<f64>,
    /// The target: weighted residuals of the fit unless replaced.
    pub(crate) target: DVector<f64>,
    /// Solved UP joints of every pose at the estimate.
    pub(crate) ups: Vec<UpJoints>,
    /// Per pose, the weighted directions of the three legs (`W J1^-1 e_i`);
    /// those of the readings are `e_c / sigma_c` ([`Linearisation::direction`]).
    directions: Vec<[[f64; 3]; 3]>,
    /// `1 / sigma_c` of the three readings.
    weights: [f64; 3],
    /// `Q^T t`.
    qtt: DVector<f64>,
    /// Weighted columns of extra terms at zero (`3n x m`).
    pub(crate) extra: DMatrix<f64>,
    /// Each extra term with its columns in `extra`.
    pub(crate) extra_terms: Vec<(Term, std::ops::Range<usize>)>,
}

fn basis_index(b: Basis) -> usize {
    match b {
        Basis::Leg(i) => i,
        Basis::Reading(c) => 3 + c,
    }
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
    fn direction(&self, j: usize, b: usize) -> [f64; 3] {
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
    fn row(&self, i: usize) -> &[f64] {
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
    fn qt(&self, xtg: &DMatrix<f64>) -> DMatrix<f64> {
        self.r
            .tr_solve_upper_triangular(xtg)
            .unwrap_or_else(|| DMatrix::zeros(xtg.nrows(), xtg.ncols()))
    }

    /// `X_B^T g` of dense columns (`3n x k`), summed over blocks of rows in
    /// block order.
    fn xt_dense(&self, g: &DMatrix<f64>) -> DMatrix<f64> {
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
    fn gram(&self, j: usize, a: usize, b: usize) -> f64 {
        dot3(&self.direction(j, a), &self.direction(j, b))
    }

    /// `d_jb . t_j` at pose `j`.
    fn target_product(&self, j: usize, b: usize) -> f64 {
        let t = &self.target.as_slice()[3 * j..3 * j + 3];
        let d = self.direction(j, b);
        d[0] * t[0] + d[1] * t[1] + d[2] * t[2]
    }

    /// Per-pose values of every parameter of a generic term, with its
    /// direction.
    pub(crate) fn generic_columns(
        &self,
        term: &GenericTerm,
        frame: &Frame,
        data: &Dataset,
    ) -> Vec<(usize, Vec<f64>)> {
        let mut cols: Vec<(usize, Vec<f64>)> = Vec::new();
        for (j, pose) in data.poses.iter().enumerate() {
            let values = if term.acts_on_legs() {
                term.leg_values(frame, pose)
            } else {
                term.reading_values(frame, pose, &self.ups[j])
            };
            if cols.is_empty() {
                cols = values
                    .iter()
                    .map(|(_, b, _)| (basis_index(*b), vec![0.0; data.poses.len()]))
                    .collect();
            }
            // A generic term has one entry per parameter, in order.
            for (k, (_, _, v)) in values.into_iter().enumerate() {
                if let Some(c) = cols.get_mut(k) {
                    c.1[j] = v;
                }
            }
        }
        cols
    }

    /// The score of a generic term's columns ([`Linearisation::generic_columns`]),
    /// evaluated pose by pose within the sums (no column is kept).
    pub(crate) fn score_generic(&self, term: &GenericTerm, frame: &Frame, data: &Dataset) -> Score {
        let n = self.poses().min(data.poses.len());
        let values_at = |j: usize| {
            if term.acts_on_legs() {
                term.leg_values(frame, &data.poses[j])
            } else {
                term.reading_values(frame, &data.poses[j], &self.ups[j])
            }
        };
        // The directions of the first pose's entries, one per parameter.
        let directions: Vec<usize> = match n {
            0 => Vec::new(),
            _ => values_at(0)
                .iter()
                .map(|(_, b, _)| basis_index(*b))
                .collect(),
        };
        let values = |j: usize, out: &mut [f64]| {
            out.iter_mut().for_each(|o| *o = 0.0);
            for (o, (_, _, v)) in out.iter_mut().zip(values_at(j)) {
                *o = v;
            }
        };
        self.score_of(self.sums(n, &directions, &values), 1.0)
    }

    /// The score of columns given as (direction, per-pose value).
    pub(crate) fn score_columns(&self, cols: &[(usize, Vec<f64>)]) -> Score {
        let n = self
            .poses()
            .min(cols.iter().map(|c| c.1.len()).min().unwrap_or(0));
        let directions: Vec<usize> = cols.iter().map(|c| c.0).collect();
        let values = |j: usize, out: &mut [f64]| {
            for (o, (_, f)) in out.iter_mut().zip(cols) {
                *o = f[j];
            }
        };
        self.score_of(self.sums(n, &directions, &values), 1.0)
    }

    /// The sums over the first `n` poses of `k` columns: column `a` at
    /// pose `j` is direction `directions[a]` times `values(j)[a]`. Blocks
    /// of poses in parallel, summed in block order.
    fn sums(
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
    fn basis_row<'s>(&'s self, i: usize, buffer: &'s mut [f64]) -> &'s [f64] {
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
    fn score_of(&self, sums: Sums, scale: f64) -> Score {
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

    /// The scores of the leg-periodic term on `legs` (its columns
    /// `1e-3 sin(2 pi f q_i)`, `1e-3 cos(2 pi f q_i)` per leg, as
    /// [`GenericTerm::leg_values`] gives them) at every frequency
    /// `f0 + k step`, `k < count` (1/mm): `(explained, rank)` per frequency,
    /// equal to [`Linearisation::score_columns`] of those columns up to
    /// rounding.
    ///
    /// One pass over the poses for the whole grid: the poses go in blocks
    /// of [`BLOCK`], whose projected directions stay in cache while every
    /// frequency accumulates its products, and the sines and cosines of
    /// consecutive frequencies follow by rotation (re-seeded exactly every
    /// [`SCAN_RESEED`] frequencies), so a frequency costs about
    /// `2 L p + 2 L (2 L + 1)` multiply-adds per pose for `L` legs and `p`
    /// fitted columns instead of a fresh evaluation of the term. Blocks run
    /// in parallel and are summed in their order: the same bits at any
    /// thread count.
    pub(crate) fn periodic_scan(
        &self,
        commands_mm: &[[f64; 3]],
        legs: &[usize],
        f0: f64,
        step: f64,
        count: usize,
    ) -> Vec<(f64, usize)> {
        let p = self.basis.len();
        let k = 2 * legs.len();
        let n = self.poses().min(commands_mm.len());
        let nl = legs.len();
        let mut wanted = [false; 6];
        legs.iter().for_each(|&i| wanted[i] = true);
        let block_sums = |start: usize| -> Vec<Sums> {
            let end = (start + BLOCK).min(n);
            let sums: Vec<Sums> = (0..count).map(|_| Sums::zero(p, k)).collect();
            // Per leg, over the block's poses: the projected directions,
            // the target products, the rotation by one grid step and the
            // current sine and cosine; per pair of legs, their directions'
            // inner products.
            let projections = self.projections(start..end, &wanted);
            let projected: Vec<&[f64]> = legs.iter().map(|&i| &projections.of[i][..]).collect();
            let products: Vec<Vec<f64>> = legs
                .iter()
                .map(|&i| (start..end).map(|j| self.target_product(j, i)).collect())
                .collect();
            let gram: Vec<Vec<f64>> = (0..nl * nl)
                .map(|ab| {
                    let (la, lb) = (legs[ab / nl], legs[ab % nl]);
                    (start..end).map(|j| self.gram(j, la, lb)).collect()
                })
                .collect();
            let angle = |f: f64, i: usize, j: usize| std::f64::consts::TAU * f * commands_mm[j][i];
            let rotation: Vec<Vec<(f64, f64)>> = if count > 1 {
                legs.iter()
                    .map(|&i| (start..end).map(|j| angle(step, i, j).sin_cos()).collect())
                    .collect()
            } else {
                vec![Vec::new(); nl]
            };
            pulp::Arch::new().dispatch(ScanBlock {
                commands_mm,
                legs,
                poses: start..end,
                f0,
                step,
                p,
                projected,
                products,
                gram,
                rotation,
                sums,
            })
        };
        let starts: Vec<usize> = (0..n).step_by(BLOCK).collect();
        let mut total: Vec<Sums> = (0..count).map(|_| Sums::zero(p, k)).collect();
        // A bounded number of blocks at a time (their sums are
        // `count x (p + k + 1) k` numbers each), added in block order.
        for group in starts.chunks(SCAN_PARALLEL_BLOCKS) {
            let partial: Vec<Vec<Sums>> =
                group.par_iter().map(|&start| block_sums(start)).collect();
            for block in partial {
                for (t, b) in total.iter_mut().zip(block) {
                    t.add(&b);
                }
            }
        }
        total
            .into_iter()
            .map(|t| {
                // The columns are `1e-3` sin and cos (mm per um).
                let s = self.score_of(t, 1e-3);
                (s.explained, s.rank)
            })
            .collect()
    }

    /// The score of the leg-periodic term on `legs` at frequency `f`
    /// (1/mm), as [`Linearisation::periodic_scan`] scores a frequency of
    /// its grid, up to rounding: its columns evaluated pose by pose.
    pub(crate) fn periodic_score(
        &self,
        commands_mm: &[[f64; 3]],
        legs: &[usize],
        f: f64,
    ) -> (f64, usize) {
        let n = self.poses().min(commands_mm.len());
        let directions: Vec<usize> = legs.iter().flat_map(|&i| [i, i]).collect();
        let values = |j: usize, out: &mut [f64]| {
            for (l, &i) in legs.iter().enumerate() {
                (out[2 * l], out[2 * l + 1]) =
                    (std::f64::consts::TAU * f * commands_mm[j][i]).sin_cos();
            }
        };
        // The columns are `1e-3` sin and cos (mm per um).
        let s = self.score_of(self.sums(n, &directions, &values), 1e-3);
        (s.explained, s.rank)
    }

    /// The prefix sums of the step scan of leg `leg` over the `cuts` of its
    /// command (increasing): element `k` sums the step column over the
    /// poses with `cuts[0] <= q < cuts[k]` (the last cut included), so that
    /// the indicator of `[cuts[u], cuts[v]]` has the products
    /// `prefix[v] - prefix[u]` ([`Linearisation::step_score`]). Poses
    /// outside the cuts are in no bin.
    ///
    /// One pass over the poses: each adds its `p + 2` numbers (its design
    /// rows times the leg's direction) to the bin of its command, in pose
    /// order, the bins are summed in their order and each prefix is taken
    /// to `Q^T g` once, so that a scan of `K` cuts costs `O(n p + K p^2)`
    /// and has the same bits at any thread count (it runs on one).
    pub(crate) fn step_prefix(
        &self,
        commands_mm: &[[f64; 3]],
        leg: usize,
        cuts: &[f64],
    ) -> Vec<StepSums> {
        let p = self.basis.len();
        let n = self.poses().min(commands_mm.len());
        let mut bins = vec![StepSums::zero(p); cuts.len().saturating_sub(1)];
        let (Some(&first), Some(&last)) = (cuts.first(), cuts.last()) else {
            return vec![StepSums::zero(p)];
        };
        let mut buffer = vec![0.0; p];
        for j in 0..n {
            let q = commands_mm[j][leg];
            if !(first..=last).contains(&q) || bins.is_empty() {
                continue;
            }
            let k = (cuts.partition_point(|c| *c <= q) - 1).min(bins.len() - 1);
            let bin = &mut bins[k];
            // X_j^T d_j,leg.
            let d = self.direction(j, leg);
            for c in 0..3 {
                let row = self.basis_row(3 * j + c, &mut buffer);
                bin.qtg
                    .iter_mut()
                    .zip(row)
                    .for_each(|(a, x)| *a += x * d[c]);
            }
            bin.gtg += self.gram(j, leg, leg);
            bin.gtt += self.target_product(j, leg);
            bin.poses += 1;
        }
        let mut prefix = Vec::with_capacity(bins.len() + 1);
        let mut running = StepSums::zero(p);
        prefix.push(running.clone());
        for b in &bins {
            running.add(b);
            prefix.push(running.clone());
        }
        // Each prefix's X^T g into Q^T g once (R^-T is linear: the
        // differences follow).
        for s in &mut prefix {
            let x = DMatrix::from_column_slice(p, 1, &s.qtg);
            s.qtg = self.qt(&x).as_slice().to_vec();
        }
        prefix
    }

    /// The score `(explained, rank)` of the step column over the poses
    /// between cuts `u < v` of `prefix` ([`Linearisation::step_prefix`]),
    /// and the number of those poses: equal to
    /// [`Linearisation::score_columns`] of the term's column up to
    /// rounding.
    pub(crate) fn step_score(
        &self,
        prefix: &[StepSums],
        u: usize,
        v: usize,
    ) -> (f64, usize, usize) {
        let (Some(a), Some(b)) = (prefix.get(u), prefix.get(v)) else {
            return (0.0, 0, 0);
        };
        if u >= v {
            return (0.0, 0, 0);
        }
        let s = b.minus(a);
        let qtg = DMatrix::from_column_slice(s.qtg.len(), 1, &s.qtg) * 1e-3;
        let gtg = DMatrix::from_element(1, 1, s.gtg * 1e-6);
        let gtt = DVector::from_element(1, s.gtt * 1e-3);
        let score = score_from(&qtg, &gtg, &gtt, &self.qtt);
        (score.explained, score.rank, s.poses)
    }

    /// Dense weighted columns (`3n x k`) of per-pose values.
    pub(crate) fn dense(&self, cols: &[(usize, Vec<f64>)]) -> DMatrix<f64> {
        let n = self.poses();
        let mut g = DMatrix::zeros(3 * n, cols.len());
        for (a, (b, f)) in cols.iter().enumerate() {
            for j in 0..n {
                for c in 0..3 {
                    g[(3 * j + c, a)] = f[j] * self.direction(j, *b)[c];
                }
            }
        }
        g
    }

    /// The score of dense weighted columns.
    pub(crate) fn score_dense(&self, g: &DMatrix<f64>) -> Score {
        let qtg = self.qt(&self.xt_dense(g));
        let gtg = g.transpose() * g;
        let gtt = g.transpose() * &self.target;
        score_from(&qtg, &gtg, &gtt, &self.qtt)
    }

    /// The columns of an extra term.
    pub(crate) fn extra_columns(&self, term: &Term) -> Option<DMatrix<f64>> {
        self.extra_terms
            .iter()
            .find(|(t, _)| t == term)
            .map(|(_, r)| self.extra.columns(r.start, r.len()).into_owned())
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

/// `out += w x`, element by element.
#[inline(always)]
fn axpy<S: pulp::Simd>(simd: S, out: &mut [f64], x: &[f64], w: f64) {
    let len = out.len().min(x.len());
    let (oh, ot) = S::as_mut_simd_f64s(&mut out[..len]);
    let (xh, xt) = S::as_simd_f64s(&x[..len]);
    let wv = simd.splat_f64s(w);
    for (o, x) in oh.iter_mut().zip(xh) {
        *o = simd.add_f64s(*o, simd.mul_f64s(*x, wv));
    }
    for (o, x) in ot.iter_mut().zip(xt) {
        *o += x * w;
    }
}

/// The frequency loop of one block of [`Linearisation::periodic_scan`],
/// run with the widest vector instructions the CPU has
/// ([`pulp::Arch::dispatch`]). The code is scalar: each product's four
/// interleaved partial sums are the same at any vector width and nothing
/// is fused into a multiply-add, so the bits do not depend on the CPU.
struct ScanBlock<'a> {
    commands_mm: &'a [[f64; 3]],
    legs: &'a [usize],
    poses: Range<usize>,
    f0: f64,
    step: f64,
    /// Basis columns.
    p: usize,
    /// Per leg, the projected directions (`p x len`, row-major).
    projected: Vec<&'a [f64]>,
    /// Per leg, the directions' products with the target.
    products: Vec<Vec<f64>>,
    /// Per pair of legs, their directions' inner products.
    gram: Vec<Vec<f64>>,
    /// Per leg, the rotation by one grid step.
    rotation: Vec<Vec<(f64, f64)>>,
    /// Per frequency, the block's sums.
    sums: Vec<Sums>,
}

impl pulp::WithSimd for ScanBlock<'_> {
    type Output = Vec<Sums>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Vec<Sums> {
        self.run(simd)
    }
}

impl ScanBlock<'_> {
    #[inline(always)]
    fn run<S: pulp::Simd>(self, simd: S) -> Vec<Sums> {
        let (commands_mm, legs, poses, p) = (self.commands_mm, self.legs, &self.poses, self.p);
        let (projected, products, gram) = (&self.projected, &self.products, &self.gram);
        let mut sums = self.sums;
        let len = poses.len();
        let nl = legs.len();
        let k = 2 * nl;
        let angle = |f: f64, i: usize, j: usize| std::f64::consts::TAU * f * commands_mm[j][i];
        // values[2 l] the sines of leg l, values[2 l + 1] its cosines.
        let mut values = vec![vec![0.0; len]; 2 * nl];
        for (f, acc) in sums.iter_mut().enumerate() {
            let frequency = self.f0 + f as f64 * self.step;
            for (l, &i) in legs.iter().enumerate() {
                let (sines, rest) = values[2 * l..].split_at_mut(1);
                let (sines, cosines) = (&mut sines[0], &mut rest[0]);
                if f % SCAN_RESEED == 0 {
                    for (t, j) in poses.clone().enumerate() {
                        (sines[t], cosines[t]) = angle(frequency, i, j).sin_cos();
                    }
                } else {
                    for ((s, c), &(ws, wc)) in sines
                        .iter_mut()
                        .zip(cosines.iter_mut())
                        .zip(&self.rotation[l])
                    {
                        (*s, *c) = (*s * wc + *c * ws, *c * wc - *s * ws);
                    }
                }
                // X^T G for the leg's two columns: a pair of dot products
                // per basis column, two columns at a time.
                let (qs, qc) = acc.xtg[2 * l * p..(2 * l + 2) * p].split_at_mut(p);
                let rows = projected[l];
                for r in (0..p).step_by(2) {
                    let x = &rows[r * len..(r + 1) * len];
                    if r + 1 < p {
                        let y = &rows[(r + 1) * len..(r + 2) * len];
                        let [sx, cx, sy, cy] = sums4(
                            simd,
                            [x, y, sines, cosines],
                            |[x, y, s, c]| {
                                [(x, s), (x, c), (y, s), (y, c)].map(|(a, b)| simd.mul_f64s(*a, *b))
                            },
                            |[x, y, s, c]| [x * s, x * c, y * s, y * c],
                        );
                        (qs[r], qc[r], qs[r + 1], qc[r + 1]) = (sx, cx, sy, cy);
                    } else {
                        let [sx, cx] = sums4(
                            simd,
                            [x, sines, cosines],
                            |[x, s, c]| [simd.mul_f64s(*x, *s), simd.mul_f64s(*x, *c)],
                            |[x, s, c]| [x * s, x * c],
                        );
                        (qs[r], qc[r]) = (sx, cx);
                    }
                }
            }
            for a in 0..k {
                let va = &values[a];
                let [t] = sums4(
                    simd,
                    [va, &products[a / 2]],
                    |[x, y]| [simd.mul_f64s(*x, *y)],
                    |[x, y]| [x * y],
                );
                acc.gtt[a] += t;
                for b in a..k {
                    let g = &gram[(a / 2) * nl + b / 2];
                    let [w] = sums4(
                        simd,
                        [va, &values[b], g],
                        |[x, y, w]| [simd.mul_f64s(simd.mul_f64s(*x, *y), *w)],
                        |[x, y, w]| [x * y * w],
                    );
                    acc.gtg[a * k + b] += w;
                }
            }
        }
        sums
    }
}

/// The four lanes of a four-wide vector.
#[inline(always)]
fn lanes<S: pulp::Simd>(v: S::f64s) -> [f64; 4] {
    let mut out = [0.0; 4];
    if let Some(o) = S::as_mut_simd_f64s(&mut out).0.first_mut() {
        *o = v;
    }
    out
}

/// `(s0 + s1) + (s2 + s3) + tail` of four partial sums.
#[inline(always)]
fn combine(s: [f64; 4], tail: f64) -> f64 {
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// `n` products of slices, summed as the scalar kernels below do (element
/// `t` into partial sum `t mod 4`, the tail after the last whole four in
/// order, then [`combine`]) with four-wide vectors when `S` has four lanes
/// and with the scalar kernel otherwise: the same bits either way (no
/// fused multiply-add).
#[inline(always)]
fn sums4<S: pulp::Simd, const N: usize, const M: usize>(
    simd: S,
    x: [&[f64]; M],
    vector: impl Fn(&[S::f64s; M]) -> [S::f64s; N],
    scalar: impl Fn(&[f64; M]) -> [f64; N],
) -> [f64; N] {
    let len = x.iter().map(|v| v.len()).min().unwrap_or(0);
    let whole = len / 4 * 4;
    let mut partial = [[0.0; 4]; N];
    if S::F64_LANES == 4 {
        let heads = x.map(|v| S::as_simd_f64s(&v[..whole]).0);
        let mut acc = [simd.splat_f64s(0.0); N];
        for i in 0..whole / 4 {
            let t = vector(&std::array::from_fn(|m| heads[m][i]));
            for q in 0..N {
                acc[q] = simd.add_f64s(acc[q], t[q]);
            }
        }
        for q in 0..N {
            partial[q] = lanes::<S>(acc[q]);
        }
    } else {
        for i in (0..whole).step_by(4) {
            for l in 0..4 {
                let t = scalar(&std::array::from_fn(|m| x[m][i + l]));
                for q in 0..N {
                    partial[q][l] += t[q];
                }
            }
        }
    }
    let mut tail = [0.0; N];
    for i in whole..len {
        let t = scalar(&std::array::from_fn(|m| x[m][i]));
        for q in 0..N {
            tail[q] += t[q];
        }
    }
    std::array::from_fn(|q| combine(partial[q], tail[q]))
}

/// `a . b` of 3-vectors.
fn dot3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Whether the column space of `a` lies inside that of `b` (every
/// canonical correlation 1 to `1e-6`): `b` generalises `a`.
pub(crate) fn nested(a: &DMatrix<f64>, b: &DMatrix<f64>) -> bool {
    let (Some(ua), Some(ub)) = (column_basis(a), column_basis(b)) else {
        return false;
    };
    ua.ncols() <= ub.ncols()
        && (ua.transpose() * ub)
            .singular_values()
            .iter()
            .all(|s| *s > 1.0 - 1e-6)
}

/// An orthonormal basis of the numerically independent columns of `m`.
fn column_basis(m: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let svd = m.clone().svd(true, false);
    let top = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > 1e-8 * top && top > 0.0)
        .collect();
    let u = svd.u?;
    (!keep.is_empty()).then(|| u.select_columns(&keep))
}

/// Largest canonical correlation between the column spaces of `a` and `b`
/// (1 when they share a direction).
pub(crate) fn canonical_correlation(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    match (column_basis(a), column_basis(b)) {
        (Some(ua), Some(ub)) => (ua.transpose() * ub)
            .singular_values()
            .iter()
            .copied()
            .fold(0.0, f64::max)
            .min(1.0),
        _ => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use tricept_model::effects::{periodic_extra_mm, segment_extra_mm};

    /// An orthonormal basis of the column space of `a` (thin QR).
    fn orthonormal_basis(a: &DMatrix<f64>) -> DMatrix<f64> {
        a.clone().qr().q()
    }

    /// A linearisation of `n` random poses: random fitted columns,
    /// directions and target, and leg commands over 600-1000 mm.
    fn synthetic(n: usize, seed: u64) -> (Linearisation, Vec<[f64; 3]>) {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        let mut normal = || rng.random_range(-1.0..1.0);
        let width = 7;
        let rows: Vec<f64> = (0..3 * n * width).map(|_| normal()).collect();
        let target = DVector::from_fn(3 * n, |_, _| normal());
        let directions: Vec<[[f64; 3]; 3]> = (0..n)
            .map(|_| std::array::from_fn(|_| std::array::from_fn(|_| normal())))
            .collect();
        let weights = [2.0 + normal(), 0.5, 3.0];
        let commands: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|_| 800.0 + 200.0 * normal()))
            .collect();
        let mut lin = Linearisation {
            rows,
            width,
            x_params: (0..4).collect(),
            basis: Vec::new(),
            r: DMatrix::zeros(0, 0),
            target: target.clone(),
            ups: Vec::new(),
            directions,
            weights,
            qtt: DVector::zeros(0),
            extra: DMatrix::zeros(3 * n, 0),
            extra_terms: Vec::new(),
        };
        lin.set_basis(&[]);
        // A target with a periodic part on leg 2 (period 10 mm), so that
        // the scores range from noise to signal.
        let signal = lin.dense(&[(
            1,
            (0..n)
                .map(|j| 3.0 * periodic_extra_mm(1000.0, 300.0, 10.0, commands[j][1]))
                .collect(),
        )]);
        lin.set_target(target + signal.column(0));
        (lin, commands)
    }

    /// A scan's `(explained, rank)` equals the direct score to rounding.
    fn assert_same_score(scan: (f64, usize), direct: &Score, what: &str) {
        assert_eq!(scan.1, direct.rank, "{what}");
        let tolerance = 1e-9 * direct.explained.max(1.0);
        assert!(
            (scan.0 - direct.explained).abs() <= tolerance,
            "{what}: scan {} against {}",
            scan.0,
            direct.explained
        );
    }

    #[test]
    fn the_periodic_scan_equals_scoring_each_period() {
        // 700 poses: several blocks, the last one partial.
        let (lin, commands) = synthetic(700, 5);
        let (f0, step, count) = (1.0 / 50.0, 1.0 / 1600.0, 140);
        for legs in [vec![0, 1, 2], vec![1]] {
            let scan = lin.periodic_scan(&commands, &legs, f0, step, count);
            assert_eq!(scan.len(), count);
            let mut best = (0, f64::MIN);
            for (k, &(explained, rank)) in scan.iter().enumerate() {
                let period = 1.0 / (f0 + k as f64 * step);
                let cols: Vec<(usize, Vec<f64>)> = legs
                    .iter()
                    .flat_map(|&i| {
                        let at = |a: f64, b: f64| -> Vec<f64> {
                            commands
                                .iter()
                                .map(|q| periodic_extra_mm(a, b, period, q[i]))
                                .collect()
                        };
                        [(i, at(1.0, 0.0)), (i, at(0.0, 1.0))]
                    })
                    .collect();
                let direct = lin.score_columns(&cols);
                assert_same_score((explained, rank), &direct, &format!("frequency {k}"));
                let one = lin.periodic_score(&commands, &legs, f0 + k as f64 * step);
                assert_same_score(one, &direct, &format!("frequency {k} alone"));
                if explained > best.1 {
                    best = (k, explained);
                }
            }
            // The hidden 10 mm period on leg 2 is grid frequency 128.
            assert_eq!(best.0, 128, "{legs:?}");
        }
    }

    #[test]
    fn scores_without_q_equal_those_with_an_explicit_q() {
        let (mut lin, commands) = synthetic(900, 11);
        // Columns of very different sizes, as offsets (rad) and parameters
        // (mm) are in noise units.
        let width = lin.width;
        for (i, v) in lin.rows.iter_mut().enumerate() {
            *v *= 10f64.powi((i % width) as i32 - 2);
        }
        let n = lin.poses();
        let x = DMatrix::from_fn(3 * n, width, |i, c| lin.row(i)[c]);
        let cols: Vec<(usize, Vec<f64>)> = [(0, 0.0), (0, 1.0), (2, 0.0), (4, 0.0)]
            .iter()
            .map(|&(b, phase)| {
                let leg = if b < 3 { b } else { 1 };
                let values = commands
                    .iter()
                    .map(|q| periodic_extra_mm(1.0 - phase, phase, 37.0, q[leg]))
                    .collect();
                (b, values)
            })
            .collect();
        for drop in [vec![], vec![1]] {
            lin.set_basis(&drop);
            let keep: Vec<usize> = (0..width)
                .filter(|&c| c < 3 || !drop.contains(&(c - 3)))
                .collect();
            let q = orthonormal_basis(&x.select_columns(&keep));
            let g = lin.dense(&cols);
            let t = &lin.target;
            let explicit = score_from(
                &(q.transpose() * &g),
                &(g.transpose() * &g),
                &(g.transpose() * t),
                &(q.transpose() * t),
            );
            for s in [lin.score_columns(&cols), lin.score_dense(&g)] {
                assert_eq!(s.rank, explicit.rank, "{drop:?}");
                let tolerance = 1e-9 * explicit.explained.max(1.0);
                assert!(
                    (s.explained - explicit.explained).abs() <= tolerance,
                    "{drop:?}: {} against {}",
                    s.explained,
                    explicit.explained
                );
                let dc = (&s.coefficients - &explicit.coefficients).norm();
                assert!(dc <= 1e-9 * explicit.coefficients.norm(), "{drop:?}: {dc}");
            }
            let projected = &g - &q * (q.transpose() * &g);
            let dp = (lin.project(&g) - &projected).norm();
            assert!(dp <= 1e-9 * g.norm(), "{drop:?}: {dp}");
            // A design column projects to nothing once in the basis, and to
            // its own residual when dropped.
            let own = lin.projected_columns(&[1]);
            let column = x.column(4).into_owned();
            let expected = if drop.is_empty() {
                DVector::zeros(3 * n)
            } else {
                &column - &q * (q.transpose() * &column)
            };
            assert!((own.column(0) - expected).norm() <= 1e-9 * column.norm());
        }
    }

    #[test]
    fn the_step_scan_equals_scoring_each_segment() {
        // 700 poses over 600-1000 mm; cuts every 25 mm over that range.
        let (lin, commands) = synthetic(700, 11);
        let cuts: Vec<f64> = (0..=16).map(|k| 600.0 + 25.0 * f64::from(k)).collect();
        for leg in 0..3 {
            let prefix = lin.step_prefix(&commands, leg, &cuts);
            assert_eq!(prefix.len(), cuts.len());
            for u in 0..cuts.len() {
                for v in u + 1..cuts.len() {
                    let (explained, rank, inside) = lin.step_score(&prefix, u, v);
                    let column: Vec<f64> = commands
                        .iter()
                        .map(|q| segment_extra_mm(1.0, cuts[u], cuts[v], q[leg]))
                        .collect();
                    let expected_inside = column.iter().filter(|v| **v != 0.0).count();
                    assert_eq!(inside, expected_inside, "leg {leg} cuts {u}-{v}");
                    let direct = lin.score_columns(&[(leg, column)]);
                    assert_same_score(
                        (explained, rank),
                        &direct,
                        &format!("leg {leg} cuts {u}-{v}"),
                    );
                }
            }
            // A segment the wrong way round, or of one cut, is empty.
            assert_eq!(lin.step_score(&prefix, 5, 3), (0.0, 0, 0));
            assert_eq!(lin.step_score(&prefix, 4, 4), (0.0, 0, 0));
        }
    }

    #[test]
    fn the_periodic_scan_has_the_same_bits_at_any_thread_count() {
        let (lin, commands) = synthetic(3000, 8);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| lin.periodic_scan(&commands, &[0, 1, 2], 0.02, 1.0 / 1600.0, 40))
        };
        let one = run(1);
        for threads in [2, 3] {
            let other = run(threads);
            assert!(
                one.iter()
                    .zip(&other)
                    .all(|(a, b)| a.0.to_bits() == b.0.to_bits() && a.1 == b.1),
                "{threads} threads"
            );
        }
    }

    #[test]
    fn vector_sums_have_the_bits_of_the_scalar_ones() {
        fn sums<S: pulp::Simd>(simd: S, x: &[f64], y: &[f64], w: &[f64]) -> [f64; 2] {
            sums4(
                simd,
                [x, y, w],
                |[x, y, w]| {
                    [
                        simd.mul_f64s(*x, *y),
                        simd.mul_f64s(simd.mul_f64s(*x, *y), *w),
                    ]
                },
                |[x, y, w]| [x * y, x * y * w],
            )
        }
        for len in [0, 3, 4, 9, 256, 1001] {
            let v = |k: f64| -> Vec<f64> { (0..len).map(|i| (i as f64 * k).sin()).collect() };
            let (x, y, w) = (v(0.3), v(1.7), v(2.9));
            let scalar = sums(pulp::Scalar::new(), &x, &y, &w);
            let naive: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
            assert!(
                (scalar[0] - naive).abs() <= 1e-12 * (len as f64 + 1.0),
                "{len}"
            );
            #[cfg(target_arch = "x86_64")]
            if let Some(simd) = pulp::x86::V3::try_new() {
                let vector = sums(simd, &x, &y, &w);
                assert_eq!(vector.map(f64::to_bits), scalar.map(f64::to_bits), "{len}");
            }
        }
    }

    #[test]
    fn score_is_the_explained_sum_of_squares() {
        // x = [1, 1, 1, 1]^T (fitted), g = [0, 1, 2, 3]^T, t = g - mean(g) + noise.
        let x = DMatrix::from_column_slice(4, 1, &[1.0, 1.0, 1.0, 1.0]);
        let q = orthonormal_basis(&x);
        let g = DMatrix::from_column_slice(4, 1, &[0.0, 1.0, 2.0, 3.0]);
        let t = DVector::from_column_slice(&[-1.5, -0.5, 0.5, 1.5]) * 2.0;
        let s = score_from(
            &(q.transpose() * &g),
            &(g.transpose() * &g),
            &(g.transpose() * &t),
            &(q.transpose() * &t),
        );
        // t lies in span(x, g): everything is explained, with coefficient 2.
        assert!((s.explained - t.norm_squared()).abs() < 1e-12);
        assert_eq!(s.rank, 1);
        assert!((s.coefficients[0] - 2.0).abs() < 1e-12);
        // A column inside span(x) explains nothing and has no rank.
        let s = score_from(
            &(q.transpose() * &x),
            &(x.transpose() * &x),
            &(x.transpose() * &t),
            &(q.transpose() * &t),
        );
        assert_eq!(s.rank, 0);
        assert_eq!(s.explained, 0.0);
    }

    #[test]
    fn canonical_correlation_of_shared_and_orthogonal_spaces() {
        let a = DMatrix::from_column_slice(3, 1, &[1.0, 0.0, 0.0]);
        let b = DMatrix::from_column_slice(3, 2, &[2.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let c = DMatrix::from_column_slice(3, 1, &[0.0, 0.0, 1.0]);
        assert!((canonical_correlation(&a, &b) - 1.0).abs() < 1e-12);
        assert!(canonical_correlation(&a, &c).abs() < 1e-12);
    }
}
