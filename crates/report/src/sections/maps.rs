//! Section 1: the platform error over the workspace before and after
//! calibration. Before: the compensation map at a few heights (where the
//! nominal commands put the platform by the calibrated model, the
//! correction `tricept compensate --map` writes); after: the file's
//! accuracy promise, marked on the same colour scale.

use crate::html::{figure, p, section as wrap, table};
use crate::json::{Digits, Lookup, number};
use crate::sources::Sources;
use crate::svg::{Plot, cividis, range};

/// The section.
pub fn section(l: &Lookup<'_>, sources: &Sources) -> String {
    let mut s = p(&format!(
        "<strong>Before calibration</strong>: where the nominal machine's commands put the platform, by the calibrated model: the correction the calibration makes (the compensation map of the calibrated machine at a plane and a spacing, its map.csv), at {} heights of the workspace. <strong>After calibration</strong>: the file's commands put the platform where it should be up to the accuracy the file promises, rms {} mm with a 95 % upper bound of {} mm at the {}, marked on the colour bar.",
        sources.maps.len(),
        l.num("machine", "/calibration/accuracy/rms_mm"),
        l.num("machine", "/calibration/accuracy/upper_mm"),
        l.text("machine", "/calibration/accuracy/point"),
    ));
    if sources.maps.is_empty() {
        return wrap("platform-error", "1. Platform error over the workspace", &s);
    }
    let top = sources
        .maps
        .iter()
        .filter_map(|m| l.f64(&m.id, "/predicted_correction/max_mm"))
        .fold(0.0, f64::max);
    let promise: Vec<f64> = ["rms_mm", "upper_mm"]
        .iter()
        .filter_map(|k| l.f64("machine", &format!("/calibration/accuracy/{k}")))
        .collect();
    let (_, scale_top) = range([top], &promise);
    let scale_top = if scale_top > 0.0 { scale_top } else { 1.0 };
    let plots: Vec<String> = sources
        .maps
        .iter()
        .map(|m| heat_map(l, &m.id, scale_top))
        .collect();
    s.push_str(&figure(
        &plots,
        "Predicted platform error before calibration (mm) over the workspace disc at each height, seen from above (x to the right, y up); each cell one point of the map, its colour the size of the correction on the scale below.",
    ));
    s.push_str(&figure(
        &[colour_bar(l, scale_top)],
        "The colour scale (mm), with the promise after calibration: its rms and its 95 % upper bound.",
    ));
    let rows: Vec<Vec<String>> = sources
        .maps
        .iter()
        .map(|m| {
            let id = m.id.as_str();
            let c = |k: &str| l.show(id, &format!("/predicted_correction/{k}"), Digits::Sig(3));
            vec![
                l.num(id, "/plane_z_mm"),
                l.num(id, "/grid_points"),
                c("max_mm"),
                c("mean_mm"),
                c("rms_mm"),
                c("min_mm"),
            ]
        })
        .collect();
    s.push_str(&table(
        &[
            "plane z, mm",
            "points",
            "max, mm",
            "mean, mm",
            "rms, mm",
            "min, mm",
        ],
        &[true; 6],
        &rows,
    ));
    wrap("platform-error", "1. Platform error over the workspace", &s)
}

/// The heat map of one plane's map.
fn heat_map(l: &Lookup<'_>, id: &str, scale_top: f64) -> String {
    let xs = l.array(id, "/points/x");
    let ys = l.array(id, "/points/y");
    let vs = l.array(id, "/points/correction_mm");
    let spacing = l.f64(id, "/spacing_mm").unwrap_or(10.0);
    let reach = xs
        .iter()
        .chain(ys)
        .filter_map(serde_json::Value::as_f64)
        .fold(0.0, |a: f64, v| a.max(v.abs()))
        + 0.5 * spacing;
    let z = l
        .f64(id, "/plane_z_mm")
        .map_or("-".into(), |z| number(z, Digits::Sig(4)));
    let mut plot = Plot::new(
        &format!("fig-{id}"),
        &format!("Platform error before calibration at z = {z} mm"),
        "Heat map of the predicted platform error before calibration over the workspace disc at this height; its statistics are in the table below the figures.",
        (300.0, 320.0),
        (44.0, 10.0, 26.0, 34.0),
        (-reach, reach),
        (-reach, reach),
    );
    for ((x, y), v) in xs.iter().zip(ys).zip(vs) {
        let (Some(x), Some(y), Some(v)) = (x.as_f64(), y.as_f64(), v.as_f64()) else {
            continue;
        };
        let h = 0.5 * spacing;
        plot.rect(
            (x - h, y - h),
            (x + h, y + h),
            "cell",
            Some(&cividis(v / scale_top)),
        );
    }
    plot.axes("x, mm", "y, mm", (5, 5));
    let (x0, x1) = plot.x_edges();
    plot.label_px(
        (0.5 * (x0 + x1), 16.0),
        &format!("z = {z} mm"),
        "middle",
        "axis",
    );
    plot.finish()
}

/// The colour scale with the promise's rms and upper bound marked.
fn colour_bar(l: &Lookup<'_>, top: f64) -> String {
    let mut plot = Plot::new(
        "fig-colour-scale",
        "Colour scale of the platform error, mm, with the promise after calibration",
        "The colours of the heat maps from zero to the largest error, with the promised rms and 95 % upper bound after calibration marked as lines.",
        (560.0, 92.0),
        (14.0, 14.0, 30.0, 34.0),
        (0.0, top),
        (0.0, 1.0),
    );
    let n = 64;
    for k in 0..n {
        let (a, b) = (top * k as f64 / n as f64, top * (k + 1) as f64 / n as f64);
        plot.rect(
            (a, 0.0),
            (b, 1.0),
            "cell",
            Some(&cividis((k as f64 + 0.5) / n as f64)),
        );
    }
    plot.axes("platform error, mm", "", (6, 0));
    let (_, y_top) = plot.y_edges();
    let (_, right) = plot.x_edges();
    for (row, (key, name)) in [("rms_mm", "promise: rms"), ("upper_mm", "95 % upper bound")]
        .into_iter()
        .enumerate()
    {
        if let Some(v) = l.f64("machine", &format!("/calibration/accuracy/{key}")) {
            plot.segment((v, 0.0), (v, 1.0), "ref");
            let (px, _) = plot.at(v, 1.0);
            let y = y_top - 18.0 + 12.0 * row as f64;
            if px > 0.7 * right {
                plot.label_px((px - 3.0, y), name, "end", "axis");
            } else {
                plot.label_px((px + 3.0, y), name, "start", "axis");
            }
        }
    }
    plot.finish()
}
