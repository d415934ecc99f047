//! Physical plausibility of fitted terms: every effect of the vocabulary
//! and every generic family has a documented range (and sign) of its
//! physical quantities; an estimate whose 3-sigma interval misses the range
//! is not a cause but evidence that the real cause is something else.
//!
//! The ranges (`docs/diagnosis.md` gives the reasons) can be overridden for
//! other machines, e.g. aluminium legs (23 ppm/K) or CFRP legs (about
//! 0-2 ppm/K), from a JSON object `{"thermal.expansion_ppm_per_k": [20, 26]}`
//! (`tricept diagnose --plausibility FILE.json`).

use std::collections::BTreeMap;

use nalgebra::DMatrix;
use serde::Serialize;
use tricept_model::effects::{EffectName, GenericFamily, legendre_p2, legendre_p3};

use crate::terms::{CHANNELS, GenericTerm, Term};

pub use tricept_model::plausibility::{PlausibilityError, Range};
use tricept_model::plausibility::{insert_range, round3};

/// The plausibility table: quantity key (`effect.quantity`) to range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plausibility {
    /// The ranges.
    pub ranges: BTreeMap<String, Range>,
}

/// A quantity of a fitted term that the table judges.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Quantity {
    /// Table key.
    pub(crate) key: String,
    /// What it is, for messages (`amplitude of leg 2`).
    pub(crate) label: String,
    /// Estimate.
    pub(crate) value: f64,
    /// Its standard deviation.
    pub(crate) sd: f64,
}

impl Default for Plausibility {
    fn default() -> Plausibility {
        let mut ranges = BTreeMap::new();
        let mut add = |key: &str, min: f64, max: f64, unit: &'static str, why: &str| {
            insert_range(&mut ranges, key, min, max, unit, why)
        };
        add(
            "leg-lead.lead_ppm",
            -300.0,
            300.0,
            "ppm",
            "ball-screw lead deviations are tens of ppm",
        );
        add(
            "backlash.backlash_um",
            0.0,
            50.0,
            "um",
            "lost motion is positive: the nut lags",
        );
        add(
            "thermal.expansion_ppm_per_k",
            8.0,
            16.0,
            "ppm/K",
            "steel or cast-iron legs",
        );
        add(
            "scale-gain.scale_gain_ppm",
            -300.0,
            300.0,
            "ppm",
            "glass scales and their mounting",
        );
        add(
            "encoder-eccentricity.amplitude_arcsec",
            0.0,
            60.0,
            "arcsec",
            "10 um of eccentricity on a 35-50 mm graduation radius",
        );
        add(
            "ujoint-axes.axis_skew_arcsec",
            -300.0,
            300.0,
            "arcsec",
            "machining of the U-joint cross",
        );
        add(
            "ujoint-axes.axis_offset_um",
            -100.0,
            100.0,
            "um",
            "bore and cross tolerances",
        );
        add(
            "tube-twist.twist_arcsec_per_100mm",
            -50.0,
            50.0,
            "arcsec per 100 mm",
            "guide-rail twist tolerances (150 arcsec over the stroke)",
        );
        add(
            "compliance.compliance_um_per_kn_at_1m",
            0.0,
            200.0,
            "um/kN at 1 m",
            "tension stretches the legs; 5 N/um is a very soft leg",
        );
        add(
            "leg-periodic.amplitude_um",
            0.0,
            25.0,
            "um",
            "pitch errors of precision screws",
        );
        add("leg-periodic.period_mm", 1.0, 200.0, "mm", "a screw lead");
        add(
            "leg-polynomial.peak_to_valley_um",
            0.0,
            50.0,
            "um",
            "travel variation of transport-grade screws",
        );
        add(
            "reading-drift.phi_arcsec",
            -30.0,
            30.0,
            "arcsec",
            "beyond: a sensor fault, not a drift",
        );
        add(
            "reading-drift.theta_arcsec",
            -30.0,
            30.0,
            "arcsec",
            "beyond: a sensor fault, not a drift",
        );
        add(
            "reading-drift.s_um",
            -50.0,
            50.0,
            "um",
            "beyond: a sensor fault, not a drift",
        );
        add(
            "reading-temperature.phi_arcsec_per_k",
            -10.0,
            10.0,
            "arcsec/K",
            "thermal bending of a sensor mount",
        );
        add(
            "reading-temperature.theta_arcsec_per_k",
            -10.0,
            10.0,
            "arcsec/K",
            "thermal bending of a sensor mount",
        );
        add(
            "reading-temperature.s_um_per_k",
            -20.0,
            20.0,
            "um/K",
            "a 2 m steel path",
        );
        add(
            "leg-drift.leg_um",
            -50.0,
            50.0,
            "um",
            "creep or drive warm-up over a campaign",
        );
        add(
            "encoder-gain.gain_ppm",
            -1000.0,
            1000.0,
            "ppm",
            "encoder scaling or interpolation faults",
        );
        add(
            "scale-polynomial.peak_to_valley_um",
            0.0,
            20.0,
            "um",
            "scale bending or mounting",
        );
        add(
            "reading-hysteresis.phi_arcsec",
            0.0,
            5.0,
            "arcsec",
            "encoder reversal error (lag)",
        );
        add(
            "reading-hysteresis.theta_arcsec",
            0.0,
            5.0,
            "arcsec",
            "encoder reversal error (lag)",
        );
        add(
            "reading-hysteresis.s_um",
            0.0,
            2.0,
            "um",
            "scale reversal error (lag)",
        );
        Plausibility { ranges }
    }
}

