//! Section 5: the daily checks over time (`tricept check --history`): each
//! check's verdict on a time line with the change it named, each key
//! quantity against its band (the change beyond which that check flags it)
//! with two standard deviations, and the checks one row each.

use serde_json::Value;

use crate::html::{figure, legend, list, p, section as wrap, table};
use crate::json::{Digits, Lookup, escape};
use crate::sources::Sources;
use crate::svg::{Plot, days_range, range};

const TITLE: &str = "5. Daily checks";

/// The section.
pub fn section(l: &Lookup<'_>, sources: &Sources) -> String {
    let h = "history";
    let n = l.array(h, "").len();
    if sources.history.is_none() || n == 0 {
        return wrap(
            "checks",
            TITLE,
            &p(
                "No check history given: a daily check with a history (<code>history</code>, CHECKS.jsonl) keeps one, and giving it to the report (<code>history</code>) shows it here.",
            ),
        );
    }
    let mut s = p(&format!(
        "The history {} holds the checks of this calibration against its readings: has the machine changed since? Each quantity is fitted alone at each check; inside its band it is noise, outside it the check flags it (docs/check.md).",
        sources
            .history
            .as_ref()
            .and_then(|x| x.file.as_deref())
            .map_or(String::new(), |f| format!("<code>{}</code>", escape(f)))
    ));
    let t = "trends";
    let trends = l.array(t, "").len();
    let days: Vec<f64> = l
        .array(t, "/0/days")
        .iter()
        .filter_map(Value::as_f64)
        .collect();
    if days.len() == n {
        s.push_str(&figure(&[timeline(l, &days)], "Each check's verdict over time (days since the first check): green unchanged, amber noisier than stated, red changed, with the change it named."));
    }
    let plots: Vec<String> = (0..trends).map(|k| trend_plot(l, k)).collect();
    if !plots.is_empty() {
        s.push_str(&figure(
            &plots,
            "Each key quantity at each check (dot, with two standard deviations) against its band (shaded): the change beyond which that check flags it alone; red dots are outside their band.",
        ));
        s.push_str(&legend(&[
            ("s1", "estimate, two standard deviations".into()),
            ("bad", "outside its band".into()),
        ]));
        let items: Vec<String> = (0..trends)
            .map(|k| {
                let q = |key: &str| format!("/{k}/{key}");
                let slope = if l.get(t, &q("slope_per_day")).is_some_and(|v| !v.is_null()) {
                    format!(
                        "slope {} &plusmn; {} {} a day",
                        l.num(t, &q("slope_per_day/0")),
                        l.num(t, &q("slope_per_day/1")),
                        l.text(t, &q("unit"))
                    )
                } else {
                    "no slope (fewer than three checks, or less than a day)".into()
                };
                let outside: Vec<String> = l
                    .array(t, &q("outside"))
                    .iter()
                    .filter_map(Value::as_u64)
                    .map(|j| l.text(h, &format!("/{j}/time")))
                    .collect();
                let outside = if outside.is_empty() {
                    "inside its band at every check".into()
                } else {
                    format!("outside its band at the checks of {}", outside.join(", "))
                };
                format!("{}: {slope}; {outside}", l.text(t, &q("name")))
            })
            .collect();
        s.push_str(&list(&items));
    }
    let rows: Vec<Vec<String>> = (0..n)
        .map(|k| {
            let q = |key: &str| format!("/{k}/{key}");
            let named = if l.str(h, &q("most_likely")).is_some() {
                // The shortlist's first is the most likely change itself.
                let short: Vec<String> = (1..l.array(h, &q("shortlist")).len())
                    .map(|j| l.text(h, &format!("/{k}/shortlist/{j}")))
                    .collect();
                format!(
                    "{} (cannot be told apart: {})",
                    l.text(h, &q("most_likely")),
                    if short.is_empty() {
                        "-".into()
                    } else {
                        short.join(", ")
                    }
                )
            } else {
                "-".into()
            };
            vec![
                format!(
                    "{}<br>{}",
                    l.text(h, &q("time")),
                    l.text(h, &q("data_file"))
                ),
                l.text(h, &q("verdict")),
                named,
                format!(
                    "{} for {} (p = {})",
                    l.show(h, &q("consistency/0"), Digits::Sig(4)),
                    l.num(h, &q("consistency/1")),
                    l.num(h, &q("consistency/2"))
                ),
            ]
        })
        .collect();
    s.push_str(&table(
        &[
            "when, campaign",
            "verdict",
            "most likely change",
            "consistency: chi-square for dof (p)",
        ],
        &[false, false, false, true],
        &rows,
    ));
    wrap("checks", TITLE, &s)
}

