//! The page: its head (title, viewport, style), the header with the
//! verdict, the sections in reading order, and the sources' JSON blocks.

use crate::html::STYLE;
use crate::json::{Lookup, escape};
use crate::sections;
use crate::sources::Sources;
use crate::verdict::Verdict;

/// The HTML document of `sources` with its `verdict`.
pub fn html(sources: &Sources, verdict: &Verdict) -> String {
    let verdict_json = verdict.to_json();
    let mut list = sources.lookup_list();
    list.push(("verdict", &verdict_json));
    let l = Lookup::new(&list);
    let name = l.str("machine", "/name").unwrap_or("a calibrated machine");
    let mut out = String::with_capacity(1 << 18);
    out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    out.push_str(&format!(
        "<meta name=\"generator\" content=\"tricept {}\">\n<title>Calibration report: {}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n",
        env!("CARGO_PKG_VERSION"),
        escape(name)
    ));
    out.push_str(&sections::head::header(&l, sources, verdict));
    out.push_str("<main>\n");
    out.push_str(&sections::maps::section(&l, sources));
    out.push_str(&sections::residuals::section(&l, sources));
    out.push_str(&sections::deployed::section(&l, sources));
    out.push_str(&sections::looked_for::section(&l, sources));
    out.push_str(&sections::checks::section(&l, sources));
    out.push_str(&sections::controller::section(&l, sources));
    out.push_str(&sections::blocks::section(sources, &verdict_json));
    out.push_str("</main>\n</body>\n</html>\n");
    out
}
