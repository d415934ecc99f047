//! The dictionary's grids scored in one pass over the poses: every
//! frequency of the leg-periodic term's scan, and the prefix sums of the
//! step scan from which every segment between two cuts is scored.

use std::ops::Range;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::kernels::sums4;
use super::linearisation::{BLOCK, Linearisation};
use super::score::{Sums, score_from};

/// Frequencies between exact evaluations of the scan's sines and cosines
/// (in between, a rotation: its rounding grows by about one unit in the
/// last place per frequency).
const SCAN_RESEED: usize = 32;

/// Blocks of the scan summed at a time.
const SCAN_PARALLEL_BLOCKS: usize = 16;

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

impl Linearisation {
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
