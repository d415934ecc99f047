//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! SVG figures for the docs, drawn with `plotters` (SVG backend only, so no
//! system font or image library is needed).
//!
//! - [`heat_map`]: a scalar over a lattice of the workspace plane, with a
//!   colour bar (the paper's Fig. 3 error maps); [`plane_z`] names the
//!   plane in its title;
//! - [`curves`]: lines with optional shaded bands and horizontal reference
//!   lines, optionally on log axes labelled where the data are (the paper's
//!   Fig. 4);
//! - [`scatter`]: point clouds (residuals against a regressor).
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use thiserror::Error;

/// A drawing failure: an empty data set, or the backend's error (I/O).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PlotError {
    /// Nothing to draw.
    #[error("{path}: no data")]
    NoData {
        /// The output file.
        path: String,
    },
    /// The drawing backend failed (typically writing the file).
    #[error("{path}: {source}")]
    Drawing {
        /// The output file.
        path: String,
        /// The backend's error.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

fn err<E: std::error::Error + Send + Sync + 'static>(path: &Path, e: E) -> PlotError {
    PlotError::Drawing {
        path: path.display().to_string(),
        source: Box::new(e),
    }
}

/// Draws a figure of `size` pixels with `draw` and writes it to `path`
/// atomically (`tricept_data::write_atomic`: a failed write leaves the
/// previous figure as it was).
fn render(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(|e| err(path, e))?;
    }
    tricept_data::write_atomic(path, |w| w.write_all(svg.as_bytes())).map_err(|e| err(path, e))
}

fn no_data(path: &Path) -> PlotError {
    PlotError::NoData {
        path: path.display().to_string(),
    }
}

/// Viridis-like colour map, `t` in [0, 1].
pub fn colour(t: f64) -> RGBColor {
    const STOPS: [(f64, [u8; 3]); 6] = [
        (0.0, [68, 1, 84]),
        (0.2, [65, 68, 135]),
        (0.4, [42, 120, 142]),
        (0.6, [34, 168, 132]),
        (0.8, [122, 209, 81]),
        (1.0, [253, 231, 37]),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    for w in STOPS.windows(2) {
        let ((t0, c0), (t1, c1)) = (w[0], w[1]);
        if t <= t1 {
            let f = (t - t0) / (t1 - t0);
            let mix =
                |a: u8, b: u8| (f64::from(a) + f * (f64::from(b) - f64::from(a))).round() as u8;
            return RGBColor(mix(c0[0], c1[0]), mix(c0[1], c1[1]), mix(c0[2], c1[2]));
        }
    }
    RGBColor(253, 231, 37)
}

/// One value on a square lattice cell centred at `(x, y)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Cell centre x, mm.
    pub x: f64,
    /// Cell centre y, mm.
    pub y: f64,
    /// The value.
    pub value: f64,
}

/// A heat map of `cells` (square cells of side `spacing`) with a colour bar.
/// `range` fixes the colour scale (default: the data's min..max).
pub fn heat_map(
    path: &Path,
    title: &str,
    cells: &[Cell],
    spacing: f64,
    value_label: &str,
    range: Option<(f64, f64)>,
) -> Result<(), PlotError> {
    if cells.is_empty() {
        return Err(no_data(path));
    }
    let (lo, hi) = range.unwrap_or_else(|| {
        cells
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
                (a.min(c.value), b.max(c.value))
            })
    });
    let span = if hi > lo { hi - lo } else { 1.0 };
    let half = spacing / 2.0;
    let (x0, x1, y0, y1) = cells.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), p| {
            (
                a.min(p.x - half),
                b.max(p.x + half),
                c.min(p.y - half),
                d.max(p.y + half),
            )
        },
    );
    render(path, (760, 620), |root| {
        root.fill(&WHITE).map_err(|e| err(path, e))?;
        let (main, bar) = root.split_horizontally(620);
        let mut chart = ChartBuilder::on(&main)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(62)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(path, e))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x (mm)")
            .y_desc("y (mm)")
            .axis_desc_style(AXIS_DESC_FONT)
            .label_style(LABEL_FONT)
            .x_label_formatter(&|v| trim_number(*v))
            .y_label_formatter(&|v| trim_number(*v))
            .draw()
            .map_err(|e| err(path, e))?;
        chart
            .draw_series(cells.iter().map(|c| {
                Rectangle::new(
                    [(c.x - half, c.y - half), (c.x + half, c.y + half)],
                    colour((c.value - lo) / span).filled(),
                )
            }))
            .map_err(|e| err(path, e))?;
        colour_bar(&bar, lo, hi, value_label).map_err(|e| err(path, e))?;
        Ok(())
    })
}