impl Plausibility {
    /// The default table with overrides from a JSON object of
    /// `key: [min, max]`.
    ///
    /// # Example
    /// ```
    /// use tricept_diagnose::Plausibility;
    /// let p = Plausibility::with_overrides(r#"{"thermal.expansion_ppm_per_k": [20, 26]}"#).unwrap();
    /// assert_eq!(p.ranges["thermal.expansion_ppm_per_k"].min, 20.0);
    /// assert!(Plausibility::with_overrides(r#"{"thermal.alpha": [1, 2]}"#).is_err());
    /// ```
    pub fn with_overrides(json: &str) -> Result<Plausibility, PlausibilityError> {
        let mut p = Plausibility::default();
        tricept_model::plausibility::override_ranges(&mut p.ranges, json)?;
        Ok(p)
    }

    /// `Ok` when every quantity of the fitted term is plausible, else the
    /// reason (the first implausible quantity).
    pub(crate) fn check(&self, quantities: &[Quantity]) -> Result<(), String> {
        for q in quantities {
            let Some(r) = self.ranges.get(&q.key) else {
                continue;
            };
            if !r.admits(q.value, q.sd) {
                return Err(format!(
                    "{} = {} +- {} {} is outside {} to {} {} ({}): the real cause is something else",
                    q.label,
                    round3(q.value),
                    round3(q.sd),
                    r.unit,
                    r.min,
                    r.max,
                    r.unit,
                    r.why
                ));
            }
        }
        Ok(())
    }
}

/// Amplitude `sqrt(a^2 + b^2)` and its standard deviation (delta method).
fn amplitude(a: f64, b: f64, caa: f64, cab: f64, cbb: f64) -> (f64, f64) {
    let r = a.hypot(b);
    if r == 0.0 {
        return (0.0, caa.max(cbb).max(0.0).sqrt());
    }
    let var = (a * a * caa + 2.0 * a * b * cab + b * b * cbb) / (r * r);
    (r, var.max(0.0).sqrt())
}

