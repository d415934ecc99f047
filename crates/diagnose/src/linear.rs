//! The fitted model linearised at its estimate: what a further term could
//! still explain, without refitting.
//!
//! With `X` the weighted design of the fit (the three sensor offsets and
//! the identifiable parameters, `3n` rows in noise units), `Q` an
//! orthonormal basis of it and `t` a target (the weighted residuals, or a
//! fitted term's signature), the columns `G` of a candidate term explain
//!
//! ```text
//! S(G) = v^T M^+ v,   M = G^T G - (Q^T G)^T (Q^T G),   v = G^T t - (Q^T G)^T (Q^T t)
//! ```
//!
//! of `|t|^2`: the Rao score statistic, the linearised drop of chi-square
//! (its degrees of freedom the numerical rank of `M`). Generic terms are
//! combinations of six per-pose directions (the three legs through
//! `W J1^-1 e_i`, the three readings through `e_c / sigma_c`) times scalar
//! functions of the pose, so every product above reduces to sums over poses
//! of precomputed 3-vectors: a period of the ball-screw scan costs a few
//! hundred flops per pose.

use nalgebra::{DMatrix, DVector, Matrix3};
use tricept_data::Dataset;
use tricept_ident::ReadingModel;
use tricept_kinematics::UpJoints;

use tricept_model::effects::Basis;

use crate::fit::Fit;
use crate::terms::{Frame, GenericTerm, Term};

/// Numerical rank threshold of a term's projected columns: an eigenvalue of
/// `M` below this share of the largest squared column norm of `G` is a
/// direction the fitted model already absorbs.
const ABSORBED: f64 = 1e-10;

/// Poses per block of [`Linearisation::periodic_scan`].
const SCAN_BLOCK: usize = 256;

/// Frequencies between exact evaluations of the scan's sines and cosines
/// (in between, a rotation: its rounding grows by about one unit in the
/// last place per frequency).
const SCAN_RESEED: usize = 32;

/// Blocks of the scan summed at a time.
const SCAN_PARALLEL_BLOCKS: usize = 16;

/// The products of one frequency of the scan, accumulated over poses:
/// `Q^T G` (`p x k`, column-major), the upper triangle of `G^T G` (row-major)
/// and `G^T t`.
struct PeriodicSums {
    qtg: Vec<f64>,
    gtg: Vec<f64>,
    gtt: Vec<f64>,
}

impl PeriodicSums {
    fn add(&mut self, other: &PeriodicSums) {
        for (a, b) in [
            (&mut self.qtg, &other.qtg),
            (&mut self.gtg, &other.gtg),
            (&mut self.gtt, &other.gtt),
        ] {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
    }
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
    let mut out = Score {
        explained: 0.0,
        rank: 0,
        coefficients: DVector::zeros(k),
        covariance: DMatrix::zeros(k, k),
    };
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
    /// Weighted design `[offsets | identifiable parameters]`, `3n x p`.
    pub(crate) x: DMatrix<f64>,
    /// Model parameter index of each column of `x` after the three offsets.
    pub(crate) x_params: Vec<usize>,
    /// Orthonormal basis of the columns of `x` kept (all, or all but a term's).
    q: DMatrix<f64>,
    /// The target: weighted residuals of the fit unless replaced.
    pub(crate) target: DVector<f64>,
    /// Solved UP joints of every pose at the estimate.
    pub(crate) ups: Vec<UpJoints>,
    /// Per pose, the six weighted directions: legs 1-3, readings phi, theta, s.
    directions: Vec<[[f64; 3]; 6]>,
    /// Per direction, `Q_j^T d_j` for every pose (`p x n`).
    projected: Vec<DMatrix<f64>>,
    /// Per pose, the Gram matrix of the six directions.
    gram: Vec<[[f64; 6]; 6]>,
    /// Per pose, the directions' products with the target.
    target_products: Vec<[f64; 6]>,
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
        let cols = 3 + identifiable.len();
        let mut x = DMatrix::zeros(3 * n, cols);
        let mut ext = DMatrix::zeros(3 * n, kf - k);
        let mut target = DVector::zeros(3 * n);
        let mut ups = Vec::with_capacity(n);
        let mut directions = Vec::with_capacity(n);
        let mut jac = vec![0.0; 3 * kf];
        for (j, pose) in data.poses.iter().enumerate() {
            let mut seed = None;
            let g = predictor.predict(pose, &mut seed, &mut jac).ok()?;
            let up = seed?;
            let legs = machine.legs_at(&up);
            let j1_inv: Matrix3<f64> = legs.j1().try_inverse()?;
            let y = pose.readings.to_array();
            let mut dirs = [[0.0; 3]; 6];
            for c in 0..3 {
                let w = 1.0 / sigma[c];
                let row = 3 * j + c;
                x[(row, c)] = w;
                for (t, &gi) in identifiable.iter().enumerate() {
                    x[(row, 3 + t)] = w * jac[c * kf + gi];
                }
                for e in 0..kf - k {
                    ext[(row, e)] = w * jac[c * kf + k + e];
                }
                target[row] = w * (y[c] - g[c] - fit.id.offsets[c]);
                for i in 0..3 {
                    dirs[i][c] = w * j1_inv[(c, i)];
                }
                dirs[3 + c][c] = w;
            }
            ups.push(up);
            directions.push(dirs);
        }
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
        let gram = grams(&directions);
        let mut lin = Linearisation {
            q: DMatrix::zeros(0, 0),
            x,
            x_params: identifiable,
            target,
            ups,
            directions,
            projected: Vec::new(),
            gram,
            target_products: Vec::new(),
            qtt: DVector::zeros(0),
            extra: ext,
            extra_terms,
        };
        lin.set_basis(&[]);
        let t = lin.target.clone();
        lin.set_target(t);
        Some(lin)
    }