/// The plane a map lies in, for its title: `z = 750 mm`, or the range of z
/// when the points do not share one (`z = 700 to 800 mm`).
///
/// ```
/// # use tricept_plot::plane_z;
/// assert_eq!(plane_z([750.0, 750.0]), "z = 750 mm");
/// assert_eq!(plane_z([700.0, 812.5]), "z = 700 to 812.5 mm");
/// ```
pub fn plane_z(z_mm: impl IntoIterator<Item = f64>) -> String {
    let (lo, hi) = z_mm
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
            (a.min(z), b.max(z))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return "z unknown".into();
    }
    if hi - lo < 1e-6 {
        format!("z = {} mm", trim_number(lo))
    } else {
        format!("z = {} to {} mm", trim_number(lo), trim_number(hi))
    }
}

/// Tick labels and axis descriptions: large enough to read on a page.
const LABEL_FONT: (&str, u32) = ("sans-serif", 14);
const AXIS_DESC_FONT: (&str, u32) = ("sans-serif", 16);

fn colour_bar(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    lo: f64,
    hi: f64,
    label: &str,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let hi = if hi > lo { hi } else { lo + 1.0 };
    // Enough decimals to tell the ticks apart (plotters puts at most about
    // ten on the bar), and no more.
    let decimals = (-((hi - lo) / 10.0).log10()).ceil().clamp(0.0, 9.0) as usize;
    let mut chart = ChartBuilder::on(area)
        .margin_top(45)
        .margin_bottom(52)
        .margin_right(4)
        .y_label_area_size(78)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .axis_desc_style(AXIS_DESC_FONT)
        .label_style(LABEL_FONT)
        .y_label_formatter(&|v| format!("{v:.decimals$}"))
        .draw()?;
    let steps = 100;
    chart.draw_series((0..steps).map(|k| {
        let a = lo + (hi - lo) * k as f64 / steps as f64;
        let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            colour(k as f64 / (steps - 1) as f64).filled(),
        )
    }))?;
    Ok(())
}

/// A line with an optional band (`lo`, `hi` per point).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend text.
    pub name: String,
    /// x values.
    pub x: Vec<f64>,
    /// y values.
    pub y: Vec<f64>,
    /// Optional band, `(lo, hi)` per point.
    pub band: Option<Vec<(f64, f64)>>,
}

/// A horizontal reference line.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// Legend text.
    pub name: String,
    /// y value.
    pub y: f64,
}

/// A marker at one point (e.g. a figure quoted in a paper).
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Legend text.
    pub name: String,
    /// Position.
    pub at: (f64, f64),
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Axes description for [`curves`].
#[derive(Debug, Clone, PartialEq)]
pub struct Axes<'a> {
    /// Figure title.
    pub title: &'a str,
    /// x axis label.
    pub x_label: &'a str,
    /// y axis label.
    pub y_label: &'a str,
    /// Log-scale x axis.
    pub log_x: bool,
    /// Log-scale y axis.
    pub log_y: bool,
}

