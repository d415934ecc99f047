//! The accuracy a fused machine file promises, kept in truth: machines and
//! instruments from the independent generator (`tricept-truth`: a true
//! module and a general two-axis head written from the documented
//! conventions, a laser tracker station, a ballbar and a touch probe on a
//! reference sphere, never through the project's plant or kinematics), the
//! external poses planned by the door (`plan`), calibrated by the door
//! (`identify` with `--tracker`/`--ballbar`/`--touch`), the file written at
//! exit 0, and the true machine commanded with that file on held-out tool
//! poses: the door's `tool-ik` of the FILE computes the leg commands and
//! head angles of a target tool tip and axis, the true machine's forward
//! kinematics says where the tool tip goes. The promise is at the tool tip
//! after touch-off (the mean error over the targets removed: the part is
//! located with the machine itself). The delivered rms must be within the
//! file's `upper_mm` in at least 95 % of the files written at exit 0, and
//! never beyond twice it.
//!
//! The documented configurations: a tracker with k = 12 and 30 points, its
//! target at the tip, at a stated 20 mm offset and free; a ballbar with 30
//! readings; each with 24 touch-offs on a sphere beside it. The CI test
//! runs two machines per configuration; the tallies of
//! `docs/reliability.md` run 30, without and with a static leg effect
//! hidden in every instrument's true leg lengths. The tally at the tails
//! runs every configuration the tool accepts (`tails::tail_configurations`: k =
//! 12-60, planned and random poses, offsets along and across the tool, a
//! ballbar's stated ball, touch-offs beside each, without the gross-error
//! screen) on 16 machines each, heads half to four typical sizes off, alike
//! or by kind (`cargo test -p tricept-ident --test fused_accuracy --
//! --ignored --nocapture` runs the three).

mod tails;

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use tricept_ident::DataInput;
use tricept_ident::advanced::nalgebra::Vector3;
use tricept_ident::advanced::{SensorNoise, TrackerTargetSpec, Triple, load_machine};
use tricept_ident::calibrate::{CalibrateRequest, FusedSources, calibrate};
use tricept_ident::kinematics::{GeometricMachine as Machine, Verb as KinematicsVerb, solve_point};
use tricept_ident::plan::{Instrument, PlanRequest, plan};
use tricept_truth::{
    HeadSizes, LegEffect, Row, TrueBallbar, TrueMachine, TrueSphere, TrueTracker, normal, to_csv,
};

/// Held-out tool poses per file.
const TARGETS: usize = 60;

/// The documented reference sphere of a touch plan (`plan`'s defaults).
const SPHERE_MM: [f64; 3] = [0.0, 0.0, 1150.0];
const SPHERE_RADIUS_MM: f64 = 12.7;
const STYLUS_MM: f64 = 1.0;

/// The ballbar's pivot and length (`plan`'s defaults).
const PIVOT_MM: [f64; 3] = [0.0, 0.0, 1250.0];
const BALLBAR_MM: f64 = 150.0;

/// Where the tracker's target sits, truly and as stated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    Tip,
    /// At this offset from the tip (mm, spindle frame at zero head
    /// angles), stated as such.
    Offset([f64; 3]),
    /// At this offset from the tip, stated `free`.
    Free([f64; 3]),
}

/// 20 mm beyond the tip along the tool.
const ALONG: [f64; 3] = [0.0, 0.0, 20.0];

/// 20 mm from the tip, mostly across the tool.
const ACROSS: [f64; 3] = [16.0, -6.0, 10.0];

impl Target {
    /// Where the target truly sits from the tip, mm.
    fn offset_mm(self) -> Vector3<f64> {
        match self {
            Target::Tip => Vector3::zeros(),
            Target::Offset(v) | Target::Free(v) => Vector3::from(v),
        }
    }

    /// What the campaign states (`--tracker-target`).
    fn spec(self) -> TrackerTargetSpec {
        match self {
            Target::Tip => TrackerTargetSpec::Tip,
            Target::Offset(v) => TrackerTargetSpec::Offset(v),
            Target::Free(_) => TrackerTargetSpec::Free,
        }
    }

