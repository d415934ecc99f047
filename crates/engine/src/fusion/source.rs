//! Data sources of a fused identification: each is a block of weighted
//! rows with its own noise and its own nuisance parameters, on the exact
//! model.
//!
//! | source | rows per record | nuisance parameters |
//! |---|---|---|
//! | internal (UP limb) | 3 readings | 3 sensor zero offsets (linear) |
//! | tracker / CMM | 3 coordinates | target offset (3) + per station: frame rotation (3), translation (3) |
//! | ballbar | 1 length | per setup: pivot (3), bar length error (1, with a prior) |
//! | touch-offs | 1 contact | stylus radius (1, with a prior); per sphere: centre (3); per plane: tilt (2), offset (1) |
//!
//! A nuisance parameter that the model depends on nonlinearly (a frame, a
//! pivot) is carried from one evaluation to the next and moved by each
//! accepted step; rotations and plane normals are re-based after every
//! step, so that their coordinates stay small (zero at the current
//! estimate) and the Jacobian is exact. The internal source's offsets are
//! linear and re-solved at every evaluation, exactly as
//! [`crate::identify`] does.
//!
//! What every external instrument's source shares is written here once:
//! its records with their standard deviations and file ([`Readings`]:
//! built from the data layer's [`InstrumentRecord`]s, grouped by setup,
//! the lines of a group for a message), the [`SourceRows`] methods that
//! only read them (file, record count, pose, line, row count, the copy),
//! and the loops over the records' spindle points: `initial` (every
//! point at the start, handed to `fit_start`) and `evaluate` (every point
//! with its Jacobian, handed to `point_rows`, then `priors`). Adding an
//! instrument is one file in this folder: a struct holding a `Readings`
//! and what is new (options, the nuisance's layout in `start`, its
//! closed-form `fit_start`, the rows of one point, the priors, `retract`
//! when not additive), its `Source::` constructor, and a [`SourceKind`];
//! its record and reader are
//! one file in `tricept-data`'s `external/`, its simulated reading one in
//! `tricept-plant`'s `instruments/`.

use nalgebra::{Matrix3, Vector3};
use tricept_data::{external::ExternalData, external::ExternalPose, external::InstrumentRecord};
use tricept_kinematics::up_limb::UpJoints;
use tricept_model::head_errors::Effector;
use tricept_numerics::linalg::TriangularAccumulator;
use tricept_numerics::lsq::ReducedProblem;

use crate::error::IdentError;
use crate::fusion::model::{FusedAt, FusedModel, LegContext, SpindlePoint};

/// What kind of instrument a source is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum SourceKind {
    /// The UP limb's own sensors.
    Internal,
    /// A laser tracker or CMM measuring a point in the spindle.
    Tracker,
    /// A ballbar from the spindle ball to a pivot on the table.
    Ballbar,
    /// A probe in the spindle touching reference spheres and planes.
    Touch,
}

impl SourceKind {
    /// The lowercase name (`internal`, `tracker`, `ballbar`, `touch`).
    pub fn as_str(self) -> &'static str {
        match self {
            SourceKind::Internal => "internal",
            SourceKind::Tracker => "tracker",
            SourceKind::Ballbar => "ballbar",
            SourceKind::Touch => "touch",
        }
    }
}

/// The nuisance parameters of a source as carried between evaluations:
/// values (additive coordinates), and the bases that rotations and plane
/// normals are re-based on.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Nuisance {
    /// One value per nuisance parameter.
    pub values: Vec<f64>,
    /// Frame rotations (tracker stations).
    pub rotations: Vec<Matrix3<f64>>,
    /// Plane normals (touch features; zero for spheres).
    pub normals: Vec<Vector3<f64>>,
}

impl Nuisance {
    /// Moves every value by its step.
    pub fn add(&mut self, step: &[f64]) {
        for (v, s) in self.values.iter_mut().zip(step) {
            *v += s;
        }
    }
}

/// The rows of one source being accumulated: `[nuisance | parameters |
/// residual]`, each weighted by `1 / sigma`, and the standardised data
/// residuals by record. Records outside the fit (set aside by the
/// gross-error screen) are evaluated but not accumulated.
pub(crate) struct Sink {
    acc: TriangularAccumulator,
    n_nuisance: usize,
    k: usize,
    row: Vec<f64>,
    /// `(record, standardised residual, residual)` of every data row in the fit.
    pub standardised: Vec<(usize, f64, f64)>,
    /// Every weighted row, of records outside the fit too, and every prior.
    kept: KeptRows,
    /// Which records are in the fit (`None`: all).
    active: Option<Vec<bool>>,
}

