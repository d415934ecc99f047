//! Deploy by what the file will deliver: a term of the final model is
//! deployed when the file with it is predicted better than the file
//! without it, out of sample and where the readings cannot see.
//!
//! **The out-of-sample benefit.** K-fold cross-validation (the folds of
//! [`crate::fit::Fitter::holdout_rms`]): the model with the term and the
//! model without it are each fitted on K-1 folds, and each predicts the
//! readings of the held-out fold. A held-out pose's reading residual
//! (`phi`, `theta`, `s`) is mapped to the platform through the UP limb of
//! the fitted model at the pose's predicted joints (the sensors measure
//! where the platform went): `e_j`, mm. The benefit is the difference of
//! the two files' root mean square held-out platform errors,
//! `rms(e_without) - rms(e_with)`, and its standard deviation follows from
//! the per-pose differences `d_j = |e_without_j|^2 - |e_with_j|^2`:
//! `sd(d) / sqrt(n) / (rms_without + rms_with)`. A term fitted to noise
//! has none.
//!
//! **What the readings cannot see.** Along the weak leg-length direction
//! the sensors do not see where the platform goes
//! (`docs/identifiability.md`): a held-out reading says nothing of it, and
//! there a term's worth is the predicted improvement of
//! [`crate::gain::improvement`] (how far the file without it puts the
//! platform from where the file with it does), against its standard
//! deviation (the uncertainty the term adds to the file, and the move's).
//!
//! **The rule** (no term is exempt: backlash and thermal expansion are
//! judged as every other term). A term is deployed when its out-of-sample
//! benefit exceeds [`DEPLOY_BENEFIT_SD`] standard deviations and its
//! predicted improvement exceeds [`DEPLOY_IMPROVEMENT_SD`] standard
//! deviations or is no larger than the out-of-sample benefit (plus its
//! [`DEPLOY_BENEFIT_SD`] sd: the file moves the platform where the readings
//! cannot see by no more than they see it gain, as a backlash visited from
//! both directions does), each judged against the *deployed* model without it:
//! backward elimination removes the least useful failing term (smallest
//! improvement in standard deviations), refits the rest and judges them
//! again. A term whose absence leaves a model that cannot be fitted is
//! needed and deployed. The predicted improvement's standard deviation
//! takes the deployed model's own platform uncertainty at least as large
//! as that of the deployed model with a polynomial on every leg that
//! carries none ([`structured_sd`]): a move along the weak direction is
//! trusted only when it stands out of what the legs' structure leaves
//! unknown.

use nalgebra::Vector3;
use rayon::prelude::*;
use tricept_data::{Dataset, MeasuredPose};
use tricept_engine::model::ReadingModel;
use tricept_kinematics::{Machine, up_limb::UpJoints};

use crate::fit::Fit;
use crate::gain::{Improvement, improvement};
use crate::model::ExtendedModel;
use crate::options::DeployRule;
use crate::report::{DEPLOY_BENEFIT_SD, DEPLOY_IMPROVEMENT_SD, ModelTerm};
use crate::select::Setup;
use crate::terms::{GenericTerm, Scope, Term};
use tricept_model::effects::{EffectName, GenericFamily};

/// The out-of-sample benefit of one file over another, mm.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Benefit {
    /// `rms(e_without) - rms(e_with)`, mm.
    pub(crate) mean_mm: f64,
    /// Its standard deviation from the held-out poses alone, mm.
    pub(crate) sd_mm: f64,
}

/// Held-out platform errors (mm) of `model` on `data`, one per pose, each
/// pose predicted by the fit on the other folds (pose `j` is in fold
/// `j % K`); `None` when a fold cannot be fitted or a pose predicted.
pub(crate) fn platform_errors(
    setup: &Setup<'_>,
    model: &ExtendedModel,
    data: &Dataset,
) -> Option<Vec<Vector3<f64>>> {
    let fitter = &setup.fitter;
    let k = fitter.options.folds.max(2);
    let parts: Vec<Option<PoseErrors>> = (0..k)
        .into_par_iter()
        .map(|fold| {
            let train = data.subset(|j| j % k != fold);
            let f = fitter.fit(model.clone(), &train).ok()?;
            let held: Vec<(usize, &MeasuredPose)> = data
                .poses
                .iter()
                .enumerate()
                .filter(|(j, _)| j % k == fold)
                .collect();
            pose_errors(&f, &held)
        })
        .collect();
    let mut out = vec![Vector3::zeros(); data.poses.len()];
    for part in parts {
        for (j, e) in part? {
            out[j] = e;
        }
    }
    Some(out)
}

