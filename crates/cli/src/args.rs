//! Arguments and loaders shared by several verbs: the machine and its
//! sensor noise, the parameter set, pose sets, measured data, true errors
//! and effects of simulated machines, the settings of `identify` (its fit,
//! its external measurements and head) that `compensate` and the fused
//! path share, number lists, progress display.

use std::path::{Path, PathBuf};

use clap::Args;
use nalgebra::Vector3;
use tricept_data::Dataset;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{
    KinematicsError, MAX_POSES, Machine, MachineDescription, PoseSet, PoseSetError,
};
use tricept_model::ParameterSet;
use tricept_plant::Effect;

use crate::cli_error::CliError;
use crate::limits;

/// Options shared by every verb that works on a machine.
#[derive(Debug, Args, Clone)]
pub struct MachineArgs {
    /// Machine description (JSON; a calibrated machine file too); default:
    /// the paper's Table 1 machine.
    #[arg(long, value_name = "FILE.json")]
    pub machine: Option<PathBuf>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Sensor-noise overrides (default: the machine description's).
#[derive(Debug, Args, Clone, Default)]
pub struct NoiseArgs {
    /// Encoder noise of one reading (standard deviation), arcsec.
    #[arg(long, value_name = "ARCSEC")]
    pub angle_noise_arcsec: Option<f64>,
    /// Linear-scale noise of one reading (standard deviation), um.
    #[arg(long, value_name = "UM")]
    pub length_noise_um: Option<f64>,
    /// Readings averaged into one logged value (a count).
    #[arg(long, value_name = "N")]
    pub readings_per_pose: Option<u32>,
}

/// The parameter set to identify.
#[derive(Debug, Args, Clone)]
pub struct ParamArgs {
    /// Parameter set: `paper15` (the paper's 15, under its frame
    /// conventions) or `full21` (all joint and length errors; reports the
    /// rigid-body gauges as unidentifiable).
    #[arg(long, default_value = "paper15", value_name = "SET")]
    pub params: String,
}

impl ParamArgs {
    /// The parameter set named by `--params`.
    pub fn set(&self) -> Result<ParameterSet, CliError> {
        ParameterSet::by_label(&self.params).map_err(|e| CliError::input(format!("--params: {e}")))
    }
}

/// The true machine behind simulated data: `simulate` simulates it,
/// `compensate` measures the compensation on it.
#[derive(Debug, Args, Clone, Default)]
pub struct TruthArgs {
    /// True geometric errors of the simulated machine: `table2`, `zero`,
    /// `random:MAG_MM[,SEED]` (uniform in +-MAG_MM) or a JSON file
    /// `{name: mm}` (simulate's default: table2).
    #[arg(long, value_name = "ERRORS", alias = "errors")]
    pub truth: Option<String>,
    /// An unmodelled effect of the true machine: a JSON object (or @FILE),
    /// e.g. '{"effect":"leg-lead","ppm":[50,-30,40]}' (magnitudes in the
    /// units their keys name: ppm, um, K, arcsec, N/um); repeatable.
    #[arg(long = "truth-effect", value_name = "JSON", alias = "effect")]
    pub truth_effects: Vec<String>,
}

/// A reference sphere touched by a probe in the spindle (feature 1 of the
/// features file) and the probe's stylus: nominal for `plan`, the simulated
/// truth for `simulate`.
#[derive(Debug, Args, Clone)]
pub struct TouchSphereArgs {
    /// The reference sphere's centre, mm.
    #[arg(
        long,
        default_value = "0,0,1150",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub touch_sphere_mm: String,
    /// The reference sphere's radius, mm.
    #[arg(long, default_value_t = 12.7, value_name = "MM")]
    pub touch_sphere_radius_mm: f64,
    /// The stylus' nominal radius, mm.
    #[arg(long, default_value_t = 1.0, value_name = "MM")]
    pub touch_stylus_radius_mm: f64,
    /// Standard deviation of the stylus radius (its calibration, as the
    /// features file states it), um.
    #[arg(long, default_value_t = 2.0, value_name = "UM")]
    pub touch_stylus_sigma_um: f64,
    /// Noise of a touch along the surface normal, um.
    #[arg(long, default_value_t = 1.5, value_name = "UM")]
    pub touch_sigma_um: f64,
}

/// How to fit.
#[derive(Debug, Args, Clone, Default)]
pub struct FitArgs {
    /// Keep every pose: do not reject gross reading errors (by default,
    /// poses with a gross reading error are rejected and reported by their
    /// file line).
    #[arg(long)]
    pub no_robust: bool,
    /// Manufacturing tolerance of each geometric parameter, mm: the error a
    /// machine has without calibration. A campaign whose predicted platform
    /// accuracy is not at most half of what this tolerance gives is
    /// refused (exit 3; docs/reliability.md).
    #[arg(long, default_value_t = tricept_engine::DEFAULT_TOLERANCE_MM, value_name = "MM")]
    pub tolerance_mm: f64,
}

/// A machine as loaded: its description (with the calibration record of a
/// calibrated machine), the machine built from it, and where it came from.
#[derive(Debug, Clone)]
pub struct LoadedMachine {
    /// The description as read.
    pub description: MachineDescription,
    /// The validated machine.
    pub machine: Machine,
    /// The file name, or `the built-in Table 1 machine`.
    pub source: String,
}

impl LoadedMachine {
    /// The machine whose structure decides the rank rule: the nominal
    /// machine a calibrated file was calibrated from, else this machine.
    pub fn rank_reference(&self) -> Result<Option<Machine>, CliError> {
        match &self.description.calibration {
            None => Ok(None),
            Some(c) => c
                .nominal
                .build()
                .map(Some)
                .map_err(|e| CliError::description(&self.source, &e)),
        }
    }

    /// The nominal machine a calibrated file records, as a description
    /// without calibration of its own.
    pub fn nominal_description(&self) -> MachineDescription {
        match &self.description.calibration {
            Some(c) => (*c.nominal).clone(),
            None => {
                let mut d = self.description.clone();
                d.calibration = None;
                d
            }
        }
    }
}

/// Loads the machine named by `--machine`, or the embedded default; warns
/// on stderr when it holds a calibration that was forced or did not
/// explain its data.
pub fn load(args: &MachineArgs) -> Result<LoadedMachine, CliError> {
    let (description, source) = match &args.machine {
        None => (
            MachineDescription::paper(),
            "the built-in Table 1 machine".to_string(),
        ),
        Some(path) => {
            let source = path.display().to_string();
            (
                MachineDescription::from_file(path)
                    .map_err(|e| CliError::description(&source, &e))?,
                source,
            )
        }
    };
    let machine = description
        .build()
        .map_err(|e| CliError::description(&source, &e))?;
    if let Some((r, why)) = machine.unreachable_workspace_point() {
        let w = &machine.workspace;
        return Err(CliError::input(format!(
            "{source}: the workspace (radius {} mm, z from {} to {} mm) is not within the machine's reach: at ({:.1}, {:.1}, {:.1}) mm: {why}; shrink `workspace` or correct `limits`",
            w.radius_mm, w.z_min_mm, w.z_max_mm, r.x, r.y, r.z
        )));
    }
    tricept_engine::check_calibration_record(&description)
        .map_err(|e| CliError::input(format!("{source}: {e}")))?;
    if let Some(c) = &description.calibration {
        if c.forced {
            errln!(
                "warning: {source} holds a calibration written with --force although it is not to be trusted (converged: {}, adequate: {})",
                c.converged,
                c.adequate
            );
        } else if !c.converged {
            errln!(
                "warning: {source} holds a calibration whose fit did not converge: its estimates are not a calibration"
            );
        } else if !c.adequate {
            errln!(
                "warning: {source} holds a calibration whose model did not explain its data (chi2/dof {:.2})",
                c.chi2_per_dof
            );
        }
    }
    Ok(LoadedMachine {
        description,
        machine,
        source,
    })
}

/// Loads the machine and applies the noise overrides.
pub fn machine_with_noise(args: &MachineArgs, noise: &NoiseArgs) -> Result<Machine, CliError> {
    Ok(load_with_noise(args, noise)?.machine)
}

/// [`load`] with the noise overrides applied to the machine.
pub fn load_with_noise(args: &MachineArgs, noise: &NoiseArgs) -> Result<LoadedMachine, CliError> {
    let mut loaded = load(args)?;
    let m = &mut loaded.machine;
    let check = |flag: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(CliError::input(format!(
                "{flag}: must be a positive number, got {v}"
            )))
        }
    };
    if let Some(a) = noise.angle_noise_arcsec {
        m.sensors.angle_rad = check("--angle-noise-arcsec", a)? * RAD_PER_ARCSEC;
    }
    if let Some(l) = noise.length_noise_um {
        m.sensors.length_mm = check("--length-noise-um", l)? * 1e-3;
    }
    if let Some(k) = noise.readings_per_pose {
        if k == 0 {
            return Err(CliError::input("--readings-per-pose: must be at least 1"));
        }
        m.sensors.readings_per_pose = k;
    }
    Ok(loaded)
}