/// The weighted rows `[nuisance | parameters | residual]` a sink saw, each
/// with its record (`None`: a prior), stored flat.
#[derive(Debug, Clone, Default)]
pub(crate) struct KeptRows {
    width: usize,
    values: Vec<f64>,
    records: Vec<Option<usize>>,
}

impl KeptRows {
    fn push(&mut self, record: Option<usize>, row: &[f64]) {
        self.values.extend_from_slice(row);
        self.records.push(record);
    }

    /// Every row with its record.
    pub fn iter(&self) -> impl Iterator<Item = (Option<usize>, &[f64])> {
        self.records
            .iter()
            .zip(self.values.chunks_exact(self.width.max(1)))
            .map(|(r, v)| (*r, v))
    }
}

impl Sink {
    /// A sink for `n_nuisance` nuisance and `k` global parameters, sized
    /// for about `rows` rows.
    pub fn new(n_nuisance: usize, k: usize, rows: usize) -> Sink {
        Sink {
            acc: TriangularAccumulator::with_rows_hint(n_nuisance + k + 1, rows),
            n_nuisance,
            k,
            row: vec![0.0; n_nuisance + k + 1],
            standardised: Vec::with_capacity(rows),
            kept: KeptRows {
                width: n_nuisance + k + 1,
                values: Vec::with_capacity(rows * (n_nuisance + k + 1)),
                records: Vec::with_capacity(rows),
            },
            active: None,
        }
    }

    /// The same sink, accumulating only the records marked in `active`.
    pub fn with_active(mut self, active: &[bool]) -> Sink {
        self.active = (!active.iter().all(|a| *a)).then(|| active.to_vec());
        self
    }

    /// Every row the sink saw, with its record (`None`: a prior).
    pub fn take_kept(&mut self) -> Vec<(Option<usize>, Vec<f64>)> {
        let kept = std::mem::take(&mut self.kept);
        kept.iter().map(|(r, v)| (r, v.to_vec())).collect()
    }

    /// One data row of `record`: weight `w = 1 / sigma`, the derivatives of
    /// the model with respect to the nuisance parameters and to the global
    /// parameters, and the residual `measured - model`.
    pub fn data(&mut self, record: usize, w: f64, nuisance: &[f64], theta: &[f64], residual: f64) {
        let (nn, k) = (self.n_nuisance, self.k);
        for (r, v) in self.row[..nn].iter_mut().zip(nuisance) {
            *r = w * v;
        }
        for (r, v) in self.row[nn..nn + k].iter_mut().zip(theta) {
            *r = w * v;
        }
        self.row[nn + k] = w * residual;
        self.kept.push(Some(record), &self.row);
        if self
            .active
            .as_ref()
            .is_some_and(|a| !a.get(record).copied().unwrap_or(true))
        {
            return;
        }
        self.acc.push_row(&self.row);
        self.standardised.push((record, w * residual, residual));
    }

    /// A prior on nuisance parameter `column`: `(prior - value) / sigma`.
    pub fn prior(&mut self, column: usize, sigma: f64, residual: f64) {
        self.row.iter_mut().for_each(|v| *v = 0.0);
        self.row[column] = 1.0 / sigma;
        self.row[self.n_nuisance + self.k] = residual / sigma;
        self.acc.push_row(&self.row);
        self.kept.push(None, &self.row);
    }

    /// The reduced problem of the rows pushed, their standardised residuals
    /// and every row seen.
    pub fn finish(self) -> (ReducedProblem, Vec<(usize, f64, f64)>, KeptRows) {
        let rows = self.acc.rows();
        (
            ReducedProblem {
                rows,
                r: self.acc.finish(),
                n_nuisance: self.n_nuisance,
                k: self.k,
            },
            self.standardised,
            self.kept,
        )
    }
}

/// The records of a source as the fused identification reads them: the
/// file, how many, and each one's pose and line.
pub(crate) trait RecordList {
    /// The file (or label) the records came from.
    fn file(&self) -> &str;
    /// Number of records.
    fn len(&self) -> usize;
    /// Where the machine stood at a record.
    fn pose(&self, record: usize) -> ExternalPose;
    /// The record's line in its file.
    fn line(&self, record: usize) -> u64;
}

