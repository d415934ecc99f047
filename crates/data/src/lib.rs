//! The measured-data contract of the Tricept self-calibration: one CSV row
//! per pose, written by logging tools and the plant simulator, read by
//! identification and diagnosis.
//!
//! Columns (header required, `#` lines are comments, any order):
//!
//! | column | unit | required | meaning |
//! |---|---|---|---|
//! | `q1,q2,q3` | mm | yes | commanded leg lengths sent to the drives |
//! | `phi,theta` | rad | yes | U-joint encoder readings of the UP limb (unknown zero offsets) |
//! | `s` | mm | yes | linear-scale reading of the UP limb (unknown zero offset) |
//! | `temp_c` | °C | no | structure temperature |
//! | `time_s` | s | no | time of the reading |
//! | `dir1,dir2,dir3` | ±1 | no (all three or none) | sign of each leg's last motion before the pose |
//!
//! Other columns are ignored. The reader is strict: every problem is a
//! [`DataError`] that names the file, the line and the column, never a
//! panic and never a silently skipped row.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

use std::io::{Read, Write};
use std::path::Path;

use thiserror::Error;

/// The three sensor readings of one pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Readings {
    /// Encoder reading of the U joint's x-type axis, rad.
    pub phi_rad: f64,
    /// Encoder reading of the U joint's y-type axis, rad.
    pub theta_rad: f64,
    /// Linear-scale reading of the UP limb's prismatic joint, mm.
    pub s_mm: f64,
}

impl Readings {
    /// `[phi, theta, s]` (rad, rad, mm).
    pub fn to_array(self) -> [f64; 3] {
        [self.phi_rad, self.theta_rad, self.s_mm]
    }

    /// From `[phi, theta, s]` (rad, rad, mm).
    pub fn from_array(v: [f64; 3]) -> Readings {
        Readings {
            phi_rad: v[0],
            theta_rad: v[1],
            s_mm: v[2],
        }
    }
}

/// One logged pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeasuredPose {
    /// Commanded leg lengths, mm.
    pub commands_mm: [f64; 3],
    /// Sensor readings.
    pub readings: Readings,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Time of the reading, s.
    pub time_s: Option<f64>,
    /// Sign (+1/-1) of each leg's last motion before the pose.
    pub approach: Option<[i8; 3]>,
    /// Line of the source file the pose came from (1-based; 0 if none).
    pub line: u64,
}

/// A set of logged poses and where they came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Dataset {
    /// The poses in file order.
    pub poses: Vec<MeasuredPose>,
    /// File name (or a label) used in error messages.
    pub source: String,
}

/// A problem with a measured-data file. Every variant names the file; those
/// about a value also name the line and the column.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DataError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// File name.
        file: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// No header line.
    #[error("{file}: empty file (expected a header line with q1,q2,q3,phi,theta,s)")]
    Empty {
        /// File name.
        file: String,
    },
    /// A header but no data rows.
    #[error("{file}: header only, no data rows")]
    NoRows {
        /// File name.
        file: String,
    },
    /// A required column is missing from the header.
    #[error("{file}: line {line}: missing required column `{column}`{hint}")]
    MissingColumn {
        /// File name.
        file: String,
        /// Line of the header.
        line: u64,
        /// The missing column.
        column: String,
        /// ", found `x` (misspelt?)" when a header name is close.
        hint: String,
    },
    /// A column appears twice in the header.
    #[error("{file}: line {line}: column `{column}` appears twice in the header")]
    DuplicateColumn {
        /// File name.
        file: String,
        /// Line of the header.
        line: u64,
        /// The repeated column.
        column: String,
    },
    /// Only some of dir1, dir2, dir3 are present.
    #[error(
        "{file}: line {line}: approach-direction columns come as a set: found {found}, missing {missing}"
    )]
    PartialDirections {
        /// File name.
        file: String,
        /// Line of the header.
        line: u64,
        /// The ones present.
        found: String,
        /// The ones missing.
        missing: String,
    },
    /// A row with the wrong number of fields.
    #[error("{file}: line {line}: expected {expected} fields like the header, found {found}")]
    FieldCount {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Fields in the header.
        expected: usize,
        /// Fields in this row.
        found: usize,
    },
    /// A field that is not an acceptable value.
    #[error("{file}: line {line}, column `{column}`: {reason} (got `{value}`)")]
    BadValue {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Column name.
        column: String,
        /// The raw field.
        value: String,
        /// What is wrong.
        reason: String,
    },
    /// Angle readings whose spread is impossible in radians.
    #[error(
        "{file}: column `{column}` spans {span:.3} (lines {line_min} to {line_max}), more than a U joint can turn ({limit_rad} rad): are the angles in degrees? Readings must be in rad"
    )]
    LooksLikeDegrees {
        /// File name.
        file: String,
        /// `phi` or `theta`.
        column: String,
        /// max - min of the column.
        span: f64,
        /// The largest plausible span, rad.
        limit_rad: f64,
        /// Line of the smallest value.
        line_min: u64,
        /// Line of the largest value.
        line_max: u64,
    },
    /// Two rows identical in every column.
    #[error(
        "{file}: line {line} repeats line {first_line} exactly (a logging error? repeated poses must carry their own readings)"
    )]
    DuplicateRow {
        /// File name.
        file: String,
        /// Line of the repeat.
        line: u64,
        /// Line of the first occurrence.
        first_line: u64,
    },
    /// A line that is not text.
    #[error("{file}: line {line}: {message}")]
    NotText {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// The parser's message.
        message: String,
    },
}

