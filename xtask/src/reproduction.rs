//! `cargo xtask reproduction`: the numbers behind the corrections of
//! `docs/reproduction.md` and `docs/identifiability.md`, each section a
//! table printed with the command that reproduces it.
//!
//! - `singular`: the size of the unidentifiable direction of the x-first
//!   machine (the report's singular value, and the raw Jacobian column);
//! - `invisible`: the rule for the invisible platform joint
//!   ([`tricept_study::invisible`]) against the identifiability report, over
//!   joint placements, both U-joint conventions and both parameter sets;
//! - `noise`: the paper's differenced, unweighted solve split into its
//!   error sources (noise-free, encoders only, scale only);
//! - `fig3b`: the compensated middle plane of Fig. 3 with the paper's solve
//!   (exact readings, exact compensation, many noise seeds);
//! - `poses`: the spread of `mu` over many random pose sets of each size;
//! - `differencing`: what differencing against a reference pose costs
//!   against estimating the sensor offsets, per grade and reference pose,
//!   with the differenced rows treated as independent and with their
//!   covariance;
//! - `held`: what holding the invisible `dyA3` at zero biases, by campaign
//!   size: the bias of every other parameter in its standard deviations
//!   (exact noise-free readings, held at zero against held at the truth)
//!   and the Mahalanobis distance of noisy fits from the truth.
//!
//! Seeded and reproducible; all sections together take about 20 s on two
//! cores (release build), `poses` most of it.

use std::path::PathBuf;

use nalgebra::Vector3;
use rayon::prelude::*;
use serde_json::{Value, json};
use tricept_engine::{IdentifyOptions, identify::design, model::GeometricModel};
use tricept_ident::advanced::ParameterSet;
use tricept_kinematics::{
    Machine, MachineDescription, description::AxisOrder, description::Placement,
};
use tricept_model::{params::residual_mu, volumetric::MapStats};
use tricept_numerics::stats::quantile;
use tricept_study::grades::mu_at_grade;
use tricept_study::invisible::invisible_platform_errors;
use tricept_study::paper::{Differenced, DifferencedSolve, NominalLinearisation, RowWeights};
use tricept_study::{
    Scenario, StudyError, fast::GradeModel, fast::LinearEstimator, results::Summary,
};

/// The paper's Fig. 3b figures (max, min, mean after compensation), mm.
const PAPER_AFTER_MM: [f64; 3] = [0.278, 0.171, 0.203];
/// The paper's `mu` at 4 arcsec, mm.
const PAPER_MU_AT_4: f64 = 0.291;
/// The paper's encoder noise, arcsec.
const PAPER_GRADE: f64 = 0.8;

/// The sections, in the order they run.
const SECTIONS: [&str; 7] = [
    "singular",
    "invisible",
    "noise",
    "fig3b",
    "poses",
    "differencing",
    "held",
];

/// Options of `cargo xtask reproduction`.
#[derive(Debug, clap::Args)]
pub struct ReproductionArgs {
    /// Sections to run (comma separated; default all): singular, invisible,
    /// noise, fig3b, poses, differencing, held.
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Fast-path trials per estimator and grade (noise, differencing).
    #[arg(long, default_value_t = 20_000)]
    trials: usize,
    /// Random pose sets per size (poses).
    #[arg(long, default_value_t = 200)]
    sets: u64,
    /// Fast-path trials per pose set and grade (poses).
    #[arg(long, default_value_t = 2000)]
    set_trials: usize,
    /// Noise seeds of the Fig. 3b maps.
    #[arg(long, default_value_t = 200)]
    seeds: u64,
    /// Noisy campaigns per size (held).
    #[arg(long, default_value_t = 20)]
    held_campaigns: u64,
    /// Seed of all Monte Carlo noise.
    #[arg(long, default_value_t = 2009)]
    seed: u64,
    /// Output directory of `reproduction.json`.
    #[arg(long, default_value = "target/reproduction")]
    out: PathBuf,
}

fn s(e: StudyError) -> String {
    e.to_string()
}

/// The two machines of the paper's Table 1: x-first (its eq. 8) and y-first.
fn machines() -> [(AxisOrder, Machine); 2] {
    [AxisOrder::XFirst, AxisOrder::YFirst].map(|o| (o, Machine::paper().with_axis_order(o)))
}

/// The default pose set (`grid`, 75 poses).
fn default_targets(m: &Machine) -> Vec<Vector3<f64>> {
    m.workspace.polar_grid(3, 8, 3)
}

fn median(v: &[f64]) -> f64 {
    Summary::of(v).median
}

fn q(v: &[f64], p: f64) -> f64 {
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    quantile(&sorted, p)
}