/// Peak-to-valley of `c2 P2(x) + c3 P3(x)` over `[-1, 1]` and its standard
/// deviation (delta method, numerical gradient).
fn peak_to_valley(c2: f64, c3: f64, c22: f64, c23: f64, c33: f64) -> (f64, f64) {
    let pv = |a: f64, b: f64| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=200 {
            let x = -1.0 + 0.01 * i as f64;
            let y = a * legendre_p2(x) + b * legendre_p3(x);
            lo = lo.min(y);
            hi = hi.max(y);
        }
        hi - lo
    };
    let v = pv(c2, c3);
    let h = 1e-6 * (c2.abs() + c3.abs()).max(1e-3);
    let g2 = (pv(c2 + h, c3) - pv(c2 - h, c3)) / (2.0 * h);
    let g3 = (pv(c2, c3 + h) - pv(c2, c3 - h)) / (2.0 * h);
    let var = g2 * g2 * c22 + 2.0 * g2 * g3 * c23 + g3 * g3 * c33;
    (v, var.max(0.0).sqrt())
}

/// The judged quantities of a fitted term with parameters `v` (in its
/// parameter order), covariance `cov`, and for `leg-periodic` the period's
/// standard deviation.
pub(crate) fn quantities(term: &Term, v: &[f64], cov: &DMatrix<f64>) -> Vec<Quantity> {
    let sd = |i: usize| cov.get((i, i)).copied().unwrap_or(0.0).max(0.0).sqrt();
    let c = |i: usize, j: usize| cov.get((i, j)).copied().unwrap_or(0.0);
    let q = |key: &str, label: String, value: f64, sd: f64| Quantity {
        key: key.to_string(),
        label,
        value,
        sd,
    };
    let mut out = Vec::new();
    match term {
        Term::Catalogue(cand) => {
            let e = cand.0;
            let names = cand.params();
            match e {
                EffectName::EncoderEccentricity => {
                    for (k, enc) in ["phi", "theta"].iter().enumerate() {
                        let (a, s) = amplitude(
                            v[2 * k],
                            v[2 * k + 1],
                            c(2 * k, 2 * k),
                            c(2 * k, 2 * k + 1),
                            c(2 * k + 1, 2 * k + 1),
                        );
                        out.push(q(
                            "encoder-eccentricity.amplitude_arcsec",
                            format!("eccentricity of the {enc} encoder"),
                            a,
                            s,
                        ));
                    }
                }
                EffectName::LegLead | EffectName::Backlash => {
                    let key = if e == EffectName::LegLead {
                        "leg-lead.lead_ppm"
                    } else {
                        "backlash.backlash_um"
                    };
                    for i in 0..3 {
                        out.push(q(key, names[i].to_string(), v[i], sd(i)));
                    }
                }
                _ => {
                    for (i, n) in names.iter().enumerate() {
                        out.push(q(&format!("{e}.{n}"), n.to_string(), v[i], sd(i)));
                    }
                }
            }
        }
        Term::Generic(g) => out.extend(generic_quantities(g, v, cov)),
    }
    out
}

