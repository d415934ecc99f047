//! External measurements: what an instrument outside the machine measured
//! while the machine stood at known leg commands and head angles. Three CSV
//! contracts, read as strictly as the measured-data file (same record
//! machinery, same messages: file, line and column), and the features file
//! (JSON) that touch-offs refer to. One reader and one writer serve every
//! record type: [`read_external_path`]`::<TrackerPoint>`, ...
//!
//! | file | required columns | optional columns |
//! |---|---|---|
//! | tracker / CMM points | `q1,q2,q3,h1,h2,x,y,z` | `sigma_um`, `extension_mm`, `setup`, `temp_c` |
//! | ballbar | `q1,q2,q3,h1,h2,length` | `sigma_um`, `setup`, `temp_c` |
//! | touch-offs | `q1,q2,q3,h1,h2,feature` | `sigma_um`, `temp_c` |
//!
//! `q1,q2,q3` are leg commands (mm) and `h1,h2` commanded head angles
//! (rad), as `tricept tool-ik` prints them; `x,y,z` a point in the
//! instrument's own frame (mm); `length` the ballbar's reading (mm);
//! `feature` the id of a sphere or plane of the features file; `sigma_um`
//! the standard deviation of this row's measurement (per coordinate for a
//! tracker), um; `extension_mm` a known extension of the measured point
//! along the tool axis beyond the tool tip, mm; `setup` the instrument's
//! station (a tracker moved, a ballbar pivot re-mounted), a whole number
//! from 1; `temp_c` the structure temperature, °C.
//!
//! Row checks beyond the number format: positive commands, head angles
//! within ±2π rad (a larger value is degrees), positive `sigma_um`, a
//! ballbar `length` of 10-2000 mm (a value outside is um or m), whole
//! `setup` and `feature` numbers from 1, plausible temperatures, and no row
//! repeated exactly.

use std::io::{Read, Write};
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::records::{Header, Record, Records, open};
use crate::{DataError, MAX_LENGTH_MM};

/// Where the machine stood when an instrument measured.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ExternalPose {
    /// Leg commands, mm.
    pub commands_mm: [f64; 3],
    /// Commanded head angles `[h1, h2]`, rad.
    pub head_rad: [f64; 2],
}

/// One point measured by a laser tracker or a CMM.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrackerPoint {
    /// Where the machine stood.
    pub pose: ExternalPose,
    /// The measured point in the instrument's frame, mm.
    pub position_mm: [f64; 3],
    /// Standard deviation of each coordinate, um (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Known extension of the target along the tool axis beyond the tool
    /// tip, mm (0 when the column is absent).
    pub extension_mm: f64,
    /// Instrument station, from 1.
    pub setup: u32,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// One reading of a ballbar between the tool-tip ball and a pivot on the table.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BallbarReading {
    /// Where the machine stood.
    pub pose: ExternalPose,
    /// The bar's reading: the ball-to-pivot distance, mm.
    pub length_mm: f64,
    /// Standard deviation of the reading, um (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Pivot mounting, from 1.
    pub setup: u32,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// One touch of a probe in the spindle on a feature of the features file.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TouchReading {
    /// Where the machine stood when the probe triggered (latched values).
    pub pose: ExternalPose,
    /// Id of the feature touched.
    pub feature: u32,
    /// Standard deviation of the touch along the surface normal, um
    /// (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// A pose to measure at (what `tricept plan` writes and `tricept simulate`
/// reads): the commands and, for information, the nominal tool tip and
/// ballbar length there.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlannedPose {
    /// Where the machine is to stand.
    pub pose: ExternalPose,
    /// Known extension of a tracker target along the tool, mm.
    pub extension_mm: f64,
    /// The nominal tool tip there, mm (columns `x,y,z`).
    pub tip_mm: Option<[f64; 3]>,
    /// The nominal ballbar length there, mm (column `length`).
    pub length_mm: Option<f64>,
    /// The feature to touch there (column `feature`, touch-offs).
    pub feature: Option<u32>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// The records of one external-measurement file and where they came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExternalData<T> {
    /// Records in file order.
    pub records: Vec<T>,
    /// File name (or a label) used in messages.
    pub source: String,
}

