//! Physical plausibility of fitted terms: every effect of the vocabulary
//! and every generic family has documented ranges (and signs) of its
//! physical quantities, declared once in its spec
//! ([`tricept_model::effects::EffectSpec::plausible`],
//! [`tricept_model::effects::GenericSpec::ranges`]); an estimate whose
//! 3-sigma interval misses the range is not a cause but evidence that the
//! real cause is something else.
//!
//! The ranges (`docs/diagnosis.md` gives the reasons) can be overridden for
//! other machines, e.g. aluminium legs (23 ppm/K) or CFRP legs (about
//! 0-2 ppm/K), from a JSON object `{"thermal.expansion_ppm_per_k": [20, 26]}`
//! (`tricept diagnose --plausibility FILE.json`). Every judged quantity is
//! judged: by its overridden range when the table has its key, else by its
//! spec's own.

use std::collections::BTreeMap;

use nalgebra::DMatrix;
use serde::Serialize;
use tricept_model::effects::{CauseName, EffectName, GenericFamily, Judgement};
use tricept_model::plausibility::{override_ranges, round3};

pub use tricept_model::plausibility::{PlausibilityError, Range};

/// The plausibility table: quantity key (`effect.quantity`) to range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plausibility {
    /// The ranges.
    pub ranges: BTreeMap<String, Range>,
}

/// The table key of a judged quantity of `cause`.
fn key(cause: CauseName, j: &Judgement) -> String {
    format!("{cause}.{}", j.range.quantity)
}

impl Default for Plausibility {
    /// Every range of the registry, vocabulary and generic families.
    ///
    /// # Example
    /// ```
    /// let p = tricept_diagnose::plausibility::Plausibility::default();
    /// assert_eq!(p.ranges["thermal.expansion_ppm_per_k"].max, 16.0);
    /// assert_eq!(p.ranges["reading-drift.s_um"].unit, "um");
    /// ```
    fn default() -> Plausibility {
        let mut ranges = BTreeMap::new();
        for e in EffectName::ALL {
            for j in e.spec().plausible {
                ranges.insert(format!("{e}.{}", j.range.quantity), j.range.to_range());
            }
        }
        for g in GenericFamily::ALL {
            for (_, r) in g.spec().ranges {
                ranges.insert(format!("{g}.{}", r.quantity), r.to_range());
            }
        }
        Plausibility { ranges }
    }
}

impl Plausibility {
    /// The default table with overrides from a JSON object of
    /// `key: [min, max]`.
    ///
    /// # Example
    /// ```
    /// use tricept_diagnose::plausibility::Plausibility;
    /// let p = Plausibility::with_overrides(r#"{"thermal.expansion_ppm_per_k": [20, 26]}"#).unwrap();
    /// assert_eq!(p.ranges["thermal.expansion_ppm_per_k"].min, 20.0);
    /// assert!(Plausibility::with_overrides(r#"{"thermal.alpha": [1, 2]}"#).is_err());
    /// ```
    pub fn with_overrides(json: &str) -> Result<Plausibility, PlausibilityError> {
        let mut p = Plausibility::default();
        override_ranges(&mut p.ranges, json)?;
        Ok(p)
    }

