//! Inline SVG plots for the page: a plot area with linear or logarithmic
//! axes, and the marks the sections draw on it (lines, points, whiskers,
//! bands, bars, cells, labels). Every plot is an accessible image: `role
//! img`, labelled by its `<title>` and described by its `<desc>` (its text
//! alternative). Colours are CSS classes of the page (`s1` .. `s4`, the
//! Okabe-Ito palette, which colour-blind readers tell apart), so that a
//! plot prints as it shows. Axis ticks are the plot's scale, not results:
//! they carry no `data-path`.

use std::fmt::Write as _;

use crate::json::escape;

/// One axis: data values `lo..hi` onto plot coordinates `a..b`.
#[derive(Debug, Clone, Copy)]
struct Scale {
    lo: f64,
    hi: f64,
    a: f64,
    b: f64,
    log: bool,
}

impl Scale {
    fn t(&self, v: f64) -> f64 {
        if self.log {
            let l = |x: f64| x.max(f64::MIN_POSITIVE).log10();
            (l(v) - l(self.lo)) / (l(self.hi) - l(self.lo))
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    fn px(&self, v: f64) -> f64 {
        let t = self.t(v);
        let t = if t.is_finite() { t } else { 0.0 };
        self.a + t * (self.b - self.a)
    }
}

/// A range that holds `values` (and `include`), padded by 5 % each side;
/// a flat range is widened to a unit around its value.
///
/// # Example
/// ```
/// let (lo, hi) = tricept_report::svg::range([1.0, 3.0], &[0.0]);
/// assert!(lo < 0.0 && hi > 3.0);
/// ```
pub fn range(values: impl IntoIterator<Item = f64>, include: &[f64]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().chain(include.iter().copied()) {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * (1.0 + hi.abs()) {
        let w = if hi == 0.0 { 1.0 } else { 0.5 * hi.abs() };
        return (lo - w, hi + w);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// A time axis in days for `days`: [`range`] of them, but at least one day
/// wide, so that checks made seconds apart (a script, a test) are drawn at
/// the left of a day rather than on an axis of millionths of a day whose
/// labels would not fit.
///
/// # Example
/// ```
/// let (lo, hi) = tricept_report::svg::days_range([0.0, 2e-7]);
/// assert!(hi - lo >= 1.0 && lo < 0.0 && hi > 1.0);
/// let (_, decimals) = tricept_report::svg::ticks(lo, hi, 6);
/// assert!(decimals <= 1);
/// // Checks weeks apart keep their own range.
/// assert_eq!(tricept_report::svg::days_range([0.0, 30.0]), tricept_report::svg::range([0.0, 30.0], &[]));
/// ```
pub fn days_range(days: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let days: Vec<f64> = days.into_iter().filter(|d| d.is_finite()).collect();
    let first = days.iter().copied().fold(f64::INFINITY, f64::min);
    let last = days.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if days.is_empty() || last - first >= 1.0 {
        return range(days, &[]);
    }
    (first - 0.05, first + 1.05)
}

/// Tick positions for `lo..hi`: steps of 1, 2 or 5 times a power of ten,
/// about `n` of them, with the decimals their labels need.
///
/// # Example
/// ```
/// let (ticks, decimals) = tricept_report::svg::ticks(0.0, 1.0, 5);
/// assert_eq!(ticks, vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]);
/// assert_eq!(decimals, 1);
/// ```
pub fn ticks(lo: f64, hi: f64, n: usize) -> (Vec<f64>, usize) {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return (vec![lo], 0);
    }
    let raw = span / n.max(1) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let ticks = (first..=last).map(|k| k as f64 * step).collect();
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    (ticks, decimals)
}

/// The colour of `t` in [0, 1] on cividis, a sequential scale whose
/// lightness grows steadily and which readers with any colour vision
/// deficiency read alike (Nunez, Anderton and Renslow 2018), as `#rrggbb`.
///
/// # Example
/// ```
/// assert_eq!(tricept_report::svg::cividis(0.0), "#00204d");
/// assert_eq!(tricept_report::svg::cividis(1.0), "#ffea46");
/// assert_eq!(tricept_report::svg::cividis(f64::NAN), "#00204d");
/// ```
pub fn cividis(t: f64) -> String {
    // The scale at 0, 1/4, 1/2, 3/4 and 1, linear between.
    const AT: [[f64; 3]; 5] = [
        [0.0, 32.0, 77.0],
        [65.0, 77.0, 107.0],
        [124.0, 123.0, 120.0],
        [188.0, 175.0, 111.0],
        [255.0, 234.0, 70.0],
    ];
    let x = 4.0
        * if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        };
    let k = (x.floor() as usize).min(3);
    let f = x - k as f64;
    let channel = |i: usize| (AT[k][i] + f * (AT[k + 1][i] - AT[k][i])).round() as u8;
    format!("#{:02x}{:02x}{:02x}", channel(0), channel(1), channel(2))
}

/// An accessible SVG plot under construction.
#[derive(Debug, Clone)]
pub struct Plot {
    id: String,
    title: String,
    desc: String,
    width: f64,
    height: f64,
    x: Scale,
    y: Scale,
    body: String,
}

/// The plot area's margins in plot units: left, right, top, bottom.
pub type Margins = (f64, f64, f64, f64);

impl Plot {
    /// A plot `width` x `height` (plot units; it scales to the page's
    /// width) of the data ranges `x` and `y`, with its title and its text
    /// alternative.
    pub fn new(
        id: &str,
        title: &str,
        desc: &str,
        (width, height): (f64, f64),
        (left, right, top, bottom): Margins,
        x: (f64, f64),
        y: (f64, f64),
    ) -> Plot {
        Plot {
            id: id.to_string(),
            title: title.to_string(),
            desc: desc.to_string(),
            width,
            height,
            x: Scale {
                lo: x.0,
                hi: x.1,
                a: left,
                b: width - right,
                log: false,
            },
            y: Scale {
                lo: y.0,
                hi: y.1,
                a: height - bottom,
                b: top,
                log: false,
            },
            body: String::new(),
        }
    }

    /// The y axis on a logarithmic scale (its range must be positive).
    pub fn log_y(mut self) -> Plot {
        self.y.log = true;
        self
    }

    /// Plot coordinates of a data point.
    pub fn at(&self, x: f64, y: f64) -> (f64, f64) {
        (self.x.px(x), self.y.px(y))
    }

    /// The frame, the ticks of both axes (none on an axis whose `n` is 0)
    /// and their labels.
    pub fn axes(&mut self, x_label: &str, y_label: &str, n: (usize, usize)) {
        let (x0, x1, y0, y1) = (self.x.a, self.x.b, self.y.a, self.y.b);
        let mut s = String::new();
        let _ = write!(
            s,
            "<rect class=\"frame\" x=\"{x0:.1}\" y=\"{y1:.1}\" width=\"{:.1}\" height=\"{:.1}\"/>",
            x1 - x0,
            y0 - y1
        );
        if n.0 > 0 {
            let (t, d) = ticks(self.x.lo.min(self.x.hi), self.x.lo.max(self.x.hi), n.0);
            for v in t {
                let px = self.x.px(v);
                let _ = write!(
                    s,
                    "<line class=\"grid\" x1=\"{px:.1}\" x2=\"{px:.1}\" y1=\"{y1:.1}\" y2=\"{y0:.1}\"/><text class=\"tick\" aria-hidden=\"true\" x=\"{px:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{v:.d$}</text>",
                    y0 + 14.0
                );
            }
        }
        if n.1 > 0 {
            let ticks: Vec<(f64, String)> = if self.y.log {
                log_ticks(self.y.lo, self.y.hi)
            } else {
                let (t, d) = ticks(self.y.lo.min(self.y.hi), self.y.lo.max(self.y.hi), n.1);
                t.into_iter().map(|v| (v, format!("{v:.d$}"))).collect()
            };
            for (v, label) in ticks {
                let py = self.y.px(v);
                let _ = write!(
                    s,
                    "<line class=\"grid\" x1=\"{x0:.1}\" x2=\"{x1:.1}\" y1=\"{py:.1}\" y2=\"{py:.1}\"/><text class=\"tick\" aria-hidden=\"true\" x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{label}</text>",
                    x0 - 4.0,
                    py + 4.0
                );
            }
        }
        if !x_label.is_empty() {
            let _ = write!(
                s,
                "<text class=\"axis\" x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
                0.5 * (x0 + x1),
                self.height - 4.0,
                escape(x_label)
            );
        }
        if !y_label.is_empty() {
            let _ = write!(
                s,
                "<text class=\"axis\" x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"start\">{}</text>",
                x0,
                y1 - 6.0,
                escape(y_label)
            );
        }
        // The frame and grid go under the marks drawn so far.
        s.push_str(&self.body);
        self.body = s;
    }

    /// A line through `points` (data coordinates).
    pub fn line(&mut self, points: &[(f64, f64)], class: &str) {
        if points.is_empty() {
            return;
        }
        let mut d = String::new();
        for (x, y) in points {
            let (px, py) = self.at(*x, *y);
            let _ = write!(d, "{px:.2},{py:.2} ");
        }
        let _ = write!(
            self.body,
            "<polyline class=\"{class}\" fill=\"none\" points=\"{}\"/>",
            d.trim_end()
        );
    }

    /// A filled area between `lower` and `upper` over `x`.
    pub fn band(&mut self, x: &[f64], lower: &[f64], upper: &[f64], class: &str) {
        let mut d = String::new();
        for (x, y) in x.iter().zip(upper) {
            let (px, py) = self.at(*x, *y);
            let _ = write!(d, "{px:.2},{py:.2} ");
        }
        for (x, y) in x.iter().zip(lower).rev() {
            let (px, py) = self.at(*x, *y);
            let _ = write!(d, "{px:.2},{py:.2} ");
        }
        let _ = write!(
            self.body,
            "<polygon class=\"{class}\" points=\"{}\"/>",
            d.trim_end()
        );
    }

    /// A point of radius `r` (plot units).
    pub fn point(&mut self, x: f64, y: f64, r: f64, class: &str) {
        let (px, py) = self.at(x, y);
        let _ = write!(
            self.body,
            "<circle class=\"{class}\" cx=\"{px:.2}\" cy=\"{py:.2}\" r=\"{r}\"/>"
        );
    }

    /// A segment between two data points.
    pub fn segment(&mut self, from: (f64, f64), to: (f64, f64), class: &str) {
        let (a, b) = (self.at(from.0, from.1), self.at(to.0, to.1));
        let _ = write!(
            self.body,
            "<line class=\"{class}\" x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\"/>",
            a.0, a.1, b.0, b.1
        );
    }

    /// A rectangle between two data corners, filled with `fill` when
    /// given (else by its class).
    pub fn rect(&mut self, c0: (f64, f64), c1: (f64, f64), class: &str, fill: Option<&str>) {
        let (a, b) = (self.at(c0.0, c0.1), self.at(c1.0, c1.1));
        let fill = fill.map(|f| format!(" fill=\"{f}\"")).unwrap_or_default();
        let _ = write!(
            self.body,
            "<rect class=\"{class}\"{fill} x=\"{:.2}\" y=\"{:.2}\" width=\"{:.2}\" height=\"{:.2}\"/>",
            a.0.min(b.0),
            a.1.min(b.1),
            (b.0 - a.0).abs(),
            (b.1 - a.1).abs()
        );
    }

    /// A text at a data point, anchored `start`, `middle` or `end`.
    pub fn label(&mut self, at: (f64, f64), text: &str, anchor: &str, class: &str) {
        let (px, py) = self.at(at.0, at.1);
        self.label_px((px, py), text, anchor, class);
    }

    /// A text at plot coordinates.
    pub fn label_px(&mut self, (px, py): (f64, f64), text: &str, anchor: &str, class: &str) {
        let _ = write!(
            self.body,
            "<text class=\"{class}\" x=\"{px:.1}\" y=\"{py:.1}\" text-anchor=\"{anchor}\">{}</text>",
            escape(text)
        );
    }

    /// The plot area's left and right edges, plot units.
    pub fn x_edges(&self) -> (f64, f64) {
        (self.x.a, self.x.b)
    }

    /// The plot area's bottom and top edges, plot units.
    pub fn y_edges(&self) -> (f64, f64) {
        (self.y.a, self.y.b)
    }

    /// The `<svg>` element.
    pub fn finish(self) -> String {
        let id = escape(&self.id);
        format!(
            "<svg class=\"plot\" id=\"{id}\" role=\"img\" aria-labelledby=\"{id}-t\" aria-describedby=\"{id}-d\" viewBox=\"0 0 {} {}\" preserveAspectRatio=\"xMidYMid meet\"><title id=\"{id}-t\">{}</title><desc id=\"{id}-d\">{}</desc>{}</svg>",
            self.width,
            self.height,
            escape(&self.title),
            escape(&self.desc),
            self.body
        )
    }
}

/// Decade ticks of a logarithmic axis, labelled `1e-3` ...
fn log_ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let (a, b) = (lo.min(hi), lo.max(hi));
    if !(a > 0.0 && b.is_finite()) {
        return Vec::new();
    }
    let (first, last) = (a.log10().ceil() as i32, b.log10().floor() as i32);
    let step = ((last - first) / 6 + 1).max(1);
    (first..=last)
        .step_by(step as usize)
        .map(|e| (10f64.powi(e), format!("1e{e}")))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_cover_the_range_with_round_steps() {
        let (t, d) = ticks(-0.013, 0.041, 6);
        assert_eq!(d, 2);
        assert!(t.first().unwrap() >= &-0.013 && t.last().unwrap() <= &0.041);
        assert!(t.windows(2).all(|w| ((w[1] - w[0]) - 0.01).abs() < 1e-12));
        assert_eq!(ticks(5.0, 5.0, 4), (vec![5.0], 0));
    }

    #[test]
    fn a_plot_is_an_image_with_its_text_alternative() {
        let mut p = Plot::new(
            "f1",
            "A <title>",
            "what it shows",
            (400.0, 200.0),
            (40.0, 10.0, 20.0, 30.0),
            (0.0, 10.0),
            (0.0, 1.0),
        );
        p.axes("x mm", "y", (5, 4));
        p.line(&[(0.0, 0.0), (10.0, 1.0)], "s1");
        let svg = p.finish();
        assert!(svg.starts_with("<svg class=\"plot\" id=\"f1\" role=\"img\""));
        assert!(svg.contains("<title id=\"f1-t\">A &lt;title&gt;</title>"));
        assert!(svg.contains("<desc id=\"f1-d\">what it shows</desc>"));
        assert!(svg.contains("points=\"40.00,170.00 390.00,20.00\""));
        assert_eq!(log_ticks(1e-3, 1.0).len(), 4);
    }
}
