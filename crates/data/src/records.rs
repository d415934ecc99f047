//! The line and record machinery shared by every CSV reader of the crate
//! (measured data in `read.rs`, target lists in `targets.rs`, external
//! measurements in `external/`), so that all
//! read the same format the same way and report problems with the same
//! messages.
//!
//! [`Records`] turns bytes into records: lines split on `\n`, a UTF-8
//! byte-order mark at the start of the file stripped, blank lines and `#`
//! comments skipped (they still count, so line numbers are exact and
//! 1-based), each remaining line checked to be UTF-8 and split on commas
//! (the format has no quoting: every field is a number or a column name),
//! fields trimmed; `Records::next_lines` hands over batches of lines unparsed,
//! for a reader that turns them into records in parallel (`read.rs`).
//! [`Header`] takes the first record as the column names,
//! locates the columns a reader needs, checks that each row has as many
//! fields, and parses fields as finite numbers. Files written with `;` as
//! separator or with decimal commas are recognised and reported as such.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use crate::DataError;
use crate::message::shown;

/// The longest line a reader accepts, in bytes: far longer than any row of
/// numbers, short enough that `/dev/zero` or a binary file is refused
/// without reading it whole.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// The largest magnitude any number in a data file may have: beyond it a
/// value is not a reading in any unit of the format, and its square would
/// lose all precision in a fit.
pub const MAX_MAGNITUDE: f64 = 1e12;

/// The UTF-8 encoding of U+FEFF, which some editors and spreadsheets write at
/// the start of a "UTF-8" file.
const BYTE_ORDER_MARK: &[u8] = b"\xEF\xBB\xBF";

/// Opens `path` for reading; the error names the file.
pub(crate) fn open(path: &Path) -> Result<(std::fs::File, String), DataError> {
    let file = path.display().to_string();
    match std::fs::File::open(path) {
        Ok(f) => Ok((f, file)),
        Err(source) => Err(DataError::Io { file, source }),
    }
}

/// One line that is neither blank nor a comment.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Record {
    /// Line in the file, 1-based (comments and blank lines count).
    pub line: u64,
    /// The comma-separated fields, trimmed.
    pub fields: Vec<String>,
}

/// The records of a CSV source, in file order. Stop at the first error: the
/// line after an unreadable one is not a meaningful place to go on from.
pub(crate) struct Records<'f, R> {
    reader: BufReader<R>,
    file: &'f str,
    buf: Vec<u8>,
    line: u64,
}

impl<'f, R: Read> Records<'f, R> {
    /// Records of `reader`; `file` names it in errors.
    pub fn new(reader: R, file: &'f str) -> Self {
        Records {
            reader: BufReader::new(reader),
            file,
            buf: Vec::new(),
            line: 0,
        }
    }

    /// Reads the next line into `self.buf` (line end included) and counts
    /// it; `false` at the end of the source.
    fn read_line(&mut self) -> Result<bool, DataError> {
        self.buf.clear();
        let n = (&mut self.reader)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|source| DataError::Io {
                file: self.file.to_string(),
                source,
            })?;
        if n == 0 {
            return Ok(false);
        }
        self.line += 1;
        if self.buf.len() > MAX_LINE_BYTES {
            return Err(DataError::NotText {
                file: self.file.to_string(),
                line: self.line,
                message: format!(
                    "a line longer than {MAX_LINE_BYTES} bytes: not a data file of numbers"
                ),
            });
        }
        Ok(true)
    }

    fn next_record(&mut self) -> Result<Option<Record>, DataError> {
        while self.read_line()? {
            if let Some(record) = record_of(self.file, self.line, &self.buf)? {
                return Ok(Some(record));
            }
        }
        Ok(None)
    }

    /// Reads up to `max_lines` further lines into `batch` (cleared first),
    /// unparsed, so that a reader can turn them into records in parallel
    /// ([`record_of`]). An error (unreadable source, an overlong line) is
    /// returned with the lines read before it kept in `batch`: they come
    /// first in the file, and so do their errors.
    pub fn next_lines(&mut self, max_lines: usize, batch: &mut LineBatch) -> Result<(), DataError> {
        batch.bytes.clear();
        batch.lines.clear();
        while batch.lines.len() < max_lines && self.read_line()? {
            let start = batch.bytes.len();
            batch.bytes.extend_from_slice(&self.buf);
            batch.lines.push((self.line, start..batch.bytes.len()));
        }
        Ok(())
    }
}