/// The checks' verdicts on a time line, the named change beside a change.
fn timeline(l: &Lookup<'_>, days: &[f64]) -> String {
    let h = "history";
    let (lo, hi) = days_range(days.iter().copied());
    let mut plot = Plot::new(
        "fig-check-verdicts",
        "The checks' verdicts over time",
        "One marker per check at its day: its verdict by colour and, for a change, the change it named; the verdicts are in the table of this section.",
        (560.0, 110.0),
        (20.0, 20.0, 20.0, 36.0),
        (lo, hi),
        (0.0, 1.0),
    );
    plot.axes("days since the first check", "", (6, 0));
    for (k, day) in days.iter().enumerate() {
        let verdict = l.str(h, &format!("/{k}/verdict")).unwrap_or("");
        let class = match verdict {
            "unchanged" => "ok",
            "noisier-than-stated" => "warn",
            _ => "bad",
        };
        plot.point(*day, 0.5, 6.0, class);
        if let Some(name) = l.str(h, &format!("/{k}/most_likely")) {
            let (px, py) = plot.at(*day, 0.5);
            let (x0, x1) = plot.x_edges();
            let anchor = if px > 0.75 * x1 {
                "end"
            } else if px < x0 + 40.0 {
                "start"
            } else {
                "middle"
            };
            plot.label_px((px, py - 12.0), name, anchor, "tick");
        }
    }
    plot.finish()
}

/// One key quantity over the checks against its band.
fn trend_plot(l: &Lookup<'_>, k: usize) -> String {
    let t = "trends";
    let series = |key: &str| -> Vec<f64> {
        l.array(t, &format!("/{k}/{key}"))
            .iter()
            .filter_map(Value::as_f64)
            .collect()
    };
    let (days, values, sd, band) = (
        series("days"),
        series("values"),
        series("std_dev"),
        series("band"),
    );
    let outside: Vec<usize> = l
        .array(t, &format!("/{k}/outside"))
        .iter()
        .filter_map(Value::as_u64)
        .map(|v| v as usize)
        .collect();
    let name = l.str(t, &format!("/{k}/name")).unwrap_or("-");
    let unit = l.str(t, &format!("/{k}/unit")).unwrap_or("");
    let spread = values
        .iter()
        .zip(&sd)
        .flat_map(|(v, s)| [v - 2.0 * s, v + 2.0 * s])
        .chain(band.iter().flat_map(|b| [-b, *b]));
    let (ylo, yhi) = range(spread, &[0.0]);
    let (xlo, xhi) = days_range(days.iter().copied());
    let mut plot = Plot::new(
        &format!("fig-trend-{}", k + 1),
        &format!("{name} at each check against its band, {unit}"),
        "The quantity's estimate at each check with two standard deviations, and its band shaded; the values are in the trends JSON block and the list below.",
        (280.0, 210.0),
        (46.0, 10.0, 24.0, 36.0),
        (xlo, xhi),
        (ylo, yhi),
    );
    let lower: Vec<f64> = band.iter().map(|b| -b).collect();
    plot.band(&days, &lower, &band, "band");
    plot.axes("days", &format!("{name}, {unit}"), (4, 4));
    plot.segment((xlo, 0.0), (xhi, 0.0), "ref");
    for (j, ((d, v), s)) in days.iter().zip(&values).zip(&sd).enumerate() {
        let class = if outside.contains(&j) { "bad" } else { "s1" };
        plot.segment(
            (*d, v - 2.0 * s),
            (*d, v + 2.0 * s),
            &format!("{class} whisker"),
        );
        plot.point(*d, *v, 3.2, class);
    }
    plot.finish()
}
