//! Whether a check history and an export belong to the calibration of the
//! machine file: each names it by its digest (`calibration_digest`, the
//! SHA-256 of the record's identifying fields:
//! `MachineDescription::calibration_digest` of `tricept-kinematics`).
//! Another digest is refused, naming the file (and the check); no digest
//! (a line or summary written before they named one) is accepted, and the
//! page says that it could not be told.

use serde_json::Value;

use crate::error::ReportError;

/// The key a history line and an export summary name their calibration by.
pub const DIGEST_KEY: &str = "calibration_digest";

/// Checks that every line of the history `file` (its checks as JSON, in
/// file order) is a check of the calibration `digest`; returns the checks
/// (0-based) that name none.
///
/// # Example
/// ```
/// use serde_json::json;
/// use tricept_report::identity::check_history;
/// let lines = [json!({"verdict": "unchanged", "calibration_digest": "ab"}), json!({"verdict": "unchanged"})];
/// assert_eq!(check_history("ab", "h.jsonl", &lines).unwrap(), vec![1]);
/// let e = check_history("cd", "h.jsonl", &lines).unwrap_err().to_string();
/// assert!(e.starts_with("h.jsonl: check 1 is a check of another calibration"), "{e}");
/// ```
pub fn check_history(digest: &str, file: &str, lines: &[Value]) -> Result<Vec<usize>, ReportError> {
    let mut unnamed = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        match line.get(DIGEST_KEY).and_then(Value::as_str) {
            None => unnamed.push(k),
            Some(found) if found == digest => {}
            Some(found) => {
                return Err(ReportError::HistoryOfAnotherCalibration {
                    file: file.to_string(),
                    check: k + 1,
                    found: found.to_string(),
                    expected: digest.to_string(),
                });
            }
        }
    }
    Ok(unnamed)
}

/// Checks that the export summary `file` is an export of the calibration
/// `digest`; `Ok(false)` when it names none.
///
/// # Example
/// ```
/// use serde_json::json;
/// use tricept_report::identity::check_export;
/// assert_eq!(check_export("ab", "export.json", &json!({"calibration_digest": "ab"})), Ok(true));
/// assert_eq!(check_export("ab", "export.json", &json!({})), Ok(false));
/// assert!(check_export("cd", "export.json", &json!({"calibration_digest": "ab"})).is_err());
/// ```
pub fn check_export(digest: &str, file: &str, summary: &Value) -> Result<bool, ReportError> {
    match summary.get(DIGEST_KEY).and_then(Value::as_str) {
        None => Ok(false),
        Some(found) if found == digest => Ok(true),
        Some(found) => Err(ReportError::ExportOfAnotherCalibration {
            file: file.to_string(),
            found: found.to_string(),
            expected: digest.to_string(),
        }),
    }
}
