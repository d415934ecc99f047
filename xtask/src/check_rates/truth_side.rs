//! The data side of `cargo xtask check-rates`: true machines and their
//! campaigns from `tricept-truth` alone (never the plant's effect code).
//! The door (`tricept-ident`) only calibrates, plans the check's poses and
//! turns leg commands of the nominal machine into targets' commands, as a
//! user's controller would.
//!
//! - [`Calibrated`]: a true machine, calibrated by the door's `identify`
//!   (the mean of 3 readings at 80 random poses, logged at 20 °C) and
//!   written as a sealed machine file, with the check's planned poses at
//!   each pose count;
//! - [`Scenario`]: what happened to the machine and its sensors before a
//!   check (a change, more noise, a jittery temperature log, a bad reading);
//! - [`Calibrated::campaign`]: one check campaign of a scenario, as the
//!   documented CSV rows.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use tricept_ident::LoadedMachine;
use tricept_ident::advanced::{SensorNoise, load_machine};
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::plan::{Instrument, PlanRequest, plan};
use tricept_ident::{DataInput, MachineInput};
use tricept_truth::{ARCSEC_PER_RAD, Row, TrueMachine, normal, to_csv};

/// Temperature of the calibration campaign, °C.
pub const CALIBRATION_C: f64 = 20.0;
/// Growth of the structure and of the legs (steel), ppm/K.
pub const STEEL_PPM_PER_K: f64 = 11.5;
/// Poses of the calibration campaign.
pub const CALIBRATION_POSES: usize = 80;

/// A gross error in one reading of one pose of the campaign.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BadReading {
    /// The scale's reading off by this much, um.
    ScaleUm(f64),
    /// The first encoder's reading (`phi`) off by this much, arcsec.
    PhiArcsec(f64),
}

/// What changed in the machine since its calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Change {
    /// Nothing.
    None,
    /// One leg (the campaign's index mod 3) slipped by 20-25 um, either sign.
    LegSlip,
    /// One joint (base `B1..B3` or platform `A1..A3`, by the campaign's
    /// index mod 6) moved by 50-60 um in a random direction.
    JointMoved,
    /// Two legs (a pair by the campaign's index) slipped by +25 and -25 um.
    TwoLegs,
    /// The legs `kelvin` K warmer than at the calibration (11.5 ppm/K).
    WarmLegs(f64),
    /// The whole structure (joints and legs) `kelvin` K warmer.
    WarmStructure(f64),
}

/// What happened before one check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario {
    /// How the table names it.
    pub name: &'static str,
    /// The change of the machine.
    pub change: Change,
    /// The sensors' noise as a multiple of the stated one.
    pub noise_factor: f64,
    /// Standard deviation of the logged temperature about the true one, K
    /// (each pose's own).
    pub temp_jitter_k: f64,
    /// One bad reading at a random pose.
    pub bad: Option<BadReading>,
}

impl Scenario {
    /// Nothing changed, nothing unusual: the reference scenario.
    pub const fn unchanged(name: &'static str) -> Scenario {
        Scenario {
            name,
            change: Change::None,
            noise_factor: 1.0,
            temp_jitter_k: 0.0,
            bad: None,
        }
    }

    /// `change` at the stated noise with a precise temperature log.
    pub const fn changed(name: &'static str, change: Change) -> Scenario {
        Scenario {
            change,
            ..Scenario::unchanged(name)
        }
    }
}

/// The campaign's truth of a scenario: the candidate names a correct check
/// gives (empty when nothing changed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Hidden {
    /// Names of the changed candidates (`leg 2`, `base joint B1`,
    /// `thermal growth`), empty when nothing changed.
    pub names: Vec<String>,
    /// A line describing the hidden change and its size.
    pub text: String,
    /// The row (0-based) with the bad reading, if any.
    pub bad_row: Option<usize>,
}

/// A true machine, its calibration and the check's planned poses.
#[derive(Debug, Clone)]
pub struct Calibrated {
    /// The seed the machine was drawn from.
    pub seed: u64,
    /// The true machine.
    pub truth: TrueMachine,
    /// The calibrated machine file as the door loads it.
    pub loaded: LoadedMachine,
    /// The planned check poses per pose count: (count, commands).
    pub planned: Vec<(usize, Vec<[f64; 3]>)>,
}

/// The commands `q1..q3` of every data line of a check plan's output
/// (`x,y,z,q1,q2,q3`).
fn planned_commands(text: &str) -> Result<Vec<[f64; 3]>, String> {
    let mut out = Vec::new();
    for line in text.lines() {
        if line.starts_with('#') || line.starts_with('x') || line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split(',')
            .map(|f| f.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("planned poses: {line}: {e}"))?;
        if v.len() != 6 {
            return Err(format!("planned poses: {line}: expected x,y,z,q1,q2,q3"));
        }
        out.push([v[3], v[4], v[5]]);
    }
    Ok(out)
}

