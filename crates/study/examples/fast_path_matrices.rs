//! Writes the fast path's matrices for the benchmark's scenario (the
//! default 75-pose grid at 2 arcsec, Table 2), so that a peer
//! implementation of the same algorithm (`benches/peers/fast_path.py`) runs
//! on exactly the same numbers, with this crate's own Monte Carlo means to
//! check it against.
//!
//! ```sh
//! cargo run --release -p tricept-study --example fast_path_matrices -- fast_path.json
//! ```

use tricept_kinematics::Machine;
use tricept_study::{Scenario, fast::GradeModel, results::TrialResult};

/// One field of a trial's result.
type Field = fn(&TrialResult) -> f64;

fn main() -> Result<(), String> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: fast_path_matrices OUT.json")?;
    let m = Machine::paper();
    // The scenario of `benches/study.rs`.
    let s =
        Scenario::paper(m.clone(), m.workspace.polar_grid(3, 8, 3)).map_err(|e| e.to_string())?;
    let g = GradeModel::new(&s, 2.0).map_err(|e| e.to_string())?;
    let e = &g.estimator;
    let rows = |a: &faer::Mat<f64>| -> Vec<Vec<f64>> {
        (0..a.nrows())
            .map(|i| (0..a.ncols()).map(|j| a[(i, j)]).collect())
            .collect()
    };
    let trials = 200_000;
    let results = e.run(&s, trials, 1, 0, &|_| {});
    let mean = |f: Field| results.iter().map(f).sum::<f64>() / trials as f64;
    let sd = |f: Field| {
        let m = mean(f);
        (results.iter().map(|t| (f(t) - m).powi(2)).sum::<f64>() / (trials - 1) as f64).sqrt()
    };
    let fields: [(&str, Field); 4] = [
        ("mu_mm", |t| t.mu_mm),
        ("plane_mean_mm", |t| t.plane_mean_mm),
        ("plane_max_mm", |t| t.plane_max_mm),
        ("plane_touched_mean_mm", |t| t.plane_touched_mean_mm),
    ];
    let summary: serde_json::Map<String, serde_json::Value> = fields
        .iter()
        .map(|(n, f)| {
            (
                n.to_string(),
                serde_json::json!({"mean": mean(*f), "sd": sd(*f)}),
            )
        })
        .collect();
    let json = serde_json::json!({
        "scenario": "75-pose grid (polar_grid(3, 8, 3)), 2 arcsec, Table 2, paper machine",
        "trials_per_block": tricept_study::fast::BLOCK,
        "columns": e.columns,
        "p_star": e.p_star,
        "truth": s.truth,
        "factor": rows(&e.factor),
        "plane_jacobian": rows(&e.plane_jacobian),
        "plane_clean": e.plane_clean,
        "rust": {"trials": trials, "seed": 1, "summary": summary},
    });
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?,
    )
    .map_err(|e| format!("{path}: {e}"))?;
    println!("wrote {path}");
    Ok(())
}
