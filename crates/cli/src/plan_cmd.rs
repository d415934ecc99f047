//! `tricept plan`: flags in, one call of the door (`tricept_ident::plan`),
//! the plan out (and the planned poses written with `--out`).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use tricept_ident::advanced::{
    EffectNames, EvalGrid, HeadAngles, Poses, TrackerTargetSpec, Triple,
};
use tricept_ident::plan::{self as door, PlanRequest};

use crate::args::{MachineArgs, NoiseArgs, ParamArgs, TouchSphereArgs};
use crate::cli_error::CliError;

/// The instrument to plan for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Instrument {
    /// A laser tracker or CMM on a target in the spindle.
    Tracker,
    /// A ballbar from the spindle ball to a pivot on the table.
    Ballbar,
    /// A touch probe in the spindle on a reference sphere.
    Touch,
    /// A check of the calibrated machine from its own sensors (`tricept
    /// check`): the fewest poses that detect a stated change.
    Check,
}

/// `tricept plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The instrument.
    #[arg(long, value_enum)]
    pub instrument: Instrument,
    /// Numbers of measurements to plan for, comma-separated (default
    /// 3,5,8,12,20,30,50; for a check, the largest number of poses it may
    /// take, default 20).
    #[arg(long, value_delimiter = ',')]
    pub k: Vec<usize>,
    /// For a check: the change to detect, as the mean platform error it
    /// causes over the workspace, um (from any single joint or length
    /// parameter).
    #[arg(long, default_value_t = 20.0, value_name = "UM")]
    pub detect_um: f64,
    /// For a check: the power with which it is detected.
    #[arg(long, default_value_t = tricept_ident::advanced::DEFAULT_POWER, value_name = "P")]
    pub power: f64,
    /// The internal campaign's measured-data file (only its commands are
    /// used); default: the pose set of --poses.
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    /// The internal campaign's pose set when no --data is given.
    #[arg(long, default_value = "grid")]
    pub poses: Poses,
    /// Candidate platform points of a tracker (a pose-set spec).
    #[arg(long, default_value = "grid:2,8,3")]
    pub candidates: Poses,
    /// Candidate head angles of a tracker, deg: `H1,H1,...:H2,H2,...`.
    #[arg(
        long,
        default_value = "0,60,120,180,240,300:-45,-25,25,45",
        value_name = "H1S:H2S"
    )]
    pub head_angles_deg: HeadAngles,
    /// Known extensions of the tracker target along the tool, mm: every
    /// candidate pose is offered at each; with two or more the plan fixes
    /// the tool's direction too (its criterion adds the tool axis).
    #[arg(
        long,
        default_value = "0",
        value_delimiter = ',',
        value_name = "MM,..."
    )]
    pub extensions: Vec<f64>,
    /// Noise of a tracker coordinate, um.
    #[arg(long, default_value_t = 10.0, value_name = "UM")]
    pub tracker_sigma_um: f64,
    /// Noise of a ballbar reading, um.
    #[arg(long, default_value_t = 1.0, value_name = "UM")]
    pub ballbar_sigma_um: f64,
    /// The instrument's noise (old name of the three flags above).
    #[arg(long, hide = true, value_name = "UM")]
    pub sigma_um: Option<f64>,
    /// Where the tracker's target sits (required for a tracker; no
    /// default): `tip`, `X,Y,Z` (a known offset, mm, spindle frame at zero
    /// head angles) or `free`.
    #[arg(long, value_name = "tip|X,Y,Z|free", allow_hyphen_values = true)]
    pub tracker_target: Option<TrackerTargetSpec>,
    /// Standard deviation of a known target offset, um.
    #[arg(long, default_value_t = 5.0, value_name = "UM")]
    pub tracker_target_sigma_um: f64,
    /// The ballbar's pivot, mm.
    #[arg(
        long,
        default_value = "0,0,1250",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub ballbar_pivot_mm: Triple,
    /// The ballbar's nominal length, mm.
    #[arg(long, default_value_t = 150.0, value_name = "MM")]
    pub ballbar_length_mm: f64,
    /// Number of ballbar (or touch) candidate positions.
    #[arg(long, default_value_t = 300, value_name = "N")]
    pub ballbar_candidates: usize,
    /// The reference sphere (touch-offs).
    #[command(flatten)]
    pub touch: TouchSphereArgs,
    /// Effects in the model (as for `identify --effects`).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub effects: Vec<EffectNames>,
    /// The accuracy to reach, um: the report recommends the smallest
    /// planned k that predicts it and leaves its rows enough redundancy to
    /// check the fit.
    #[arg(long, value_name = "UM")]
    pub target_um: Option<f64>,
    /// Random selections per k for the baseline (0: none).
    #[arg(long, default_value_t = 50, value_name = "N")]
    pub random_baseline: usize,
    /// Seed of the random baseline.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Exchange passes at each k.
    #[arg(long, default_value_t = 10, value_name = "N")]
    pub passes: usize,
    /// Evaluation grid of the tool tip (as for `identify`).
    #[arg(long, default_value = "2,8,3", value_name = "RINGS,PER_RING,LEVELS")]
    pub eval_grid: EvalGrid,
    /// Head angles of the evaluation grid, deg.
    #[arg(long, default_value = "0,90,180,270:15,35", value_name = "H1S:H2S")]
    pub eval_head_angles_deg: HeadAngles,
    /// Write the planned poses for the largest k (CSV
    /// `q1,q2,q3,h1,h2[,extension_mm],x,y,z[,length][,feature]`: nominal
    /// tool tip, bar length, feature touched).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

