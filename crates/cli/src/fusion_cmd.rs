//! `tricept identify` with external measurements: the fused identification
//! of the module, the head and every instrument's nuisance
//! (`tricept_engine::fusion`). `identify` dispatches here when a tracker,
//! ballbar or touch file, a head option or an effect is given; without them
//! it runs the internal-only path unchanged.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use tricept_data::{
    BallbarReading, ExternalData, ExternalRecord, Features, TouchReading, TrackerPoint,
};
use tricept_engine::IdentError;
use tricept_engine::fusion::{
    BallbarOptions, FusedModel, Fusion, FusionOptions, FusionPlausibility, Source, SourceKind,
    TouchOptions, TrackerOptions, TrackerTarget, evaluation_poses, identify_fused,
};
use tricept_kinematics::description::ExternalSourceRecord;
use tricept_model::effects::EffectName;

use crate::args::{IdentifyArgs, load_with_noise, parse_head_angles, read_data};
use crate::cli_error::{CliError, EXIT_NOT_CONVERGED};
use tricept_ident::limits;
use tricept_ident::machine_file;
use tricept_ident::{check_commands, parse_numbers, positive};

/// Exit code of a fit that converged but that the user must not trust as
/// it stands: a source the model does not explain (`identify`'s 3).
pub const EXIT_UNTRUSTED: u8 = crate::cli_error::EXIT_INADEQUATE;

/// The effects named by `--effects`.
pub fn parse_effect_names(names: &[String]) -> Result<Vec<EffectName>, CliError> {
    names
        .iter()
        .filter(|n| !n.is_empty())
        .map(|n| {
            n.parse::<EffectName>()
                .map_err(|e| CliError::input(format!("--effects: {e}")))
        })
        .collect()
}

/// An identification error as the CLI reports it.
pub fn fusion_error(e: IdentError) -> CliError {
    match e {
        IdentError::Source { .. } | IdentError::NuisanceUnidentifiable { .. } => {
            CliError::input(e.to_string())
        }
        IdentError::Invalid(m) => CliError::input(m),
        e => CliError::other(e.to_string()),
    }
}

fn data_error(e: tricept_data::DataError) -> CliError {
    CliError::input(e.to_string())
}

/// `--tracker-target` as a target statement, with the standard deviation
/// of a known offset; an input error when it is not given (there is no
/// default: following `plan` or not, the statement changes what is
/// calibrated).
pub fn tracker_target(text: Option<&str>, sigma_um: f64) -> Result<TrackerTarget, CliError> {
    let Some(text) = text else {
        return Err(CliError::input(
            "--tracker-target is required with a tracker: state where its target sits: `tip` (in a nest at the tool tip), `X,Y,Z` (a known offset from the tip, mm, spindle frame at zero head angles) or `free` (unknown: the tool tip is then not calibrated)",
        ));
    };
    Ok(match text {
        "free" => TrackerTarget::Free,
        "tip" => TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: positive("--tracker-target-sigma-um", sigma_um)?,
        },
        text => {
            let v = parse_numbers("--tracker-target", text, 3).map_err(|_| {
                CliError::input(format!(
                    "--tracker-target: expected `tip`, `free` or X,Y,Z in mm, got `{text}`"
                ))
            })?;
            TrackerTarget::Known {
                offset_mm: [v[0], v[1], v[2]],
                sigma_um: positive("--tracker-target-sigma-um", sigma_um)?,
            }
        }
    })
}

