//! Input as messages repeat it: bounded and inert.
//!
//! A message names what is wrong, and often repeats it: a field of a CSV
//! file, a JSON key, a path. Repeated raw, a 50 MB JSON key becomes a 50 MB
//! line on stderr, and a path holding a newline or an escape sequence
//! splits the line or makes the terminal obey it. Every message the
//! project prints goes through one of these:
//!
//! - [`shown`]: a field, cut to [`SHOWN_CHARS`] characters with the count
//!   of the rest, control characters escaped;
//! - [`shown_path`]: a path, cut to [`SHOWN_PATH_CHARS`] the same way;
//! - [`one_line`]: a whole message: every quoted span (between backticks
//!   or double quotes, as serde_json quotes a key or a string) longer than [`MAX_QUOTED_CHARS`] cut, every control character (a
//!   newline too) escaped, and a line still longer than
//!   [`MAX_MESSAGE_CHARS`] cut in the middle, so that its start (what)
//!   and its end (where: a line and a column) both stay.
//!
//! Each is idempotent: a message already bounded passes unchanged.

use std::path::Path;

/// The longest field a message repeats, in characters.
pub const SHOWN_CHARS: usize = 80;

/// The longest path a message repeats, in characters.
pub const SHOWN_PATH_CHARS: usize = 300;

/// The longest span between backticks or double quotes [`one_line`] keeps
/// whole, in characters (a longer one keeps its first
/// [`MAX_QUOTED_CHARS`] / 2).
pub const MAX_QUOTED_CHARS: usize = 400;

/// The longest message [`one_line`] keeps whole, in characters.
pub const MAX_MESSAGE_CHARS: usize = 2000;

/// A field as messages show it: control characters escaped, cut to
/// [`SHOWN_CHARS`] characters with the length of the rest.
///
/// # Example
/// ```
/// let long = "x".repeat(100);
/// assert_eq!(tricept_data::message::shown(&long), format!("{}… (20 more bytes)", "x".repeat(80)));
/// assert_eq!(tricept_data::message::shown("a\nb\u{1b}[31m"), "a\\nb\\u{1b}[31m");
/// ```
pub fn shown(field: &str) -> String {
    cut(field, SHOWN_CHARS)
}

/// A path as messages show it: [`shown`] with room for
/// [`SHOWN_PATH_CHARS`] characters (a path that is not UTF-8 is shown
/// with replacement characters).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use std::path::Path;
assert_eq!(tricept_data::message::shown_path(Path::new("a\nb.csv")), "a\\nb.csv");
```
"#
)]
pub fn shown_path(path: &Path) -> String {
    cut(&path.to_string_lossy(), SHOWN_PATH_CHARS)
}

/// `text` with control characters escaped, cut after `keep` characters
/// with the number of bytes left out.
fn cut(text: &str, keep: usize) -> String {
    let mut out = String::with_capacity(text.len().min(keep.saturating_mul(4)));
    for (count, (i, c)) in text.char_indices().enumerate() {
        if count == keep {
            out.push_str(&format!("… ({} more bytes)", text.len() - i));
            return out;
        }
        push_inert(&mut out, c);
    }
    out
}

/// Pushes `c`, escaped when a terminal would act on it: control characters
/// (`\n`, `\r`, `\u{1b}`, ...) and the bidirectional overrides that
/// reorder what is shown.
fn push_inert(out: &mut String, c: char) {
    let reorders = matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    if c.is_control() || reorders {
        out.extend(c.escape_default());
    } else {
        out.push(c);
    }
}

/// A message as one bounded line (see the module docs): quoted spans cut,
/// control characters escaped, the whole cut in the middle past
/// [`MAX_MESSAGE_CHARS`].
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
let key = "k".repeat(1_000_000);
let m = tricept_data::message::one_line(&format!("unknown field `{key}` at line 1 column 1000014\nnext"));
assert!(m.len() < 1000, "{}", m.len());
assert!(m.starts_with("unknown field `kkk"));
assert!(m.contains("(999800 more bytes)`"), "{m}");
assert!(m.ends_with("at line 1 column 1000014\\nnext"), "{m}");
assert_eq!(tricept_data::message::one_line(&m), m);
```
"#
)]
pub fn one_line(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(2 * MAX_MESSAGE_CHARS));
    let mut rest = message;
    while let Some(open) = rest.find(['`', '"']) {
        let quote = &rest[open..open + 1];
        out.push_str(&cut(&rest[..open], usize::MAX));
        out.push_str(quote);
        let inside = &rest[open + 1..];
        let (span, after) = match inside.find(quote) {
            Some(close) => (&inside[..close], Some(&inside[close..])),
            None => (inside, None),
        };
        let keep = if span.chars().nth(MAX_QUOTED_CHARS).is_some() {
            MAX_QUOTED_CHARS / 2
        } else {
            usize::MAX
        };
        out.push_str(&cut(span, keep));
        match after {
            Some(after) => {
                out.push_str(quote);
                rest = &after[1..];
            }
            None => rest = "",
        }
    }
    out.push_str(&cut(rest, usize::MAX));
    let chars = out.chars().count();
    if chars <= MAX_MESSAGE_CHARS {
        return out;
    }
    let head: String = out.chars().take(MAX_MESSAGE_CHARS / 2).collect();
    let tail_chars = MAX_MESSAGE_CHARS / 4;
    let tail: String = out.chars().skip(chars - tail_chars).collect();
    let left_out = out.len() - head.len() - tail.len();
    format!("{head} … ({left_out} bytes cut) … {tail}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_messages_keep_their_start_and_end_and_are_idempotent() {
        let long = format!("start {}end", "word ".repeat(10_000));
        let m = one_line(&long);
        assert!(m.chars().count() <= MAX_MESSAGE_CHARS, "{}", m.len());
        assert!(m.starts_with("start word"));
        assert!(m.ends_with("word end"));
        assert!(m.contains("bytes cut"));
        assert_eq!(one_line(&m), m);
        // Short messages and short quotes pass unchanged.
        let short = "a.csv: line 3, column `s`: not a number (got `x`)";
        assert_eq!(one_line(short), short);
    }

    #[test]
    fn every_control_character_and_reordering_mark_is_escaped() {
        for c in (0u32..0x20).chain([0x7f, 0x85, 0x202e, 0x2066]) {
            let c = char::from_u32(c).unwrap();
            let m = one_line(&format!("a{c}b"));
            assert!(!m.contains(c), "{c:?} in {m:?}");
            assert!(m.starts_with('a') && m.ends_with('b'), "{m:?}");
            assert_eq!(one_line(&m), m);
        }
    }
}