    /// Number of poses.
    pub(crate) fn poses(&self) -> usize {
        self.directions.len()
    }

    /// Uses the columns of `x` except those of the model parameters `drop`
    /// as the fitted model.
    pub(crate) fn set_basis(&mut self, drop: &[usize]) {
        let keep: Vec<usize> = (0..self.x.ncols())
            .filter(|&c| c < 3 || !drop.contains(&self.x_params[c - 3]))
            .collect();
        let xk = self.x.select_columns(&keep);
        self.q = orthonormal_basis(&xk);
        let p = self.q.ncols();
        let n = self.poses();
        self.projected = (0..6)
            .map(|b| {
                let mut m = DMatrix::zeros(p, n);
                for j in 0..n {
                    for c in 0..3 {
                        let d = self.directions[j][b][c];
                        if d != 0.0 {
                            for r in 0..p {
                                m[(r, j)] += self.q[(3 * j + c, r)] * d;
                            }
                        }
                    }
                }
                m
            })
            .collect();
        let t = self.target.clone();
        self.set_target(t);
    }

    /// Replaces the target.
    pub(crate) fn set_target(&mut self, target: DVector<f64>) {
        self.qtt = self.q.transpose() * &target;
        self.target_products = self
            .directions
            .iter()
            .enumerate()
            .map(|(j, d)| {
                std::array::from_fn(|b| (0..3).map(|c| d[b][c] * target[3 * j + c]).sum())
            })
            .collect();
        self.target = target;
    }

    /// Columns of `x` for the model parameters `params`, projected onto the
    /// complement of the current basis (the part the rest cannot absorb).
    pub(crate) fn projected_columns(&self, params: &[usize]) -> DMatrix<f64> {
        let cols: Vec<usize> = (0..self.x_params.len())
            .filter(|&c| params.contains(&self.x_params[c]))
            .map(|c| c + 3)
            .collect();
        let g = self.x.select_columns(&cols);
        &g - &self.q * (self.q.transpose() * &g)
    }

