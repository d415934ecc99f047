//! Compensate (`tricept compensate`): from data (calibrated here) or from a
//! calibrated machine file (with the static leg effects a diagnosis wrote
//! into it), the corrected commands of target points, the volumetric error
//! map on a plane before and after (against a simulated true machine when
//! its errors are given), and the compensation table a controller looks up,
//! with its measured interpolation error.
//!
//! [`compensate`] computes; the result writes its CSV files
//! ([`Compensation::map_csv`], [`Compensation::write_tables`]) and gives
//! the cells of its heat maps ([`Compensation::maps`]).
//!
//! # Example
//! ```no_run
//! use tricept_ident::MachineInput;
//! use tricept_ident::compensate::{Calibrated, CompensateRequest, compensate};
//! let calibrated = Calibrated::MachineFile(MachineInput::from("calibrated.json"));
//! let compensation = compensate(CompensateRequest::new(calibrated))?;
//! if let Some(targets) = compensation.corrected_targets() {
//!     for (target_mm, command) in targets {
//!         println!("{target_mm:?} -> {command:?}");
//!     }
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::linalg::Vector3;
use serde_json::{Map, Value, json};
use tricept_engine::compensate::{MapError, TableError, WorkspaceTable};
use tricept_model::ExtendedMachine;
use tricept_model::ParameterSet;
use tricept_plant::Effect;

use crate::Setting;
use crate::calibrate::{CalibrateRequest, calibrate, exit_reason, write_text};
use crate::error::{EXIT_INADEQUATE, EXIT_NOT_CONVERGED, Error};
use crate::inputs::TrueErrors;
use crate::machine_file::write_rule;
use crate::machine_input::MachineInput;

/// A volumetric error map on a plane ([`Compensation::maps`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::compensate::{Calibrated, CompensateRequest, ErrorMap, compensate};
/// let calibrated = Calibrated::MachineFile(MachineInput::from("calibrated.json"));
/// let compensation = compensate(CompensateRequest::new(calibrated))?;
/// let (map, _before_after): (&ErrorMap, _) = compensation.maps();
/// let worst_mm = map.errors_mm.iter().map(|e| e.norm()).fold(0.0, f64::max);
/// println!("{} points, worst {worst_mm} mm", map.targets_mm.len());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_model::volumetric::ErrorMap;
/// The largest, smallest, mean and RMS length of a map's error vectors
/// (mm): [`ErrorMap::stats`].
///
/// # Example
/// ```
/// use tricept_ident::compensate::{ErrorMap, MapStats};
/// use tricept_ident::kinematics::Vector3;
/// let map = ErrorMap {
///     targets_mm: vec![Vector3::new(0.0, 0.0, 700.0), Vector3::new(100.0, 0.0, 700.0)],
///     errors_mm: vec![Vector3::new(0.003, 0.004, 0.0), Vector3::new(0.0, 0.0, 0.001)],
/// };
/// let stats: MapStats = map.stats();
/// assert!((stats.max_mm - 0.005).abs() < 1e-15); // |(3, 4, 0) um| = 5 um
/// assert!((stats.min_mm - 0.001).abs() < 1e-15);
/// assert!((stats.mean_mm - 0.003).abs() < 1e-15);
/// assert!((stats.rms_mm - 13e-6f64.sqrt()).abs() < 1e-15); // sqrt((25 + 1) / 2) um
/// ```
#[doc(inline)]
pub use tricept_model::volumetric::MapStats;

/// The largest interpolation error (um) the default table spacing allows.
///
/// # Example
/// ```
/// use tricept_ident::compensate::TABLE_ERROR_LIMIT_UM;
/// // A table whose interpolation error exceeds it is refined, never used.
/// assert!(TABLE_ERROR_LIMIT_UM <= 1.0);
/// ```
pub const TABLE_ERROR_LIMIT_UM: f64 = 1.0;

