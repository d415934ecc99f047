//! The diagnosis: is the geometric model adequate, and if not, why.
//!
//! 1. **Outliers.** The geometric model is fitted; a pose whose reading lies
//!    beyond the Bonferroni-corrected normal quantile of `3 n` readings (in
//!    noise units, against a robust scale of the residuals so that a
//!    systematic misfit is not mistaken for gross errors) is set aside, and
//!    the screen repeats on the refit. Flagged poses (at most 10 %) make the
//!    cause `outliers`; the rest of the analysis uses the clean poses.
//! 2. **Adequacy.** The chi-square of the weighted residuals against its
//!    degrees of freedom, and the correlation of the residuals with every
//!    available regressor.
//! 3. **Causes, by forward selection.** Every candidate effect whose data
//!    columns are present is fitted on top of the current model. It is
//!    selected only if (a) the nested likelihood-ratio test (the drop of
//!    chi-square, known noise) is significant at `alpha` divided by the
//!    number of candidates, (b) the BIC improves, and (c) the 5-fold
//!    cross-validated held-out residual RMS improves; the strongest (largest
//!    BIC gain) enters, and the search repeats.
//! 4. **Report.** Each cause with its parameters and standard deviations,
//!    the evidence, how far it had biased the geometric parameters, and the
//!    gain: held-out RMS and the platform displacement on the middle plane
//!    between the geometric-only and the extended calibration.

use tricept_data::{Dataset, MeasuredPose};
use tricept_ident::{GeometricModel, IdentError, ReadingModel};
use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_model::ParameterSet;
use tricept_model::effects::EffectName;
use tricept_numerics::stats::chi2_sf;

use crate::model::ExtendedModel;
use crate::report::{Cause, ChannelRms, Diagnosis, Estimate, Evidence, Gain};
use crate::residuals::{residual_plot, structure};
use crate::select::{
    Fit, Selection, estimates, fit, holdout_rms, residuals_of, screen_outliers, select,
};

/// Why a diagnosis could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// The geometric identification itself failed.
    #[error(transparent)]
    Ident(#[from] IdentError),
    /// Too few poses for cross-validation.
    #[error("too few poses ({0}) for a diagnosis: at least 20 are needed")]
    TooFewPoses(usize),
}

/// Options of [`diagnose`].
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Standard deviation of one logged reading `[phi, theta, s]`.
    pub sigma: [f64; 3],
    /// Family-wise significance level of the tests.
    pub alpha: f64,
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Largest number of causes named.
    pub max_causes: usize,
    /// Lattice of the middle-plane comparison, mm.
    pub plane_spacing_mm: f64,
    /// Largest share of poses that may be called outliers.
    pub max_outlier_share: f64,
}

impl DiagnoseOptions {
    /// Defaults with the logged noise of `machine`'s sensors.
    pub fn for_machine(machine: &Machine) -> DiagnoseOptions {
        DiagnoseOptions {
            sigma: machine.sensors.logged_sigma(),
            alpha: 1e-3,
            folds: 5,
            max_causes: 3,
            plane_spacing_mm: 50.0,
            max_outlier_share: 0.1,
        }
    }
}

