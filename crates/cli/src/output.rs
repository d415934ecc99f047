//! Printing results: aligned text for people, JSON for programs.

use serde_json::{Map, Value};

/// Prints `pairs` as a JSON object (in order) or as `key = value` lines.
pub fn print_record(json: bool, pairs: &[(&str, Value)]) {
    if json {
        let map: Map<String, Value> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        outln!("{}", Value::Object(map));
    } else {
        let width = pairs.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
        for (k, v) in pairs {
            let text = match v {
                Value::Number(n) => match n.as_f64() {
                    Some(x) => format!("{x:.9}"),
                    None => n.to_string(),
                },
                Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            outln!("{k:>width$} = {text}");
        }
    }
}