/// The files of a map directory.
///
/// # Example
/// ```
/// use tricept_ident::compensate::MAP_FILES;
/// let dir = std::path::Path::new("maps");
/// let files: Vec<_> = MAP_FILES.iter().map(|f| dir.join(f)).collect();
/// assert_eq!(files[0], dir.join("map.csv"));
/// ```
pub const MAP_FILES: &[&str] = &["map.csv", "correction.svg", "before.svg", "after.svg"];
/// The files of a table directory (the second only for a machine with
/// per-leg compensation tables).
///
/// # Example
/// ```
/// use tricept_ident::compensate::TABLE_FILES;
/// assert!(TABLE_FILES.contains(&"table.csv"));
/// ```
pub const TABLE_FILES: &[&str] = &["table.csv", "leg-tables.csv"];

/// Where the calibrated machine comes from.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::calibrate::CalibrateRequest;
/// use tricept_ident::compensate::Calibrated;
/// // From a calibrated machine file, or calibrated here from data.
/// let from_file = Calibrated::MachineFile(MachineInput::from("calibrated.json"));
/// let from_data = Calibrated::Data(Box::new(CalibrateRequest::new("campaign.csv")));
/// assert!(matches!(from_file, Calibrated::MachineFile(_)));
/// assert!(matches!(from_data, Calibrated::Data(_)));
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Calibrated {
    /// Calibrated here from data.
    Data(Box<CalibrateRequest>),
    /// A calibrated machine file, compensated against the nominal machine
    /// its record holds.
    MachineFile(MachineInput),
}

/// What to compensate, and what to produce.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::compensate::{Calibrated, CompensateRequest};
/// let request = CompensateRequest::new(Calibrated::MachineFile(MachineInput::from("calibrated.json")));
/// assert_eq!(request.spacing_mm, 10.0);
/// assert!(request.map_dir.is_none() && request.table_dir.is_none());
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CompensateRequest {
    /// The calibrated machine.
    pub calibrated: Calibrated,
    /// Compensate even from a calibration that is not to be trusted.
    pub force: bool,
    /// The true errors of a simulated machine (before/after maps).
    pub truth: Option<TrueErrors>,
    /// The true machine's unmodelled effects (need `truth`).
    pub truth_effects: Vec<Effect>,
    /// The parameter set of `truth`.
    pub parameter_set: ParameterSet,
    /// Plane of the map, z in mm (default: the workspace's middle plane).
    pub plane_z_mm: Option<f64>,
    /// Lattice spacing of the map, mm (at least 1).
    pub spacing_mm: f64,
    /// Target points to correct (CSV x,y,z).
    pub targets: Option<PathBuf>,
    /// The directory the map is written to (named in the JSON).
    pub map_dir: Option<PathBuf>,
    /// The directory the compensation table is written to: the table is
    /// built when given.
    pub table_dir: Option<PathBuf>,
    /// Grid spacing of the table, mm (default: the coarsest whose
    /// interpolation error is below [`TABLE_ERROR_LIMIT_UM`]).
    pub table_spacing_mm: Option<f64>,
}

impl CompensateRequest {
    /// A compensation of `calibrated` with the defaults (10 mm map).
    pub fn new(calibrated: Calibrated) -> CompensateRequest {
        CompensateRequest {
            calibrated,
            force: false,
            truth: None,
            truth_effects: Vec::new(),
            parameter_set: ParameterSet::paper15(),
            plane_z_mm: None,
            spacing_mm: 10.0,
            targets: None,
            map_dir: None,
            table_dir: None,
            table_spacing_mm: None,
        }
    }
}

crate::request::setters!(CompensateRequest {
    force: bool,
    truth: some TrueErrors,
    truth_effects: Vec<Effect>,
    parameter_set: ParameterSet,
    plane_z_mm: some f64,
    spacing_mm: f64,
    targets: some into PathBuf,
    map_dir: some into PathBuf,
    table_dir: some into PathBuf,
    table_spacing_mm: some f64,
});

/// A target (mm) and its corrected leg commands (mm).
///
/// # Example
/// ```
/// use tricept_ident::compensate::CorrectedTarget;
/// use tricept_ident::kinematics::Vector3;
/// let (target_mm, legs_mm): CorrectedTarget = (Vector3::new(0.0, 0.0, 750.0), [773.3, 773.3, 773.3]);
/// assert_eq!(target_mm.z, 750.0);
/// assert_eq!(legs_mm.len(), 3);
/// ```
pub type CorrectedTarget = (Vector3, [f64; 3]);