/// The records of an external instrument's file with each one's standard
/// deviation (mm): what every external source holds.
#[derive(Debug, Clone)]
pub(crate) struct Readings<R> {
    /// Records in file order.
    pub records: Vec<R>,
    /// Standard deviation of each record's rows, mm.
    pub sigma_mm: Vec<f64>,
    /// The file the records came from.
    pub file: String,
}

impl<R: InstrumentRecord> Readings<R> {
    /// The records of `data`, a row without `sigma_um` at `default_sigma_um`.
    pub fn new(data: &ExternalData<R>, default_sigma_um: f64) -> Readings<R> {
        Readings {
            sigma_mm: data
                .records
                .iter()
                .map(|r| 1e-3 * r.reading().sigma_um.unwrap_or(default_sigma_um))
                .collect(),
            records: data.records.clone(),
            file: data.source.clone(),
        }
    }

    /// The records' setups (sorted) and each record's index into them; a
    /// setup with fewer than `min` records is refused with
    /// `message(setup, count)` ([`groups`]).
    pub fn setups(
        &self,
        min: usize,
        message: impl Fn(u32, usize) -> String,
    ) -> Result<(Vec<u32>, Vec<usize>), IdentError> {
        let keyed = self.records.iter().map(|r| {
            let common = r.reading();
            (common.setup.unwrap_or(1), common.line)
        });
        groups(&self.file, keyed, min, message)
    }

    /// The refusal of a group of records (those `in_group`) whose geometry
    /// cannot be fitted: `message` given the group's lines (`lines 3, 7`).
    pub fn degenerate(
        &self,
        in_group: impl Fn(usize) -> bool,
        message: impl FnOnce(String) -> String,
    ) -> IdentError {
        let lines = (0..self.records.len())
            .filter(|&j| in_group(j))
            .map(|j| self.records[j].reading().line);
        IdentError::Source {
            file: self.file.clone(),
            line: None,
            message: message(lines_text(lines)),
        }
    }
}

impl<R: InstrumentRecord> RecordList for Readings<R> {
    fn file(&self) -> &str {
        &self.file
    }

    fn len(&self) -> usize {
        self.records.len()
    }

    fn pose(&self, record: usize) -> ExternalPose {
        self.records[record].reading().pose
    }

    fn line(&self, record: usize) -> u64 {
        self.records[record].reading().line
    }
}

/// A boxed copy of a source's rows (written once for every `Clone` source).
pub(crate) trait BoxedClone {
    /// A copy.
    fn boxed_clone(&self) -> Box<dyn SourceRows>;
}

impl<T: SourceRows + Clone + 'static> BoxedClone for T {
    fn boxed_clone(&self) -> Box<dyn SourceRows> {
        Box::new(self.clone())
    }
}

