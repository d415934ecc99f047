//! A compensation table a controller can load: leg-command corrections on
//! a regular grid over the workspace, looked up by trilinear interpolation,
//! with the interpolation error measured.
//!
//! The controller keeps its nominal IK and adds the correction
//! `dq(r) = q_calibrated(r) - q_nominal(r)` interpolated at the target `r`.
//! The correction is smooth (geometric errors of tenths of a mm change it by
//! microns over the workspace), so a coarse grid suffices; how coarse is
//! measured, not assumed: [`CompensationTable::interpolation_error_um`]
//! compares the trilinear lookup with the exact correction on a lattice
//! four times finer than the grid (every cell centre, face centre and
//! quarter point), over the whole workspace cylinder.

use nalgebra::Vector3;
use tricept_kinematics::{KinematicsError, Workspace};
use tricept_model::ExtendedMachine;

/// Grid spacings (mm) tried by [`CompensationTable::with_error_below`],
/// coarsest first. The finest is 10 mm: measuring a table's error takes
/// `(4 / spacing)^3` times the workspace volume in IK pairs (9 million at
/// 10 mm on the Table 1 workspace, a few seconds); a calibration that needs
/// more is far from the smooth corrections geometric errors give, and a
/// finer table is then the user's explicit choice.
pub const SPACING_LADDER_MM: [f64; 6] = [100.0, 50.0, 40.0, 25.0, 20.0, 10.0];

/// Leg-command corrections on a regular grid.
///
/// Node `(i, j, k)` is at `origin + (i, j, k) * spacing`, `i` fastest in
/// [`CompensationTable::nodes`]. The grid covers the workspace cylinder's
/// bounding box; nodes the machine cannot reach (box corners beyond the
/// tilt limit) hold `None` and are never needed: every cell that meets the
/// cylinder has all eight corners (checked when the table is built).
///
/// # Example
/// ```
/// use tricept_engine::table::CompensationTable;
/// use tricept_kinematics::Machine;
/// use tricept_model::ExtendedMachine;
/// let nominal = Machine::paper();
/// let mut calibrated = nominal.clone();
/// calibrated.leg_offsets_mm = [0.3, -0.2, 0.1];
/// calibrated.base_joints_mm[0].x += 0.25;
/// let (n, c) = (ExtendedMachine::new(nominal.clone()), ExtendedMachine::new(calibrated));
/// let t = CompensationTable::build(&n, &c, &nominal.workspace, 50.0).unwrap();
/// // Leg 2 only has a length offset: a constant correction (0.2 mm short,
/// // 0.2 mm more command), which trilinear lookup reproduces exactly.
/// let r = nalgebra::Vector3::new(12.0, -80.0, 700.0);
/// let dq = t.interpolate(&r).unwrap();
/// assert!((dq[1] - 0.2).abs() < 1e-9);
/// assert!(t.interpolation_error_um(&n, &c, &nominal.workspace).unwrap() < 1.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CompensationTable {
    /// Position of node `(0, 0, 0)`, mm.
    pub origin_mm: Vector3<f64>,
    /// Grid spacing (the same along x, y and z), mm.
    pub spacing_mm: f64,
    /// Number of nodes along x, y, z.
    pub counts: [usize; 3],
    /// Corrections `[dq1, dq2, dq3]` (mm) per node, `i` fastest, then `j`,
    /// then `k`; `None` where the machine cannot reach the node.
    pub nodes: Vec<Option<[f64; 3]>>,
}

/// The exact correction at `r`.
fn correction(
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
    r: &Vector3<f64>,
) -> Result<[f64; 3], KinematicsError> {
    let a = nominal.inverse(r)?.legs_mm;
    let b = calibrated.inverse(r)?.legs_mm;
    Ok(std::array::from_fn(|i| b[i] - a[i]))
}

/// The most nodes a compensation table may have (checked before any is
/// computed).
pub const MAX_TABLE_NODES: usize = 2_000_000;

impl CompensationTable {
    /// The table of `calibrated` against `nominal` over `workspace` at
    /// `spacing_mm` (at least 1 mm). Fails when a node of a cell that
    /// meets the workspace cannot be reached.
    pub fn build(
        nominal: &ExtendedMachine,
        calibrated: &ExtendedMachine,
        workspace: &Workspace,
        spacing_mm: f64,
    ) -> Result<CompensationTable, KinematicsError> {
        if !(spacing_mm.is_finite() && spacing_mm >= 1.0) {
            return Err(KinematicsError::OutOfReach {
                reason: format!("table spacing {spacing_mm} mm: must be at least 1 mm"),
            });
        }
        let h = spacing_mm;
        let n_xy = (workspace.radius_mm / h).ceil() as usize;
        let n_z = ((workspace.z_max_mm - workspace.z_min_mm) / h).ceil() as usize;
        let total = (2.0 * n_xy as f64 + 1.0).powi(2) * (n_z as f64 + 1.0);
        if total > MAX_TABLE_NODES as f64 {
            return Err(KinematicsError::OutOfReach {
                reason: format!(
                    "table spacing {spacing_mm} mm: {total} nodes, more than the {MAX_TABLE_NODES} a table may have; a coarser spacing is needed"
                ),
            });
        }
        let origin_mm = Vector3::new(-(n_xy as f64) * h, -(n_xy as f64) * h, workspace.z_min_mm);
        let counts = [2 * n_xy + 1, 2 * n_xy + 1, n_z + 1];
        let mut nodes = Vec::with_capacity(counts[0] * counts[1] * counts[2]);
        for k in 0..counts[2] {
            for j in 0..counts[1] {
                for i in 0..counts[0] {
                    let r = origin_mm + Vector3::new(i as f64, j as f64, k as f64) * h;
                    nodes.push(correction(nominal, calibrated, &r).ok());
                }
            }
        }
        let table = CompensationTable {
            origin_mm,
            spacing_mm: h,
            counts,
            nodes,
        };
        // Every cell that meets the cylinder must have its eight corners.
        for k in 0..counts[2] - 1 {
            for j in 0..counts[1] - 1 {
                for i in 0..counts[0] - 1 {
                    if table.cell_meets(workspace, [i, j, k])
                        && let Some(missing) = table.missing_corner([i, j, k])
                    {
                        return Err(KinematicsError::OutOfReach {
                            reason: format!(
                                "table node ({:.1}, {:.1}, {:.1}) mm, a corner of a cell inside the workspace, cannot be reached; use a finer spacing",
                                missing.x, missing.y, missing.z
                            ),
                        });
                    }
                }
            }
        }
        Ok(table)
    }