/// Points of a laser tracker or CMM.
pub type TrackerData = ExternalData<TrackerPoint>;
/// Readings of a ballbar.
pub type BallbarData = ExternalData<BallbarReading>;
/// Touches of a probe.
pub type TouchData = ExternalData<TouchReading>;
/// Poses to measure at.
pub type PlannedPoses = ExternalData<PlannedPose>;

/// The pose columns every external file starts with.
const POSE_COLUMNS: [&str; 5] = ["q1", "q2", "q3", "h1", "h2"];

/// Largest head angle accepted as radians.
const MAX_HEAD_ANGLE_RAD: f64 = std::f64::consts::TAU;
/// Plausible ballbar lengths, mm.
const BALLBAR_LENGTH_MM: (f64, f64) = (10.0, 2000.0);
/// Plausible structure temperatures, °C.
const TEMP_RANGE_C: (f64, f64) = (-60.0, 200.0);
/// Largest extension along the tool accepted, mm.
const MAX_EXTENSION_MM: f64 = 1000.0;

/// A record type of an external file ([`TrackerPoint`], [`BallbarReading`],
/// [`TouchReading`], [`PlannedPose`]): what [`read_external_from`] and
/// [`write_external_to`] read and write. Sealed: the file formats are the
/// crate's contract.
pub trait ExternalRecord: sealed::ExternalRow {}

impl<T: sealed::ExternalRow> ExternalRecord for T {}

mod sealed {
    pub use super::ExternalRow;
}

/// A record type of an external file: its columns and how a row reads
/// and writes.
pub trait ExternalRow: Sized {
    /// Required columns after the pose columns.
    const MEASURED: &'static [&'static str];
    /// Optional columns.
    const OPTIONAL: &'static [&'static str];
    /// Builds the record from its pose and a reader of the other columns.
    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError>;
    /// The pose.
    fn pose(&self) -> &ExternalPose;
    /// Value of a measured or optional column (`None`: not set).
    fn value(&self, column: &str) -> Option<f64>;
    /// The value written for an optional column a record does not set
    /// (`None`: the column is written only when every record sets it).
    fn default_of(column: &str) -> Option<f64> {
        match column {
            "extension_mm" => Some(0.0),
            "setup" => Some(1.0),
            _ => None,
        }
    }
}

/// One row being parsed: the header, the record and the located columns.
pub struct Row<'a> {
    header: &'a Header,
    record: &'a Record,
    measured: &'a [usize],
    optional: &'a [Option<usize>],
    optional_names: &'a [&'a str],
}

impl Row<'_> {
    fn measured(&self, k: usize) -> Result<f64, DataError> {
        self.header.number(self.record, self.measured[k])
    }

    /// A measured length or coordinate, mm, within ±[`MAX_LENGTH_MM`].
    fn measured_mm(&self, k: usize) -> Result<f64, DataError> {
        let v = self.measured(k)?;
        if v.abs() > MAX_LENGTH_MM {
            return Err(self.header.bad_value(
                self.record,
                self.measured[k],
                format!("beyond ±{MAX_LENGTH_MM} mm: not a measurement of this machine"),
            ));
        }
        Ok(v)
    }

    fn measured_column(&self, k: usize) -> usize {
        self.measured[k]
    }

    /// An optional column's value, checked by `check` (which says why a
    /// value is refused).
    fn optional(
        &self,
        name: &str,
        check: impl Fn(f64) -> Option<&'static str>,
    ) -> Result<Option<f64>, DataError> {
        let Some(k) = self.optional_names.iter().position(|n| *n == name) else {
            return Ok(None);
        };
        let Some(idx) = self.optional[k] else {
            return Ok(None);
        };
        let v = self.header.number(self.record, idx)?;
        match check(v) {
            None => Ok(Some(v)),
            Some(reason) => Err(self.header.bad_value(self.record, idx, reason)),
        }
    }

    fn sigma_um(&self) -> Result<Option<f64>, DataError> {
        self.optional("sigma_um", |v| {
            (v <= 0.0).then_some("a standard deviation must be positive (um)")
        })
    }

    fn temp_c(&self) -> Result<Option<f64>, DataError> {
        self.optional("temp_c", |t| {
            (!(TEMP_RANGE_C.0..=TEMP_RANGE_C.1).contains(&t))
                .then_some("temperature outside -60..200 °C")
        })
    }

    fn whole_from_one(&self, name: &str) -> Result<Option<u32>, DataError> {
        Ok(self
            .optional(name, |v| {
                (v < 1.0 || v.fract() != 0.0 || v > f64::from(u32::MAX))
                    .then_some("must be a whole number from 1")
            })?
            .map(|v| v as u32))
    }

    fn bad(&self, idx: usize, reason: &str) -> DataError {
        self.header.bad_value(self.record, idx, reason)
    }
}

