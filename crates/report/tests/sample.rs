//! The sample page of the docs, docs/report-sample.html, is what
//! `cargo xtask report-sample` makes from the checked-in inputs
//! (fixtures/report/, the Table 2 fixture) today, byte for byte: the page
//! is deterministic, and a change of the page or of what it shows fails
//! here until the sample is made again. Its own binary: it runs from the
//! workspace's root (the page names its inputs as the docs do).

use std::path::Path;

use tricept_ident::report::{ReportRequest, report};

#[test]
fn the_sample_page_is_current() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::env::set_current_dir(&root).unwrap();
    let out =
        std::env::temp_dir().join(format!("tricept-report-sample-{}.html", std::process::id()));
    // As xtask/src/report_sample.rs asks for it.
    let mut request = ReportRequest::new("fixtures/report/table2.json", &out);
    request.data = Some("fixtures/data/table2-grid-seed1.csv".into());
    request.history = Some("fixtures/report/checks.jsonl".into());
    request.export = Some("fixtures/report/export".into());
    let first = report(request.clone()).unwrap();
    let made = std::fs::read(&out).unwrap();
    report(request).unwrap();
    assert_eq!(
        std::fs::read(&out).unwrap(),
        made,
        "two runs made two pages"
    );
    std::fs::remove_file(&out).unwrap();
    let sample = std::fs::read("docs/report-sample.html").unwrap();
    assert!(
        sample == made,
        "docs/report-sample.html is not the page `cargo xtask report-sample` makes now ({} bytes, the sample {}): run it and commit the page",
        made.len(),
        sample.len()
    );
    // The sample shows the slip its last check found.
    assert_eq!(first.exit_code(), tricept_ident::EXIT_INADEQUATE);
}
