//! `tricept simulate`: a measured-data CSV from a simulated machine. The
//! flags into a request of the door (`tricept_ident::simulate`), the
//! simulated data written.

use std::path::PathBuf;

use clap::Args;
use tricept_ident::advanced::{FrameMmRad, Poses, Triple};
use tricept_ident::simulate::{
    BallbarSimulation, HeadErrors, SimulateRequest, TouchSimulation, TrackerSimulation, simulate,
};

use crate::args::{MachineArgs, NoiseArgs, ParamArgs, TouchSphereArgs, TruthArgs, load_with_noise};
use crate::cli_error::CliError;

/// `tricept simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub truth: TruthArgs,
    /// Pose set (as for `identifiability`; positions in mm).
    #[arg(long, default_value = "grid", value_parser = clap::value_parser!(Poses))]
    pub poses: Poses,
    /// Seed of the sensor noise (a whole number).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub seed: u64,
    /// Visit every pose twice, approaching from both directions.
    #[arg(long)]
    pub both_directions: bool,
    /// Revisit the first N targets at the end of the campaign (separate
    /// visits of the same commands: what `diagnose --noise-from-data` uses).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub revisit: usize,
    /// Make the true noise this many times the machine's stated noise
    /// (vibration, a sensor worse than its data sheet).
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub noise_factor: f64,
    /// Output file (default, or `-`: stdout; with --json, a summary goes
    /// to stdout).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    /// Head errors of the simulated machine: `zero`, `random:SCALE[,SEED]`
    /// (each of the 13 parameters SCALE times its typical size, times 0.5-1,
    /// random sign), or a JSON file `{name: value}` (docs/hybrid.md).
    #[arg(long, default_value = "zero", value_name = "HEAD", value_parser = clap::value_parser!(HeadErrors))]
    pub head_errors: HeadErrors,
    /// Also write laser-tracker points (CSV) measured at the poses of
    /// --tracker-poses.
    #[arg(long, value_name = "FILE.csv")]
    pub tracker_out: Option<PathBuf>,
    /// Poses for the tracker (CSV `q1,q2,q3,h1,h2[,extension_mm]`, as
    /// `tricept plan --out` writes them).
    #[arg(long, value_name = "FILE.csv")]
    pub tracker_poses: Option<PathBuf>,
    /// The tracker's frame: translation (mm) and rotation vector (rad) that
    /// map the machine's base frame into the tracker's.
    #[arg(
        long,
        default_value = "1500,-800,200,0.1,0.2,0.3",
        value_name = "X,Y,Z,RX,RY,RZ",
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(FrameMmRad)
    )]
    pub tracker_frame_mm_rad: FrameMmRad,
    /// The tracker target's offset from the tool tip, mm (spindle frame at
    /// zero head angles).
    #[arg(
        long,
        default_value = "0,0,0",
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(Triple)
    )]
    pub tracker_target_mm: Triple,
    /// Noise of a tracker coordinate, um.
    #[arg(long, default_value_t = 10.0, value_name = "UM")]
    pub tracker_sigma_um: f64,
    /// Also write ballbar readings (CSV) at the poses of --ballbar-poses.
    #[arg(long, value_name = "FILE.csv")]
    pub ballbar_out: Option<PathBuf>,
    /// Poses for the ballbar (CSV `q1,q2,q3,h1,h2`).
    #[arg(long, value_name = "FILE.csv")]
    pub ballbar_poses: Option<PathBuf>,
    /// The ballbar's pivot on the table, mm.
    #[arg(
        long,
        default_value = "0,0,1250",
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(Triple)
    )]
    pub ballbar_pivot_mm: Triple,
    /// The bar's reading minus the true distance, um.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "UM",
        allow_hyphen_values = true
    )]
    pub ballbar_length_error_um: f64,
    /// Noise of a ballbar reading, um.
    #[arg(long, default_value_t = 1.0, value_name = "UM")]
    pub ballbar_sigma_um: f64,
    /// Also write touch-offs (CSV) at the planned touches of --touch-poses
    /// (needs --features-out).
    #[arg(long, value_name = "FILE.csv")]
    pub touch_out: Option<PathBuf>,
    /// The features file of the touch-offs (JSON: the stylus and the
    /// reference sphere, as a user would write it).
    #[arg(long, value_name = "FILE.json")]
    pub features_out: Option<PathBuf>,
    /// Planned touches (CSV `q1,q2,q3,h1,h2,x,y,z,feature`, as `tricept plan
    /// --instrument touch --out` writes them).
    #[arg(long, value_name = "FILE.csv")]
    pub touch_poses: Option<PathBuf>,
    /// The reference sphere as it truly is (feature 1), the stylus' nominal
    /// radius and noise.
    #[command(flatten)]
    pub touch: TouchSphereArgs,
    /// The stylus' true radius minus the nominal one, um.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "UM",
        allow_hyphen_values = true
    )]
    pub touch_stylus_error_um: f64,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// The file of `--out`: `None` for stdout (no `--out`, or `-`).