impl ExternalRow for TrackerPoint {
    const MEASURED: &'static [&'static str] = &["x", "y", "z"];
    const OPTIONAL: &'static [&'static str] = &["sigma_um", "extension_mm", "setup", "temp_c"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        Ok(TrackerPoint {
            pose,
            position_mm: [
                row.measured_mm(0)?,
                row.measured_mm(1)?,
                row.measured_mm(2)?,
            ],
            sigma_um: row.sigma_um()?,
            extension_mm: row
                .optional("extension_mm", |v| {
                    (v.abs() > MAX_EXTENSION_MM).then_some("an extension beyond ±1000 mm (mm?)")
                })?
                .unwrap_or(0.0),
            setup: row.whole_from_one("setup")?.unwrap_or(1),
            temp_c: row.temp_c()?,
            line: row.record.line,
        })
    }

    fn pose(&self) -> &ExternalPose {
        &self.pose
    }

    fn value(&self, column: &str) -> Option<f64> {
        match column {
            "x" => Some(self.position_mm[0]),
            "y" => Some(self.position_mm[1]),
            "z" => Some(self.position_mm[2]),
            "sigma_um" => self.sigma_um,
            "extension_mm" => (self.extension_mm != 0.0).then_some(self.extension_mm),
            "setup" => (self.setup != 1).then_some(f64::from(self.setup)),
            "temp_c" => self.temp_c,
            _ => None,
        }
    }
}

impl ExternalRow for BallbarReading {
    const MEASURED: &'static [&'static str] = &["length"];
    const OPTIONAL: &'static [&'static str] = &["sigma_um", "setup", "temp_c"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let length_mm = row.measured(0)?;
        if !(BALLBAR_LENGTH_MM.0..=BALLBAR_LENGTH_MM.1).contains(&length_mm) {
            return Err(row.bad(
                row.measured_column(0),
                "a ballbar length must be 10-2000 mm (um or m?)",
            ));
        }
        Ok(BallbarReading {
            pose,
            length_mm,
            sigma_um: row.sigma_um()?,
            setup: row.whole_from_one("setup")?.unwrap_or(1),
            temp_c: row.temp_c()?,
            line: row.record.line,
        })
    }

    fn pose(&self) -> &ExternalPose {
        &self.pose
    }

    fn value(&self, column: &str) -> Option<f64> {
        match column {
            "length" => Some(self.length_mm),
            "sigma_um" => self.sigma_um,
            "setup" => (self.setup != 1).then_some(f64::from(self.setup)),
            "temp_c" => self.temp_c,
            _ => None,
        }
    }
}

impl ExternalRow for TouchReading {
    const MEASURED: &'static [&'static str] = &["feature"];
    const OPTIONAL: &'static [&'static str] = &["sigma_um", "temp_c"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let f = row.measured(0)?;
        if f < 1.0 || f.fract() != 0.0 || f > f64::from(u32::MAX) {
            return Err(row.bad(
                row.measured_column(0),
                "a feature id must be a whole number from 1",
            ));
        }
        Ok(TouchReading {
            pose,
            feature: f as u32,
            sigma_um: row.sigma_um()?,
            temp_c: row.temp_c()?,
            line: row.record.line,
        })
    }

    fn pose(&self) -> &ExternalPose {
        &self.pose
    }

    fn value(&self, column: &str) -> Option<f64> {
        match column {
            "feature" => Some(f64::from(self.feature)),
            "sigma_um" => self.sigma_um,
            "temp_c" => self.temp_c,
            _ => None,
        }
    }
}