/// The platform error (mm) of each of `poses` under the fit `f`: the
/// reading residual mapped through the UP limb's derivatives at the pose's
/// predicted joints; `None` when a pose cannot be predicted.
fn pose_errors(f: &Fit, poses: &[(usize, &MeasuredPose)]) -> Option<PoseErrors> {
    let predictor = f.model.at(&f.id.estimate);
    let limb = f.model.machine_at(&f.id.estimate).up_limb;
    let mut jac = vec![0.0; 3 * f.id.estimate.len()];
    let offsets = f.id.offsets;
    poses
        .iter()
        .map(|(j, p)| {
            let mut seed: Option<UpJoints> = None;
            let g = predictor.predict(p, &mut seed, &mut jac).ok()?;
            let up = seed?;
            let y = p.readings.to_array();
            let r: [f64; 3] = std::array::from_fn(|c| y[c] - g[c] - offsets[c]);
            let mut e = Vector3::zeros();
            for (c, h) in JOINT_STEPS.iter().enumerate() {
                let at = |s: f64| {
                    let mut a = up.to_array();
                    a[c] += s;
                    limb.pose(&UpJoints {
                        phi_rad: a[0],
                        theta_rad: a[1],
                        q4_mm: a[2],
                    })
                    .position_mm
                };
                e += (at(*h) - at(-*h)) / (2.0 * h) * r[c];
            }
            e.iter().all(|v| v.is_finite()).then_some((*j, e))
        })
        .collect()
}

/// Each pose's index with its platform error, mm.
type PoseErrors = Vec<(usize, Vector3<f64>)>;

/// Central-difference steps of the UP limb's joints (rad, rad, mm).
const JOINT_STEPS: [f64; 3] = [1e-6, 1e-6, 1e-3];

/// The out-of-sample benefit of the file whose held-out platform errors
/// are `with` over the one whose errors are `without` (the same poses).
pub(crate) fn benefit(with: &[Vector3<f64>], without: &[Vector3<f64>]) -> Option<Benefit> {
    let n = with.len();
    if n < 2 || without.len() != n {
        return None;
    }
    let d: Vec<f64> = with
        .iter()
        .zip(without)
        .map(|(w, o)| o.norm_squared() - w.norm_squared())
        .collect();
    let mean_d = d.iter().sum::<f64>() / n as f64;
    let var_d = d.iter().map(|v| (v - mean_d).powi(2)).sum::<f64>() / (n - 1) as f64;
    let rms =
        |e: &[Vector3<f64>]| (e.iter().map(|v| v.norm_squared()).sum::<f64>() / n as f64).sqrt();
    let (rms_with, rms_without) = (rms(with), rms(without));
    let total = rms_with + rms_without;
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    Some(Benefit {
        mean_mm: rms_without - rms_with,
        sd_mm: (var_d / n as f64).sqrt() / total,
    })
}

/// The deployed model terms are judged against: its fit, its held-out
/// platform errors, its platform's standard deviation when every leg may
/// also carry a polynomial ([`structured_sd`]), the richer model itself,
/// and the deployed model's expected squared error against it
/// ([`expected_error`]).
#[derive(Clone, Copy)]
struct Against<'a> {
    fit: &'a Fit,
    full: Option<&'a [Vector3<f64>]>,
    structured_sd_mm: Option<f64>,
    /// The richer fit, `None` when every leg is shaped already (the
    /// deployed model is then its own reference).
    rich: Option<&'a Fit>,
    /// The deployed model's expected mean squared platform error, mm^2.
    expected_mse_mm2: Option<f64>,
}

/// The deployed model `with` and a polynomial on every leg it does not
/// shape ([`shapes_leg`]), fitted; `None` when every leg has one or that
/// model cannot be fitted.
///
/// A move along the weak direction is made by a term's small correlation
/// with it, scaled by the weak direction's large uncertainty; a term that
/// is nearly right (a drift at a constant rate where the legs grow with
/// their length, a polynomial beside an unexplained slip) moves it as far
/// and as confidently, but wrongly. The readings cannot tell: only a move
/// that stands out of what the legs' structure leaves unknown is trusted.
fn richer(setup: &Setup<'_>, clean: &Dataset, with: &Fit) -> Option<Fit> {
    let fitter = &setup.fitter;
    let terms = richer_terms(with.model.terms())?;
    fitter.fit(fitter.model(&terms), clean).ok()
}

