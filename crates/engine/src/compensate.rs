//! Compensation: command the machine through the identified model's IK and
//! compare where the platform goes before and after.
//!
//! "Before" commands come from the nominal IK, "after" from the IK of the
//! identified machine; both drive the actual machine's exact FK. The
//! residual after compensation is reported raw and with the best-fit rigid
//! translation removed (what touching off on the work piece removes).
//!
//! With the leg effects applied (`tricept compensate`): the correction the
//! calibrated model predicts on a plane ([`correction_map`]), where a true
//! machine goes when commanded by a machine's IK ([`commanded_map`]), the
//! workspace table a controller looks up with its measured interpolation
//! error ([`workspace_table`]), and the CSV files of the map and the
//! tables ([`map_csv`], [`table_csv`], [`leg_tables_csv`]).

use std::fmt::Write as _;

use nalgebra::Vector3;
use tricept_kinematics::description::LegTableDescription;
use tricept_kinematics::{KinematicsError, Machine, Workspace};
use tricept_model::{
    ExtendedMachine, ModelError, volumetric::ErrorMap, volumetric::volumetric_errors,
};

use crate::table::CompensationTable;

/// Before/after error maps of a compensation.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let id = tricept_engine::identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// let actual = tricept_model::actual::actual_machine(&m, &set.to_errors(&set.table2()));
/// let plane = m.workspace.disc_grid(750.0, 100.0);
/// let c = tricept_engine::compensate::compensation(&m, &model.machine_at(&id.estimate), &actual, &plane).unwrap();
/// assert!(c.after.stats().mean_mm < 0.2 * c.before.stats().mean_mm);
/// ```
#[derive(Debug, Clone)]
pub struct Compensation {
    /// Nominal commands on the actual machine.
    pub before: ErrorMap,
    /// Identified-model commands on the actual machine.
    pub after: ErrorMap,
}

/// Error maps over `targets_mm` of `actual` commanded by `nominal`
/// (before) and by `identified` (after).
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let nominal = Machine::paper();
/// let mut actual = nominal.clone();
/// actual.leg_offsets_mm = [0.3, -0.2, 0.1];
/// let targets = nominal.workspace.disc_grid(nominal.workspace.mid_plane_z_mm(), 100.0);
/// // A perfect identification removes the error entirely.
/// let c = tricept_engine::compensate::compensation(&nominal, &actual, &actual, &targets).unwrap();
/// assert!(c.before.stats().max_mm > 0.1 && c.after.stats().max_mm < 1e-9);
/// ```
pub fn compensation(
    nominal: &Machine,
    identified: &Machine,
    actual: &Machine,
    targets_mm: &[Vector3<f64>],
) -> Result<Compensation, ModelError> {
    Ok(Compensation {
        before: volumetric_errors(nominal, actual, targets_mm)?,
        after: volumetric_errors(identified, actual, targets_mm)?,
    })
}

/// Corrected leg commands for `targets_mm`: the identified machine's IK.
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// // A machine whose leg 1 is 0.1 mm long needs 0.1 mm less command.
/// let mut identified = m.clone();
/// identified.leg_offsets_mm[0] = 0.1;
/// let r = Vector3::new(0.0, 0.0, 750.0);
/// let q = tricept_engine::compensate::corrected_commands(&identified, &[r]).unwrap();
/// assert!((m.inverse(&r).unwrap().legs_mm[0] - q[0][0] - 0.1).abs() < 1e-12);
/// ```
pub fn corrected_commands(
    identified: &Machine,
    targets_mm: &[Vector3<f64>],
) -> Result<Vec<[f64; 3]>, ModelError> {
    targets_mm
        .iter()
        .map(|r| Ok(identified.inverse(r)?.legs_mm))
        .collect()
}

/// What the calibrated model says compensation changes on `grid`: where
/// the nominal commands put the platform of `calibrated`, minus the
/// target.
pub fn correction_map(
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
    grid: &[Vector3<f64>],
) -> Result<ErrorMap, KinematicsError> {
    let mut errors = Vec::with_capacity(grid.len());
    for r in grid {
        let ik = nominal.inverse(r)?;
        let p = calibrated.forward_from(&ik.legs_mm, &ik.up)?;
        errors.push(p.position_mm - r);
    }
    Ok(ErrorMap {
        targets_mm: grid.to_vec(),
        errors_mm: errors,
    })
}