/// Required columns, in canonical order.
pub const REQUIRED_COLUMNS: [&str; 6] = ["q1", "q2", "q3", "phi", "theta", "s"];
/// Optional context columns, in canonical order.
pub const OPTIONAL_COLUMNS: [&str; 5] = ["temp_c", "time_s", "dir1", "dir2", "dir3"];

/// Largest span of an encoder column accepted as radians: a U joint of a
/// Tricept turns well under 100 degrees in all.
pub const MAX_ANGLE_SPAN_RAD: f64 = 1.75;

/// Plausible structure temperatures, °C.
const TEMP_RANGE_C: (f64, f64) = (-60.0, 200.0);

struct Columns {
    required: [usize; 6],
    temp: Option<usize>,
    time: Option<usize>,
    dirs: Option<[usize; 3]>,
    count: usize,
}

/// Reads and validates a measured-data file.
///
/// # Example
/// ```
/// let csv = "# a comment\nq1,q2,q3,phi,theta,s,temp_c\n796.5,796.5,796.5,0.001,-0.002,12.5,20.1\n";
/// let data = tricept_data::read_from(csv.as_bytes(), "example.csv").unwrap();
/// assert_eq!(data.poses.len(), 1);
/// assert_eq!(data.poses[0].temp_c, Some(20.1));
/// let err = tricept_data::read_from("q1,q2,q3,phi,theta\n".as_bytes(), "bad.csv").unwrap_err();
/// assert!(err.to_string().contains("missing required column `s`"));
/// ```
pub fn read_path(path: &Path) -> Result<Dataset, DataError> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|source| DataError::Io {
        file: file.clone(),
        source,
    })?;
    read_from(std::io::BufReader::new(f), &file)
}

/// Reads and validates measured data from any reader; `file` names it in errors.
pub fn read_from<R: Read>(reader: R, file: &str) -> Result<Dataset, DataError> {
    read_with_progress(reader, file, |_| {})
}

