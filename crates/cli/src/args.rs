//! Arguments and loaders shared by several verbs: the machine and its
//! sensor noise, the parameter set, pose sets, measured data, true errors
//! and effects of simulated machines, the settings of `identify` (its fit,
//! its external measurements and head) and the door's requests they make
//! (`FitSettings::request`, `ExternalArgs::sources`; `compensate` shares
//! them), progress display. Typed values are parsed by the door's
//! `FromStr` types as clap value parsers.

use std::path::{Path, PathBuf};

use clap::Args;
use tricept_ident::Dataset;
use tricept_ident::advanced::{
    EffectNames, EvalGrid, HeadAngles, HeadModel, LengthSigma, ParameterSet, SensorNoise,
    TrackerTargetSpec, Triple, TrueErrors,
};
use tricept_ident::calibrate::{CalibrateRequest, FusedSources};
use tricept_ident::effects::{Effect, EffectName};
use tricept_ident::kinematics::GeometricMachine as Machine;
use tricept_ident::simulate::TruthEffects;
use tricept_ident::{DataInput, LoadedMachine, MachineInput};

use crate::cli_error::CliError;

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

impl MachineArgs {
    /// The machine every request takes: `--machine` (or the embedded
    /// Table 1 machine) with the noise overrides of `noise`.
    pub fn input(&self, noise: &NoiseArgs) -> MachineInput {
        MachineInput::new(self.machine.clone(), noise.overrides())
    }
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

impl NoiseArgs {
    /// The overrides as the door takes them.
    pub fn overrides(&self) -> SensorNoise {
        SensorNoise {
            angle_noise_arcsec: self.angle_noise_arcsec,
            length_noise_um: self.length_noise_um,
            readings_per_pose: self.readings_per_pose,
        }
    }
}

/// The parameter set to identify.
#[derive(Debug, Args, Clone)]
pub struct ParamArgs {
    /// Parameter set: `paper15` (the paper's 15, under its frame
    /// conventions) or `full21` (all joint and length errors; reports the
    /// rigid-body gauges as unidentifiable).
    #[arg(long, default_value = "paper15", value_name = "SET", value_parser = parameter_set)]
    pub params: ParameterSet,
}

/// `--params` as a parameter set.
fn parameter_set(label: &str) -> Result<ParameterSet, CliError> {
    ParameterSet::by_label(label).map_err(|e| CliError::input(e.to_string()))
}

impl ParamArgs {
    /// The parameter set named by `--params`.
    pub fn set(&self) -> Result<ParameterSet, CliError> {
        Ok(self.params.clone())
    }
}

/// The true machine behind simulated data: `simulate` simulates it,
/// `compensate` measures the compensation on it.
#[derive(Debug, Args, Clone, Default)]
pub struct TruthArgs {
    /// True geometric errors of the simulated machine: `table2`, `zero`,
    /// `random:MAG_MM[,SEED]` (uniform in +-MAG_MM) or a JSON file
    /// `{name: mm}` (simulate's default: table2).
    #[arg(
        long,
        value_name = "ERRORS",
        alias = "errors",
        value_parser = clap::value_parser!(TrueErrors)
    )]
    pub truth: Option<TrueErrors>,
    /// An unmodelled effect of the true machine: a JSON object (or @FILE),
    /// e.g. '{"effect":"leg-lead","ppm":[50,-30,40]}' (magnitudes in the
    /// units their keys name: ppm, um, K, arcsec, N/um); repeatable.
    #[arg(
        long = "truth-effect",
        value_name = "JSON",
        alias = "effect",
        value_parser = clap::value_parser!(TruthEffects)
    )]
    pub truth_effects: Vec<TruthEffects>,
}

impl TruthArgs {
    /// The effects of every `--truth-effect`, in order.
    pub fn effects(&self) -> Vec<Effect> {
        self.truth_effects
            .iter()
            .flat_map(|t| t.effects().iter().cloned())
            .collect()
    }
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
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(Triple)
    )]
    pub touch_sphere_mm: Triple,
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
    #[arg(long, default_value_t = tricept_ident::advanced::DEFAULT_TOLERANCE_MM, value_name = "MM")]
    pub tolerance_mm: f64,
}

/// Loads the machine named by `--machine`, or the embedded default
/// (`tricept_ident::MachineInput::load`); warns on stderr when it holds a
/// calibration that was forced or did not explain its data.
pub fn load(args: &MachineArgs) -> Result<LoadedMachine, CliError> {
    load_with_noise(args, &NoiseArgs::default())
}

/// [`load`] with the noise overrides applied to the machine.
pub fn load_with_noise(args: &MachineArgs, noise: &NoiseArgs) -> Result<LoadedMachine, CliError> {
    let loaded = args.input(noise).load()?;
    for w in loaded.warnings() {
        errln!("warning: {w}");
    }
    Ok(loaded)
}

/// Reads a measured-data file (`tricept_ident::advanced::read_data_from`) with a
/// progress bar over the bytes read (drawn only on a terminal).
pub fn read_data(path: &Path, machine: &Machine) -> Result<Dataset, CliError> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|e| CliError::input(format!("{file}: {e}")))?;
    let size = f.metadata().map(|m| m.len()).unwrap_or(0);
    let bar = progress_bar(size, &format!("reading {file}"));
    let data = tricept_ident::advanced::read_data_from(
        bar.wrap_read(std::io::BufReader::new(f)),
        &file,
        machine,
    )?;
    bar.finish_and_clear();
    Ok(data)
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