/// The compensation table and where it is written.
#[derive(Debug, Clone)]
struct Table {
    built: WorkspaceTable,
    path: PathBuf,
    legs_path: PathBuf,
}

/// A compensation: its JSON fields, maps, table and corrected targets.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::compensate::{Calibrated, CompensateRequest, compensate};
/// let calibrated = Calibrated::MachineFile(MachineInput::from("calibrated.json"));
/// let compensation = compensate(CompensateRequest::new(calibrated))?;
/// println!("map spacing {} mm", compensation.spacing_mm());
/// if let Some(targets) = compensation.corrected_targets() {
///     for (target_mm, command) in targets {
///         println!("{target_mm:?} -> {command:?}");
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Compensation {
    out: Map<String, Value>,
    nominal: ExtendedMachine,
    calibrated: ExtendedMachine,
    predicted: ErrorMap,
    truth: Option<(ErrorMap, ErrorMap)>,
    table: Option<Table>,
    targets: Option<Vec<CorrectedTarget>>,
    warnings: Vec<String>,
    machine_warnings: Vec<String>,
    code: u8,
    reason: Option<String>,
    z_mm: f64,
    spacing_mm: f64,
}

crate::outcome::outcome!(Compensation);

/// The two machines of a compensation and where they came from.
struct Pair {
    nominal: ExtendedMachine,
    calibrated: ExtendedMachine,
    out: Map<String, Value>,
    warnings: Vec<String>,
    machine_warnings: Vec<String>,
    code: u8,
    why: String,
}

fn machines(r: &CompensateRequest) -> Result<Pair, Error> {
    let mut out = Map::new();
    match &r.calibrated {
        Calibrated::Data(request) => {
            let fit = calibrate(CalibrateRequest::clone(request))?;
            let code = fit.exit_code();
            write_rule(
                "compensate",
                code,
                &fit.refusal().unwrap_or_default(),
                r.force,
            )?;
            out.insert("data_file".into(), request.data.name().into());
            out.insert("converged".into(), fit.converged().into());
            out.insert("adequate".into(), fit.adequate().into());
            out.insert("rejected".into(), fit.rejected_json());
            Ok(Pair {
                nominal: ExtendedMachine::new(fit.loaded().machine().clone()),
                calibrated: ExtendedMachine::new(fit.identified_geometry()),
                out,
                warnings: fit.warnings().to_vec(),
                machine_warnings: fit.machine_warnings().to_vec(),
                code,
                why: fit.why(),
            })
        }
        Calibrated::MachineFile(machine) => {
            let loaded = machine.clone().load()?;
            let Some(c) = &loaded.description().calibration else {
                return Err(Error::input(format!(
                    "compensate: give data (a CSV file) to identify from, or a calibrated machine file as the machine ({} holds no `calibration` record)",
                    loaded.source()
                )));
            };
            let nominal = c
                .nominal
                .build()
                .map_err(|e| crate::inputs::description_error(loaded.source(), e))?;
            let (code, why) = if !c.converged {
                (EXIT_NOT_CONVERGED, "its calibration did not converge")
            } else if c.forced || !c.adequate {
                (
                    EXIT_INADEQUATE,
                    "its calibration is not to be trusted (written forced, or its model did not explain its data)",
                )
            } else {
                (0, "")
            };
            write_rule(loaded.source(), code, why, r.force)?;
            out.insert("machine".into(), loaded.description().name.clone().into());
            out.insert("converged".into(), c.converged.into());
            out.insert("adequate".into(), c.adequate.into());
            Ok(Pair {
                nominal: ExtendedMachine::new(nominal),
                calibrated: ExtendedMachine::new(loaded.machine().clone()),
                out,
                warnings: Vec::new(),
                machine_warnings: loaded.warnings().to_vec(),
                code,
                why: why.to_string(),
            })
        }
    }
}

fn stats_json(s: &MapStats) -> Value {
    json!({"max_mm": s.max_mm, "min_mm": s.min_mm, "mean_mm": s.mean_mm, "rms_mm": s.rms_mm})
}