    fn name(self) -> String {
        let v = |v: [f64; 3]| format!("{},{},{}", v[0], v[1], v[2]);
        match self {
            Target::Tip => "Tip".into(),
            Target::Offset(o) if o == ALONG => "Offset".into(),
            Target::Free(o) if o == ALONG => "Free".into(),
            Target::Offset(o) => format!("Offset {}", v(o)),
            Target::Free(o) => format!("Free at {}", v(o)),
        }
    }
}

/// How an instrument's poses were chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Poses {
    /// By the door's `plan`.
    Planned,
    /// At random: tracker points anywhere in the workspace with random
    /// head angles; ballbar positions anywhere on the bar's sphere cap,
    /// the tool tilted at random (the door's `tool-ik` of the nominal
    /// machine).
    Random,
}

/// The machines a tally calibrates: the size of their heads' errors (in
/// the head table's typical sizes; machine `seed` has
/// `sizes[seed % sizes.len()]`) and of their internal campaigns.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Machines {
    /// Heads of one, two and three typical sizes; 60-120 internal poses.
    Documented,
    /// 40-200 internal poses; heads of half, one, two and four typical
    /// sizes, every kind of error alike (even seeds) or each kind (axis
    /// tilts, axis points, angle zeros, tool length, the tool tip across the
    /// tool, the tool's tilt) its own size (odd seeds, as a real head's may
    /// be): the tails.
    Tails,
}

impl Machines {
    /// The true machine `seed`.
    fn truth(self, seed: u64) -> TrueMachine {
        const TAILS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];
        match self {
            Machines::Documented => TrueMachine::random(1.0 + (seed % 3) as f64, seed),
            Machines::Tails if seed.is_multiple_of(2) => {
                TrueMachine::random(TAILS[(seed / 2 % 4) as usize], seed)
            }
            Machines::Tails => {
                let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x4ead_5e5e);
                let mut size = || TAILS[(rng.random::<f64>() * 4.0) as usize % 4];
                let sizes = HeadSizes {
                    axis_tilts: size(),
                    axis_points: size(),
                    angle_zeros: size(),
                    tool_length: size(),
                    tool_across: size(),
                    tool_tilt: size(),
                };
                TrueMachine::random_head(sizes, seed)
            }
        }
    }

    /// The internal campaign's poses, drawn by `rng`.
    fn internal_poses(self, rng: &mut Pcg64Mcg) -> usize {
        let (low, high) = match self {
            Machines::Documented => (60, 120),
            Machines::Tails => (40, 200),
        };
        low + (rng.random::<f64>() * (high - low + 1) as f64) as usize
    }
}

/// One fused configuration.
#[derive(Debug, Clone, Copy)]
struct Config {
    /// Tracker points, where the target sits, how the points were chosen.
    tracker: Option<(usize, Target, Poses)>,
    /// Ballbar readings and how their poses were chosen.
    ballbar: Option<(usize, Poses)>,
    /// The ballbar's ball's offset from the tool tip, stated (mm, spindle
    /// frame at zero head angles; `--ballbar-ball-mm`).
    ball_mm: [f64; 3],
    /// Touch-offs on the sphere.
    touch: Option<usize>,
    /// The probe's stylus centre beyond the tool tip the other instruments
    /// measure, mm (0: as documented; otherwise touches that disagree).
    touch_beyond_mm: f64,
    /// A static leg effect hidden in the true leg lengths ([`leg_effect`]).
    leg_effects: bool,
    /// The gross-error screen (`identify`'s default; `--no-robust` off).
    robust: bool,
    /// The true machines.
    machines: Machines,
}

/// A static leg effect hidden in the true leg lengths of machine `seed`
/// (every instrument and the delivery see it): a lead of each leg
/// (0.2-25 ppm) or a curved screw on one leg (0.5-12 um), log-uniform
/// sizes from invisible to plainly not geometric.
fn leg_effect(seed: u64, m: &Machine) -> LegEffect {
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x1e6e_ffec);
    let mut size = |lo: f64, hi: f64| lo * (hi / lo).powf(rng.random::<f64>());
    if seed.is_multiple_of(2) {
        LegEffect::Lead {
            ppm: [size(0.2, 25.0), -size(0.2, 25.0), size(0.2, 25.0)],
        }
    } else {
        let mut um = [0.0; 3];
        um[(seed / 2 % 3) as usize] = size(0.5, 12.0);
        let [start, end] = m.limits.leg_stroke_mm;
        LegEffect::Quadratic {
            um,
            centre_mm: 0.5 * (start + end),
            half_width_mm: 0.5 * (end - start),
        }
    }
}