/// As [`read_from`], calling `progress(rows_read)` every 65 536 rows.
///
/// The format has no quoting (every field is a number or a column name), so
/// lines are split on commas directly; this keeps line numbers exact
/// (comments and blank lines count) and reading fast.
pub fn read_with_progress<R: Read>(
    reader: R,
    file: &str,
    mut progress: impl FnMut(u64),
) -> Result<Dataset, DataError> {
    let mut reader = std::io::BufReader::new(reader);
    let mut buf = Vec::new();
    let mut line: u64 = 0;
    // Reads the next line that is neither blank nor a comment.
    let mut next_line = |buf: &mut Vec<u8>| -> Result<Option<u64>, DataError> {
        use std::io::BufRead;
        loop {
            buf.clear();
            let n = reader
                .read_until(b'\n', buf)
                .map_err(|source| DataError::Io {
                    file: file.to_string(),
                    source,
                })?;
            if n == 0 {
                return Ok(None);
            }
            line += 1;
            let trimmed = buf.trim_ascii();
            if trimmed.is_empty() || trimmed.starts_with(b"#") {
                continue;
            }
            return Ok(Some(line));
        }
    };
    let split = |buf: &[u8], line: u64| -> Result<Vec<String>, DataError> {
        let text = std::str::from_utf8(buf.trim_ascii()).map_err(|_| DataError::NotText {
            file: file.to_string(),
            line,
            message: "not valid UTF-8 text".into(),
        })?;
        Ok(text.split(',').map(|f| f.trim().to_string()).collect())
    };

    let Some(header_line) = next_line(&mut buf)? else {
        return Err(DataError::Empty { file: file.into() });
    };
    let names = split(&buf, header_line)?;
    let columns = locate_columns(&names, file, header_line)?;

    let mut poses = Vec::new();
    while let Some(line) = next_line(&mut buf)? {
        let fields = split(&buf, line)?;
        if fields.len() != columns.count {
            return Err(DataError::FieldCount {
                file: file.into(),
                line,
                expected: columns.count,
                found: fields.len(),
            });
        }
        let pose = parse_row(&fields, &columns, &names, file, line)?;
        poses.push(pose);
        if poses.len() % 65_536 == 0 {
            progress(poses.len() as u64);
        }
    }
    if poses.is_empty() {
        return Err(DataError::NoRows { file: file.into() });
    }
    if let Some((first_line, line)) = first_duplicate(&poses) {
        return Err(DataError::DuplicateRow {
            file: file.into(),
            line,
            first_line,
        });
    }
    check_angle_spans(&poses, file)?;
    Ok(Dataset {
        poses,
        source: file.into(),
    })
}

/// The bits of every value of a row.
fn record_key(p: &MeasuredPose) -> [u64; 8] {
    let r = p.readings.to_array();
    [
        p.commands_mm[0].to_bits(),
        p.commands_mm[1].to_bits(),
        p.commands_mm[2].to_bits(),
        r[0].to_bits(),
        r[1].to_bits(),
        r[2].to_bits(),
        p.temp_c.map_or(u64::MAX, f64::to_bits),
        p.time_s.map_or(u64::MAX, f64::to_bits),
    ]
}

/// The earliest-ending pair of identical rows, as `(first line, repeat
/// line)`: rows sorted by a hash of their values (16 bytes per row, so a
/// million-row file needs 16 MB), equal hashes compared exactly.
fn first_duplicate(poses: &[MeasuredPose]) -> Option<(u64, u64)> {
    use std::hash::{DefaultHasher, Hash, Hasher};
    let mut keyed: Vec<(u64, u32)> = poses
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut h = DefaultHasher::new();
            record_key(p).hash(&mut h);
            (h.finish(), i as u32)
        })
        .collect();
    keyed.sort_unstable();
    let mut best: Option<(u64, u64)> = None;
    let mut start = 0;
    while start < keyed.len() {
        let mut end = start + 1;
        while end < keyed.len() && keyed[end].0 == keyed[start].0 {
            end += 1;
        }
        // Within a run of equal hashes (indices ascending), find repeats.
        for a in start..end {
            for b in a + 1..end {
                let (i, j) = (keyed[a].1 as usize, keyed[b].1 as usize);
                if record_key(&poses[i]) == record_key(&poses[j]) {
                    let pair = (poses[i].line, poses[j].line);
                    if best.is_none_or(|(_, l)| pair.1 < l) {
                        best = Some(pair);
                    }
                    break;
                }
            }
        }
        start = end;
    }
    best
}

