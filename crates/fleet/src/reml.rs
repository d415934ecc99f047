//! The machine-to-machine spread of a batch, estimated by restricted
//! maximum likelihood (REML), and the tests of a machine against the batch.
//!
//! Each machine `m` of a batch has its own calibration from its own data:
//! an estimate `p_m` of the `r` identifiable parameters with covariance
//! `C_m` (the machine's likelihood to second order, [`Summary`]). The
//! hierarchical model says `p_m = mu + u_m + e_m`: `mu` the batch's
//! systematic error (a drawing or fixture error, the same on every machine),
//! `u_m ~ N(0, D)` the machine's own assembly deviation, `D =
//! diag(tau_k^2)` the spread, `e_m ~ N(0, C_m)` its calibration's noise.
//! So `p_m ~ N(mu, V_m)`, `V_m = D + C_m`.
//!
//! REML maximises the likelihood of the contrasts free of `mu`
//! (`mu` integrated out under a flat prior):
//!
//! ```text
//! l_R(d) = -1/2 [ sum log|V_m| + log|S| + sum r_m^T W_m r_m ],
//! W_m = V_m^-1,  S = sum W_m,  mu^ = S^-1 sum W_m p_m,  r_m = p_m - mu^
//! ```
//!
//! by Fisher scoring on `d = (tau_k^2)`, each kept at or above zero (a
//! parameter whose spread hits zero stays there while its score is
//! negative): the score is `-1/2 tr(P E_k) + 1/2 sum_m (W_m r_m)_k^2`, the
//! expected information `1/2 tr(P E_k P E_l)` with `P` the REML projection
//! and `E_k` the indicator of parameter `k` in every machine, both summed
//! per machine in `O(M r^3)` (module code). The step is halved until
//! `l_R` does not fall. The spread's standard deviations are the inverse
//! information's.
//!
//! A machine is tested against the others ([`leave_one_out`]): its
//! estimate against the mean of the rest, `T = r^T (V_m + S_-m^-1)^-1 r`,
//! chi-square with `r` degrees of freedom when it belongs to the batch.

use nalgebra::{DMatrix, DVector};

use crate::error::FleetError;

/// One machine's own calibration over the batch's identifiable
/// parameters: its estimate and covariance.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The estimate, mm.
    pub estimate: DVector<f64>,
    /// Its covariance, mm^2.
    pub covariance: DMatrix<f64>,
}

/// The REML estimate of a batch: spread, mean and their uncertainties.
#[derive(Debug, Clone, PartialEq)]
pub struct Spread {
    /// `tau_k^2` per parameter, mm^2.
    pub variance: Vec<f64>,
    /// Standard deviation of each `tau_k^2` (inverse expected
    /// information), mm^2.
    pub variance_sd: Vec<f64>,
    /// The batch mean `mu^` (generalised least squares at the spread), mm.
    pub mean: DVector<f64>,
    /// Its covariance `S^-1`, mm^2.
    pub mean_covariance: DMatrix<f64>,
    /// The restricted log-likelihood at the estimate.
    pub log_likelihood: f64,
    /// Fisher-scoring iterations.
    pub iterations: usize,
    /// Whether the scoring met its tolerance (every step below 1e-6 of the
    /// spread's standard deviation).
    pub converged: bool,
}

impl Spread {
    /// The spread `tau_k`, mm.
    pub fn spread_mm(&self) -> Vec<f64> {
        self.variance.iter().map(|v| v.max(0.0).sqrt()).collect()
    }

    /// A 95 % upper bound of each `tau_k` (the variance plus 1.645 of its
    /// standard deviations), mm.
    pub fn spread_upper_mm(&self) -> Vec<f64> {
        self.variance
            .iter()
            .zip(&self.variance_sd)
            .map(|(v, sd)| (v + 1.644_853_626_951_472_2 * sd).max(0.0).sqrt())
            .collect()
    }
}

/// The weights of the batch at spread `d`: every machine's `W_m = (D +
/// C_m)^-1` and `log|V_m|`, their sum `S`, the mean and the restricted
/// log-likelihood.
struct Weights {
    w: Vec<DMatrix<f64>>,
    s_inv: DMatrix<f64>,
    mean: DVector<f64>,
    log_likelihood: f64,
}

