//! Section 7: the sources: each JSON source of the page with what it is
//! and where it came from, and the JSON itself, in a `<script
//! type="application/json" id="json-<source>">` block (data, never run),
//! which every value shown names by `data-src` and `data-path`.

use serde_json::Value;

use crate::html::{p, section as wrap, table};
use crate::json::escape;
use crate::sources::Sources;

/// The section and the JSON blocks.
pub fn section(sources: &Sources, verdict: &Value) -> String {
    let mut s = p(
        "Every value on this page is an element naming its source and its place in that source's JSON: <code>data-src</code> (the source below) and <code>data-path</code> (a JSON pointer, RFC 6901). Numbers are rounded for reading, never converted: each is shown in the unit its key names. Each source's JSON is in this page, in a <code>&lt;script type=\"application/json\" id=\"json-SOURCE\"&gt;</code> block (data, not a program). The verdict's rule: docs/report.md.",
    );
    let mut rows: Vec<Vec<String>> = sources
        .all()
        .into_iter()
        .map(|src| {
            vec![
                format!("<code>{}</code>", escape(&src.id)),
                escape(&src.what),
                src.file
                    .as_deref()
                    .map_or("-".into(), |f| format!("<code>{}</code>", escape(f))),
            ]
        })
        .collect();
    rows.push(vec![
        "<code>verdict</code>".into(),
        "the verdict of this page and the values it read (docs/report.md)".into(),
        "-".into(),
    ]);
    s.push_str(&table(&["source", "what", "file"], &[], &rows));
    for src in sources.all() {
        s.push_str(&block(&src.id, &src.json));
    }
    s.push_str(&block("verdict", verdict));
    wrap("sources", "7. Sources", &s)
}

/// A JSON block: the JSON text with `<` written `\u003c`, so that no text
/// of it can end the block.
fn block(id: &str, json: &Value) -> String {
    let text = serde_json::to_string(json)
        .unwrap_or_default()
        .replace('<', "\\u003c");
    format!(
        "<script type=\"application/json\" id=\"json-{}\">{text}</script>\n",
        escape(id)
    )
}