/// The terms of [`richer`]: `terms` and a polynomial on every leg none of
/// them shapes (one term over all legs when no leg is shaped); `None` when
/// every leg is shaped.
fn richer_terms(terms: &[Term]) -> Option<Vec<Term>> {
    let carried = |leg: usize| terms.iter().any(|t| shapes_leg(t, leg));
    let free: Vec<u8> = (0..3u8).filter(|&i| !carried(usize::from(i))).collect();
    let legs: Vec<Term> = match free.as_slice() {
        [] => return None,
        [_, _, _] => vec![Term::Generic(GenericTerm::new(
            GenericFamily::LegPolynomial,
            Scope::AllLegs,
        ))],
        some => some
            .iter()
            .map(|&i| {
                Term::Generic(GenericTerm::new(
                    GenericFamily::LegPolynomial,
                    Scope::Leg(i),
                ))
            })
            .collect(),
    };
    Some([terms, &legs].concat())
}

/// The deployed model's own platform standard deviation on the middle
/// plane under the richer model ([`richer`]), from the improvement `g` of
/// the richer model over it: its own part, mm.
fn structured_sd(g: Improvement) -> Option<f64> {
    let own2 = g.sd_mm.powi(2) - g.difference_sd_mm.powi(2);
    own2.is_finite().then(|| own2.max(0.0).sqrt())
}

/// The expected mean squared platform error on the middle plane (mm^2)
/// of a file whose model is nested in a reference model, from the
/// improvement `g` of the reference over it and the reference's own
/// platform standard deviation `reference_sd_mm`: an unbiased risk
/// estimate (Mallows' `C_p` on the platform). The file's error is the
/// reference's minus the difference `D` of the two (`rms D^2` over the
/// plane); nested least squares make `D` uncorrelated with the file, so its
/// variance is the reference's less `var D` (Hausman,
/// `difference_sd_mm^2`), and its squared bias is `E|D|^2 - var D`,
/// estimated by `rms D^2 - var D`, at least 0.
fn expected_error(g: Improvement, reference_sd_mm: f64) -> f64 {
    let var_d = g.difference_sd_mm.powi(2);
    let bias2 = (g.rms_mm.powi(2) - var_d).max(0.0);
    (reference_sd_mm.powi(2) - var_d).max(0.0) + bias2
}

/// The reference's own platform standard deviation ([`structured_sd`])
/// and the nested file's expected mean squared error against it
/// ([`expected_error`]), both from the improvement `g` of the reference
/// over the file.
fn against_reference(g: Improvement) -> Option<(f64, f64)> {
    structured_sd(g).map(|sd| (sd, expected_error(g, sd)))
}

/// Whether `t` already describes how leg `leg`'s length error varies with
/// its command (a lead, a polynomial, a periodic error): that leg keeps its
/// own description and gets no polynomial of [`structured_sd`].
fn shapes_leg(t: &Term, leg: usize) -> bool {
    match t {
        Term::Catalogue(e) => *e == EffectName::LegLead,
        Term::Generic(g) => {
            matches!(
                g.family,
                GenericFamily::LegPolynomial | GenericFamily::LegPeriodic
            ) && g.legs().contains(&leg)
        }
    }
}

/// `g` with its own part at least `structured_sd_mm` ([`structured_sd`]).
fn with_structure(g: Improvement, structured_sd_mm: Option<f64>) -> Improvement {
    let own = (g.sd_mm.powi(2) - g.difference_sd_mm.powi(2))
        .max(0.0)
        .sqrt();
    match structured_sd_mm {
        Some(s) if s > own => Improvement {
            sd_mm: s.hypot(g.difference_sd_mm),
            ..g
        },
        _ => g,
    }
}

/// A term judged against the deployed model `with` (which holds it).
struct Judged {
    record: ModelTerm,
    /// Whether it pays by both halves of the rule.
    pays: bool,
    /// How many standard deviations its predicted improvement is (the
    /// least useful failing term goes first).
    z: f64,
}