/// What every kind of source provides to the fused identification.
pub(crate) trait SourceRows: BoxedClone + Send + Sync + std::fmt::Debug {
    /// The kind of instrument.
    fn kind(&self) -> SourceKind;
    /// The source's records.
    fn record_list(&self) -> &dyn RecordList;
    /// The file (or label) the records came from.
    fn file(&self) -> &str {
        self.record_list().file()
    }
    /// Nuisance parameter names (the source's label is prefixed by the caller).
    fn nuisance_names(&self) -> Vec<String>;
    /// Number of records.
    fn records(&self) -> usize {
        self.record_list().len()
    }
    /// Data rows each record gives (3 for a point or the UP limb's
    /// readings, 1 for a length or a touch).
    fn rows_each(&self) -> usize;
    /// Number of data rows (records times rows per record).
    fn data_rows(&self) -> usize {
        self.rows_each() * self.records()
    }
    /// Number of prior rows (a known target offset, a certified bar
    /// length, a stylus radius).
    fn prior_rows(&self) -> usize {
        0
    }
    /// Data rows per record: [`SourceRows::rows_each`], 0 without records.
    fn rows_per_record(&self) -> usize {
        self.data_rows() / self.records().max(1)
    }
    /// The redundancy (degrees of freedom) below which the source's rows
    /// cannot check the fit: 6 per tracker station, 4 per ballbar setup or
    /// touched feature, 6 for the UP limb's data
    /// ([`crate::fusion::SourceFit::checkable`]).
    fn min_redundancy(&self) -> f64;
    /// The source's nuisance estimates that have a plausible size:
    /// `(table key, nuisance index, value judged)` for the values reported
    /// by [`SourceRows::report_values`] (e.g. a target offset's change from
    /// its stated value).
    fn judged_nuisance(&self, _values: &[f64]) -> Vec<(&'static str, usize, f64)> {
        Vec::new()
    }
    /// The tracker target's stated offset (tracker sources only).
    fn tracker_target(&self) -> Option<TrackerTarget> {
        None
    }
    /// The stated offset from the tool tip (mm, spindle frame at zero head
    /// angles) of the point the source measures, when it is stated and not
    /// zero: a known tracker target's, a ballbar's ball's.
    fn stated_offset_mm(&self) -> Option<Vector3<f64>> {
        None
    }
    /// The same records with another statement of the tracker target
    /// (tracker sources only): what the likely-cause search refits.
    fn with_tracker_target(&self, _target: TrackerTarget) -> Option<Box<dyn SourceRows>> {
        None
    }
    /// Where the machine stood at a record.
    fn pose(&self, record: usize) -> ExternalPose {
        self.record_list().pose(record)
    }
    /// The record's line in its file.
    fn line(&self, record: usize) -> u64 {
        self.record_list().line(record)
    }
    /// Unit of the residuals in um for reports (`None`: mixed units).
    fn residual_unit_um(&self) -> Option<f64> {
        Some(1e3)
    }
    /// Whether the nuisance is linear and re-solved at every evaluation
    /// (nothing carried).
    fn linear_nuisance(&self) -> bool {
        false
    }
    /// The effector whose point the instrument measures at a record under
    /// the nuisance `nu` (default: the tool tip).
    fn effector(&self, _record: usize, _nu: &Nuisance) -> Effector {
        Effector::default()
    }
    /// The nuisance before its closed-form start: sizes, and the values
    /// stated (a known target offset, a stylus radius).
    fn start(&self) -> Nuisance {
        Nuisance::default()
    }
    /// The starting nuisance fitted to the spindle points of [`Start`]
    /// (default: [`SourceRows::start`] as it is).
    fn fit_start(&self, start: Start<'_>) -> Result<Nuisance, IdentError> {
        Ok(start.nu)
    }
    /// Starting values of the nuisance, by closed-form fits of the records
    /// marked `active` to the model's predictions at the starting point.
    /// Default: every record's spindle point under [`SourceRows::start`],
    /// handed to [`SourceRows::fit_start`].
    fn initial(
        &self,
        at: &FusedAt<'_>,
        contexts: &[LegContext],
        seeds: &mut [Option<UpJoints>],
        active: &[bool],
    ) -> Result<Nuisance, IdentError> {
        let nu = self.start();
        let mut points = Vec::with_capacity(self.records());
        for_each_point(at, contexts, seeds, self.points(&nu), |_, x, _| {
            points.push(*x)
        })?;
        self.fit_start(Start {
            nu,
            points,
            tool_direction: at.tool_direction(),
            active,
        })
    }
    /// The data rows of one record's spindle point ([`PointRows`]).
    /// Default: none (a source that writes its own [`SourceRows::evaluate`]).
    fn point_rows(&self, _rows: PointRows<'_>, _sink: &mut Sink) {}
    /// The prior rows at the nuisance `nu` (default: none).
    fn priors(&self, _nu: &Nuisance, _sink: &mut Sink) {}
    /// The rows at the model `at` and nuisance `nu`. Default: every
    /// record's spindle point and Jacobian handed to
    /// [`SourceRows::point_rows`], then [`SourceRows::priors`].
    fn evaluate(
        &self,
        at: &FusedAt<'_>,
        contexts: &[LegContext],
        nu: &Nuisance,
        seeds: &mut [Option<UpJoints>],
        sink: &mut Sink,
    ) -> Result<(), IdentError> {
        let k = at.len();
        let mut theta = vec![0.0; k];
        let mut dnu = vec![0.0; nu.values.len()];
        for_each_point(
            at,
            contexts,
            seeds,
            self.points(nu),
            |record, point, jac| {
                dnu.iter_mut().for_each(|v| *v = 0.0);
                let rows = PointRows {
                    record,
                    point,
                    jac,
                    k,
                    nu,
                    dnu: &mut dnu,
                    theta: &mut theta,
                };
                self.point_rows(rows, sink);
            },
        )?;
        self.priors(nu, sink);
        Ok(())
    }
    /// Every record's pose, line and effector under `nu`.
    fn points<'a>(
        &'a self,
        nu: &'a Nuisance,
    ) -> Box<dyn Iterator<Item = (ExternalPose, u64, Effector)> + 'a> {
        Box::new(
            (0..self.records()).map(move |j| (self.pose(j), self.line(j), self.effector(j, nu))),
        )
    }
    /// Takes the values of a linear nuisance off the residuals of the data
    /// rows (which are computed without it). Default: nothing to take off.
    fn take_off_linear_nuisance(&self, _rows: &mut [(usize, f64, f64)], _nuisance: &[f64]) {}
    /// Moves the nuisance by `step` (re-basing rotations and normals).
    /// Default: every value moved by its step.
    fn retract(&self, nu: &mut Nuisance, step: &[f64]) {
        nu.add(step);
    }
    /// The nuisance values to report (rotations as rotation vectors).
    fn report_values(&self, nu: &Nuisance) -> Vec<f64> {
        nu.values.clone()
    }
    /// Fitted geometry beyond the nuisance values (plane normals), as JSON.
    fn report_extra(&self, _nu: &Nuisance) -> serde_json::Value {
        serde_json::Value::Null
    }
    /// What the nuisance looks like when it cannot be determined.
    fn nuisance_hint(&self) -> &'static str;
}