impl ExternalRow for PlannedPose {
    const MEASURED: &'static [&'static str] = &[];
    const OPTIONAL: &'static [&'static str] = &["extension_mm", "x", "y", "z", "length", "feature"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let any = |_: f64| None;
        let tip = [
            row.optional("x", any)?,
            row.optional("y", any)?,
            row.optional("z", any)?,
        ];
        Ok(PlannedPose {
            pose,
            extension_mm: row
                .optional("extension_mm", |v| {
                    (v.abs() > MAX_EXTENSION_MM).then_some("an extension beyond ±1000 mm (mm?)")
                })?
                .unwrap_or(0.0),
            tip_mm: match tip {
                [Some(x), Some(y), Some(z)] => Some([x, y, z]),
                _ => None,
            },
            length_mm: row.optional("length", any)?,
            feature: row.whole_from_one("feature")?,
            line: row.record.line,
        })
    }

    fn pose(&self) -> &ExternalPose {
        &self.pose
    }

    fn value(&self, column: &str) -> Option<f64> {
        match column {
            "extension_mm" => (self.extension_mm != 0.0).then_some(self.extension_mm),
            "x" => self.tip_mm.map(|t| t[0]),
            "y" => self.tip_mm.map(|t| t[1]),
            "z" => self.tip_mm.map(|t| t[2]),
            "length" => self.length_mm,
            "feature" => self.feature.map(f64::from),
            _ => None,
        }
    }
}

/// Reads the records of one external file.
fn read_rows<R: Read, T: ExternalRow>(reader: R, file: &str) -> Result<ExternalData<T>, DataError> {
    let mut records = Records::new(reader, file);
    let required: Vec<&str> = POSE_COLUMNS.iter().chain(T::MEASURED).copied().collect();
    let header = Header::read(&mut records, &required.join(","))?;
    let known: Vec<&str> = required.iter().chain(T::OPTIONAL).copied().collect();
    let pose_idx: Vec<usize> = POSE_COLUMNS
        .iter()
        .map(|c| header.locate_one(c, &known))
        .collect::<Result<_, _>>()?;
    let measured: Vec<usize> = T::MEASURED
        .iter()
        .map(|c| header.locate_one(c, &known))
        .collect::<Result<_, _>>()?;
    let optional: Vec<Option<usize>> = T::OPTIONAL.iter().map(|c| header.find(c)).collect();
    let mut out = Vec::new();
    let mut seen = std::collections::HashMap::new();
    for record in records {
        let record = record?;
        header.check(&record)?;
        let mut p = [0.0; 5];
        for (v, &idx) in p.iter_mut().zip(&pose_idx) {
            *v = header.number(&record, idx)?;
        }
        for k in 0..3 {
            if p[k] <= 0.0 {
                return Err(header.bad_value(
                    &record,
                    pose_idx[k],
                    "a leg length command must be positive (mm)",
                ));
            }
        }
        for k in 3..5 {
            if p[k].abs() > MAX_HEAD_ANGLE_RAD {
                return Err(header.bad_value(
                    &record,
                    pose_idx[k],
                    "a head angle beyond ±2π rad: are the angles in degrees? Head angles must be in rad",
                ));
            }
        }
        let pose = ExternalPose {
            commands_mm: [p[0], p[1], p[2]],
            head_rad: [p[3], p[4]],
        };
        let row = Row {
            header: &header,
            record: &record,
            measured: &measured,
            optional: &optional,
            optional_names: T::OPTIONAL,
        };
        let parsed = T::from_row(pose, &row)?;
        let key: Vec<u64> = p
            .iter()
            .copied()
            .chain(
                T::MEASURED
                    .iter()
                    .chain(T::OPTIONAL)
                    .map(|c| parsed.value(c).unwrap_or(f64::NAN)),
            )
            .map(f64::to_bits)
            .collect();
        if let Some(first_line) = seen.insert(key, record.line) {
            return Err(DataError::DuplicateRow {
                file: file.into(),
                line: record.line,
                first_line,
            });
        }
        out.push(parsed);
    }
    if out.is_empty() {
        return Err(DataError::NoRows { file: file.into() });
    }
    Ok(ExternalData {
        records: out,
        source: file.into(),
    })
}