/// Why a [`commanded_map`] stopped: the commanding machine's IK, or the
/// machine that was commanded.
#[derive(Debug, Clone, PartialEq)]
pub enum MapError<E> {
    /// A target the commanding machine cannot reach.
    Commanding(KinematicsError),
    /// The commanded machine failed.
    Reach(E),
}

/// Where a machine goes (`reach`: leg commands to its platform point, mm)
/// when commanded by the IK of `commanding`, minus the target, on `grid`.
pub fn commanded_map<E>(
    commanding: &ExtendedMachine,
    grid: &[Vector3<f64>],
    reach: impl Fn(&[f64; 3]) -> Result<Vector3<f64>, E>,
) -> Result<ErrorMap, MapError<E>> {
    let mut errors = Vec::with_capacity(grid.len());
    for r in grid {
        let q = commanding.inverse(r).map_err(MapError::Commanding)?.legs_mm;
        errors.push(reach(&q).map_err(MapError::Reach)? - r);
    }
    Ok(ErrorMap {
        targets_mm: grid.to_vec(),
        errors_mm: errors,
    })
}

/// The workspace table of a calibrated machine and the per-leg tables it
/// carries (exported as they are: the controller's pitch-error
/// compensation on each leg axis; the workspace table carries the rest,
/// which is smooth).
#[derive(Debug, Clone)]
pub struct WorkspaceTable {
    /// The table of leg-command corrections.
    pub table: CompensationTable,
    /// Its largest interpolation error, um.
    pub error_um: f64,
    /// The calibrated machine's per-leg tables (left out of `table`).
    pub leg_tables: Vec<LegTableDescription>,
}

/// Why a [`workspace_table`] could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum TableError {
    /// The grid of the stated spacing cannot be built.
    Spacing(KinematicsError),
    /// A node or a check point could not be solved.
    Kinematics(KinematicsError),
}

/// The compensation table from `nominal` to `calibrated` over `workspace`:
/// of grid spacing `spacing_mm`, or the coarsest spacing whose
/// interpolation error is below `limit_um` when none is given.
pub fn workspace_table(
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
    workspace: &Workspace,
    spacing_mm: Option<f64>,
    limit_um: f64,
) -> Result<WorkspaceTable, TableError> {
    let leg_tables = calibrated.machine().leg_effects.tables.clone();
    let calibrated = if leg_tables.is_empty() {
        calibrated.clone()
    } else {
        let mut m = calibrated.machine().clone();
        m.leg_effects.tables.clear();
        ExtendedMachine::new(m)
    };
    let (table, error_um) = match spacing_mm {
        Some(h) => {
            let t = CompensationTable::build(nominal, &calibrated, workspace, h)
                .map_err(TableError::Spacing)?;
            let e = t
                .interpolation_error_um(nominal, &calibrated, workspace)
                .map_err(TableError::Kinematics)?;
            (t, e)
        }
        None => CompensationTable::with_error_below(nominal, &calibrated, workspace, limit_um)
            .map_err(TableError::Kinematics)?,
    };
    Ok(WorkspaceTable {
        table,
        error_um,
        leg_tables,
    })
}

/// The per-point map as CSV: the predicted correction and, against a
/// true machine, the error before and after, mm.
pub fn map_csv(predicted: &ErrorMap, truth: Option<&(ErrorMap, ErrorMap)>) -> String {
    let mut csv = String::new();
    let _ = writeln!(
        csv,
        "# tricept compensate: per-point map on a plane, mm; correction = where the calibrated model says the nominal commands put the platform, minus the target"
    );
    if truth.is_some() {
        let _ = writeln!(
            csv,
            "# before/after = where the simulated true machine goes when commanded by the nominal / calibrated IK, minus the target"
        );
    }
    let mut header = "x,y,z,correction_dx,correction_dy,correction_dz,correction_mm".to_string();
    if truth.is_some() {
        header.push_str(
            ",before_dx,before_dy,before_dz,before_mm,after_dx,after_dy,after_dz,after_mm",
        );
    }
    let _ = writeln!(csv, "{header}");
    for (i, r) in predicted.targets_mm.iter().enumerate() {
        let c = predicted.errors_mm[i];
        let _ = write!(
            csv,
            "{},{},{},{},{},{},{}",
            r.x,
            r.y,
            r.z,
            c.x,
            c.y,
            c.z,
            c.norm()
        );
        if let Some((b, a)) = truth {
            let (b, a) = (b.errors_mm[i], a.errors_mm[i]);
            let _ = write!(
                csv,
                ",{},{},{},{},{},{},{},{}",
                b.x,
                b.y,
                b.z,
                b.norm(),
                a.x,
                a.y,
                a.z,
                a.norm()
            );
        }
        csv.push('\n');
    }
    csv
}

