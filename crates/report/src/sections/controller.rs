//! Section 6: the controller files written (`tricept export`, its
//! `export.json`): the control and its files, each leg axis' table
//! (points, span, format error against the tolerance), what the format
//! errors do to the platform, the parameters to set and what the files
//! cannot carry.

use crate::html::{figure, list, p, section as wrap, table};
use crate::json::{Digits, Lookup};
use crate::sources::Sources;
use crate::svg::{Plot, range};

const TITLE: &str = "6. Controller files";

/// The section.
pub fn section(l: &Lookup<'_>, sources: &Sources) -> String {
    let Some(export) = &sources.export else {
        return wrap(
            "controller",
            TITLE,
            &p(
                "No export given: an export of this machine file writes the control's files into a folder, and giving that folder to the report (<code>export</code>) shows them here.",
            ),
        );
    };
    let e = "export";
    let files: Vec<String> = (0..l.array(e, "/files").len())
        .map(|k| format!("<code>{}</code>", l.text(e, &format!("/files/{k}"))))
        .collect();
    let mut s = p(&format!(
        "{}: the {} files for the {} control, written as one set: {}.",
        export.file.as_deref().map_or(String::new(), |f| format!(
            "<code>{}</code>",
            crate::json::escape(f)
        )),
        l.text(e, "/controller"),
        l.text(e, "/control"),
        files.join(", ")
    ));
    let n = l.array(e, "/axes").len();
    if n > 0 {
        s.push_str(&figure(&[format_errors(l, n)], "Each leg axis' format error: the largest distance between where the control leaves the axis, reading the written table as its documentation says, and where the machine file's exact correction puts it; the dashed line is the tolerance past which nothing is written."));
    }
    let rows: Vec<Vec<String>> = (0..n)
        .map(|k| {
            let a = |key: &str| format!("/axes/{k}/{key}");
            vec![
                format!("{} &rarr; {}", l.num(e, &a("leg")), l.text(e, &a("axis"))),
                l.num(e, &a("points")),
                format!(
                    "{} to {} every {}",
                    l.show(e, &a("min_mm"), Digits::Sig(6)),
                    l.show(e, &a("max_mm"), Digits::Sig(6)),
                    l.show(e, &a("step_mm"), Digits::Sig(4))
                ),
                l.num(e, &a("format_error_um")),
                format!(
                    "{} / {}",
                    l.show(e, &a("reference_mm"), Digits::Sig(6)),
                    l.show(e, &a("zero_mm"), Digits::Sig(6))
                ),
            ]
        })
        .collect();
    s.push_str(&table(
        &[
            "leg → axis",
            "points",
            "span, mm",
            "format error, um",
            "reference / zero, mm",
        ],
        &[false, true, false, true, false],
        &rows,
    ));
    s.push_str(&p(&format!(
        "Together the axes' format errors move the platform point by up to {} um over the workspace (tolerance per axis {} um; within it: {}).",
        l.num(e, "/platform_error_um"),
        l.num(e, "/tolerance_um"),
        l.text(e, "/within_tolerance"),
    )));
    let lines = |key: &str| -> Vec<String> {
        (0..l.array(e, &format!("/{key}")).len())
            .map(|k| l.text(e, &format!("/{key}/{k}")))
            .collect()
    };
    let parameters = lines("parameters");
    if !parameters.is_empty() {
        s.push_str("<h3>Parameters to set on the control</h3>\n");
        s.push_str(&list(&parameters));
    }
    let not: Vec<String> = (0..l.array(e, "/not_exported").len())
        .map(|k| {
            let q = |key: &str| format!("/not_exported/{k}/{key}");
            format!(
                "{} ({} um): {}",
                l.text(e, &q("what")),
                l.num(e, &q("size_um")),
                l.text(e, &q("why"))
            )
        })
        .collect();
    if !not.is_empty() {
        s.push_str("<h3>What the files cannot carry</h3>\n");
        s.push_str(&list(&not));
    }
    for (key, title) in [("warnings", "Warnings"), ("limits", "Limits to raise")] {
        let items = lines(key);
        if !items.is_empty() {
            s.push_str(&format!("<h3>{title}</h3>\n"));
            s.push_str(&list(&items));
        }
    }
    wrap("controller", TITLE, &s)
}

/// The axes' format errors against the tolerance.
fn format_errors(l: &Lookup<'_>, n: usize) -> String {
    let e = "export";
    let errors: Vec<Option<f64>> = (0..n)
        .map(|k| l.f64(e, &format!("/axes/{k}/format_error_um")))
        .collect();
    let tolerance = l.f64(e, "/tolerance_um");
    let (_, hi) = range(
        errors.iter().flatten().copied(),
        &[0.0, tolerance.unwrap_or(0.0)],
    );
    let rows = n as f64;
    let mut plot = Plot::new(
        "fig-format-errors",
        "Format error of each leg axis against the tolerance, um",
        "One bar per leg axis: its format error; the dashed line: the tolerance; the values are in the table below.",
        (560.0, 60.0 + 30.0 * rows),
        (70.0, 14.0, 20.0, 36.0),
        (0.0, hi),
        (0.0, rows),
    );
    plot.axes("format error, um", "", (5, 0));
    let (x0, _) = plot.x_edges();
    for (k, v) in errors.iter().enumerate() {
        let y = rows - k as f64 - 0.5;
        if let Some(v) = v {
            plot.rect((0.0, y - 0.3), (*v, y + 0.3), "s1", None);
        }
        let axis = l.str(e, &format!("/axes/{k}/axis")).unwrap_or("-");
        let (_, py) = plot.at(0.0, y);
        plot.label_px((x0 - 5.0, py + 4.0), axis, "end", "tick");
    }
    if let Some(t) = tolerance {
        plot.segment((t, 0.0), (t, rows), "ref");
    }
    plot.finish()
}