/// Writes records as CSV: the pose and measured columns, then every
/// optional column some record sets (records that do not set it get its
/// default; a column without a default is written only when every record
/// sets it). Values are written so that they read back to the same `f64`.
fn write_rows<W: Write, T: ExternalRow>(
    mut w: W,
    data: &ExternalData<T>,
    comments: &[String],
) -> std::io::Result<()> {
    for c in comments {
        for line in c.lines() {
            writeln!(w, "# {line}")?;
        }
    }
    let optional: Vec<&str> = T::OPTIONAL
        .iter()
        .copied()
        .filter(|c| match T::default_of(c) {
            Some(_) => data.records.iter().any(|r| r.value(c).is_some()),
            None => !data.records.is_empty() && data.records.iter().all(|r| r.value(c).is_some()),
        })
        .collect();
    let columns: Vec<&str> = POSE_COLUMNS
        .iter()
        .chain(T::MEASURED)
        .chain(&optional)
        .copied()
        .collect();
    writeln!(w, "{}", columns.join(","))?;
    for r in &data.records {
        let p = r.pose();
        let mut fields: Vec<String> = p
            .commands_mm
            .iter()
            .chain(&p.head_rad)
            .map(|v| v.to_string())
            .collect();
        for c in T::MEASURED.iter().chain(&optional) {
            let v = r.value(c).or(T::default_of(c)).unwrap_or(f64::NAN);
            fields.push(v.to_string());
        }
        writeln!(w, "{}", fields.join(","))?;
    }
    Ok(())
}

/// Reads external records of type `T` from any reader; `file` names it in
/// errors.
///
/// # Example
/// ```
/// use tricept_data::{BallbarReading, TouchReading, TrackerPoint, read_external_from};
/// let csv = "q1,q2,q3,h1,h2,x,y,z,sigma_um\n800,810,790,0.5,-0.3,1500.1,-20.2,300.3,12\n";
/// let t = read_external_from::<TrackerPoint, _>(csv.as_bytes(), "t.csv").unwrap();
/// assert_eq!(t.records[0].position_mm, [1500.1, -20.2, 300.3]);
/// assert_eq!((t.records[0].sigma_um, t.records[0].setup), (Some(12.0), 1));
/// let bad = "q1,q2,q3,h1,h2,x,y,z\n800,810,790,30,-0.3,1,2,3\n";
/// let e = read_external_from::<TrackerPoint, _>(bad.as_bytes(), "t.csv").unwrap_err();
/// assert!(e.to_string().starts_with("t.csv: line 2, column `h1`: a head angle beyond"));
///
/// let csv = "q1,q2,q3,h1,h2,length\n800,810,790,0.5,-0.3,150.0012\n";
/// let b = read_external_from::<BallbarReading, _>(csv.as_bytes(), "b.csv").unwrap();
/// assert_eq!(b.records[0].length_mm, 150.0012);
/// let um = "q1,q2,q3,h1,h2,length\n800,810,790,0.5,-0.3,150001.2\n";
/// let e = read_external_from::<BallbarReading, _>(um.as_bytes(), "b.csv").unwrap_err();
/// assert!(e.to_string().contains("column `length`: a ballbar length must be 10-2000 mm"));
///
/// let csv = "q1,q2,q3,h1,h2,feature\n800,810,790,0.5,-0.3,2\n";
/// let t = read_external_from::<TouchReading, _>(csv.as_bytes(), "touch.csv").unwrap();
/// assert_eq!(t.records[0].feature, 2);
/// ```
pub fn read_external_from<T: ExternalRecord, R: Read>(
    reader: R,
    file: &str,
) -> Result<ExternalData<T>, DataError> {
    read_rows(reader, file)
}

/// Reads an external-measurement file of records of type `T` (see
/// [`read_external_from`]).
pub fn read_external_path<T: ExternalRecord>(path: &Path) -> Result<ExternalData<T>, DataError> {
    let (f, file) = open(path)?;
    read_rows(f, &file)
}

