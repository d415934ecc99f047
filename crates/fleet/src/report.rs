//! A batch as JSON (the contract keys of `tricept fleet --json`) and as
//! the text report.

use serde_json::{Map, Value, json};
use tricept_numerics::stats::chi2_sf;

use crate::batch::Batch;

/// `{name: value}`, `null` where there is none.
fn named(names: &[String], values: &[Option<f64>]) -> Value {
    Value::Object(
        names
            .iter()
            .zip(values)
            .map(|(n, v)| {
                (
                    n.clone(),
                    v.filter(|x| x.is_finite()).map_or(Value::Null, Value::from),
                )
            })
            .collect::<Map<_, _>>(),
    )
}

impl Batch {
    /// The JSON of `tricept fleet --json`: `batch_mean_mm`,
    /// `batch_mean_sd_mm`, `batch_spread_mm` (`{name: mm}`, `null` where
    /// held), `machines[]` (`data_file`, `estimates_mm`, `std_dev_mm`,
    /// `exit_code`, `deviates`, and `in_batch`, `kept_out`, `outlier`,
    /// `distance`, `offsets`, `rejected_lines`), `outliers`, `solver`
    /// (`kind`, `unknowns`, `nonzeros`, `readings`, `seconds`), and the
    /// spread's upper bound, the held parameters, the exit code and the
    /// warnings.
    pub fn to_json(&self) -> Value {
        let names = &self.names;
        let (mean, mean_sd) = self.mean();
        let held: Vec<&String> = self.held().iter().map(|&j| &names[j]).collect();
        let machines: Vec<Value> = self
            .machines
            .iter()
            .map(|m| {
                json!({
                    "data_file": m.own.source,
                    "estimates_mm": named(names, &m.estimate.iter().map(|v| Some(*v)).collect::<Vec<_>>()),
                    "std_dev_mm": named(names, &m.std_dev),
                    "exit_code": m.own.exit_code,
                    "deviates": m.deviates,
                    "in_batch": m.in_batch,
                    "outlier": m.outlier,
                    "kept_out": m.kept_out,
                    "distance": m.distance.as_ref().map(|d| json!({
                        "chi_square": d.chi_square, "dof": d.dof, "p_value": m.p_value,
                    })),
                    "offsets": {"phi_rad": m.offsets[0], "theta_rad": m.offsets[1], "s_mm": m.offsets[2]},
                    "poses": m.own.kept.poses.len(),
                    "rejected_lines": m.own.rejected.iter().map(|r| r.line).collect::<Vec<_>>(),
                })
            })
            .collect();
        let s = &self.joint.stats;
        json!({
            "batch_mean_mm": named(names, &mean.iter().zip(&mean_sd).map(|(v, sd)| sd.map(|_| *v)).collect::<Vec<_>>()),
            "batch_mean_sd_mm": named(names, &mean_sd),
            "batch_spread_mm": named(names, &self.spread_mm()),
            "batch_spread_upper_mm": named(names, &self.spread_upper_mm()),
            "held": held,
            "machines": machines,
            "members": self.members(),
            "outliers": self.outliers(),
            "solver": {
                "kind": s.kind.name(),
                "unknowns": s.unknowns,
                "nonzeros": s.nonzeros,
                "readings": self.joint.readings,
                "seconds": s.seconds,
                "rows": s.rows,
                "iterations": self.joint.iterations,
                "converged": self.joint.converged,
                "fit_seconds": self.joint.fit_seconds,
            },
            "spread_method": "REML (Fisher scoring)",
            "spread_converged": self.spread.converged,
            "chi_square": {
                "readings": self.joint.chi_square_readings.iter().sum::<f64>(),
                "prior_rows": self.joint.chi_square_prior,
            },
            "exit_code": self.exit_code(),
            "warnings": self.warnings,
        })
    }

    /// The text report.
    pub fn to_text(&self) -> String {
        let names = &self.names;
        let (mean, mean_sd) = self.mean();
        let spread = self.spread_mm();
        let upper = self.spread_upper_mm();
        let s = &self.joint.stats;
        let mut out = format!(
            "batch of {} machines, {} in the batch estimates; outliers: {}\n",
            self.machines.len(),
            self.members(),
            if self.outliers().is_empty() {
                "none".to_string()
            } else {
                self.outliers().join(", ")
            }
        );
        for w in &self.warnings {
            out.push_str(&format!("WARNING: {w}\n"));
        }
        out.push_str(&format!(
            "joint fit: {} readings, {} unknowns, {} non-zeros, solver {}: {:.3} s solving, {:.3} s in all, {} Gauss-Newton iterations, {}\n",
            self.joint.readings,
            s.unknowns,
            s.nonzeros,
            s.kind.name(),
            s.seconds,
            self.joint.fit_seconds,
            self.joint.iterations,
            if self.joint.converged { "converged" } else { "NOT converged" }
        ));
        out.push_str(&format!(
            "{:>6} {:>12} {:>10} {:>11} {:>11}\n",
            "param", "batch mean", "sd mm", "spread mm", "95% upper"
        ));
        for (j, n) in names.iter().enumerate() {
            match (mean_sd[j], spread[j], upper[j]) {
                (Some(sd), Some(t), Some(u)) => out.push_str(&format!(
                    "{n:>6} {:>12.5} {sd:>10.5} {t:>11.5} {u:>11.5}\n",
                    mean[j]
                )),
                _ => out.push_str(&format!(
                    "{n:>6} {:>12} (held: no machine's data see it)\n",
                    "held"
                )),
            }
        }
        out.push_str("machines:\n");
        for m in &self.machines {
            let status = match (&m.kept_out, m.outlier) {
                (_, true) => "OUTLIER".to_string(),
                (Some(_), false) => "kept out".to_string(),
                (None, false) => "in the batch".to_string(),
            };
            let distance = m.distance.as_ref().map_or(String::new(), |d| {
                format!(
                    ", distance chi2 {:.1} on {} (p = {:.1e})",
                    d.chi_square,
                    d.dof,
                    chi2_sf(d.chi_square, d.dof as f64)
                )
            });
            let deviates = if m.deviates.is_empty() {
                String::new()
            } else {
                format!(", beyond the spread: {}", m.deviates.join(", "))
            };
            out.push_str(&format!(
                "  {}: {status}, exit code {}{distance}{deviates}\n",
                m.own.source, m.own.exit_code
            ));
        }
        out
    }
}
