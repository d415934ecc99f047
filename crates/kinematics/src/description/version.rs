//! Format versions of the files tricept writes: the `format_version` key
//! (an integer) of a machine file, and the rules every versioned file
//! shares (a batch's prior, a check history's lines, an export's summary).
//!
//! A file without the key was written before formats had versions and is
//! version 1 ([`UNVERSIONED`]): it reads as it always did. A file whose
//! version is newer than the reader knows is refused before anything else
//! is read of it ([`newer_format`]), with a message that says so: its other
//! keys may mean what this reader cannot know, and a guess would be a silent
//! misreading. What bumps a version is in `CHANGELOG.md` ("Versions").

use serde::Deserialize;

/// The machine file format this tricept writes (and the newest it reads).
pub const FORMAT_VERSION: u32 = 1;

/// The version of a file without `format_version`: every file written
/// before the key existed (the same format; its readers never changed).
pub const UNVERSIONED: u32 = 1;

/// The key every versioned file carries.
pub const FORMAT_VERSION_KEY: &str = "format_version";

/// serde's default of the key: a file without it is [`UNVERSIONED`].
pub(crate) fn unversioned() -> u32 {
    UNVERSIONED
}

/// The version a JSON text declares, read on its own: the other keys are
/// skipped unread, so that a newer file is named as such rather than
/// refused for a key this reader does not know. `None` when the text is not
/// a JSON object, has no integer `format_version` (the full parse says what
/// is wrong), or has none.
fn declared(text: &str) -> Option<u64> {
    #[derive(Deserialize)]
    struct Peek {
        #[serde(default)]
        format_version: Option<serde_json::Value>,
    }
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let peek: Peek = serde_json::from_str(text).ok()?;
    peek.format_version?.as_u64()
}

/// A file of a format version newer than this tricept reads: what to tell
/// the user.
///
/// # Example
/// ```
/// use tricept_kinematics::description::{NewerFormat, newer_format};
/// let e: NewerFormat = newer_format(r#"{"format_version": 7, "new_key": 1}"#, "machine file", 1).unwrap();
/// assert_eq!(e.found, 7);
/// assert!(e.to_string().contains("format_version 7"), "{e}");
/// assert!(newer_format(r#"{"format_version": 1}"#, "machine file", 1).is_none());
/// assert!(newer_format(r#"{"name": "no version: 1"}"#, "machine file", 1).is_none());
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "format_version {found}: this {what} was written by a newer tricept; this tricept ({tool}) reads {what}s up to format version {supported}: read it with the tricept that wrote it or a newer one"
)]
pub struct NewerFormat {
    /// The version the file declares.
    pub found: u64,
    /// The newest version this tricept reads.
    pub supported: u32,
    /// The kind of file (`machine file`, `prior file`, ...).
    pub what: &'static str,
    /// This tricept's version.
    pub tool: &'static str,
}

/// [`NewerFormat`] when the JSON `text` declares a `format_version` above
/// `supported`, read before the rest of the text.
pub fn newer_format(text: &str, what: &'static str, supported: u32) -> Option<NewerFormat> {
    declared(text)
        .filter(|&v| v > u64::from(supported))
        .map(|found| NewerFormat {
            found,
            supported,
            what,
            tool: env!("CARGO_PKG_VERSION"),
        })
}

/// [`NewerFormat`] when an already parsed `version` is above `supported`.
pub fn check_version(version: u32, what: &'static str, supported: u32) -> Result<(), NewerFormat> {
    if version <= supported {
        return Ok(());
    }
    Err(NewerFormat {
        found: version.into(),
        supported,
        what,
        tool: env!("CARGO_PKG_VERSION"),
    })
}

/// Whether a field absent from a seal written before formats had versions
/// is the key as such a file reads: `format_version` (at any depth) of
/// [`UNVERSIONED`]. An old seal does not name it, and a file without the
/// key is that version, so the key read back (or written back, as this
/// reader writes it) is no edit.
pub(crate) fn is_unversioned_leaf(path: &str, canonical_text: &str) -> bool {
    let last = path.rsplit('.').next().unwrap_or(path);
    last == FORMAT_VERSION_KEY && canonical_text == format!("{:?}", f64::from(UNVERSIONED))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_declared_integer_above_the_supported_version_is_newer() {
        for (text, newer) in [
            (r#"{"format_version": 2}"#, Some(2)),
            (
                "\u{feff}{\"format_version\": 9, \"x\": [1, {\"y\": 2}]}",
                Some(9),
            ),
            (r#"{"format_version": 1}"#, None),
            (r#"{"format_version": 0}"#, None),
            (r#"{"format_version": "2"}"#, None),
            (r#"{"format_version": 2.5}"#, None),
            (r#"{"name": "x"}"#, None),
            ("[1, 2]", None),
            ("not json", None),
        ] {
            assert_eq!(
                newer_format(text, "machine file", 1).map(|e| e.found),
                newer,
                "{text}"
            );
        }
        assert!(check_version(1, "machine file", 1).is_ok());
        let e = check_version(2, "prior file", 1).unwrap_err();
        assert!(
            e.to_string().contains("prior files up to format version 1"),
            "{e}"
        );
    }

    #[test]
    fn the_unversioned_leaf_is_version_1_at_any_depth_and_nothing_else() {
        assert!(is_unversioned_leaf("format_version", "1.0"));
        assert!(is_unversioned_leaf(
            "calibration.nominal.format_version",
            "1.0"
        ));
        assert!(!is_unversioned_leaf("format_version", "2.0"));
        assert!(!is_unversioned_leaf("calibration.format_versions", "1.0"));
        assert!(!is_unversioned_leaf("leg_offsets_mm", "1.0"));
    }
}
