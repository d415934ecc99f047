//! The error type of the crate: [`DataError`], one variant per problem a
//! measured-data or target file can have. Every message names the file and,
//! where there is one, the line and the column, so that the CLI can print it
//! as the one line a user needs to fix the file.

use thiserror::Error;

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
    #[error("{file}: empty file (expected a header line with {expected})")]
    Empty {
        /// File name.
        file: String,
        /// The columns the header should have, e.g. `q1,q2,q3,phi,theta,s`.
        expected: String,
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
    /// Fields separated by `;` instead of `,` (a CSV export with a
    /// semicolon list separator).
    #[error(
        "{file}: line {line}: the file uses `;` as separator; tricept needs commas (`,`) between fields"
    )]
    SemicolonSeparated {
        /// File name.
        file: String,
        /// The first line found separated by `;` (the header, or a row of a
        /// file whose header uses commas).
        line: u64,
    },
    /// Fields separated by `;` and numbers written with a decimal comma: a
    /// spreadsheet's CSV export in a locale such as German
    /// (`q1;q2;q3;phi;theta;s`, then `796,5;796,5;...`).
    #[error(
        "{file}: line {line}: the file uses `;` as separator and decimal commas (`{value}`), as spreadsheets export CSV in some locales; tricept needs commas (`,`) between fields, and decimal commas are not accepted: use a point (`{}`)",
        .value.replace(',', ".")
    )]
    SemicolonsAndDecimalCommas {
        /// File name.
        file: String,
        /// The first row with a decimal comma.
        line: u64,
        /// The first number with a decimal comma, e.g. `796,5`.
        value: String,
    },
    /// A comma-separated row with more fields than the header, where fields
    /// read as the two halves of a number written with a decimal comma
    /// (`0,5` for `0.5`).
    #[error(
        "{file}: line {line}: expected {expected} fields like the header, found {found}: {}",
        decimal_comma_advice(.value)
    )]
    DecimalComma {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Fields in the header.
        expected: usize,
        /// Fields in this row.
        found: usize,
        /// The pair of fields that reads as one number with a decimal comma
        /// (e.g. `0,5`), when only one pair of the row does.
        value: Option<String>,
    },
    /// A JSON file (the features of a touch-off campaign) that does not parse.
    #[error("{file}: line {line}, column {column}: {message}")]
    Json {
        /// File name.
        file: String,
        /// Line of the problem.
        line: u64,
        /// Column of the problem.
        column: u64,
        /// What is wrong.
        message: String,
    },
    /// A file that parses but describes something impossible.
    #[error("{file}: {message}")]
    Invalid {
        /// File name.
        file: String,
        /// What is wrong.
        message: String,
    },
}

/// The end of the [`DataError::DecimalComma`] message.
fn decimal_comma_advice(value: &Option<String>) -> String {
    match value {
        Some(v) => format!(
            "`{v}` looks like a number with a decimal comma; decimal commas are not accepted, use a point (`{}`)",
            v.replace(',', ".")
        ),
        None => "is a number written with a decimal comma (`0,5` for `0.5`)? \
                 Decimal commas are not accepted, use a point"
            .into(),
    }
}