/// Compensates as `request` says.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::compensate::{Calibrated, CompensateRequest, compensate};
/// let calibrated = Calibrated::MachineFile(MachineInput::from("calibrated.json"));
/// let compensation = compensate(CompensateRequest::new(calibrated))?;
/// if let Some(targets) = compensation.corrected_targets() {
///     for (target_mm, command) in targets {
///         println!("{target_mm:?} -> {command:?}");
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn compensate(request: CompensateRequest) -> Result<Compensation, Error> {
    let request = &request;
    let spacing = request.spacing_mm;
    if !(spacing.is_finite() && spacing >= 1.0) {
        return Err(Error::invalid(
            Setting::Spacing,
            format!("the map's lattice spacing must be at least 1 mm, got {spacing} mm"),
        ));
    }
    if let Some(h) = request.table_spacing_mm
        && !(h.is_finite() && h >= 1.0)
    {
        return Err(Error::invalid(
            Setting::TableSpacing,
            format!("the table's grid spacing must be at least 1 mm, got {h} mm"),
        ));
    }
    let Pair {
        nominal,
        calibrated,
        mut out,
        mut warnings,
        machine_warnings,
        code,
        why,
    } = machines(request)?;
    let w = nominal.machine().workspace;
    let z = request.plane_z_mm.unwrap_or_else(|| w.mid_plane_z_mm());
    if !(z.is_finite() && z >= w.z_min_mm && z <= w.z_max_mm) {
        return Err(Error::invalid(
            Setting::PlaneZ,
            format!(
                "{z} mm is outside the workspace, whose z runs from {} to {} mm",
                w.z_min_mm, w.z_max_mm
            ),
        ));
    }
    let points = std::f64::consts::PI * (w.radius_mm / spacing + 1.0).powi(2);
    if points > crate::limits::MAX_MAP_POINTS as f64 {
        return Err(Error::invalid_value(
            Setting::Spacing,
            format!("{spacing} mm"),
            format!(
                "about {points:.0} map points, more than {}; a coarser spacing is needed",
                crate::limits::MAX_MAP_POINTS
            ),
        ));
    }
    let grid = w.disc_grid(z, spacing);
    // What compensation changes, as the calibrated model sees it: nominal
    // commands, positions by the calibrated machine.
    let predicted = tricept_engine::compensate::correction_map(&nominal, &calibrated, &grid)
        .map_err(|e| Error::with_context(MAP_CONTEXT, e))?;
    out.insert("plane_z_mm".into(), z.into());
    out.insert("grid_points".into(), grid.len().into());
    out.insert(
        "predicted_correction".into(),
        stats_json(&predicted.stats()),
    );
    let truth = truth_maps(request, &nominal, &calibrated, &grid)?;
    if let Some((before, after)) = &truth {
        let residual = after.without_mean_translation();
        let t = after.mean_translation_mm();
        out.insert("before".into(), stats_json(&before.stats()));
        out.insert("after".into(), stats_json(&after.stats()));
        out.insert(
            "after_without_translation".into(),
            stats_json(&residual.stats()),
        );
        out.insert("translation_mm".into(), json!([t.x, t.y, t.z]));
    }
    if let Some(dir) = &request.map_dir {
        out.insert("map".into(), dir.display().to_string().into());
    }
    let table = match &request.table_dir {
        Some(dir) => Some(table(request, dir, &nominal, &calibrated, &mut warnings)?),
        None => None,
    };
    if let Some(t) = &table {
        let mut entry = json!({
            "file": t.path.display().to_string(),
            "spacing_mm": t.built.table.spacing_mm,
            "counts": t.built.table.counts,
            "interpolation_error_um": t.built.error_um,
        });
        if !t.built.leg_tables.is_empty() {
            entry["leg_tables"] = t.legs_path.display().to_string().into();
        }
        out.insert("table".into(), entry);
    }
    out.insert("warnings".into(), warnings.clone().into());
    let targets = match &request.targets {
        Some(path) => Some(corrected_targets(path, &calibrated)?),
        None => None,
    };
    Ok(Compensation {
        out,
        nominal,
        calibrated,
        predicted,
        truth,
        table,
        targets,
        warnings,
        machine_warnings,
        code,
        reason: exit_reason(code, &why),
        z_mm: z,
        spacing_mm: spacing,
    })
}

