//! The `format_version` of every JSON output a workflow prints (`--json`
//! of every verb, and the same text from the Python binding): one version
//! for the outputs, bumped by the rule of CHANGELOG.md ("Versions"), and
//! the one way it is put first into an output.

use serde_json::{Map, Value};

/// The format version of the JSON outputs of this tricept (the
/// `format_version` key each output object starts with; `tricept schema
/// NAME` prints the JSON Schema of each).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{OUTPUT_FORMAT_VERSION, serde_json, versioned_json};
/// let text = versioned_json(r#"{"exit_code":0}"#).unwrap();
/// let json: serde_json::Value = serde_json::from_str(&text).unwrap();
/// assert_eq!(json["format_version"], OUTPUT_FORMAT_VERSION);
/// ```
pub const OUTPUT_FORMAT_VERSION: u32 = 1;

/// `text` (one JSON object, or one per line) with `format_version`
/// ([`OUTPUT_FORMAT_VERSION`]) as the first key of each object that does
/// not carry its own (a machine file's), one compact object per line;
/// `None` when `text` is not JSON objects.
///
/// # Example
/// ```
/// use tricept_ident::advanced::versioned_json;
/// assert_eq!(
///     versioned_json(r#"{"x": 1.5}"#).unwrap(),
///     "{\"format_version\":1,\"x\":1.5}\n"
/// );
/// assert_eq!(
///     versioned_json("{\"a\":1}\n{\"format_version\":1,\"b\":2}\n").unwrap(),
///     "{\"format_version\":1,\"a\":1}\n{\"format_version\":1,\"b\":2}\n"
/// );
/// assert!(versioned_json("not json").is_none());
/// ```
pub fn versioned_json(text: &str) -> Option<String> {
    let objects: Vec<Value> = match serde_json::from_str::<Value>(text) {
        Ok(v) => vec![v],
        Err(_) => text
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(serde_json::from_str::<Value>)
            .collect::<Result<_, _>>()
            .ok()?,
    };
    let mut out = String::with_capacity(text.len() + 32 * objects.len());
    for v in objects {
        let Value::Object(map) = v else {
            return None;
        };
        let v = if map.contains_key("format_version") {
            Value::Object(map)
        } else {
            let mut versioned = Map::with_capacity(map.len() + 1);
            versioned.insert("format_version".into(), OUTPUT_FORMAT_VERSION.into());
            versioned.extend(map);
            Value::Object(versioned)
        };
        out.push_str(&v.to_string());
        out.push('\n');
    }
    Some(out)
}
