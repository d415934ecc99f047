//! The target-list reader: [`read_targets`] and [`read_targets_from`],
//! points `x,y,z` in mm (`tricept compensate --targets`, `--poses FILE`).
//! Same format rules and same messages as the measured-data reader, from the
//! same record machinery (`records.rs`).

use std::io::Read;
use std::path::Path;

use crate::DataError;
use crate::records::{Header, Records, open};

/// The columns of a target list, in order.
const TARGET_COLUMNS: [&str; 3] = ["x", "y", "z"];

/// Reads target points from a CSV file with columns `x,y,z` (mm; header
/// required, `#` comments, other columns ignored); see
/// [`read_targets_from`].
///
/// # Example
/// ```
/// let dir = std::env::temp_dir().join(format!("tricept-targets-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("targets.csv");
/// std::fs::write(&path, "x,y,z\n0,0,1000\n50,-25,1010.5\n").unwrap();
/// let points = tricept_data::targets::read_targets(&path).unwrap();
/// assert_eq!(points, vec![[0.0, 0.0, 1000.0], [50.0, -25.0, 1010.5]]);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn read_targets(path: &Path) -> Result<Vec<[f64; 3]>, DataError> {
    let (f, file) = open(path)?;
    read_targets_from(f, &file)
}

/// Reads target points `x,y,z` (mm) from any reader; `file` names it in
/// errors. The rules are those of the measured-data reader: a header line
/// is required, columns may come in any order, other columns are ignored,
/// `#` lines are comments, blank lines are skipped, a byte-order mark at the
/// start is dropped, and every field read must be a finite number. Every
/// error names the file and the line (and the column).
///
/// # Example
/// ```
/// let csv = "# targets\nid,z,y,x\n1,1000,0,0\n2,1010.5,-25,50\n";
/// let points = tricept_data::targets::read_targets_from(csv.as_bytes(), "targets.csv").unwrap();
/// assert_eq!(points, vec![[0.0, 0.0, 1000.0], [50.0, -25.0, 1010.5]]);
///
/// let err = tricept_data::targets::read_targets_from("x,y,z\n0,0,abc\n".as_bytes(), "t.csv").unwrap_err();
/// assert_eq!(err.to_string(), "t.csv: line 2, column `z`: not a number (got `abc`)");
/// ```
pub fn read_targets_from<R: Read>(reader: R, file: &str) -> Result<Vec<[f64; 3]>, DataError> {
    let points = NumericRows::new(reader, file, TARGET_COLUMNS)?
        .map(|row| row.map(|(_, p)| p))
        .collect::<Result<Vec<_>, _>>()?;
    if points.is_empty() {
        return Err(DataError::NoRows { file: file.into() });
    }
    Ok(points)
}

/// The rows of a CSV source as the numbers of `N` named columns, streamed
/// one row at a time with its 1-based file line (for batch inputs that need
/// not fit in memory). The format rules and messages are those of
/// [`read_targets_from`]; an empty file is an error, a header without rows
/// yields nothing.
///
/// # Example
/// ```
/// use tricept_data::targets::NumericRows;
/// let csv = "\u{feff}q2,q1,q3\n# a comment\n700,701,702.5\n";
/// let rows: Vec<_> = NumericRows::new(csv.as_bytes(), "legs.csv", ["q1", "q2", "q3"])
///     .unwrap()
///     .collect::<Result<_, _>>()
///     .unwrap();
/// assert_eq!(rows, vec![(3, [701.0, 700.0, 702.5])]);
/// let bad = NumericRows::new("q1;q2;q3\n1;2;3\n".as_bytes(), "legs.csv", ["q1", "q2", "q3"]);
/// assert!(bad.is_err());
/// ```
pub struct NumericRows<'f, R, const N: usize> {
    records: Records<'f, R>,
    header: Header,
    columns: [usize; N],
}

