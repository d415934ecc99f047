//! `tricept compensate`: flags in, one call of the door
//! (`tricept_ident::compensate`), the report, the corrected commands, the
//! map and the table out (the heat maps drawn here, by `tricept_plot`).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use tricept_ident::compensate::{
    Calibrated, CompensateRequest, Compensation, ErrorMap, compensate,
};

use crate::args::{FitSettings, NoiseArgs, TruthArgs};
use crate::cli_error::CliError;

pub use tricept_ident::compensate::{MAP_FILES, TABLE_FILES};

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

/// `tricept compensate`.
pub fn run_compensate(a: &CompensateArgs) -> Result<u8, CliError> {
    let calibrated = match &a.data {
        Some(data) => Calibrated::Data(Box::new(a.settings.request(data))),
        None => Calibrated::MachineFile(a.settings.machine.input(&NoiseArgs::default())),
    };
    let mut request = CompensateRequest::new(calibrated);
    request.force = a.force;
    request.truth = a.truth.truth.clone();
    request.truth_effects = a.truth.effects();
    request.parameter_set = a.settings.params.params.clone();
    request.plane_z_mm = a.plane_z;
    request.spacing_mm = a.spacing;
    request.targets = a.targets.clone();
    request.map_dir = a.map.clone();
    request.table_dir = a.table.clone();
    request.table_spacing_mm = a.table_spacing;
    let c = compensate(request)?;
    crate::output::warn_all(c.machine_warnings());
    if let Some(dir) = &a.map {
        write_map(dir, &c)?;
    }
    for path in c.write_tables()? {
        errln!("wrote {}", path.display());
    }
    if a.settings.machine.json {
        crate::output::write_json(c.to_json());
    } else {
        let report = c.report();
        match c.corrected_targets() {
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
    if let Some(why) = c.reason() {
        errln!("compensate: exit {}: {why}", c.exit_code());
    }
    Ok(c.exit_code())
}

/// Writes the map's CSV and its heat maps into `dir`.
fn write_map(dir: &Path, c: &Compensation) -> Result<(), CliError> {
    crate::files::create_dir(dir)?;
    crate::files::write_text(&dir.join(MAP_FILES[0]), &c.map_csv())?;
    let (predicted, truth) = c.maps();
    let cells = |m: &ErrorMap| -> Vec<tricept_ident::advanced::plot::Cell> {
        m.targets_mm
            .iter()
            .zip(&m.errors_mm)
            .map(|(r, e)| tricept_ident::advanced::plot::Cell {
                x: r.x,
                y: r.y,
                value: e.norm(),
            })
            .collect()
    };
    // Each map on its own colour scale (its min..max): an after map is often
    // ten times smaller than the before map and flat on the before's scale.
    let plot = |name: &str, what: &str, m: &ErrorMap| {
        let z = tricept_ident::advanced::plot::plane_z(m.targets_mm.iter().map(|r| r.z));
        let title = format!("{what} |dr| (mm), {z}");
        let path = dir.join(name);
        let drawn = tricept_ident::advanced::plot::heat_map(
            &path,
            &title,
            &cells(m),
            c.spacing_mm(),
            "|dr| (mm)",
            None,
        );
        crate::files::plotted(&path, drawn)
    };
    plot("correction.svg", "Predicted correction", predicted)?;
    if let Some((b, a)) = truth {
        plot("before.svg", "Error before compensation", b)?;
        plot("after.svg", "Error after compensation", a)?;
    }
    Ok(())
}