/// Reads a measured-data file; every problem is an input error naming
/// file, line and column.
pub fn read_data(path: &Path, machine: &Machine) -> Result<Dataset, CliError> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|e| CliError::input(format!("{file}: {e}")))?;
    // A progress bar over the bytes read (drawn only on a terminal).
    let size = f.metadata().map(|m| m.len()).unwrap_or(0);
    let bar = progress_bar(size, &format!("reading {file}"));
    let data = tricept_data::read_from(bar.wrap_read(std::io::BufReader::new(f)), &file)
        .map_err(|e| CliError::input(e.to_string()))?;
    bar.finish_and_clear();
    // Commands the machine cannot take are input errors too, found here
    // with their line rather than deep inside the solver.
    check_commands(
        &data.source,
        data.poses.iter().map(|p| (p.line, p.commands_mm)),
        machine,
    )?;
    Ok(data)
}

/// Refuses leg commands outside the machine's stroke: an input error naming
/// the file, the line and the column (`records` give line and commands).
pub fn check_commands(
    file: &str,
    records: impl Iterator<Item = (u64, [f64; 3])>,
    machine: &Machine,
) -> Result<(), CliError> {
    for (line, q) in records {
        if let Err(e) = machine.check_commands(&q) {
            let message = match e {
                KinematicsError::OutOfStroke {
                    leg,
                    length_mm,
                    min_mm,
                    max_mm,
                } => format!(
                    "{file}: line {line}, column `q{leg}`: command {length_mm} mm is outside the leg stroke [{min_mm}, {max_mm}] mm"
                ),
                e => format!("{file}: line {line}: {e}"),
            };
            return Err(CliError::input(message));
        }
    }
    Ok(())
}

