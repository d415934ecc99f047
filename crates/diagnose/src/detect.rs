//! Detectability: for a campaign (its poses, their logged context and the
//! sensor noise), how large must each effect be before the diagnosis finds
//! it, and what does it do to the geometric parameters when it is smaller.
//!
//! With `W` the noise weighting, `A` the identifiable geometric columns (and
//! the three offsets) and `S` the effect's columns, the part of the effect
//! the geometric model cannot absorb is `S_perp = (I - P_A) W S`. For an
//! effect of parameter vector `v` the likelihood-ratio statistic is
//! non-central chi-square with `k` degrees of freedom and non-centrality
//! `lambda = v^T S_perp^T S_perp v`; detection means power 95 % at the
//! diagnosis' level (`alpha / 2` divided by the vocabulary's 8 candidates for
//! an effect of the vocabulary, by the dictionary's multiplicity for a
//! generic term: the same levels as the diagnosis). The held-out residual RMS of the
//! geometric model is about `sqrt(1 + lambda / m)` noise units over `m`
//! readings, so halving it needs `lambda / m >= 3`. Below detection, the
//! effect biases the geometric parameters by `B v`, `B = (A^T A)^-1 A^T W S`
//! (read off the triangular factor of `[offsets | A | S]`).

use faer::Mat;
use serde::Serialize;
use tricept_data::MeasuredPose;
use tricept_engine::{
    IdentifyOptions, identify::design, model::GeometricModel, model::ReadingModel,
};
use tricept_kinematics::up_limb::UpJoints;
use tricept_numerics::linalg::{TriangularAccumulator, invert_upper};

use std::sync::Arc;

use tricept_model::effects::{CauseName, GenericFamily};

use tricept_model::effects::EffectName;

use crate::dictionary::Dictionary;
use crate::model::ExtendedModel;
use crate::options::DictionaryOptions;
use crate::terms::{Frame, GenericTerm, Scope, Term};
use tricept_numerics::stats::{chi2_power, required_noncentrality};

/// Detectability of one effect of parameters `v` on a campaign.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Detectability {
    /// The effect or generic family.
    pub effect: CauseName,
    /// The parameter vector analysed (the effect's "realistic" magnitude).
    pub parameters: Vec<(String, f64)>,
    /// Non-centrality of the likelihood-ratio test at `v`.
    pub noncentrality: f64,
    /// Power of the diagnosis' test at `v`.
    pub power: f64,
    /// Smallest multiple of `v` detected with 95 % power.
    pub detectable_multiple: f64,
    /// Expected held-out RMS of the geometric model at `v`, noise units.
    pub expected_rms_geometric: f64,
    /// Smallest multiple of `v` at which the extended model halves the
    /// held-out RMS (`lambda / m = 3`).
    pub halving_multiple: f64,
    /// Bias of the geometric parameters per `v` (largest first), mm.
    pub bias: Vec<(String, f64)>,
}

/// Analyses the effect `effect` with parameters `v` on the poses `poses`
/// (with their context), noise `sigma`, at family-wise level `alpha`.
pub fn detectability(
    geometric: &GeometricModel,
    effect: EffectName,
    v: &[f64],
    poses: &[MeasuredPose],
    sigma: [f64; 3],
    alpha: f64,
) -> Option<Detectability> {
    term_detectability(geometric, &Term::Catalogue(effect), v, poses, sigma, alpha)
}

