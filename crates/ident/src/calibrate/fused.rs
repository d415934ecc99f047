//! The fused calibration: the module, the head and every instrument's
//! nuisance in one fit from the internal data and external measurements
//! (laser tracker, ballbar, touch-offs; `tricept_engine::fusion`), its
//! verdict (every source checkable, explained and every estimate
//! plausible), its JSON, its text report and its calibrated machine file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use tricept_data::{
    external::BallbarReading, external::ExternalData, external::ExternalRecord,
    external::TouchReading, external::TrackerPoint,
};
use tricept_engine::IdentError;
use tricept_engine::fusion::{FusedModel, Fusion, Source, SourceKind, identify_fused};
use tricept_kinematics::description::ExternalSourceRecord;
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::effects::EffectName;

use super::checked::{Checked, FusedWork};
use super::values::fused_model;
use crate::data_input::check_commands;
use crate::error::{EXIT_INADEQUATE, EXIT_NOT_CONVERGED, EXIT_OK, Error};
use crate::inputs::LoadedMachine;
use crate::machine_file;

/// A fused fit with its model and its sources.
#[derive(Debug)]
pub(crate) struct FusedFit {
    pub model: FusedModel,
    pub fit: Fusion,
    pub sources: Vec<Source>,
    /// The module's parameter set label.
    pub set_label: String,
    /// The outcome of the last write, for the JSON (`deployed`).
    pub deployed: std::sync::Mutex<Option<Value>>,
    /// The promise of the written file, made once when first asked.
    pub promise: std::sync::OnceLock<crate::accuracy::Accuracy>,
    /// External sources that cannot be checked on their own, tested
    /// against the checkable fit of the others (`None`: nothing to test).
    pub unchecked: Option<Unchecked>,
    /// The promise's structure part `(rms_mm, upper_mm)`
    /// (`accuracy::fused_structure`).
    pub structure: (f64, f64),
}

/// External sources that cannot be checked on their own (too little
/// redundancy: a gross error would fit them) tested against the fit of the
/// other sources, which can be: the chi-square they add to it, and how far
/// they move the tool tip.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Unchecked {
    /// Their labels.
    pub labels: Vec<String>,
    /// The fit with them converged, is plausible, and explains every
    /// source that can be checked.
    pub others_fine: bool,
    /// The chi-square they add to the fit of the others.
    pub delta_chi2: f64,
    /// Its degrees of freedom (the redundancy they add).
    pub dof: f64,
    /// `P(chi2 > delta_chi2)`.
    pub p_value: f64,
    /// The tool tip's rms shift after touch-off over the evaluation poses
    /// between the fits with and without them, mm.
    pub shift_mm: f64,
    /// What chance gives that shift in mean square: the tip's predicted
    /// variance after touch-off without them less with them (the held
    /// parameters at the size the data show of the head), mm^2.
    pub chance_mm2: f64,
}

impl Unchecked {
    /// They agree with the checked fit: their added chi-square passes its
    /// test at the adequacy level, and the fit with them may otherwise be
    /// trusted.
    pub fn agrees(&self) -> bool {
        self.others_fine && self.p_value > tricept_engine::verdict::ADEQUACY_ALPHA
    }

    /// The promise's part `(rms_mm, upper_mm)`: the tip's shift beyond
    /// chance (a Hausman comparison of the two fits), its bound adding
    /// 1.645 times the chance's standard deviation (`sqrt(2)` times its
    /// mean at most).
    pub fn part_mm(&self) -> (f64, f64) {
        let bias2 = self.shift_mm.powi(2) - self.chance_mm2;
        let sd = std::f64::consts::SQRT_2 * self.chance_mm2;
        (
            bias2.max(0.0).sqrt(),
            (bias2 + 1.644_853_626_951_472_2 * sd).max(0.0).sqrt(),
        )
    }

    /// The JSON (`unchecked`).
    pub fn to_json(&self) -> Value {
        let (rms, upper) = self.part_mm();
        json!({
            "sources": self.labels,
            "agrees_with_checked_fit": self.agrees(),
            "added_chi_square": self.delta_chi2,
            "added_dof": self.dof,
            "p_value": self.p_value,
            "tip_shift_mm": self.shift_mm,
            "unchecked_mm": rms,
            "unchecked_upper_mm": upper,
        })
    }

