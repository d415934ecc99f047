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
//!
//! Adding an instrument: one file here with its record (the measured fields
//! and the [`Reading`] fields every instrument's row carries), its
//! `ExternalRow` impl (the measured columns, read with [`Row`]'s checks, and
//! their values; the common columns come through `Row::reading` and
//! [`Reading::value`]) and one line `instrument_record!(Record, setup)`,
//! which writes the common part (its [`InstrumentRecord`] impl and
//! `with_reading`); then `tricept-plant`'s `instruments/` (the simulated
//! reading) and `tricept-engine`'s `fusion/` (the model term), one file each.

use std::io::{Read, Write};
use std::path::Path;

use crate::records::{Header, Record, Records, open};
use crate::{DataError, read::MAX_LENGTH_MM};

mod ballbar;
mod planned;
mod touch;
mod tracker;

pub use ballbar::{BallbarData, BallbarReading};
pub use planned::{PlannedPose, PlannedPoses};
pub use touch::{Feature, Features, Stylus, TouchData, TouchReading};
pub use tracker::{TrackerData, TrackerPoint};

/// Where the machine stood when an instrument measured.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ExternalPose {
    /// Leg commands, mm.
    pub commands_mm: [f64; 3],
    /// Commanded head angles `[h1, h2]`, rad.
    pub head_rad: [f64; 2],
}

/// What every instrument's row carries beside its measurement: where the
/// machine stood, the row's standard deviation, the instrument's setup, the
/// structure temperature and the line in the file.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Reading {
    /// Where the machine stood.
    pub pose: ExternalPose,
    /// Standard deviation of the measurement, um (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Setup (station, mounting), from 1 (`None`: the kind has no setups).
    pub setup: Option<u32>,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

impl Reading {
    /// Value of a common optional column (`sigma_um`, `setup`, `temp_c`) as
    /// written; `None` for a column not set (a setup of 1 is the default).
    ///
    /// # Example
    /// ```
    /// use tricept_data::external::Reading;
    /// let r = Reading { sigma_um: Some(2.0), setup: Some(1), ..Reading::default() };
    /// assert_eq!((r.value("sigma_um"), r.value("setup"), r.value("x")), (Some(2.0), None, None));
    /// ```
    pub fn value(&self, column: &str) -> Option<f64> {
        match column {
            "sigma_um" => self.sigma_um,
            "setup" => self.setup.filter(|s| *s != 1).map(f64::from),
            "temp_c" => self.temp_c,
            _ => None,
        }
    }
}

/// A record an instrument measured: its [`Reading`] fields read the same
/// way for every instrument (what the fusion's sources and the simulated
/// instruments share).
pub trait InstrumentRecord: ExternalRecord + Clone {
    /// The fields every instrument's row carries.
    fn reading(&self) -> Reading {
        self.common()
    }
}

/// The [`Reading`] fields of a record (a planned pose has only its pose
/// and line).
pub trait CommonFields {
    /// The record's common fields.
    fn common(&self) -> Reading;
}

/// Writes the part every instrument's record shares once: its
/// [`CommonFields`] (the record's `pose`, `sigma_um`, `temp_c`, `line` and,
/// for a kind with setups, `setup: u32`), its [`InstrumentRecord`] impl,
/// and `with_reading`, the record with a row's common fields and the
/// measured ones at their defaults. `instrument_record!(TrackerPoint,
/// setup)`; `instrument_record!(TouchReading)` for a kind without setups.
macro_rules! instrument_record {
    ($record:ident $(, $setup:ident)?) => {
        impl $crate::external::CommonFields for $record {
            fn common(&self) -> $crate::external::Reading {
                $crate::external::Reading {
                    pose: self.pose,
                    sigma_um: self.sigma_um,
                    setup: instrument_record!(@some $(self.$setup)?),
                    temp_c: self.temp_c,
                    line: self.line,
                }
            }
        }

        impl $crate::external::InstrumentRecord for $record {}

        impl $record {
            /// The record with `common`'s fields, the measured ones at
            /// their defaults.
            fn with_reading(common: $crate::external::Reading) -> Self {
                $record {
                    pose: common.pose,
                    sigma_um: common.sigma_um,
                    $($setup: common.$setup.unwrap_or(1),)?
                    temp_c: common.temp_c,
                    line: common.line,
                    ..$record::default()
                }
            }
        }
    };
    (@some) => { None };
    (@some $value:expr) => { Some($value) };
}
use instrument_record;