    /// The coarsest spacing of [`SPACING_LADDER_MM`] whose measured
    /// interpolation error is below `limit_um`, with that error (um); the
    /// finest of the ladder, with its larger error, when none is.
    pub fn with_error_below(
        nominal: &ExtendedMachine,
        calibrated: &ExtendedMachine,
        workspace: &Workspace,
        limit_um: f64,
    ) -> Result<(CompensationTable, f64), KinematicsError> {
        let mut last = None;
        for h in SPACING_LADDER_MM {
            let Ok(t) = CompensationTable::build(nominal, calibrated, workspace, h) else {
                continue;
            };
            let e = t.interpolation_error_um(nominal, calibrated, workspace)?;
            if e < limit_um {
                return Ok((t, e));
            }
            last = Some((t, e));
        }
        last.ok_or_else(|| KinematicsError::OutOfReach {
            reason: "no table spacing covers the workspace".into(),
        })
    }

    fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        i + self.counts[0] * (j + self.counts[1] * k)
    }

    fn position(&self, [i, j, k]: [usize; 3]) -> Vector3<f64> {
        self.origin_mm + Vector3::new(i as f64, j as f64, k as f64) * self.spacing_mm
    }

    /// Whether cell `c` (lower corner index) meets the workspace cylinder.
    fn cell_meets(&self, w: &Workspace, c: [usize; 3]) -> bool {
        let lo = self.position(c);
        let hi = lo + Vector3::repeat(self.spacing_mm);
        let nearest_x = 0f64.clamp(lo.x, hi.x);
        let nearest_y = 0f64.clamp(lo.y, hi.y);
        nearest_x.hypot(nearest_y) <= w.radius_mm && hi.z >= w.z_min_mm && lo.z <= w.z_max_mm
    }

    fn missing_corner(&self, [i, j, k]: [usize; 3]) -> Option<Vector3<f64>> {
        (0..8).find_map(|c| {
            let n = [i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)];
            self.nodes[self.index(n)]
                .is_none()
                .then(|| self.position(n))
        })
    }

    /// The trilinear interpolation of the corrections at `r` (mm); `None`
    /// outside the grid or in a cell with an unreachable corner.
    pub fn interpolate(&self, r: &Vector3<f64>) -> Option<[f64; 3]> {
        let u = (r - self.origin_mm) / self.spacing_mm;
        let mut cell = [0usize; 3];
        let mut t = [0.0; 3];
        for a in 0..3 {
            let last = (self.counts[a] - 1) as f64;
            if !(u[a] >= 0.0 && u[a] <= last) {
                return None;
            }
            // The upper face belongs to the last cell.
            let c = u[a].floor().min(last - 1.0).max(0.0);
            cell[a] = c as usize;
            t[a] = u[a] - c;
        }
        let mut out = [0.0; 3];
        for c in 0..8 {
            let bits = [c & 1, c >> 1 & 1, c >> 2 & 1];
            let w: f64 = (0..3)
                .map(|a| if bits[a] == 1 { t[a] } else { 1.0 - t[a] })
                .product();
            let node = [cell[0] + bits[0], cell[1] + bits[1], cell[2] + bits[2]];
            let v = self.nodes.get(self.index(node)).copied().flatten()?;
            for l in 0..3 {
                out[l] += w * v[l];
            }
        }
        Some(out)
    }

    /// Largest difference (um, over the three legs) between the trilinear
    /// lookup and the exact correction on the lattice of spacing
    /// `spacing / 4` aligned with the grid, over the points of `workspace`.
    pub fn interpolation_error_um(
        &self,
        nominal: &ExtendedMachine,
        calibrated: &ExtendedMachine,
        workspace: &Workspace,
    ) -> Result<f64, KinematicsError> {
        let fine = self.spacing_mm / 4.0;
        let n = [
            4 * (self.counts[0] - 1),
            4 * (self.counts[1] - 1),
            4 * (self.counts[2] - 1),
        ];
        let mut worst: f64 = 0.0;
        for k in 0..=n[2] {
            for j in 0..=n[1] {
                for i in 0..=n[0] {
                    let r = self.origin_mm + Vector3::new(i as f64, j as f64, k as f64) * fine;
                    if !workspace.contains(&r) {
                        continue;
                    }
                    let exact = correction(nominal, calibrated, &r)?;
                    let looked_up =
                        self.interpolate(&r)
                            .ok_or_else(|| KinematicsError::OutOfReach {
                                reason: format!("no table cell holds the workspace point {r:?}"),
                            })?;
                    for l in 0..3 {
                        worst = worst.max((looked_up[l] - exact[l]).abs());
                    }
                }
            }
        }
        Ok(worst * 1e3)
    }
}
