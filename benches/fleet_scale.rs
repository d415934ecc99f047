//! A batch at scale, timed and its peak memory read (docs/performance.md,
//! "Pooled calibration"):
//!
//! ```text
//! cargo run --release -p tricept-benches --example fleet_scale -- MACHINES [--solver KIND] [--compare] [--export DIR]
//! ```
//!
//! Simulates `MACHINES` machines of 80 poses (`tricept_benches::fleet_batch`),
//! calibrates them as a batch and prints one JSON line: the times (the
//! simulation, the batch end to end, the joint fit, its solves), the
//! problem's size and the process's peak resident memory (`VmHWM` of
//! `/proc/self/status`). `--compare` also times one solve of the joint fit's
//! first step by every solver kind and their largest difference from the
//! block elimination's. `--export DIR` writes that step's normal equations
//! for the scipy peer (`benches/peers/fleet.py`): `normal.mtx` (the lower
//! triangle of `J^T J`, Matrix Market), `rhs.txt` (`J^T b`) and
//! `solution.txt` (the block elimination's solution, locals of every
//! machine then the batch mean).

use std::io::Write;
use std::time::Instant;

use tricept_benches::fleet_batch;
use tricept_engine::{
    IdentifyOptions, accuracy::AccuracyModel, accuracy::accuracy_points, model::GeometricModel,
};
use tricept_fleet::{BatchOptions, calibrate_batch};
use tricept_ident::advanced::ParameterSet;
use tricept_ident::fleet::SolverKind;
use tricept_kinematics::Machine;
use tricept_numerics::sparse::{BlockProblem, BlockSolution};

/// The peak resident memory of this process, MB (Linux).
fn peak_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// A solution in `J`'s column order: every block's locals, then the globals.
fn flat(s: &BlockSolution) -> Vec<f64> {
    s.local.iter().flatten().chain(&s.global).copied().collect()
}

/// Every unknown's standard deviation in `J`'s column order, from the
/// block elimination.
fn standard_deviations(problem: &BlockProblem, s: &BlockSolution) -> Vec<f64> {
    use tricept_numerics::sparse::ReducedBlock;
    let cov = s
        .global_covariance
        .as_ref()
        .expect("the Schur solve has it");
    let mut out = Vec::new();
    for (i, b) in problem.blocks.iter().enumerate() {
        let r = ReducedBlock::new(b, problem.n_global, i).unwrap();
        let c = r.local_covariance(cov.as_ref());
        out.extend((0..b.n_local).map(|j| c[(j, j)].sqrt()));
    }
    out.extend((0..problem.n_global).map(|j| cov[(j, j)].sqrt()));
    out
}

fn export(problem: &BlockProblem, dir: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let n = problem.unknowns();
    let g = problem.n_global;
    let mut entries: Vec<(usize, usize, f64)> = Vec::new();
    let mut rhs = vec![0.0; n];
    let mut offset = 0;
    for b in &problem.blocks {
        let l = b.n_local;
        let m = b.rows.nrows();
        let col = |j: usize| if j < l { offset + j } else { n - g + j - l };
        for p in 0..l + g {
            rhs[col(p)] += (0..m)
                .map(|i| b.rows[(i, p)] * b.rows[(i, l + g)])
                .sum::<f64>();
            for q in 0..=p {
                let v: f64 = (0..m).map(|i| b.rows[(i, p)] * b.rows[(i, q)]).sum();
                if v != 0.0 {
                    let (r, c) = (col(p).max(col(q)), col(p).min(col(q)));
                    entries.push((r, c, v));
                }
            }
        }
        offset += l;
    }
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("normal.mtx"))?);
    writeln!(f, "%%MatrixMarket matrix coordinate real symmetric")?;
    writeln!(f, "{n} {n} {}", entries.len())?;
    for (r, c, v) in &entries {
        writeln!(f, "{} {} {v:e}", r + 1, c + 1)?;
    }
    let text = |v: &[f64]| v.iter().map(|x| format!("{x:e}\n")).collect::<String>();
    std::fs::write(dir.join("rhs.txt"), text(&rhs))?;
    let s = problem
        .solve(SolverKind::Schur)
        .expect("the problem solves");
    std::fs::write(dir.join("solution.txt"), text(&flat(&s)))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let machines: usize = args
        .first()
        .and_then(|a| a.parse().ok())
        .expect("usage: fleet_scale MACHINES [--solver KIND] [--compare] [--export DIR]");
    let flag = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
    };
    let kind: SolverKind =
        flag("--solver").map_or(SolverKind::Schur, |k| k.parse().expect("a solver kind"));
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let accuracy = AccuracyModel::new(&m, &set, &accuracy_points(&m), 0.25).unwrap();
    let t = Instant::now();
    let data = fleet_batch(machines, 80, 47);
    let simulate_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let batch = calibrate_batch(
        &model,
        &data,
        &options,
        &accuracy,
        &BatchOptions {
            kind,
            ..BatchOptions::default()
        },
    )
    .unwrap();
    let batch_s = t.elapsed().as_secs_f64();
    let s = &batch.joint.stats;
    let mut line = serde_json::json!({
        "machines": machines,
        "poses": 80,
        "solver": kind.name(),
        "simulate_s": simulate_s,
        "calibrate_batch_s": batch_s,
        "joint_fit_s": batch.joint.fit_seconds,
        "solve_s": s.seconds,
        "iterations": batch.joint.iterations,
        "unknowns": s.unknowns,
        "nonzeros": s.nonzeros,
        "readings": batch.joint.readings,
        "members": batch.members(),
        "exit_code": batch.exit_code(),
        "peak_rss_mb": peak_mb(),
    });
    if args.iter().any(|a| a == "--compare") {
        let problem = batch.first_step_problem(&model, options.sigma).unwrap();
        let schur = problem.solve(SolverKind::Schur).unwrap();
        let reference = flat(&schur);
        let sd = standard_deviations(&problem, &schur);
        let scale = reference.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for k in SolverKind::ALL {
            if k == SolverKind::Dense && machines > 100 {
                continue;
            }
            let t = Instant::now();
            let solved = problem.solve(k).unwrap();
            let seconds = t.elapsed().as_secs_f64();
            let worst = flat(&solved)
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs() / b.abs().max(1e-6 * scale))
                .fold(0.0f64, f64::max);
            let in_sd = flat(&solved)
                .iter()
                .zip(&reference)
                .zip(&sd)
                .map(|((a, b), s)| (a - b).abs() / s)
                .fold(0.0f64, f64::max);
            line[format!("one_solve_{}_s", k.name())] = seconds.into();
            line[format!("{}_vs_schur_relative", k.name())] = worst.into();
            line[format!("{}_vs_schur_in_sd", k.name())] = in_sd.into();
        }
        line["peak_rss_mb"] = peak_mb().into();
    }
    if let Some(dir) = flag("--export") {
        let problem = batch.first_step_problem(&model, options.sigma).unwrap();
        export(&problem, std::path::Path::new(dir)).unwrap();
    }
    println!("{line}");
}
