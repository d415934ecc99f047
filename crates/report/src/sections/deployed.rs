//! Section 3: what the calibration deploys: the geometric estimates with
//! their uncertainty, the per-leg compensation tables along each leg's
//! stroke, the effects' fitted sizes (thermal growth, backlash, leads,
//! pitch terms) with their uncertainty, the controller parameters, and,
//! from the campaign's diagnosis, each model term's gain with its
//! uncertainty and whether it was deployed.

use serde_json::Value;

use crate::html::{figure, legend, list, p, section as wrap, series, table};
use crate::json::{Digits, Lookup, number, token};
use crate::sections::ptr;
use crate::sources::Sources;
use crate::svg::{Plot, range};

const TITLE: &str = "3. What the calibration deploys";

/// The section.
pub fn section(l: &Lookup<'_>, sources: &Sources) -> String {
    let mut s = estimates(l);
    s.push_str(&tables(l));
    s.push_str(&effects(l));
    s.push_str(&controller(l));
    s.push_str(&gains(l, sources));
    let lines = |key: &str| -> Vec<String> {
        (0..l.array("machine", &ptr(&["calibration", key])).len())
            .map(|k| l.text("machine", &format!("/calibration/{key}/{k}")))
            .collect()
    };
    let (applies, records) = (lines("applies"), lines("records"));
    if !applies.is_empty() {
        s.push_str("<h3>What the file applies</h3>\n");
        s.push_str(&list(&applies));
    }
    if !records.is_empty() {
        s.push_str("<h3>What the file only records</h3>\n");
        s.push_str(&list(&records));
    }
    wrap("deployed", TITLE, &s)
}

/// `(name, pointer)` of every key of the object at `pointer`.
fn keys(l: &Lookup<'_>, src: &str, pointer: &str) -> Vec<(String, String)> {
    l.get(src, pointer)
        .and_then(Value::as_object)
        .map(|o| {
            o.keys()
                .map(|k| (k.clone(), format!("{pointer}/{}", token(k))))
                .collect()
        })
        .unwrap_or_default()
}

/// Rows of estimates with whiskers of two standard deviations; a row
/// without a standard deviation (held) is an open marker.
fn whisker_plot(
    id: &str,
    title: &str,
    desc: &str,
    unit: &str,
    rows: &[(String, Option<f64>, Option<f64>)],
) -> String {
    let values = rows.iter().flat_map(|(_, v, sd)| {
        let v = v.unwrap_or(0.0);
        let w = 2.0 * sd.unwrap_or(0.0);
        [v - w, v + w]
    });
    let (lo, hi) = range(values, &[0.0]);
    let n = rows.len() as f64;
    let label_width = rows.iter().map(|(r, _, _)| r.len()).max().unwrap_or(4) as f64 * 6.6;
    let mut plot = Plot::new(
        id,
        title,
        desc,
        (560.0, 56.0 + 17.0 * n),
        ((label_width + 12.0).min(280.0), 14.0, 20.0, 36.0),
        (lo, hi),
        (0.0, n),
    );
    plot.axes(unit, "", (5, 0));
    plot.segment((0.0, 0.0), (0.0, n), "ref");
    let (x0, _) = plot.x_edges();
    for (k, (name, v, sd)) in rows.iter().enumerate() {
        let y = n - k as f64 - 0.5;
        let (_, py) = plot.at(0.0, y);
        plot.label_px((x0 - 5.0, py + 4.0), name, "end", "tick");
        let Some(v) = v else { continue };
        match sd {
            Some(sd) => {
                plot.segment((v - 2.0 * sd, y), (v + 2.0 * sd, y), "s1 whisker");
                plot.point(*v, y, 3.2, "s1");
            }
            None => plot.point(*v, y, 3.2, "s2 open"),
        }
    }
    plot.finish()
}