/// The spindle points a source's nuisance starts from
/// ([`SourceRows::fit_start`]).
pub(crate) struct Start<'a> {
    /// The nuisance before the fit ([`SourceRows::start`]).
    pub nu: Nuisance,
    /// Every record's spindle point at the starting model.
    pub points: Vec<SpindlePoint>,
    /// The tool direction at zero head angles.
    pub tool_direction: Vector3<f64>,
    /// Which records the fit uses.
    pub active: &'a [bool],
}

/// One record's spindle point at the model and the buffers of its rows
/// ([`SourceRows::point_rows`]).
pub(crate) struct PointRows<'a> {
    /// The record.
    pub record: usize,
    /// Its spindle point.
    pub point: &'a SpindlePoint,
    /// The point's Jacobian, row-major `3 x k`.
    pub jac: &'a [f64],
    /// The number of global parameters.
    pub k: usize,
    /// The nuisance.
    pub nu: &'a Nuisance,
    /// A row's derivatives with respect to the nuisance (zeroed).
    pub dnu: &'a mut [f64],
    /// A row's derivatives with respect to the global parameters.
    pub theta: &'a mut [f64],
}

/// What is known about the tracker target's offset from the tool tip (a
/// statement the likely-cause search restates, so every source can be
/// asked for it: [`Source::tracker_target`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackerTarget {
    /// Unknown (the default): the target offset is a free nuisance, and the
    /// tool tip is not calibrated by this source.
    Free,
    /// Known to `sigma_um` (a target in a presetter-measured nest at the tool
    /// tip: offset zero).
    Known {
        /// The offset, mm, spindle frame at zero head angles.
        offset_mm: [f64; 3],
        /// Its standard deviation per coordinate, um.
        sigma_um: f64,
    },
}

/// One data source of a fused identification.
///
/// # Example
/// ```
/// use tricept_engine::fusion::{Source, SourceKind};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let data = tricept_data::read_path(std::path::Path::new(concat!(
///     env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv"))).unwrap();
/// let s = Source::internal(&data, m.sensors.logged_sigma());
/// assert_eq!((s.label(), s.kind(), s.records()), ("internal", SourceKind::Internal, 75));
/// ```
#[derive(Debug)]
pub struct Source {
    label: String,
    rows: Box<dyn SourceRows>,
}

impl Clone for Source {
    fn clone(&self) -> Source {
        Source {
            label: self.label.clone(),
            rows: self.rows.boxed_clone(),
        }
    }
}

impl Source {
    pub(crate) fn new(rows: Box<dyn SourceRows>) -> Source {
        Source {
            label: rows.kind().as_str().to_string(),
            rows,
        }
    }

    /// The same source under another label (the prefix of its nuisance
    /// parameters' names; default: its kind).
    pub fn with_label(mut self, label: impl Into<String>) -> Source {
        self.label = label.into();
        self
    }

