//! `tricept compensate`: corrected commands, the before/after error map and
//! the compensation table, from data (identified here) or from a calibrated
//! machine file (with the static leg effects a diagnosis wrote into it).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use nalgebra::Vector3;
use serde_json::{Map, Value, json};
use tricept_engine::{CompensationTable, ExtendedMachine};
use tricept_model::{ErrorMap, MapStats};

use crate::args::FitSettings;
use crate::args::{TruthArgs, load, parse_errors};
use crate::cli_error::{CliError, EXIT_INADEQUATE, EXIT_NOT_CONVERGED};
use crate::ident_cmd::{fit_from_file, rejected_json, report_exit};
use tricept_ident::parse_effects;

/// The largest interpolation error (um) the default table spacing allows.
pub const TABLE_ERROR_LIMIT_UM: f64 = 1.0;

/// The files `--map DIR` writes into DIR.
pub const MAP_FILES: &[&str] = &["map.csv", "correction.svg", "before.svg", "after.svg"];
/// The files `--table DIR` writes into DIR (the second only for a machine
/// with per-leg compensation tables).
pub const TABLE_FILES: &[&str] = &["table.csv", "leg-tables.csv"];

/// `tricept compensate`.
#[derive(Debug, Args)]
pub struct CompensateArgs {
    /// Measured-data CSV to identify from. Without it, --machine must be a
    /// calibrated machine file (`identify` or `diagnose --write-machine`),
    /// compensated against the nominal machine it records.
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    #[command(flatten)]
    pub settings: FitSettings,
    #[command(flatten)]
    pub truth: TruthArgs,
    /// Plane of the error map, z in mm (default: the workspace's middle
    /// plane); must lie within the workspace.
    #[arg(long, value_name = "Z_MM")]
    pub plane_z: Option<f64>,
    /// Lattice spacing of the error map on the plane, mm (at least 1).
    #[arg(long, default_value_t = 10.0, value_name = "MM")]
    pub spacing: f64,
    /// Target points (CSV x,y,z in mm): their corrected leg commands go to
    /// stdout as CSV (x,y,z,q1,q2,q3, mm), the report to stderr.
    #[arg(long, value_name = "FILE.csv")]
    pub targets: Option<PathBuf>,
    /// Write the per-point map on the plane: DIR/map.csv (predicted
    /// correction, and with --truth the error before and after, mm) and SVG
    /// heat maps (DIR/correction.svg, DIR/before.svg, DIR/after.svg).
    #[arg(long, value_name = "DIR")]
    pub map: Option<PathBuf>,
    /// Write the compensation table DIR/table.csv: leg-command corrections
    /// (mm) on a regular grid over the workspace, for trilinear lookup (see
    /// docs/data-format.md), with its measured interpolation error; and for
    /// a machine file with per-leg compensation tables (a pitch error, a
    /// curved or worn screw: `diagnose --write-machine`), those tables as
    /// DIR/leg-tables.csv (leg command to extra length, linear), which the
    /// controller applies on each leg axis after table.csv.
    #[arg(long, value_name = "DIR")]
    pub table: Option<PathBuf>,
    /// Grid spacing of the table, mm (default: the coarsest of 100, 50,
    /// 40, 25, 20, 10 mm whose measured interpolation error is below 1 um).
    #[arg(long, value_name = "MM")]
    pub table_spacing: Option<f64>,
    /// Compensate even from a fit that is not to be trusted (exit code 3
    /// or 4 of `identify`), or from a calibrated machine file that says it
    /// is not.
    #[arg(long)]
    pub force: bool,
}

/// The two machines of a compensation.
struct Pair {
    /// What the controller believes today.
    nominal: ExtendedMachine,
    /// The calibrated machine.
    calibrated: ExtendedMachine,
    /// Report lines about where they came from.
    out: Map<String, Value>,
    warnings: Vec<String>,
    code: u8,
    /// Why the code is not 0.
    why: String,
}