    /// `Ok` when every judged quantity of a fitted term of `cause` with
    /// parameters `values` (covariance `cov`) is plausible, else the reason
    /// (the first implausible quantity).
    pub(crate) fn judge(
        &self,
        cause: CauseName,
        judgements: &[Judgement],
        values: &[f64],
        cov: &DMatrix<f64>,
    ) -> Result<(), String> {
        let range_of = |j: &Judgement| {
            self.ranges
                .get(&key(cause, j))
                .cloned()
                .unwrap_or_else(|| j.range.to_range())
        };
        for j in judgements {
            let r = range_of(j);
            let (value, sd) = j.measure.evaluate(values, cov);
            if !r.admits(value, sd) {
                // A sign convention flips every quantity its hint covers.
                let hint = j.range.if_negated;
                let negated_plausible = judgements
                    .iter()
                    .filter(|k| k.range.if_negated == hint)
                    .all(|k| {
                        let (v, sd) = k.measure.evaluate(values, cov);
                        range_of(k).admits(-v, sd)
                    });
                let cause = if !hint.is_empty() && negated_plausible {
                    format!("; likely cause: {hint}")
                } else {
                    ": the real cause is something else".to_string()
                };
                return Err(format!(
                    "{} = {} +- {} {} is outside {} to {} {} ({}){cause}",
                    j.label,
                    round3(value),
                    round3(sd),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn judge(p: &Plausibility, e: EffectName, v: &[f64], sd: f64) -> Result<(), String> {
        let cov = DMatrix::from_diagonal_element(v.len(), v.len(), sd * sd);
        p.judge(e.into(), &e.judgements(), v, &cov)
    }

    #[test]
    fn the_issue_examples_are_implausible() {
        let p = Plausibility::default();
        // Negative thermal expansion.
        let r = judge(&p, EffectName::Thermal, &[-0.8], 0.2);
        assert!(r.unwrap_err().contains("outside 8 to 16 ppm/K"));
        // A noisy but compatible estimate is plausible.
        assert!(judge(&p, EffectName::Thermal, &[6.0], 1.0).is_ok());
        // 496 arcsec of eccentricity.
        let v = [400.0, 293.0, 1.0, 0.0];
        assert!(judge(&p, EffectName::EncoderEccentricity, &v, 5.0).is_err());
        // A -199 um U-joint offset.
        assert!(judge(&p, EffectName::UjointAxes, &[0.0, -199.0], 10.0).is_err());
        // Negative backlash, far from zero, on one leg: no sign convention
        // explains it.
        let one = judge(&p, EffectName::Backlash, &[5.0, -8.0, 5.0], 1.0).unwrap_err();
        assert!(one.contains("the real cause is something else"), "{one}");
        // On every leg: the `dir` columns' sign convention is flipped.
        let all = judge(&p, EffectName::Backlash, &[-6.0, -5.0, -8.0], 1.0).unwrap_err();
        assert!(
            all.contains("likely cause") && all.contains("`dir`"),
            "{all}"
        );
    }

    /// The keys are the `--plausibility` contract (docs/diagnosis.md).
    #[test]
    fn the_table_has_the_documented_keys() {
        let keys: Vec<String> = Plausibility::default().ranges.into_keys().collect();
        let mut documented = vec![
            "leg-lead.lead_ppm",
            "backlash.backlash_um",
            "thermal.expansion_ppm_per_k",
            "scale-gain.scale_gain_ppm",
            "encoder-eccentricity.amplitude_arcsec",
            "ujoint-axes.axis_skew_arcsec",
            "ujoint-axes.axis_offset_um",
            "tube-twist.twist_arcsec_per_100mm",
            "compliance.compliance_um_per_kn_at_1m",
            "leg-periodic.amplitude_um",
            "leg-periodic.period_mm",
            "leg-polynomial.peak_to_valley_um",
            "leg-step.step_um",
            "reading-drift.phi_arcsec",
            "reading-drift.theta_arcsec",
            "reading-drift.s_um",
            "reading-temperature.phi_arcsec_per_k",
            "reading-temperature.theta_arcsec_per_k",
            "reading-temperature.s_um_per_k",
            "leg-drift.leg_um",
            "encoder-gain.gain_ppm",
            "scale-polynomial.peak_to_valley_um",
            "reading-hysteresis.phi_arcsec",
            "reading-hysteresis.theta_arcsec",
            "reading-hysteresis.s_um",
        ];
        documented.sort_unstable();
        assert_eq!(keys, documented);
    }

    /// An overridden range is the one judged by (issue 32: the key of a
    /// judged quantity must find its override): aluminium legs' 20 to 26
    /// ppm/K, from the module's example.
    #[test]
    fn an_overridden_range_replaces_the_specs_own() {
        let json = r#"{"thermal.expansion_ppm_per_k": [20, 26]}"#;
        let p = Plausibility::with_overrides(json).expect("a known key");
        // 12 ppm/K: plausible for steel (8 to 16), not for aluminium.
        assert!(judge(&Plausibility::default(), EffectName::Thermal, &[12.0], 0.5).is_ok());
        let too_low = judge(&p, EffectName::Thermal, &[12.0], 0.5).unwrap_err();
        assert!(too_low.contains("outside 20 to 26 ppm/K"), "{too_low}");
        assert!(judge(&p, EffectName::Thermal, &[23.0], 0.5).is_ok());
    }

    /// A table without a key still judges by the spec's own range.
    #[test]
    fn a_missing_key_is_still_checked() {
        let empty = Plausibility {
            ranges: BTreeMap::new(),
        };
        assert!(judge(&empty, EffectName::Thermal, &[-0.8], 0.2).is_err());
    }
}