    /// Label.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Kind of instrument.
    pub fn kind(&self) -> SourceKind {
        self.rows.kind()
    }

    /// File the records came from.
    pub fn file(&self) -> &str {
        self.rows.file()
    }

    /// Number of records.
    pub fn records(&self) -> usize {
        self.rows.records()
    }

    /// Nuisance parameter names, prefixed with the label.
    pub fn nuisance_names(&self) -> Vec<String> {
        self.rows
            .nuisance_names()
            .into_iter()
            .map(|n| format!("{}.{n}", self.label))
            .collect()
    }

    pub(crate) fn rows(&self) -> &dyn SourceRows {
        self.rows.as_ref()
    }

    /// The leg effects' context of every record at its commands
    /// ([`FusedModel`]'s nominal machine); a record whose commands cannot
    /// be reached is an error naming its line.
    pub(crate) fn leg_contexts(&self, model: &FusedModel) -> Result<Vec<LegContext>, IdentError> {
        let rows = self.rows();
        (0..rows.records())
            .map(|j| {
                model
                    .leg_context(&rows.pose(j).commands_mm)
                    .map_err(|e| IdentError::Source {
                        file: self.file().to_string(),
                        line: Some(rows.line(j)),
                        message: format!("the commands of this record cannot be reached: {e}"),
                    })
            })
            .collect()
    }

    /// The same tracker records with the target stated as `target` (same
    /// label); `None` for a source that is not a tracker.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::{Source, TrackerOptions, TrackerTarget};
    /// let csv = "q1,q2,q3,h1,h2,x,y,z\n800,800,800,0,0,1,2,3\n810,800,800,0,0,1,5,3\n800,820,800,0,0,4,2,3\n";
    /// let data = tricept_data::external::read_external_from(csv.as_bytes(), "t.csv").unwrap();
    /// let s = Source::tracker(&data, &TrackerOptions::default()).unwrap();
    /// let t = s.with_tracker_target(TrackerTarget::Known { offset_mm: [0.0; 3], sigma_um: 5.0 }).unwrap();
    /// assert_eq!((t.label(), t.records()), ("tracker", 3));
    /// ```
    pub fn with_tracker_target(&self, target: TrackerTarget) -> Option<Source> {
        Some(Source {
            label: self.label.clone(),
            rows: self.rows.with_tracker_target(target)?,
        })
    }

    /// How the tracker target is stated (`None` for other sources).
    pub fn tracker_target(&self) -> Option<TrackerTarget> {
        self.rows.tracker_target()
    }

    /// The stated offset from the tool tip (mm, spindle frame at zero head
    /// angles) of the point this source measures, when it is stated and not
    /// zero: a known tracker target's, a ballbar's ball's.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::{Source, TrackerOptions, TrackerTarget};
    /// let csv = "q1,q2,q3,h1,h2,x,y,z\n800,800,800,0,0,1,2,3\n810,800,800,0,0,1,5,3\n800,820,800,0,0,4,2,3\n";
    /// let data = tricept_data::external::read_external_from(csv.as_bytes(), "t.csv").unwrap();
    /// let s = Source::tracker(&data, &TrackerOptions::default()).unwrap();
    /// assert_eq!(s.stated_offset_mm(), None);
    /// let t = s.with_tracker_target(TrackerTarget::Known { offset_mm: [0.0, 0.0, 20.0], sigma_um: 5.0 }).unwrap();
    /// assert_eq!(t.stated_offset_mm(), Some(nalgebra::Vector3::new(0.0, 0.0, 20.0)));
    /// ```
    pub fn stated_offset_mm(&self) -> Option<Vector3<f64>> {
        self.rows.stated_offset_mm()
    }
}