/// Curves with bands, reference lines and markers.
pub fn curves(
    path: &Path,
    axes: &Axes<'_>,
    curves: &[Curve],
    references: &[Reference],
    markers: &[Marker],
) -> Result<(), PlotError> {
    let xs = curves.iter().flat_map(|c| c.x.iter().copied());
    let ys = curves
        .iter()
        .flat_map(|c| {
            c.y.iter().copied().chain(
                c.band
                    .iter()
                    .flat_map(|b| b.iter().flat_map(|(l, h)| [*l, *h])),
            )
        })
        .chain(references.iter().map(|r| r.y))
        .chain(markers.iter().map(|m| m.at.1));
    let (x0, x1) = xs
        .chain(markers.iter().map(|m| m.at.0))
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    let (y0, y1) = ys
        .filter(|v| v.is_finite() && (!axes.log_y || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(no_data(path));
    }
    render(path, (820, 560), |root| {
        root.fill(&WHITE).map_err(|e| err(path, e))?;
        let (yd0, yd1) = (y0, y1);
        let (y0, y1) = if axes.log_y {
            (y0 / 1.3, y1 * 1.3)
        } else {
            let pad = 0.06 * (y1 - y0).max(1e-12);
            (
                (y0 - pad).max(if y0 >= 0.0 { 0.0 } else { f64::NEG_INFINITY }),
                y1 + pad,
            )
        };
        // What the legend must not hide: the curves (and the segments between
        // their points), the bands, the reference lines and the markers.
        let mut drawn: Vec<(f64, f64)> = Vec::new();
        for c in curves {
            let line: Vec<(f64, f64)> = c.x.iter().copied().zip(c.y.iter().copied()).collect();
            drawn.extend(along(&line));
            if let Some(band) = &c.band {
                for (x, (l, h)) in c.x.iter().zip(band) {
                    drawn.extend(along(&[(*x, *l), (*x, *h)]));
                }
            }
        }
        for r in references {
            drawn.extend(along(&[(x0, r.y), (x1, r.y)]));
        }
        drawn.extend(markers.iter().map(|m| m.at));
        let names = curves
            .iter()
            .map(|c| &c.name)
            .chain(references.iter().map(|r| &r.name))
            .chain(markers.iter().map(|m| &m.name));
        let (corner, y1) = legend_place(
            &drawn,
            names,
            (x0, x1, axes.log_x),
            (y0, y1, axes.log_y),
            CURVES_AREA_PX,
        );
        macro_rules! draw {
            ($xr:expr, $yr:expr) => {{
                let mut chart = ChartBuilder::on(&root)
                    .caption(axes.title, ("sans-serif", 20))
                    .margin(15)
                    .x_label_area_size(45)
                    .y_label_area_size(78)
                    .build_cartesian_2d($xr, $yr)
                    .map_err(|e| err(path, e))?;
                chart
                    .configure_mesh()
                    .x_desc(axes.x_label)
                    .y_desc(axes.y_label)
                    .axis_desc_style(AXIS_DESC_FONT)
                    .label_style(LABEL_FONT)
                    .x_label_formatter(&|v| trim_number(*v))
                    .y_label_formatter(&|v| trim_number(*v))
                    .light_line_style(WHITE)
                    .draw()
                    .map_err(|e| err(path, e))?;
                for (k, c) in curves.iter().enumerate() {
                    let col = PALETTE[k % PALETTE.len()];
                    if let Some(band) = &c.band {
                        let mut poly: Vec<(f64, f64)> =
                            c.x.iter().zip(band).map(|(x, (l, _))| (*x, *l)).collect();
                        poly.extend(c.x.iter().zip(band).rev().map(|(x, (_, h))| (*x, *h)));
                        chart
                            .draw_series(std::iter::once(Polygon::new(
                                poly,
                                col.mix(0.18).filled(),
                            )))
                            .map_err(|e| err(path, e))?;
                    }
                    chart
                        .draw_series(LineSeries::new(
                            c.x.iter().zip(&c.y).map(|(x, y)| (*x, *y)),
                            col.stroke_width(2),
                        ))
                        .map_err(|e| err(path, e))?
                        .label(c.name.clone())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(2))
                        });
                    chart
                        .draw_series(
                            c.x.iter()
                                .zip(&c.y)
                                .map(|(x, y)| Circle::new((*x, *y), 3, col.filled())),
                        )
                        .map_err(|e| err(path, e))?;
                }
                for (k, r) in references.iter().enumerate() {
                    let col = if k == 0 {
                        BLACK
                    } else {
                        PALETTE[(k + 3) % PALETTE.len()]
                    };
                    chart
                        .draw_series(DashedLineSeries::new(
                            vec![(x0, r.y), (x1, r.y)],
                            8,
                            5,
                            col.stroke_width(1),
                        ))
                        .map_err(|e| err(path, e))?
                        .label(r.name.clone())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(1))
                        });
                }
                for m in markers {
                    chart
                        .draw_series(std::iter::once(Cross::new(m.at, 7, RED.stroke_width(2))))
                        .map_err(|e| err(path, e))?
                        .label(m.name.clone())
                        .legend(|(x, y)| Cross::new((x + 9, y), 5, RED.stroke_width(2)));
                }
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(LEGEND_FONT)
                    .position(corner.clone())
                    .draw()
                    .map_err(|e| err(path, e))?;
            }};
        }
        // Log axes are labelled where the data are (plotters labels only the
        // powers of ten, which may all lie outside the curves).
        let log_axis = |lo: f64, hi: f64, data: (f64, f64)| {
            (lo..hi)
                .log_scale()
                .with_key_points(log_ticks(lo, hi, data))
        };
        let (xd, yd) = ((x0, x1), (yd0, yd1));
        match (axes.log_x, axes.log_y) {
            (true, true) => draw!(log_axis(x0, x1, xd), log_axis(y0, y1, yd)),
            (true, false) => draw!(log_axis(x0, x1, xd), y0..y1),
            (false, true) => draw!(x0..x1, log_axis(y0, y1, yd)),
            (false, false) => draw!(x0..x1, y0..y1),
        }
        Ok(())
    })
}