fn estimates(l: &Lookup<'_>) -> String {
    let m = "machine";
    let names = keys(l, m, "/calibration/estimates_mm");
    let mut rows = Vec::new();
    let mut cells = Vec::new();
    for (name, path) in &names {
        let sd_path = format!("/calibration/std_dev_mm/{}", token(name));
        let sd = l.f64(m, &sd_path);
        rows.push((name.clone(), l.f64(m, path), sd));
        cells.push(vec![
            format!("<code>{}</code>", crate::json::escape(name)),
            l.show(m, path, Digits::Sig(4)),
            if sd.is_some() {
                l.show(m, &sd_path, Digits::Sig(3))
            } else {
                "held".into()
            },
        ]);
    }
    let mut s = p(&format!(
        "The geometry, estimated by <code>tricept {}</code> relative to <code>{}</code> (parameter set {}): each parameter's estimate with two standard deviations; a parameter the sensors cannot see is held at its prior (open marker; section 4 says why).",
        l.text(m, "/calibration/method"),
        l.text(m, "/calibration/relative_to"),
        l.text(m, "/calibration/parameter_set"),
    ));
    if rows.is_empty() {
        return s;
    }
    s.push_str(&figure(
        &[whisker_plot(
            "fig-estimates",
            "Geometric estimates with two standard deviations, mm",
            "Each geometric parameter's estimate (dot) with two standard deviations (line); held parameters as open dots; the values are in the table below.",
            "estimate, mm (line: two standard deviations)",
            &rows,
        )],
        "The calibrated geometry: module errors relative to the nominal machine (mm).",
    ));
    s.push_str(&table(
        &["parameter", "estimate, mm", "standard deviation, mm"],
        &[false, true, true],
        &cells,
    ));
    s
}

/// The per-leg compensation tables, along each leg's stroke.
fn tables(l: &Lookup<'_>) -> String {
    let m = "machine";
    let n = l.array(m, "/leg_effects/tables").len();
    if n == 0 {
        return p(
            "Per-leg compensation tables: none (the file deploys no pitch, curvature or worn-segment term).",
        );
    }
    let mut lines = Vec::new();
    for k in 0..n {
        let t = |key: &str| format!("/leg_effects/tables/{k}/{key}");
        let (start, step) = (l.f64(m, &t("start_mm")), l.f64(m, &t("step_mm")));
        let (Some(start), Some(step)) = (start, step) else {
            continue;
        };
        let points: Vec<(f64, f64)> = l
            .array(m, &t("extra_length_um"))
            .iter()
            .enumerate()
            .filter_map(|(j, v)| Some((start + step * j as f64, v.as_f64()?)))
            .collect();
        lines.push((k, points));
    }
    let (xlo, xhi) = range(lines.iter().flat_map(|(_, p)| p.iter().map(|q| q.0)), &[]);
    let keys: Vec<(&str, String)> = lines
        .iter()
        .map(|(k, _)| {
            let leg = l
                .f64(m, &format!("/leg_effects/tables/{k}/leg"))
                .map_or("-".into(), |v| number(v, Digits::Fixed(0)));
            (series(*k), format!("leg {leg}"))
        })
        .collect();
    // The middle tenth of the stroke, where a pitch error's period shows.
    let (mid, half) = (0.5 * (xlo + xhi), 0.05 * (xhi - xlo));
    let plots = [
        table_plot(
            &lines,
            "fig-leg-tables",
            "along the whole stroke",
            (xlo, xhi),
        ),
        table_plot(
            &lines,
            "fig-leg-tables-detail",
            "in the middle tenth of the stroke",
            (mid - half, mid + half),
        ),
    ];
    let mut s = String::new();
    for plot in plots {
        s.push_str(&figure(
            &[plot],
            "The file's compensation tables (leg_effects.tables), read by linear interpolation, the end values beyond: a ball-screw pitch error shows as a periodic curve, a curved screw as a bow, a worn segment as a step.",
        ));
    }
    s.push_str(&legend(&keys));
    let items: Vec<String> = (0..n)
        .map(|k| {
            let t = |key: &str| format!("/leg_effects/tables/{k}/{key}");
            format!(
                "leg {}: from {} mm every {} mm: {}",
                l.num(m, &t("leg")),
                l.show(m, &t("start_mm"), Digits::Sig(6)),
                l.show(m, &t("step_mm"), Digits::Sig(4)),
                l.text(m, &t("source"))
            )
        })
        .collect();
    s.push_str(&list(&items));
    s
}

