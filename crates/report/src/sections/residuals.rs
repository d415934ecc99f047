//! Section 2: the residuals against the stated noise: the campaign's
//! residual rms per channel beside the noise the machine file states
//! (`tricept diagnose --data CAMPAIGN.csv --json`: `residual_rms_geometric`
//! and `noise.stated`, per logged reading), the fits' chi-square, and the
//! strongest structure left in the residuals.

use crate::html::{figure, list, p, section as wrap};
use crate::json::Lookup;
use crate::sources::Sources;
use crate::svg::{Plot, range};

const TITLE: &str = "2. Residuals against the stated noise";

/// The section.
pub fn section(l: &Lookup<'_>, sources: &Sources) -> String {
    let m = "machine";
    let mut s = p(&format!(
        "The calibration's fit: chi-square per degree of freedom {} on {} degrees of freedom (1 when the model explains the data to the stated noise); model adequate: {}.",
        l.num(m, "/calibration/chi2_per_dof"),
        l.num(m, "/calibration/dof"),
        l.text(m, "/calibration/adequate"),
    ));
    if sources.diagnosis.is_none() {
        s.push_str(&p(
            "The residuals of each channel need the campaign: give it to the report (<code>data</code>, CAMPAIGN.csv: the file the calibration was made from).",
        ));
        return wrap("residuals", TITLE, &s);
    }
    let d = "diagnosis";
    let panel = |id: &str, title: &str, unit: &str, channels: &[(&str, &str)]| {
        let values: Vec<f64> = channels
            .iter()
            .flat_map(|(_, key)| {
                [
                    l.f64(d, &format!("/residual_rms_geometric/{key}")),
                    l.f64(d, &format!("/noise/stated/{key}")),
                ]
            })
            .flatten()
            .collect();
        let (_, hi) = range(values, &[0.0]);
        let rows = channels.len() as f64;
        let mut plot = Plot::new(
            id,
            title,
            "Bars: the residual rms of each channel after the geometric fit; dashed lines: the stated noise of one logged reading; the values are in the text of this section.",
            (280.0, 60.0 + 34.0 * rows),
            (56.0, 12.0, 22.0, 36.0),
            (0.0, hi),
            (0.0, rows),
        );
        for (k, (name, key)) in channels.iter().enumerate() {
            let y = rows - k as f64 - 0.5;
            if let Some(v) = l.f64(d, &format!("/residual_rms_geometric/{key}")) {
                plot.rect((0.0, y - 0.25), (v, y + 0.25), "s1", None);
            }
            if let Some(v) = l.f64(d, &format!("/noise/stated/{key}")) {
                plot.segment((v, y - 0.42), (v, y + 0.42), "ref");
            }
            let (x0, _) = plot.x_edges();
            let (_, py) = plot.at(0.0, y);
            plot.label_px((x0 - 5.0, py + 4.0), name, "end", "axis");
        }
        plot.axes(unit, "", (4, 0));
        plot.finish()
    };
    let angles = panel(
        "fig-residuals-encoders",
        "Encoder residuals against the stated noise, arcsec",
        "residual rms, arcsec",
        &[("phi", "phi_arcsec"), ("theta", "theta_arcsec")],
    );
    let scale = panel(
        "fig-residuals-scale",
        "Linear scale residuals against the stated noise, um",
        "residual rms, um",
        &[("s", "s_um")],
    );
    s.push_str(&figure(
        &[angles, scale],
        "The campaign's residual rms per channel after the geometric fit (bars) and the noise the file states for one logged reading (dashed). A bar well past its line is a misfit the geometry alone leaves: what the diagnosis explains (section 3) or leaves (section 4).",
    ));
    let r = |key: &str| l.num(d, &format!("/residual_rms_geometric/{key}"));
    let n = |key: &str| l.num(d, &format!("/noise/stated/{key}"));
    s.push_str(&list(&[
        format!(
            "residual rms of the geometric fit: phi {} arcsec, theta {} arcsec, s {} um; stated noise: {} arcsec, {} arcsec, {} um",
            r("phi_arcsec"),
            r("theta_arcsec"),
            r("s_um"),
            n("phi_arcsec"),
            n("theta_arcsec"),
            n("s_um")
        ),
        format!(
            "geometric fit: chi-square {} for {} degrees of freedom (p = {}); the final model, with the causes the diagnosis names: chi-square {} for {} (p = {})",
            l.num(d, "/chi_square"),
            l.num(d, "/dof"),
            l.num(d, "/chi_square_p_value"),
            l.num(d, "/final/chi_square"),
            l.num(d, "/final/dof"),
            l.num(d, "/final/p_value"),
        ),
        format!("the noise: {}", l.text(d, "/noise/note")),
    ]));
    let structure: Vec<String> = (0..l.array(d, "/structure").len().min(3))
        .map(|k| {
            let q = |key: &str| format!("/structure/{k}/{key}");
            format!(
                "{} against {}: correlation {} (p = {})",
                l.text(d, &q("channel")),
                l.text(d, &q("regressor")),
                l.num(d, &q("correlation")),
                l.num(d, &q("p_value"))
            )
        })
        .collect();
    if !structure.is_empty() {
        s.push_str(&p(
            "The strongest structure in the residuals (a correlation with a small p-value is an effect the model misses):",
        ));
        s.push_str(&list(&structure));
    }
    wrap("residuals", TITLE, &s)
}
