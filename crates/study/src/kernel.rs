//! The fast path's trial kernel: a block of trials with the trials in the
//! SIMD lanes.
//!
//! Per trial the fast path draws `q` standard normals `z`, forms
//! `dp = T z` (`T` the `q x q` lower-triangular factor), `d = dr0 - G dp`
//! (`G` the `3 P x q` plane map) and reduces `d` to four numbers: `mu`, the
//! mean and largest `|d_p|` over the `P` plane points, and the mean after
//! removing the best-fit translation. With `q = 14` and `P = 49` that is
//! about 2 150 multiply-adds, 98 square roots and 1 000 other flops, on
//! 16 KB of matrices that every trial shares (L1-resident) and 32 bytes of
//! output: compute-bound.
//!
//! A trial's numbers never leave the registers between the products and
//! the reductions: each step holds two SIMD vectors of trials (8 trials
//! with AVX2), and the plane map runs two plane points at a time, so the
//! inner loop is a register-blocked micro-kernel (12 accumulators, 2 loads
//! of `dp` and 6 broadcasts of `G` per 12 multiply-adds). The vector width
//! is chosen at run time ([`pulp::Arch`]); every lane computes the same
//! operations in the same order, so a trial's result does not depend on
//! which lane or step it lands in, nor on the thread that runs its block.

use pulp::{Simd, WithSimd};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::results::TrialResult;

/// Vectors of trials per step.
const W: usize = 2;

/// Plane points per group of the plane map's micro-kernel.
const GROUP: usize = 2;

/// The fast path's matrices laid out for the kernel, with what `mu` needs.
#[derive(Debug, Clone)]
pub(crate) struct Kernel {
    /// Normals per trial (`q`).
    q: usize,
    /// The rows of `T` up to their last non-zero, one after the other.
    factor: Vec<f64>,
    /// Where each row of `factor` starts (`q + 1` entries).
    factor_start: Vec<usize>,
    /// `G` by groups of `3 GROUP` rows (fewer in the last group), each
    /// group column after column: the 6 values one column of `dp` meets
    /// are adjacent.
    plane: Vec<f64>,
    /// `dr0`, `3 P`.
    clean: Vec<f64>,
    /// The mean of `G`'s rows per component (`3 x q`, column after column).
    plane_mean: Vec<f64>,
    /// The mean of `dr0` per component.
    clean_mean: Vec<f64>,
    /// `truth - p*` on the moving columns.
    offset: Vec<f64>,
    /// `sum |truth - p*|` over the parameters that do not move.
    held: f64,
    /// `n` in `mu = |truth - p_hat|_1 / n`.
    n_params: f64,
}

impl Kernel {
    /// The kernel of `factor` (`q x q`, `factor(u, k)`), `plane` (`3 P x q`)
    /// and `clean` (`3 P`), with `mu` measured as `(held + sum_u |offset_u -
    /// dp_u|) / n_params`.
    pub(crate) fn new(
        factor: impl Fn(usize, usize) -> f64,
        q: usize,
        plane: impl Fn(usize, usize) -> f64,
        clean: Vec<f64>,
        offset: Vec<f64>,
        held: f64,
        n_params: usize,
    ) -> Kernel {
        let mut t = Vec::new();
        let mut factor_start = vec![0];
        for u in 0..q {
            let len = (0..q)
                .rev()
                .find(|&k| factor(u, k) != 0.0)
                .map_or(0, |k| k + 1);
            t.extend((0..len).map(|k| factor(u, k)));
            factor_start.push(t.len());
        }
        let rows = clean.len() / 3 * 3;
        let points = (rows / 3).max(1) as f64;
        let mut plane_mean = Vec::with_capacity(3 * q);
        for u in 0..q {
            plane_mean.extend(
                (0..3).map(|c| (c..rows).step_by(3).map(|r| plane(r, u)).sum::<f64>() / points),
            );
        }
        let clean_mean = (0..3)
            .map(|c| (c..rows).step_by(3).map(|r| clean[r]).sum::<f64>() / points)
            .collect();
        let mut g = Vec::with_capacity(rows * q);
        for first in (0..rows).step_by(3 * GROUP) {
            let last = rows.min(first + 3 * GROUP);
            for u in 0..q {
                g.extend((first..last).map(|r| plane(r, u)));
            }
        }
        Kernel {
            q,
            factor: t,
            factor_start,
            plane: g,
            clean,
            plane_mean,
            clean_mean,
            offset,
            held,
            n_params: n_params.max(1) as f64,
        }
    }