/// Tick positions on a log axis over `lo..hi` whose data span `data`:
/// `{1, 2, 5} x 10^k` (every integer mantissa when the axis spans at most a
/// decade, powers of ten beyond four decades), and the data's ends (to two
/// significant digits) where no tick lies within a tenth of a decade of
/// them, so that the labels span the data.
fn log_ticks(lo: f64, hi: f64, data: (f64, f64)) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo && lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    let decades = (hi / lo).log10();
    let mantissas: &[f64] = if decades <= 1.0 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if decades <= 4.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let inside = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
    let mut ticks: Vec<f64> = (lo.log10().floor() as i32..=hi.log10().ceil() as i32)
        .flat_map(|k| {
            mantissas
                .iter()
                .map(move |m| round_significant(m * 10f64.powi(k), 2))
        })
        .filter(|v| inside(*v))
        .collect();
    for end in [data.0, data.1] {
        let end = round_significant(end, 2);
        let far = ticks.iter().all(|t| (t / end).log10().abs() > 0.1);
        if end > 0.0 && inside(end) && far {
            ticks.push(end);
        }
    }
    ticks.sort_by(f64::total_cmp);
    ticks
}

/// `v` rounded to `digits` significant digits (and free of the binary noise
/// of `m * 10^k`, so that labels print short).
fn round_significant(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// A tick label with at most four significant digits and no trailing zeros.
fn trim_number(v: f64) -> String {
    let s = format!("{:.4}", v);
    let s = if v.abs() >= 1.0 { format!("{v:.2}") } else { s };
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s
    }
}

/// Named point clouds on shared axes.
pub fn scatter(
    path: &Path,
    axes: &Axes<'_>,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<(), PlotError> {
    let all = series.iter().flat_map(|(_, p)| p.iter());
    let (x0, x1, y0, y1) = all.fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(a, b, c, d), (x, y)| (a.min(*x), b.max(*x), c.min(*y), d.max(*y)),
    );
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(no_data(path));
    }
    let padx = 0.04 * (x1 - x0).max(1e-12);
    let pady = 0.08 * (y1 - y0).max(1e-12);
    let (x0, x1, y0, y1) = (x0 - padx, x1 + padx, y0 - pady, y1 + pady);
    let points: Vec<(f64, f64)> = series.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    let (corner, y1) = legend_place(
        &points,
        series.iter().map(|(name, _)| name),
        (x0, x1, false),
        (y0, y1, false),
        SCATTER_AREA_PX,
    );
    render(path, (820, 520), |root| {
        root.fill(&WHITE).map_err(|e| err(path, e))?;
        let mut chart = ChartBuilder::on(root)
            .caption(axes.title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(78)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(path, e))?;
        chart
            .configure_mesh()
            .x_desc(axes.x_label)
            .y_desc(axes.y_label)
            .axis_desc_style(AXIS_DESC_FONT)
            .label_style(LABEL_FONT)
            .x_label_formatter(&|v| trim_number(*v))
            .y_label_formatter(&|v| trim_number(*v))
            .light_line_style(WHITE)
            .draw()
            .map_err(|e| err(path, e))?;
        for (k, (name, points)) in series.iter().enumerate() {
            let col = PALETTE[k % PALETTE.len()];
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|p| Circle::new(*p, 3, col.mix(0.8).filled())),
                )
                .map_err(|e| err(path, e))?
                .label(name.clone())
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, col.filled()));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(LEGEND_FONT)
            .position(corner)
            .draw()
            .map_err(|e| err(path, e))?;
        Ok(())
    })
}