fn machines(a: &CompensateArgs) -> Result<Pair, CliError> {
    let mut out = Map::new();
    match &a.data {
        Some(data) => {
            let fit = fit_from_file(data, &a.settings)?;
            let code = fit.exit_code();
            crate::files::write_rule("compensate", code, fit.refusal().unwrap_or(""), a.force)?;
            out.insert("data_file".into(), data.display().to_string().into());
            out.insert("converged".into(), fit.verdict.converged.into());
            out.insert("adequate".into(), fit.verdict.adequate.into());
            out.insert("rejected".into(), rejected_json(&fit.rejected));
            Ok(Pair {
                nominal: ExtendedMachine::new(fit.loaded.machine().clone()),
                calibrated: ExtendedMachine::new(fit.identified()),
                out,
                warnings: fit.verdict.warnings.clone(),
                code,
                why: fit.reason(),
            })
        }
        None => {
            let loaded = load(&a.settings.machine)?;
            let Some(c) = &loaded.description().calibration else {
                return Err(CliError::input(format!(
                    "compensate: give --data FILE.csv to identify from, or a calibrated machine file as --machine ({} holds no `calibration` record)",
                    loaded.source()
                )));
            };
            let nominal = c
                .nominal
                .build()
                .map_err(|e| tricept_ident::description_error(loaded.source(), &e))?;
            let (code, why) = if !c.converged {
                (EXIT_NOT_CONVERGED, "its calibration did not converge")
            } else if c.forced || !c.adequate {
                (
                    EXIT_INADEQUATE,
                    "its calibration is not to be trusted (written with --force, or its model did not explain its data)",
                )
            } else {
                (0, "")
            };
            crate::files::write_rule(
                &format!("compensate --machine {}", loaded.source()),
                code,
                why,
                a.force,
            )?;
            out.insert("machine".into(), loaded.description().name.clone().into());
            out.insert("converged".into(), c.converged.into());
            out.insert("adequate".into(), c.adequate.into());
            Ok(Pair {
                nominal: ExtendedMachine::new(nominal),
                calibrated: ExtendedMachine::new(loaded.machine().clone()),
                out,
                warnings: Vec::new(),
                code,
                why: why.to_string(),
            })
        }
    }
}

fn stats_json(s: &MapStats) -> Value {
    json!({"max_mm": s.max_mm, "min_mm": s.min_mm, "mean_mm": s.mean_mm, "rms_mm": s.rms_mm})
}

fn map_error(e: impl std::fmt::Display) -> CliError {
    CliError::other(format!("compensation map: {e}"))
}