/// Writes external records as CSV (they read back exactly).
///
/// # Example
/// ```
/// use tricept_data::{ExternalData, ExternalPose, PlannedPose, TrackerPoint};
/// let data = ExternalData {
///     records: vec![TrackerPoint {
///         pose: ExternalPose { commands_mm: [800.0; 3], head_rad: [0.1, 0.2] },
///         position_mm: [1.0, 2.0, 3.0],
///         extension_mm: 100.0,
///         setup: 1,
///         ..Default::default()
///     }],
///     source: "mem".into(),
/// };
/// let mut out = Vec::new();
/// tricept_data::write_external_to(&mut out, &data, &[]).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// assert_eq!(text, "q1,q2,q3,h1,h2,x,y,z,extension_mm\n800,800,800,0.1,0.2,1,2,3,100\n");
/// let back = tricept_data::read_external_from::<TrackerPoint, _>(text.as_bytes(), "mem").unwrap();
/// assert_eq!(back.records[0].position_mm, data.records[0].position_mm);
///
/// // Poses to measure at carry the nominal tool tip for information.
/// let csv = "q1,q2,q3,h1,h2,x,y,z\n800,810,790,0.5,-0.3,10,20,1100\n";
/// let p = tricept_data::read_external_from::<PlannedPose, _>(csv.as_bytes(), "plan.csv").unwrap();
/// assert_eq!(p.records[0].tip_mm, Some([10.0, 20.0, 1100.0]));
/// ```
pub fn write_external_to<T: ExternalRecord, W: Write>(
    w: W,
    data: &ExternalData<T>,
    comments: &[String],
) -> std::io::Result<()> {
    write_rows(w, data, comments)
}

/// Writes external records to a file (see [`write_external_to`]),
/// atomically ([`crate::write_atomic`]).
pub fn write_external_path<T: ExternalRecord>(
    path: &Path,
    data: &ExternalData<T>,
    comments: &[String],
) -> std::io::Result<()> {
    crate::write_atomic(path, |w| write_rows(w, data, comments))
}

/// The probe's stylus.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stylus {
    /// Effective radius of the stylus ball (pre-travel included), mm.
    pub radius_mm: f64,
    /// Standard deviation of that radius (calibration certificate), um.
    pub radius_sigma_um: f64,
}

/// A reference feature on the table or the part, touched by the probe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Feature {
    /// A reference sphere of known radius; its centre is unknown.
    Sphere {
        /// Id used by the touch file's `feature` column.
        id: u32,
        /// Radius, mm.
        radius_mm: f64,
        /// Standard deviation of the radius, um.
        #[serde(default)]
        radius_sigma_um: f64,
    },
    /// A plane; its position and orientation are unknown.
    Plane {
        /// Id used by the touch file's `feature` column.
        id: u32,
    },
}

impl Feature {
    /// The feature's id.
    pub fn id(&self) -> u32 {
        match self {
            Feature::Sphere { id, .. } | Feature::Plane { id } => *id,
        }
    }
}

/// The features file of a touch-off campaign (JSON).
///
/// # Example
/// ```
/// let json = r#"{"stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0},
///   "features": [{"id": 1, "kind": "sphere", "radius_mm": 12.7, "radius_sigma_um": 0.5},
///                {"id": 2, "kind": "plane"}]}"#;
/// let f = tricept_data::Features::from_json(json, "features.json").unwrap();
/// assert_eq!(f.features.len(), 2);
/// let e = tricept_data::Features::from_json(r#"{"stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0},
///   "features": [{"id": 1, "kind": "cube"}]}"#, "f.json").unwrap_err();
/// assert!(e.to_string().starts_with("f.json: line 2, column"), "{e}");
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// The stylus.
    pub stylus: Stylus,
    /// The features, with distinct ids.
    pub features: Vec<Feature>,
}

/// The largest stylus ball radius a features file may state, mm.
pub const MAX_STYLUS_RADIUS_MM: f64 = 50.0;
/// The largest sphere radius a features file may state, mm.
pub const MAX_SPHERE_RADIUS_MM: f64 = 1000.0;