impl Config {
    /// A configuration of one or more instruments, the rest as the
    /// documented campaign has it (no leg effect, robust, heads of one to
    /// three typical sizes).
    fn of(
        tracker: Option<(usize, Target, Poses)>,
        ballbar: Option<(usize, Poses)>,
        touch: Option<usize>,
    ) -> Config {
        Config {
            tracker,
            ballbar,
            ball_mm: [0.0; 3],
            touch,
            touch_beyond_mm: 0.0,
            leg_effects: false,
            robust: true,
            machines: Machines::Documented,
        }
    }

    fn name(&self) -> String {
        let random = |p: Poses| if p == Poses::Random { " random" } else { "" };
        let mut parts = Vec::new();
        if let Some((k, t, p)) = self.tracker {
            parts.push(format!("tracker k={k}{} target {}", random(p), t.name()));
        }
        if let Some((k, p)) = self.ballbar {
            let b = self.ball_mm;
            let ball = if b == [0.0; 3] {
                String::new()
            } else {
                format!(" ball at {},{},{}", b[0], b[1], b[2])
            };
            parts.push(format!("ballbar k={k}{}{ball}", random(p)));
        }
        if let Some(k) = self.touch {
            parts.push(format!("touch k={k}"));
        }
        let mut name = parts.join(" + ");
        if !self.robust {
            name.push_str(" (no robust)");
        }
        name
    }
}

/// The configurations of the documented tally.
fn configurations() -> Vec<Config> {
    let tracker = |k, t| Config::of(Some((k, t, Poses::Planned)), None, None);
    let ballbar = Config::of(None, Some((30, Poses::Planned)), None);
    let mut out = vec![
        tracker(12, Target::Tip),
        tracker(30, Target::Tip),
        tracker(12, Target::Offset(ALONG)),
        tracker(30, Target::Offset(ALONG)),
        tracker(30, Target::Free(ALONG)),
        ballbar,
    ];
    let with_touch: Vec<Config> = out
        .iter()
        .map(|c| Config {
            touch: Some(24),
            ..*c
        })
        .collect();
    out.extend(with_touch);
    out
}

/// One planned external pose: commands, head angles, extension.
#[derive(Debug, Clone, Copy)]
struct Planned {
    q: [f64; 3],
    h: [f64; 2],
    extension_mm: f64,
}

/// The planned poses of `instrument` with `k` records, planned by the door
/// and read back from its CSV as plain text.
fn planned(instrument: Instrument, k: usize, dir: &Path) -> Vec<Planned> {
    let mut request = PlanRequest::new(instrument);
    request.k = vec![k];
    request.random_baseline = 0;
    request.passes = 1;
    if instrument == Instrument::Tracker {
        request.tracker_target = Some(TrackerTargetSpec::Tip);
    }
    let path = dir.join(format!("plan-{instrument:?}-{k}.csv"));
    request.out = Some(path.clone());
    let p = plan(request).unwrap();
    assert!(p.write_out(&path).unwrap());
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| h.trim() == name);
    let rows: Vec<Planned> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            let at = |n: &str| v[col(n).unwrap()];
            Planned {
                q: [at("q1"), at("q2"), at("q3")],
                h: [at("h1"), at("h2")],
                extension_mm: col("extension_mm").map_or(0.0, |c| v[c]),
            }
        })
        .collect();
    assert_eq!(rows.len(), k, "{instrument:?}");
    rows
}

/// The plans the configurations draw from, each made once, when first
/// needed.
struct Plans {
    dir: PathBuf,
    made: RefCell<BTreeMap<(String, usize), Vec<Planned>>>,
}

impl Plans {
    fn new(dir: &Path) -> Plans {
        Plans {
            dir: dir.to_path_buf(),
            made: RefCell::new(BTreeMap::new()),
        }
    }