/// `tricept compensate`.
pub fn run_compensate(a: &CompensateArgs) -> Result<u8, CliError> {
    if !(a.spacing.is_finite() && a.spacing >= 1.0) {
        return Err(CliError::input(format!(
            "--spacing: the map's lattice spacing must be at least 1 mm, got {} mm",
            a.spacing
        )));
    }
    if let Some(h) = a.table_spacing
        && !(h.is_finite() && h >= 1.0)
    {
        return Err(CliError::input(format!(
            "--table-spacing: the table's grid spacing must be at least 1 mm, got {h} mm"
        )));
    }
    let Pair {
        nominal,
        calibrated,
        mut out,
        mut warnings,
        code,
        why,
    } = machines(a)?;
    let w = &nominal.machine().workspace;
    let z = a.plane_z.unwrap_or_else(|| w.mid_plane_z_mm());
    if !(z.is_finite() && z >= w.z_min_mm && z <= w.z_max_mm) {
        return Err(CliError::input(format!(
            "--plane-z: {z} mm is outside the workspace, whose z runs from {} to {} mm",
            w.z_min_mm, w.z_max_mm
        )));
    }
    let points = std::f64::consts::PI * (w.radius_mm / a.spacing + 1.0).powi(2);
    if points > tricept_ident::limits::MAX_MAP_POINTS as f64 {
        return Err(CliError::input(format!(
            "--spacing {} mm: about {points:.0} map points, more than {}; a coarser spacing is needed",
            a.spacing,
            tricept_ident::limits::MAX_MAP_POINTS
        )));
    }
    let grid = w.disc_grid(z, a.spacing);
    // What compensation changes, as the calibrated model sees it: nominal
    // commands, positions by the calibrated machine.
    let mut predicted = Vec::with_capacity(grid.len());
    for r in &grid {
        let ik = nominal.inverse(r).map_err(map_error)?;
        let p = calibrated
            .forward_from(&ik.legs_mm, &ik.up)
            .map_err(map_error)?;
        predicted.push(p.position_mm - r);
    }
    let predicted = ErrorMap {
        targets_mm: grid.clone(),
        errors_mm: predicted,
    };
    out.insert("plane_z_mm".into(), z.into());
    out.insert("grid_points".into(), grid.len().into());
    out.insert(
        "predicted_correction".into(),
        stats_json(&predicted.stats()),
    );
    let truth = truth_maps(a, &nominal, &calibrated, &grid)?;
    if let Some((before, after)) = &truth {
        let residual = after.without_mean_translation();
        let t = after.mean_translation_mm();
        out.insert("before".into(), stats_json(&before.stats()));
        out.insert("after".into(), stats_json(&after.stats()));
        out.insert(
            "after_without_translation".into(),
            stats_json(&residual.stats()),
        );
        out.insert("translation_mm".into(), json!([t.x, t.y, t.z]));
    }
    if let Some(dir) = &a.map {
        write_map(dir, &predicted, truth.as_ref(), a.spacing)?;
        out.insert("map".into(), dir.display().to_string().into());
    }
    if let Some(dir) = &a.table {
        // The per-leg compensation tables are exported as they are (the
        // controller's pitch-error compensation on each leg axis); the
        // workspace table carries the rest, which is smooth.
        let leg_tables = calibrated.machine().leg_effects.tables.clone();
        let calibrated = if leg_tables.is_empty() {
            calibrated.clone()
        } else {
            let mut m = calibrated.machine().clone();
            m.leg_effects.tables.clear();
            ExtendedMachine::new(m)
        };
        let (table, error_um) = match a.table_spacing {
            Some(h) => {
                let t = CompensationTable::build(&nominal, &calibrated, w, h)
                    .map_err(|e| CliError::input(format!("--table-spacing {h}: {e}")))?;
                let e = t
                    .interpolation_error_um(&nominal, &calibrated, w)
                    .map_err(map_error)?;
                (t, e)
            }
            None => {
                CompensationTable::with_error_below(&nominal, &calibrated, w, TABLE_ERROR_LIMIT_UM)
                    .map_err(map_error)?
            }
        };
        if error_um >= TABLE_ERROR_LIMIT_UM {
            warnings.push(format!(
                "the compensation table's interpolation error is {error_um:.3} um at {} mm spacing, above {TABLE_ERROR_LIMIT_UM} um: a finer --table-spacing reduces it",
                table.spacing_mm
            ));
        }
        let path = dir.join(TABLE_FILES[0]);
        write_table(&path, &table, error_um, &nominal, &calibrated)?;
        let mut entry = json!({
            "file": path.display().to_string(),
            "spacing_mm": table.spacing_mm,
            "counts": table.counts,
            "interpolation_error_um": error_um,
        });
        if !leg_tables.is_empty() {
            let legs = dir.join(TABLE_FILES[1]);
            write_leg_tables(&legs, &leg_tables, calibrated.machine())?;
            entry["leg_tables"] = legs.display().to_string().into();
        }
        out.insert("table".into(), entry);
    }
    out.insert("warnings".into(), warnings.clone().into());
    let targets = match &a.targets {
        Some(path) => Some(corrected_targets(path, &calibrated)?),
        None => None,
    };
    if a.settings.machine.json {
        if let Some(rows) = &targets {
            out.insert(
                "corrected_commands".into(),
                Value::Array(
                    rows.iter()
                        .map(|(r, q)| json!({"x": r.x, "y": r.y, "z": r.z, "q1": q[0], "q2": q[1], "q3": q[2]}))
                        .collect(),
                ),
            );
        }
        outln!("{}", Value::Object(out));
    } else {
        let report = text_report(&out, z, grid.len(), a.spacing, &warnings);
        match &targets {
            // The CSV owns stdout; the report goes to stderr.
            Some(rows) => {
                for line in report.lines() {
                    errln!("{line}");
                }
                let mut w = std::io::BufWriter::new(crate::output::Stdout);
                let _ = writeln!(w, "x,y,z,q1,q2,q3");
                for (r, q) in rows {
                    let _ = writeln!(w, "{},{},{},{},{},{}", r.x, r.y, r.z, q[0], q[1], q[2]);
                }
                let _ = w.flush();
            }
            None => crate::output::write_text(&report),
        }
    }
    report_exit("compensate", code, &why);
    Ok(code)
}

/// Before/after maps of the simulated true machine (`--truth`).
fn truth_maps(
    a: &CompensateArgs,
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
    grid: &[Vector3<f64>],
) -> Result<Option<(ErrorMap, ErrorMap)>, CliError> {
    let Some(spec) = &a.truth.truth else {
        if !a.truth.truth_effects.is_empty() {
            return Err(CliError::input(
                "--truth-effect: needs --truth (the true errors of the simulated machine)",
            ));
        }
        return Ok(None);
    };
    let set = a.settings.params.set()?;
    let mut plant = tricept_plant::Plant::geometric(
        nominal.machine().clone(),
        set.to_errors(&parse_errors(spec, &set)?),
    );
    plant.effects = parse_effects(&a.truth.truth_effects)?;
    // Where the true machine goes when commanded by a machine's IK.
    let map = |commanding: &ExtendedMachine| -> Result<ErrorMap, CliError> {
        let mut errors = Vec::with_capacity(grid.len());
        for r in grid {
            let q = commanding.inverse(r).map_err(map_error)?.legs_mm;
            errors.push(plant.reach(&q).map_err(map_error)? - r);
        }
        Ok(ErrorMap {
            targets_mm: grid.to_vec(),
            errors_mm: errors,
        })
    };
    Ok(Some((map(nominal)?, map(calibrated)?)))
}