    /// The report's line.
    pub fn line(&self) -> String {
        let (rms, upper) = self.part_mm();
        format!(
            "unchecked: {} cannot be checked on {} own; {} the checked fit of the other sources (added chi-square {:.1} for {:.1} degrees of freedom, p = {:.2e}); the tool tip rests on {} by {:.4} mm rms after touch-off, {:.4} mm beyond chance (95 % bound {:.4} mm, in the promise)",
            self.labels.join(", "),
            if self.labels.len() == 1 {
                "its"
            } else {
                "their"
            },
            if self.agrees() {
                "it agrees with"
            } else {
                "it DISAGREES with"
            },
            self.delta_chi2,
            self.dof,
            self.p_value,
            if self.labels.len() == 1 { "it" } else { "them" },
            self.shift_mm,
            rms,
            upper
        )
    }
}

/// Fits the checked fused calibration `w` on `c`'s machine.
pub(crate) fn fit(c: &Checked, w: &FusedWork) -> Result<FusedFit, Error> {
    let (machine, model, options) = (c.loaded.machine(), &w.model, &w.options);
    let all = sources(w, machine)?;
    let fit = identify_fused(model, &all, options)?;
    let unchecked = unchecked(model, &fit, options, || sources(w, machine))?;
    // The geometric estimate's shift when every leg may have a lead.
    let mut structure = (0.0, 0.0);
    if model.effects().is_empty() && fit.converged {
        let mut rich = fused_model(machine, &c.set, &[EffectName::LegLead], w.head)?;
        if let Some(reference) = c.loaded.rank_reference()? {
            rich = rich.with_rank_reference(reference)?;
        }
        if let Ok(r) = identify_fused(&rich, &all, options) {
            structure =
                crate::accuracy::fused_structure(model, &fit, &rich, &r, &options.eval_poses);
        }
    }
    Ok(FusedFit {
        model: model.clone(),
        fit,
        sources: all,
        set_label: c.set.label().to_string(),
        deployed: std::sync::Mutex::new(None),
        promise: std::sync::OnceLock::new(),
        unchecked,
        structure,
    })
}

/// The external sources of `fit` that cannot be checked on their own,
/// tested against the fit of the others when that fit holds an external
/// source and can be trusted (they agree when their added chi-square
/// passes and the fit with them is otherwise trustworthy); `again` reads
/// the sources anew.
fn unchecked(
    model: &FusedModel,
    fit: &Fusion,
    options: &tricept_engine::fusion::FusionOptions,
    again: impl Fn() -> Result<Vec<Source>, Error>,
) -> Result<Option<Unchecked>, Error> {
    let labels: Vec<String> = fit
        .sources
        .iter()
        .filter(|s| !s.checkable)
        .map(|s| s.label.clone())
        .collect();
    if labels.is_empty()
        || fit.is_trustworthy()
        || fit
            .sources
            .iter()
            .any(|s| !s.checkable && s.kind == SourceKind::Internal)
    {
        return Ok(None);
    }
    // Everything else about the fit with them may be trusted.
    let others_fine = fit.converged
        && fit.implausible.is_empty()
        && fit.sources.iter().all(|s| !s.checkable || s.explained());
    let rest: Vec<Source> = again()?
        .into_iter()
        .filter(|s| !labels.iter().any(|l| l == s.label()))
        .collect();
    // Something outside the machine must check them: the internal data do
    // not see the head (a tracker or ballbar that cannot be checked, with
    // the internal data alone, stays refused).
    if rest.iter().all(|s| s.kind() == SourceKind::Internal) {
        return Ok(None);
    }
    // The others alone must be a fit that can be trusted.
    let Ok(checked) = identify_fused(model, &rest, options) else {
        return Ok(None);
    };
    if !checked.is_trustworthy() {
        return Ok(None);
    }
    let sum = |f: &Fusion, g: fn(&tricept_engine::fusion::SourceFit) -> f64| {
        f.sources.iter().map(g).sum::<f64>()
    };
    let delta_chi2 = (sum(fit, |s| s.chi_square) - sum(&checked, |s| s.chi_square)).max(0.0);
    let dof = sum(fit, |s| s.redundancy) - sum(&checked, |s| s.redundancy);
    if dof < 1.0 {
        return Ok(None);
    }
    let tips = |m: &Machine| -> Option<Vec<nalgebra::Vector3<f64>>> {
        options
            .eval_poses
            .iter()
            .map(|p| {
                let up = m.forward(&p.commands_mm).ok()?.up;
                Some(m.tool_forward(&up, p.head_rad).tip_mm)
            })
            .collect()
    };
    let (Some(with), Some(without)) = (
        tips(&model.machine_at(&fit.estimate)),
        tips(&model.machine_at(&checked.estimate)),
    ) else {
        return Ok(None);
    };
    let d: Vec<nalgebra::Vector3<f64>> = with.iter().zip(&without).map(|(a, b)| a - b).collect();
    let n = d.len().max(1) as f64;
    let mean = d.iter().sum::<nalgebra::Vector3<f64>>() / n;
    let shift_mm = (d.iter().map(|x| (x - mean).norm_squared()).sum::<f64>() / n).sqrt();
    // The tip's predicted variance after touch-off, the held parameters at
    // the size the data show of the head (`accuracy::head_scale`).
    let tip = |f: &Fusion| {
        let t = &f.report.tool_tip;
        let held = t.held_touch_off_rms_um * 1e-3;
        let seen = held * crate::accuracy::head_scale(model, f).scale;
        (t.touch_off_rms_um * 1e-3).powi(2) - held * held + seen * seen
    };
    Ok(Some(Unchecked {
        labels,
        others_fine,
        delta_chi2,
        dof,
        p_value: tricept_numerics::stats::chi2_sf(delta_chi2, dof),
        shift_mm,
        chance_mm2: (tip(&checked) - tip(fit)).max(0.0),
    }))
}

