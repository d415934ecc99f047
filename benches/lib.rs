//! Shared inputs for the criterion benchmarks in this directory.
//!
//! Run them with `cargo bench -p tricept-benches`; the numbers and the
//! command are recorded in `docs/performance.md`.

use nalgebra::Vector3;
use tricept_kinematics::Machine;

/// Points spread over the workspace of `m` (a fixed, seeded sample).
pub fn workspace_points(m: &Machine, n: usize) -> Vec<Vector3<f64>> {
    m.workspace.random_poses(n, 2009)
}