pub fn out_file(a: &SimulateArgs) -> Option<PathBuf> {
    a.out
        .clone()
        .filter(|p| p.as_os_str() != crate::files::STDIO)
}

/// `tricept simulate`.
pub fn run(a: &SimulateArgs) -> Result<u8, CliError> {
    let out = out_file(a);
    if a.machine.json && out.is_none() {
        return Err(CliError::input(
            "--json: needs --out FILE.csv (without it the CSV itself goes to stdout)",
        ));
    }
    let mut request = SimulateRequest::new().machine(load_with_noise(&a.machine, &a.noise)?);
    request.parameter_set = a.params.set()?;
    if let Some(truth) = &a.truth.truth {
        request.truth = truth.clone();
    }
    request.truth_effects = a.truth.effects();
    request.head_errors = a.head_errors.clone();
    request.poses = a.poses.clone();
    request.seed = a.seed;
    request.both_directions = a.both_directions;
    request.revisit = a.revisit;
    request.noise_factor = a.noise_factor;
    request.tracker = tracker(a)?;
    request.ballbar = ballbar(a)?;
    request.touch = touch(a)?;
    request.out = out.clone();
    let sim = simulate(request)?;
    let written = |path: &std::path::Path, r| crate::files::written(path, r);
    if let (Some(out), Some((data, c))) = (&a.tracker_out, sim.tracker()) {
        written(
            out,
            tricept_ident::advanced::files::write_external_path(out, data, c),
        )?;
    }
    if let (Some(out), Some((data, c))) = (&a.ballbar_out, sim.ballbar()) {
        written(
            out,
            tricept_ident::advanced::files::write_external_path(out, data, c),
        )?;
    }
    if let (Some(out), Some(features_out), Some((data, c, features))) =
        (&a.touch_out, &a.features_out, sim.touch())
    {
        written(
            out,
            tricept_ident::advanced::files::write_external_path(out, data, c),
        )?;
        crate::files::write_text(features_out, features)?;
    }
    match &out {
        Some(path) => {
            written(
                path,
                tricept_ident::advanced::files::write_path(path, sim.data(), sim.comments()),
            )?;
            if a.machine.json {
                crate::output::write_json(sim.to_json());
            } else {
                errln!("{}", sim.report());
            }
        }
        // A closed stdout (`| head`) is not an error: the writer swallows it.
        None => tricept_ident::advanced::files::write_to(
            std::io::BufWriter::new(crate::output::Stdout),
            sim.data(),
            sim.comments(),
        )
        .map_err(|e| CliError::other(format!("stdout: {e}")))?,
    }
    Ok(sim.exit_code())
}

/// The tracker to simulate: --tracker-out and --tracker-poses together.
fn tracker(a: &SimulateArgs) -> Result<Option<TrackerSimulation>, CliError> {
    match (&a.tracker_out, &a.tracker_poses) {
        (Some(_), Some(poses)) => Ok(Some(TrackerSimulation {
            poses: poses.clone(),
            frame_mm_rad: a.tracker_frame_mm_rad.0,
            target_mm: a.tracker_target_mm.0,
            sigma_um: a.tracker_sigma_um,
        })),
        (None, None) => Ok(None),
        _ => Err(CliError::input(
            "--tracker-out and --tracker-poses go together",
        )),
    }
}

/// The ballbar to simulate: --ballbar-out and --ballbar-poses together.
fn ballbar(a: &SimulateArgs) -> Result<Option<BallbarSimulation>, CliError> {
    match (&a.ballbar_out, &a.ballbar_poses) {
        (Some(_), Some(poses)) => Ok(Some(BallbarSimulation {
            poses: poses.clone(),
            pivot_mm: a.ballbar_pivot_mm.0,
            length_error_um: a.ballbar_length_error_um,
            sigma_um: a.ballbar_sigma_um,
        })),
        (None, None) => Ok(None),
        _ => Err(CliError::input(
            "--ballbar-out and --ballbar-poses go together",
        )),
    }
}

/// The touch probe to simulate: --touch-out, --features-out and
/// --touch-poses together.
fn touch(a: &SimulateArgs) -> Result<Option<TouchSimulation>, CliError> {
    match (&a.touch_out, &a.features_out, &a.touch_poses) {
        (Some(_), Some(_), Some(poses)) => Ok(Some(TouchSimulation {
            poses: poses.clone(),
            sphere_mm: a.touch.touch_sphere_mm.0,
            sphere_radius_mm: a.touch.touch_sphere_radius_mm,
            stylus_radius_mm: a.touch.touch_stylus_radius_mm,
            stylus_sigma_um: a.touch.touch_stylus_sigma_um,
            stylus_error_um: a.touch_stylus_error_um,
            sigma_um: a.touch.touch_sigma_um,
        })),
        (None, None, None) => Ok(None),
        _ => Err(CliError::input(
            "--touch-out, --features-out and --touch-poses go together",
        )),
    }
}
