//! Gross errors in small campaigns: a single 25-100 um misread of the
//! scale in a 40-pose campaign (the mean of 3 readings) must be flagged as
//! an outlier, by its line, and never explained as a physical effect.
//!
//! `cargo test -p tricept-diagnose --test diagnose small_campaigns:: -- --nocapture`
//! prints the tallies.

use crate::common::*;
use tricept_diagnose::finite::first_non_finite;
use tricept_model::effects::EffectName as E;

const SETS: u64 = 20;

#[test]
fn one_glitch_in_forty_poses_is_an_outlier() {
    let mut failures = Vec::new();
    for um in [25.0, 50.0, 75.0, 100.0] {
        let base = 0x6117 + um as u64 * 1000;
        let res = run_case(SETS, |i| {
            let mut s = simulate(40, base + i, Vec::new(), CampaignOptions::default());
            let j = (7 * i as usize + 3) % 40;
            s.data.poses[j].readings.s_mm += um * 1e-3 * if i % 2 == 0 { 1.0 } else { -1.0 };
            s
        });
        let mut flagged = 0;
        for (i, (s, d)) in res.iter().enumerate() {
            let line = s.data.poses[(7 * i + 3) % 40].line;
            let rows: Vec<u64> = d
                .causes
                .iter()
                .filter(|c| c.effect == E::Outliers)
                .flat_map(|c| c.rows.clone())
                .collect();
            let exact = rows == vec![line];
            flagged += usize::from(exact);
            let physical =
                d.causes.iter().any(|c| c.effect != E::Outliers) || !d.aliases.is_empty();
            if physical {
                failures.push(format!(
                    "{um} um, set {i} (line {line}): explained as a physical effect: {}",
                    summary(d)
                ));
            }
            if !exact {
                eprintln!(
                    "{um} um, set {i} (line {line}): flagged {rows:?}: {}",
                    summary(d)
                );
            }
        }
        tally(
            &format!("one {um} um scale glitch"),
            40,
            "exactly the glitch flagged",
            flagged,
            SETS as usize,
        );
        if flagged < 19 {
            failures.push(format!(
                "{um} um: exactly the glitch flagged in {flagged}/{SETS}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The last guard: a non-finite number anywhere in a report is found, by
/// its path (the diagnosis returns an error instead of such a report).
#[test]
fn a_non_finite_number_in_a_report_is_caught() {
    let (_, mut d) = run_case(1, |_| {
        simulate(40, 0xf1, Vec::new(), CampaignOptions::default())
    })
    .pop()
    .expect("one diagnosis");
    assert_eq!(first_non_finite(&d), None);
    d.gain.holdout_rms_extended = f64::NAN;
    assert_eq!(
        first_non_finite(&d).as_deref(),
        Some("gain.holdout_rms_extended")
    );
    d.gain.holdout_rms_extended = 1.0;
    d.extended[3].value = f64::INFINITY;
    let path = first_non_finite(&d).unwrap_or_default();
    assert!(path.starts_with("extended."), "{path}");
}