/// Lines read by [`Records::next_lines`]: their bytes end to end, and each
/// line's number and byte range.
#[derive(Debug, Default)]
pub(crate) struct LineBatch {
    bytes: Vec<u8>,
    lines: Vec<(u64, std::ops::Range<usize>)>,
}

impl LineBatch {
    /// The lines as a slice of `(line number, byte range)` (for a parallel
    /// iterator), with [`LineBatch::bytes`] to resolve them.
    pub fn spans(&self) -> &[(u64, std::ops::Range<usize>)] {
        &self.lines
    }

    /// The bytes of line `range` of [`LineBatch::spans`].
    pub fn bytes(&self, range: &std::ops::Range<usize>) -> &[u8] {
        &self.bytes[range.clone()]
    }
}

/// The record of line `line` of `file` (its bytes as read, line end
/// included): `None` for a blank line or a `#` comment; an error for text
/// that is not this format's.
pub(crate) fn record_of(file: &str, line: u64, bytes: &[u8]) -> Result<Option<Record>, DataError> {
    let not_text = |message: String| DataError::NotText {
        file: file.to_string(),
        line,
        message,
    };
    let bytes = if line == 1 {
        bytes.strip_prefix(BYTE_ORDER_MARK).unwrap_or(bytes)
    } else {
        bytes
    };
    let trimmed = bytes.trim_ascii();
    if trimmed.contains(&b'\r') {
        return Err(not_text(
            "carriage returns (\\r) inside the line: the file has old Mac line ends; save it with \\n (or \\r\\n) line ends".into(),
        ));
    }
    if trimmed.is_empty() || trimmed.starts_with(b"#") {
        return Ok(None);
    }
    let text = std::str::from_utf8(trimmed).map_err(|_| not_text("not valid UTF-8 text".into()))?;
    Ok(Some(Record {
        line,
        fields: text.split(',').map(|f| f.trim().to_string()).collect(),
    }))
}

impl<R: Read> Iterator for Records<'_, R> {
    type Item = Result<Record, DataError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_record().transpose()
    }
}

/// The header of a CSV source: the column names and where they stand.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Header {
    /// File name, for errors.
    pub file: String,
    /// Line of the header.
    pub line: u64,
    /// Column names, in file order.
    pub names: Vec<String>,
}

impl Header {
    /// Reads the first record of `records` as the header. Refuses an empty
    /// file (`expected` says which columns the header should have), a
    /// header separated by `;` (looking at the first row to tell a
    /// spreadsheet export with decimal commas), and repeated names.
    pub fn read<R: Read>(
        records: &mut Records<'_, R>,
        expected: &str,
    ) -> Result<Header, DataError> {
        let file = records.file.to_string();
        let Some(record) = records.next().transpose()? else {
            return Err(DataError::Empty {
                file,
                expected: expected.into(),
            });
        };
        if is_semicolon_separated(&record.fields) {
            // A spreadsheet's export also writes decimal commas: say so, on
            // the first row, if that is the case.
            let first_row = records.next().and_then(Result::ok);
            return Err(match first_row.map(|row| semicolon_problem(&file, &row)) {
                Some(e @ DataError::SemicolonsAndDecimalCommas { .. }) => e,
                _ => DataError::SemicolonSeparated {
                    file,
                    line: record.line,
                },
            });
        }
        if record.fields.len() == 1 && record.fields[0].contains('\t') {
            return Err(DataError::NotText {
                file,
                line: record.line,
                message:
                    "the fields are separated by tabs; tricept needs commas (`,`) between fields"
                        .into(),
            });
        }
        if record
            .fields
            .iter()
            .all(|f| !f.is_empty() && f.parse::<f64>().is_ok())
        {
            return Err(DataError::NotText {
                file,
                line: record.line,
                message: format!(
                    "the first line holds numbers, not column names: the file needs a header line ({expected})"
                ),
            });
        }
        let names = record.fields;
        for (i, n) in names.iter().enumerate() {
            if !n.is_empty() && names[..i].contains(n) {
                return Err(DataError::DuplicateColumn {
                    file,
                    line: record.line,
                    column: shown(n),
                });
            }
        }
        Ok(Header {
            file,
            line: record.line,
            names,
        })
    }

