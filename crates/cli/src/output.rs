//! Printing results: aligned text for people, JSON for programs, CSV for
//! batches; every path safe on a closed stdout.
//!
//! When stdout is closed (`tricept identify ... | head -1`), printing stops
//! quietly: the first failed write marks stdout closed, later writes are
//! skipped, and the command finishes its other work (a machine file to
//! write, its exit code) as if it had printed everything. Nothing here
//! panics on a write error, on stdout or stderr.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use serde_json::{Map, Value};

static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Whether a write to stdout has failed (a closed pipe).
pub fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}

/// Writes `args` and a newline to stdout unless it is closed.
pub fn write_line(args: std::fmt::Arguments<'_>) {
    if stdout_closed() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if out
        .write_fmt(args)
        .and_then(|_| out.write_all(b"\n"))
        .is_err()
    {
        STDOUT_CLOSED.store(true, Ordering::Relaxed);
    }
}

/// Writes `text` as it is (a report that ends its own lines).
pub fn write_text(text: &str) {
    if stdout_closed() {
        return;
    }
    if std::io::stdout().lock().write_all(text.as_bytes()).is_err() {
        STDOUT_CLOSED.store(true, Ordering::Relaxed);
    }
}

/// A line on stderr; a failed write is ignored (there is nowhere left to
/// report it).
pub fn write_err_line(args: std::fmt::Arguments<'_>) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_fmt(args).and_then(|_| err.write_all(b"\n"));
}

/// Stdout as a [`Write`] for bulk output (CSV): a write to a closed stdout
/// marks it closed and reports success, so that a writer stops caring; a
/// loop producing the output should check [`stdout_closed`] to stop early.
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if !stdout_closed() && std::io::stdout().lock().write_all(buf).is_err() {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if !stdout_closed() && std::io::stdout().lock().flush().is_err() {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
        }
        Ok(())
    }
}

/// One field of a record: its key (the JSON key and CSV column), value and
/// unit for the text output (empty when it has none).
pub type Field = (&'static str, Value, &'static str);

/// Prints `fields` as a JSON object (in order) or as aligned
/// `key = value unit` lines.
pub fn print_record(json: bool, fields: &[Field]) {
    if json {
        let map: Map<String, Value> = fields
            .iter()
            .map(|(k, v, _)| (k.to_string(), v.clone()))
            .collect();
        outln!("{}", Value::Object(map));
    } else {
        let width = fields.iter().map(|(k, _, _)| k.len()).max().unwrap_or(0);
        for (k, v, unit) in fields {
            let text = match v {
                Value::Number(n) => match (n.as_u64(), n.as_f64()) {
                    (Some(i), _) => i.to_string(),
                    (None, Some(x)) => format!("{x:.9}"),
                    _ => n.to_string(),
                },
                Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            if unit.is_empty() {
                outln!("{k:>width$} = {text}");
            } else {
                outln!("{k:>width$} = {text} {unit}");
            }
        }
    }
}
