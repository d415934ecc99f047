//! A named cause in words a machine builder can act on: an effect of the
//! vocabulary by its spec's description and estimates
//! ([`tricept_model::effects::EffectSpec::description`]); a generic term by
//! what its fitted form reads as (a screw lead, a curved leg, a worn
//! segment, a drift),
//! with the alternatives this campaign cannot tell from it.

use tricept_model::effects::{CHANNELS, GenericFamily, legendre_p2, legendre_p3};

use crate::fit::{Fit, term_estimates};
use crate::terms::{Frame, Term};

/// Standard screw leads, mm.
const SCREW_LEADS_MM: [f64; 12] = [
    4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0, 40.0, 50.0,
];

/// One-line description of a named term.
pub(crate) fn describe(
    term: &Term,
    fit: &Fit,
    frame: &Frame,
    period_sd: Option<f64>,
    edges_sd: [Option<f64>; 2],
    alternatives: &[String],
) -> String {
    let (v, cov) = term_estimates(fit, term);
    let sd = |i: usize| cov[(i, i)].max(0.0).sqrt();
    let pm = |i: usize| format!("{:.1} +- {:.1}", v[i], sd(i));
    let legs_list = |legs: &[usize]| {
        let names: Vec<String> = legs.iter().map(|i| (i + 1).to_string()).collect();
        format!(
            "leg{} {}",
            if legs.len() > 1 { "s" } else { "" },
            names.join(", ")
        )
    };
    let or_alternatives = if alternatives.is_empty() {
        String::new()
    } else {
        format!(
            " (or, indistinguishably on this campaign: {})",
            alternatives.join(", ")
        )
    };
    let text = match term {
        Term::Catalogue(e) => {
            let params: Vec<String> = e
                .parameter_names()
                .iter()
                .enumerate()
                .map(|(i, n)| format!("{n} {}", pm(i)))
                .collect();
            format!("{}: {}", e.spec().description, params.join(", "))
        }
        Term::Generic(g) => {
            let legs = g.legs();
            match g.family {
                GenericFamily::LegPeriodic => {
                    let period = g.period_mm.unwrap_or(f64::NAN);
                    let amps: Vec<String> = (0..legs.len())
                        .map(|k| format!("{:.1}", v[2 * k].hypot(v[2 * k + 1])))
                        .collect();
                    let sd_text = period_sd.map_or(String::new(), |s| format!(" +- {s:.3}"));
                    let lead = SCREW_LEADS_MM.iter().find(|&&l| {
                        (period - l).abs() <= 3.0 * period_sd.unwrap_or(0.0) + 0.005 * l
                    });
                    // A harmonic of another periodic term of the model: the
                    // error is periodic but not sinusoidal.
                    let fundamental = fit.model.terms().iter().find_map(|t| match t {
                        Term::Generic(o) if o.period_mm.is_some_and(|p| p > 1.5 * period) => {
                            let p = o.period_mm.unwrap_or(f64::NAN);
                            let k = (p / period).round();
                            ((p / period - k).abs() < 0.01 * k).then_some((p, k))
                        }
                        _ => None,
                    });
                    format!(
                        "{}: length error periodic in the leg length, period {period:.3}{sd_text} mm, amplitude {} um: {}",
                        legs_list(&legs),
                        amps.join(" / "),
                        match (fundamental, lead) {
                            (Some((p, k)), _) => format!(
                                "harmonic {k:.0} of the {p:.3} mm period: that periodic error is not a sine"
                            ),
                            (None, Some(l)) => format!("ball-screw pitch error ({l} mm lead)?"),
                            (None, None) => "a periodic error of the drive (screw pitch, gear or encoder of the drive)?".into(),
                        }
                    )
                }
                GenericFamily::LegPolynomial => {
                    let parts: Vec<String> = legs
                        .iter()
                        .enumerate()
                        .map(|(k, i)| {
                            let [lo, hi] = frame.leg_range_mm[*i];
                            let (c1, a, b) = (v[3 * k], v[3 * k + 1], v[3 * k + 2]);
                            let curve = |x: f64| {
                                a * legendre_p2(x)
                                    + b * legendre_p3(x)
                            };
                            let (mn, mx) = (0..=100)
                                .map(|s| curve(-1.0 + 0.02 * s as f64))
                                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
                                    (l.min(y), h.max(y))
                                });
                            let lead_ppm = c1 / (0.5 * (hi - lo)).max(1e-9) * 1e3;
                            format!(
                                "leg {}: curvature {:.1} um peak-to-valley over {lo:.0}-{hi:.0} mm, linear part {lead_ppm:.0} ppm",
                                i + 1,
                                mx - mn
                            )
                        })
                        .collect();
                    format!(
                        "length error curved along the stroke ({}): ball-screw travel variation (and mean travel deviation) or a bent guide?",
                        parts.join("; ")
                    )
                }
                GenericFamily::LegStep => {
                    let [a, b] = g.edges_mm.unwrap_or([f64::NAN; 2]);
                    let [lo, hi] = legs
                        .first()
                        .map_or([f64::NAN; 2], |&i| frame.leg_range_mm[i]);
                    let edge = |x: f64, sd: Option<f64>, end: &str| match sd {
                        Some(sd) => format!("{x:.1} +- {sd:.1} mm"),
                        None => format!("{x:.1} mm ({end})"),
                    };
                    let reads_as = match (a <= lo, b >= hi) {
                        (false, false) => "a worn screw segment (a step at each edge)?".to_string(),
                        (true, _) => format!(
                            "a step of the screw at {b:.1} mm (a worn segment reaching beyond the campaign's stroke)?"
                        ),
                        (false, true) => format!(
                            "a step of the screw at {a:.1} mm (a worn segment reaching beyond the campaign's stroke)?"
                        ),
                    };
                    format!(
                        "{}: length error of {} um while the command is from {} to {}: {reads_as}",
                        legs_list(&legs),
                        pm(0),
                        edge(a, edges_sd[0], "the campaign's smallest command"),
                        edge(b, edges_sd[1], "the campaign's largest command"),
                    )
                }
                GenericFamily::LegDrift => {
                    let d: Vec<String> = (0..legs.len()).map(pm).collect();
                    format!(
                        "{}: lengths drift by {} um over the campaign: creep or drive warm-up?",
                        legs_list(&legs),
                        d.join(" / ")
                    )
                }
                GenericFamily::ReadingDrift => {
                    let c = g.channel().unwrap_or(2);
                    let unit = if c == 2 { "um" } else { "arcsec" };
                    let temperature = if alternatives
                        .iter()
                        .any(|a| a.starts_with("reading-temperature") || a == "thermal")
                    {
                        "with time or with temperature (they followed each other during the campaign)"
                    } else if frame.temperature_follows_time() {
                        "with time or with the logged temperature, which followed time during the campaign"
                    } else if frame.temperature.is_some() {
                        "independent of temperature"
                    } else {
                        "with time (no varying temperature was logged to tell)"
                    };
                    format!(
                        "{} reading drifts {} {unit} over the campaign, {temperature}",
                        CHANNELS[c],
                        pm(0)
                    )
                }
                GenericFamily::ReadingTemperature => {
                    let c = g.channel().unwrap_or(2);
                    let unit = if c == 2 { "um/K" } else { "arcsec/K" };
                    format!(
                        "{} reading changes by {} {unit} with the logged temperature: thermal drift of the sensor or its mount?",
                        CHANNELS[c],
                        pm(0)
                    )
                }
                GenericFamily::EncoderGain => {
                    let c = g.channel().unwrap_or(0);
                    format!(
                        "the {} encoder reads (1 + g) times the angle, g = {} ppm: encoder gain (scaling or interpolation) error?",
                        CHANNELS[c],
                        pm(0)
                    )
                }
                GenericFamily::ScalePolynomial => format!(
                    "scale reading error curved along the UP-limb stroke (P2 {} um, P3 {} um): scale bending or mounting?",
                    pm(0),
                    pm(1)
                ),
                GenericFamily::ReadingHysteresis => {
                    let c = g.channel().unwrap_or(2);
                    let unit = if c == 2 { "um" } else { "arcsec" };
                    format!(
                        "{} reading lags in the direction the sensor moved: reversal error {} {unit}",
                        CHANNELS[c],
                        pm(0)
                    )
                }
            }
        }
    };
    format!("{text}{or_alternatives}")
}