/// The sources of `a`: the internal data and every external file.
fn sources(
    a: &IdentifyArgs,
    machine: &tricept_kinematics::Machine,
) -> Result<Vec<Source>, CliError> {
    let x = &a.external;
    let data = read_data(a.data.as_path(), machine)?;
    let mut sources = vec![Source::internal(&data, machine.sensors.logged_sigma())];
    let target = if x.tracker.is_empty() {
        TrackerTarget::Free
    } else {
        tracker_target(x.tracker_target.as_deref(), x.tracker_target_sigma_um)?
    };
    let tracker = TrackerOptions {
        sigma_um: positive("--tracker-sigma-um", x.tracker_sigma_um)?,
        target,
    };
    sources.extend(external_sources(
        &x.tracker,
        "tracker",
        machine,
        |r: &TrackerPoint| (r.line, r.pose.commands_mm),
        |d| Source::tracker(d, &tracker),
    )?);
    let length_sigma_um = match x.ballbar_length_sigma_um.as_str() {
        "free" => None,
        text => Some(positive(
            "--ballbar-length-sigma-um",
            text.parse().map_err(|_| {
                CliError::input(format!(
                    "--ballbar-length-sigma-um: expected a number of um or `free`, got `{text}`"
                ))
            })?,
        )?),
    };
    let ball = match &x.ballbar_ball_mm {
        Some(t) => {
            let v = parse_numbers("--ballbar-ball-mm", t, 3)?;
            if let Some(x) = v.iter().find(|x| x.abs() > limits::MAX_TOOL_OFFSET_MM) {
                return Err(CliError::input(format!(
                    "--ballbar-ball-mm: {x} mm is beyond ±{} mm from the tool tip",
                    limits::MAX_TOOL_OFFSET_MM
                )));
            }
            [v[0], v[1], v[2]]
        }
        None => [0.0; 3],
    };
    let ballbar = BallbarOptions {
        sigma_um: positive("--ballbar-sigma-um", x.ballbar_sigma_um)?,
        length_sigma_um,
        ball_offset_mm: ball,
    };
    sources.extend(external_sources(
        &x.ballbar,
        "ballbar",
        machine,
        |r: &BallbarReading| (r.line, r.pose.commands_mm),
        |d| Source::ballbar(d, &ballbar),
    )?);
    if !x.touch.is_empty() {
        let Some(features) = &x.features else {
            return Err(CliError::input(
                "--touch needs --features FILE.json (the spheres and planes touched)",
            ));
        };
        let features = Features::from_path(features).map_err(data_error)?;
        let touch = TouchOptions {
            sigma_um: positive("--touch-sigma-um", x.touch_sigma_um)?,
        };
        sources.extend(external_sources(
            &x.touch,
            "touch",
            machine,
            |r: &TouchReading| (r.line, r.pose.commands_mm),
            |d| Source::touch(d, &features, &touch),
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
    machine: &tricept_kinematics::Machine,
    at: impl Fn(&T) -> (u64, [f64; 3]),
    source: impl Fn(&ExternalData<T>) -> Result<Source, IdentError>,
) -> Result<Vec<Source>, CliError> {
    paths
        .iter()
        .enumerate()
        .map(|(k, path)| {
            let d = tricept_data::read_external_path::<T>(path).map_err(data_error)?;
            check_commands(&d.source, d.records.iter().map(&at), machine)?;
            let label = if k == 0 {
                kind.to_string()
            } else {
                format!("{kind}{}", k + 1)
            };
            Ok(source(&d).map_err(fusion_error)?.with_label(label))
        })
        .collect()
}

/// The fused model of `a`.
pub fn fused_model(
    machine: &tricept_kinematics::Machine,
    params: &tricept_model::ParameterSet,
    effects: &[String],
    head: Option<&str>,
) -> Result<FusedModel, CliError> {
    let head = match head.unwrap_or("head13") {
        "head13" => true,
        "none" => false,
        other => {
            return Err(CliError::input(format!(
                "--head: expected head13 or none, got `{other}`"
            )));
        }
    };
    FusedModel::new(
        machine.clone(),
        params.clone(),
        &parse_effect_names(effects)?,
        head,
    )
    .map_err(fusion_error)
}

/// The evaluation poses of `--eval-grid` and `--eval-head-angles-deg`.
pub fn eval_options(
    machine: &tricept_kinematics::Machine,
    grid: &str,
    angles: &str,
) -> Result<FusionOptions, CliError> {
    let g = parse_numbers("--eval-grid", grid, 3)?;
    if g.iter().any(|v| *v < 0.0 || v.fract() != 0.0) || g[2] < 1.0 {
        return Err(CliError::input(format!(
            "--eval-grid: expected whole numbers RINGS,PER_RING,LEVELS, got `{grid}`"
        )));
    }
    let (h1, h2) = parse_head_angles("--eval-head-angles-deg", angles)?;
    let poses = (g[0] * g[1] + 1.0) * g[2] * (h1.len() * h2.len()) as f64;
    if poses > limits::MAX_EVAL_POSES as f64 {
        return Err(CliError::input(format!(
            "--eval-grid {grid} with --eval-head-angles-deg {angles}: {poses} evaluation poses; at most {}",
            limits::MAX_EVAL_POSES
        )));
    }
    let mut options = FusionOptions::for_machine(machine);
    options.eval_poses = evaluation_poses(
        machine,
        (g[0] as usize, g[1] as usize, g[2] as usize),
        &h1,
        &h2,
    );
    if options.eval_poses.is_empty() {
        return Err(CliError::input("--eval-grid: no reachable evaluation pose"));
    }
    Ok(options)
}

/// `tricept identify` with external data.
pub fn run(a: &IdentifyArgs) -> Result<u8, CliError> {
    let loaded = load_with_noise(&a.settings.machine, &a.settings.noise)?;
    let machine = loaded.machine().clone();
    let set = a.settings.params.set()?;
    let x = &a.external;
    if x.tracker.is_empty() && x.tracker_target.is_some() {
        return Err(CliError::input(
            "--tracker-target: there is no --tracker file to state the target of",
        ));
    }
    let mut model = fused_model(&machine, &set, &x.effects, x.head.as_deref())?;
    if a.write_machine.is_some() && !model.effects().is_empty() {
        let names: Vec<&str> = model.effects().iter().map(|e| e.as_str()).collect();
        return Err(CliError::input(format!(
            "--write-machine: {} fitted, but the machine format cannot carry {}; write a geometric fit (without --effects) or compensate with the fused model",
            names.join(", "),
            if names.len() == 1 { "it" } else { "them" }
        )));
    }
    // A calibrated machine: the rank decision of its nominal machine, as in
    // `identify` (docs/identifiability.md).
    if let Some(reference) = loaded.rank_reference()? {
        model = model.with_rank_reference(reference).map_err(fusion_error)?;
    }
    let mut options = eval_options(&machine, &x.eval_grid, &x.eval_head_angles_deg)?;
    if a.settings.fit.no_robust {
        options.screen = None;
    }
    if let Some(path) = &x.plausibility {
        let text = tricept_data::read_json_text(path)
            .map_err(|e| CliError::input(format!("--plausibility {}: {e}", path.display())))?;
        options.plausibility = FusionPlausibility::with_overrides(&text)
            .map_err(|e| CliError::input(format!("--plausibility {}: {e}", path.display())))?;
    }
    options.tool_axis_arcsec = positive("--tool-axis-warn-arcsec", x.tool_axis_warn_arcsec)?;
    let sources = sources(a, &machine)?;
    let fit = identify_fused(&model, &sources, &options).map_err(fusion_error)?;
    // The exit codes of `identify`: 4 not converged, 3 converged but not to
    // be trusted (a source not explained or not checkable, an implausible
    // estimate).
    let code = if !fit.converged {
        EXIT_NOT_CONVERGED
    } else if !fit.is_trustworthy() {
        EXIT_UNTRUSTED
    } else {
        0
    };
    let refused = a.write_machine.as_ref().filter(|_| code != 0 && !a.force);
    let deployed = match (&a.write_machine, refused) {
        (Some(path), None) => Some(write_machine(a, path, &model, &fit, &sources, code)?),
        (Some(path), Some(_)) => {
            Some(json!({"written": Value::Null, "refused": path.display().to_string()}))
        }
        (None, _) => None,
    };
    if a.settings.machine.json {
        let mut v = fit.to_json(&model);
        if let Value::Object(o) = &mut v {
            o.insert("machine".into(), loaded.description().name.clone().into());
            o.insert("data_file".into(), a.data.display().to_string().into());
            if let Some(d) = &deployed {
                o.insert("deployed".into(), d.clone());
            }
        }
        outln!("{v}");
    } else {
        print_text(&model, &fit, &sources);
    }
    for w in &fit.warnings {
        errln!("warning: {w}");
    }
    if let Some(path) = refused {
        return Err(CliError::new(
            tricept_ident::ErrorKind::of_exit_code(code),
            format!(
                "--write-machine {}: not written: {}; --force writes it anyway, marked as forced",
                path.display(),
                refusal_reason(&fit)
            ),
        ));
    }
    match code {
        EXIT_NOT_CONVERGED => {
            errln!("identify: exit {code}: the fused fit did not converge");
        }
        EXIT_UNTRUSTED => errln!(
            "identify: exit {code}: the fit completed but must not be trusted as it stands: {}",
            refusal_reason(&fit)
        ),
        _ => {}
    }
    Ok(code)
}

/// Why a fused fit must not be deployed, in one clause per reason.
fn refusal_reason(fit: &Fusion) -> String {
    let v = &fit.verdict;
    let mut why = Vec::new();
    if !v.converged {
        why.push("the fused fit did not converge".to_string());
    }
    for s in fit.sources.iter().filter(|s| !s.checkable) {
        why.push(format!(
            "{} cannot be checked: at least {} more records make it checkable",
            s.label,
            s.more_records.unwrap_or(1)
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

fn print_text(model: &FusedModel, fit: &Fusion, sources: &[Source]) {
    let list: Vec<String> = sources
        .iter()
        .map(|s| format!("{} {} ({} records)", s.label(), s.file(), s.records()))
        .collect();
    outln!("fused identification: {}", list.join(", "));
    for r in &fit.rejected {
        outln!("{}", r.to_text());
    }
    let effects: Vec<&str> = model.effects().iter().map(|e| e.as_str()).collect();
    outln!(
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
    outln!("{:>34} {:>14} {:>12}", "parameter", "estimate", "sd");
    for ((n, v), sd) in fit.names.iter().zip(&fit.estimate).zip(&fit.std_dev) {
        match sd {
            Some(s) => outln!("{n:>34} {v:>14.6e} {s:>12.3e}"),
            None => outln!("{n:>34} {v:>14.6e} {:>12}", "held"),
        }
    }
    for s in &fit.sources {
        let check = if s.checkable {
            format!(
                "chi2/dof {:.3} (p = {:.2e})",
                s.reduced_chi_square, s.p_value
            )
        } else {
            format!(
                "NOT checkable (needs {:.0}; at least {} more records)",
                s.min_redundancy,
                s.more_records.unwrap_or(1)
            )
        };
        outln!(
            "{} ({}): {} records, redundancy {:.1}: {check}{}; largest {:.1} sigma at line {}",
            s.label,
            s.file,
            s.records,
            s.redundancy,
            s.rms_um
                .map(|r| format!(", rms {r:.2} um"))
                .unwrap_or_default(),
            s.max_standardised.0,
            s.max_standardised.1
        );
        for ((n, v), sd) in s
            .nuisance_names
            .iter()
            .zip(&s.nuisance)
            .zip(&s.nuisance_std_dev)
        {
            outln!("  {n:>32} {v:>14.6e} {sd:>12.3e}");
        }
    }
    crate::output::write_text(&fit.report.to_text());
    let v = &fit.verdict;
    outln!(
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
        outln!("WARNING: {w}");
    }
}

/// Writes the calibrated machine: the module explicit, the head's fields
/// and angle offsets from the estimate, and the `calibration` record (as
/// `identify` writes it, with every external file, its hash and its
/// fitted nuisance); the caller refuses fitted effects, which the geometric
/// machine format cannot carry, and a fit with a non-zero exit `code`
/// unless `--force` (then it is marked forced).
fn write_machine(
    a: &IdentifyArgs,
    path: &Path,
    model: &FusedModel,
    fit: &Fusion,
    sources: &[Source],
    code: u8,
) -> Result<Value, CliError> {
    // The caller refused a non-zero code without --force; with it the
    // file says it was forced (the one rule of `machine_file::write_rule`).
    let forced = crate::files::write_rule(
        &format!("--write-machine {}", path.display()),
        code,
        &refusal_reason(fit),
        a.force,
    )?;
    let held: Vec<String> = fit
        .std_dev
        .iter()
        .zip(&fit.names)
        .filter(|(sd, _)| sd.is_none())
        .map(|(_, n)| n.clone())
        .collect();
    let loaded = load_with_noise(&a.settings.machine, &a.settings.noise)?;
    let external: Vec<(&Path, ExternalSourceRecord)> = sources
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
        &loaded,
        &model.machine_at(&fit.estimate),
        &machine_file::FitRecord::of_fusion(fit),
        machine_file::Provenance {
            method: "identify (fused)",
            data_file: a.data.as_path(),
            parameter_set: &format!("{} + head", a.settings.params.set()?.label()),
            rejected_lines: fit
                .rejected
                .iter()
                .filter(|r| r.label == "internal")
                .map(|r| r.line)
                .collect(),
            adequate: fit.is_trustworthy(),
            forced,
            warnings: fit.warnings.clone(),
            effects: serde_json::Map::new(),
            n_geometric: fit.names.len(),
            external,
            temperature_c: None,
        },
        None,
    )?;
    let files: Vec<&str> = sources.iter().map(|s| s.file()).collect();
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
    crate::files::write_machine(path, &d)?;
    Ok(json!({"written": path.display().to_string(), "held_at_nominal": held}))
}