/// The records of one external-measurement file and where they came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExternalData<T> {
    /// Records in file order.
    pub records: Vec<T>,
    /// File name (or a label) used in messages.
    pub source: String,
}

/// The pose columns every external file starts with.
const POSE_COLUMNS: [&str; 5] = ["q1", "q2", "q3", "h1", "h2"];

/// Largest head angle accepted as radians.
const MAX_HEAD_ANGLE_RAD: f64 = std::f64::consts::TAU;
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
pub trait ExternalRow: CommonFields + Sized {
    /// Required columns after the pose columns.
    const MEASURED: &'static [&'static str];
    /// Optional columns.
    const OPTIONAL: &'static [&'static str];
    /// Builds the record from its pose and a reader of the other columns.
    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError>;
    /// Value of a column of this kind's own (`None`: not set, or a common
    /// column).
    fn own_value(&self, column: &str) -> Option<f64>;
    /// The pose.
    fn pose(&self) -> ExternalPose {
        self.common().pose
    }
    /// Value of a measured or optional column (`None`: not set).
    fn value(&self, column: &str) -> Option<f64> {
        self.own_value(column)
            .or_else(|| self.common().value(column))
    }
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

    /// The common columns of an instrument's row (`setup` where the kind
    /// has that column).
    fn reading(&self, pose: ExternalPose) -> Result<Reading, DataError> {
        Ok(Reading {
            pose,
            sigma_um: self.sigma_um()?,
            setup: self.whole_from_one("setup")?,
            temp_c: self.temp_c()?,
            line: self.record.line,
        })
    }

    fn bad(&self, idx: usize, reason: &str) -> DataError {
        self.header.bad_value(self.record, idx, reason)
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
/// use tricept_data::{external::BallbarReading, external::TouchReading, external::TrackerPoint, external::read_external_from};
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
/// use tricept_data::{external::ExternalData, external::ExternalPose, external::PlannedPose, external::TrackerPoint};
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
/// tricept_data::external::write_external_to(&mut out, &data, &[]).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// assert_eq!(text, "q1,q2,q3,h1,h2,x,y,z,extension_mm\n800,800,800,0.1,0.2,1,2,3,100\n");
/// let back = tricept_data::external::read_external_from::<TrackerPoint, _>(text.as_bytes(), "mem").unwrap();
/// assert_eq!(back.records[0].position_mm, data.records[0].position_mm);
///
/// // Poses to measure at carry the nominal tool tip for information.
/// let csv = "q1,q2,q3,h1,h2,x,y,z\n800,810,790,0.5,-0.3,10,20,1100\n";
/// let p = tricept_data::external::read_external_from::<PlannedPose, _>(csv.as_bytes(), "plan.csv").unwrap();
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
        let back = assert_round_trips(&tracker, &["a comment".into()], |a, line| TrackerPoint {
            line,
            ..*a
        });
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
        assert_round_trips(&ballbar, &[], |a, line| BallbarReading { line, ..*a });

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
        assert_round_trips(&touch, &[], |a, line| TouchReading { line, ..*a });
    }

    /// Writes `data` with `comments`, reads it back and checks every record
    /// came back equal, its line aside (`relined`: the record at a line).
    fn assert_round_trips<T: ExternalRecord + PartialEq + std::fmt::Debug>(
        data: &ExternalData<T>,
        comments: &[String],
        relined: impl Fn(&T, u64) -> T,
    ) -> ExternalData<T> {
        let mut buf = Vec::new();
        write_external_to(&mut buf, data, comments).unwrap();
        let back = read_external_from::<T, _>(buf.as_slice(), "mem").unwrap();
        assert_eq!(back.records.len(), data.records.len());
        for (a, b) in data.records.iter().zip(&back.records) {
            assert_eq!(relined(a, b.common().line), *b);
        }
        back
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
