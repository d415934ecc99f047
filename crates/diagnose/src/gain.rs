//! What the extended model changes where it matters: the platform's
//! displacement on the middle plane between the geometric-only
//! calibration and the final one, and the predicted true improvement of
//! deploying one model rather than another, with its standard deviation
//! ([`improvement`]).

use nalgebra::{DMatrix, Vector3};
use tricept_data::MeasuredPose;
use tricept_engine::model::ReadingModel;
use tricept_kinematics::{Machine, up_limb::UpJoints};

use crate::fit::Fit;
use crate::options::DiagnoseOptions;

/// Mean, max and touched-off mean displacement of the platform on the
/// middle plane between the geometric-only calibration and the final one
/// (targets commanded through the geometric fit's IK, positions predicted
/// by the final model with the leg effects at the campaign's mean context),
/// and a note when targets could not be reached.
pub(crate) fn volumetric_difference(
    nominal: &Machine,
    geo: &Fit,
    fin: &Fit,
    options: &DiagnoseOptions,
) -> (Option<(f64, f64, f64)>, Option<String>) {
    let targets = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), options.plane_spacing_mm);
    let m_geo = geo.model.machine_at(&geo.id.estimate);
    let m_fin = fin.model.machine_at(&fin.id.estimate);
    let predictor = fin.model.at(&fin.id.estimate);
    let k = fin.model.names().len();
    let mut jac = vec![0.0; 3 * k];
    let mut map = tricept_model::volumetric::ErrorMap {
        targets_mm: Vec::new(),
        errors_mm: Vec::new(),
    };
    for r in &targets {
        let Ok(ik) = m_geo.inverse(r) else { continue };
        let pose = MeasuredPose {
            commands_mm: ik.legs_mm,
            approach: None,
            ..Default::default()
        };
        let mut seed = Some(ik.up);
        // The final model's reading prediction solves its UP joints (the
        // reading effects are sensor-side and do not move the platform).
        if predictor.predict(&pose, &mut seed, &mut jac).is_err() {
            continue;
        }
        let Some(up) = seed else { continue };
        map.targets_mm.push(*r);
        map.errors_mm.push(m_fin.up_limb.pose(&up).position_mm - r);
    }
    let reached = map.targets_mm.len();
    if reached == 0 {
        return (
            None,
            Some(format!(
                "the calibrations cannot reach the middle plane (0 of {} targets)",
                targets.len()
            )),
        );
    }
    let raw = map.stats();
    let touched = map.without_mean_translation().stats();
    let note = (reached < targets.len()).then(|| {
        format!(
            "{reached} of {} middle-plane targets reached",
            targets.len()
        )
    });
    (Some((raw.mean_mm, raw.max_mm, touched.mean_mm)), note)
}

/// The predicted true improvement of commanding the machine with `better`
/// rather than `base` (a fit whose terms are a subset of `better`'s), and
/// its standard deviation, mm.
///
/// Targets on the middle plane are commanded through each fit's own
/// inverse: its geometry's IK with its leg terms undone (the commands that
/// put its predicted platform on the target; the terms at the campaign's
/// middle context). The platform is then predicted by `better`: `base`'s
/// commands miss by `D_k`, `better`'s by nothing, so the improvement is
/// `mean_k |D_k|`. Its standard deviations are root mean squares over the
/// plane of platform uncertainties `tr(J_k C J_k^T)` (`J_k` the
/// platform's derivatives with respect to `better`'s parameters, by
/// central differences): for `C` the covariance of the difference of the
/// two fits, `C_better - C_base` (Hausman; its negative eigenvalues,
/// rounding, set to zero), the uncertainty of the move itself; and in
/// quadrature with it, for `C` `better`'s covariance, what the deployed
/// model itself does not know (its weak directions included), which the
/// true improvement also carries. `None` when no target can be commanded.
pub(crate) fn improvement(
    nominal: &Machine,
    base: &Fit,
    better: &Fit,
    options: &DiagnoseOptions,
) -> Option<Improvement> {
    let targets = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), options.plane_spacing_mm);
    let m_base = base.model.machine_at(&base.id.estimate);
    let m_better = better.model.machine_at(&better.id.estimate);
    let p = &better.id.estimate;
    let mut commanded: Vec<(Vector3<f64>, [f64; 3], UpJoints)> = Vec::new();
    for r in &targets {
        let (Some(q), Some(_)) = (commands(base, &m_base, r), commands(better, &m_better, r))
        else {
            continue;
        };
        let Ok(ik) = m_base.inverse(r) else { continue };
        commanded.push((*r, q, ik.up));
    }
    if commanded.is_empty() {
        return None;
    }
    let at_p = positions(better, p, &commanded)?;
    let misses: Vec<f64> = at_p
        .iter()
        .zip(&commanded)
        .map(|(x, (r, _, _))| (x - r).norm())
        .collect();
    let count = misses.len() as f64;
    let mean = misses.iter().sum::<f64>() / count;
    let rms = (misses.iter().map(|m| m * m).sum::<f64>() / count).sqrt();
    // The uncertainty on every fourth target (the platform's derivatives
    // are smooth over the plane).
    let sampled: Vec<(Vector3<f64>, [f64; 3], UpJoints)> =
        commanded.iter().step_by(4).copied().collect();
    let k = p.len();
    let c = &better.id.covariance;
    if c.nrows() != k || c.ncols() != k {
        return None;
    }
    let difference = difference_covariance(base, better);
    let mut jac: Vec<DMatrix<f64>> = vec![DMatrix::zeros(3, k); sampled.len()];
    for j in 0..k {
        let h = c[(j, j)].sqrt();
        if !(h > 0.0 && h.is_finite()) {
            continue;
        }
        let mut plus = p.clone();
        let mut minus = p.clone();
        plus[j] += h;
        minus[j] -= h;
        let xp = positions(better, &plus, &sampled)?;
        let xm = positions(better, &minus, &sampled)?;
        for (t, jk) in jac.iter_mut().enumerate() {
            let d = (xp[t] - xm[t]) / (2.0 * h);
            for row in 0..3 {
                jk[(row, j)] = d[row];
            }
        }
    }
    let sd = |cov: &DMatrix<f64>| {
        let variance = jac
            .iter()
            .map(|jk| (jk * cov * jk.transpose()).trace())
            .sum::<f64>()
            / sampled.len() as f64;
        variance.max(0.0).sqrt()
    };
    let own = sd(c);
    let moved = sd(&difference);
    Some(Improvement {
        mean_mm: mean,
        rms_mm: rms,
        sd_mm: own.hypot(moved),
        difference_sd_mm: moved,
    })
}