    /// The plan of `instrument` with `k` records (fewer touch-offs than
    /// 24: the first `k` of the plan of 24; fewer tracker points or ballbar
    /// readings than 12: the first `k` of the plan of 12).
    fn of(&self, instrument: Instrument, k: usize) -> Vec<Planned> {
        let planned_k = k.max(if instrument == Instrument::Touch {
            24
        } else {
            12
        });
        let key = (format!("{instrument:?}"), planned_k);
        let mut made = self.made.borrow_mut();
        let plan = made
            .entry(key)
            .or_insert_with(|| planned(instrument, planned_k, &self.dir));
        plan[..k].to_vec()
    }
}

/// The poses of an instrument with `k` records chosen as `poses` for
/// machine `seed`.
fn poses_of(
    plans: &Plans,
    instrument: Instrument,
    k: usize,
    poses: Poses,
    seed: u64,
) -> Vec<Planned> {
    match (poses, instrument) {
        (Poses::Planned, _) => plans.of(instrument, k),
        (Poses::Random, Instrument::Tracker) => tails::random_tracker_poses(k, seed),
        (Poses::Random, _) => tails::random_ballbar_poses(k, seed),
    }
}

/// One file: its exit code, and when written its promise and delivery.
#[derive(Debug)]
struct Outcome {
    seed: u64,
    exit: u8,
    rms_mm: f64,
    upper_mm: f64,
    delivered_mm: f64,
    parts: serde_json::Value,
    unchecked: serde_json::Value,
}

impl Outcome {
    /// The 95 % bound with the head parts the data cannot calibrate at
    /// their typical size (one degree of freedom), as before the head was
    /// priced by what the data show.
    fn typical_upper_mm(&self) -> f64 {
        let part = |k: &str| self.parts[k].as_f64().unwrap_or(0.0);
        let typical = 3.841_458_820_694_124_f64.sqrt() * part("head_at_typical_size_mm");
        (self.upper_mm.powi(2) - part("head_upper_mm").powi(2) + typical.powi(2))
            .max(0.0)
            .sqrt()
    }
}

/// A line of plain CSV.
fn csv_line(values: &[f64]) -> String {
    let v: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
    v.join(",") + "\n"
}