fn locate_columns(names: &[String], file: &str, line: u64) -> Result<Columns, DataError> {
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) && !n.is_empty() {
            return Err(DataError::DuplicateColumn {
                file: file.into(),
                line,
                column: n.clone(),
            });
        }
    }
    let find = |name: &str| names.iter().position(|n| n == name);
    let mut required = [0; 6];
    for (k, name) in REQUIRED_COLUMNS.iter().enumerate() {
        required[k] = find(name).ok_or_else(|| DataError::MissingColumn {
            file: file.into(),
            line,
            column: name.to_string(),
            hint: closest_unknown(names, name)
                .map(|n| format!(", found `{n}` (misspelt?)"))
                .unwrap_or_default(),
        })?;
    }
    let dir_positions: Vec<Option<usize>> =
        ["dir1", "dir2", "dir3"].iter().map(|d| find(d)).collect();
    let dirs = match dir_positions.iter().filter(|p| p.is_some()).count() {
        0 => None,
        3 => Some([0, 1, 2].map(|k| dir_positions[k].unwrap_or(0))),
        _ => {
            let list = |present: bool| {
                ["dir1", "dir2", "dir3"]
                    .iter()
                    .zip(&dir_positions)
                    .filter(|(_, p)| p.is_some() == present)
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(",")
            };
            return Err(DataError::PartialDirections {
                file: file.into(),
                line,
                found: list(true),
                missing: list(false),
            });
        }
    };
    Ok(Columns {
        required,
        temp: find("temp_c"),
        time: find("time_s"),
        dirs,
        count: names.len(),
    })
}

/// A header name that is not a known column and is within edit distance 2
/// of `wanted` (case-insensitive).
fn closest_unknown<'a>(names: &'a [String], wanted: &str) -> Option<&'a str> {
    let known = |n: &str| REQUIRED_COLUMNS.contains(&n) || OPTIONAL_COLUMNS.contains(&n);
    names
        .iter()
        .filter(|n| !known(n))
        .map(|n| (n, edit_distance(&n.to_lowercase(), wanted)))
        .filter(|(n, d)| *d <= 2 && *d < n.len().max(wanted.len()))
        .min_by_key(|(_, d)| *d)
        .map(|(n, _)| n.as_str())
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

fn parse_row(
    record: &[String],
    c: &Columns,
    names: &[String],
    file: &str,
    line: u64,
) -> Result<MeasuredPose, DataError> {
    let field = |idx: usize| -> Result<f64, DataError> {
        let text = record[idx].as_str();
        let bad = |reason: &str| DataError::BadValue {
            file: file.into(),
            line,
            column: names[idx].clone(),
            value: text.to_string(),
            reason: reason.into(),
        };
        if text.is_empty() {
            return Err(bad("empty field"));
        }
        let v: f64 = text.parse().map_err(|_| bad("not a number"))?;
        if !v.is_finite() {
            return Err(bad("not a finite number"));
        }
        Ok(v)
    };
    let bad_value = |idx: usize, reason: String| DataError::BadValue {
        file: file.into(),
        line,
        column: names[idx].clone(),
        value: record[idx].clone(),
        reason,
    };
    let mut v = [0.0; 6];
    for k in 0..6 {
        v[k] = field(c.required[k])?;
    }
    for k in 0..3 {
        if v[k] <= 0.0 {
            return Err(bad_value(
                c.required[k],
                "a leg length command must be positive (mm)".into(),
            ));
        }
    }
    let temp_c = match c.temp {
        Some(i) => {
            let t = field(i)?;
            if !(TEMP_RANGE_C.0..=TEMP_RANGE_C.1).contains(&t) {
                return Err(bad_value(
                    i,
                    format!(
                        "temperature outside {}..{} °C",
                        TEMP_RANGE_C.0, TEMP_RANGE_C.1
                    ),
                ));
            }
            Some(t)
        }
        None => None,
    };
    let time_s = c.time.map(field).transpose()?;
    let approach = match c.dirs {
        Some(idx) => {
            let mut d = [0i8; 3];
            for k in 0..3 {
                let x = field(idx[k])?;
                d[k] = if x == 1.0 {
                    1
                } else if x == -1.0 {
                    -1
                } else {
                    return Err(bad_value(
                        idx[k],
                        "approach direction must be +1 or -1".into(),
                    ));
                };
            }
            Some(d)
        }
        None => None,
    };
    Ok(MeasuredPose {
        commands_mm: [v[0], v[1], v[2]],
        readings: Readings {
            phi_rad: v[3],
            theta_rad: v[4],
            s_mm: v[5],
        },
        temp_c,
        time_s,
        approach,
        line,
    })
}