fn weights(summaries: &[Summary], d: &[f64]) -> Result<Weights, FleetError> {
    let r = d.len();
    let mut log_det = 0.0;
    let mut w = Vec::with_capacity(summaries.len());
    let mut s = DMatrix::zeros(r, r);
    let mut h = DVector::zeros(r);
    for m in summaries {
        let mut v = m.covariance.clone();
        for k in 0..r {
            v[(k, k)] += d[k];
        }
        let chol = v.cholesky().ok_or(FleetError::Numerical(
            "a machine's covariance plus the spread is not positive definite",
        ))?;
        log_det += 2.0 * chol.l().diagonal().iter().map(|x| x.ln()).sum::<f64>();
        let wm = chol.inverse();
        s += &wm;
        h += &wm * &m.estimate;
        w.push(wm);
    }
    let chol_s = s
        .cholesky()
        .ok_or(FleetError::Numerical("the batch mean is not determined"))?;
    let log_det_s = 2.0 * chol_s.l().diagonal().iter().map(|x| x.ln()).sum::<f64>();
    let s_inv = chol_s.inverse();
    let mean = &s_inv * h;
    let quadratic: f64 = summaries
        .iter()
        .zip(&w)
        .map(|(m, wm)| {
            let res = &m.estimate - &mean;
            (res.transpose() * wm * &res)[0]
        })
        .sum();
    Ok(Weights {
        w,
        s_inv,
        mean,
        log_likelihood: -0.5 * (log_det + log_det_s + quadratic),
    })
}

/// The REML score and expected information at `weights` (module docs).
fn score_and_information(summaries: &[Summary], x: &Weights) -> (DVector<f64>, DMatrix<f64>) {
    let r = x.mean.len();
    let mut score = DVector::zeros(r);
    let mut info = DMatrix::zeros(r, r);
    // G_k = sum_m w_mk w_mk^T (w_mk: column k of W_m).
    let mut g: Vec<DMatrix<f64>> = vec![DMatrix::zeros(r, r); r];
    for (m, wm) in summaries.iter().zip(&x.w) {
        let z = wm * (&m.estimate - &x.mean);
        let wsw = wm * &x.s_inv * wm;
        for k in 0..r {
            score[k] += -0.5 * (wm[(k, k)] - wsw[(k, k)]) + 0.5 * z[k] * z[k];
            for l in 0..r {
                info[(k, l)] += wm[(k, l)].powi(2) - 2.0 * wm[(k, l)] * wsw[(k, l)];
            }
            let col = wm.column(k);
            g[k] += col * col.transpose();
        }
    }
    let h: Vec<DMatrix<f64>> = g.iter().map(|gk| &x.s_inv * gk).collect();
    for k in 0..r {
        for l in 0..r {
            info[(k, l)] += h[k].component_mul(&h[l].transpose()).sum();
        }
    }
    (score, info * 0.5)
}