/// The campaign of `config` on the true machine of `seed`, written in
/// `dir`: the internal data and every external file, and the request that
/// calibrates from them.
fn campaign(
    config: &Config,
    plans: &Plans,
    seed: u64,
    dir: &Path,
) -> (TrueMachine, CalibrateRequest, Vec<LegEffect>) {
    let nominal = Machine::paper();
    let effects: Vec<LegEffect> = if config.leg_effects {
        vec![leg_effect(seed, &nominal)]
    } else {
        Vec::new()
    };
    let joints = |truth: &TrueMachine, q: &[f64; 3]| {
        truth.forward_lengths(&truth.delivered_lengths(q, &effects))
    };
    let truth = config.machines.truth(seed);
    let mut rng = Pcg64Mcg::seed_from_u64(seed.wrapping_mul(0x9e37_79b9) ^ 0xf05e);
    let poses = config.machines.internal_poses(&mut rng);
    let rows: Vec<Row> = nominal
        .workspace
        .random_poses(poses, seed ^ 0x5eed)
        .iter()
        .filter_map(|r| nominal.inverse(r).ok().map(|s| s.legs_mm))
        .map(|q| Row {
            commands_mm: q,
            readings: truth.sensed(
                &joints(&truth, &q),
                &tricept_truth::SensorNoise::DOCUMENTED,
                &mut rng,
            ),
            temp_c: None,
            directions: None,
        })
        .collect();
    let internal = dir.join(format!("internal-{seed}.csv"));
    std::fs::write(&internal, to_csv(&rows)).unwrap();
    let mut x = FusedSources::default();
    if let Some((k, target, chosen)) = config.tracker {
        let station = TrueTracker::random(seed);
        let offset = target.offset_mm();
        let mut text = String::from("q1,q2,q3,h1,h2,x,y,z,extension_mm\n");
        for p in poses_of(plans, Instrument::Tracker, k, chosen, seed) {
            let at = truth.spindle_point_at(&joints(&truth, &p.q), p.h, p.extension_mm, &offset);
            let y = station.measure(&at, &mut rng);
            text.push_str(&csv_line(&[
                p.q[0],
                p.q[1],
                p.q[2],
                p.h[0],
                p.h[1],
                y[0],
                y[1],
                y[2],
                p.extension_mm,
            ]));
        }
        let path = dir.join(format!("tracker-{seed}.csv"));
        std::fs::write(&path, text).unwrap();
        x.tracker = vec![path];
        x.tracker_target = Some(target.spec());
    }
    if let Some((k, chosen)) = config.ballbar {
        let bar = TrueBallbar {
            pivot_mm: Vector3::from(PIVOT_MM)
                + Vector3::from_fn(|_, _| 0.5 * normal(&mut rng).clamp(-3.0, 3.0)),
            sigma_um: 1.0,
        };
        let mut text = String::from("q1,q2,q3,h1,h2,length\n");
        for p in poses_of(plans, Instrument::Ballbar, k, chosen, seed) {
            let ball = Vector3::from(config.ball_mm);
            let length = bar.read(&truth, &p.q, p.h, &ball, &effects, &mut rng);
            text.push_str(&csv_line(&[p.q[0], p.q[1], p.q[2], p.h[0], p.h[1], length]));
        }
        let path = dir.join(format!("ballbar-{seed}.csv"));
        std::fs::write(&path, text).unwrap();
        x.ballbar = vec![path];
        if config.ball_mm != [0.0; 3] {
            x.ballbar_ball_mm = Some(Triple(config.ball_mm));
        }
    }
    if let Some(k) = config.touch {
        let sphere = TrueSphere {
            centre_mm: Vector3::from(SPHERE_MM)
                + Vector3::from_fn(|_, _| 0.5 * normal(&mut rng).clamp(-3.0, 3.0)),
            radius_mm: SPHERE_RADIUS_MM,
            stylus_mm: STYLUS_MM + 1.5e-3 * normal(&mut rng),
            sigma_um: 1.5,
            beyond_tip_mm: config.touch_beyond_mm,
        };
        let mut text = String::from("q1,q2,q3,h1,h2,feature\n");
        for p in plans.of(Instrument::Touch, k) {
            let q = sphere.touch(&truth, &p.q, p.h, &effects, &mut rng).unwrap();
            text.push_str(&csv_line(&[q[0], q[1], q[2], p.h[0], p.h[1], 1.0]));
        }
        let path = dir.join(format!("touch-{seed}.csv"));
        std::fs::write(&path, text).unwrap();
        let features = dir.join(format!("features-{seed}.json"));
        std::fs::write(
            &features,
            format!(
                r#"{{"stylus": {{"radius_mm": {STYLUS_MM:?}, "radius_sigma_um": 2.0}}, "features": [{{"id": 1, "kind": "sphere", "radius_mm": {SPHERE_RADIUS_MM:?}, "radius_sigma_um": 0.5}}]}}"#
            ),
        )
        .unwrap();
        x.touch = vec![path];
        x.features = Some(features);
    }
    let mut request = CalibrateRequest::new(DataInput::File(internal));
    request.robust = config.robust;
    request.fused = Some(x);
    request.for_machine_file = true;
    (truth, request, effects)
}

/// Held-out tool poses: the documented machine's tool tip and axis at
/// random platform points, `h1` anywhere, `h2` 15-35 deg (the evaluation
/// poses' range).
fn targets(seed: u64) -> Vec<[f64; 6]> {
    let documented = TrueMachine::documented();
    let nominal = Machine::paper();
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x07a2_6e75);
    nominal
        .workspace
        .random_poses(TARGETS, seed ^ 0x7a46)
        .iter()
        .filter_map(|r| nominal.inverse(r).ok().map(|s| s.legs_mm))
        .map(|q| {
            let h = [
                std::f64::consts::TAU * rng.random::<f64>(),
                (15.0 + 20.0 * rng.random::<f64>()).to_radians(),
            ];
            let tip = documented.spindle_point(&q, h, 0.0, &Vector3::zeros());
            let axis = documented.tool_axis(&q, h);
            [tip.x, tip.y, tip.z, axis.x, axis.y, axis.z]
        })
        .collect()
}