impl Instrument {
    /// The door's instrument.
    fn door(self) -> door::Instrument {
        match self {
            Instrument::Tracker => door::Instrument::Tracker,
            Instrument::Ballbar => door::Instrument::Ballbar,
            Instrument::Touch => door::Instrument::Touch,
            Instrument::Check => door::Instrument::Check,
        }
    }
}

/// The door's request of `plan`'s flags.
fn request(a: &PlanArgs) -> Result<PlanRequest, CliError> {
    let mut r = PlanRequest::new(a.instrument.door());
    r.k = a.k.clone();
    r.detect_um = a.detect_um;
    r.power = a.power;
    r.data = a.data.clone().map(tricept_ident::DataInput::File);
    r.poses = Some(a.poses.clone());
    r.candidates = Some(a.candidates.clone());
    r.head_angles_deg = a.head_angles_deg.clone();
    r.extensions = a.extensions.clone();
    r.tracker_sigma_um = a.tracker_sigma_um;
    r.ballbar_sigma_um = a.ballbar_sigma_um;
    r.sigma_um = a.sigma_um;
    r.tracker_target = a.tracker_target;
    r.tracker_target_sigma_um = a.tracker_target_sigma_um;
    r.ballbar_pivot_mm = a.ballbar_pivot_mm;
    r.ballbar_length_mm = a.ballbar_length_mm;
    r.ballbar_candidates = a.ballbar_candidates;
    r.touch_sphere_mm = a.touch.touch_sphere_mm;
    r.touch_sphere_radius_mm = a.touch.touch_sphere_radius_mm;
    r.touch_stylus_radius_mm = a.touch.touch_stylus_radius_mm;
    r.touch_stylus_sigma_um = a.touch.touch_stylus_sigma_um;
    r.touch_sigma_um = a.touch.touch_sigma_um;
    r.effects = crate::args::effect_names(&a.effects);
    r.target_um = a.target_um;
    r.random_baseline = a.random_baseline;
    r.seed = a.seed;
    r.passes = a.passes;
    r.eval_grid = a.eval_grid;
    r.eval_head_angles_deg = a.eval_head_angles_deg.clone();
    r.out = a.out.clone();
    r.machine = a.machine.input(&a.noise);
    r.parameter_set = a.params.params.clone();
    Ok(r)
}

/// `tricept plan`.
pub fn run(a: &PlanArgs) -> Result<u8, CliError> {
    let plan = door::plan(request(a)?)?;
    crate::output::warn_all(plan.machine_warnings());
    if let Some(path) = &a.out
        && plan.write_out(path)?
    {
        errln!("wrote {}", path.display());
    }
    if a.machine.json {
        crate::output::write_json(plan.to_json());
    } else {
        crate::output::write_text(&plan.report());
    }
    Ok(0)
}
