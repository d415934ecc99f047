//! What a diagnosis reports: the geometric model's adequacy, the named
//! causes with their parameters and evidence, the bias they had put into
//! the geometric parameters, and the gain of the extended model; as data
//! (serialised to JSON by `serde`) and as text for people.

use serde::Serialize;
use serde::ser::{SerializeMap, Serializer};
use serde_json::Value;
use tricept_model::effects::EffectName;

/// The statistical evidence for one candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evidence {
    /// Drop of chi-square when the effect is added.
    pub delta_chi_square: f64,
    /// Identifiable parameters the effect adds (the test's degrees of freedom).
    pub dof: usize,
    /// Likelihood-ratio p-value.
    pub p_value: f64,
    /// The p-value it had to beat (alpha / candidates).
    pub threshold: f64,
    /// BIC improvement (`delta_chi_square - dof ln N`; positive favours the effect).
    pub delta_bic: f64,
    /// Held-out weighted residual RMS without the effect (noise = 1).
    pub holdout_rms_without: Option<f64>,
    /// Held-out weighted residual RMS with the effect.
    pub holdout_rms_with: Option<f64>,
    /// Whether every criterion passed.
    pub selected: bool,
}

/// An estimated parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Name (unit in the name).
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard deviation (`None` when unidentifiable and held at zero).
    pub std_dev: Option<f64>,
}

/// A named cause.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cause {
    /// The effect, from the vocabulary.
    pub effect: EffectName,
    /// Its parameters in the final model.
    #[serde(serialize_with = "estimates_by_name")]
    pub parameters: Vec<Estimate>,
    /// The evidence when it was selected.
    pub evidence: Evidence,
    /// Lines of the data file flagged (outliers only).
    pub rows: Vec<u64>,
}

/// A residual correlation with a regressor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Structure {
    /// The regressor.
    pub regressor: String,
    /// The reading channel (`phi`, `theta`, `s`).
    pub channel: &'static str,
    /// Pearson correlation of the weighted residual with the regressor.
    pub correlation: f64,
    /// Two-sided p-value (Fisher z).
    pub p_value: f64,
}

/// What the final model gains over the geometric one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gain {
    /// Held-out weighted residual RMS of the geometric model (noise = 1).
    pub holdout_rms_geometric: f64,
    /// Held-out weighted residual RMS of the final model.
    pub holdout_rms_extended: f64,
    /// Mean platform displacement on the middle plane between the
    /// geometric-only and the final calibration (commands of the former,
    /// positions predicted by both), mm.
    pub volumetric_mean_mm: f64,
    /// Largest such displacement, mm.
    pub volumetric_max_mm: f64,
    /// Mean displacement after removing the best-fit rigid translation
    /// (touch-off): most of the raw figure is often a translation along the
    /// weak leg-length direction that the sensors cannot see, mm.
    pub volumetric_touched_mean_mm: f64,
}

/// A residual plot: weighted residuals of a channel (or implied leg-length
/// residuals) against the regressor that exposes a cause.
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualPlot {
    /// The cause it illustrates.
    pub effect: EffectName,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Points with the geometric model.
    pub before: Vec<(f64, f64)>,
    /// Points with the final model.
    pub after: Vec<(f64, f64)>,
}

/// The diagnosis of a data set.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnosis {
    /// The geometric model alone explains the data.
    pub adequate: bool,
    /// Chi-square of the geometric fit (clean poses).
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// `P(chi2_dof > chi_square)`.
    pub chi_square_p_value: f64,
    /// RMS residual of the geometric fit.
    pub residual_rms_geometric: ChannelRms,
    /// Strongest residual correlations of the geometric fit.
    pub structure: Vec<Structure>,
    /// Named causes, strongest first.
    pub causes: Vec<Cause>,
    /// Every candidate tested at the first selection step.
    pub candidates: Vec<Tested>,
    /// When the data are not explained and no cause is found: what is seen.
    pub unexplained: Option<String>,
    /// Gain of the final model.
    pub gain: Gain,
    /// Geometric parameters of the geometric-only fit.
    #[serde(serialize_with = "estimates_by_name")]
    pub geometric_only: Vec<Estimate>,
    /// Every parameter of the final model.
    #[serde(serialize_with = "estimates_by_name")]
    pub extended: Vec<Estimate>,
    /// How much adding the causes moved each geometric parameter
    /// (final minus geometric-only), mm.
    #[serde(rename = "geometric_bias_mm", serialize_with = "values_by_name")]
    pub geometric_bias: Vec<(String, f64)>,
    /// Residual plots of the named causes.
    #[serde(skip)]
    pub plots: Vec<ResidualPlot>,
}