/// The rms tool-tip error after touch-off the true machine delivers when
/// commanded with the machine file `file` through the door's `tool-ik`.
fn delivered(file: &Path, truth: &TrueMachine, effects: &[LegEffect], targets: &[[f64; 6]]) -> f64 {
    let loaded = load_machine(Some(file), &SensorNoise::default()).unwrap();
    let errors: Vec<Vector3<f64>> = targets
        .iter()
        .filter_map(|t| {
            let s = solve_point(KinematicsVerb::ToolIk, &loaded, t).ok()?;
            let v: Vec<f64> = s
                .cells()
                .iter()
                .map(|c| c.to_json().as_f64().unwrap_or(f64::NAN))
                .collect();
            let keys = KinematicsVerb::ToolIk.keys();
            let at = |k: &str| v[keys.iter().position(|x| *x == k).unwrap()];
            let q = [at("q1"), at("q2"), at("q3")];
            let h = [at("h1"), at("h2")];
            Some(
                truth.spindle_point_at(
                    &truth.forward_lengths(&truth.delivered_lengths(&q, effects)),
                    h,
                    0.0,
                    &Vector3::zeros(),
                ) - Vector3::new(t[0], t[1], t[2]),
            )
        })
        .collect();
    assert!(
        errors.len() > targets.len() / 2,
        "{} targets reached",
        errors.len()
    );
    let n = errors.len() as f64;
    let mean = errors.iter().sum::<Vector3<f64>>() / n;
    (errors
        .iter()
        .map(|e| (e - mean).norm_squared())
        .sum::<f64>()
        / n)
        .sqrt()
}