/// The target points of a `--poses` spec (a generated set or a CSV file
/// of `x,y,z`); every problem is an input error.
pub fn pose_targets(spec: &str, machine: &Machine) -> Result<Vec<Vector3<f64>>, CliError> {
    if let Some(n) = spec.strip_prefix("optimal:") {
        let n: usize = n
            .parse()
            .ok()
            .filter(|n| (1..=MAX_POSES).contains(n))
            .ok_or_else(|| {
                CliError::input(format!(
                    "--poses `{spec}`: expected optimal:N with N a whole number from 1 to {MAX_POSES}"
                ))
            })?;
        return tricept_study::campaign::d_optimal_targets(machine, &ParameterSet::paper15(), n)
            .map_err(|e| CliError::other(format!("--poses `{spec}`: {e}")));
    }
    let set: PoseSet = spec
        .parse()
        .map_err(|e: PoseSetError| CliError::input(e.to_string()))?;
    match set.generate(&machine.workspace) {
        Some(points) => Ok(points),
        None => Ok(tricept_data::read_targets(Path::new(spec))
            .map_err(|e| CliError::input(e.to_string()))?
            .into_iter()
            .map(Vector3::from)
            .collect()),
    }
}

/// A progress bar on stderr; invisible when stderr is not a terminal or for
/// small jobs.
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    if len < 20_000_000 {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {bytes}/{total_bytes} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(what.to_string());
    bar
}

/// A spinner on stderr while a long step runs (terminal only).
pub fn spinner(what: String, poses: usize) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget};
    if poses < 50_000 {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_message(what);
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// Parses `table2`, `zero`, `random:MAG[,SEED]` or a JSON file of
/// parameter values.
pub fn parse_errors(spec: &str, set: &ParameterSet) -> Result<Vec<f64>, CliError> {
    match spec {
        "table2" => Ok(set.table2()),
        "zero" => Ok(vec![0.0; set.len()]),
        s if s.starts_with("random:") => {
            let parts: Vec<&str> = s["random:".len()..].split(',').collect();
            let mag: f64 = parts[0]
                .parse()
                .ok()
                .filter(|v: &f64| {
                    v.is_finite() && (0.0..=tricept_model::MAX_PARAMETER_ERROR.0).contains(v)
                })
                .ok_or_else(|| {
                    CliError::input(format!(
                        "errors `{s}`: expected random:MAG_MM[,SEED] with MAG_MM from 0 to {} mm",
                        tricept_model::MAX_PARAMETER_ERROR.0
                    ))
                })?;
            let seed: u64 = match parts.get(1) {
                Some(t) => t.parse().map_err(|_| {
                    CliError::input(format!("errors `{s}`: SEED must be a whole number"))
                })?,
                None => 0,
            };
            Ok(tricept_plant::random_errors(set.len(), mag, seed))
        }
        path => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError::input(format!("{path}: {e}")))?;
            set.parse_values(&text)
                .map_err(|e| CliError::input(format!("{path}: {e}")))
        }
    }
}