/// Runs the chosen sections, prints their tables and writes the JSON.
pub fn run(a: ReproductionArgs) -> Result<(), String> {
    let started = std::time::Instant::now();
    if let Some(bad) = a.only.iter().find(|o| !SECTIONS.contains(&o.as_str())) {
        return Err(format!(
            "--only: unknown section `{bad}` (one of {})",
            SECTIONS.join(", ")
        ));
    }
    if a.trials == 0 || a.set_trials == 0 || a.sets == 0 || a.seeds == 0 || a.held_campaigns == 0 {
        return Err(
            "--trials, --set-trials, --sets, --seeds and --held-campaigns must be at least 1"
                .into(),
        );
    }
    let wanted = |name: &str| a.only.is_empty() || a.only.iter().any(|o| o == name);
    let mut report = serde_json::Map::new();
    for name in SECTIONS.into_iter().filter(|n| wanted(n)) {
        let t = std::time::Instant::now();
        let value = match name {
            "singular" => singular()?,
            "invisible" => invisible()?,
            "noise" => noise(&a)?,
            "fig3b" => fig3b(&a)?,
            "poses" => poses(&a)?,
            "held" => held(&a)?,
            _ => differencing(&a)?,
        };
        println!("\n({name}: {:.1} s)", t.elapsed().as_secs_f64());
        report.insert(name.to_string(), value);
    }
    report.insert(
        "config".into(),
        json!({"trials": a.trials, "sets": a.sets, "set_trials": a.set_trials,
               "seeds": a.seeds, "seed": a.seed,
               "elapsed_s": started.elapsed().as_secs_f64()}),
    );
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let path = a.out.join("reproduction.json");
    let text = serde_json::to_string_pretty(&Value::Object(report)).map_err(|e| e.to_string())?;
    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    println!(
        "\nwrote {} in {:.1} s",
        path.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The report's smallest singular value relative to the largest, and the
/// norm of each parameter's noise-weighted Jacobian column relative to the
/// largest, on the default pose set with the paper's noise.
fn singular() -> Result<Value, String> {
    println!("## The unidentifiable direction (`cargo xtask reproduction --only singular`)\n");
    println!(
        "| U joint | rank | s_min / s_max (report) | weakest column | its weighted column norm / largest |\n|---|---|---|---|---|"
    );
    let mut out = Vec::new();
    for (order, m) in machines() {
        let sc = Scenario::paper(m.clone(), default_targets(&m)).map_err(s)?;
        let model = GeometricModel::new(m.clone(), sc.set.clone());
        let options = IdentifyOptions::for_machine(&m);
        let d = design(&model, &vec![0.0; sc.set.len()], &sc.clean, &options)
            .map_err(|e| e.to_string())?;
        let sv = &d.report().singular_values;
        let ratio = sv.last().copied().unwrap_or(0.0) / sv.first().copied().unwrap_or(1.0);
        let lin = NominalLinearisation::new(&sc).map_err(s)?;
        let sigma = options.sigma;
        let norms: Vec<f64> = (0..sc.set.len())
            .map(|t| {
                (0..lin.rows())
                    .map(|r| (lin.jacobian[(r, t)] / sigma[r % 3]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        let largest = norms.iter().copied().fold(0.0, f64::max);
        let (weakest, norm) = norms
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, n)| (sc.set.names()[i].clone(), n / largest))
            .unwrap_or_default();
        println!(
            "| {order} | {} | {ratio:.1e} | {weakest} | {norm:.1e} |",
            d.rank()
        );
        out.push(json!({"axis_order": order.to_string(), "rank": d.rank(),
                        "singular_values": sv, "smallest_over_largest": ratio,
                        "weakest_column": weakest, "weakest_column_norm_over_largest": norm}));
    }
    println!(
        "\nColumns below {:.0e} of the largest are rounding noise and are zeroed before the SVD (`tricept_numerics::lsq::ZERO_COLUMN`).",
        tricept_numerics::lsq::ZERO_COLUMN
    );
    Ok(Value::Array(out))
}

/// The Table 1 machine with the joints at `angles_deg` and the U joint `order`.
fn placed_machine(angles_deg: [f64; 3], order: AxisOrder) -> Result<Machine, String> {
    let mut d = MachineDescription::paper();
    if let Placement::Circular(c) = &mut d.placement {
        c.joint_angles_deg = angles_deg;
    }
    d.up_limb.axis_order = order;
    d.build().map_err(|e| e.to_string())
}

/// Whether a combination is one parameter alone (every other coefficient
/// below 1e-6 of the largest, which is 1).
fn single_term(c: &tricept_engine::report::Combination) -> Option<String> {
    let others = c.terms.iter().skip(1).all(|(_, v)| v.abs() < 1e-6);
    (others && !c.terms.is_empty()).then(|| c.terms[0].0.clone())
}

/// The rule for the invisible platform joint against the report.
fn invisible() -> Result<Value, String> {
    println!(
        "## The invisible platform joint (`cargo xtask reproduction --only invisible`)\n\nDefault pose set (75 poses), paper noise; `rule` is `tricept_study::invisible`, `report` the parameters the identifiability report finds unidentifiable on their own.\n"
    );
    println!(
        "| joint angles a1,a2,a3 (deg) | U joint | parameters | rank | rule: invisible | report: invisible alone | other unidentifiable combinations | rule holds |\n|---|---|---|---|---|---|---|---|"
    );
    let placements = [
        [120.0, 240.0, 0.0],
        [240.0, 120.0, 0.0],
        [60.0, 300.0, 180.0],
        [0.0, 120.0, 240.0],
        [90.0, 210.0, 330.0],
        [30.0, 150.0, 270.0],
        [150.0, 30.0, 270.0],
        [210.0, 330.0, 90.0],
    ];
    let mut out = Vec::new();
    let mut all_hold = true;
    for angles in placements {
        for order in [AxisOrder::XFirst, AxisOrder::YFirst] {
            let m = placed_machine(angles, order)?;
            let rule: Vec<String> = invisible_platform_errors(&m)
                .into_iter()
                .map(|e| e.parameter)
                .collect();
            let poses: Vec<tricept_data::MeasuredPose> = default_targets(&m)
                .iter()
                .map(|r| {
                    m.inverse(r).map(|ik| tricept_data::MeasuredPose {
                        commands_mm: ik.legs_mm,
                        ..Default::default()
                    })
                })
                .collect::<Result<_, _>>()
                .map_err(|e| e.to_string())?;
            for set in [ParameterSet::paper15(), ParameterSet::full21()] {
                let model = GeometricModel::new(m.clone(), set.clone());
                let report = tricept_engine::identify::identifiability(
                    &model,
                    &vec![0.0; set.len()],
                    &poses,
                    &IdentifyOptions::for_machine(&m),
                )
                .map_err(|e| e.to_string())?;
                let mut alone: Vec<String> = report
                    .unidentifiable
                    .iter()
                    .filter_map(single_term)
                    .filter(|n| n.contains('A'))
                    .collect();
                alone.sort();
                let others: Vec<String> = report
                    .unidentifiable
                    .iter()
                    .filter(|c| single_term(c).is_none_or(|n| !n.contains('A')))
                    .map(|c| c.to_text())
                    .collect();
                let mut expected = rule.clone();
                expected.sort();
                let holds = alone == expected;
                all_hold &= holds;
                let list = |v: &[String]| {
                    if v.is_empty() {
                        "-".to_string()
                    } else {
                        v.join(", ")
                    }
                };
                println!(
                    "| {:?} | {order} | {} | {}/{} | {} | {} | {} | {} |",
                    angles.map(|x| x as i32),
                    set.label(),
                    report.rank,
                    set.len(),
                    list(&rule),
                    list(&alone),
                    if others.is_empty() {
                        "-".to_string()
                    } else {
                        others.join("; ")
                    },
                    if holds { "yes" } else { "NO" }
                );
                out.push(
                    json!({"joint_angles_deg": angles, "axis_order": order.to_string(),
                                "parameters": set.label(), "rank": report.rank,
                                "rule": rule, "report_alone": alone, "other_unidentifiable": others,
                                "holds": holds}),
                );
            }
        }
    }
    println!(
        "\nThe rule {} on every row.",
        if all_hold { "holds" } else { "FAILS" }
    );
    Ok(json!({"rows": out, "all_hold": all_hold}))
}

/// The paper's solve on `m`: every parameter the report can identify (all
/// 15 on the y-first machine; on the x-first one `H^T H` is singular and
/// `dyA3` is held at zero), readings differenced against pose 0, no
/// weighting.
fn paper_like_solve(
    sc: &Scenario,
    lin: &NominalLinearisation,
) -> Result<(DifferencedSolve, Vec<usize>, bool), String> {
    let all: Vec<usize> = (0..sc.set.len()).collect();
    let unit = RowWeights::PerSensor([1.0; 3]);
    if let Differenced::Formed(solve) = DifferencedSolve::form(lin, &all, 0, unit).map_err(s)? {
        return Ok((*solve, all, true));
    }
    let ident = GradeModel::new(sc, PAPER_GRADE)
        .map_err(s)?
        .design
        .identifiable()
        .to_vec();
    match DifferencedSolve::form(lin, &ident, 0, unit).map_err(s)? {
        Differenced::Formed(solve) => Ok((*solve, ident, false)),
        Differenced::Singular { condition } => Err(format!(
            "the paper's solve on the identifiable parameters is singular (condition {condition:.1e})"
        )),
    }
}

/// The paper's solve on the default pose set of `m`, with what it needs.
struct PaperLike {
    sc: Scenario,
    lin: NominalLinearisation,
    solve: DifferencedSolve,
    /// The parameters it estimates.
    columns: Vec<usize>,
    /// Whether it estimates all 15.
    all: bool,
}

fn paper_like(m: &Machine) -> Result<PaperLike, String> {
    let sc = Scenario::paper(m.clone(), default_targets(m)).map_err(s)?;
    let lin = NominalLinearisation::new(&sc).map_err(s)?;
    let (solve, columns, all) = paper_like_solve(&sc, &lin)?;
    Ok(PaperLike {
        sc,
        lin,
        solve,
        columns,
        all,
    })
}

fn label(order: AxisOrder, all: bool) -> String {
    if all {
        format!("{order}, 15 parameters")
    } else {
        format!("{order}, 14 parameters (dyA3 held at 0)")
    }
}

/// The paper's solve split into its error sources.
fn noise(a: &ReproductionArgs) -> Result<Value, String> {
    println!(
        "## The paper's solve: where its error comes from (`cargo xtask reproduction --only noise`)\n\nDefault pose set (75 poses), scale noise 0.5 um, mean of 3 readings, {} trials per cell (same seed in every column), median `mu` (mm).\n",
        a.trials
    );
    println!(
        "| machine | condition of H^T H | grade (arcsec) | all noise | noise-free | encoders only | scale only | the same solve weighted by 1/sigma^2, all noise | ours (weighted, offsets estimated, iterated), all noise |\n|---|---|---|---|---|---|---|---|---|"
    );
    let grades = [0.25, 0.5, PAPER_GRADE, 1.0, 2.0, 4.0, 8.0];
    let mut out = Vec::new();
    for (order, m) in machines() {
        let PaperLike {
            sc,
            lin,
            solve,
            columns,
            all,
        } = paper_like(&m)?;
        let k = sc.set.len();
        let mu_of = |solve: &DifferencedSolve, sigma: [f64; 3], gi: u64| -> Result<f64, String> {
            let e = solve.estimator(&sc, &lin, sigma).map_err(s)?;
            let r = e.run(&sc, a.trials, a.seed, gi, &|_| {});
            Ok(median(&r.iter().map(|t| t.mu_mm).collect::<Vec<_>>()))
        };
        let mu = |sigma: [f64; 3], gi: u64| mu_of(&solve, sigma, gi);
        let p_star = solve.estimate(&lin, k, &flat_readings(&sc)).map_err(s)?;
        let clean = residual_mu(&sc.truth, &p_star);
        let scale_only = mu([0.0, 0.0, sc.logged_sigma(1.0)[2]], 0)?;
        for (gi, &g) in grades.iter().enumerate() {
            let sigma = sc.logged_sigma(g);
            let full = mu(sigma, gi as u64)?;
            let encoders = mu([sigma[0], sigma[1], 0.0], gi as u64)?;
            let weighted = match DifferencedSolve::form(
                &lin,
                &columns,
                0,
                RowWeights::PerSensor(sigma.map(|x| 1.0 / (x * x))),
            )
            .map_err(s)?
            {
                Differenced::Formed(w) => mu_of(&w, sigma, gi as u64)?,
                Differenced::Singular { .. } => f64::NAN,
            };
            let ours = GradeModel::new(&sc, g).map_err(s)?.estimator;
            let ours_mu = median(
                &ours
                    .run(&sc, a.trials, a.seed, gi as u64, &|_| {})
                    .iter()
                    .map(|t| t.mu_mm)
                    .collect::<Vec<_>>(),
            );
            println!(
                "| {} | {:.1e} | {g} | {full:.4} | {clean:.4} | {encoders:.4} | {scale_only:.4} | {weighted:.4} | {ours_mu:.4} |",
                label(order, all),
                solve.condition
            );
            out.push(json!({"axis_order": order.to_string(), "parameters_estimated": solve.columns.len(),
                            "condition": solve.condition, "grade_arcsec": g,
                            "mu_median_mm": full, "mu_noise_free_mm": clean,
                            "mu_encoders_only_median_mm": encoders, "mu_scale_only_median_mm": scale_only,
                            "weighted_mu_median_mm": weighted,
                            "ours_mu_median_mm": ours_mu}));
        }
    }
    Ok(Value::Array(out))
}

/// The scenario's exact noise-free readings, `[phi, theta, s]` per pose.
fn flat_readings(sc: &Scenario) -> Vec<f64> {
    sc.clean
        .iter()
        .flat_map(|p| p.readings.to_array())
        .collect()
}

/// Statistics of one Fig. 3b seed.
struct MapResult {
    after: MapStats,
    touched: MapStats,
    translation_z_mm: f64,
}

/// Which estimator a Fig. 3b row uses.
#[derive(Clone, Copy, PartialEq)]
enum Estimator {
    Paper,
    Ours,
}

/// Fig. 3b with the paper's solve: exact readings from the plant, the
/// paper's solve (or ours, for comparison), the legs commanded through the
/// identified machine's IK, the exact error of the actual machine on the
/// 10 mm lattice.
fn fig3b(a: &ReproductionArgs) -> Result<Value, String> {
    println!(
        "## Fig. 3b with the paper's solve (`cargo xtask reproduction --only fig3b`)\n\nTable 2 errors, 0.8 arcsec / 0.5 um, mean of 3, default pose set (75 poses), exact compensation on the middle plane (10 mm lattice, 5025 points), noise seeds 1..{}: median [5 %, 95 %] over seeds (mm). `match` counts the seeds whose mean and max/min are both within 10 % of the paper's.\n",
        a.seeds
    );
    println!(
        "| machine | estimator | max | min | mean | max / min | seeds with max / min >= 1.63 | match | mean, rigid translation removed | translation along z |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    let paper_ratio = PAPER_AFTER_MM[0] / PAPER_AFTER_MM[1];
    println!(
        "| paper | paper | {} | {} | {} | {paper_ratio:.2} | - | - | - | - |",
        PAPER_AFTER_MM[0], PAPER_AFTER_MM[1], PAPER_AFTER_MM[2]
    );
    let mut out = Vec::new();
    for (order, m) in machines() {
        let PaperLike {
            sc,
            lin,
            solve,
            all,
            ..
        } = paper_like(&m)?;
        let k = sc.set.len();
        let plant = tricept_plant::Plant::geometric(m.clone(), sc.set.to_errors(&sc.truth));
        let actual = plant.actual_machine();
        let model = GeometricModel::new(m.clone(), sc.set.clone());
        let options = IdentifyOptions::for_machine(&m);
        let plane = m.workspace.disc_grid(m.workspace.mid_plane_z_mm(), 10.0);
        for estimator in [Estimator::Paper, Estimator::Ours] {
            let results: Vec<MapResult> = (1..=a.seeds)
                .into_par_iter()
                .map(|seed| -> Result<MapResult, String> {
                    let campaign =
                        tricept_plant::Campaign::from_targets(&m, sc.targets_mm.clone(), seed);
                    let data = plant.simulate(&campaign).map_err(|e| e.to_string())?;
                    let p = match estimator {
                        Estimator::Paper => {
                            let y: Vec<f64> = data
                                .poses
                                .iter()
                                .flat_map(|p| p.readings.to_array())
                                .collect();
                            solve.estimate(&lin, k, &y).map_err(s)?
                        }
                        Estimator::Ours => {
                            tricept_engine::identify(&model, &data, &options)
                                .map_err(|e| e.to_string())?
                                .estimate
                        }
                    };
                    let map = tricept_model::volumetric::volumetric_errors(
                        &model.machine_at(&p),
                        &actual,
                        &plane,
                    )
                    .map_err(|e| e.to_string())?;
                    Ok(MapResult {
                        after: map.stats(),
                        touched: map.without_mean_translation().stats(),
                        translation_z_mm: map.mean_translation_mm().z,
                    })
                })
                .collect::<Result<_, _>>()?;
            let col = |f: &dyn Fn(&MapResult) -> f64| -> (String, [f64; 3]) {
                let v: Vec<f64> = results.iter().map(f).collect();
                let t = [q(&v, 0.05), q(&v, 0.5), q(&v, 0.95)];
                (format!("{:.3} [{:.3}, {:.3}]", t[1], t[0], t[2]), t)
            };
            let ratio_of = |r: &MapResult| r.after.max_mm / r.after.min_mm;
            let max = col(&|r| r.after.max_mm);
            let min = col(&|r| r.after.min_mm);
            let mean = col(&|r| r.after.mean_mm);
            let ratio = col(&ratio_of);
            let touched = col(&|r| r.touched.mean_mm);
            let tz = col(&|r| r.translation_z_mm);
            let share = |f: &dyn Fn(&MapResult) -> bool| {
                100.0 * results.iter().filter(|r| f(r)).count() as f64 / results.len() as f64
            };
            let steep = share(&|r| ratio_of(r) >= paper_ratio);
            let matched = share(&|r| {
                (r.after.mean_mm / PAPER_AFTER_MM[2] - 1.0).abs() <= 0.1
                    && (ratio_of(r) / paper_ratio - 1.0).abs() <= 0.1
            });
            let name = match estimator {
                Estimator::Paper => "paper's solve",
                Estimator::Ours => "ours",
            };
            println!(
                "| {} | {name} | {} | {} | {} | {} | {steep:.1} % | {matched:.1} % | {} | {} |",
                if estimator == Estimator::Paper {
                    label(order, all)
                } else {
                    format!("{order}, 15 parameters (rank rule)")
                },
                max.0,
                min.0,
                mean.0,
                ratio.0,
                touched.0,
                tz.0
            );
            out.push(json!({"axis_order": order.to_string(), "estimator": name,
                            "parameters_estimated": if estimator == Estimator::Paper { solve.columns.len() } else { k },
                            "seeds": a.seeds, "plane_points": plane.len(),
                            "after_max_mm_q05_q50_q95": max.1, "after_min_mm_q05_q50_q95": min.1,
                            "after_mean_mm_q05_q50_q95": mean.1, "max_over_min_q05_q50_q95": ratio.1,
                            "share_max_over_min_at_least_paper_percent": steep,
                            "share_matching_mean_and_ratio_percent": matched,
                            "touched_mean_mm_q05_q50_q95": touched.1, "translation_z_mm_q05_q50_q95": tz.1}));
        }
    }
    Ok(Value::Array(out))
}

/// The spread of the median `mu` over random pose sets of each size.
fn poses(a: &ReproductionArgs) -> Result<Value, String> {
    let sizes = [6usize, 7, 8, 9, 10, 12, 15, 20];
    println!(
        "## mu over random pose sets (`cargo xtask reproduction --only poses`)\n\n{} sets per size (`random:N,SEED`, SEED = 1..{}), the median `mu` of each set over {} fast trials; quantiles over the sets (mm). The paper: mu = {PAPER_MU_AT_4} mm at 4 arcsec, above mu_0 = 0.285, and 2 arcsec chosen.\n",
        a.sets, a.sets, a.set_trials
    );
    println!(
        "| U joint | poses | mu at 2 arcsec: 10 / 50 / 90 % | mu at 4 arcsec: 10 / 50 / 90 % | sets with mu(4) > mu_0 | sets with mu(2) < mu_0 < mu(4) | sets with mu(4) within 0.291 +- 20 % | failed sets |\n|---|---|---|---|---|---|---|---|"
    );
    let mut out = Vec::new();
    for (order, m) in machines() {
        let mu0 = Scenario::paper(m.clone(), default_targets(&m))
            .map_err(s)?
            .mu0_mm;
        for n in sizes {
            let per_set: Vec<Result<(f64, f64), String>> = (1..=a.sets)
                .into_par_iter()
                .map(|set| {
                    let sc =
                        Scenario::paper(m.clone(), m.workspace.random_poses(n, set)).map_err(s)?;
                    let at = |g: f64| -> Result<f64, String> {
                        Ok(mu_at_grade(&sc, g, a.set_trials, a.seed).map_err(s)?.median)
                    };
                    Ok((at(2.0)?, at(4.0)?))
                })
                .collect();
            let failure = per_set.iter().find_map(|r| r.as_ref().err().cloned());
            let failed = per_set.iter().filter(|r| r.is_err()).count();
            let ok: Vec<(f64, f64)> = per_set.into_iter().filter_map(Result::ok).collect();
            if ok.is_empty() {
                let why = failure.unwrap_or_default();
                println!("| {order} | {n} | - | - | - | - | - | {failed}: {why} |");
                out.push(json!({"axis_order": order.to_string(), "poses": n, "failed": failed, "failure": why}));
                continue;
            }
            let m2: Vec<f64> = ok.iter().map(|r| r.0).collect();
            let m4: Vec<f64> = ok.iter().map(|r| r.1).collect();
            let share = |f: &dyn Fn(&(f64, f64)) -> bool| {
                100.0 * ok.iter().filter(|r| f(r)).count() as f64 / ok.len() as f64
            };
            let above = share(&|r| r.1 > mu0);
            let pattern = share(&|r| r.0 < mu0 && mu0 < r.1);
            let near = share(&|r| (r.1 / PAPER_MU_AT_4 - 1.0).abs() <= 0.2);
            let t2 = [q(&m2, 0.1), q(&m2, 0.5), q(&m2, 0.9)];
            let t4 = [q(&m4, 0.1), q(&m4, 0.5), q(&m4, 0.9)];
            println!(
                "| {order} | {n} | {:.3} / {:.3} / {:.3} | {:.3} / {:.3} / {:.3} | {above:.0} % | {pattern:.0} % | {near:.0} % | {failed} |",
                t2[0], t2[1], t2[2], t4[0], t4[1], t4[2]
            );
            out.push(json!({"axis_order": order.to_string(), "poses": n, "sets": ok.len(), "failed": failed,
                            "mu0_mm": mu0,
                            "mu_at_2_arcsec_q10_q50_q90": t2, "mu_at_4_arcsec_q10_q50_q90": t4,
                            "share_mu4_above_mu0_percent": above, "share_paper_pattern_percent": pattern,
                            "share_mu4_near_paper_percent": near}));
        }
    }
    Ok(Value::Array(out))
}

/// The noise part of `mu`, `||p_hat - p*||_1 / 15`, per trial.
fn noise_part(e: &LinearEstimator, k: usize, a: &ReproductionArgs, gi: u64) -> f64 {
    median(&e.noise_mu(k, a.trials, a.seed, gi))
}

/// What differencing against a reference pose costs against estimating the
/// offsets: the same parameters, the rows weighted by `1 / sigma^2` as if
/// independent, and by the covariance the differencing introduces.
fn differencing(a: &ReproductionArgs) -> Result<Value, String> {
    println!(
        "## Differencing against estimating the offsets (`cargo xtask reproduction --only differencing`)\n\nDefault pose set (75 poses), the identifiable parameters; noise part of `mu` = median of `||p_hat - p*||_1 / 15` over {} trials per estimator (same seed). Ratios are differenced / offsets estimated. `independent`: each differenced row weighted by `1 / sigma^2` as if the rows were independent; `covariance`: weighted by the inverse covariance the differencing introduces (generalised least squares).\n",
        a.trials
    );
    println!(
        "| U joint | grade (arcsec) | offsets estimated (mm) | differenced against pose 0, independent (mm) | ratio | ratio over the 75 reference poses, independent: best (pose) / median / worst (pose) | ratio over the 75 reference poses, covariance: min / max | the paper's solve (differenced against pose 0, unweighted): ratio |\n|---|---|---|---|---|---|---|---|"
    );
    let grades = [PAPER_GRADE, 2.0, 4.0];
    let mut out = Vec::new();
    for (order, m) in machines() {
        let sc = Scenario::paper(m.clone(), default_targets(&m)).map_err(s)?;
        let lin = NominalLinearisation::new(&sc).map_err(s)?;
        let k = sc.set.len();
        let n = sc.clean.len();
        for (gi, &g) in grades.iter().enumerate() {
            let gi = gi as u64;
            let ours = GradeModel::new(&sc, g).map_err(s)?;
            let ident = ours.design.identifiable().to_vec();
            let joint = noise_part(&ours.estimator, k, a, gi);
            let sigma = sc.logged_sigma(g);
            let differenced = |reference: usize, w: RowWeights| -> Result<f64, String> {
                match DifferencedSolve::form(&lin, &ident, reference, w).map_err(s)? {
                    Differenced::Formed(d) => Ok(noise_part(
                        &d.estimator(&sc, &lin, sigma).map_err(s)?,
                        k,
                        a,
                        gi,
                    )),
                    Differenced::Singular { condition } => Err(format!(
                        "differenced solve singular (condition {condition:.1e})"
                    )),
                }
            };
            let ratios_over_references = |w: RowWeights| -> Result<Vec<f64>, String> {
                (0..n)
                    .into_par_iter()
                    .map(|r| Ok(differenced(r, w)? / joint))
                    .collect()
            };
            let ratios =
                ratios_over_references(RowWeights::PerSensor(sigma.map(|x| 1.0 / (x * x))))?;
            let covariance = ratios_over_references(RowWeights::DifferencedCovariance(sigma))?;
            let (best, worst) = (argmin(&ratios, |x| x), argmin(&ratios, |x| -x));
            let (cov_min, cov_max) = (
                covariance[argmin(&covariance, |x| x)],
                covariance[argmin(&covariance, |x| -x)],
            );
            let unweighted = differenced(0, RowWeights::PerSensor([1.0; 3]))? / joint;
            let pose = |i: usize| {
                let p = sc.targets_mm[i];
                // Rounded first, and + 0.0 turns -0 into 0.
                let [x, y, z] = [p.x, p.y, p.z].map(|v| v.round() + 0.0);
                format!("{i}: ({x}, {y}, {z})")
            };
            println!(
                "| {order} | {g} | {joint:.4} | {:.4} | {:.2} | {:.2} ({}) / {:.2} / {:.2} ({}) | {cov_min:.3} / {cov_max:.3} | {unweighted:.2} |",
                ratios[0] * joint,
                ratios[0],
                ratios[best],
                pose(best),
                median(&ratios),
                ratios[worst],
                pose(worst)
            );
            out.push(json!({"axis_order": order.to_string(), "grade_arcsec": g,
                            "offsets_estimated_noise_mu_mm": joint,
                            "independent_ratio_by_reference": ratios,
                            "ratio_reference_0": ratios[0], "ratio_best": ratios[best], "best_reference": best,
                            "ratio_median": median(&ratios), "ratio_worst": ratios[worst], "worst_reference": worst,
                            "covariance_ratio_min": cov_min, "covariance_ratio_max": cov_max,
                            "paper_solve_ratio_reference_0": unweighted}));
        }
    }
    Ok(Value::Array(out))
}

/// Index of the smallest `key(v[i])`.
fn argmin(v: &[f64], key: impl Fn(f64) -> f64) -> usize {
    (0..v.len())
        .min_by(|&i, &j| key(v[i]).total_cmp(&key(v[j])))
        .unwrap_or(0)
}

/// `b^T C^-1 b` over the identifiable parameters `ident`, `C` the fit's
/// covariance.
fn mahalanobis2(
    id: &tricept_engine::Identification,
    ident: &[usize],
    b: &[f64],
) -> Result<f64, String> {
    let c = nalgebra::DMatrix::from_fn(ident.len(), ident.len(), |u, v| {
        id.covariance[(ident[u], ident[v])]
    });
    let x = nalgebra::DVector::from_fn(ident.len(), |u, _| b[ident[u]]);
    let chol = c
        .cholesky()
        .ok_or("the covariance of the identifiable parameters is not positive definite")?;
    Ok(x.dot(&chol.solve(&x)))
}

/// What holding `dyA3` at zero biases (`docs/identifiability.md`): Table 2
/// (dyA3 = 0.2 mm) on the x-first machine, random campaigns of each size
/// (the default grid too), the paper's noise. The bias is the estimate
/// from exact noise-free readings with `dyA3` held at zero (the rank
/// rule) minus the truth, in each parameter's standard deviation at that
/// campaign; holding `dyA3` at its true value instead recovers the truth
/// (the check column). The noisy fits give the Mahalanobis distance
/// `d^2 = (p_hat - p)^T C^-1 (p_hat - p)` from the truth over the 14
/// identifiable parameters: 14 on average for an unbiased fit, `14 +
/// b^T C^-1 b` with the bias `b`.
fn held(a: &ReproductionArgs) -> Result<Value, String> {
    use tricept_engine::{identify, identify::Start, identify::identify_from};
    use tricept_plant::{Campaign, Plant};
    println!(
        "## What holding dyA3 at zero biases (`cargo xtask reproduction --only held`)\n\nTable 2 on the x-first machine (dyA3 = 0.2 mm), paper noise. Bias: noise-free exact readings fitted with dyA3 held at zero, minus the truth, in standard deviations of that campaign; `check`: the largest |error| / sd with dyA3 held at its true value. d^2: mean Mahalanobis distance from the truth of {} noisy campaigns per size (14 identifiable parameters), with dyA3 at zero and at the truth, the bias's own b^T C^-1 b, and the fits' mean chi-square per degree of freedom.\n",
        a.held_campaigns
    );
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let truth = set.table2();
    let dya3 = set.index_of("dyA3").ok_or("no dyA3 in paper15")?;
    let plant = Plant::geometric(m.clone(), set.to_errors(&truth));
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let mut at_truth = vec![0.0; set.len()];
    at_truth[dya3] = truth[dya3];
    // The default grid (75 poses) and random campaigns of each size; a
    // noise seed per campaign, and for the random ones new poses too.
    let sizes: [(&str, Option<usize>); 4] = [
        ("75 (grid)", None),
        ("200", Some(200)),
        ("1000", Some(1000)),
        ("10000", Some(10_000)),
    ];
    let campaign = |size: Option<usize>, seed: u64| match size {
        None => Campaign::grid(&m, seed),
        Some(n) => Campaign::random(&m, n, n as u64 + 1000 * seed),
    };
    let names = set.names();
    let fits = |c: &Campaign| -> Result<_, String> {
        let data = plant.simulate(c).map_err(|e| e.to_string())?;
        let zero = identify(&model, &data, &options).map_err(|e| e.to_string())?;
        let d = design(&model, &vec![0.0; set.len()], &data.poses, &options)
            .map_err(|e| e.to_string())?;
        let start = Start {
            parameters: Some(at_truth.clone()),
            design: Some(d),
            ..Start::default()
        };
        let truth_held =
            identify_from(&model, &data, &options, &start).map_err(|e| e.to_string())?;
        if !(zero.converged && truth_held.converged) {
            return Err(format!("{}: a fit did not converge", data.source));
        }
        Ok((zero, truth_held))
    };
    let mut header = String::from("| poses |");
    let mut rule = String::from("|---|");
    for (j, n) in names.iter().enumerate() {
        if j != dya3 {
            header += &format!(" {n} |");
            rule += "---|";
        }
    }
    println!(
        "{header} check | b^T C^-1 b | d^2, dyA3 at zero | d^2, dyA3 true | chi2/dof |\n{rule}---|---|---|---|---|"
    );
    let mut rows = Vec::new();
    for (label, size) in sizes {
        let mut clean = campaign(size, 0);
        clean.noise.angle_rad = 0.0;
        clean.noise.length_mm = 0.0;
        let (zero, truth_held) = fits(&clean)?;
        let ident = zero.design().identifiable().to_vec();
        let sd = |id: &tricept_engine::Identification, j: usize| id.std_dev[j].unwrap_or(f64::NAN);
        let bias: Vec<f64> = (0..set.len())
            .map(|j| zero.estimate[j] - truth[j])
            .collect();
        let bias_sd: Vec<f64> = (0..set.len()).map(|j| bias[j] / sd(&zero, j)).collect();
        let check = ident
            .iter()
            .map(|&j| ((truth_held.estimate[j] - truth[j]) / sd(&truth_held, j)).abs())
            .fold(0.0, f64::max);
        let b2 = mahalanobis2(&zero, &ident, &bias)?;
        let noisy: Vec<(f64, f64, f64)> = (1..=a.held_campaigns)
            .into_par_iter()
            .map(|seed| {
                let (z, t) = fits(&campaign(size, seed))?;
                let e = |id: &tricept_engine::Identification| -> Vec<f64> {
                    (0..set.len()).map(|j| id.estimate[j] - truth[j]).collect()
                };
                Ok((
                    mahalanobis2(&z, &ident, &e(&z))?,
                    mahalanobis2(&t, &ident, &e(&t))?,
                    t.stats.reduced_chi_square,
                ))
            })
            .collect::<Result<_, String>>()?;
        let n = noisy.len() as f64;
        let d2_zero = noisy.iter().map(|x| x.0).sum::<f64>() / n;
        let d2_true = noisy.iter().map(|x| x.1).sum::<f64>() / n;
        let chi2 = noisy.iter().map(|x| x.2).sum::<f64>() / n;
        let mut line = format!("| {label} |");
        for &j in &ident {
            line += &format!(" {:+.2} |", bias_sd[j]);
        }
        println!("{line} {check:.1e} | {b2:.1} | {d2_zero:.1} | {d2_true:.1} | {chi2:.3} |");
        let by_name: serde_json::Map<String, Value> = ident
            .iter()
            .map(|&j| {
                (
                    names[j].to_string(),
                    json!({"bias_mm": bias[j], "bias_sd": bias_sd[j]}),
                )
            })
            .collect();
        rows.push(
            json!({"poses": label, "bias": by_name, "check_max_abs_sd": check,
                         "bias_mahalanobis2": b2, "mean_d2_dya3_zero": d2_zero,
                         "mean_d2_dya3_true": d2_true, "mean_reduced_chi_square": chi2,
                         "campaigns": a.held_campaigns}),
        );
    }
    Ok(json!({"rows": rows}))
}