impl Features {
    /// Parses and checks a features file's text; `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<Features, DataError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let f: Features = serde_json::from_str(text).map_err(|e| DataError::Json {
            file: file.into(),
            line: e.line() as u64,
            column: e.column() as u64,
            message: strip_position(&e.to_string()),
        })?;
        let invalid = |message: String| DataError::Invalid {
            file: file.into(),
            message,
        };
        let s = f.stylus;
        if !(s.radius_mm.is_finite() && (0.0..=MAX_STYLUS_RADIUS_MM).contains(&s.radius_mm)) {
            return Err(invalid(format!(
                "stylus.radius_mm must be a number of mm from 0 to {MAX_STYLUS_RADIUS_MM}, got {}",
                s.radius_mm
            )));
        }
        if !(s.radius_sigma_um.is_finite() && s.radius_sigma_um > 0.0) {
            return Err(invalid(format!(
                "stylus.radius_sigma_um must be positive, got {}",
                s.radius_sigma_um
            )));
        }
        for (k, feature) in f.features.iter().enumerate() {
            if f.features[..k].iter().any(|g| g.id() == feature.id()) {
                return Err(invalid(format!(
                    "feature id {} appears twice",
                    feature.id()
                )));
            }
            if let Feature::Sphere {
                radius_mm,
                radius_sigma_um,
                id,
            } = feature
            {
                if !(radius_mm.is_finite()
                    && *radius_mm > 0.0
                    && *radius_mm <= MAX_SPHERE_RADIUS_MM)
                {
                    return Err(invalid(format!(
                        "feature {id}: radius_mm must be positive and at most {MAX_SPHERE_RADIUS_MM} mm, got {radius_mm}"
                    )));
                }
                if !(radius_sigma_um.is_finite() && *radius_sigma_um >= 0.0) {
                    return Err(invalid(format!(
                        "feature {id}: radius_sigma_um must be non-negative, got {radius_sigma_um}"
                    )));
                }
            }
        }
        if f.features.is_empty() {
            return Err(invalid("no features".into()));
        }
        Ok(f)
    }

    /// Reads and checks a features file.
    pub fn from_path(path: &Path) -> Result<Features, DataError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| DataError::Io {
            file: file.clone(),
            source,
        })?;
        Features::from_json(&text, &file)
    }

    /// The feature with id `id`.
    pub fn get(&self, id: u32) -> Option<&Feature> {
        self.features.iter().find(|f| f.id() == id)
    }
}