    /// Projects dense columns onto the complement of the basis.
    pub(crate) fn project(&self, g: &DMatrix<f64>) -> DMatrix<f64> {
        g - &self.q * (self.q.transpose() * g)
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

    /// The score of columns given as (direction, per-pose value).
    pub(crate) fn score_columns(&self, cols: &[(usize, Vec<f64>)]) -> Score {
        let k = cols.len();
        let p = self.q.ncols();
        let mut qtg = DMatrix::zeros(p, k);
        let mut gtg = DMatrix::zeros(k, k);
        let mut gtt = DVector::zeros(k);
        for (a, (ba, fa)) in cols.iter().enumerate() {
            qtg.set_column(a, &(&self.projected[*ba] * DVector::from_column_slice(fa)));
            gtt[a] = fa
                .iter()
                .zip(&self.target_products)
                .map(|(f, t)| f * t[*ba])
                .sum();
            for (b, (bb, fb)) in cols.iter().enumerate().skip(a) {
                let v: f64 = fa
                    .iter()
                    .zip(fb)
                    .zip(&self.gram)
                    .map(|((x, y), g)| x * y * g[*ba][*bb])
                    .sum();
                gtg[(a, b)] = v;
                gtg[(b, a)] = v;
            }
        }
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
    /// of [`SCAN_BLOCK`], whose projected directions stay in cache while
    /// every frequency accumulates its products, and the sines and cosines
    /// of consecutive frequencies follow by rotation (re-seeded exactly
    /// every [`SCAN_RESEED`] frequencies), so a frequency costs about
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
        use rayon::prelude::*;
        let p = self.q.ncols();
        let k = 2 * legs.len();
        let n = self.poses().min(commands_mm.len());
        let zero = || PeriodicSums {
            qtg: vec![0.0; p * k],
            gtg: vec![0.0; k * k],
            gtt: vec![0.0; k],
        };
        let nl = legs.len();
        let block_sums = |start: usize| -> Vec<PeriodicSums> {
            let end = (start + SCAN_BLOCK).min(n);
            let len = end - start;
            let mut sums: Vec<PeriodicSums> = (0..count).map(|_| zero()).collect();
            // Per leg, over the block's poses: the projected directions
            // (`p x len`, column-major), the target products, the rotation
            // by one grid step and the current sine and cosine; per pair of
            // legs, their directions' inner products.
            let projected: Vec<&[f64]> = legs
                .iter()
                .map(|&i| &self.projected[i].as_slice()[start * p..end * p])
                .collect();
            let products: Vec<Vec<f64>> = legs
                .iter()
                .map(|&i| (start..end).map(|j| self.target_products[j][i]).collect())
                .collect();
            let gram: Vec<Vec<f64>> = (0..nl * nl)
                .map(|ab| {
                    let (la, lb) = (legs[ab / nl], legs[ab % nl]);
                    (start..end).map(|j| self.gram[j][la][lb]).collect()
                })
                .collect();
            let angle = |f: f64, i: usize, j: usize| std::f64::consts::TAU * f * commands_mm[j][i];
            let rotation: Vec<Vec<(f64, f64)>> = legs
                .iter()
                .map(|&i| (start..end).map(|j| angle(step, i, j).sin_cos()).collect())
                .collect();
            // values[2 l] the sines of leg l, values[2 l + 1] its cosines.
            let mut values = vec![vec![0.0; len]; 2 * nl];
            for (f, acc) in sums.iter_mut().enumerate() {
                let frequency = f0 + f as f64 * step;
                for (l, &i) in legs.iter().enumerate() {
                    let (sines, rest) = values[2 * l..].split_at_mut(1);
                    let (sines, cosines) = (&mut sines[0], &mut rest[0]);
                    if f % SCAN_RESEED == 0 {
                        for (t, j) in (start..end).enumerate() {
                            (sines[t], cosines[t]) = angle(frequency, i, j).sin_cos();
                        }
                    } else {
                        for ((s, c), &(ws, wc)) in
                            sines.iter_mut().zip(cosines.iter_mut()).zip(&rotation[l])
                        {
                            (*s, *c) = (*s * wc + *c * ws, *c * wc - *s * ws);
                        }
                    }
                    // Q^T G for the leg's two columns: one pass over its
                    // projected directions.
                    let (qs, qc) = acc.qtg[2 * l * p..(2 * l + 2) * p].split_at_mut(p);
                    for (t, column) in projected[l].chunks_exact(p).enumerate() {
                        let (s, c) = (sines[t], cosines[t]);
                        for ((a, b), &x) in qs.iter_mut().zip(qc.iter_mut()).zip(column) {
                            *a += x * s;
                            *b += x * c;
                        }
                    }
                }
                for a in 0..2 * nl {
                    let va = &values[a];
                    acc.gtt[a] += dot(va, &products[a / 2]);
                    for b in a..2 * nl {
                        let g = &gram[(a / 2) * nl + b / 2];
                        acc.gtg[a * k + b] += va
                            .iter()
                            .zip(&values[b])
                            .zip(g)
                            .map(|((x, y), g)| x * y * g)
                            .sum::<f64>();
                    }
                }
            }
            sums
        };
        let starts: Vec<usize> = (0..n).step_by(SCAN_BLOCK).collect();
        let mut total: Vec<PeriodicSums> = (0..count).map(|_| zero()).collect();
        // A bounded number of blocks at a time (their sums are
        // `count x (p + k + 1) k` numbers each), added in block order.
        for group in starts.chunks(SCAN_PARALLEL_BLOCKS) {
            let partial: Vec<Vec<PeriodicSums>> =
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
                let qtg = DMatrix::from_column_slice(p, k, &t.qtg) * 1e-3;
                let mut gtg = DMatrix::from_row_slice(k, k, &t.gtg) * 1e-6;
                for a in 0..k {
                    for b in 0..a {
                        gtg[(a, b)] = gtg[(b, a)];
                    }
                }
                let gtt = DVector::from_vec(t.gtt) * 1e-3;
                let s = score_from(&qtg, &gtg, &gtt, &self.qtt);
                (s.explained, s.rank)
            })
            .collect()
    }