/// The errors of a map's solutions name the map.
const MAP_CONTEXT: &str = "compensation map";

/// The compensation table (`tricept_engine::compensate::workspace_table`)
/// and where it goes.
fn table(
    request: &CompensateRequest,
    dir: &Path,
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
    warnings: &mut Vec<String>,
) -> Result<Table, Error> {
    let w = &nominal.machine().workspace;
    let built = tricept_engine::compensate::workspace_table(
        nominal,
        calibrated,
        w,
        request.table_spacing_mm,
        TABLE_ERROR_LIMIT_UM,
    )
    .map_err(|e| match (e, request.table_spacing_mm) {
        (TableError::Spacing(e), Some(h)) => {
            Error::from_library(e).in_setting_value(Setting::TableSpacing, h)
        }
        (TableError::Spacing(e) | TableError::Kinematics(e), _) => {
            Error::with_context(MAP_CONTEXT, e)
        }
    })?;
    if built.error_um >= TABLE_ERROR_LIMIT_UM {
        warnings.push(format!(
            "the compensation table's interpolation error is {:.3} um at {} mm spacing, above {TABLE_ERROR_LIMIT_UM} um: a finer table spacing (table_spacing) reduces it",
            built.error_um, built.table.spacing_mm
        ));
    }
    Ok(Table {
        built,
        path: dir.join(TABLE_FILES[0]),
        legs_path: dir.join(TABLE_FILES[1]),
    })
}

/// Before/after maps of the simulated true machine.
fn truth_maps(
    request: &CompensateRequest,
    nominal: &ExtendedMachine,
    calibrated: &ExtendedMachine,
    grid: &[Vector3],
) -> Result<Option<(ErrorMap, ErrorMap)>, Error> {
    let Some(truth) = &request.truth else {
        if !request.truth_effects.is_empty() {
            return Err(Error::invalid(
                Setting::TruthEffect,
                "needs the truth (the true errors of the simulated machine)",
            ));
        }
        return Ok(None);
    };
    let set = &request.parameter_set;
    let mut plant = tricept_plant::Plant::geometric(
        nominal.machine().clone(),
        set.to_errors(&truth.values(set)?),
    );
    plant.effects = request.truth_effects.clone();
    // Where the true machine goes when commanded by a machine's IK.
    let map = |commanding: &ExtendedMachine| -> Result<ErrorMap, Error> {
        tricept_engine::compensate::commanded_map(commanding, grid, |q| plant.reach(q)).map_err(
            |e| match e {
                MapError::Commanding(e) => Error::with_context(MAP_CONTEXT, e),
                MapError::Reach(e) => Error::with_context(MAP_CONTEXT, e),
            },
        )
    };
    Ok(Some((map(nominal)?, map(calibrated)?)))
}

fn corrected_targets(
    path: &Path,
    calibrated: &ExtendedMachine,
) -> Result<Vec<CorrectedTarget>, Error> {
    let points = tricept_data::targets::read_targets(path)?;
    let mut rows = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        let r = Vector3::from(*p);
        let q = calibrated.inverse(&r).map_err(|e| {
            Error::input(format!(
                "{}: target {} ({}, {}, {} mm): {e}",
                path.display(),
                k + 1,
                r.x,
                r.y,
                r.z
            ))
        })?;
        rows.push((r, q.legs_mm));
    }
    Ok(rows)
}

impl Compensation {
    /// 0, or the exit code of a calibration that is not to be trusted and
    /// was compensated from with `force` (3, 4).
    pub fn exit_code(&self) -> u8 {
        self.code
    }

    /// Why the exit code is not 0, in one phrase (`None` when it is 0):
    /// why the calibration compensated from is not to be trusted.
    pub fn reason(&self) -> Option<&str> {
        self.reason.as_deref()
    }

    /// The warnings of the compensation (the calibration's, the table's).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The warnings of the machine file loaded.
    pub fn machine_warnings(&self) -> &[String] {
        &self.machine_warnings
    }

    /// The corrected commands of the target points, when asked for.
    pub fn corrected_targets(&self) -> Option<&[CorrectedTarget]> {
        self.targets.as_deref()
    }