/// Judges `t` against the deployed model `with` (its held-out platform
/// errors `full`): the model without it fitted, the predicted improvement
/// of `with` over it, the out-of-sample benefit, and the rule.
fn judge(
    nominal: &Machine,
    setup: &Setup<'_>,
    clean: &Dataset,
    with: &Against<'_>,
    t: &Term,
) -> Judged {
    let Against {
        fit: with,
        full,
        structured_sd_mm,
        rich,
        expected_mse_mm2,
    } = *with;
    let fitter = &setup.fitter;
    let others: Vec<Term> = with
        .model
        .terms()
        .iter()
        .copied()
        .filter(|u| u != t)
        .collect();
    let model = fitter.model(&others);
    let without = fitter.fit(model.clone(), clean).ok();
    let moved = without
        .as_ref()
        .and_then(|w| improvement(nominal, w, with, fitter.options));
    let gained = moved.map(|g| with_structure(g, structured_sd_mm));
    // Both files' expected errors against the reference: the richer
    // model, or the deployed model itself when it shapes every leg (its
    // squared bias 0, its variance its own).
    let expected = match rich {
        Some(r) => without
            .as_ref()
            .and_then(|w| improvement(nominal, w, r, fitter.options))
            .zip(structured_sd_mm)
            .map(|(g, sd)| expected_error(g, sd))
            .and_then(|o| expected_mse_mm2.map(|w| (w, o))),
        None => moved
            .and_then(against_reference)
            .map(|(sd, error)| (sd * sd, error)),
    };
    let held_out = match (full, &without) {
        (Some(full), Some(_)) => {
            platform_errors(setup, &model, clean).and_then(|e| benefit(full, &e))
        }
        _ => None,
    };
    let z = improvement_sds(gained);
    let kept_back = kept_back_because(
        fitter.options.deploy_rule,
        without.is_some(),
        held_out,
        gained,
        expected,
    );
    let pays = kept_back.is_none();
    let (legs, channel, period_mm, edges_mm) = match t {
        Term::Generic(g) => (
            g.legs().iter().map(|i| *i as u8 + 1).collect(),
            g.channel().map(|c| c as u8),
            g.period_mm,
            g.edges_mm,
        ),
        Term::Catalogue(_) => (Vec::new(), None, None, None),
    };
    Judged {
        record: ModelTerm {
            effect: t.name(),
            description: t.label(),
            legs,
            channel,
            period_mm,
            edges_mm,
            deployed: pays,
            improvement_mm: gained.map(|g| g.mean_mm),
            improvement_sd_mm: gained.map(|g| g.sd_mm),
            difference_sd_mm: gained.map(|g| g.difference_sd_mm),
            holdout_benefit_mm: held_out.map(|b| b.mean_mm),
            holdout_benefit_sd_mm: held_out.map(|b| b.sd_mm),
            expected_rms_with_mm: expected.map(|(w, _)| w.sqrt()),
            expected_rms_without_mm: expected.map(|(_, o)| o.sqrt()),
            kept_back_because: kept_back,
        },
        pays,
        z,
    }
}

/// How many standard deviations the predicted improvement `gained` is
/// (infinite when it is unknown or has no spread: such a term goes last).
fn improvement_sds(gained: Option<Improvement>) -> f64 {
    gained.map_or(f64::INFINITY, |g| {
        if g.sd_mm > 0.0 {
            g.mean_mm / g.sd_mm
        } else {
            f64::INFINITY
        }
    })
}

/// The module's rule: why a term is kept back under `policy`, given
/// whether the model without it could be fitted (`fitted_without`), its
/// out-of-sample benefit `held_out`, its predicted improvement `gained`
/// and the expected mean squared errors of the files with and without it
/// (`expected`, mm^2, [`expected_error`]), in words for the report and the
/// file; `None` when it pays.
fn kept_back_because(
    policy: DeployRule,
    fitted_without: bool,
    held_out: Option<Benefit>,
    gained: Option<Improvement>,
    expected: Option<(f64, f64)>,
) -> Option<String> {
    let (b, g) = match (fitted_without, held_out, gained) {
        // Without it the model cannot be fitted: it is needed.
        (false, _, _) => return None,
        (true, Some(b), Some(g)) => (b, g),
        // No out-of-sample benefit can be had: nothing says it pays.
        (true, None, _) => {
            return Some(
                "no out-of-sample benefit could be had (a fold cannot be fitted without it)".into(),
            );
        }
        (true, Some(_), None) => {
            return Some(
                "its improvement where the readings cannot see could not be had (the middle plane not reached)"
                    .into(),
            );
        }
    };
    let z = improvement_sds(Some(g));
    if b.mean_mm <= DEPLOY_BENEFIT_SD * b.sd_mm {
        return Some(format!(
            "the readings do not see it pay out of sample (its benefit not above {DEPLOY_BENEFIT_SD} sd)"
        ));
    }
    // It pays where the readings cannot see, or it moves the platform
    // there by no more than the readings see it gain (so that it cannot
    // lose more than it gains).
    let confident = g.mean_mm > DEPLOY_IMPROVEMENT_SD * g.sd_mm
        || g.mean_mm <= b.mean_mm + DEPLOY_BENEFIT_SD * b.sd_mm;
    if confident {
        return None;
    }
    match policy {
        DeployRule::Confident => Some(format!(
            "the confident rule (deploy_rule `confident`): its improvement is {z:.1} sd, not above {DEPLOY_IMPROVEMENT_SD} sd, and larger than the benefit the readings see"
        )),
        DeployRule::ExpectedError => match expected {
            None => Some(format!(
                "its expected errors could not be had, and its improvement is {z:.1} sd, not above {DEPLOY_IMPROVEMENT_SD} sd"
            )),
            Some((with, without)) if with >= without => {
                Some("the file with it is not expected better".into())
            }
            // The file with it is expected better, by a move of at least
            // one standard deviation.
            Some(_) if g.mean_mm >= EXPECTED_ERROR_MIN_SD * g.sd_mm => None,
            Some(_) => Some(format!(
                "its improvement is within its own uncertainty ({z:.1} sd, below {EXPECTED_ERROR_MIN_SD}): the file without it is about as likely the better one"
            )),
        },
    }
}