/// A predicted improvement ([`improvement`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Improvement {
    /// Mean platform error on the middle plane of the base fit's commands
    /// under the better model, mm.
    pub(crate) mean_mm: f64,
    /// Root mean square of the same platform errors, mm.
    pub(crate) rms_mm: f64,
    /// Its standard deviation against the truth: the better model's own
    /// platform uncertainty and the difference's, in quadrature, mm.
    pub(crate) sd_mm: f64,
    /// The standard deviation of the difference between the two fits
    /// alone, mm: what the significance of a move is judged against.
    pub(crate) difference_sd_mm: f64,
}

/// The commands of `fit` (its machine `machine`) for target `r`: the
/// geometric IK, then its leg terms undone, `q + extra(q) = q_geometric`,
/// by fixed-point passes (the terms change by far less than the command).
fn commands(fit: &Fit, machine: &Machine, r: &Vector3<f64>) -> Option<[f64; 3]> {
    let geometric = machine.inverse(r).ok()?.legs_mm;
    let mut q = geometric;
    for _ in 0..COMMAND_PASSES {
        let pose = MeasuredPose {
            commands_mm: q,
            approach: None,
            ..Default::default()
        };
        let extra = fit.model.leg_extra_mm(&fit.id.estimate, &pose).ok()?;
        let next: [f64; 3] = std::array::from_fn(|i| geometric[i] - extra[i]);
        let change = (0..3).map(|i| (next[i] - q[i]).abs()).fold(0.0, f64::max);
        q = next;
        if change < 1e-10 {
            break;
        }
    }
    Some(q)
}

/// Passes of [`commands`].
const COMMAND_PASSES: usize = 20;

/// The platform positions (mm) `fit`'s model predicts at parameters `p`
/// for each of `commanded`'s commands (seeded by its UP joints).
fn positions(
    fit: &Fit,
    p: &[f64],
    commanded: &[(Vector3<f64>, [f64; 3], UpJoints)],
) -> Option<Vec<Vector3<f64>>> {
    let predictor = fit.model.at(p);
    let machine = fit.model.machine_at(p);
    let mut jac = vec![0.0; 3 * p.len()];
    commanded
        .iter()
        .map(|(_, q, up)| {
            let pose = MeasuredPose {
                commands_mm: *q,
                approach: None,
                ..Default::default()
            };
            let mut seed = Some(*up);
            predictor.predict(&pose, &mut seed, &mut jac).ok()?;
            seed.map(|up| machine.up_limb.pose(&up).position_mm)
        })
        .collect()
}

/// `C_better - C_base` with `base`'s parameters placed by name among
/// `better`'s, its negative eigenvalues set to zero.
fn difference_covariance(base: &Fit, better: &Fit) -> DMatrix<f64> {
    let k = better.id.names.len();
    let mut d = better.id.covariance.clone();
    let at: Vec<Option<usize>> = base
        .id
        .names
        .iter()
        .map(|n| better.id.names.iter().position(|m| m == n))
        .collect();
    let cb = &base.id.covariance;
    if cb.nrows() == at.len() && cb.ncols() == at.len() && d.nrows() == k {
        for (a, ia) in at.iter().enumerate() {
            for (b, ib) in at.iter().enumerate() {
                if let (Some(i), Some(j)) = (ia, ib) {
                    d[(*i, *j)] -= cb[(a, b)];
                }
            }
        }
    }
    let d = 0.5 * (&d + d.transpose());
    let eig = d.symmetric_eigen();
    let clipped = eig.eigenvalues.map(|v| v.max(0.0));
    &eig.eigenvectors * DMatrix::from_diagonal(&clipped) * eig.eigenvectors.transpose()
}