/// The workspace table as CSV (`table.csv`): the grid and the lookup in
/// the header, one row per reachable node.
pub fn table_csv(t: &WorkspaceTable, calibrated: &str, nominal: &str) -> String {
    let (tb, error_um) = (&t.table, t.error_um);
    let o = tb.origin_mm;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# tricept {} compensation table: leg-command corrections dq = q_calibrated - q_nominal (mm) on a regular grid",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(s, "# calibrated machine: {calibrated}");
    let _ = writeln!(s, "# nominal machine: {nominal}");
    let _ = writeln!(
        s,
        "# grid: origin_mm {} {} {}, spacing_mm {}, counts {} {} {}; node (i,j,k) at origin + spacing (i,j,k), i fastest",
        o.x, o.y, o.z, tb.spacing_mm, tb.counts[0], tb.counts[1], tb.counts[2]
    );
    let _ = writeln!(
        s,
        "# lookup: command = nominal IK + trilinear interpolation of dq at the eight corners of the cell holding the target"
    );
    let _ = writeln!(
        s,
        "# interpolation_error_um {error_um:.6} (largest difference from the exact correction on the lattice of spacing {} mm inside the workspace)",
        tb.spacing_mm / 4.0
    );
    let _ = writeln!(
        s,
        "# nodes the machine cannot reach are left out; every cell that meets the workspace has its eight corners"
    );
    let _ = writeln!(s, "i,j,k,x,y,z,dq1,dq2,dq3");
    for k in 0..tb.counts[2] {
        for j in 0..tb.counts[1] {
            for i in 0..tb.counts[0] {
                let idx = i + tb.counts[0] * (j + tb.counts[1] * k);
                if let Some(dq) = tb.nodes[idx] {
                    let r = o + Vector3::new(i as f64, j as f64, k as f64) * tb.spacing_mm;
                    let _ = writeln!(
                        s,
                        "{i},{j},{k},{},{},{},{},{},{}",
                        r.x, r.y, r.z, dq[0], dq[1], dq[2]
                    );
                }
            }
        }
    }
    s
}

/// The per-leg compensation tables of `machine` as CSV
/// (`leg-tables.csv`): one row per point
/// (`leg,command_mm,extra_length_um`), each table's range, spacing,
/// interpolation and source in the header.
pub fn leg_tables_csv(tables: &[LegTableDescription], machine: &Machine) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# tricept {} per-leg compensation tables of {}: the extra length of each leg (um) at equally spaced leg commands (mm)",
        env!("CARGO_PKG_VERSION"),
        machine.name
    );
    let _ = writeln!(
        s,
        "# interpolation: linear between the points, the end values beyond them; applied on each leg axis after table.csv: the command q with q + extra(q) = the table's command (to first order q = command - extra(command), the form of a CNC controller's pitch-error compensation)"
    );
    for t in tables {
        let _ = writeln!(
            s,
            "# leg {}: from {} mm every {} mm, {} points; {}",
            t.leg,
            t.start_mm,
            t.step_mm,
            t.extra_length_um.len(),
            t.source
        );
    }
    let _ = writeln!(s, "leg,command_mm,extra_length_um");
    for t in tables {
        for (k, v) in t.extra_length_um.iter().enumerate() {
            let _ = writeln!(s, "{},{},{v}", t.leg, t.start_mm + t.step_mm * k as f64);
        }
    }
    s
}