fn generic_quantities(g: &GenericTerm, v: &[f64], cov: &DMatrix<f64>) -> Vec<Quantity> {
    let sd = |i: usize| cov.get((i, i)).copied().unwrap_or(0.0).max(0.0).sqrt();
    let c = |i: usize, j: usize| cov.get((i, j)).copied().unwrap_or(0.0);
    let mut out = Vec::new();
    let family = g.family;
    let mut push = |key: String, label: String, value: f64, sd: f64| {
        out.push(Quantity {
            key,
            label,
            value,
            sd,
        })
    };
    match family {
        GenericFamily::LegPeriodic | GenericFamily::LegPolynomial => {
            let width = if family == GenericFamily::LegPeriodic {
                2
            } else {
                3
            };
            for (k, leg) in g.legs().into_iter().enumerate() {
                // The curvature coefficients (P2, P3) of a polynomial follow
                // its linear part (P1, a lead: judged by the leads' range
                // through the peak-to-valley of the curvature only).
                let (a, b) = (width * k + width - 2, width * k + width - 1);
                if family == GenericFamily::LegPeriodic {
                    let (amp, s) = amplitude(v[a], v[b], c(a, a), c(a, b), c(b, b));
                    push(
                        "leg-periodic.amplitude_um".into(),
                        format!("periodic amplitude of leg {}", leg + 1),
                        amp,
                        s,
                    );
                } else {
                    let (pv, s) = peak_to_valley(v[a], v[b], c(a, a), c(a, b), c(b, b));
                    push(
                        "leg-polynomial.peak_to_valley_um".into(),
                        format!("peak-to-valley of leg {}'s polynomial error", leg + 1),
                        pv,
                        s,
                    );
                }
            }
            if let Some(p) = g.period_mm {
                push("leg-periodic.period_mm".into(), "period".into(), p, 0.0);
            }
        }
        GenericFamily::ScalePolynomial => {
            let (pv, s) = peak_to_valley(v[0], v[1], c(0, 0), c(0, 1), c(1, 1));
            push(
                "scale-polynomial.peak_to_valley_um".into(),
                "peak-to-valley of the scale's polynomial error".into(),
                pv,
                s,
            );
        }
        GenericFamily::LegDrift => {
            for (k, leg) in g.legs().into_iter().enumerate() {
                push(
                    "leg-drift.leg_um".into(),
                    format!("drift of leg {} over the campaign", leg + 1),
                    v[k],
                    sd(k),
                );
            }
        }
        GenericFamily::EncoderGain => {
            let ch = CHANNELS[g.channel().unwrap_or(0)];
            push(
                "encoder-gain.gain_ppm".into(),
                format!("gain error of the {ch} encoder"),
                v[0],
                sd(0),
            );
        }
        GenericFamily::ReadingDrift
        | GenericFamily::ReadingTemperature
        | GenericFamily::ReadingHysteresis => {
            let param = g.params().first().cloned().unwrap_or_default();
            push(
                format!("{family}.{param}"),
                format!("{family} {param}"),
                v[0],
                sd(0),
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Candidate;

    #[test]
    fn the_issue_examples_are_implausible() {
        let p = Plausibility::default();
        let cov = |s: f64, k: usize| DMatrix::from_diagonal_element(k, k, s * s);
        // Negative thermal expansion.
        let thermal = Term::Catalogue(Candidate(EffectName::Thermal));
        let r = p.check(&quantities(&thermal, &[-0.8], &cov(0.2, 1)));
        assert!(r.unwrap_err().contains("outside 8 to 16 ppm/K"));
        // A noisy but compatible estimate is plausible.
        assert!(p.check(&quantities(&thermal, &[6.0], &cov(1.0, 1))).is_ok());
        // 496 arcsec of eccentricity.
        let ecc = Term::Catalogue(Candidate(EffectName::EncoderEccentricity));
        let v = [400.0, 293.0, 1.0, 0.0];
        assert!(p.check(&quantities(&ecc, &v, &cov(5.0, 4))).is_err());
        // A -199 um U-joint offset.
        let uj = Term::Catalogue(Candidate(EffectName::UjointAxes));
        assert!(
            p.check(&quantities(&uj, &[0.0, -199.0], &cov(10.0, 2)))
                .is_err()
        );
        // Negative backlash, far from zero.
        let bl = Term::Catalogue(Candidate(EffectName::Backlash));
        assert!(
            p.check(&quantities(&bl, &[5.0, -8.0, 5.0], &cov(1.0, 3)))
                .is_err()
        );
    }

    #[test]
    fn amplitude_and_peak_to_valley() {
        let (a, s) = amplitude(3.0, 4.0, 1.0, 0.0, 1.0);
        assert!((a - 5.0).abs() < 1e-12 && (s - 1.0).abs() < 1e-12);
        // P2 alone: from -1/2 at 0 to 1 at +-1.
        let (pv, _) = peak_to_valley(2.0, 0.0, 0.0, 0.0, 0.0);
        assert!((pv - 3.0).abs() < 1e-9);
    }
}