    /// Position of the column `name`, if the header has it.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Positions of the columns `wanted`. A missing one is an error whose
    /// hint names a header name that is close to it and is not one of the
    /// reader's `known` columns (a misspelling).
    pub fn locate<const N: usize>(
        &self,
        wanted: [&str; N],
        known: &[&str],
    ) -> Result<[usize; N], DataError> {
        let mut idx = [0; N];
        for (k, name) in wanted.iter().enumerate() {
            idx[k] = self.locate_one(name, known)?;
        }
        Ok(idx)
    }

    /// Position of the required column `name` (see [`Header::locate`]).
    pub fn locate_one(&self, name: &str, known: &[&str]) -> Result<usize, DataError> {
        self.find(name).ok_or_else(|| DataError::MissingColumn {
            file: self.file.clone(),
            line: self.line,
            column: name.to_string(),
            hint: closest_unknown(&self.names, name, known)
                .map(|n| format!(", found `{}` (misspelt?)", shown(n)))
                .unwrap_or_default(),
        })
    }

    /// Checks that `record` has as many fields as the header; a row that
    /// does not is reported as `;`-separated or as holding a decimal comma
    /// when it looks like one.
    pub fn check(&self, record: &Record) -> Result<(), DataError> {
        if record.fields.len() == self.names.len() {
            return Ok(());
        }
        Err(self
            .separator_problem(record)
            .unwrap_or_else(|| DataError::FieldCount {
                file: self.file.clone(),
                line: record.line,
                expected: self.names.len(),
                found: record.fields.len(),
            }))
    }

    /// Field `idx` of `record` (which passed [`Header::check`]) as a finite
    /// number.
    pub fn number(&self, record: &Record, idx: usize) -> Result<f64, DataError> {
        let text = record.fields[idx].as_str();
        if text.is_empty() {
            return Err(self.bad_value(record, idx, "empty field"));
        }
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() && v.abs() <= MAX_MAGNITUDE => Ok(v),
            Ok(v) if v.is_finite() => Err(self.bad_value(
                record,
                idx,
                format!("beyond ±{MAX_MAGNITUDE:e}: not a value in any unit of the format"),
            )),
            Ok(_) => Err(self.bad_value(record, idx, "not a finite number")),
            Err(_) if text.contains(';') => Err(semicolon_problem(&self.file, record)),
            Err(_) => Err(self.bad_value(record, idx, "not a number")),
        }
    }

    /// The error for field `idx` of `record`: `reason` says what is wrong.
    pub fn bad_value(&self, record: &Record, idx: usize, reason: impl Into<String>) -> DataError {
        DataError::BadValue {
            file: self.file.clone(),
            line: record.line,
            column: shown(&self.names[idx]),
            value: shown(&record.fields[idx]),
            reason: reason.into(),
        }
    }

    /// Why a row with the wrong number of fields has it, when the cause is
    /// recognisable: `;` as separator, or a decimal comma splitting a number
    /// in two (more fields than the header).
    fn separator_problem(&self, record: &Record) -> Option<DataError> {
        if record.fields.iter().any(|f| f.contains(';')) {
            return Some(semicolon_problem(&self.file, record));
        }
        if record.fields.len() <= self.names.len() {
            return None;
        }
        let mut pairs = record
            .fields
            .windows(2)
            .filter(|w| is_decimal_comma_number(&w[0], &w[1]));
        let first = pairs.next()?;
        // Name the number only when no other pair could be it.
        let value = match pairs.next() {
            None => Some(format!("{},{}", first[0], first[1])),
            Some(_) => None,
        };
        Some(DataError::DecimalComma {
            file: self.file.clone(),
            line: record.line,
            expected: self.names.len(),
            found: record.fields.len(),
            value,
        })
    }
}

