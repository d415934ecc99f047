//! Printing results: aligned text for people, JSON for programs, CSV for
//! batches; every path safe on a closed stdout, and loud on a failed one.
//!
//! Two failures of stdout are told apart:
//!
//! - **a closed pipe** (`tricept identify ... | head -1`): the reader has
//!   what it wanted. Printing stops quietly: the first failed write marks
//!   stdout closed, later writes are skipped, and the command finishes its
//!   other work (a machine file to write, its exit code) as if it had
//!   printed everything;
//! - **any other error** (a full disk, an I/O error, `/dev/full`): the output
//!   is incomplete, and a controller fed it would get a silently short
//!   program. Printing stops the same way, the error is kept, and
//!   [`finish`] turns it into exit code 1 with a message.
//!
//! Nothing here panics on a write error, on stdout or stderr.

use std::io::Write;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);
static STDOUT_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// Whether a write to stdout has failed (a closed pipe or an error): loops
/// producing output check this to stop early.
pub fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}

/// Records a failed write to stdout: a broken pipe only closes it, any
/// other error is kept for [`finish`].
fn failed(e: &std::io::Error) {
    STDOUT_CLOSED.store(true, Ordering::Relaxed);
    if e.kind() != std::io::ErrorKind::BrokenPipe
        && let Ok(mut slot) = STDOUT_ERROR.lock()
        && slot.is_none()
    {
        *slot = Some(e.to_string());
    }
}

/// Flushes stdout and returns the first write error that was not a closed
/// pipe (`None` when everything printed, or the reader went away).
pub fn finish() -> Option<String> {
    if !stdout_closed()
        && let Err(e) = std::io::stdout().lock().flush()
    {
        failed(&e);
    }
    STDOUT_ERROR.lock().ok().and_then(|slot| slot.clone())
}

/// Writes `args` and a newline to stdout unless it is closed (control
/// characters other than line ends and tabs escaped: [`inert`]).
pub fn write_line(args: std::fmt::Arguments<'_>) {
    write_text(&format!("{args}\n"));
}

/// Writes `text` (a report that ends its own lines) with every control
/// character but `\n` and `\t` escaped ([`inert`]): a path or a name
/// the report repeats cannot move the cursor or recolour the terminal.
pub fn write_text(text: &str) {
    if stdout_closed() {
        return;
    }
    if let Err(e) = std::io::stdout().lock().write_all(inert(text).as_bytes()) {
        failed(&e);
    }
}

/// Writes a verb's `--json` output (one JSON object, or one per line)
/// with its `format_version` first
/// (`tricept_ident::advanced::versioned_json`, as the Python binding's
/// `to_json`); a text that is not JSON objects is written as it is.
pub fn write_json(text: impl std::fmt::Display) {
    let text = text.to_string();
    match tricept_ident::advanced::versioned_json(&text) {
        Some(versioned) => write_text(&versioned),
        None => write_line(format_args!("{text}")),
    }
}

/// Writes a `--json` output that is an array as one object per line (as
/// `tricept effects --json`), anything else as [`write_json`] does.
pub fn write_json_lines(v: &tricept_ident::advanced::serde_json::Value) {
    match v.as_array() {
        Some(items) => write_json(items.iter().map(|o| format!("{o}\n")).collect::<String>()),
        None => write_json(v),
    }
}

/// `text` with every control character but `\n` and `\t` escaped (as
/// `\u{1b}`); borrowed when there is none (the usual case).
fn inert(text: &str) -> std::borrow::Cow<'_, str> {
    let active = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.chars().any(active) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        if active(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// A line on stderr, made one bounded line ([`tricept_ident::advanced::files::one_line`]:
/// repeated input cut, every control character, a newline too, escaped);
/// a failed write is ignored (there is nowhere left to report it).
pub fn write_err_line(args: std::fmt::Arguments<'_>) {
    let line = tricept_ident::advanced::files::one_line(&args.to_string());
    let mut err = std::io::stderr().lock();
    let _ = err
        .write_all(line.as_bytes())
        .and_then(|_| err.write_all(b"\n"));
}

/// Each of `warnings` on stderr as `warning: ...`.
pub fn warn_all(warnings: &[String]) {
    for w in warnings {
        errln!("warning: {w}");
    }
}

/// Stdout as a [`Write`] for bulk output (CSV): a failed write marks stdout
/// closed (keeping an error that is not a closed pipe for [`finish`]) and
/// reports success, so that a writer stops caring; a loop producing the
/// output should check [`stdout_closed`] to stop early.
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if !stdout_closed()
            && let Err(e) = std::io::stdout().lock().write_all(buf)
        {
            failed(&e);
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if !stdout_closed()
            && let Err(e) = std::io::stdout().lock().flush()
        {
            failed(&e);
        }
        Ok(())
    }
}
