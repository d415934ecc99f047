//! Tables of plausible ranges: a physical quantity's smallest and largest
//! plausible value with its unit and the reason, and overrides of the
//! ranges from a JSON object `{"key": [min, max]}`. The diagnosis judges
//! its fitted effects by one (`tricept-diagnose`, `--plausibility`), the
//! fused identification its head, tool and instrument estimates by
//! another (`tricept_engine::fusion`, `identify --plausibility`).
//!
//! A quantity is implausible when its 3-sigma interval misses the range
//! ([`Range::admits`]): an estimate that only its noise makes implausible
//! is not refused.

use std::collections::BTreeMap;

use serde::Serialize;

/// A physical range with its reason.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Range {
    /// Smallest plausible value.
    pub min: f64,
    /// Largest plausible value.
    pub max: f64,
    /// Unit.
    pub unit: &'static str,
    /// Why (material, tolerance, definition).
    pub why: String,
}

impl Range {
    /// Whether an estimate `value` with standard deviation `sd` is
    /// compatible with the range: its 3-sigma interval meets it (a
    /// non-finite value never is).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::plausibility::Range;
let r = Range { min: -3.0, max: 3.0, unit: "mm", why: "a tool length".into() };
assert!(r.admits(2.5, 0.0) && r.admits(3.5, 0.2));
assert!(!r.admits(20.0, 0.01) && !r.admits(f64::NAN, 0.0));
```
"#
    )]
    pub fn admits(&self, value: f64, sd: f64) -> bool {
        let sd = if sd.is_finite() { sd.abs() } else { 0.0 };
        value.is_finite() && value + 3.0 * sd >= self.min && value - 3.0 * sd <= self.max
    }
}

/// Inserts the range `[min, max]` of `key` (in `unit`, for the reason
/// `why`) into `table`.
///
/// # Example
/// ```
/// use std::collections::BTreeMap;
/// let mut t = BTreeMap::new();
/// tricept_model::plausibility::insert_range(&mut t, "tool_length_mm", -3.0, 3.0, "mm", "10 typical sizes");
/// assert_eq!(t["tool_length_mm"].unit, "mm");
/// ```
pub fn insert_range(
    table: &mut BTreeMap<String, Range>,
    key: &str,
    min: f64,
    max: f64,
    unit: &'static str,
    why: impl Into<String>,
) {
    table.insert(
        key.to_string(),
        Range {
            min,
            max,
            unit,
            why: why.into(),
        },
    );
}

/// Why an override file was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlausibilityError {
    /// Not a JSON object of `key: [min, max]`.
    #[error("plausibility overrides: {0}")]
    Format(String),
    /// A key that is not in the table.
    #[error("plausibility overrides: unknown quantity `{key}` (known: {known})")]
    UnknownKey {
        /// The key.
        key: String,
        /// The keys of the table.
        known: String,
    },
}

/// Overrides the ranges of `table` from a JSON object of `key: [min,
/// max]`; every key must be in the table, every range ordered and finite.
/// An overridden range's reason becomes "user override".
///
/// # Example
/// ```
/// use std::collections::BTreeMap;
/// use tricept_model::plausibility::{Range, override_ranges};
/// let mut t = BTreeMap::new();
/// t.insert("tool_length_mm".to_string(), Range { min: -3.0, max: 3.0, unit: "mm", why: "".into() });
/// override_ranges(&mut t, r#"{"tool_length_mm": [-25, 25]}"#).unwrap();
/// assert_eq!(t["tool_length_mm"].max, 25.0);
/// assert!(override_ranges(&mut t, r#"{"tool_mm": [0, 1]}"#).is_err());
/// assert!(override_ranges(&mut t, r#"{"tool_length_mm": [1, 0]}"#).is_err());
/// ```
pub fn override_ranges(
    table: &mut BTreeMap<String, Range>,
    json: &str,
) -> Result<(), PlausibilityError> {
    let v: BTreeMap<String, [f64; 2]> =
        serde_json::from_str(json).map_err(|e| PlausibilityError::Format(e.to_string()))?;
    for (key, [min, max]) in v {
        if !(min.is_finite() && max.is_finite() && min <= max) {
            return Err(PlausibilityError::Format(format!(
                "`{key}`: [{min}, {max}] is not a range"
            )));
        }
        let known = table.keys().cloned().collect::<Vec<_>>().join(", ");
        let Some(r) = table.get_mut(&key) else {
            return Err(PlausibilityError::UnknownKey { key, known });
        };
        r.min = min;
        r.max = max;
        r.why = "user override".into();
    }
    Ok(())
}

/// `v` to three significant digits, for messages.
///
/// # Example
/// ```
/// assert_eq!(tricept_model::plausibility::round3(20.0314), "20.0");
/// assert_eq!(tricept_model::plausibility::round3(0.000412345), "0.000412");
/// ```
pub fn round3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}