fn check_angle_spans(poses: &[MeasuredPose], file: &str) -> Result<(), DataError> {
    for (name, get) in [
        (
            "phi",
            (|p: &MeasuredPose| p.readings.phi_rad) as fn(&MeasuredPose) -> f64,
        ),
        ("theta", |p: &MeasuredPose| p.readings.theta_rad),
    ] {
        let (mut lo, mut hi) = (poses[0], poses[0]);
        for p in poses {
            if get(p) < get(&lo) {
                lo = *p;
            }
            if get(p) > get(&hi) {
                hi = *p;
            }
        }
        let span = get(&hi) - get(&lo);
        if span > MAX_ANGLE_SPAN_RAD {
            return Err(DataError::LooksLikeDegrees {
                file: file.into(),
                column: name.into(),
                span,
                limit_rad: MAX_ANGLE_SPAN_RAD,
                line_min: lo.line,
                line_max: hi.line,
            });
        }
    }
    Ok(())
}

/// Reads target points from a CSV file with columns `x,y,z` (mm; header
/// required, `#` comments, other columns ignored).
pub fn read_targets(path: &Path) -> Result<Vec<[f64; 3]>, DataError> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|source| DataError::Io {
        file: file.clone(),
        source,
    })?;
    let text =
        std::io::read_to_string(std::io::BufReader::new(f)).map_err(|source| DataError::Io {
            file: file.clone(),
            source,
        })?;
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i as u64 + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(DataError::Empty { file });
    };
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    let mut idx = [0usize; 3];
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        idx[k] = names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| DataError::MissingColumn {
                file: file.clone(),
                line: header_line,
                column: name.to_string(),
                hint: String::new(),
            })?;
    }
    let mut out = Vec::new();
    for (line, l) in lines {
        let fields: Vec<&str> = l.split(',').map(str::trim).collect();
        if fields.len() != names.len() {
            return Err(DataError::FieldCount {
                file,
                line,
                expected: names.len(),
                found: fields.len(),
            });
        }
        let mut p = [0.0; 3];
        for k in 0..3 {
            let raw = fields[idx[k]];
            p[k] = raw
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| DataError::BadValue {
                    file: file.clone(),
                    line,
                    column: names[idx[k]].clone(),
                    value: raw.to_string(),
                    reason: "not a finite number".into(),
                })?;
        }
        out.push(p);
    }
    if out.is_empty() {
        return Err(DataError::NoRows { file });
    }
    Ok(out)
}