/// Diagnoses `data` taken on a machine whose nominal model is `nominal`.
///
/// # Example
/// ```no_run
/// use tricept_diagnose::{diagnose, DiagnoseOptions};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let data = tricept_data::read_path("fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
/// let d = diagnose(&m, &data, &DiagnoseOptions::for_machine(&m)).unwrap();
/// println!("adequate: {}, causes: {:?}", d.adequate, d.causes.iter().map(|c| c.effect).collect::<Vec<_>>());
/// ```
pub fn diagnose(
    nominal: &Machine,
    data: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let n = data.poses.len();
    if n < 20 {
        return Err(DiagnoseError::TooFewPoses(n));
    }
    let geometric = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    let base_model = ExtendedModel::new(geometric.clone(), &[]);

    // 1-3. Outliers, adequacy, causes; the outlier screen is repeated with
    // the selected effects, so that a systematic misfit the effects explain
    // is not taken for gross errors.
    let mut flagged = screen_outliers(&base_model, data, options)?;
    let mut selection;
    let mut rounds = 0;
    loop {
        rounds += 1;
        if (flagged.len() as f64) > options.max_outlier_share * n as f64 {
            flagged.clear();
        }
        let clean = data.subset(|j| !flagged.contains(&j));
        selection = select(&geometric, &clean, options)?;
        let model = ExtendedModel::new(geometric.clone(), &selection.chosen);
        let again = screen_outliers(&model, data, options)?;
        if again == flagged || rounds == 3 {
            break;
        }
        flagged = again;
    }
    let outliers = !flagged.is_empty();
    let is_clean = |j: usize| !flagged.contains(&j);
    let clean = data.subset(is_clean);
    let Selection {
        chosen,
        evidences,
        current,
        current_rms,
        first_candidates,
        geo,
    } = selection;

    // 2. Adequacy of the geometric model on the clean poses.
    let geo_fit = geo.clone();
    let geo_res = residuals_of(&geo, &clean.poses, &options.sigma);
    let chi_square = geo.id.stats.chi_square;
    let dof = geo.id.stats.dof;
    let chi_square_p_value = chi2_sf(chi_square, dof as f64);
    let a = RAD_PER_ARCSEC;
    let rms = geo.id.stats.rms;
    let residual_rms_geometric = ChannelRms {
        phi_arcsec: rms[0] / a,
        theta_arcsec: rms[1] / a,
        s_um: rms[2] * 1e3,
    };
    let structure = structure(nominal, &clean, &geo_res);

    let mut causes = Vec::new();
    if outliers {
        let all = fit(current.model.clone(), data, options)?;
        let z_max = residuals_of(&current, &data.poses, &options.sigma)
            .iter()
            .flatten()
            .flat_map(|r| r.iter().map(|v| v.abs()))
            .fold(0.0, f64::max);
        let p_value = ((3 * n) as f64 * chi2_sf(z_max * z_max, 1.0)).min(1.0);
        let delta = all.id.stats.chi_square - current.id.stats.chi_square;
        causes.push(Cause {
            effect: EffectName::Outliers,
            parameters: vec![
                Estimate {
                    name: "flagged_poses".into(),
                    value: flagged.len() as f64,
                    std_dev: None,
                },
                Estimate {
                    name: "largest_residual_sigma".into(),
                    value: z_max,
                    std_dev: None,
                },
            ],
            evidence: Evidence {
                delta_chi_square: delta,
                dof: 3 * flagged.len(),
                p_value,
                threshold: options.alpha,
                delta_bic: delta - (3 * flagged.len()) as f64 * ((3 * n) as f64).ln(),
                holdout_rms_without: None,
                holdout_rms_with: None,
                selected: true,
            },
            rows: flagged.iter().map(|&j| data.poses[j].line).collect(),
        });
    }

    // 4. Report.
    let final_estimates = estimates(&current);
    let offsets = current.model.offsets();
    for ((c, ev), at) in chosen.iter().zip(&evidences).zip(&offsets) {
        causes.push(Cause {
            effect: c.0,
            parameters: final_estimates[*at..*at + c.params().len()].to_vec(),
            evidence: ev.clone(),
            rows: Vec::new(),
        });
    }
    // Strongest first (outliers first only when they are the strongest).
    causes.sort_by(|a, b| b.evidence.delta_bic.total_cmp(&a.evidence.delta_bic));

    let geometric_only = estimates(&geo_fit);
    let g = current.model.n_geometric();
    let geometric_bias = final_estimates[..g]
        .iter()
        .zip(&geometric_only)
        .map(|(f, o)| (f.name.clone(), f.value - o.value))
        .collect();

    // Gain: held-out RMS on the clean poses for both models; for outliers,
    // the geometric model is trained on all poses.
    let holdout_rms_geometric = if outliers {
        holdout_rms(&base_model, data, options, &is_clean)
    } else {
        holdout_rms(&base_model, &clean, options, &|_| true)
    }
    .unwrap_or(f64::NAN);
    let holdout_rms_extended = if chosen.is_empty() {
        holdout_rms(&current.model, &clean, options, &|_| true)
    } else {
        current_rms
    }
    .unwrap_or(f64::NAN);
    let displacement = volumetric_difference(nominal, &geo_fit, &current, options);
    let raw = displacement.stats();
    let touched = displacement.without_mean_translation().stats();

    let adequate = causes.is_empty() && chi_square_p_value > options.alpha;
    let unexplained = (!adequate && causes.is_empty()).then(|| {
        let s = structure.first();
        format!(
            "the geometric model leaves chi-square {chi_square:.1} for {dof} degrees of freedom (p = {chi_square_p_value:.2e}) and no candidate effect explains it{}",
            s.map_or(String::new(), |s| format!(
                "; strongest residual structure: {} residual vs {} (r = {:+.2}, p = {:.1e})",
                s.channel, s.regressor, s.correlation, s.p_value
            ))
        )
    });
    let plots = causes
        .iter()
        .filter_map(|c| residual_plot(c.effect, nominal, &clean, &geo_fit, &current, options))
        .collect();
    Ok(Diagnosis {
        adequate,
        chi_square,
        dof,
        chi_square_p_value,
        residual_rms_geometric,
        structure,
        causes,
        candidates: first_candidates,
        unexplained,
        gain: Gain {
            holdout_rms_geometric,
            holdout_rms_extended,
            volumetric_mean_mm: raw.mean_mm,
            volumetric_max_mm: raw.max_mm,
            volumetric_touched_mean_mm: touched.mean_mm,
        },
        geometric_only,
        extended: final_estimates,
        geometric_bias,
        plots,
    })
}

/// Displacement of the platform on the middle plane between the
/// geometric-only calibration and the final one: targets commanded through
/// the geometric fit's IK, positions predicted by the final model (leg
/// effects at the campaign's mean context).
fn volumetric_difference(
    nominal: &Machine,
    geo: &Fit,
    fin: &Fit,
    options: &DiagnoseOptions,
) -> tricept_model::ErrorMap {
    let targets = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), options.plane_spacing_mm);
    let m_geo = geo.model.machine_at(&geo.id.estimate);
    let m_fin = fin.model.machine_at(&fin.id.estimate);
    let predictor = fin.model.at(&fin.id.estimate);
    let k = fin.model.names().len();
    let mut jac = vec![0.0; 3 * k];
    let mut map = tricept_model::ErrorMap {
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
    map
}