/// The skew-symmetric matrix of `a` (`[a]x b = a x b`).
pub(crate) fn cross_matrix(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// `(M J)` row `c` for a 3x3 `M` and a row-major `3 x k` `J`, into `out`.
pub(crate) fn rotate_row(m: &Matrix3<f64>, jac: &[f64], k: usize, c: usize, out: &mut [f64]) {
    for (t, o) in out.iter_mut().enumerate().take(k) {
        *o = m[(c, 0)] * jac[t] + m[(c, 1)] * jac[k + t] + m[(c, 2)] * jac[2 * k + t];
    }
}

/// `u^T J` for a unit vector `u` and a row-major `3 x k` `J`, into `out`.
pub(crate) fn project_rows(u: &Vector3<f64>, jac: &[f64], k: usize, out: &mut [f64]) {
    for (t, o) in out.iter_mut().enumerate().take(k) {
        *o = u.x * jac[t] + u.y * jac[k + t] + u.z * jac[2 * k + t];
    }
}

/// `lines 3, 7, 9` (at most eight, then `...`) for messages about a group
/// of records.
pub(crate) fn lines_text(lines: impl Iterator<Item = u64>) -> String {
    let all: Vec<u64> = lines.collect();
    let mut shown: Vec<String> = all.iter().take(8).map(|l| l.to_string()).collect();
    if all.len() > 8 {
        shown.push("...".into());
    }
    format!(
        "{} {}",
        if all.len() == 1 { "line" } else { "lines" },
        shown.join(", ")
    )
}

/// Sorted distinct values of `keys` (stations, setups; with each record's
/// line) and each record's index into them; a group with fewer than `min`
/// records is refused with `message(id, count)` and the group's lines.
pub(crate) fn groups(
    file: &str,
    keyed: impl Iterator<Item = (u32, u64)>,
    min: usize,
    message: impl Fn(u32, usize) -> String,
) -> Result<(Vec<u32>, Vec<usize>), IdentError> {
    let (keys, lines): (Vec<u32>, Vec<u64>) = keyed.unzip();
    let mut distinct = keys.clone();
    distinct.sort_unstable();
    distinct.dedup();
    let index: Vec<usize> = keys
        .iter()
        .map(|k| distinct.binary_search(k).unwrap_or(0))
        .collect();
    for (g, id) in distinct.iter().enumerate() {
        let n = index.iter().filter(|&&x| x == g).count();
        if n < min {
            let at = lines_text(
                index
                    .iter()
                    .zip(&lines)
                    .filter(|(x, _)| **x == g)
                    .map(|(_, l)| *l),
            );
            return Err(IdentError::Source {
                file: file.to_string(),
                line: None,
                message: format!("{} ({at})", message(*id, n)),
            });
        }
    }
    Ok((distinct, index))
}

/// Evaluates the spindle point of every record (`(pose, line, effector)`)
/// at the model `at` and hands it, with its Jacobian (row-major `3 x k`),
/// to `f` with the record's index; a pose the model cannot reach is named
/// by its line.
pub(crate) fn for_each_point(
    at: &FusedAt<'_>,
    contexts: &[LegContext],
    seeds: &mut [Option<UpJoints>],
    records: impl Iterator<Item = (ExternalPose, u64, tricept_model::head_errors::Effector)>,
    mut f: impl FnMut(usize, &SpindlePoint, &[f64]),
) -> Result<(), IdentError> {
    let mut jac = vec![0.0; 3 * at.len()];
    for (j, (pose, line, effector)) in records.enumerate() {
        let x = at
            .spindle_point(&pose, &contexts[j], &effector, &mut seeds[j], &mut jac)
            .map_err(|source| IdentError::Kinematics {
                pose: j,
                line,
                source,
            })?;
        f(j, &x, &jac);
    }
    Ok(())
}

/// Centre of the sphere through points `x_j` whose distances from it are
/// `radius_j`, by linear least squares on the differences of
/// `|x_j - c|^2 = radius_j^2`; `None` when the points are (nearly) coplanar.
pub(crate) fn sphere_centre(points: &[Vector3<f64>], radii: &[f64]) -> Option<Vector3<f64>> {
    if points.len() < 4 {
        return None;
    }
    let (x0, r0) = (points[0], radii[0]);
    let n = points.len() - 1;
    let a = nalgebra::DMatrix::from_fn(n, 3, |i, c| 2.0 * (points[i + 1][c] - x0[c]));
    let b = nalgebra::DVector::from_fn(n, |i, _| {
        points[i + 1].norm_squared() - x0.norm_squared() - (radii[i + 1].powi(2) - r0 * r0)
    });
    let svd = a.svd(true, true);
    let s = &svd.singular_values;
    let (max, min) = (s.max(), s.min());
    if min.is_nan() || min <= 1e-6 * max {
        return None;
    }
    let x = svd.solve(&b, 0.0).ok()?;
    Some(Vector3::new(x[0], x[1], x[2]))
}
