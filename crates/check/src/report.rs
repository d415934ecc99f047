//! A check's report as text: the verdict and the most likely change first,
//! then the evidence, the sensors and every candidate.

use std::fmt::Write as _;

use tricept_kinematics::units::RAD_PER_ARCSEC;

use crate::changes::Change;
use crate::check::{CheckReport, CheckVerdict};
use crate::parts::CandidateResult;

/// A parameter's value in the unit a person reads: um for a length
/// (parameters ending in `_mm`), the parameter's own unit otherwise.
pub(crate) fn shown(parameter: &str, value: f64) -> (String, f64, &'static str) {
    if let Some(name) = parameter.strip_suffix("_um") {
        return (name.to_string(), value, "um");
    }
    match parameter.strip_suffix("_mm") {
        Some(name) => (name.to_string(), value * 1e3, "um"),
        None => match parameter.strip_suffix("_ppm_per_k") {
            Some(name) => (name.to_string(), value, "ppm/K"),
            None => match parameter.strip_suffix("_ppm") {
                Some(name) => (name.to_string(), value, "ppm"),
                None => (parameter.to_string(), value, ""),
            },
        },
    }
}

/// `dq2 = +25.3 +- 1.2 um, lead2 = ...` for the components the campaign sees.
pub(crate) fn estimate_text(c: &CandidateResult) -> String {
    values_text(&c.parameters, &c.estimate, &c.std_dev)
}

/// `dq2 = +25.3 +- 1.2 um, ...` for each parameter with a standard
/// deviation.
fn values_text(parameters: &[String], estimate: &[f64], std_dev: &[Option<f64>]) -> String {
    parameters
        .iter()
        .zip(estimate)
        .zip(std_dev)
        .filter_map(|((p, v), sd)| {
            sd.map(|sd| {
                let (name, v, unit) = shown(p, *v);
                let (_, sd, _) = shown(p, sd);
                format!("{name} = {v:+.1} +- {sd:.1} {unit}")
            })
        })
        .collect::<Vec<_>>()
        .join(", ")
}