    /// The prefix sums of the step scan of leg `leg` over the `cuts` of its
    /// command (increasing): element `k` sums the step column over the
    /// poses with `cuts[0] <= q < cuts[k]` (the last cut included), so that
    /// the indicator of `[cuts[u], cuts[v]]` has the products
    /// `prefix[v] - prefix[u]` ([`Linearisation::step_score`]). Poses
    /// outside the cuts are in no bin.
    ///
    /// One pass over the poses: each adds its `p + 2` numbers to the bin
    /// of its command, in pose order, and the bins are summed in their
    /// order, so that a scan of `K` cuts costs `O(n p + K p)` and has the
    /// same bits at any thread count (it runs on one).
    pub(crate) fn step_prefix(
        &self,
        commands_mm: &[[f64; 3]],
        leg: usize,
        cuts: &[f64],
    ) -> Vec<StepSums> {
        let p = self.q.ncols();
        let n = self.poses().min(commands_mm.len());
        let mut bins = vec![StepSums::zero(p); cuts.len().saturating_sub(1)];
        let (Some(&first), Some(&last)) = (cuts.first(), cuts.last()) else {
            return vec![StepSums::zero(p)];
        };
        let projected = &self.projected[leg];
        for j in 0..n {
            let q = commands_mm[j][leg];
            if !(first..=last).contains(&q) || bins.is_empty() {
                continue;
            }
            let k = (cuts.partition_point(|c| *c <= q) - 1).min(bins.len() - 1);
            let bin = &mut bins[k];
            bin.qtg
                .iter_mut()
                .zip(projected.column(j).iter())
                .for_each(|(a, x)| *a += x);
            bin.gtg += self.gram[j][leg][leg];
            bin.gtt += self.target_products[j][leg];
            bin.poses += 1;
        }
        let mut prefix = Vec::with_capacity(bins.len() + 1);
        let mut running = StepSums::zero(p);
        prefix.push(running.clone());
        for b in &bins {
            running.add(b);
            prefix.push(running.clone());
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
                    g[(3 * j + c, a)] = f[j] * self.directions[j][*b][c];
                }
            }
        }
        g
    }

    /// The score of dense weighted columns.
    pub(crate) fn score_dense(&self, g: &DMatrix<f64>) -> Score {
        let qtg = self.q.transpose() * g;
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

/// Per pose, the Gram matrix of its six directions.
fn grams(directions: &[[[f64; 3]; 6]]) -> Vec<[[f64; 6]; 6]> {
    directions
        .iter()
        .map(|d| {
            std::array::from_fn(|a| {
                std::array::from_fn(|b| (0..3).map(|c| d[a][c] * d[b][c]).sum())
            })
        })
        .collect()
}

/// `a . b`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// An orthonormal basis of the column space of `a` (thin QR; `a` has full
/// column rank by construction: identifiable columns only).
pub(crate) fn orthonormal_basis(a: &DMatrix<f64>) -> DMatrix<f64> {
    if a.ncols() == 0 {
        return DMatrix::zeros(a.nrows(), 0);
    }
    a.clone().qr().q()
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

    /// A linearisation of `n` random poses: random fitted columns,
    /// directions and target, and leg commands over 600-1000 mm.
    fn synthetic(n: usize, seed: u64) -> (Linearisation, Vec<[f64; 3]>) {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        let mut normal = || rng.random_range(-1.0..1.0);
        let x = DMatrix::from_fn(3 * n, 7, |_, _| normal());
        let target = DVector::from_fn(3 * n, |_, _| normal());
        let directions: Vec<[[f64; 3]; 6]> = (0..n)
            .map(|_| {
                std::array::from_fn(|b| {
                    std::array::from_fn(|c| if b < 3 || b - 3 == c { normal() } else { 0.0 })
                })
            })
            .collect();
        let commands: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|_| 800.0 + 200.0 * normal()))
            .collect();
        let mut lin = Linearisation {
            q: DMatrix::zeros(0, 0),
            x_params: (0..4).collect(),
            x,
            target: target.clone(),
            ups: Vec::new(),
            gram: grams(&directions),
            directions,
            projected: Vec::new(),
            target_products: Vec::new(),
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
                if explained > best.1 {
                    best = (k, explained);
                }
            }
            // The hidden 10 mm period on leg 2 is grid frequency 128.
            assert_eq!(best.0, 128, "{legs:?}");
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