/// A target (mm) and its corrected leg commands (mm).
type CorrectedTarget = (Vector3<f64>, [f64; 3]);

fn corrected_targets(
    path: &Path,
    calibrated: &ExtendedMachine,
) -> Result<Vec<CorrectedTarget>, CliError> {
    let points = tricept_data::read_targets(path).map_err(|e| CliError::input(e.to_string()))?;
    let mut rows = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        let r = Vector3::from(*p);
        let q = calibrated.inverse(&r).map_err(|e| {
            CliError::input(format!(
                "{}: target {} ({}, {}, {} mm): {e}",
                path.display(),
                k + 1,
                r.x,
                r.y,
                r.z
            ))
        })?;
        rows.push((r, q.legs_mm));
    }
    Ok(rows)
}

fn text_report(
    out: &Map<String, Value>,
    z: f64,
    points: usize,
    spacing: f64,
    warnings: &[String],
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "compensation over the plane z = {z} mm ({points} points, {spacing} mm lattice)"
    );
    for key in [
        "predicted_correction",
        "before",
        "after",
        "after_without_translation",
    ] {
        if let Some(v) = out.get(key) {
            let _ = writeln!(
                s,
                "{key:>26}: max {:.4} / min {:.4} / mean {:.4} mm",
                v["max_mm"].as_f64().unwrap_or(f64::NAN),
                v["min_mm"].as_f64().unwrap_or(f64::NAN),
                v["mean_mm"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
    if let Some(Value::Array(t)) = out.get("translation_mm") {
        let t: Vec<f64> = t.iter().filter_map(Value::as_f64).collect();
        if let [x, y, zt] = t[..] {
            let _ = writeln!(
                s,
                "{:>26}: ({x:.4}, {y:.4}, {zt:.4}) mm",
                "rigid translation"
            );
        }
    }
    if let Some(m) = out.get("map").and_then(Value::as_str) {
        let _ = writeln!(s, "{:>26}: {m}/map.csv and SVG heat maps", "per-point map");
    }
    if let Some(t) = out.get("table") {
        let _ = writeln!(
            s,
            "{:>26}: {} ({} mm grid, {} nodes along x, y, z); trilinear interpolation error {:.3} um (largest over a lattice 4 times finer)",
            "compensation table",
            t["file"].as_str().unwrap_or(""),
            t["spacing_mm"],
            t["counts"],
            t["interpolation_error_um"].as_f64().unwrap_or(f64::NAN)
        );
    }
    for w in warnings {
        let _ = writeln!(s, "WARNING: {w}");
    }
    s
}

fn write_map(
    dir: &Path,
    predicted: &ErrorMap,
    truth: Option<&(ErrorMap, ErrorMap)>,
    spacing: f64,
) -> Result<(), CliError> {
    crate::files::create_dir(dir)?;
    let mut csv = String::new();
    let _ = writeln!(
        csv,
        "# tricept compensate: per-point map on a plane, mm; correction = where the calibrated model says the nominal commands put the platform, minus the target"
    );
    if truth.is_some() {
        let _ = writeln!(
            csv,
            "# before/after = where the simulated true machine goes when commanded by the nominal / calibrated IK, minus the target"
        );
    }
    let mut header = "x,y,z,correction_dx,correction_dy,correction_dz,correction_mm".to_string();
    if truth.is_some() {
        header.push_str(
            ",before_dx,before_dy,before_dz,before_mm,after_dx,after_dy,after_dz,after_mm",
        );
    }
    let _ = writeln!(csv, "{header}");
    for (i, r) in predicted.targets_mm.iter().enumerate() {
        let c = predicted.errors_mm[i];
        let _ = write!(
            csv,
            "{},{},{},{},{},{},{}",
            r.x,
            r.y,
            r.z,
            c.x,
            c.y,
            c.z,
            c.norm()
        );
        if let Some((b, a)) = truth {
            let (b, a) = (b.errors_mm[i], a.errors_mm[i]);
            let _ = write!(
                csv,
                ",{},{},{},{},{},{},{},{}",
                b.x,
                b.y,
                b.z,
                b.norm(),
                a.x,
                a.y,
                a.z,
                a.norm()
            );
        }
        csv.push('\n');
    }
    crate::files::write_text(&dir.join(MAP_FILES[0]), &csv)?;
    let cells = |m: &ErrorMap| -> Vec<tricept_plot::Cell> {
        m.targets_mm
            .iter()
            .zip(&m.errors_mm)
            .map(|(r, e)| tricept_plot::Cell {
                x: r.x,
                y: r.y,
                value: e.norm(),
            })
            .collect()
    };
    // Each map on its own colour scale (its min..max): an after map is often
    // ten times smaller than the before map and flat on the before's scale.
    let plot = |name: &str, what: &str, m: &ErrorMap| {
        let z = tricept_plot::plane_z(m.targets_mm.iter().map(|r| r.z));
        let title = format!("{what} |dr| (mm), {z}");
        let path = dir.join(name);
        let drawn = tricept_plot::heat_map(&path, &title, &cells(m), spacing, "|dr| (mm)", None);
        crate::files::plotted(&path, drawn)
    };
    plot("correction.svg", "Predicted correction", predicted)?;
    if let Some((b, a)) = truth {
        plot("before.svg", "Error before compensation", b)?;
        plot("after.svg", "Error after compensation", a)?;
    }
    Ok(())
}

fn write_table(
    path: &Path,
    t: &CompensationTable,
    error_um: f64,
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
) -> Result<(), CliError> {
    if let Some(dir) = path.parent() {
        crate::files::create_dir(dir)?;
    }
    let o = t.origin_mm;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# tricept {} compensation table: leg-command corrections dq = q_calibrated - q_nominal (mm) on a regular grid",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(s, "# calibrated machine: {}", calibrated.machine().name);
    let _ = writeln!(s, "# nominal machine: {}", nominal.machine().name);
    let _ = writeln!(
        s,
        "# grid: origin_mm {} {} {}, spacing_mm {}, counts {} {} {}; node (i,j,k) at origin + spacing (i,j,k), i fastest",
        o.x, o.y, o.z, t.spacing_mm, t.counts[0], t.counts[1], t.counts[2]
    );
    let _ = writeln!(
        s,
        "# lookup: command = nominal IK + trilinear interpolation of dq at the eight corners of the cell holding the target"
    );
    let _ = writeln!(
        s,
        "# interpolation_error_um {error_um:.6} (largest difference from the exact correction on the lattice of spacing {} mm inside the workspace)",
        t.spacing_mm / 4.0
    );
    let _ = writeln!(
        s,
        "# nodes the machine cannot reach are left out; every cell that meets the workspace has its eight corners"
    );
    let _ = writeln!(s, "i,j,k,x,y,z,dq1,dq2,dq3");
    for k in 0..t.counts[2] {
        for j in 0..t.counts[1] {
            for i in 0..t.counts[0] {
                let idx = i + t.counts[0] * (j + t.counts[1] * k);
                if let Some(dq) = t.nodes[idx] {
                    let r = o + Vector3::new(i as f64, j as f64, k as f64) * t.spacing_mm;
                    let _ = writeln!(
                        s,
                        "{i},{j},{k},{},{},{},{},{},{}",
                        r.x, r.y, r.z, dq[0], dq[1], dq[2]
                    );
                }
            }
        }
    }
    crate::files::write_text(path, &s)
}

/// Writes the per-leg compensation tables of `machine` as CSV: one row per
/// point (`leg,command_mm,extra_length_um`), each table's range, spacing,
/// interpolation and source in the header.
fn write_leg_tables(
    path: &Path,
    tables: &[tricept_kinematics::description::LegTableDescription],
    machine: &tricept_kinematics::Machine,
) -> Result<(), CliError> {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# tricept {} per-leg compensation tables of {}: the extra length of each leg (um) at equally spaced leg commands (mm)",
        env!("CARGO_PKG_VERSION"),
        machine.name
    );
    let _ = writeln!(
        s,
        "# interpolation: linear between the points, the end values beyond them; applied on each leg axis after table.csv: the command q with q + extra(q) = the table's command (to first order q = command - extra(command), the form of a CNC controller's pitch-error compensation)"
    );
    for t in tables {
        let _ = writeln!(
            s,
            "# leg {}: from {} mm every {} mm, {} points; {}",
            t.leg,
            t.start_mm,
            t.step_mm,
            t.extra_length_um.len(),
            t.source
        );
    }
    let _ = writeln!(s, "leg,command_mm,extra_length_um");
    for t in tables {
        for (k, v) in t.extra_length_um.iter().enumerate() {
            let _ = writeln!(s, "{},{},{v}", t.leg, t.start_mm + t.step_mm * k as f64);
        }
    }
    crate::files::write_text(path, &s)
}