    /// `n` trials drawn from `rng` (trial after trial, `q` normals each).
    /// With `plane` false only `mu` is computed (the other fields are zero).
    pub(crate) fn trials<R: Rng>(&self, rng: &mut R, n: usize, plane: bool) -> Vec<TrialResult> {
        pulp::Arch::new().dispatch(Trials {
            kernel: self,
            rng,
            n,
            plane,
        })
    }
}

struct Trials<'a, R> {
    kernel: &'a Kernel,
    rng: &'a mut R,
    n: usize,
    plane: bool,
}

impl<R: Rng> WithSimd for Trials<'_, R> {
    type Output = Vec<TrialResult>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Vec<TrialResult> {
        let Trials {
            kernel: kn,
            rng,
            n,
            plane,
        } = self;
        let lanes = S::F64_LANES;
        let width = W * lanes;
        let q = kn.q;
        let zero = simd.splat_f64s(0.0);
        // Normals of one step, `z[k * width + t]` for trial `t` of the
        // step: vector `k * W + h` holds normal `k` of trials `h * lanes..`.
        let mut z = vec![0.0; q * width];
        let mut dp = vec![zero; q * W];
        let points = kn.clean.len() / 3;
        let mut out = Vec::with_capacity(n);
        let mut start = 0;
        while start < n {
            let m = width.min(n - start);
            // Trial after trial, as the normals are drawn.
            for t in 0..width {
                for v in z[t..].iter_mut().step_by(width) {
                    *v = if t < m {
                        StandardNormal.sample(rng)
                    } else {
                        0.0
                    };
                }
            }
            let zv = S::as_simd_f64s(&z).0;

            // dp = T z.
            for (u, out) in dp.chunks_exact_mut(W).enumerate() {
                let row = &kn.factor[kn.factor_start[u]..kn.factor_start[u + 1]];
                let mut acc = [zero; W];
                for (&t, x) in row.iter().zip(zv.chunks_exact(W)) {
                    let t = simd.splat_f64s(t);
                    for h in 0..W {
                        acc[h] = simd.mul_add_e_f64s(t, x[h], acc[h]);
                    }
                }
                out.copy_from_slice(&acc);
            }

            // mu = (held + sum_u |offset_u - dp_u|) / n.
            let mut mu = [simd.splat_f64s(kn.held); W];
            for (&o, x) in kn.offset.iter().zip(dp.chunks_exact(W)) {
                let o = simd.splat_f64s(o);
                for h in 0..W {
                    mu[h] = simd.add_f64s(mu[h], simd.abs_f64s(simd.sub_f64s(o, x[h])));
                }
            }
            let n_params = simd.splat_f64s(kn.n_params);
            for v in &mut mu {
                *v = simd.div_f64s(*v, n_params);
            }

            let mut stats = [[zero; W]; 3];
            if plane && points > 0 {
                stats = plane_stats(simd, kn, &dp);
            }
            for h in 0..W.min(m.div_ceil(lanes)) {
                let mut fields = [[0.0; 8]; 4];
                for (f, v) in fields
                    .iter_mut()
                    .zip([mu[h], stats[0][h], stats[1][h], stats[2][h]])
                {
                    simd.partial_store_f64s(&mut f[..lanes], v);
                }
                for l in 0..lanes.min(m - h * lanes) {
                    out.push(TrialResult {
                        mu_mm: fields[0][l],
                        plane_mean_mm: fields[1][l],
                        plane_max_mm: fields[2][l],
                        plane_touched_mean_mm: fields[3][l],
                    });
                }
            }
            start += width;
        }
        out
    }
}