/// The least predicted improvement, in its standard deviations, of a term
/// [`DeployRule::ExpectedError`] deploys for its expected error alone:
/// below it the file without the term is about as likely the better one
/// (measured: leg leads at 0.8 sd, 72 -> 94 and 67 -> 76 um).
const EXPECTED_ERROR_MIN_SD: f64 = 1.0;

/// Every term of the final model `current` with its predicted
/// improvement ([`improvement`]), its out-of-sample benefit, and whether
/// it is deployed (the module's rule), by backward elimination: every
/// deployed term is judged against the deployed model without it, the
/// least useful failing term (the smallest predicted improvement in
/// standard deviations) leaves, the rest is refitted and judged again.
/// A term left out keeps the numbers it was judged by. With the model of
/// the deployed terms when some are left out (`None` when all are
/// deployed, or none).
pub(crate) fn deployable(
    nominal: &Machine,
    setup: &Setup<'_>,
    clean: &Dataset,
    current: &Fit,
) -> (Vec<ModelTerm>, Option<Fit>) {
    let fitter = &setup.fitter;
    let terms = current.model.terms().to_vec();
    let mut records: Vec<Option<ModelTerm>> = vec![None; terms.len()];
    let mut with = current.clone();
    let mut kept = terms.clone();
    while !kept.is_empty() {
        let full = platform_errors(setup, &with.model, clean);
        let rich = richer(setup, clean, &with);
        // The deployed model against the richer one (with none, see
        // `judge`).
        let (structured_sd_mm, expected_mse_mm2) = match &rich {
            Some(r) => improvement(nominal, &with, r, fitter.options)
                .and_then(against_reference)
                .unzip(),
            None => (None, None),
        };
        let against = Against {
            fit: &with,
            full: full.as_deref(),
            structured_sd_mm,
            rich: rich.as_ref(),
            expected_mse_mm2,
        };
        let judged: Vec<Judged> = kept
            .par_iter()
            .map(|t| judge(nominal, setup, clean, &against, t))
            .collect();
        let failing = judged
            .iter()
            .enumerate()
            .filter(|(_, j)| !j.pays)
            .min_by(|a, b| a.1.z.total_cmp(&b.1.z))
            .map(|(k, _)| k);
        for (t, j) in kept.iter().zip(&judged) {
            if let Some(slot) = terms.iter().position(|u| u == t) {
                records[slot] = Some(j.record.clone());
            }
        }
        // The failing term leaves (its record says it is not deployed);
        // the rest are refitted and judged again, their records replaced.
        let Some(k) = failing else { break };
        kept.remove(k);
        if kept.is_empty() {
            break;
        }
        match fitter.fit(fitter.model(&kept), clean) {
            Ok(fit) => with = fit,
            Err(_) => {
                // The model of the remaining terms cannot be fitted:
                // deploy none.
                for r in records.iter_mut().flatten() {
                    if r.deployed {
                        r.deployed = false;
                        r.kept_back_because = Some(
                            "the model of the terms that pay cannot be fitted without the ones kept back: none is deployed".into(),
                        );
                    }
                }
                kept.clear();
            }
        }
    }
    let out: Vec<ModelTerm> = records.into_iter().flatten().collect();
    if kept.len() == terms.len() || kept.is_empty() {
        (out, None)
    } else {
        (out, Some(with))
    }
}

#[cfg(test)]
mod tests;