/// Writes `data` as CSV: the required columns, then the context columns
/// that every pose carries. Values are written with full precision
/// (shortest representation that reads back to the same `f64`).
pub fn write_to<W: Write>(mut w: W, data: &Dataset, comments: &[String]) -> std::io::Result<()> {
    for c in comments {
        for line in c.lines() {
            writeln!(w, "# {line}")?;
        }
    }
    let has_temp = data.poses.iter().all(|p| p.temp_c.is_some()) && !data.poses.is_empty();
    let has_time = data.poses.iter().all(|p| p.time_s.is_some()) && !data.poses.is_empty();
    let has_dirs = data.poses.iter().all(|p| p.approach.is_some()) && !data.poses.is_empty();
    let mut header: Vec<&str> = REQUIRED_COLUMNS.to_vec();
    if has_temp {
        header.push("temp_c");
    }
    if has_time {
        header.push("time_s");
    }
    if has_dirs {
        header.extend(["dir1", "dir2", "dir3"]);
    }
    writeln!(w, "{}", header.join(","))?;
    for p in &data.poses {
        let [q1, q2, q3] = p.commands_mm;
        let r = p.readings;
        write!(w, "{q1},{q2},{q3},{},{},{}", r.phi_rad, r.theta_rad, r.s_mm)?;
        if let (true, Some(t)) = (has_temp, p.temp_c) {
            write!(w, ",{t}")?;
        }
        if let (true, Some(t)) = (has_time, p.time_s) {
            write!(w, ",{t}")?;
        }
        if let (true, Some(d)) = (has_dirs, p.approach) {
            write!(w, ",{},{},{}", d[0], d[1], d[2])?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// Writes `data` to a file (see [`write_to`]).
pub fn write_path(path: &Path, data: &Dataset, comments: &[String]) -> std::io::Result<()> {
    let f = std::fs::File::create(path)?;
    let mut w = std::io::BufWriter::new(f);
    write_to(&mut w, data, comments)?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Dataset, DataError> {
        read_from(text.as_bytes(), "t.csv")
    }

    #[test]
    fn round_trip_is_exact() {
        let data = Dataset {
            poses: (0..20)
                .map(|k| MeasuredPose {
                    commands_mm: [700.0 + k as f64 / 3.0, 701.1, 702.000_000_1],
                    readings: Readings {
                        phi_rad: 0.1 / (k as f64 + 1.0),
                        theta_rad: -1e-7 * k as f64,
                        s_mm: 123.456_789_012_345,
                    },
                    temp_c: Some(20.0 + 0.01 * k as f64),
                    time_s: Some(10.0 * k as f64),
                    approach: Some([1, -1, if k % 2 == 0 { 1 } else { -1 }]),
                    line: 0,
                })
                .collect(),
            source: "mem".into(),
        };
        let mut buf = Vec::new();
        write_to(&mut buf, &data, &["generated by a test".into()]).unwrap();
        let back = read_from(buf.as_slice(), "mem").unwrap();
        assert_eq!(back.poses.len(), 20);
        for (a, b) in data.poses.iter().zip(&back.poses) {
            assert_eq!(a.commands_mm, b.commands_mm);
            assert_eq!(a.readings, b.readings);
            assert_eq!(a.temp_c, b.temp_c);
            assert_eq!(a.approach, b.approach);
        }
        // Comment line + header: the first pose is on line 3.
        assert_eq!(back.poses[0].line, 3);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = read("").unwrap_err().to_string();
        assert!(e.contains("empty file"), "{e}");
        let e = read("q1,q2,q3,phi,theta,s\n").unwrap_err().to_string();
        assert!(e.contains("header only"), "{e}");
        let e = read("q1,q2,q3,phi,theat,s\n1,2,3,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("missing required column `theta`") && e.contains("theat"),
            "{e}"
        );
        let e = read("q1,q2,q3,phi,theta,s\n700,700,700,0.1,abc,5\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t.csv: line 2, column `theta`: not a number"),
            "{e}"
        );
        let e = read("q1,q2,q3,phi,theta,s\n700,700,700,0.1,NaN,5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("column `theta`: not a finite number"), "{e}");
        let e = read("q1,q2,q3,phi,theta,s\n700,700,700,0.1,0.2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 2: expected 6 fields like the header, found 5"),
            "{e}"
        );
        let e = read("q1,q2,q3,phi,theta,s\n700,700,700,10,0.2,5\n700,700,701,-12,0.2,5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("degrees"), "{e}");
        let e = read("q1,q2,q3,phi,theta,s,dir1,dir2\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing dir3"), "{e}");
        let e = read("q1,q2,q3,phi,theta,s,dir1,dir2,dir3\n700,700,700,0,0,1,1,0,1\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("column `dir2`: approach direction must be +1 or -1"),
            "{e}"
        );
        let e = read("q1,q2,q3,phi,theta,s\n700,700,700,0,0,1\n#c\n700,700,700,0,0,1\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 4 repeats line 2"), "{e}");
        let e = read("q1,q2,q3,phi,theta,s\n-700,700,700,0,0,1\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("column `q1`: a leg length command must be positive"),
            "{e}"
        );
        let e = read("q1,q1,q3,phi,theta,s\n").unwrap_err().to_string();
        assert!(e.contains("`q1` appears twice"), "{e}");
    }

    #[test]
    fn extra_columns_and_column_order_are_free() {
        let d = read("pose_id,s,theta,phi,q3,q2,q1\n7,5.5,0.2,0.1,703,702,701\n").unwrap();
        assert_eq!(d.poses[0].commands_mm, [701.0, 702.0, 703.0]);
        assert_eq!(d.poses[0].readings.s_mm, 5.5);
    }
}