/// `R` rows of `d = dr0 - G dp` for the step's `W` vectors: `clean` their
/// `dr0`, `panel` their `G` column after column.
#[inline(always)]
fn rows<S: Simd, const R: usize>(
    simd: S,
    clean: &[f64],
    panel: &[f64],
    dp: &[S::f64s],
) -> [[S::f64s; W]; R] {
    let mut acc = [[simd.splat_f64s(0.0); W]; R];
    for (a, &c) in acc.iter_mut().zip(clean) {
        *a = [simd.splat_f64s(c); W];
    }
    for (g, x) in panel.chunks_exact(R).zip(dp.chunks_exact(W)) {
        for (a, &g) in acc.iter_mut().zip(g) {
            let g = simd.splat_f64s(g);
            for h in 0..W {
                a[h] = simd.negate_mul_add_e_f64s(g, x[h], a[h]);
            }
        }
    }
    acc
}

/// `|x|^2` of three vectors of components.
#[inline(always)]
fn norm2<S: Simd>(simd: S, x: S::f64s, y: S::f64s, z: S::f64s) -> S::f64s {
    simd.add_f64s(
        simd.add_f64s(simd.mul_f64s(x, x), simd.mul_f64s(y, y)),
        simd.mul_f64s(z, z),
    )
}

/// Running sums over the plane points: `|d_p|`, its largest square, and
/// `|d_p - t|`.
struct PlaneSums<S: Simd> {
    sum: [S::f64s; W],
    max2: [S::f64s; W],
    touched: [S::f64s; W],
}

/// Adds the points of `a` (three rows each) to the running sums, `t3` the
/// best-fit translation of the step's trials.
#[inline(always)]
fn reduce_points<S: Simd>(
    simd: S,
    a: &[[S::f64s; W]],
    t3: &[[S::f64s; W]; 3],
    acc: &mut PlaneSums<S>,
) {
    for a in a.chunks_exact(3) {
        for h in 0..W {
            let n2 = norm2(simd, a[0][h], a[1][h], a[2][h]);
            acc.sum[h] = simd.add_f64s(acc.sum[h], simd.sqrt_f64s(n2));
            acc.max2[h] = simd.max_f64s(acc.max2[h], n2);
            let x = simd.sub_f64s(a[0][h], t3[0][h]);
            let y = simd.sub_f64s(a[1][h], t3[1][h]);
            let z = simd.sub_f64s(a[2][h], t3[2][h]);
            acc.touched[h] = simd.add_f64s(acc.touched[h], simd.sqrt_f64s(norm2(simd, x, y, z)));
        }
    }
}