/// The tables' lines over the commands `window` (mm).
fn table_plot(
    lines: &[(usize, Vec<(f64, f64)>)],
    id: &str,
    what: &str,
    window: (f64, f64),
) -> String {
    let inside = |q: &&(f64, f64)| q.0 >= window.0 && q.0 <= window.1;
    let (ylo, yhi) = range(
        lines
            .iter()
            .flat_map(|(_, p)| p.iter().filter(inside).map(|q| q.1)),
        &[0.0],
    );
    let mut plot = Plot::new(
        id,
        &format!("Per-leg compensation tables {what}: the leg's extra length, um"),
        "One line per leg: the extra length the file adds to the leg at each command; the tables' ranges and spacing are in the list below.",
        (640.0, 250.0),
        (48.0, 14.0, 24.0, 36.0),
        window,
        (ylo, yhi),
    );
    plot.axes("leg command, mm", "extra length, um", (6, 5));
    for (k, points) in lines {
        let shown: Vec<(f64, f64)> = points.iter().filter(inside).copied().collect();
        plot.line(&shown, series(*k));
    }
    plot.finish()
}

/// The unit of an effect parameter, from its name.
fn unit_of(name: &str) -> &'static str {
    const UNITS: [(&str, &str); 12] = [
        ("_ppm_per_k", "ppm/K"),
        ("_um_per_kn_at_1m", "um/kN at 1 m"),
        ("_arcsec_per_100mm", "arcsec/100 mm"),
        ("_arcsec_per_k", "arcsec/K"),
        ("_um_per_k", "um/K"),
        ("_per_k", "1/K"),
        ("_ppm", "ppm"),
        ("_um", "um"),
        ("_mm", "mm"),
        ("_arcsec", "arcsec"),
        ("_rad", "rad"),
        ("_deg", "deg"),
    ];
    UNITS
        .iter()
        .find(|(suffix, _)| name.ends_with(suffix))
        .map_or("", |(_, u)| u)
}

/// The effects' fitted sizes, one plot per unit.
fn effects(l: &Lookup<'_>) -> String {
    let m = "machine";
    let names = keys(l, m, "/calibration/effects");
    if names.is_empty() {
        return p("Effects beyond the geometry: none fitted (the record's effects are empty).");
    }
    let mut units: Vec<&str> = Vec::new();
    for (name, _) in &names {
        let u = unit_of(name);
        if !units.contains(&u) {
            units.push(u);
        }
    }
    let mut s = String::new();
    for (k, unit) in units.iter().enumerate() {
        let rows: Vec<(String, Option<f64>, Option<f64>)> = names
            .iter()
            .filter(|(n, _)| unit_of(n) == *unit)
            .map(|(n, path)| {
                (
                    n.clone(),
                    l.f64(m, &format!("{path}/value")),
                    l.f64(m, &format!("{path}/std_dev")),
                )
            })
            .filter(|r| r.2.is_some())
            .collect();
        if rows.is_empty() {
            continue;
        }
        let plot = whisker_plot(
            &format!("fig-effects-{}", k + 1),
            &format!("Fitted effect sizes, {unit}"),
            "Each effect parameter's fitted value (dot) with two standard deviations (line); the values are in the table below.",
            &format!("value, {unit}"),
            &rows,
        );
        s.push_str(&figure(
            &[plot],
            &format!(
                "The effects in {unit} the calibration fitted beside the geometry (calibration.effects), each with two standard deviations."
            ),
        ));
    }
    if names
        .iter()
        .any(|(_, path)| l.f64(m, &format!("{path}/std_dev")).is_none())
    {
        s.push_str(&p(
            "A parameter without a standard deviation (a scanned period) is in the table only.",
        ));
    }
    let cells: Vec<Vec<String>> = names
        .iter()
        .map(|(n, path)| {
            vec![
                format!("<code>{}</code>", crate::json::escape(n)),
                l.show(m, &format!("{path}/value"), Digits::Sig(4)),
                l.num(m, &format!("{path}/std_dev")),
            ]
        })
        .collect();
    s.push_str(&table(
        &["effect parameter", "value", "standard deviation"],
        &[false, true, true],
        &cells,
    ));
    s
}