/// The sources: the internal data and every external file.
fn sources(w: &FusedWork, machine: &Machine) -> Result<Vec<Source>, Error> {
    let mut sources = vec![Source::internal(&w.data, machine.sensors.logged_sigma())];
    let (paths, tracker) = &w.tracker;
    sources.extend(external_sources(
        paths,
        "tracker",
        machine,
        |r: &TrackerPoint| (r.line, r.pose.commands_mm),
        |d| Source::tracker(d, tracker),
    )?);
    let (paths, ballbar) = &w.ballbar;
    sources.extend(external_sources(
        paths,
        "ballbar",
        machine,
        |r: &BallbarReading| (r.line, r.pose.commands_mm),
        |d| Source::ballbar(d, ballbar),
    )?);
    if let Some((paths, features, touch)) = &w.touch {
        sources.extend(external_sources(
            paths,
            "touch",
            machine,
            |r: &TouchReading| (r.line, r.pose.commands_mm),
            |d| Source::touch(d, features, touch),
        )?);
    }
    Ok(sources)
}

/// Reads the external files `paths` of one kind, checks their commands
/// against the leg stroke (`at` gives a record's line and commands) and
/// makes each a source labelled `kind`, `kind2`, ...
fn external_sources<T: ExternalRecord>(
    paths: &[PathBuf],
    kind: &str,
    machine: &Machine,
    at: impl Fn(&T) -> (u64, [f64; 3]),
    source: impl Fn(&ExternalData<T>) -> Result<Source, IdentError>,
) -> Result<Vec<Source>, Error> {
    paths
        .iter()
        .enumerate()
        .map(|(k, path)| {
            let d = tricept_data::external::read_external_path::<T>(path)?;
            check_commands(&d.source, d.records.iter().map(&at), machine)?;
            let label = if k == 0 {
                kind.to_string()
            } else {
                format!("{kind}{}", k + 1)
            };
            Ok(source(&d)?.with_label(label))
        })
        .collect()
}

impl FusedFit {
    /// 4 not converged, 3 converged but not to be trusted (a source not
    /// explained or not checkable, an implausible estimate), else 0.
    pub fn exit_code(&self) -> u8 {
        if !self.fit.converged {
            EXIT_NOT_CONVERGED
        } else if !self.trusted() {
            EXIT_INADEQUATE
        } else {
            EXIT_OK
        }
    }

    /// Whether the fit may be deployed: trustworthy, or only external
    /// sources that cannot be checked on their own stand in the way and
    /// they agree with the checked fit of the others ([`Unchecked`]).
    pub fn trusted(&self) -> bool {
        self.fit.is_trustworthy() || self.unchecked.as_ref().is_some_and(Unchecked::agrees)
    }

    /// The promise of the written file (`accuracy`), made once.
    pub fn accuracy(&self) -> &crate::accuracy::Accuracy {
        self.promise.get_or_init(|| self.promise())
    }

    fn promise(&self) -> crate::accuracy::Accuracy {
        crate::accuracy::of_fusion(
            &self.model,
            &self.fit,
            self.structure,
            self.unchecked
                .as_ref()
                .filter(|u| u.agrees())
                .map(Unchecked::part_mm),
        )
    }