/// Mean, largest and translation-removed mean `|d_p|` over the plane, per
/// trial of the step (`[mean, max, touched]`). The best-fit translation
/// (the mean of `d_p`) is `mean(dr0) - mean(G) dp`, known before any
/// point: one pass over the points computes both norms, so that the square
/// roots overlap the products.
#[inline(always)]
fn plane_stats<S: Simd>(simd: S, kn: &Kernel, dp: &[S::f64s]) -> [[S::f64s; W]; 3] {
    let zero = simd.splat_f64s(0.0);
    let q = kn.q;
    let points = kn.clean.len() / 3;
    let t3 = rows::<S, 3>(simd, &kn.clean_mean, &kn.plane_mean, dp);
    let mut acc = PlaneSums::<S> {
        sum: [zero; W],
        max2: [zero; W],
        touched: [zero; W],
    };
    let full = points / GROUP;
    let (panels, tail) = kn.plane.split_at(full * 3 * GROUP * q);
    let (clean, clean_tail) = kn.clean.split_at(full * 3 * GROUP);
    for (panel, clean) in panels
        .chunks_exact(3 * GROUP * q)
        .zip(clean.chunks_exact(3 * GROUP))
    {
        let a = rows::<S, { 3 * GROUP }>(simd, clean, panel, dp);
        reduce_points(simd, &a, &t3, &mut acc);
    }
    if points % GROUP == 1 {
        let a = rows::<S, 3>(simd, clean_tail, tail, dp);
        reduce_points(simd, &a, &t3, &mut acc);
    }
    let inv = simd.splat_f64s(1.0 / points as f64);
    let mut out = [[zero; W]; 3];
    for h in 0..W {
        out[0][h] = simd.mul_f64s(acc.sum[h], inv);
        out[1][h] = simd.sqrt_f64s(acc.max2[h]);
        out[2][h] = simd.mul_f64s(acc.touched[h], inv);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// A kernel on made-up matrices: `q = 5` normals, `P = 7` plane points
    /// (an odd count, so the last group is short), a lower-triangular
    /// factor with one zero row end.
    fn made_up() -> (Kernel, Vec<f64>, Vec<f64>) {
        let q = 5;
        let factor = |u: usize, k: usize| {
            if k > u || (u == 3 && k == 3) {
                0.0
            } else {
                1.0 + 0.1 * (u * 7 + k) as f64
            }
        };
        let plane = |r: usize, u: usize| ((r * 5 + u) as f64 * 0.37).sin();
        let clean: Vec<f64> = (0..21).map(|r| 0.01 * r as f64 - 0.1).collect();
        let t: Vec<f64> = (0..q * q).map(|i| factor(i / q, i % q)).collect();
        let g: Vec<f64> = (0..21 * q).map(|i| plane(i / q, i % q)).collect();
        let offset = vec![0.3, -0.2, 0.1, 0.0, 0.05];
        (Kernel::new(factor, q, plane, clean, offset, 0.25, 9), t, g)
    }

    /// The fast path's formulas written out for one trial.
    fn by_hand(kn: &Kernel, t: &[f64], g: &[f64], z: &[f64]) -> [f64; 4] {
        let q = kn.q;
        let dp: Vec<f64> = (0..q)
            .map(|u| (0..q).map(|k| t[u * q + k] * z[k]).sum())
            .collect();
        let mu =
            (kn.held + (0..q).map(|u| (kn.offset[u] - dp[u]).abs()).sum::<f64>()) / kn.n_params;
        let rows = kn.clean.len();
        let d: Vec<f64> = (0..rows)
            .map(|r| kn.clean[r] - (0..q).map(|u| g[r * q + u] * dp[u]).sum::<f64>())
            .collect();
        let points = rows / 3;
        let norm = |e: &[f64]| (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
        let norms: Vec<f64> = d.chunks(3).map(norm).collect();
        let mean = norms.iter().sum::<f64>() / points as f64;
        let max = norms.iter().cloned().fold(0.0, f64::max);
        let t3: Vec<f64> = (0..3)
            .map(|c| (0..points).map(|p| d[3 * p + c]).sum::<f64>() / points as f64)
            .collect();
        let touched = d
            .chunks(3)
            .map(|e| norm(&[e[0] - t3[0], e[1] - t3[1], e[2] - t3[2]]))
            .sum::<f64>()
            / points as f64;
        [mu, mean, max, touched]
    }

    fn fields(r: &TrialResult) -> [f64; 4] {
        [
            r.mu_mm,
            r.plane_mean_mm,
            r.plane_max_mm,
            r.plane_touched_mean_mm,
        ]
    }

    #[test]
    fn every_trial_matches_the_formulas_written_out_at_every_vector_width() {
        let (kn, t, g) = made_up();
        // 37 trials: several steps of any width and a partial last one.
        let n = 37;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let z: Vec<f64> = (0..n * kn.q)
            .map(|_| StandardNormal.sample(&mut rng))
            .collect();
        let expected: Vec<[f64; 4]> = z.chunks(kn.q).map(|z| by_hand(&kn, &t, &g, z)).collect();
        let trials = |rng: &mut Xoshiro256PlusPlus, simd: Option<pulp::Scalar>| {
            let op = Trials {
                kernel: &kn,
                rng,
                n,
                plane: true,
            };
            match simd {
                Some(s) => op.with_simd(s),
                None => pulp::Arch::new().dispatch(op),
            }
        };
        for simd in [None, Some(pulp::Scalar::new())] {
            let got = trials(&mut Xoshiro256PlusPlus::seed_from_u64(5), simd);
            assert_eq!(got.len(), n);
            for (trial, (r, e)) in got.iter().zip(&expected).enumerate() {
                for (a, b) in fields(r).iter().zip(e) {
                    assert!(
                        (a - b).abs() <= 1e-13 * b.abs().max(1.0),
                        "trial {trial}: {a} against {b} ({simd:?})"
                    );
                }
            }
        }
        // Without the plane only mu is computed, from the same draws.
        let mu = kn.trials(&mut Xoshiro256PlusPlus::seed_from_u64(5), n, false);
        for (r, e) in mu.iter().zip(&expected) {
            assert!((r.mu_mm - e[0]).abs() <= 1e-13);
            assert_eq!(r.plane_mean_mm, 0.0);
        }
    }
}