impl CheckReport {
    /// The report as text (see the module docs).
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let best = self.most_likely.map(|i| &self.candidates[i]);
        match (self.verdict, best) {
            (CheckVerdict::Unchanged, _) => {
                let _ = writeln!(
                    s,
                    "verdict: UNCHANGED: the readings are consistent with the calibrated machine (false-alarm probability {})",
                    self.alpha
                );
            }
            (CheckVerdict::NoisierThanStated, _) => {
                let _ = writeln!(
                    s,
                    "verdict: NOISIER THAN STATED: the readings scatter {:.2} times the stated noise and no change stands out beyond it (state the noise or service the sensors; false-alarm probability {})",
                    self.noise.factor, self.alpha
                );
            }
            (v, Some(b)) => {
                let _ = writeln!(
                    s,
                    "verdict: CHANGED{}: most likely {} ({}), which moves the platform by {:.1} um on average and up to {:.1} um over the workspace",
                    if v == CheckVerdict::ChangedUnexplained {
                        ", and no single change explains it all"
                    } else {
                        ""
                    },
                    b.name,
                    estimate_text(b),
                    b.platform_mean_um,
                    b.platform_max_um
                );
                if self.shortlist.len() > 1 {
                    let _ = writeln!(
                        s,
                        "  the check cannot tell apart: {} (each explains the readings as well; a campaign planned for a check (instrument `check`) or a diagnosis separates them)",
                        self.shortlist.join(", ")
                    );
                }
            }
            (_, None) => {
                let _ = writeln!(
                    s,
                    "verdict: CHANGED, cause unknown: the readings do not fit the calibrated machine, and no leg, joint, thermal state or sensor gain explains them (run `tricept diagnose` on a full campaign)"
                );
            }
        }
        // The set, unless it is the most likely change alone, without
        // aliases (the verdict line names it).
        let alone = match (self.changes.as_slice(), best) {
            ([one], Some(b)) => one.name == b.name && one.aliases.is_empty(),
            _ => false,
        };
        if !self.changes.is_empty() && !alone {
            let list: Vec<String> = self.changes.iter().map(change_text).collect();
            let _ = writeln!(
                s,
                "changes (the smallest set that explains the readings, each tested given the others): {}",
                list.join("; ")
            );
        }
        if let Some(r) = self.after_changes.as_ref().filter(|_| !alone) {
            let _ = writeln!(
                s,
                "after the changes: chi2 {:.1} for {} dof (p = {:.2e})",
                r.statistic, r.dof, r.p_value
            );
        }
        let c = &self.consistency;
        let _ = writeln!(
            s,
            "consistency with the calibration: chi2 {:.1} for {} dof (p = {:.2e}; a change above {:.1}), {} poses",
            c.statistic, c.dof, c.p_value, c.critical, self.poses
        );
        if let Some(r) = &self.remaining {
            let _ = writeln!(
                s,
                "after the most likely change: chi2 {:.1} for {} dof (p = {:.2e})",
                r.statistic, r.dof, r.p_value
            );
        }
        let (n, t) = (&self.noise.seen, &self.noise.stated);
        let _ = writeln!(
            s,
            "noise seen: {:.2} x the stated (per logged reading: phi {:.2} arcsec, theta {:.2} arcsec, s {:.2} um; stated {:.2}, {:.2}, {:.2})",
            self.noise.factor,
            n.phi_arcsec,
            n.theta_arcsec,
            n.s_um,
            t.phi_arcsec,
            t.theta_arcsec,
            t.s_um
        );
        let a = RAD_PER_ARCSEC;
        let d = self.offsets_change;
        let _ = writeln!(
            s,
            "sensor zeros since the calibration: phi {:+.2} arcsec, theta {:+.2} arcsec, s {:+.2} um (re-estimated at every check: a re-referenced sensor is not a change of the machine)",
            d[0] / a,
            d[1] / a,
            d[2] * 1e3
        );
        if let Some(t) = self.temperature_c {
            let _ = writeln!(s, "structure temperature at the check: {t:.2} °C");
        }
        let _ = writeln!(
            s,
            "{:<18} {:>12} {:>10}  {:<44} {:>26}  {:>16}",
            "candidate", "chi2 / dof", "p", "estimate", "detectable (95 %)", "platform um"
        );
        for c in &self.candidates {
            let detectable = c
                .parameters
                .iter()
                .zip(&c.detectable)
                .filter_map(|(p, d)| {
                    d.map(|d| {
                        let (name, v, unit) = shown(p, d);
                        format!("{name} {v:.1} {unit}")
                    })
                })
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(
                s,
                "{:<18} {:>7.1} / {:<2} {:>10.2e}  {:<44} {:>26}  {:>7.1} / {:>6.1}{}",
                c.name,
                c.test.statistic,
                c.test.dof,
                c.test.p_value,
                estimate_text(c),
                detectable,
                c.platform_mean_um,
                c.platform_max_um,
                if c.significant { "  *" } else { "" }
            );
        }
        for w in &self.warnings {
            let _ = writeln!(s, "WARNING: {w}");
        }
        s
    }
}

/// `leg 1 (dq1 = +25.3 +- 2.6 um; moves the platform 30.1 um on average)`,
/// with the candidates that explain it as well.
fn change_text(c: &Change) -> String {
    let aliases = if c.aliases.is_empty() {
        String::new()
    } else {
        format!("; or, as well: {}", c.aliases.join(", "))
    };
    format!(
        "{} ({}; moves the platform {:.1} um on average, up to {:.1} um{aliases})",
        c.name,
        values_text(&c.parameters, &c.estimate, &c.std_dev),
        c.platform_mean_um,
        c.platform_max_um
    )
}