/// [`detectability`] of any term: an effect of the vocabulary or a generic
/// term of the dictionary (its coordinates from the campaign `poses`).
///
/// # Example
/// ```
/// use tricept_diagnose::detect::term_detectability;
/// use tricept_diagnose::{terms::GenericFamily, terms::GenericTerm, terms::Scope, terms::Term};
/// let m = tricept_kinematics::Machine::paper();
/// let data = tricept_data::read_path("../../fixtures/data/diagnose-pitch.csv".as_ref()).unwrap();
/// let g = tricept_engine::model::GeometricModel::new(m.clone(), tricept_model::ParameterSet::paper15());
/// let drift = Term::Generic(GenericTerm::new(GenericFamily::ReadingDrift, Scope::Channel(2)));
/// // A 3 um drift of the scale over these 80 poses is seen with 95 % power.
/// let d = term_detectability(&g, &drift, &[3.0], &data.poses, m.sensors.logged_sigma(), 1e-3).unwrap();
/// assert!(d.detectable_multiple < 1.0, "{}", d.detectable_multiple);
/// ```
pub fn term_detectability(
    geometric: &GeometricModel,
    term: &Term,
    v: &[f64],
    poses: &[MeasuredPose],
    sigma: [f64; 3],
    alpha: f64,
) -> Option<Detectability> {
    let kg = geometric.names().len();
    // The identifiable geometric columns of this pose set.
    let mut o = IdentifyOptions::for_machine(geometric.nominal());
    o.sigma = sigma;
    let d = design(geometric, &vec![0.0; kg], poses, &o).ok()?;
    let geo_cols = d.identifiable().to_vec();
    let data = tricept_data::Dataset {
        poses: poses.to_vec(),
        source: String::new(),
    };
    let frame = Frame::of(geometric.nominal(), &data);
    let dictionary = Dictionary::new(&frame, &DictionaryOptions::default());
    let model = ExtendedModel::with_terms(geometric.clone(), &[*term], Arc::new(frame.clone()));
    let k = model.names().len();
    let ke = k - kg;
    let predictor = model.at(&vec![0.0; k]);
    let width = 3 + geo_cols.len() + ke;
    let mut acc = TriangularAccumulator::with_rows_hint(width, 3 * poses.len());
    let mut jac = vec![0.0; 3 * k];
    let mut row = vec![0.0; width];
    for p in poses {
        let mut seed: Option<UpJoints> = None;
        predictor.predict(p, &mut seed, &mut jac).ok()?;
        for c in 0..3 {
            let w = 1.0 / sigma[c];
            row.iter_mut().for_each(|x| *x = 0.0);
            row[c] = w;
            for (t, &g) in geo_cols.iter().enumerate() {
                row[3 + t] = w * jac[c * k + g];
            }
            for e in 0..ke {
                row[3 + geo_cols.len() + e] = w * jac[c * k + kg + e];
            }
            acc.push_row(&row);
        }
    }
    let m = acc.rows() as f64;
    let r = acc.finish();
    let ng = 3 + geo_cols.len();
    // lambda = |R_ee v|^2.
    let r_ee = r.as_ref().submatrix(ng, ng, ke, ke);
    let rv: Vec<f64> = (0..ke)
        .map(|i| (0..ke).map(|j| r_ee[(i, j)] * v[j]).sum())
        .collect();
    // An effect whose data columns are absent or constant has no signature.
    let available = term.available(&frame);
    let lambda: f64 = if available {
        rv.iter().map(|x| x * x).sum()
    } else {
        0.0
    };
    let dof = (0..ke)
        .filter(|&i| r_ee[(i, i)].abs() > 1e-9 * r_ee[(0, 0)].abs().max(1e-300))
        .count()
        .max(1) as f64;
    let level = 0.5 * alpha
        / match term {
            Term::Catalogue(_) => EffectName::terms().count(),
            Term::Generic(_) => dictionary.multiplicity().max(1),
        } as f64;
    let needed = required_noncentrality(dof, level, 0.95)?;
    // Bias: B = R_gg^-1 R_ge (rows: offsets then geometric parameters).
    let r_gg = r.as_ref().submatrix(0, 0, ng, ng).to_owned();
    let r_ge = r.as_ref().submatrix(0, ng, ng, ke).to_owned();
    let inv = invert_upper(r_gg.as_ref());
    let b: Mat<f64> = &inv * &r_ge;
    let names = geometric.names();
    let mut bias: Vec<(String, f64)> = geo_cols
        .iter()
        .enumerate()
        .map(|(t, &g)| {
            (
                names[g].clone(),
                (0..ke).map(|e| b[(3 + t, e)] * v[e]).sum(),
            )
        })
        .collect();
    bias.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    bias.truncate(5);
    let ratio = |mult: f64| mult * mult * lambda / m;
    Some(Detectability {
        effect: term.name(),
        parameters: term.params().into_iter().zip(v.iter().copied()).collect(),
        noncentrality: lambda,
        power: chi2_power(lambda, dof, level),
        detectable_multiple: if lambda > 0.0 {
            (needed / lambda).sqrt()
        } else {
            f64::INFINITY
        },
        expected_rms_geometric: (1.0 + ratio(1.0)).sqrt(),
        halving_multiple: if lambda > 0.0 {
            (3.0 * m / lambda).sqrt()
        } else {
            f64::INFINITY
        },
        bias,
    })
}