    /// Why the fit must not be deployed, in one clause per reason.
    pub fn refusal_reason(&self) -> String {
        let fit = &self.fit;
        let mut why = Vec::new();
        if !fit.verdict.converged {
            why.push("the fused fit did not converge".to_string());
        }
        for s in fit.sources.iter().filter(|s| !s.checkable) {
            why.push(format!(
                "{} cannot be checked: at least {} more records make it checkable",
                s.label,
                s.more_records.unwrap_or(1)
            ));
        }
        if let Some(u) = self.unchecked.as_ref().filter(|u| !u.agrees()) {
            why.push(format!(
                "{} disagree with the checked fit of the other sources (added chi-square {:.1} for {:.1} degrees of freedom, p = {:.1e})",
                u.labels.join(", "),
                u.delta_chi2,
                u.dof,
                u.p_value
            ));
        }
        let unexplained: Vec<&str> = fit
            .sources
            .iter()
            .filter(|s| s.checkable && !s.explained())
            .map(|s| s.label.as_str())
            .collect();
        if !unexplained.is_empty() {
            why.push(format!(
                "the model does not explain {}",
                unexplained.join(", ")
            ));
        }
        if !fit.implausible.is_empty() {
            let names: Vec<&str> = fit.implausible.iter().map(|i| i.name.as_str()).collect();
            why.push(format!("implausible estimates: {}", names.join(", ")));
        }
        if why.is_empty() {
            "see the warnings".into()
        } else {
            format!("{} (see the warnings)", why.join("; "))
        }
    }

    /// Why the exit code is not 0, one phrase (`None` for 0).
    pub fn exit_reason(&self) -> Option<String> {
        match self.exit_code() {
            EXIT_NOT_CONVERGED => Some("the fused fit did not converge".to_string()),
            EXIT_INADEQUATE => Some(format!(
                "the fit completed but must not be trusted as it stands: {}",
                self.refusal_reason()
            )),
            _ => None,
        }
    }

    /// The parameters held at nominal (not seen by the data).
    fn held(&self) -> Vec<String> {
        self.fit
            .std_dev
            .iter()
            .zip(&self.fit.names)
            .filter(|(sd, _)| sd.is_none())
            .map(|(_, n)| n.clone())
            .collect()
    }

    /// The calibrated machine: the module explicit, the head's fields and
    /// angle offsets from the estimate, and the `calibration` record (with
    /// every external file, its hash and its fitted nuisance).
    pub fn description(
        &self,
        loaded: &LoadedMachine,
        data: &Path,
        forced: Option<String>,
    ) -> Result<MachineDescription, Error> {
        let fit = &self.fit;
        let external: Vec<(&Path, ExternalSourceRecord)> = self
            .sources
            .iter()
            .zip(&fit.sources)
            .filter(|(s, _)| s.kind() != SourceKind::Internal)
            .map(|(s, f)| {
                let nuisance = f
                    .nuisance_names
                    .iter()
                    .zip(f.nuisance.iter().zip(&f.nuisance_std_dev))
                    .map(|(n, (v, sd))| (n.clone(), json!({"value": v, "std_dev": sd})))
                    .collect();
                let record = ExternalSourceRecord {
                    kind: s.kind().as_str().to_string(),
                    file: s.file().to_string(),
                    sha256: String::new(),
                    records: f.records,
                    chi2_per_dof: f
                        .reduced_chi_square
                        .is_finite()
                        .then_some(f.reduced_chi_square),
                    redundancy: f.redundancy,
                    checkable: f.checkable,
                    rejected_lines: fit
                        .rejected
                        .iter()
                        .filter(|r| r.label == f.label)
                        .map(|r| r.line)
                        .collect(),
                    nuisance,
                };
                (Path::new(s.file()), record)
            })
            .collect();
        let mut d = machine_file::calibrated_description(
            loaded,
            &self.model.machine_at(&fit.estimate),
            &machine_file::FitRecord::of_fusion(fit),
            machine_file::Provenance {
                method: "identify (fused)",
                data_file: data,
                parameter_set: &format!("{} + head", self.set_label),
                rejected_lines: fit
                    .rejected
                    .iter()
                    .filter(|r| r.label == "internal")
                    .map(|r| r.line)
                    .collect(),
                adequate: self.trusted(),
                forced,
                warnings: fit.warnings.clone(),
                effects: serde_json::Map::new(),
                n_geometric: fit.names.len(),
                external,
                temperature_c: None,
                accuracy: Some(self.accuracy().record()),
            },
            None,
        )?;
        let files: Vec<&str> = self.sources.iter().map(|s| s.file()).collect();
        let held = self.held();
        d.notes = Some(format!(
            "{}; identified from {}; held at nominal (not seen by the data): {}",
            d.notes.unwrap_or_default(),
            files.join(", "),
            if held.is_empty() {
                "none".to_string()
            } else {
                held.join(", ")
            }
        ));
        Ok(d)
    }