/// RMS residual of each reading channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChannelRms {
    /// Encoder `phi`, arcsec.
    pub phi_arcsec: f64,
    /// Encoder `theta`, arcsec.
    pub theta_arcsec: f64,
    /// Linear scale `s`, um.
    pub s_um: f64,
}

/// A candidate effect with the evidence it had when tested.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tested {
    /// The effect.
    pub effect: EffectName,
    /// Its evidence.
    pub evidence: Evidence,
}

/// Serialises estimates as `{name: {"value": v, "std_dev": s}}`.
fn estimates_by_name<S: Serializer>(v: &[Estimate], s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Entry {
        value: f64,
        std_dev: Option<f64>,
    }
    let mut map = s.serialize_map(Some(v.len()))?;
    for e in v {
        map.serialize_entry(
            &e.name,
            &Entry {
                value: e.value,
                std_dev: e.std_dev,
            },
        )?;
    }
    map.end()
}

/// Serialises `(name, value)` pairs as `{name: value}`.
fn values_by_name<S: Serializer>(v: &[(String, f64)], s: S) -> Result<S::Ok, S::Error> {
    let mut map = s.serialize_map(Some(v.len()))?;
    for (name, value) in v {
        map.serialize_entry(name, value)?;
    }
    map.end()
}

impl Diagnosis {
    /// JSON with the contract keys `adequate`, `causes` (each with
    /// `effect`, its parameter estimates and evidence) and `gain`
    /// (`holdout_rms_geometric`, `holdout_rms_extended`), and more: the
    /// serialisation of this type.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }
}

impl Diagnosis {
    /// The report as text for people; `source` names the data (a file).
    pub fn to_text(&self, source: &str) -> String {
        use std::fmt::Write as _;
        let mut out = String::new();
        // Writing to a String cannot fail.
        macro_rules! w {
            ($($arg:tt)*) => {{
                let _ = writeln!(out, $($arg)*);
            }};
        }
        w!(
            "{}: the geometric model {}",
            source,
            if self.adequate {
                "explains the data (adequate)"
            } else {
                "does NOT explain the data"
            }
        );
        w!(
            "geometric fit: chi2 {:.1} for {} dof (p = {:.2e}); residual rms phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um",
            self.chi_square,
            self.dof,
            self.chi_square_p_value,
            self.residual_rms_geometric.phi_arcsec,
            self.residual_rms_geometric.theta_arcsec,
            self.residual_rms_geometric.s_um
        );
        if let Some(s) = self.structure.first() {
            w!(
                "strongest residual structure: {} vs {} (r = {:+.2}, p = {:.1e})",
                s.channel,
                s.regressor,
                s.correlation,
                s.p_value
            );
        }
        for (i, c) in self.causes.iter().enumerate() {
            let ev = &c.evidence;
            w!(
                "cause {}: {}   (chi2 drop {:.1} for {} dof, p = {:.1e}; BIC gain {:.1}{})",
                i + 1,
                c.effect,
                ev.delta_chi_square,
                ev.dof,
                ev.p_value,
                ev.delta_bic,
                match (ev.holdout_rms_without, ev.holdout_rms_with) {
                    (Some(a), Some(b)) => format!("; held-out rms {a:.2} -> {b:.2}"),
                    _ => String::new(),
                }
            );
            for p in &c.parameters {
                match p.std_dev {
                    Some(sd) => w!("    {:<40} {:>12.4} +- {:.4}", p.name, p.value, sd),
                    None => w!("    {:<40} {:>12.4}", p.name, p.value),
                }
            }
            if !c.rows.is_empty() {
                w!("    lines: {:?}", c.rows);
            }
        }
        if let Some(u) = &self.unexplained {
            w!("unexplained: {u}");
        }
        let mut bias = self.geometric_bias.clone();
        bias.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        if !self.causes.is_empty() {
            let text: Vec<String> = bias
                .iter()
                .take(4)
                .map(|(n, v)| format!("{n} {:+.4}", v))
                .collect();
            w!(
                "bias the causes put into the geometric parameters (mm): {}",
                text.join(", ")
            );
        }
        let g = &self.gain;
        w!(
            "gain: held-out rms {:.3} -> {:.3} (noise = 1); platform moved on the middle plane by {:.4} mm mean ({:.4} after touch-off), {:.4} mm max",
            g.holdout_rms_geometric,
            g.holdout_rms_extended,
            g.volumetric_mean_mm,
            g.volumetric_touched_mean_mm,
            g.volumetric_max_mm
        );
        out
    }
}