/// Whether a header's comma-split fields hold more `;` than `,`: a header
/// separated by `;`. (Only for the header: a `;`-separated row with decimal
/// commas may hold as many `,` as `;`.)
fn is_semicolon_separated(fields: &[String]) -> bool {
    let semicolons: usize = fields.iter().map(|f| f.matches(';').count()).sum();
    semicolons >= fields.len()
}

/// The error for a row separated by `;`: with decimal commas (a
/// spreadsheet's export in a locale such as German) if a `;`-separated
/// field reads as a number with a decimal comma.
fn semicolon_problem(file: &str, record: &Record) -> DataError {
    let text = record.fields.join(",");
    let decimal_comma = text.split(';').map(str::trim).find(|f| {
        f.split_once(',')
            .is_some_and(|(whole, fraction)| is_decimal_comma_number(whole, fraction))
    });
    match decimal_comma {
        Some(value) => DataError::SemicolonsAndDecimalCommas {
            file: file.into(),
            line: record.line,
            value: value.into(),
        },
        None => DataError::SemicolonSeparated {
            file: file.into(),
            line: record.line,
        },
    }
}

/// Whether `whole,fraction` reads as one number written with a decimal
/// comma: `whole` an optionally signed integer, `fraction` digits with an
/// optional exponent (`796` and `5`, `-0` and `002`, `1` and `5e-3`).
fn is_decimal_comma_number(whole: &str, fraction: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let unsigned = whole.strip_prefix(['+', '-']).unwrap_or(whole);
    let (mantissa, exponent) = match fraction.split_once(['e', 'E']) {
        Some((m, e)) => (m, Some(e.strip_prefix(['+', '-']).unwrap_or(e))),
        None => (fraction, None),
    };
    digits(unsigned) && digits(mantissa) && exponent.is_none_or(digits)
}