/// The plotting areas of [`curves`] and [`scatter`] in pixels (the figure
/// less margins, caption and label areas), for placing the legend.
const CURVES_AREA_PX: (f64, f64) = (820.0 - 78.0 - 30.0, 560.0 - 45.0 - 30.0 - 30.0);
const SCATTER_AREA_PX: (f64, f64) = (820.0 - 78.0 - 30.0, 520.0 - 45.0 - 30.0 - 30.0);
const LEGEND_FONT: (&str, u32) = ("sans-serif", 13);

/// Points along a polyline, every segment sampled at eight places (a legend
/// must not hide the lines between the data points either).
fn along(line: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = line.first().copied().into_iter().collect();
    for w in line.windows(2) {
        let ((xa, ya), (xb, yb)) = (w[0], w[1]);
        out.extend((1..=8).map(|k| {
            let t = f64::from(k) / 8.0;
            // Geometric interpolation would follow a log axis more closely;
            // at eight samples a segment the difference does not matter.
            (xa + t * (xb - xa), ya + t * (yb - ya))
        }));
    }
    out
}

/// `v` on an axis `lo..hi` (log or linear) as a fraction of its length.
fn normalised(v: f64, (lo, hi, log): (f64, f64, bool)) -> f64 {
    if log {
        (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
    } else {
        (v - lo) / (hi - lo)
    }
}

/// Where the legend of `names` goes on a plotting area of `area_px`: the
/// upper corner whose box covers fewer of `points`, with the top of the y
/// axis raised until the box covers none of them. Returns the corner and the
/// new top of the y axis.
fn legend_place<'n>(
    points: &[(f64, f64)],
    names: impl Iterator<Item = &'n String>,
    x: (f64, f64, bool),
    y: (f64, f64, bool),
    area_px: (f64, f64),
) -> (SeriesLabelPosition, f64) {
    let (entries, chars) = names.fold((0usize, 0usize), |(n, c), name| {
        (n + 1, c.max(name.chars().count()))
    });
    // plotters' legend: 5 px from the corner, 10 px of margin around the
    // text, 30 px for the line sample; a 13 px font is about 7 px a
    // character and 17 px a line.
    let w = (7.0 * chars as f64 + 55.0) / area_px.0;
    let h = (17.0 * entries as f64 + 28.0) / area_px.1;
    let inside: Vec<(f64, f64)> = points
        .iter()
        .filter(|(a, b)| a.is_finite() && b.is_finite() && (!y.2 || *b > 0.0) && (!x.2 || *a > 0.0))
        .map(|(a, b)| (normalised(*a, x), normalised(*b, y)))
        .collect();
    let column = |left: bool| move |p: &&(f64, f64)| if left { p.0 <= w } else { p.0 >= 1.0 - w };
    let covered = |left: bool| {
        inside
            .iter()
            .filter(column(left))
            .filter(|p| p.1 >= 1.0 - h)
            .count()
    };
    let left = covered(true) <= covered(false);
    let top = inside
        .iter()
        .filter(column(left))
        .map(|p| p.1)
        .fold(f64::NEG_INFINITY, f64::max);
    // The axis grows so that the highest point under the box lands just
    // below it (at most threefold: a legend taller than the plot stays on it).
    let room = (1.0 - h - 0.03).max(1.0 / 3.0);
    let stretch = if top > room {
        (top / room).min(3.0)
    } else {
        1.0
    };
    let y1 = if y.2 {
        y.0 * (y.1 / y.0).powf(stretch)
    } else {
        y.0 + (y.1 - y.0) * stretch
    };
    let corner = if left {
        SeriesLabelPosition::UpperLeft
    } else {
        SeriesLabelPosition::UpperRight
    };
    (corner, y1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_map_ends_and_clamps() {
        assert_eq!(colour(0.0), RGBColor(68, 1, 84));
        assert_eq!(colour(1.0), RGBColor(253, 231, 37));
        assert_eq!(colour(-3.0), colour(0.0));
        assert_eq!(colour(f64::NAN), colour(0.0));
    }

    #[test]
    fn log_ticks_label_the_data() {
        // Fig. 4: grades 0.25-8 arcsec; mu 0.015-0.29 mm on an axis padded by 1.3.
        let x = log_ticks(0.25, 8.0, (0.25, 8.0));
        assert_eq!(x, vec![0.25, 0.5, 1.0, 2.0, 5.0, 8.0]);
        let y = log_ticks(0.015 / 1.3, 0.291 * 1.3, (0.015, 0.291));
        assert_eq!(y, vec![0.015, 0.02, 0.05, 0.1, 0.2, 0.29]);
        // Within one decade every mantissa is a tick.
        assert_eq!(
            log_ticks(0.02, 0.05, (0.021, 0.05)),
            vec![0.02, 0.03, 0.04, 0.05]
        );
        // Many decades: powers of ten only.
        assert_eq!(
            log_ticks(1e-3, 1e3, (1e-3, 1e3)),
            vec![1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3]
        );
        assert!(log_ticks(0.0, 1.0, (0.0, 1.0)).is_empty());
        // Every tick lies on the axis, and the labels reach both data ends
        // within a tenth of a decade.
        for (lo, hi) in [(0.011, 0.4), (3.0, 7.0), (0.7, 130.0), (5.0, 12.0)] {
            let t = log_ticks(lo, hi, (lo, hi));
            assert!(
                t.iter().all(|v| *v >= lo * 0.999 && *v <= hi * 1.001),
                "{t:?}"
            );
            assert!((t[0] / lo).log10() <= 0.1, "{lo}..{hi}: {t:?}");
            assert!((hi / t[t.len() - 1]).log10() <= 0.1, "{lo}..{hi}: {t:?}");
        }
    }

    #[test]
    fn the_legend_hides_no_data() {
        let names = ["a legend entry".to_string(), "another".to_string()];
        let area = (700.0, 450.0);
        let lin = |lo, hi| (lo, hi, false);
        // Data high on the left only: the legend goes right, the axis stays.
        let left_high = [(0.0, 9.5), (1.0, 9.0), (5.0, 1.0), (10.0, 0.5)];
        let (corner, top) = legend_place(
            &left_high,
            names.iter(),
            lin(0.0, 10.0),
            lin(0.0, 10.0),
            area,
        );
        assert_eq!((corner, top), (SeriesLabelPosition::UpperRight, 10.0));
        // High on both sides: the axis grows until the box covers nothing.
        let both = [(0.0, 9.5), (5.0, 1.0), (10.0, 9.8)];
        let (corner, top) = legend_place(&both, names.iter(), lin(0.0, 10.0), lin(0.0, 10.0), area);
        assert_eq!(corner, SeriesLabelPosition::UpperLeft);
        assert!(top > 10.0);
        let h = (17.0 * 2.0 + 28.0) / area.1;
        assert!(
            both.iter()
                .filter(|p| p.0 < 5.0)
                .all(|p| p.1 / top < 1.0 - h)
        );
        // On a log axis the growth is in decades.
        let (_, top) = legend_place(
            &[(1.0, 90.0), (10.0, 95.0)],
            names.iter(),
            (1.0, 10.0, true),
            (1.0, 100.0, true),
            area,
        );
        assert!(top > 100.0 && (95f64.ln() / top.ln()) < 1.0 - h);
    }

    #[test]
    fn figures_are_written_as_svg() {
        let dir = std::env::temp_dir().join(format!("tricept-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cells: Vec<Cell> = (0..10)
            .flat_map(|i| {
                (0..10).map(move |j| Cell {
                    x: i as f64,
                    y: j as f64,
                    value: (i * j) as f64,
                })
            })
            .collect();
        let p = dir.join("heat.svg");
        heat_map(&p, "t", &cells, 1.0, "v", None).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with("<svg") && text.contains("<rect"));
        let axes = Axes {
            title: "c",
            x_label: "x",
            y_label: "y",
            log_x: true,
            log_y: false,
        };
        let c = Curve {
            name: "a".into(),
            x: vec![1.0, 2.0, 4.0],
            y: vec![1.0, 2.0, 3.0],
            band: Some(vec![(0.5, 1.5); 3]),
        };
        let p = dir.join("curves.svg");
        curves(
            &p,
            &axes,
            &[c],
            &[Reference {
                name: "r".into(),
                y: 2.5,
            }],
            &[Marker {
                name: "m".into(),
                at: (2.0, 2.9),
            }],
        )
        .unwrap();
        assert!(
            std::fs::read_to_string(&p).unwrap().contains("<polygon")
                || std::fs::read_to_string(&p).unwrap().contains("<path")
        );
        let p = dir.join("scatter.svg");
        scatter(&p, &axes, &[("s".into(), vec![(1.0, 2.0), (2.0, 3.0)])]).unwrap();
        assert!(heat_map(&dir.join("empty.svg"), "t", &[], 1.0, "v", None).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
