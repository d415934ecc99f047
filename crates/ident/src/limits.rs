//! The largest sizes and values the workflows accept, checked before anything
//! is allocated or computed (exit 2 beyond them), so that no input value
//! makes a verb exhaust the memory or run without end. Listed in
//! docs/reliability.md; generated pose sets are bounded by
//! [`tricept_kinematics::workspace::MAX_POSES`] and the readers' lines by
//! [`tricept_data::read::MAX_LINE_BYTES`].

/// Evaluation tool poses of the fused predictions and of `plan`
/// (`--eval-grid` times the head angles).
pub const MAX_EVAL_POSES: usize = 10_000;

/// Candidate measurement poses of `plan` (tracker points times head
/// angles, or ballbar positions).
pub const MAX_CANDIDATES: usize = 50_000;

/// Angles per head axis in a list (`--head-angles-deg`, ...).
pub const MAX_HEAD_ANGLES: usize = 360;

/// Exchange passes of `plan`.
pub const MAX_PASSES: usize = 1_000;

/// Random selections per k of `plan`'s baseline.
pub const MAX_RANDOM_BASELINE: usize = 10_000;

/// Any coordinate, angle or frame component given on the command line
/// (mm, deg or rad).
pub const MAX_COORDINATE: f64 = 1e5;

/// A ball or target offset from the tool tip, mm.
pub const MAX_TOOL_OFFSET_MM: f64 = 1000.0;

/// Points of a compensation map (`compensate --map`, `--spacing`).
pub const MAX_MAP_POINTS: usize = 1_000_000;