impl Calibrated {
    /// Draws true machine `seed` (module errors N(0, 0.25 mm)), calibrates
    /// it with the door's identify from 80 random poses (files in `dir`),
    /// and plans its check at each of `pose_counts`.
    pub fn new(seed: u64, dir: &Path, pose_counts: &[usize]) -> Result<Calibrated, String> {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let truth = TrueMachine::random(0.0, seed);
        let nominal = load_machine(None, &SensorNoise::default()).map_err(|e| e.to_string())?;
        let m = nominal.geometry();
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0xca11_b4a7);
        let rows = m
            .workspace
            .random_poses(CALIBRATION_POSES, seed)
            .iter()
            .map(|r| {
                let q = m.inverse(r).map_err(|e| e.to_string())?.legs_mm;
                Ok(Row {
                    commands_mm: q,
                    readings: truth.readings(&q, &mut rng),
                    temp_c: Some(CALIBRATION_C),
                    directions: None,
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        let data: PathBuf = dir.join("cal.csv");
        let machine_file = dir.join("cal.json");
        std::fs::write(&data, to_csv(&rows)).map_err(|e| format!("{}: {e}", data.display()))?;
        let mut request = CalibrateRequest::new(DataInput::File(data.clone()));
        request.for_machine_file = true;
        let calibration = calibrate(request).map_err(|e| format!("machine {seed}: {e}"))?;
        calibration
            .write_machine(&machine_file, tricept_ident::WriteOptions::default())
            .map_err(|e| format!("machine {seed}: identify: {e}"))?;
        let loaded = load_machine(Some(&machine_file), &SensorNoise::default())
            .map_err(|e| e.to_string())?;
        let mut planned = Vec::new();
        for &k in pose_counts {
            let out = dir.join(format!("check-{k}.csv"));
            let mut r = PlanRequest::new(Instrument::Check);
            r.machine = MachineInput::from(machine_file.clone());
            r.k = vec![k];
            r.out = Some(out.clone());
            let p = plan(r).map_err(|e| format!("machine {seed}: plan: {e}"))?;
            p.write_out(&out).map_err(|e| e.to_string())?;
            let text =
                std::fs::read_to_string(&out).map_err(|e| format!("{}: {e}", out.display()))?;
            planned.push((k, planned_commands(&text)?));
        }
        Ok(Calibrated {
            seed,
            truth,
            loaded,
            planned,
        })
    }

    /// The planned commands of the `poses`-pose check.
    pub fn commands(&self, poses: usize) -> Option<&[[f64; 3]]> {
        self.planned
            .iter()
            .find(|(k, _)| *k == poses)
            .map(|(_, c)| c.as_slice())
    }

    /// One check campaign of `scenario` at `commands`, seeded by `rng`;
    /// `index` picks the leg, joint or pair that changed. The sensors are
    /// re-referenced (every zero moved by up to 0.01 rad and 5 mm), as
    /// after a power cycle.
    pub fn campaign(
        &self,
        scenario: &Scenario,
        commands: &[[f64; 3]],
        index: usize,
        rng: &mut Pcg64Mcg,
    ) -> (Vec<Row>, Hidden) {
        let mut day = self.truth.clone();
        for (c, span) in [0.01, 0.01, 5.0].into_iter().enumerate() {
            day.sensor_offsets[c] += span * (2.0 * rng.random::<f64>() - 1.0);
        }
        let mut slips_mm = [0.0; 3];
        let mut warm_k = 0.0;
        let (names, text): (Vec<String>, String) = match scenario.change {
            Change::None => (Vec::new(), "nothing".into()),
            Change::LegSlip => {
                let leg = index % 3;
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                let um = sign * (20.0 + 5.0 * rng.random::<f64>());
                slips_mm[leg] = um * 1e-3;
                (
                    vec![format!("leg {}", leg + 1)],
                    format!("leg {} {um:+.1} um", leg + 1),
                )
            }
            Change::JointMoved => {
                let joint = index % 6;
                let um = 50.0 + 10.0 * rng.random::<f64>();
                let d = Vector3::from_fn(|_, _| normal(rng)).normalize() * um * 1e-3;
                let name = if joint < 3 {
                    day.base[joint] += d;
                    format!("base joint B{}", joint + 1)
                } else {
                    day.platform[joint - 3] += d;
                    format!("platform joint A{}", joint - 2)
                };
                (vec![name.clone()], format!("{name} {um:.1} um"))
            }
            Change::TwoLegs => {
                let (a, b) = [(0, 2), (0, 1), (1, 2)][index % 3];
                slips_mm[a] = 0.025;
                slips_mm[b] = -0.025;
                (
                    vec![format!("leg {}", a + 1), format!("leg {}", b + 1)],
                    format!("leg {} +25 um, leg {} -25 um", a + 1, b + 1),
                )
            }
            Change::WarmLegs(k) | Change::WarmStructure(k) => {
                warm_k = k;
                if matches!(scenario.change, Change::WarmStructure(_)) {
                    day = day.warmed(STEEL_PPM_PER_K, k);
                }
                (vec!["thermal growth".into()], format!("{k} K warmer"))
            }
        };
        let noise = tricept_truth::SensorNoise::DOCUMENTED.times(scenario.noise_factor);
        let mut rows: Vec<Row> = commands
            .iter()
            .map(|q| {
                let grown = day.warm_lengths(q, STEEL_PPM_PER_K, [warm_k; 3]);
                let lengths = std::array::from_fn(|i| grown[i] + slips_mm[i]);
                let joints = day.forward_lengths(&lengths);
                Row {
                    commands_mm: *q,
                    readings: day.sensed(&joints, &noise, rng),
                    temp_c: Some(CALIBRATION_C + warm_k + scenario.temp_jitter_k * normal(rng)),
                    directions: None,
                }
            })
            .collect();
        let mut bad_row = None;
        if let Some(bad) = scenario.bad {
            let i = rng.random_range(0..rows.len().max(1));
            if let Some(row) = rows.get_mut(i) {
                match bad {
                    BadReading::ScaleUm(um) => row.readings[2] += um * 1e-3,
                    BadReading::PhiArcsec(a) => row.readings[0] += a / ARCSEC_PER_RAD,
                }
                bad_row = Some(i);
            }
        }
        (
            rows,
            Hidden {
                names,
                text,
                bad_row,
            },
        )
    }
}