/// A spinner on stderr while the door works on the data file `data`
/// (terminal only, for files of about 50 000 poses or more).
pub fn spinner(what: &str, data: &Path) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget};
    // About 60 bytes a pose.
    if std::fs::metadata(data).map_or(0, |m| m.len()) < 3_000_000 {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_message(format!("{what}: {}", data.display()));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
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

impl FitSettings {
    /// The door's calibration request of these settings for `data`
    /// (internal; the caller adds external sources).
    pub fn request(&self, data: &Path) -> CalibrateRequest {
        let mut request = CalibrateRequest::new(data);
        request.machine = self.machine.input(&self.noise);
        request.parameter_set = self.params.params.clone();
        request.robust = !self.fit.no_robust;
        request.tolerance_mm = self.fit.tolerance_mm;
        request
    }
}

/// `tricept identify`.
#[derive(Debug, Args)]
pub struct IdentifyArgs {
    /// Measured-data CSV (see docs/data-format.md); given again, more
    /// campaigns of the same machine, pooled: the geometry shared, each
    /// campaign with its own sensor offsets (docs/fleet.md).
    #[arg(long, value_name = "FILE.csv", required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// A batch's prior (`tricept fleet --write-prior`): a new machine of
    /// the batch calibrates from few poses, the prior's uncertainty in its
    /// accuracy promise (docs/fleet.md).
    #[arg(long, value_name = "PRIOR.json")]
    pub prior: Option<PathBuf>,
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

impl IdentifyArgs {
    /// `identify`'s flags read in one pass: checked together, turned into
    /// the door's request, with the spinner shown while it runs.
    pub fn prepare(&self) -> Result<(CalibrateRequest, indicatif::ProgressBar), CliError> {
        if self.external.plausibility.is_some() && !self.external.any() {
            return Err(CliError::input(
                "--plausibility: the plausible ranges of the head, tool and instruments apply to the fused identification only (with --tracker, --ballbar, --touch, --head or --effects); without them it would be ignored",
            ));
        }
        let (first, more) = self
            .data
            .split_first()
            .map_or((None, &[][..]), |(f, m)| (Some(f), m));
        let first = first.map_or(Path::new(""), |p| p.as_path());
        let mut request = self.settings.request(first);
        request.campaigns = more.iter().cloned().map(DataInput::File).collect();
        request.prior = self.prior.clone();
        request.fused = self.external.any().then(|| self.external.sources());
        request.for_machine_file = self.write_machine.is_some();
        let spin = spinner(
            "identify: reading, screening and fitting (Gauss-Newton on the exact model)",
            first,
        );
        Ok((request, spin))
    }
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
    pub tracker_target: Option<TrackerTargetSpec>,
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
    pub ballbar_length_sigma_um: Option<LengthSigma>,
    /// Offset of the spindle ball from the tool tip, mm (spindle frame at
    /// zero head angles).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub ballbar_ball_mm: Option<Triple>,
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
    pub head: Option<HeadModel>,
    /// Effects to fit with the geometry (names from `tricept diagnose`):
    /// any of the registry's fusable effects, comma-separated (the help
    /// lists them).
    #[arg(long, value_name = "NAMES", value_delimiter = ',', help = effects_help())]
    pub effects: Vec<EffectNames>,
    /// Evaluation grid of the predicted tool tip: platform points of
    /// `polar_grid(RINGS, PER_RING, LEVELS)`.
    #[arg(long, default_value = "2,8,3", value_name = "RINGS,PER_RING,LEVELS")]
    pub eval_grid: Option<EvalGrid>,
    /// Head angles of the evaluation grid, deg: `H1,H1,...:H2,H2,...`.
    #[arg(long, default_value = "0,90,180,270:15,35", value_name = "H1S:H2S")]
    pub eval_head_angles_deg: Option<HeadAngles>,
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
    let names: Vec<&str> = tricept_ident::advanced::fusable_effects()
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

    /// The door's fused sources of these flags.
    pub fn sources(&self) -> FusedSources {
        let mut x = FusedSources::default();
        x.tracker = self.tracker.clone();
        x.tracker_sigma_um = self.tracker_sigma_um;
        x.tracker_target = self.tracker_target;
        x.tracker_target_sigma_um = self.tracker_target_sigma_um;
        x.ballbar = self.ballbar.clone();
        x.ballbar_sigma_um = self.ballbar_sigma_um;
        if let Some(l) = self.ballbar_length_sigma_um {
            x.ballbar_length_sigma = l;
        }
        x.ballbar_ball_mm = self.ballbar_ball_mm;
        x.touch = self.touch.clone();
        x.features = self.features.clone();
        x.touch_sigma_um = self.touch_sigma_um;
        x.head = self.head.unwrap_or_default();
        x.effects = effect_names(&self.effects);
        if let Some(g) = self.eval_grid {
            x.eval_grid = g;
        }
        if let Some(h) = &self.eval_head_angles_deg {
            x.eval_head_angles = h.clone();
        }
        x.plausibility = self.plausibility.clone();
        x.tool_axis_warn_arcsec = self.tool_axis_warn_arcsec;
        x
    }
}

/// The effect names of `--effects` values.
pub fn effect_names(lists: &[EffectNames]) -> Vec<EffectName> {
    lists.iter().flat_map(|l| l.0.iter().copied()).collect()
}