/// Realistic magnitudes of each effect, in the diagnosis'
/// parameterisation: those of the registry for the vocabulary
/// ([`tricept_model::effects::EffectSpec::realistic`]), and four effects
/// outside it through their generic terms: a ball-screw pitch error of
/// 4 um with a 10 mm lead (sine phase on every leg), a leg curvature of
/// 5 um (Legendre `P2` coefficient on every leg), a scale drift of 3 um
/// over the campaign, an encoder gain of 200 ppm.
pub fn realistic(machine: &tricept_kinematics::Machine) -> Vec<(Term, Vec<f64>, &'static str)> {
    let generic = |family, scope, period_mm| {
        Term::Generic(GenericTerm {
            family,
            scope,
            period_mm,
            edges_mm: None,
        })
    };
    let mut out: Vec<(Term, Vec<f64>, &'static str)> = EffectName::terms()
        .flat_map(|e| {
            (e.spec().realistic)(machine)
                .into_iter()
                .map(move |m| (Term::Catalogue(e), m.values, m.label))
        })
        .collect();
    out.extend([
        (
            generic(GenericFamily::LegPeriodic, Scope::AllLegs, Some(10.0)),
            vec![4.0, 0.0, 4.0, 0.0, 4.0, 0.0],
            "4 um, 10 mm pitch",
        ),
        (
            generic(GenericFamily::LegPolynomial, Scope::AllLegs, None),
            vec![0.0, 5.0, 0.0, 0.0, 5.0, 0.0, 0.0, 5.0, 0.0],
            "5 um curvature (P2)",
        ),
        (
            generic(GenericFamily::ReadingDrift, Scope::Channel(2), None),
            vec![3.0],
            "3 um scale drift",
        ),
        (
            generic(GenericFamily::EncoderGain, Scope::Channel(0), None),
            vec![200.0],
            "200 ppm phi gain",
        ),
    ]);
    out
}

/// One line of campaign advice for an effect analysed on a campaign of
/// `poses` logged poses with `readings` readings averaged per value.
pub fn advise(d: &Detectability, poses: usize, readings: u32) -> String {
    if !d.detectable_multiple.is_finite() {
        return match d.effect.needs().advice() {
            Some(advice) => format!("invisible: {advice}"),
            None => "invisible to these sensors on this pose set".into(),
        };
    }
    let mut parts = Vec::new();
    if d.detectable_multiple > 1.0 {
        let factor = d.detectable_multiple * d.detectable_multiple;
        parts.push(format!(
            "to detect it, about {:.0} poses or the mean of {:.0} readings",
            poses as f64 * factor,
            f64::from(readings) * factor
        ));
    }
    if d.halving_multiple > 1.0 {
        parts.push(format!(
            "to halve the residual, the mean of {:.0} readings per pose",
            (f64::from(readings) * d.halving_multiple * d.halving_multiple).ceil()
        ));
    }
    if parts.is_empty() {
        "detected and corrected by this campaign".into()
    } else {
        parts.join("; ")
    }
}