impl<'f, R: Read, const N: usize> NumericRows<'f, R, N> {
    /// Reads the header of `reader` (`file` names it in errors) and locates
    /// `columns`.
    pub fn new(
        reader: R,
        file: &'f str,
        columns: [&str; N],
    ) -> Result<NumericRows<'f, R, N>, DataError> {
        let mut records = Records::new(reader, file);
        let header = Header::read(&mut records, &columns.join(","))?;
        let located = header.locate(columns, &columns)?;
        Ok(NumericRows {
            records,
            header,
            columns: located,
        })
    }
}

impl<R: Read, const N: usize> Iterator for NumericRows<'_, R, N> {
    type Item = Result<(u64, [f64; N]), DataError>;

    fn next(&mut self) -> Option<Self::Item> {
        let record = match self.records.next()? {
            Ok(r) => r,
            Err(e) => return Some(Err(e)),
        };
        let row = (|| {
            self.header.check(&record)?;
            let mut v = [0.0; N];
            for (x, &idx) in v.iter_mut().zip(&self.columns) {
                *x = self.header.number(&record, idx)?;
            }
            Ok((record.line, v))
        })();
        Some(row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &[u8]) -> String {
        read_targets_from(text, "t.csv").unwrap_err().to_string()
    }

    #[test]
    fn reads_points_with_comments_blank_lines_and_extra_columns() {
        let p = read_targets_from(
            &b"# a\n\nname,x,y,z\n\nA, 1, 2, 3 \n# b\nB,4,5,6\n"[..],
            "t.csv",
        )
        .unwrap();
        assert_eq!(p, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let cases: [(&[u8], &str); 12] = [
            (b"", "t.csv: empty file (expected a header line with x,y,z)"),
            (b"# c\nx,y,z\n\n", "t.csv: header only, no data rows"),
            (
                b"x,y,Z\n1,2,3\n",
                "t.csv: line 1: missing required column `z`, found `Z` (misspelt?)",
            ),
            (b"x,y\n1,2\n", "t.csv: line 1: missing required column `z`"),
            (
                b"x,y,x,z\n",
                "t.csv: line 1: column `x` appears twice in the header",
            ),
            (
                b"x,y,z\n1,2,3\n\n# c\n1,2\n",
                "t.csv: line 5: expected 3 fields like the header, found 2",
            ),
            (
                b"x,y,z\n1,2,abc\n",
                "t.csv: line 2, column `z`: not a number (got `abc`)",
            ),
            (
                b"x,y,z\n1,inf,3\n",
                "t.csv: line 2, column `y`: not a finite number (got `inf`)",
            ),
            (
                b"x,y,z\n,2,3\n",
                "t.csv: line 2, column `x`: empty field (got ``)",
            ),
            (b"x,y,z\n1,2,\xff\n", "t.csv: line 2: not valid UTF-8 text"),
            (
                b"x;y;z\n1.5;2;3\n",
                "t.csv: line 1: the file uses `;` as separator; tricept needs commas (`,`) between fields",
            ),
            (
                b"x,y,z\n1.5,2.5,3,5\n",
                "t.csv: line 2: expected 3 fields like the header, found 4: `3,5` looks like a \
                 number with a decimal comma; decimal commas are not accepted, use a point (`3.5`)",
            ),
        ];
        for (text, message) in cases {
            assert_eq!(error(text), message, "{}", String::from_utf8_lossy(text));
        }
    }

    #[test]
    fn a_spreadsheet_export_with_semicolons_and_decimal_commas_is_named() {
        let e = error("\u{feff}x;y;z\n12,5;0;1000\n".as_bytes());
        assert!(
            e.starts_with(
                "t.csv: line 2: the file uses `;` as separator and decimal commas (`12,5`)"
            ),
            "{e}"
        );
        assert!(e.contains("use a point (`12.5`)"), "{e}");
    }

    #[test]
    fn a_byte_order_mark_is_accepted() {
        let p = read_targets_from("\u{feff}x,y,z\n1,2,3\n".as_bytes(), "t.csv").unwrap();
        assert_eq!(p, vec![[1.0, 2.0, 3.0]]);
    }

    #[test]
    fn a_missing_file_is_named() {
        let e = read_targets(Path::new("/nonexistent/targets.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/targets.csv: "), "{e}");
    }
}
