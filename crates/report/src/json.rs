//! The page's only way to show a value: looked up in a JSON source by its
//! JSON pointer (RFC 6901) and written as an element that names both
//! (`data-src`, `data-path`), so that a reader (and the browser test) can
//! find every shown value in the JSON it comes from. Numbers are shown
//! rounded ([`Digits`]), never converted: a value is shown in the unit its
//! key names.

use serde_json::Value;

/// How a number is rounded on the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Digits {
    /// Significant digits (scientific notation outside 1e-3 .. 1e6).
    Sig(usize),
    /// Digits after the decimal point.
    Fixed(usize),
}

/// One JSON pointer token, escaped (`~` as `~0`, `/` as `~1`).
///
/// # Example
/// ```
/// assert_eq!(tricept_report::json::token("a/b~c"), "a~1b~0c");
/// ```
pub fn token(key: &str) -> String {
    key.replace('~', "~0").replace('/', "~1")
}

/// The text of `s` safe inside HTML text and double-quoted attributes.
///
/// # Example
/// ```
/// assert_eq!(tricept_report::json::escape("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
/// ```
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A number as the page shows it.
///
/// # Example
/// ```
/// use tricept_report::json::{Digits, number};
/// assert_eq!(number(0.057945682797896365, Digits::Sig(3)), "0.0579");
/// assert_eq!(number(1.2345e-7, Digits::Sig(3)), "1.23e-7");
/// assert_eq!(number(208.0, Digits::Sig(3)), "208");
/// assert_eq!(number(-2.5, Digits::Fixed(2)), "-2.50");
/// ```
pub fn number(v: f64, digits: Digits) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    match digits {
        Digits::Fixed(d) => format!("{v:.d$}"),
        Digits::Sig(n) => {
            let n = n.max(1);
            if v == 0.0 {
                return "0".into();
            }
            let a = v.abs();
            if !(1e-3..1e6).contains(&a) {
                return format!("{v:.p$e}", p = n - 1);
            }
            // The decimals that keep `n` significant digits, from the
            // rounded value (9.9996 at 4 digits is 10.00, not 9.9996).
            let mut exponent = a.log10().floor() as i64;
            let decimals = |e: i64| (n as i64 - 1 - e).max(0) as usize;
            let rounded: f64 = format!("{a:.d$}", d = decimals(exponent))
                .parse()
                .unwrap_or(a);
            if rounded >= 10f64.powi(exponent as i32 + 1) {
                exponent += 1;
            }
            format!("{v:.d$}", d = decimals(exponent))
        }
    }
}

/// The JSON sources of a page, each by its id: what every shown value is
/// looked up in.
#[derive(Debug, Clone, Copy)]
pub struct Lookup<'a> {
    sources: &'a [(&'a str, &'a Value)],
}

impl<'a> Lookup<'a> {
    /// The sources, by id.
    pub fn new(sources: &'a [(&'a str, &'a Value)]) -> Lookup<'a> {
        Lookup { sources }
    }

    /// The value at `pointer` in the source `src`.
    pub fn get(&self, src: &str, pointer: &str) -> Option<&'a Value> {
        let root = self.sources.iter().find(|(id, _)| *id == src)?.1;
        root.pointer(pointer)
    }

    /// A number at `pointer` of `src`.
    pub fn f64(&self, src: &str, pointer: &str) -> Option<f64> {
        self.get(src, pointer).and_then(Value::as_f64)
    }

    /// A string at `pointer` of `src`.
    pub fn str(&self, src: &str, pointer: &str) -> Option<&'a str> {
        self.get(src, pointer).and_then(Value::as_str)
    }

    /// The value at `pointer` of `src` as a page element naming both: a
    /// number rounded to `digits`, a string as it is, `true`/`false` as
    /// `yes`/`no`; a dash (naming nothing) when there is none.
    pub fn show(&self, src: &str, pointer: &str, digits: Digits) -> String {
        let text = match self.get(src, pointer) {
            Some(Value::Number(n)) if n.is_i64() || n.is_u64() => Some(n.to_string()),
            Some(Value::Number(n)) => n.as_f64().map(|v| number(v, digits)),
            Some(Value::String(s)) => Some(s.clone()),
            Some(Value::Bool(b)) => Some(if *b { "yes" } else { "no" }.to_string()),
            _ => None,
        };
        match text {
            Some(t) => format!(
                "<span class=\"v\" data-src=\"{}\" data-path=\"{}\">{}</span>",
                escape(src),
                escape(pointer),
                escape(&t)
            ),
            None => "<span class=\"missing\">-</span>".to_string(),
        }
    }

    /// [`Lookup::show`] with 3 significant digits.
    pub fn num(&self, src: &str, pointer: &str) -> String {
        self.show(src, pointer, Digits::Sig(3))
    }

    /// [`Lookup::show`] of a string or a flag.
    pub fn text(&self, src: &str, pointer: &str) -> String {
        self.show(src, pointer, Digits::Sig(3))
    }

    /// The array at `pointer` of `src` (empty when there is none).
    pub fn array(&self, src: &str, pointer: &str) -> &'a [Value] {
        self.get(src, pointer)
            .and_then(Value::as_array)
            .map_or(&[], Vec::as_slice)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_round_across_a_decade() {
        assert_eq!(number(9.9996, Digits::Sig(4)), "10.00");
        assert_eq!(number(0.00099996, Digits::Sig(3)), "1.00e-3");
        assert_eq!(number(0.0012345, Digits::Sig(3)), "0.00123");
        assert_eq!(number(123456.0, Digits::Sig(3)), "123456");
        assert_eq!(number(0.0, Digits::Sig(3)), "0");
        assert_eq!(number(f64::NAN, Digits::Sig(3)), "-");
    }

    #[test]
    fn a_shown_value_names_its_source_and_pointer() {
        let v = serde_json::json!({"a/b": {"x": 0.25, "s": "<ok>", "f": true, "k": 75}, "n": null});
        let sources = [("m", &v)];
        let l = Lookup::new(&sources);
        assert_eq!(
            l.num("m", "/a~1b/x"),
            "<span class=\"v\" data-src=\"m\" data-path=\"/a~1b/x\">0.250</span>"
        );
        assert!(l.text("m", "/a~1b/s").contains(">&lt;ok&gt;<"));
        assert!(l.text("m", "/a~1b/f").contains(">yes<"));
        assert!(l.num("m", "/a~1b/k").contains(">75<"));
        assert_eq!(l.num("m", "/n"), "<span class=\"missing\">-</span>");
        assert_eq!(l.num("other", "/n"), "<span class=\"missing\">-</span>");
    }
}