    /// Records a written file (or a refused one) for the JSON.
    pub fn record_write(&self, path: &Path, written: bool) {
        let record = if written {
            json!({"written": path.display().to_string(), "held_at_nominal": self.held()})
        } else {
            json!({"written": Value::Null, "refused": path.display().to_string()})
        };
        match self.deployed.lock() {
            Ok(mut d) => *d = Some(record),
            Err(poisoned) => *poisoned.into_inner() = Some(record),
        }
    }

    /// The JSON of `identify --json` with external data.
    pub fn to_json(&self, loaded: &LoadedMachine, data_name: &str) -> Value {
        let mut v = self.fit.to_json(&self.model);
        if let Value::Object(o) = &mut v {
            o.insert("machine".into(), loaded.description().name.clone().into());
            o.insert("data_file".into(), data_name.into());
            o.insert("accuracy".into(), self.accuracy().to_json());
            if let Some(u) = &self.unchecked {
                o.insert("unchecked".into(), u.to_json());
            }
            let deployed = match self.deployed.lock() {
                Ok(d) => d.clone(),
                Err(poisoned) => poisoned.into_inner().clone(),
            };
            if let Some(d) = deployed {
                o.insert("deployed".into(), d);
            }
        }
        v
    }

    /// The text report.
    pub fn report(&self) -> String {
        let mut s = String::new();
        self.write_report(&mut s);
        s
    }

    fn write_report(&self, s: &mut String) {
        let (model, fit) = (&self.model, &self.fit);
        let list: Vec<String> = self
            .sources
            .iter()
            .map(|s| format!("{} {} ({} records)", s.label(), s.file(), s.records()))
            .collect();
        let _ = writeln!(s, "fused identification: {}", list.join(", "));
        let _ = writeln!(s, "{}", self.accuracy().line());
        if let Some(u) = &self.unchecked {
            let _ = writeln!(s, "{}", u.line());
        }
        for r in &fit.rejected {
            let _ = writeln!(s, "{}", r.to_text());
        }
        let effects: Vec<&str> = model.effects().iter().map(|e| e.as_str()).collect();
        let _ = writeln!(
            s,
            "model: {}{}{}; {} in {} Gauss-Newton iterations",
            model.module().label(),
            if effects.is_empty() {
                String::new()
            } else {
                format!(" + {}", effects.join(", "))
            },
            if model.head().is_some() {
                " + head13"
            } else {
                ""
            },
            if fit.converged {
                "converged"
            } else {
                "NOT converged"
            },
            fit.iterations
        );
        let _ = writeln!(s, "{:>34} {:>14} {:>12}", "parameter", "estimate", "sd");
        for ((n, v), sd) in fit.names.iter().zip(&fit.estimate).zip(&fit.std_dev) {
            let _ = match sd {
                Some(sd) => writeln!(s, "{n:>34} {v:>14.6e} {sd:>12.3e}"),
                None => writeln!(s, "{n:>34} {v:>14.6e} {:>12}", "held"),
            };
        }
        for src in &fit.sources {
            let check = if src.checkable {
                format!(
                    "chi2/dof {:.3} (p = {:.2e})",
                    src.reduced_chi_square, src.p_value
                )
            } else {
                format!(
                    "NOT checkable (needs {:.0}; at least {} more records)",
                    src.min_redundancy,
                    src.more_records.unwrap_or(1)
                )
            };
            let _ = writeln!(
                s,
                "{} ({}): {} records, redundancy {:.1}: {check}{}; largest {:.1} sigma at line {}",
                src.label,
                src.file,
                src.records,
                src.redundancy,
                src.rms_um
                    .map(|r| format!(", rms {r:.2} um"))
                    .unwrap_or_default(),
                src.max_standardised.0,
                src.max_standardised.1
            );
            for ((n, v), sd) in src
                .nuisance_names
                .iter()
                .zip(&src.nuisance)
                .zip(&src.nuisance_std_dev)
            {
                let _ = writeln!(s, "  {n:>32} {v:>14.6e} {sd:>12.3e}");
            }
        }
        s.push_str(&fit.report.to_text());
        let v = &fit.verdict;
        let _ = writeln!(
            s,
            "verdict: {}, {}, {}, {}",
            if v.converged {
                "converged"
            } else {
                "NOT converged"
            },
            if v.checkable {
                "every source checkable"
            } else {
                "NOT every source checkable"
            },
            if v.adequate {
                "adequate (the model explains every source to its stated noise)"
            } else {
                "NOT adequate"
            },
            if v.plausible {
                "every estimate plausible"
            } else {
                "implausible estimates"
            }
        );
        for w in &fit.warnings {
            let _ = writeln!(s, "WARNING: {w}");
        }
    }
}
