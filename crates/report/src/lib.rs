//! internal: use tricept-ident (`tricept_ident::report`, `tricept report`).
//!
//! One page per calibrated machine: a self-contained HTML file (inline SVG
//! and CSS, no script to run, nothing fetched) that says at a glance
//! whether the machine can be trusted and why, and prints to A4 with a page
//! break before every section. [`page`] renders it from [`Sources`]: the
//! machine file's JSON, the JSON the door's workflows give for it (the
//! compensation map at a few heights, the campaign's diagnosis), the check
//! history's lines and their trends, and the export's summary. Nothing on
//! the page is computed for the page alone: every value shown is an
//! element naming its source and JSON pointer (`data-src`, `data-path`),
//! and every source is in the page as a `<script type="application/json">`
//! block (`id="json-<source>"`), so a reader can check each number.
//! The verdict ([`verdict`]) is the one judgement the page adds, by a rule
//! stated on the page and in docs/report.md.
//!
//! The page is deterministic: the same sources give the same bytes (no
//! time of writing, no random ids).

#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

// Layer 1: the sources, values shown from JSON, plots, page blocks,
// errors.
mod error;
pub mod html;
pub mod json;
mod sources;
pub mod svg;

// Layer 2: whether the inputs belong together, and the verdict.
pub mod identity;
pub mod verdict;

// Layer 3: the sections.
mod sections;

// Layer 4: the page.
mod page;

pub use error::ReportError;
pub use sources::{Source, Sources};
pub use verdict::{Level, Verdict};

/// A rendered page.
#[derive(Debug, Clone, PartialEq)]
pub struct Page {
    /// The HTML document.
    pub html: String,
    /// Its verdict.
    pub verdict: Verdict,
}

/// The page of `sources`: refused when the history or the export names
/// another calibration than the machine file's.
pub fn page(sources: &Sources) -> Result<Page, ReportError> {
    let digest = &sources.calibration_digest;
    let unnamed = match &sources.history {
        Some(h) => identity::check_history(
            digest,
            h.file.as_deref().unwrap_or("the history"),
            h.json.as_array().map_or(&[], Vec::as_slice),
        )?,
        None => Vec::new(),
    };
    let export_named = match &sources.export {
        Some(e) => {
            identity::check_export(digest, e.file.as_deref().unwrap_or("the export"), &e.json)?
        }
        None => false,
    };
    let verdict = verdict::verdict(sources, &unnamed, export_named);
    Ok(Page {
        html: page::html(sources, &verdict),
        verdict,
    })
}
