//! What pooling adds to an internal fit (several campaigns, a batch's
//! prior): each campaign's row, the prior used, their JSON, report lines
//! and machine-file records (`pooled.rs` makes them).

use std::path::Path;

use serde_json::{Value, json};
use tricept_fleet::campaigns::Agreement;
use tricept_kinematics::description::ExternalSourceRecord;
use tricept_numerics::stats::chi2_sf;

use crate::error::Error;

/// What pooling adds to an internal fit.
#[derive(Debug)]
pub(crate) struct Pooled {
    /// Every campaign, in the order given.
    pub campaigns: Vec<CampaignRow>,
    /// The data files of the campaigns that disagree with the rest.
    pub disagreeing: Vec<String>,
    /// The prior, when there was one.
    pub prior: Option<PriorUsed>,
    /// The campaign file of each rejected pose, in the fit's order.
    pub(crate) rejected_files: Vec<String>,
}

/// One campaign's share of a pooled fit.
#[derive(Debug)]
pub(crate) struct CampaignRow {
    pub(crate) file: String,
    pub(crate) poses: usize,
    pub(crate) rejected_lines: Vec<u64>,
    pub(crate) offsets: Option<([f64; 3], [f64; 3])>,
    pub(crate) chi_square: f64,
    pub(crate) readings: usize,
    pub(crate) temperature_c: Option<f64>,
    pub(crate) agreement: Option<Agreement>,
    pub(crate) in_fit: bool,
}

/// The prior a calibration used.
#[derive(Debug)]
pub(crate) struct PriorUsed {
    pub(crate) file: String,
    pub(crate) sha256: String,
    pub(crate) machines: usize,
    pub(crate) members: usize,
    pub(crate) chi_square: f64,
    pub(crate) dof: usize,
}

impl Pooled {
    /// Whether a campaign disagrees with the rest (exit code 3).
    pub fn refused(&self) -> Option<&'static str> {
        (!self.disagreeing.is_empty()).then_some("a campaign disagrees with the rest")
    }

    /// The campaign file of the fit's `i`-th rejected pose.
    pub fn rejected_file(&self, i: usize) -> Option<&str> {
        self.rejected_files.get(i).map(String::as_str)
    }

    /// The JSON keys pooling adds: `campaigns` (each campaign's file,
    /// poses, offsets, chi-square, temperature and agreement),
    /// `disagreeing_campaigns` and `prior`.
    pub fn json(&self) -> Vec<(&'static str, Value)> {
        let campaigns: Vec<Value> = self
            .campaigns
            .iter()
            .map(|c| {
                let offsets = c.offsets.map(|(o, sd)| {
                    json!({"phi_rad": o[0], "theta_rad": o[1], "s_mm": o[2],
                           "std_dev": {"phi_rad": sd[0], "theta_rad": sd[1], "s_mm": sd[2]}})
                });
                json!({
                    "data_file": c.file,
                    "in_fit": c.in_fit,
                    "poses": c.poses,
                    "rejected_lines": c.rejected_lines,
                    "offsets": offsets,
                    "chi_square": c.chi_square,
                    "readings": c.readings,
                    "temperature_c": c.temperature_c,
                    "agreement": c.agreement,
                })
            })
            .collect();
        let prior = self.prior.as_ref().map(|p| {
            json!({"file": p.file, "sha256": p.sha256, "machines": p.machines, "members": p.members,
                   "chi_square": p.chi_square, "dof": p.dof,
                   "p_value": chi2_sf(p.chi_square, p.dof as f64)})
        });
        vec![
            ("campaigns", Value::Array(campaigns)),
            ("disagreeing_campaigns", self.disagreeing.clone().into()),
            ("prior", prior.unwrap_or(Value::Null)),
        ]
    }

    /// The report's lines: one per campaign, then the prior.
    pub fn report(&self) -> String {
        let mut s = format!(
            "{} campaigns pooled, each with its own sensor offsets:\n",
            self.campaigns.len()
        );
        for c in &self.campaigns {
            let offsets = c
                .offsets
                .map_or("left out of the fit".to_string(), |(o, _)| {
                    format!(
                        "offsets phi {:.6} rad, theta {:.6} rad, s {:.4} mm",
                        o[0], o[1], o[2]
                    )
                });
            let agreement = c.agreement.map_or(String::new(), |a| {
                format!(
                    ", agreement chi2 {:.1} on {} (p = {:.2e})",
                    a.chi_square, a.dof, a.p_value
                )
            });
            let temperature = c
                .temperature_c
                .map_or(String::new(), |t| format!(", {t:.2} °C"));
            let poses = if c.in_fit {
                format!("{} poses", c.poses)
            } else {
                "its poses".to_string()
            };
            s.push_str(&format!(
                "  {}: {poses}{}, {offsets}{}{temperature}{agreement}{}\n",
                c.file,
                if c.rejected_lines.is_empty() {
                    String::new()
                } else {
                    format!(" (rejected lines {:?})", c.rejected_lines)
                },
                if c.in_fit {
                    format!(", chi2 {:.1} on {} readings", c.chi_square, c.readings)
                } else {
                    String::new()
                },
                if self.disagreeing.contains(&c.file) {
                    ": DISAGREES with the rest"
                } else {
                    ""
                }
            ));
        }
        if let Some(p) = &self.prior {
            s.push_str(&format!(
                "prior: the batch of {} ({} machines in its estimates): chi2 {:.1} on {} (p = {:.2e})\n",
                p.file,
                p.members,
                p.chi_square,
                p.dof,
                chi2_sf(p.chi_square, p.dof as f64)
            ));
        }
        s
    }

    /// The file records of the other campaigns and the prior for the
    /// machine file (the first campaign is its `data_file`).
    pub fn sources(&self) -> Result<Vec<ExternalSourceRecord>, Error> {
        let mut out = Vec::new();
        for c in self.campaigns.iter().skip(1) {
            let mut nuisance = serde_json::Map::new();
            if let Some((o, sd)) = c.offsets {
                for (name, v, s) in [
                    ("phi_rad", o[0], sd[0]),
                    ("theta_rad", o[1], sd[1]),
                    ("s_mm", o[2], sd[2]),
                ] {
                    nuisance.insert(format!("offset.{name}"), json!({"value": v, "std_dev": s}));
                }
            }
            out.push(ExternalSourceRecord {
                kind: "campaign".into(),
                sha256: crate::machine_file::sha256_file(Path::new(&c.file))?,
                file: c.file.clone(),
                records: c.poses,
                chi2_per_dof: (c.readings > 3).then(|| c.chi_square / (c.readings - 3) as f64),
                redundancy: c.readings.saturating_sub(3) as f64,
                checkable: c.in_fit,
                rejected_lines: c.rejected_lines.clone(),
                nuisance,
            });
        }
        if let Some(p) = &self.prior {
            out.push(ExternalSourceRecord {
                kind: "prior".into(),
                file: p.file.clone(),
                sha256: p.sha256.clone(),
                records: p.members,
                chi2_per_dof: Some(p.chi_square / p.dof.max(1) as f64),
                redundancy: p.dof as f64,
                checkable: true,
                rejected_lines: Vec::new(),
                nuisance: serde_json::Map::new(),
            });
        }
        Ok(out)
    }
}