/// serde_json appends " at line L column C"; the message states it up front.
fn strip_position(s: &str) -> String {
    match s.rfind(" at line ") {
        Some(i) => s[..i].to_string(),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tracker_error(text: &str) -> String {
        read_external_from::<TrackerPoint, _>(text.as_bytes(), "t.csv")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let h = "q1,q2,q3,h1,h2,x,y,z";
        let cases: [(String, &str); 9] = [
            (
                "q1,q2,q3,h1,h2,x,y\n".into(),
                "t.csv: line 1: missing required column `z`",
            ),
            (
                "q1,q2,q3,hl,h2,x,y,z\n".into(),
                "t.csv: line 1: missing required column `h1`, found `hl` (misspelt?)",
            ),
            (
                format!("{h}\n800,800,800,0,0,1,2,NaN\n"),
                "t.csv: line 2, column `z`: not a finite number",
            ),
            (
                format!("{h}\n800,-800,800,0,0,1,2,3\n"),
                "t.csv: line 2, column `q2`: a leg length command must be positive",
            ),
            (
                format!("{h}\n800,800,800,0,90,1,2,3\n"),
                "t.csv: line 2, column `h2`: a head angle beyond ±2π rad",
            ),
            (
                format!("{h},sigma_um\n800,800,800,0,0,1,2,3,0\n"),
                "t.csv: line 2, column `sigma_um`: a standard deviation must be positive",
            ),
            (
                format!("{h},setup\n800,800,800,0,0,1,2,3,1.5\n"),
                "t.csv: line 2, column `setup`: must be a whole number from 1",
            ),
            (
                format!("{h}\n800,800,800,0,0,1,2,3\n# again\n800,800,800,0,0,1,2,3\n"),
                "t.csv: line 4 repeats line 2 exactly",
            ),
            (format!("{h}\n"), "t.csv: header only, no data rows"),
        ];
        for (text, start) in cases {
            let e = tracker_error(&text);
            assert!(e.starts_with(start), "{e}\n expected: {start}");
        }
        let e = read_external_from::<TouchReading, _>(
            "q1,q2,q3,h1,h2,feature\n800,800,800,0,0,0\n".as_bytes(),
            "f.csv",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("f.csv: line 2, column `feature`: a feature id"),
            "{e}"
        );
    }

    #[test]
    fn every_file_round_trips_exactly() {
        let pose = |k: u32| ExternalPose {
            commands_mm: [800.0 + f64::from(k) / 3.0, 801.1, 799.9],
            head_rad: [0.1 * f64::from(k), -0.25],
        };
        let tracker = TrackerData {
            records: (0..5)
                .map(|k| TrackerPoint {
                    pose: pose(k),
                    position_mm: [1500.0 / f64::from(k + 1), -3.0, 0.1],
                    sigma_um: Some(10.0),
                    extension_mm: if k % 2 == 0 { 0.0 } else { 100.0 },
                    setup: 1 + k % 2,
                    temp_c: None,
                    line: 0,
                })
                .collect(),
            source: "mem".into(),
        };
        let mut buf = Vec::new();
        write_external_to(&mut buf, &tracker, &["a comment".into()]).unwrap();
        let back = read_external_from::<TrackerPoint, _>(buf.as_slice(), "mem").unwrap();
        for (a, b) in tracker.records.iter().zip(&back.records) {
            assert_eq!(TrackerPoint { line: b.line, ..*a }, *b);
        }
        assert_eq!(back.records[0].line, 3);

        let ballbar = BallbarData {
            records: (0..4)
                .map(|k| BallbarReading {
                    pose: pose(k),
                    length_mm: 150.0 + 1e-4 * f64::from(k),
                    sigma_um: None,
                    setup: 1,
                    temp_c: Some(20.5),
                    line: 0,
                })
                .collect(),
            source: "mem".into(),
        };
        let mut buf = Vec::new();
        write_external_to(&mut buf, &ballbar, &[]).unwrap();
        let back = read_external_from::<BallbarReading, _>(buf.as_slice(), "mem").unwrap();
        for (a, b) in ballbar.records.iter().zip(&back.records) {
            assert_eq!(BallbarReading { line: b.line, ..*a }, *b);
        }

        let touch = TouchData {
            records: (0..3)
                .map(|k| TouchReading {
                    pose: pose(k),
                    feature: 1 + k,
                    sigma_um: Some(1.5),
                    temp_c: None,
                    line: 0,
                })
                .collect(),
            source: "mem".into(),
        };
        let mut buf = Vec::new();
        write_external_to(&mut buf, &touch, &[]).unwrap();
        let back = read_external_from::<TouchReading, _>(buf.as_slice(), "mem").unwrap();
        for (a, b) in touch.records.iter().zip(&back.records) {
            assert_eq!(TouchReading { line: b.line, ..*a }, *b);
        }
    }

    #[test]
    fn features_are_checked() {
        let stylus = r#""stylus": {"radius_mm": 1.0, "radius_sigma_um": 2.0}"#;
        for (body, needle) in [
            (
                r#"[{"id": 1, "kind": "plane"}, {"id": 1, "kind": "plane"}]"#,
                "feature id 1 appears twice",
            ),
            (
                r#"[{"id": 3, "kind": "sphere", "radius_mm": -2}]"#,
                "feature 3: radius_mm must be positive",
            ),
            (r#"[]"#, "no features"),
            (
                r#"[{"id": 1, "kind": "plane", "radius_mm": 2}]"#,
                "unknown field",
            ),
        ] {
            let e = Features::from_json(&format!("{{{stylus}, \"features\": {body}}}"), "f.json")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("f.json: ") && e.contains(needle), "{e}");
        }
    }
}