    /// The map of the predicted correction and, against a true machine,
    /// the error maps before and after.
    pub fn maps(&self) -> (&ErrorMap, Option<&(ErrorMap, ErrorMap)>) {
        (&self.predicted, self.truth.as_ref())
    }

    /// The lattice spacing of the maps, mm.
    pub fn spacing_mm(&self) -> f64 {
        self.spacing_mm
    }

    /// The JSON `tricept compensate --json` prints (`format_version`
    /// first).
    pub fn to_json(&self) -> Value {
        let mut out = self.out.clone();
        if let Some(rows) = &self.targets {
            out.insert(
                "corrected_commands".into(),
                Value::Array(
                    rows.iter()
                        .map(|(r, q)| json!({"x": r.x, "y": r.y, "z": r.z, "q1": q[0], "q2": q[1], "q3": q[2]}))
                        .collect(),
                ),
            );
        }
        crate::outcome::versioned(Value::Object(out))
    }

    /// The text report.
    pub fn report(&self) -> String {
        let out = &self.out;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "compensation over the plane z = {} mm ({} points, {} mm lattice)",
            self.z_mm,
            self.predicted.targets_mm.len(),
            self.spacing_mm
        );
        for key in [
            "predicted_correction",
            "before",
            "after",
            "after_without_translation",
        ] {
            if let Some(v) = out.get(key) {
                let _ = writeln!(
                    s,
                    "{key:>26}: max {:.4} / min {:.4} / mean {:.4} mm",
                    v["max_mm"].as_f64().unwrap_or(f64::NAN),
                    v["min_mm"].as_f64().unwrap_or(f64::NAN),
                    v["mean_mm"].as_f64().unwrap_or(f64::NAN)
                );
            }
        }
        if let Some(Value::Array(t)) = out.get("translation_mm") {
            let t: Vec<f64> = t.iter().filter_map(Value::as_f64).collect();
            if let [x, y, zt] = t[..] {
                let _ = writeln!(
                    s,
                    "{:>26}: ({x:.4}, {y:.4}, {zt:.4}) mm",
                    "rigid translation"
                );
            }
        }
        if let Some(m) = out.get("map").and_then(Value::as_str) {
            let _ = writeln!(s, "{:>26}: {m}/map.csv and SVG heat maps", "per-point map");
        }
        if let Some(t) = out.get("table") {
            let _ = writeln!(
                s,
                "{:>26}: {} ({} mm grid, {} nodes along x, y, z); trilinear interpolation error {:.3} um (largest over a lattice 4 times finer)",
                "compensation table",
                t["file"].as_str().unwrap_or(""),
                t["spacing_mm"],
                t["counts"],
                t["interpolation_error_um"].as_f64().unwrap_or(f64::NAN)
            );
        }
        for w in &self.warnings {
            let _ = writeln!(s, "WARNING: {w}");
        }
        s
    }

    /// The per-point map as CSV: the predicted correction and, against a
    /// true machine, the error before and after, mm.
    pub fn map_csv(&self) -> String {
        tricept_engine::compensate::map_csv(&self.predicted, self.truth.as_ref())
    }

    /// Writes the compensation table (and the per-leg tables of a machine
    /// that has them) atomically into the table directory, creating it;
    /// returns the files written.
    pub fn write_tables(&self) -> Result<Vec<PathBuf>, Error> {
        let Some(t) = &self.table else {
            return Ok(Vec::new());
        };
        if let Some(dir) = t.path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| {
                Error::other(format!(
                    "{}: cannot create the directory: {e}",
                    dir.display()
                ))
                .with_file_failure(crate::error::FileFailure::new(
                    dir.display().to_string(),
                    &e,
                ))
            })?;
        }
        let csv = tricept_engine::compensate::table_csv(
            &t.built,
            &self.calibrated.machine().name,
            &self.nominal.machine().name,
        );
        write_text(&t.path, &csv)?;
        let mut written = vec![t.path.clone()];
        if !t.built.leg_tables.is_empty() {
            let csv = tricept_engine::compensate::leg_tables_csv(
                &t.built.leg_tables,
                self.calibrated.machine(),
            );
            write_text(&t.legs_path, &csv)?;
            written.push(t.legs_path.clone());
        }
        Ok(written)
    }
}