/// A header name that is not a `known` column and is within edit distance
/// 2 of `wanted` (case-insensitive).
fn closest_unknown<'a>(names: &'a [String], wanted: &str, known: &[&str]) -> Option<&'a str> {
    names
        .iter()
        .filter(|n| !known.contains(&n.as_str()))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn records(text: &[u8]) -> Vec<(u64, Vec<String>)> {
        Records::new(text, "t.csv")
            .map(|r| r.map(|r| (r.line, r.fields)))
            .collect::<Result<_, _>>()
            .unwrap()
    }

    #[test]
    fn records_skip_comments_and_blanks_but_count_them() {
        let r = records(b"# c\n\n a , b \n  \n#x\n1,2\r\n3\n");
        assert_eq!(
            r,
            vec![
                (3, vec!["a".to_string(), "b".into()]),
                (6, vec!["1".into(), "2".into()]),
                (7, vec!["3".into()]),
            ]
        );
    }

    #[test]
    fn a_byte_order_mark_is_stripped_at_the_start_only() {
        let r = records(b"\xEF\xBB\xBF# comment\nx,y\n");
        assert_eq!(r, vec![(2, vec!["x".to_string(), "y".into()])]);
        let r = records(b"\xEF\xBB\xBFx,y\n");
        assert_eq!(r[0].1[0], "x");
        // Further in, U+FEFF is text like any other (and not a column name).
        let r = records(b"x,y\n\xEF\xBB\xBFx,y\n");
        assert_eq!(r[1].1[0], "\u{feff}x");
    }

    #[test]
    fn not_utf8_names_the_line() {
        let e = Records::new(&b"# ok\nx,\xff\n"[..], "t.csv")
            .next()
            .unwrap()
            .unwrap_err()
            .to_string();
        assert_eq!(e, "t.csv: line 2: not valid UTF-8 text");
    }

    fn first_error(text: &[u8]) -> String {
        let mut r = Records::new(text, "t.csv");
        match Header::read(&mut r, "x,y,z") {
            Err(e) => e.to_string(),
            Ok(h) => {
                for rec in r {
                    match rec {
                        Err(e) => return e.to_string(),
                        Ok(rec) => {
                            if let Err(e) = h.check(&rec).and_then(|_| h.number(&rec, 0)) {
                                return e.to_string();
                            }
                        }
                    }
                }
                String::new()
            }
        }
    }

    #[test]
    fn files_that_are_not_comma_separated_text_are_named_as_such() {
        // A line of a megabyte and more: /dev/zero, a binary file.
        let mut long = b"x,y\n".to_vec();
        long.extend(std::iter::repeat_n(b'0', MAX_LINE_BYTES + 10));
        assert_eq!(
            first_error(&long),
            format!(
                "t.csv: line 2: a line longer than {MAX_LINE_BYTES} bytes: not a data file of numbers"
            )
        );
        // Old Mac line ends: one line with carriage returns inside.
        let e = first_error(b"x,y,z\r1,2,3\r4,5,6\r");
        assert!(e.starts_with("t.csv: line 1: carriage returns"), "{e}");
        // Windows line ends are fine.
        assert_eq!(first_error(b"x,y,z\r\n1,2,3\r\n"), "");
        // Tabs.
        let e = first_error(b"x\ty\tz\n1\t2\t3\n");
        assert!(e.contains("separated by tabs"), "{e}");
        // No header: the first line holds numbers.
        let e = first_error(b"676.83,1.5,2\n676.9,1.6,2.1\n");
        assert_eq!(
            e,
            "t.csv: line 1: the first line holds numbers, not column names: the file needs a header line (x,y,z)"
        );
        // A number too large for any unit of the format.
        let e = first_error(b"x,y,z\n1e300,2,3\n");
        assert!(
            e.contains("line 2, column `x`") && e.contains("beyond"),
            "{e}"
        );
    }

    #[test]
    fn messages_cut_long_fields_and_escape_control_characters() {
        let long = "9".repeat(10_000) + "x";
        let e = first_error(format!("x,y,z\n{long},2,3\n").as_bytes());
        assert!(e.len() < 300, "{} bytes: {}", e.len(), &e[..200]);
        assert!(e.contains("… (9921 more bytes)"), "{e}");
        let e = first_error(b"x,y,z\n1\x1b[31m,2,3\n");
        assert!(e.contains("1\\u{1b}[31m"), "{e}");
        assert!(!e.contains('\x1b'));
    }

    #[test]
    fn decimal_comma_numbers() {
        for (w, f) in [("796", "5"), ("-0", "002"), ("+1", "5e-3"), ("1", "5E7")] {
            assert!(is_decimal_comma_number(w, f), "{w},{f}");
        }
        for (w, f) in [
            ("", "5"),
            ("1", ""),
            ("1.5", "2"),
            ("a", "1"),
            ("1", "-2"),
            ("1", "5e"),
        ] {
            assert!(!is_decimal_comma_number(w, f), "{w},{f}");
        }
    }

    #[test]
    fn edit_distance_counts_edits() {
        assert_eq!(edit_distance("theat", "theta"), 2);
        assert_eq!(edit_distance("phi", "phi"), 0);
        assert_eq!(edit_distance("", "s"), 1);
    }
}
