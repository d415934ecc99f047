//! The strict measured-data reader: [`read_path`], [`read_from`] and
//! [`read_with_progress`]. On top of the shared line and record machinery
//! (`records.rs`) it locates the measured-data columns, parses each row
//! into a [`MeasuredPose`] (positive commands, ±1 directions, plausible
//! temperatures), and checks the whole file for exact repeats of a row and
//! for angles that can only be degrees.

use std::io::Read;
use std::path::Path;

use rayon::prelude::*;

use crate::records::{Header, LineBatch, Record, Records, open, record_of};
pub use crate::records::{MAX_LINE_BYTES, MAX_MAGNITUDE};
use crate::{
    DataError, Dataset, MeasuredPose, Readings, pose::OPTIONAL_COLUMNS, pose::REQUIRED_COLUMNS,
};

/// Largest span of an encoder column accepted as radians: a U joint of a
/// Tricept turns well under 100 degrees in all.
pub const MAX_ANGLE_SPAN_RAD: f64 = 1.75;

/// The largest length (a leg command, a scale reading, a tracker
/// coordinate), mm: 100 m, beyond any machine the format describes.
pub const MAX_LENGTH_MM: f64 = 1e5;

/// Lines read and parsed together (in parallel) by [`read_with_progress`].
const BATCH_LINES: usize = 16_384;

/// Rows between two calls of [`read_with_progress`]'s `progress`.
const PROGRESS_ROWS: usize = 65_536;

/// Plausible structure temperatures, °C.
const TEMP_RANGE_C: (f64, f64) = (-60.0, 200.0);

/// Where the measured-data columns stand in the header.
struct Columns {
    required: [usize; 6],
    temp: Option<usize>,
    time: Option<usize>,
    dirs: Option<[usize; 3]>,
}

/// Reads and validates a measured-data file.
///
/// # Example
/// ```
/// let dir = std::env::temp_dir().join(format!("tricept-data-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("poses.csv");
/// std::fs::write(&path, "q1,q2,q3,phi,theta,s\n796.5,796.5,796.5,0.001,-0.002,12.5\n").unwrap();
/// let data = tricept_data::read_path(&path).unwrap();
/// assert_eq!(data.poses[0].readings.s_mm, 12.5);
/// assert_eq!(data.source, path.display().to_string());
///
/// let err = tricept_data::read_path(&dir.join("missing.csv")).unwrap_err();
/// assert!(err.to_string().contains("missing.csv"));
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn read_path(path: &Path) -> Result<Dataset, DataError> {
    let (f, file) = open(path)?;
    read_from(f, &file)
}

/// Reads and validates measured data from any reader; `file` names it in errors.
///
/// # Example
/// ```
/// let csv = "# a comment\nq1,q2,q3,phi,theta,s,temp_c\n796.5,796.5,796.5,0.001,-0.002,12.5,20.1\n";
/// let data = tricept_data::read_from(csv.as_bytes(), "example.csv").unwrap();
/// assert_eq!(data.poses.len(), 1);
/// assert_eq!(data.poses[0].temp_c, Some(20.1));
/// assert_eq!(data.poses[0].line, 3);
///
/// let err = tricept_data::read_from("q1,q2,q3,phi,theta\n".as_bytes(), "bad.csv").unwrap_err();
/// assert!(err.to_string().contains("missing required column `s`"));
///
/// // A spreadsheet export with `;` and decimal commas is named as such.
/// let german = "q1;q2;q3;phi;theta;s\n796,5;796,5;796,5;0,001;-0,002;12,5\n";
/// let err = tricept_data::read_from(german.as_bytes(), "export.csv").unwrap_err();
/// assert!(err.to_string().contains("decimal commas are not accepted"));
/// ```
pub fn read_from<R: Read>(reader: R, file: &str) -> Result<Dataset, DataError> {
    read_with_progress(reader, file, |_| {})
}