/// The controller's parameters and the static leg effects.
fn controller(l: &Lookup<'_>) -> String {
    let m = "machine";
    let mut items = Vec::new();
    if l.get(m, "/controller").is_some() {
        items.push(format!(
            "backlash of the leg axes, for the control's reversal compensation: {} um, {} um, {} um",
            l.num(m, "/controller/backlash_um/0"),
            l.num(m, "/controller/backlash_um/1"),
            l.num(m, "/controller/backlash_um/2"),
        ));
        items.push(format!(
            "thermal expansion of the legs, for the control's temperature compensation: {} ppm/K from {} degC",
            l.num(m, "/controller/thermal_expansion_ppm_per_k"),
            l.num(m, "/controller/reference_temperature_c"),
        ));
    }
    let nonzero = |p: &str| l.f64(m, p).is_some_and(|v| v != 0.0);
    if (0..3).any(|k| nonzero(&format!("/leg_effects/lead_ppm/{k}")))
        || nonzero("/leg_effects/compliance_um_per_kn_at_1m")
    {
        items.push(format!(
            "lead of the legs (applied by tricept's kinematics): {} ppm, {} ppm, {} ppm; gravity compliance {} um/kN at 1 m",
            l.num(m, "/leg_effects/lead_ppm/0"),
            l.num(m, "/leg_effects/lead_ppm/1"),
            l.num(m, "/leg_effects/lead_ppm/2"),
            l.num(m, "/leg_effects/compliance_um_per_kn_at_1m"),
        ));
    }
    if items.is_empty() {
        return p(
            "Controller parameters and static leg effects: none (no backlash, thermal growth, lead or compliance deployed).",
        );
    }
    let mut s = String::from("<h3>Controller parameters and static leg effects</h3>\n");
    s.push_str(&list(&items));
    s
}

/// Each model term's gain with its uncertainty (the campaign's diagnosis).
fn gains(l: &Lookup<'_>, sources: &Sources) -> String {
    let d = "diagnosis";
    if sources.diagnosis.is_none() {
        return p(
            "The gain of each deployed term needs the campaign: give it to the report (<code>data</code>, CAMPAIGN.csv).",
        );
    }
    let n = l.array(d, "/model_terms").len();
    let mut s = String::from("<h3>The gain of each term</h3>\n");
    s.push_str(&p(&format!(
        "From the campaign's diagnosis (deploy rule {}): the deployed model against the geometric-only fit improves the mean platform error on the middle plane by {} mm (standard deviation {} mm).",
        l.text(d, "/deploy_rule"),
        l.num(d, "/gain/improvement_mm"),
        l.num(d, "/gain/improvement_sd_mm"),
    )));
    if n == 0 {
        s.push_str(&p("The diagnosis deploys no term beyond the geometry."));
        return s;
    }
    let mut rows = Vec::new();
    let mut cells = Vec::new();
    for k in 0..n {
        let t = |key: &str| format!("/model_terms/{k}/{key}");
        let deployed = l.get(d, &t("deployed")).and_then(Value::as_bool) == Some(true);
        let name = l.str(d, &t("description")).unwrap_or("-").to_string();
        rows.push((
            name,
            l.f64(d, &t("improvement_mm")),
            l.f64(d, &t("improvement_sd_mm")).filter(|_| deployed),
        ));
        cells.push(vec![
            l.text(d, &t("description")),
            l.text(d, &t("deployed")),
            format!(
                "{} &plusmn; {}",
                l.num(d, &t("improvement_mm")),
                l.num(d, &t("improvement_sd_mm"))
            ),
            format!(
                "{} &plusmn; {}",
                l.num(d, &t("holdout_benefit_mm")),
                l.num(d, &t("holdout_benefit_sd_mm"))
            ),
        ]);
    }
    s.push_str(&figure(
        &[whisker_plot(
            "fig-gains",
            "Each model term's improvement of the platform error, mm",
            "Each term's predicted improvement of the mean platform error (dot) with two standard deviations (line) for deployed terms; open dots: seen, not worth deploying; the values are in the table below.",
            "improvement, mm",
            &rows,
        )],
        "What each term gains: the mean platform error on the middle plane without it minus with it (filled: deployed, with two standard deviations; open: seen but not worth deploying, docs/diagnosis.md).",
    ));
    s.push_str(&table(
        &[
            "term",
            "deployed",
            "improvement, mm (sd)",
            "held-out benefit, mm (sd)",
        ],
        &[false, false, true, true],
        &cells,
    ));
    s
}
