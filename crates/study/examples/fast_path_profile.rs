//! Where the fast path's time goes, on one thread: the whole trial
//! (`LinearEstimator::run`) against the normals, `dp = T z` and `mu` alone
//! (`LinearEstimator::noise_mu`, the same draws without the plane), in CPU
//! time per trial (read from `/proc/thread-self/stat`: Linux only), so that
//! other work on the machine inflates it less than wall time.
//!
//! ```sh
//! cargo run --release -p tricept-study --example fast_path_profile
//! ```

use std::time::Instant;

use tricept_kinematics::Machine;
use tricept_study::{Scenario, fast::GradeModel};

/// CPU time of this thread, s (10 ms resolution).
fn cpu_s() -> Result<f64, String> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").map_err(|e| e.to_string())?;
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks = |i: usize| -> Result<f64, String> {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| "unexpected /proc/thread-self/stat".to_string())
    };
    Ok((ticks(11)? + ticks(12)?) / 100.0)
}

fn main() -> Result<(), String> {
    let m = Machine::paper();
    // The scenario of `benches/study.rs`.
    let s =
        Scenario::paper(m.clone(), m.workspace.polar_grid(3, 8, 3)).map_err(|e| e.to_string())?;
    let g = GradeModel::new(&s, 2.0).map_err(|e| e.to_string())?;
    let e = &g.estimator;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    let trials = 8_000_000;
    let per_trial = |f: &(dyn Fn() -> f64 + Sync)| -> Result<(f64, f64), String> {
        let (t, c) = (Instant::now(), pool.install(cpu_s)?);
        std::hint::black_box(pool.install(f));
        let c = pool.install(cpu_s)? - c;
        let scale = 1e9 / trials as f64;
        Ok((t.elapsed().as_secs_f64() * scale, c * scale))
    };
    let (wall, cpu) = per_trial(&|| e.run(&s, trials, 1, 0, &|_| {})[7].mu_mm)?;
    println!("whole trial: {cpu:.0} ns CPU ({wall:.0} ns wall) per trial");
    let (wall_mu, cpu_mu) = per_trial(&|| e.noise_mu(15, trials, 1, 0)[7])?;
    println!("normals, dp = T z and mu: {cpu_mu:.0} ns CPU ({wall_mu:.0} ns wall) per trial");
    println!(
        "plane map, norms and reductions: {:.0} ns CPU per trial (the difference)",
        cpu - cpu_mu
    );
    Ok(())
}