/// Parses `--truth-effect` values: JSON objects (or arrays of them), inline or
/// from `@FILE`.
pub fn parse_effects(specs: &[String]) -> Result<Vec<Effect>, CliError> {
    let mut out = Vec::new();
    for spec in specs {
        let (text, origin) = match spec.strip_prefix('@') {
            Some(path) => (
                std::fs::read_to_string(path)
                    .map_err(|e| CliError::input(format!("{path}: {e}")))?,
                path.to_string(),
            ),
            None => (spec.clone(), "--truth-effect".to_string()),
        };
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| CliError::input(format!("{origin}: {e}")))?;
        let items = match value {
            serde_json::Value::Array(a) => a,
            v => vec![v],
        };
        for item in items {
            let effect: Effect = serde_json::from_value(item)
                .map_err(|e| CliError::input(format!("{origin}: {e}")))?;
            effect
                .validate()
                .map_err(|why| CliError::input(format!("{origin}: {why}")))?;
            out.push(effect);
        }
    }
    Ok(out)
}

/// The fit settings of `identify` and `compensate`.
#[derive(Debug, Args)]
pub struct FitSettings {
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept identify`.
#[derive(Debug, Args)]
pub struct IdentifyArgs {
    /// Measured-data CSV (see docs/data-format.md).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    #[command(flatten)]
    pub settings: FitSettings,
    /// Also write the calibrated machine as a description file (loadable
    /// by every --machine), with a `calibration` record of the estimates,
    /// their uncertainties and the fit's quality. Refused when the fit did
    /// not converge or the data cannot come from the machine.
    #[arg(long, value_name = "FILE.json")]
    pub write_machine: Option<PathBuf>,
    /// Write the machine even when the fit is not to be trusted; the file
    /// says so (`calibration.forced`, its name).
    #[arg(long, requires = "write_machine")]
    pub force: bool,
    /// External measurements and the head (the fused identification).
    #[command(flatten)]
    pub external: ExternalArgs,
}

/// External measurements and the head (options of `tricept identify`).
#[derive(Debug, Args, Clone, Default)]
pub struct ExternalArgs {
    /// Laser-tracker or CMM points (CSV `q1,q2,q3,h1,h2,x,y,z`); repeatable.
    #[arg(long, value_name = "FILE.csv")]
    pub tracker: Vec<PathBuf>,
    /// Standard deviation of a tracker coordinate for rows without `sigma_um`, um.
    #[arg(long, default_value_t = 10.0, value_name = "UM")]
    pub tracker_sigma_um: f64,
    /// Where the tracker's target sits (required with --tracker; no
    /// default): `tip` (in a nest at the tool tip), `X,Y,Z` (a known offset
    /// from the tip, mm, spindle frame at zero head angles) or `free`
    /// (unknown: the tool tip is then not calibrated).
    #[arg(long, value_name = "tip|X,Y,Z|free", allow_hyphen_values = true)]
    pub tracker_target: Option<String>,
    /// Standard deviation of a known target offset, um.
    #[arg(long, default_value_t = 5.0, value_name = "UM")]
    pub tracker_target_sigma_um: f64,
    /// Ballbar readings (CSV `q1,q2,q3,h1,h2,length`); repeatable.
    #[arg(long, value_name = "FILE.csv")]
    pub ballbar: Vec<PathBuf>,
    /// Standard deviation of a ballbar reading for rows without `sigma_um`, um.
    #[arg(long, default_value_t = 1.0, value_name = "UM")]
    pub ballbar_sigma_um: f64,
    /// Standard deviation of the bar's length (its certificate), um, or
    /// `free` (the machine's scale then stays invisible to the ballbar).
    #[arg(long, default_value = "1", value_name = "UM|free")]
    pub ballbar_length_sigma_um: String,
    /// Offset of the spindle ball from the tool tip, mm (spindle frame at
    /// zero head angles).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub ballbar_ball_mm: Option<String>,
    /// Touch-offs (CSV `q1,q2,q3,h1,h2,feature`); repeatable; needs --features.
    #[arg(long, value_name = "FILE.csv")]
    pub touch: Vec<PathBuf>,
    /// The features file of the touch-offs (JSON: stylus, spheres, planes).
    #[arg(long, value_name = "FILE.json")]
    pub features: Option<PathBuf>,
    /// Standard deviation of a touch for rows without `sigma_um`, um.
    #[arg(long, default_value_t = 1.5, value_name = "UM")]
    pub touch_sigma_um: f64,
    /// The head's parameters: `head13` (default with external data) or
    /// `none` (the head held nominal).
    #[arg(long, value_name = "head13|none")]
    pub head: Option<String>,
    /// Effects to fit with the geometry (names from `tricept diagnose`):
    /// any of the registry's fusable effects, comma-separated (the help
    /// lists them).
    #[arg(long, value_name = "NAMES", value_delimiter = ',', help = effects_help())]
    pub effects: Vec<String>,
    /// Evaluation grid of the predicted tool tip: platform points of
    /// `polar_grid(RINGS, PER_RING, LEVELS)`.
    #[arg(long, default_value = "2,8,3", value_name = "RINGS,PER_RING,LEVELS")]
    pub eval_grid: String,
    /// Head angles of the evaluation grid, deg: `H1,H1,...:H2,H2,...`.
    #[arg(long, default_value = "0,90,180,270:15,35", value_name = "H1S:H2S")]
    pub eval_head_angles_deg: String,
    /// Override plausible ranges of the head, tool and instrument
    /// estimates: a JSON object `{"tool_length_mm": [-5, 5]}` (keys and
    /// defaults in docs/hybrid.md).
    #[arg(long, value_name = "FILE.json")]
    pub plausibility: Option<PathBuf>,
    /// Warn when the predicted tool-axis uncertainty exceeds this, arcsec.
    #[arg(long, default_value_t = 30.0, value_name = "ARCSEC")]
    pub tool_axis_warn_arcsec: f64,
}

/// The help of `--effects`: the effects the fused model can carry, from
/// the registry.
fn effects_help() -> String {
    let names: Vec<&str> = tricept_engine::fusion::fusable_effects()
        .map(|e| e.as_str())
        .collect();
    format!(
        "Effects to fit with the geometry (names from `tricept diagnose`): any of {}, comma-separated",
        names.join(", ")
    )
}

impl ExternalArgs {
    /// Whether the fused path is asked for.
    pub fn any(&self) -> bool {
        !self.tracker.is_empty()
            || !self.ballbar.is_empty()
            || !self.touch.is_empty()
            || self.head.is_some()
            || !self.effects.is_empty()
    }
}

/// `X,Y,Z` (or any count) as numbers.
pub fn parse_numbers(flag: &str, text: &str, count: usize) -> Result<Vec<f64>, CliError> {
    let values: Result<Vec<f64>, _> = text.split(',').map(|t| t.trim().parse::<f64>()).collect();
    match values {
        Ok(v) if v.len() == count && v.iter().all(|x| x.is_finite()) => {
            if let Some(x) = v.iter().find(|x| x.abs() > limits::MAX_COORDINATE) {
                return Err(CliError::input(format!(
                    "{flag}: {x} is beyond ±{} (mm, deg or rad): not a value for this machine",
                    limits::MAX_COORDINATE
                )));
            }
            Ok(v)
        }
        _ => Err(CliError::input(format!(
            "{flag}: expected {count} comma-separated numbers, got `{text}`"
        ))),
    }
}

/// A list of angles in degrees, `a,b,c`.
fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>, CliError> {
    let n = text.split(',').count();
    if n > limits::MAX_HEAD_ANGLES {
        return Err(CliError::input(format!(
            "{flag}: {n} angles; at most {} per head axis",
            limits::MAX_HEAD_ANGLES
        )));
    }
    parse_numbers(flag, text, n)
}

/// `H1S:H2S` lists of degrees.
pub fn parse_head_angles(flag: &str, text: &str) -> Result<(Vec<f64>, Vec<f64>), CliError> {
    let Some((a, b)) = text.split_once(':') else {
        return Err(CliError::input(format!(
            "{flag}: expected `H1,H1,...:H2,H2,...` in degrees, got `{text}`"
        )));
    };
    Ok((parse_list(flag, a)?, parse_list(flag, b)?))
}

pub fn positive(flag: &str, v: f64) -> Result<f64, CliError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CliError::input(format!(
            "{flag}: must be a positive number, got {v}"
        )))
    }
}
