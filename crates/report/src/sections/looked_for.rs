//! Section 4: what was looked for and not found: the parameters the
//! sensors cannot see (held), and, from the campaign's diagnosis, each
//! candidate effect's evidence against its level, the generic dictionary's
//! tests, what was rejected, what cannot be told apart, the remainder and
//! what the campaign could not show.

use serde_json::Value;

use crate::html::{figure, legend, list, p, section as wrap};
use crate::json::Lookup;
use crate::sources::Sources;
use crate::svg::Plot;

const TITLE: &str = "4. What was looked for and not found";

/// The section.
pub fn section(l: &Lookup<'_>, sources: &Sources) -> String {
    let m = "machine";
    let held: Vec<String> = (0..l.array(m, "/calibration/held").len())
        .map(|k| {
            format!(
                "<code>{}</code>: {}",
                l.text(m, &format!("/calibration/held/{k}/name")),
                l.text(m, &format!("/calibration/held/{k}/reason"))
            )
        })
        .collect();
    let mut s = String::from("<h3>What the sensors cannot see</h3>\n");
    if held.is_empty() {
        s.push_str(&p("Every parameter of the set was estimated (none held)."));
    } else {
        s.push_str(&p("Held at their prior, with the reason the fit gives:"));
        s.push_str(&list(&held));
    }
    if sources.diagnosis.is_none() {
        s.push_str(&p(
            "What the campaign's diagnosis looked for needs the campaign: give it to the report (<code>data</code>, CAMPAIGN.csv).",
        ));
        return wrap("looked-for", TITLE, &s);
    }
    let d = "diagnosis";
    s.push_str("<h3>The campaign's diagnosis</h3>\n");
    s.push_str(&p(&format!(
        "<code>tricept diagnose</code> of the campaign: verdict {}; {} tests of the generic dictionary (periodic, polynomial and stepped leg errors, drifts, gains, hysteresis) beside the effects below.",
        l.text(d, "/verdict"),
        l.num(d, "/dictionary_tests"),
    )));
    s.push_str(&candidates(l));
    let causes: Vec<String> = (0..l.array(d, "/causes").len())
        .map(|k| {
            format!(
                "<code>{}</code>: {}",
                l.text(d, &format!("/causes/{k}/effect")),
                l.text(d, &format!("/causes/{k}/description"))
            )
        })
        .collect();
    if causes.is_empty() {
        s.push_str(&p("Named causes: none (nothing beyond the geometry explains the data better than the noise)."));
    } else {
        s.push_str(&p("Named causes:"));
        s.push_str(&list(&causes));
    }
    for (key, what) in [
        (
            "rejected",
            "Fits rejected (physically implausible, or no better on held-out poses):",
        ),
        ("aliases", "What this campaign cannot tell apart:"),
        ("limitations", "What this campaign could not show:"),
    ] {
        let items: Vec<String> = l
            .array(d, &format!("/{key}"))
            .iter()
            .enumerate()
            .map(|(k, v)| summary(l, d, &format!("/{key}/{k}"), v))
            .collect();
        if !items.is_empty() {
            s.push_str(&p(what));
            s.push_str(&list(&items));
        }
    }
    if l.str(d, "/unexplained").is_some() {
        s.push_str(&p(&format!(
            "Left unexplained: {}",
            l.text(d, "/unexplained")
        )));
    }
    wrap("looked-for", TITLE, &s)
}

/// One entry of a list of the diagnosis: a string as it is, an object by
/// its readable fields.
fn summary(l: &Lookup<'_>, d: &str, path: &str, v: &Value) -> String {
    match v {
        Value::Object(o) => {
            let fields: Vec<String> = [
                "effect",
                "description",
                "members",
                "reason",
                "why",
                "separate_by",
            ]
            .iter()
            .filter(|k| o.get(**k).is_some_and(Value::is_string))
            .map(|k| l.text(d, &format!("{path}/{k}")))
            .collect();
            fields.join(": ")
        }
        _ => l.text(d, path),
    }
}

/// Each candidate effect's evidence at the first step against its level.
fn candidates(l: &Lookup<'_>) -> String {
    let d = "diagnosis";
    let list_ = l.array(d, "/candidates");
    if list_.is_empty() {
        return String::new();
    }
    // -log10 p, with p = 0 (beyond the double's range) drawn at the
    // range's end.
    let strength = |p: f64| -(p.max(1e-300)).log10();
    let mut rows = Vec::new();
    for (k, c) in list_.iter().enumerate() {
        let e = |key: &str| l.f64(d, &format!("/candidates/{k}/evidence/{key}"));
        let name = c
            .get("effect")
            .and_then(Value::as_str)
            .unwrap_or("-")
            .to_string();
        let selected = c
            .pointer("/evidence/selected")
            .and_then(Value::as_bool)
            .unwrap_or(false);
        rows.push((
            name,
            e("p_value").map(strength),
            e("threshold").map(strength),
            selected,
        ));
    }
    let top = rows
        .iter()
        .flat_map(|(_, a, b, _)| [a.unwrap_or(0.0), b.unwrap_or(0.0)])
        .fold(1.0, f64::max)
        .min(320.0);
    let n = rows.len() as f64;
    let mut plot = Plot::new(
        "fig-candidates",
        "Evidence of each candidate effect against its level",
        "One bar per candidate effect: its evidence as minus the base-10 logarithm of its p-value; the dashed mark is the level it must pass to be named; bars of named causes in the second colour; the p-values are in the diagnosis JSON block.",
        (560.0, 56.0 + 19.0 * n),
        (150.0, 14.0, 20.0, 36.0),
        (0.0, top * 1.05),
        (0.0, n),
    );
    plot.axes("evidence: -log10(p-value)", "", (5, 0));
    let (x0, _) = plot.x_edges();
    for (k, (name, value, level, selected)) in rows.iter().enumerate() {
        let y = n - k as f64 - 0.5;
        if let Some(v) = value {
            let class = if *selected { "s2" } else { "s1" };
            plot.rect((0.0, y - 0.3), (v.min(top * 1.05), y + 0.3), class, None);
        }
        if let Some(t) = level {
            plot.segment((*t, y - 0.45), (*t, y + 0.45), "ref");
        }
        let (_, py) = plot.at(0.0, y);
        plot.label_px((x0 - 5.0, py + 4.0), name, "end", "tick");
    }
    let mut s = figure(
        &[plot.finish()],
        "The first step of the selection screens every candidate alone: a bar short of its level (dashed) was looked for and not found; a bar past it but not named was explained by the named causes (docs/diagnosis.md, \"Method\").",
    );
    s.push_str(&legend(&[
        ("s1", "candidate".into()),
        ("s2", "named cause".into()),
    ]));
    s
}