/// As [`read_from`], calling `progress(rows_read)` every 65 536 rows.
///
/// The format has no quoting (every field is a number or a column name), so
/// lines are split on commas directly; this keeps line numbers exact
/// (comments and blank lines count) and reading fast.
///
/// # Example
/// ```
/// let mut csv = String::from("q1,q2,q3,phi,theta,s\n");
/// for k in 0..70_000 {
///     csv.push_str(&format!("{},800,800,0.01,0.02,5\n", 700.0 + k as f64 * 1e-3));
/// }
/// let mut reports = Vec::new();
/// let data = tricept_data::read::read_with_progress(csv.as_bytes(), "big.csv", |n| reports.push(n)).unwrap();
/// assert_eq!(data.poses.len(), 70_000);
/// assert_eq!(reports, [65_536]);
/// ```
pub fn read_with_progress<R: Read>(
    reader: R,
    file: &str,
    mut progress: impl FnMut(u64),
) -> Result<Dataset, DataError> {
    let mut records = Records::new(reader, file);
    let header = Header::read(&mut records, &REQUIRED_COLUMNS.join(","))?;
    let columns = locate_columns(&header)?;

    // Lines are read in batches and parsed in parallel; every batch's rows
    // are appended in file order, and its first error (in file order) is
    // the one reported, as a line-by-line reader would.
    let mut poses = Vec::new();
    let mut batch = LineBatch::default();
    loop {
        let read = records.next_lines(BATCH_LINES, &mut batch);
        let parsed: Vec<Result<Option<MeasuredPose>, DataError>> = batch
            .spans()
            .par_iter()
            .map(
                |(line, range)| match record_of(file, *line, batch.bytes(range))? {
                    None => Ok(None),
                    Some(record) => {
                        header.check(&record)?;
                        parse_row(&record, &columns, &header).map(Some)
                    }
                },
            )
            .collect();
        let before = poses.len();
        for pose in parsed {
            if let Some(pose) = pose? {
                poses.push(pose);
            }
        }
        read?;
        for reached in (before / PROGRESS_ROWS + 1)..=(poses.len() / PROGRESS_ROWS) {
            progress((reached * PROGRESS_ROWS) as u64);
        }
        if batch.spans().len() < BATCH_LINES {
            break;
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

fn locate_columns(header: &Header) -> Result<Columns, DataError> {
    // An external measurement file given as measured data: say which it
    // is rather than which column it lacks.
    let has = |c: &str| header.find(c).is_some();
    if !has("phi") && has("h1") && has("h2") {
        let kind = if has("x") && has("y") && has("z") {
            Some(
                "a laser-tracker file (columns h1, h2, x, y, z): give it as a tracker file (tracker)",
            )
        } else if has("length") {
            Some("a ballbar file (columns h1, h2, length): give it as a ballbar file (ballbar)")
        } else if has("feature") {
            Some("a touch-off file (columns h1, h2, feature): give it as a touch-off file (touch)")
        } else {
            None
        };
        if let Some(kind) = kind {
            return Err(DataError::Invalid {
                file: header.file.clone(),
                message: format!(
                    "line {}: this is not a measured-data file of the UP limb's readings (q1, q2, q3, phi, theta, s) but {kind}",
                    header.line
                ),
            });
        }
    }
    let known: Vec<&str> = REQUIRED_COLUMNS
        .iter()
        .chain(&OPTIONAL_COLUMNS)
        .copied()
        .collect();
    let required = header.locate(REQUIRED_COLUMNS, &known)?;
    let dir_names = ["dir1", "dir2", "dir3"];
    let dir_positions = dir_names.map(|d| header.find(d));
    let dirs = match dir_positions.iter().filter(|p| p.is_some()).count() {
        0 => None,
        3 => Some(dir_positions.map(|p| p.unwrap_or(0))),
        _ => {
            let list = |present: bool| {
                dir_names
                    .iter()
                    .zip(&dir_positions)
                    .filter(|(_, p)| p.is_some() == present)
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(",")
            };
            return Err(DataError::PartialDirections {
                file: header.file.clone(),
                line: header.line,
                found: list(true),
                missing: list(false),
            });
        }
    };
    Ok(Columns {
        required,
        temp: header.find("temp_c"),
        time: header.find("time_s"),
        dirs,
    })
}

fn parse_row(record: &Record, c: &Columns, header: &Header) -> Result<MeasuredPose, DataError> {
    let field = |idx: usize| header.number(record, idx);
    let mut v = [0.0; 6];
    for k in 0..6 {
        v[k] = field(c.required[k])?;
    }
    for k in 0..3 {
        if v[k] <= 0.0 {
            return Err(header.bad_value(
                record,
                c.required[k],
                "a leg length command must be positive (mm)",
            ));
        }
    }
    for k in [0, 1, 2, 5] {
        if v[k].abs() > MAX_LENGTH_MM {
            return Err(header.bad_value(
                record,
                c.required[k],
                format!("a length beyond {MAX_LENGTH_MM} mm: not a reading of this machine"),
            ));
        }
    }
    let temp_c = match c.temp {
        Some(i) => {
            let t = field(i)?;
            if !(TEMP_RANGE_C.0..=TEMP_RANGE_C.1).contains(&t) {
                return Err(header.bad_value(
                    record,
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
                    return Err(header.bad_value(
                        record,
                        idx[k],
                        "approach direction must be +1 or -1",
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
        line: record.line,
        campaign: 0,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Dataset, DataError> {
        read_from(text.as_bytes(), "t.csv")
    }

    fn error(text: &str) -> String {
        read(text).unwrap_err().to_string()
    }

    /// Asserts that reading `text` fails with a message starting with `start`.
    fn assert_error_starts(text: &str, start: &str) {
        let e = error(text);
        assert!(e.starts_with(start), "{e}");
    }

    /// Rows are parsed in parallel batches ([`BATCH_LINES`]); the error
    /// reported is still the first in the file, within a batch, across
    /// batches and before an overlong line, and rows keep their order.
    #[test]
    fn batches_report_the_first_error_in_the_file_and_keep_row_order() {
        let rows = |n: usize, comment_every: usize| {
            let mut csv = String::from("q1,q2,q3,phi,theta,s\n");
            for k in 0..n {
                if comment_every > 0 && k % comment_every == 0 {
                    csv.push_str("# a comment\n");
                }
                csv.push_str(&format!(
                    "{},800,800,0.01,0.02,5\n",
                    700.0 + k as f64 * 1e-3
                ));
            }
            csv
        };
        let n = 3 * BATCH_LINES + 17;
        let data = read(&rows(n, 1000)).unwrap();
        assert_eq!(data.poses.len(), n);
        for (k, p) in data.poses.iter().enumerate() {
            assert_eq!(p.commands_mm[0], 700.0 + k as f64 * 1e-3);
        }
        // Line numbers count the header and the comments.
        assert_eq!(data.poses[0].line, 3);
        assert_eq!(data.poses[n - 1].line, (n + 1 + n.div_ceil(1000)) as u64);

        let spoil = |csv: &str, lines: &[usize], with: &str| -> String {
            csv.lines()
                .enumerate()
                .map(|(i, l)| if lines.contains(&(i + 1)) { with } else { l })
                .collect::<Vec<_>>()
                .join("\n")
        };
        let clean = rows(n, 0);
        // Two bad rows in one batch, and one in a later batch.
        let two = spoil(
            &clean,
            &[2 * BATCH_LINES + 5, BATCH_LINES + 9, BATCH_LINES + 3],
            "1,2,x,0,0,0",
        );
        assert!(error(&two).starts_with(&format!("t.csv: line {}, column `q3`", BATCH_LINES + 3)));
        // A bad row before an overlong line in the same batch.
        let long = "9".repeat(crate::records::MAX_LINE_BYTES + 10);
        let both = spoil(
            &spoil(&clean, &[BATCH_LINES + 100], &long),
            &[BATCH_LINES + 50],
            "1,2,3,0,0",
        );
        assert!(
            error(&both).starts_with(&format!("t.csv: line {}:", BATCH_LINES + 50)),
            "{}",
            error(&both)
        );
        let only_long = spoil(&clean, &[BATCH_LINES + 100], &long);
        assert!(error(&only_long).contains("longer than"));
    }

    #[test]
    fn errors_name_file_line_and_column() {
        // (file, what the message must contain)
        let cases: [(&str, &[&str]); 12] = [
            ("", &["empty file"]),
            ("q1,q2,q3,phi,theta,s\n", &["header only"]),
            (
                "q1,q2,q3,phi,theat,s\n1,2,3,0,0,0\n",
                &["missing required column `theta`", "theat"],
            ),
            (
                "q1,q2,q3,phi,theta,s\n700,700,700,0.1,abc,5\n",
                &["t.csv: line 2, column `theta`: not a number"],
            ),
            (
                "q1,q2,q3,phi,theta,s\n700,700,700,0.1,NaN,5\n",
                &["column `theta`: not a finite number"],
            ),
            (
                "q1,q2,q3,phi,theta,s\n700,700,700,0.1,0.2\n",
                &["line 2: expected 6 fields like the header, found 5"],
            ),
            (
                "q1,q2,q3,phi,theta,s\n700,700,700,10,0.2,5\n700,700,701,-12,0.2,5\n",
                &["degrees"],
            ),
            ("q1,q2,q3,phi,theta,s,dir1,dir2\n", &["missing dir3"]),
            (
                "q1,q2,q3,phi,theta,s,dir1,dir2,dir3\n700,700,700,0,0,1,1,0,1\n",
                &["column `dir2`: approach direction must be +1 or -1"],
            ),
            (
                "q1,q2,q3,phi,theta,s\n700,700,700,0,0,1\n#c\n700,700,700,0,0,1\n",
                &["line 4 repeats line 2"],
            ),
            (
                "q1,q2,q3,phi,theta,s\n-700,700,700,0,0,1\n",
                &["column `q1`: a leg length command must be positive"],
            ),
            ("q1,q1,q3,phi,theta,s\n", &["`q1` appears twice"]),
        ];
        for (text, needles) in cases {
            let e = error(text);
            for needle in needles {
                assert!(e.contains(needle), "{e}");
            }
        }
    }

    #[test]
    fn extra_columns_and_column_order_are_free() {
        let d = read("pose_id,s,theta,phi,q3,q2,q1\n7,5.5,0.2,0.1,703,702,701\n").unwrap();
        assert_eq!(d.poses[0].commands_mm, [701.0, 702.0, 703.0]);
        assert_eq!(d.poses[0].readings.s_mm, 5.5);
    }

    #[test]
    fn the_empty_file_message_names_the_columns() {
        assert_eq!(
            error("# only a comment\n\n"),
            "t.csv: empty file (expected a header line with q1,q2,q3,phi,theta,s)"
        );
    }

    #[test]
    fn a_byte_order_mark_is_accepted() {
        let plain = "q1,q2,q3,phi,theta,s\n700,700,700,0.1,0.2,5\n";
        let with_bom = format!("\u{feff}{plain}");
        let d = read(&with_bom).unwrap();
        assert_eq!(d, read(plain).unwrap());
        assert_eq!(d.poses[0].line, 2);
        // Before a comment too.
        let d = read(&format!("\u{feff}# logged by hand\n{plain}")).unwrap();
        assert_eq!(d.poses[0].line, 3);
        // A BOM alone is an empty file.
        assert!(error("\u{feff}").contains("empty file"));
    }

    #[test]
    fn a_semicolon_separated_file_is_named_as_such() {
        let e = error("q1;q2;q3;phi;theta;s\n796.5;796.5;796.5;0.001;-0.002;12.5\n");
        assert_eq!(
            e,
            "t.csv: line 1: the file uses `;` as separator; tricept needs commas (`,`) between fields"
        );
        // Header only, after comments: the header's line.
        assert_error_starts(
            "# export\nq1;q2;q3;phi;theta;s\n",
            "t.csv: line 2: the file uses `;` as separator",
        );
        // A comma header over `;` rows: the first such row.
        assert_error_starts(
            "q1,q2,q3,phi,theta,s\n\n796.5;796.5;796.5;0.001;-0.002;12.5\n",
            "t.csv: line 3: the file uses `;` as separator",
        );
    }

    #[test]
    fn a_german_spreadsheet_export_gets_the_decimal_comma_message() {
        let e = error("q1;q2;q3;phi;theta;s\n796,5;796,5;796,5;0,001;-0,002;12,5\n");
        assert_eq!(
            e,
            "t.csv: line 2: the file uses `;` as separator and decimal commas (`796,5`), \
             as spreadsheets export CSV in some locales; tricept needs commas (`,`) between \
             fields, and decimal commas are not accepted: use a point (`796.5`)"
        );
        // With a BOM and a comma header, the same diagnosis on the row.
        let e = error("\u{feff}q1,q2,q3,phi,theta,s\n700;700;700;0,25;0;1\n");
        assert!(
            e.starts_with(
                "t.csv: line 2: the file uses `;` as separator and decimal commas (`0,25`)"
            ) && e.ends_with("use a point (`0.25`)"),
            "{e}"
        );
        // Integers only in the first row: the separator is what can be told.
        assert_error_starts(
            "q1;q2;q3;phi;theta;s\n700;700;700;0;0;1\n",
            "t.csv: line 1: the file uses `;` as separator;",
        );
    }

    #[test]
    fn a_decimal_comma_in_a_comma_separated_row_is_named() {
        let header = "q1,q2,q3,phi,theta,s\n796.5,796.5,796.5,0.1,0.2,12.5\n";
        let e = error(&format!("{header}796.5,796.5,796.5,0,5,0.2,12.5\n"));
        assert_eq!(
            e,
            "t.csv: line 3: expected 6 fields like the header, found 7: `0,5` looks like a \
             number with a decimal comma; decimal commas are not accepted, use a point (`0.5`)"
        );
        let e = error(&format!("{header}796.5,796.5,796.5,0.1,0.2,12,5e-1\n"));
        assert!(e.contains("`12,5e-1` looks like"), "{e}");
        // Several pairs could be the number: none is named.
        let e = error(&format!("{header}700,700,700,0,5,0.2,5\n"));
        assert_eq!(
            e,
            "t.csv: line 3: expected 6 fields like the header, found 7: is a number written \
             with a decimal comma (`0,5` for `0.5`)? Decimal commas are not accepted, use a point"
        );
        // Fewer fields, or an extra field that no number explains: the count only.
        let e = error(&format!("{header}796.5,796.5,796.5,0.1,0.2,5.5,x\n"));
        assert_eq!(
            e,
            "t.csv: line 3: expected 6 fields like the header, found 7"
        );
        let e = error(&format!("{header}700,700,700,0,5\n"));
        assert_eq!(
            e,
            "t.csv: line 3: expected 6 fields like the header, found 5"
        );
    }

    #[test]
    fn a_semicolon_inside_a_field_of_the_right_count_is_named() {
        // `;` where a number belongs, with the comma count right by chance.
        assert_error_starts(
            "q1,q2,q3,phi,theta,s\n700,700,700;1,0.1,0.2,5\n",
            "t.csv: line 2: the file uses `;` as separator",
        );
        // `;` in an ignored text column is not a separator problem.
        let d = read("q1,q2,q3,phi,theta,s,note\n700,700,700,0.1,0.2,5,ok; again\n").unwrap();
        assert_eq!(d.poses.len(), 1);
    }
}