/// Calibrates `config` on machine `seed`, writes the file (`force`: even
/// when refused) and measures it.
fn run(config: &Config, plans: &Plans, seed: u64, dir: &Path, force: bool) -> Outcome {
    let (truth, request, effects) = campaign(config, plans, seed, dir);
    let c = calibrate(request).unwrap();
    let json = c.to_json();
    // TRICEPT_FUSED_DUMP=SEED prints the true machine and the calibration's
    // JSON of machine SEED (how a file beyond its promise is looked into).
    if std::env::var("TRICEPT_FUSED_DUMP").ok() == Some(seed.to_string()) {
        eprintln!(
            "DUMP {}\n{truth:#?}\n{}",
            config.name(),
            serde_json::to_string_pretty(&json).unwrap()
        );
    }
    let a = &json["accuracy"];
    assert_eq!(a["point"], "tool tip", "{a}");
    let mut outcome = Outcome {
        seed,
        exit: c.exit_code(),
        rms_mm: a["rms_mm"].as_f64().unwrap(),
        upper_mm: a["upper_mm"].as_f64().unwrap(),
        delivered_mm: f64::NAN,
        parts: a["parts"].clone(),
        unchecked: json["unchecked"].clone(),
    };
    if outcome.exit != 0 && !force {
        return outcome;
    }
    let file: PathBuf = dir.join(format!("fused-{seed}.json"));
    c.write_machine(&file, tricept_ident::WriteOptions::default().force(force))
        .unwrap();
    let loaded = load_machine(Some(&file), &SensorNoise::default()).unwrap();
    let promise = loaded
        .description()
        .calibration
        .as_ref()
        .unwrap()
        .accuracy
        .clone()
        .unwrap();
    assert_eq!(
        (promise.rms_mm, promise.upper_mm),
        (outcome.rms_mm, outcome.upper_mm),
        "the file promises what the JSON says"
    );
    outcome.delivered_mm = delivered(&file, &truth, &effects, &targets(seed));
    outcome
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-fused-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The tally of `seeds` per configuration: prints one TALLY line each and
/// returns (files written at exit 0, within the promise, beyond 2x).
fn tally(seeds: std::ops::Range<u64>, leg_effects: bool, dir: &Path) -> (usize, usize, usize) {
    let configs: Vec<(u64, Config)> = (0..)
        .zip(configurations())
        .map(|(i, c)| (i, Config { leg_effects, ..c }))
        .collect();
    tally_of(&configs, seeds, "", dir)
}

/// The tally of `seeds` for each of `configs` (`(i, config)`: machine
/// `100 i + seed`), the TALLY lines named with `label`: (files written at
/// exit 0, within the promise, beyond 2x).
fn tally_of(
    configs: &[(u64, Config)],
    seeds: std::ops::Range<u64>,
    label: &str,
    dir: &Path,
) -> (usize, usize, usize) {
    let plans = Plans::new(dir);
    let (mut written, mut within, mut beyond, mut typical) = (0, 0, 0, 0);
    for (i, config) in configs {
        let outcomes: Vec<Outcome> = seeds
            .clone()
            .map(|s| run(config, &plans, 100 * i + s, dir, false))
            .collect();
        for o in &outcomes {
            eprintln!(
                "{}: seed {} exit {} rms {:.4} upper {:.4} delivered {:.4} ratio {:.2} {} unchecked {}",
                config.name(),
                o.seed,
                o.exit,
                o.rms_mm,
                o.upper_mm,
                o.delivered_mm,
                o.delivered_mm / o.upper_mm,
                o.parts,
                o.unchecked
            );
        }
        let ok: Vec<&Outcome> = outcomes.iter().filter(|o| o.exit == 0).collect();
        let w = ok.iter().filter(|o| o.delivered_mm <= o.upper_mm).count();
        let b = ok
            .iter()
            .filter(|o| o.delivered_mm > 2.0 * o.upper_mm)
            .count();
        // The promise with the head parts the data cannot calibrate at their
        // typical size (before issue 30, item 1).
        let typical_within = ok
            .iter()
            .filter(|o| o.delivered_mm <= o.typical_upper_mm())
            .count();
        let worst = ok
            .iter()
            .map(|o| o.delivered_mm / o.upper_mm)
            .fold(0.0, f64::max);
        println!(
            "TALLY {}{}: machines {}, written (exit 0) {}, within upper_mm {w}, beyond 2x {b}, worst delivered/upper {worst:.2}; head at its typical size: within {typical_within}",
            config.name(),
            if config.leg_effects {
                " + leg effect"
            } else {
                ""
            },
            outcomes.len(),
            ok.len()
        );
        written += ok.len();
        within += w;
        beyond += b;
        typical += typical_within;
    }
    println!(
        "TALLY fused{label}: written (exit 0) {written}, within upper_mm {within}, beyond 2x {beyond}; head at its typical size: within {typical}"
    );
    (written, within, beyond)
}

/// The tally of 30 machines per configuration (`leg_effects`: with a
/// static leg effect hidden): at least 95 % within, none beyond 2x.
fn tally_of_30(name: &str, leg_effects: bool) {
    let dir = scratch(name);
    let (written, within, beyond) = tally(0..30, leg_effects, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(written > 0);
    assert!(
        within as f64 >= 0.95 * written as f64,
        "{within} of {written}"
    );
    assert_eq!(beyond, 0);
}

#[test]
#[ignore = "the fused tally of docs/reliability.md: 30 machines per configuration"]
fn fused_files_keep_their_promise_tally() {
    tally_of_30("tally", false);
}

#[test]
fn one_fused_file_per_configuration_keeps_its_promise() {
    let dir = scratch("ci");
    let (written, within, beyond) = tally(0..2, false, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(written >= 16, "{written} of 24 files written");
    assert!(
        written - within <= 1,
        "{within} of {written} within the promise"
    );
    assert_eq!(beyond, 0, "a file delivered beyond twice its promise");
}

/// A good k = 12 tracker campaign (target at the tip) with the first
/// `touches` planned touch-offs, the probe's stylus centre `beyond_mm`
/// beyond the tip.
fn twelve_points_and_touches(touches: usize, beyond_mm: f64) -> Config {
    Config {
        touch_beyond_mm: beyond_mm,
        ..Config::of(Some((12, Target::Tip, Poses::Planned)), None, Some(touches))
    }
}

/// The JSON of a source by kind.
fn source<'a>(json: &'a serde_json::Value, kind: &str) -> &'a serde_json::Value {
    json["sources"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["kind"] == kind)
        .unwrap()
}

#[test]
fn touches_that_cannot_be_checked_but_agree_with_the_tracker_are_deployed_and_named() {
    let dir = scratch("unchecked");
    let plans = Plans::new(&dir);
    // 24 planned touch-offs beside 12 tracker points: checkable here, exit 0.
    let o = run(&twelve_points_and_touches(24, 0.0), &plans, 7, &dir, false);
    assert_eq!(o.exit, 0, "{o:?}");
    assert!(o.delivered_mm <= o.upper_mm, "{o:?}");
    // 8 and 12 of them: too few to be checked on their own, but they agree
    // with the tracker's checked fit: exit 0, the touches named unchecked
    // in the JSON and the report, their part in the promise, and the file
    // within it in truth.
    for (touches, seed) in [(8, 7), (12, 8)] {
        let config = twelve_points_and_touches(touches, 0.0);
        let (_, request, _) = campaign(&config, &plans, seed, &dir);
        let c = calibrate(request).unwrap();
        let json = c.to_json();
        assert_eq!(source(&json, "touch")["checkable"], false, "{json}");
        assert_eq!(source(&json, "tracker")["checkable"], true, "{json}");
        assert_eq!(c.exit_code(), 0, "{touches} touches: {}", c.report());
        let u = &json["unchecked"];
        assert_eq!(u["sources"][0], "touch", "{u}");
        assert_eq!(u["agrees_with_checked_fit"], true, "{u}");
        let parts = &json["accuracy"]["parts"];
        assert_eq!(
            parts["unchecked_upper_mm"], u["unchecked_upper_mm"],
            "{parts}"
        );
        assert!(
            c.report()
                .lines()
                .take(3)
                .any(|l| l
                    .starts_with("unchecked: touch cannot be checked on its own; it agrees with")),
            "{}",
            c.report()
        );
        // The cannot-be-checked warning stays: it says what is unchecked.
        assert!(
            c.warnings().iter().any(|w| w.contains("cannot be checked")),
            "{:?}",
            c.warnings()
        );
        let o = run(&config, &plans, seed, &dir, false);
        assert_eq!(o.exit, 0);
        assert!(o.delivered_mm <= o.upper_mm, "{o:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn touches_that_disagree_with_the_tracker_are_still_refused() {
    // The probe's stylus centre 0.3 mm beyond the tip the tracker's nest
    // holds: the touches say the tool is longer than the tracker says.
    let dir = scratch("disagree");
    let plans = Plans::new(&dir);
    let (_, request, _) = campaign(&twelve_points_and_touches(12, 0.3), &plans, 8, &dir);
    let c = calibrate(request).unwrap();
    let json = c.to_json();
    assert_eq!(c.exit_code(), 3, "{}", c.report());
    assert_eq!(source(&json, "touch")["checkable"], false, "{json}");
    assert_eq!(
        json["unchecked"]["agrees_with_checked_fit"],
        false,
        "{:?} {}",
        c.reason(),
        json["warnings"]
    );
    let why = c.reason().unwrap();
    assert!(
        why.contains("touch cannot be checked") && why.contains("disagree with the checked fit"),
        "{why}"
    );
    let file = dir.join("m.json");
    assert!(
        c.write_machine(&file, tricept_ident::WriteOptions::default())
            .is_err()
    );
    assert!(!file.exists());
    // A tracker that cannot be checked beside the internal data alone (which
    // do not see the head): nothing outside the machine checks it, refused.
    let config = Config::of(Some((6, Target::Tip, Poses::Planned)), None, None);
    let (_, request, _) = campaign(&config, &plans, 8, &dir);
    let c = calibrate(request).unwrap();
    let json = c.to_json();
    assert_eq!(source(&json, "tracker")["checkable"], false, "{json}");
    assert_eq!(c.exit_code(), 3, "{}", c.report());
    assert!(json["unchecked"].is_null(), "{}", json["unchecked"]);
    // A disagreement of 0.05 mm the test cannot see: written, the shift the
    // touches bring in the promise, and the file within it in truth.
    let o = run(&twelve_points_and_touches(12, 0.05), &plans, 8, &dir, false);
    assert_eq!(o.exit, 0, "{o:?}");
    assert!(o.parts["unchecked_mm"].as_f64().unwrap() > 0.005, "{o:?}");
    assert!(o.delivered_mm <= o.upper_mm, "{o:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
#[ignore = "the fused tally with a leg effect of docs/reliability.md: 30 machines per configuration"]
fn fused_files_with_a_leg_effect_keep_their_promise_tally() {
    tally_of_30("tally-effects", true);
}