/// The REML estimate of the spread (module docs) from at least two
/// machines' [`Summary`].
///
/// # Example
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use tricept_fleet::reml::{Summary, reml};
/// // One parameter, four machines known to 0.1: estimates 1, 2, 3, 4.
/// let s: Vec<Summary> = (1..=4)
///     .map(|i| Summary { estimate: DVector::from_element(1, i as f64), covariance: DMatrix::from_element(1, 1, 0.01) })
///     .collect();
/// let spread = reml(&s).unwrap();
/// // The sample variance 5/3 less the noise 0.01: the balanced case in closed form.
/// assert!((spread.variance[0] - (5.0 / 3.0 - 0.01)).abs() < 1e-9);
/// assert!((spread.mean[0] - 2.5).abs() < 1e-12);
/// ```
pub fn reml(summaries: &[Summary]) -> Result<Spread, FleetError> {
    let r = summaries.first().map_or(0, |s| s.estimate.len());
    if summaries.len() < 2 || r == 0 {
        return Err(FleetError::Input(format!(
            "the spread needs two machines or more ({} given)",
            summaries.len()
        )));
    }
    if summaries
        .iter()
        .any(|s| s.estimate.len() != r || s.covariance.shape() != (r, r))
    {
        return Err(FleetError::Input(
            "machines with different parameter counts".into(),
        ));
    }
    let n = summaries.len() as f64;
    // Start at the moment estimate: the estimates' scatter less their
    // mean noise (never below 1 % of that noise).
    let mut d: Vec<f64> = (0..r)
        .map(|k| {
            let mean = summaries.iter().map(|s| s.estimate[k]).sum::<f64>() / n;
            let scatter = summaries
                .iter()
                .map(|s| (s.estimate[k] - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0);
            let noise = summaries.iter().map(|s| s.covariance[(k, k)]).sum::<f64>() / n;
            (scatter - noise).max(0.01 * noise)
        })
        .collect();
    let mut x = weights(summaries, &d)?;
    let mut converged = false;
    let mut iterations = 0;
    let mut info_inv = DMatrix::zeros(r, r);
    for it in 1..=MAX_ITERATIONS {
        iterations = it;
        let (score, info) = score_and_information(summaries, &x);
        info_inv = info.clone().try_inverse().ok_or(FleetError::Numerical(
            "the spread's information is singular",
        ))?;
        // Parameters at zero with a score pushing below it stay there.
        let free: Vec<usize> = (0..r).filter(|&k| d[k] > 0.0 || score[k] > 0.0).collect();
        let mut step = vec![0.0; r];
        if !free.is_empty() {
            let sub = DMatrix::from_fn(free.len(), free.len(), |a, b| info[(free[a], free[b])]);
            let rhs = DVector::from_fn(free.len(), |a, _| score[free[a]]);
            let delta = sub.try_inverse().ok_or(FleetError::Numerical(
                "the spread's information is singular",
            ))? * rhs;
            for (a, &k) in free.iter().enumerate() {
                step[k] = delta[a];
            }
        }
        let small = (0..r).all(|k| {
            let moved = (d[k] + step[k]).max(0.0) - d[k];
            moved.abs() <= 1e-6 * info_inv[(k, k)].max(0.0).sqrt()
        });
        let mut t = 1.0;
        let accepted = loop {
            let trial: Vec<f64> = (0..r).map(|k| (d[k] + t * step[k]).max(0.0)).collect();
            if let Ok(y) = weights(summaries, &trial)
                && y.log_likelihood >= x.log_likelihood - 1e-12 * x.log_likelihood.abs()
            {
                break Some((trial, y));
            }
            t *= 0.5;
            if t < 1e-8 {
                break None;
            }
        };
        match accepted {
            Some((trial, y)) => {
                d = trial;
                x = y;
            }
            None => {
                converged = small;
                break;
            }
        }
        if small {
            converged = true;
            break;
        }
    }
    Ok(Spread {
        variance_sd: (0..r).map(|k| info_inv[(k, k)].max(0.0).sqrt()).collect(),
        variance: d,
        mean: x.mean,
        mean_covariance: x.s_inv,
        log_likelihood: x.log_likelihood,
        iterations,
        converged,
    })
}

/// Fisher-scoring iterations at most.
const MAX_ITERATIONS: usize = 200;

/// A machine against the rest of the batch: its estimate's distance from
/// the mean of the others, beyond the spread and both uncertainties.
#[derive(Debug, Clone, PartialEq)]
pub struct Distance {
    /// `T = r^T (V_m + S_-m^-1)^-1 r`.
    pub chi_square: f64,
    /// Its degrees of freedom (the identifiable parameters).
    pub dof: usize,
    /// Per parameter, `r_k / sqrt((V_m + S_-m^-1)_kk)`.
    pub z: Vec<f64>,
}

/// Every machine's [`Distance`] from the mean of the members other than
/// itself at spread `d` (members: `member[m]`; a machine that is not a
/// member is tested against all members).
///
/// # Example
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use tricept_fleet::reml::{Summary, leave_one_out};
/// let s: Vec<Summary> = [0.0, 0.1, -0.1, 3.0]
///     .iter()
///     .map(|&x| Summary { estimate: DVector::from_element(1, x), covariance: DMatrix::from_element(1, 1, 0.01) })
///     .collect();
/// let d = leave_one_out(&s, &[0.0], &[true, true, true, false]).unwrap();
/// // The fourth is 3 / sqrt(0.01 + 0.01 / 3) = 26 standard deviations away.
/// assert!((d[3].z[0] - 3.0 / (0.01f64 + 0.01 / 3.0).sqrt()).abs() < 1e-9);
/// ```
pub fn leave_one_out(
    summaries: &[Summary],
    d: &[f64],
    member: &[bool],
) -> Result<Vec<Distance>, FleetError> {
    let r = d.len();
    let mut w = Vec::with_capacity(summaries.len());
    let mut s = DMatrix::zeros(r, r);
    let mut h = DVector::zeros(r);
    for (m, &inside) in summaries.iter().zip(member) {
        let mut v = m.covariance.clone();
        for k in 0..r {
            v[(k, k)] += d[k];
        }
        let wm = v.clone().try_inverse().ok_or(FleetError::Numerical(
            "a machine's covariance plus the spread is singular",
        ))?;
        if inside {
            s += &wm;
            h += &wm * &m.estimate;
        }
        w.push((v, wm));
    }
    summaries
        .iter()
        .zip(&w)
        .zip(member)
        .map(|((m, (v, wm)), &inside)| {
            let (s_rest, h_rest) = if inside {
                (&s - wm, &h - wm * &m.estimate)
            } else {
                (s.clone(), h.clone())
            };
            let s_rest_inv = s_rest.try_inverse().ok_or(FleetError::Input(
                "a machine cannot be tested against fewer than one other".into(),
            ))?;
            let res = &m.estimate - &s_rest_inv * h_rest;
            let var = v + &s_rest_inv;
            let var_inv = var.clone().try_inverse().ok_or(FleetError::Numerical(
                "a machine's distance from the batch has a singular covariance",
            ))?;
            Ok(Distance {
                chi_square: (res.transpose() * var_inv * &res)[0],
                dof: r,
                z: (0..r).map(|k| res[k] / var[(k, k)].sqrt()).collect(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// `n` machines of 3 parameters, spread `tau`, noise covariances that
    /// differ from machine to machine and correlate; seeded.
    fn batch(n: usize, tau: [f64; 3], seed: u64) -> Vec<Summary> {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        (0..n)
            .map(|i| {
                let a = DMatrix::from_fn(3, 3, |r, c| {
                    0.02 * (1.0 + (i % 4) as f64)
                        * if r == c {
                            1.0
                        } else {
                            0.3 * ((r + c) as f64).sin()
                        }
                });
                let cov = &a * a.transpose();
                let chol = cov.clone().cholesky().unwrap();
                let noise = chol.l() * DVector::from_fn(3, |_, _| normal());
                let estimate =
                    DVector::from_fn(3, |k, _| [0.2, -0.1, 0.05][k] + tau[k] * normal()) + noise;
                Summary {
                    estimate,
                    covariance: cov,
                }
            })
            .collect()
    }

    #[test]
    fn the_spread_is_recovered_within_its_standard_deviation() {
        // 40 batches of 60 machines: each spread within 3 of its own sd
        // in all but a few, and the mean of the estimates near the truth.
        let tau = [0.1, 0.03, 0.0];
        let mut within = [0usize; 3];
        let mut sum = [0.0; 3];
        for seed in 0..40 {
            let s = reml(&batch(60, tau, seed)).unwrap();
            assert!(s.converged, "seed {seed}");
            for k in 0..3 {
                let z = (s.variance[k] - tau[k] * tau[k]) / s.variance_sd[k];
                within[k] += usize::from(z.abs() < 3.0);
                sum[k] += s.variance[k];
            }
        }
        for k in 0..3 {
            assert!(
                within[k] >= 37,
                "parameter {k}: {} of 40 within 3 sd",
                within[k]
            );
        }
        assert!((sum[0] / 40.0 / 0.01 - 1.0).abs() < 0.1);
        assert!((sum[1] / 40.0 / 9e-4 - 1.0).abs() < 0.25);
    }

    #[test]
    fn the_balanced_one_parameter_case_has_its_closed_form() {
        // Equal noise c: REML is max(0, sample variance - c).
        for (xs, c) in [
            (vec![1.0, 2.0, 4.0, 7.0], 0.5),
            (vec![0.0, 0.01, -0.01], 1.0),
        ] {
            let n = xs.len() as f64;
            let s: Vec<Summary> = xs
                .iter()
                .map(|&x| Summary {
                    estimate: DVector::from_element(1, x),
                    covariance: DMatrix::from_element(1, 1, c),
                })
                .collect();
            let mean = xs.iter().sum::<f64>() / n;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let spread = reml(&s).unwrap();
            assert!(
                (spread.variance[0] - (var - c).max(0.0)).abs() < 1e-8,
                "{xs:?}"
            );
        }
    }

    #[test]
    fn the_leave_one_out_distance_is_chi_square_in_a_clean_batch() {
        // Mean T over many machines of clean batches is the dof, 3.
        let mut total = 0.0;
        let mut count = 0.0;
        for seed in 100..120 {
            let s = batch(40, [0.1, 0.03, 0.01], seed);
            let spread = reml(&s).unwrap();
            let d = leave_one_out(&s, &spread.variance, &vec![true; s.len()]).unwrap();
            total += d.iter().map(|x| x.chi_square).sum::<f64>();
            count += d.len() as f64;
        }
        assert!(
            (total / count - 3.0).abs() < 0.3,
            "mean T {}",
            total / count
        );
    }
}
