//! Effects outside the vocabulary, on realistic campaigns (40, 80, 200
//! random poses, one approach direction, the mean of 3 readings): the
//! diagnosis must never dress them up as a known effect, and its generic
//! dictionary must describe them (family, leg or channel, period).
//!
//! Expectations come from the simulator's inputs only. Each case prints
//! `TALLY` lines (`cargo test -p tricept-diagnose --test diagnose
//! out_of_vocabulary:: -- --nocapture`), quoted in `docs/diagnosis.md`.
//!
//! What is asserted is what the campaigns can physically show (design and
//! detectability numbers in `docs/diagnosis.md`): a 100-300 ppm encoder
//! gain is named only at 200 poses (at 40 and 80 poses its signature is
//! below detection in most sets); at every size it must not be named as
//! an eccentricity alone.

use crate::common::*;
use tricept_diagnose::detect::detectability;
use tricept_diagnose::{Diagnosis, report::Verdict};
use tricept_engine::model::GeometricModel;
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_model::effects::{CauseName, EffectName as E, GenericFamily as G};
use tricept_plant::effects::{Effect, Waveform};

const SIZES: [usize; 3] = [40, 80, 200];
const SETS: u64 = 20;

/// A catalogue effect named while the final model claims to explain the
/// data: an out-of-vocabulary effect dressed up as a known one.
fn dressed_up(d: &Diagnosis, allowed: &[E]) -> bool {
    d.final_adequate && catalogue_named(d).iter().any(|e| !allowed.contains(e))
}

/// Runs one out-of-vocabulary case at every size; `right` judges a
/// diagnosis from the simulator's inputs.
fn case(
    name: &str,
    base: u64,
    sizes: &[usize],
    make: impl Fn(&mut rand_pcg::Pcg64Mcg) -> Effect + Sync,
    right: impl Fn(&Simulated, &Diagnosis) -> bool,
    allowed: impl Fn(&Simulated, &Diagnosis) -> Vec<E>,
    required: impl Fn(usize) -> usize,
) {
    let mut failures = Vec::new();
    for &n in sizes {
        let res = run_case(SETS, |i| {
            let seed = base + i;
            let e = make(&mut rng(base, seed));
            simulate(n, seed, vec![e], CampaignOptions::default())
        });
        let (mut good, mut dressed) = (0, 0);
        for (i, (s, d)) in res.iter().enumerate() {
            let ok = right(s, d);
            good += usize::from(ok);
            let bad = dressed_up(d, &allowed(s, d));
            dressed += usize::from(bad);
            for v in invariants(d) {
                failures.push(format!("{name} n={n} set {i}: {v}"));
            }
            if bad {
                failures.push(format!(
                    "{name} n={n} set {i}: a catalogue effect explains it: {}",
                    summary(d)
                ));
            }
            if !ok {
                eprintln!(
                    "{name} n={n} set {i} not right: {} ({:?})",
                    summary(d),
                    s.effects
                );
            }
        }
        tally(
            name,
            n,
            "right family, leg/channel and form",
            good,
            SETS as usize,
        );
        tally(
            name,
            n,
            "catalogue effect named with final_adequate true",
            dressed,
            SETS as usize,
        );
        if good < required(n) {
            failures.push(format!(
                "{name} n={n}: right in {good}/{SETS}, {} required",
                required(n)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn pitch_is_named() {
    case(
        "leg-periodic 4 um, 10 mm",
        0x9170,
        &SIZES,
        |r| {
            Effect::from(tricept_plant::effects::LegPeriodic {
                um: [4.0; 3],
                period_mm: 10.0,
                phase_deg: std::array::from_fn(|_| uniform(r, 0.0, 360.0)),
                waveform: Waveform::Sine,
            })
        },
        |_, d| {
            d.causes.iter().any(|c| {
                let period = c.parameters.iter().find(|p| p.name.ends_with("period_mm"));
                c.effect == G::LegPeriodic
                    && c.legs == vec![1, 2, 3]
                    && period.is_some_and(|p| {
                        (p.value - 10.0).abs() <= 3.0 * p.std_dev.unwrap_or(0.0) + 0.05
                    })
            })
        },
        |_, _| Vec::new(),
        |_| 16,
    );
}

/// The lead error implied by a quadratic centred away from the campaign's
/// middle: its linear part over the campaign's commands (least squares).
fn implied_leads(s: &Simulated) -> Vec<f64> {
    let Some(&tricept_plant::effects::LegQuadratic {
        um,
        centre_mm,
        half_width_mm,
    }) = s.effects[0].input()
    else {
        return vec![0.0; 3];
    };
    (0..3)
        .map(|i| {
            let q: Vec<f64> = s.data.poses.iter().map(|p| p.commands_mm[i]).collect();
            let y: Vec<f64> = q
                .iter()
                .map(|v| um[i] * ((v - centre_mm) / half_width_mm).powi(2))
                .collect();
            let n = q.len() as f64;
            let (mq, my) = (q.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
            let sxy: f64 = q.iter().zip(&y).map(|(a, b)| (a - mq) * (b - my)).sum();
            let sxx: f64 = q.iter().map(|a| (a - mq).powi(2)).sum();
            // um per mm = ppm * 1e-3.
            sxy / sxx * 1e3
        })
        .collect()
}

#[test]
fn quadratic_is_named() {
    let m = Machine::paper();
    let geometric = GeometricModel::new(m.clone(), ParameterSet::paper15());
    case(
        "leg-quadratic 5-15 um",
        0x9a0d,
        &SIZES,
        |r| {
            Effect::from(tricept_plant::effects::LegQuadratic {
                um: std::array::from_fn(|_| sign(r) * uniform(r, 5.0, 15.0)),
                centre_mm: 845.0,
                half_width_mm: 250.0,
            })
        },
        |_, d| {
            d.causes
                .iter()
                .filter(|c| c.effect == G::LegPolynomial)
                .flat_map(|c| c.legs.clone())
                .collect::<std::collections::BTreeSet<u8>>()
                .len()
                == 3
        },
        // The lead a quadratic centred away from the campaign implies may
        // be named when it is detectable (95 % power at alpha).
        |s, _| {
            let lambda = detectability(
                &geometric,
                E::LegLead,
                &implied_leads(s),
                &s.data.poses,
                s.sigma,
                1e-3,
            )
            .map_or(0.0, |d| d.noncentrality);
            if lambda > 24.4 {
                vec![E::LegLead]
            } else {
                Vec::new()
            }
        },
        |_| 16,
    );
}

/// A worn segment of one leg's screw, 2.5-4 um of either sign: inside the
/// campaign's stroke (both edges), or reaching beyond it at one end (a
/// single step), by data set.
fn worn_segment(r: &mut rand_pcg::Pcg64Mcg, set: u64) -> Effect {
    let leg = (uniform(r, 0.0, 3.0) as usize).min(2);
    let mut um = [0.0; 3];
    um[leg] = sign(r) * uniform(r, 2.5, 4.0);
    let (from, to) = (uniform(r, 700.0, 760.0), uniform(r, 900.0, 960.0));
    let (from_mm, to_mm) = match set % 3 {
        0 => (from, to),
        1 => (from, 1200.0),
        _ => (400.0, to),
    };
    Effect::from(tricept_plant::effects::LegStep { um, from_mm, to_mm })
}

/// The edges of a step inside `[lo, hi]` with the jump of the leg's
/// length at each (a step going up as the command increases is positive):
/// `h` over `[a, b]` jumps by `h` at `a` and by `-h` at `b`. A one-edge
/// step and its complement (`-h` outside the segment) are the same machine
/// up to a leg offset, and have the same edges and jumps.
fn jumps(h: f64, a: f64, b: f64, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    [(a, h), (b, -h)]
        .into_iter()
        .filter(|(e, _)| *e > lo && *e < hi)
        .collect()
}

/// Whether `d` names the simulated step on its leg: the same edges inside
/// the campaign's stroke, each placed within two poses of the simulator's
/// (at most two of the leg's commands between them) or within 3 standard
/// deviations, with the same jumps of the leg's length within 3 standard
/// deviations plus 0.3 um.
fn step_found(s: &Simulated, d: &Diagnosis) -> bool {
    let Some(&tricept_plant::effects::LegStep { um, from_mm, to_mm }) = s.effects[0].input() else {
        return false;
    };
    let Some(leg) = um.iter().position(|u| *u != 0.0) else {
        return false;
    };
    let q: Vec<f64> = s.data.poses.iter().map(|p| p.commands_mm[leg]).collect();
    let (lo, hi) = q
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let truth = jumps(um[leg], from_mm, to_mm, lo, hi);
    let prefix = format!("leg-step.leg{}", leg + 1);
    d.causes.iter().any(|c| {
        let get = |name: &str| {
            c.parameters
                .iter()
                .find(|p| p.name == format!("{prefix}_{name}"))
        };
        let (Some(a), Some(b), Some(h)) = (get("from_mm"), get("to_mm"), get("um")) else {
            return false;
        };
        let sd_of = |e: f64| [a, b].iter().find(|p| p.value == e).and_then(|p| p.std_dev);
        let fitted = jumps(h.value, a.value, b.value, lo, hi);
        c.effect == G::LegStep
            && c.legs == vec![leg as u8 + 1]
            && fitted.len() == truth.len()
            && fitted.iter().zip(&truth).all(|((e, j), (te, tj))| {
                let between = q
                    .iter()
                    .filter(|v| (e.min(*te)..=e.max(*te)).contains(v))
                    .count();
                let placed = between <= 2 || sd_of(*e).is_some_and(|sd| (e - te).abs() <= 3.0 * sd);
                placed && (j - tj).abs() <= 3.0 * h.std_dev.unwrap_or(0.0) + 0.3
            })
    })
}

#[test]
fn worn_segment_is_named() {
    let base = 0x5e97;
    let mut failures = Vec::new();
    for n in SIZES {
        let res = run_case(SETS, |i| {
            let seed = base + i;
            let e = worn_segment(&mut rng(base, seed), i);
            simulate(n, seed, vec![e], CampaignOptions::default())
        });
        let (mut good, mut dressed) = (0, 0);
        for (i, (s, d)) in res.iter().enumerate() {
            let ok = step_found(s, d);
            good += usize::from(ok);
            let bad = dressed_up(d, &[]);
            dressed += usize::from(bad);
            failures.extend(
                invariants(d)
                    .into_iter()
                    .map(|v| format!("n={n} set {i}: {v}")),
            );
            if bad {
                failures.push(format!(
                    "worn segment n={n} set {i}: a catalogue effect explains it: {}",
                    summary(d)
                ));
            }
            if !ok {
                eprintln!(
                    "worn segment n={n} set {i} not right: {} ({:?})",
                    summary(d),
                    s.effects
                );
            }
        }
        tally(
            "worn segment 2.5-4 um",
            n,
            "right leg, edges and step",
            good,
            SETS as usize,
        );
        tally(
            "worn segment 2.5-4 um",
            n,
            "catalogue effect named with final_adequate true",
            dressed,
            SETS as usize,
        );
        if good < 16 {
            failures.push(format!(
                "worn segment n={n}: right in {good}/{SETS}, 16 required"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn scale_drift_is_named() {
    case(
        "scale drift 2-6 um",
        0xd21f,
        &SIZES,
        |r| {
            Effect::from(tricept_plant::effects::ScaleDrift {
                um: sign(r) * uniform(r, 2.0, 6.0),
            })
        },
        |_, d| {
            // The temperature follows time in these campaigns: a drift with
            // time and a change with temperature are one alias set.
            (group_found(d, "reading-drift:s") || group_found(d, "reading-temperature:s"))
                && !named(d, CauseName::Catalogue(E::Thermal))
        },
        |_, _| Vec::new(),
        |_| 16,
    );
}

#[test]
fn encoder_gain() {
    case(
        "encoder gain 100-300 ppm",
        0x9a1e,
        &SIZES,
        |r| {
            let g = sign(r) * uniform(r, 100.0, 300.0);
            if uniform(r, 0.0, 1.0) < 0.5 {
                Effect::from(tricept_plant::effects::EncoderGain {
                    phi_ppm: g,
                    theta_ppm: 0.0,
                })
            } else {
                Effect::from(tricept_plant::effects::EncoderGain {
                    phi_ppm: 0.0,
                    theta_ppm: g,
                })
            }
        },
        |s, d| {
            let Some(&tricept_plant::effects::EncoderGain { phi_ppm, .. }) = s.effects[0].input()
            else {
                return false;
            };
            let label = if phi_ppm != 0.0 {
                "encoder-gain:phi"
            } else {
                "encoder-gain:theta"
            };
            group_found(d, label)
        },
        |_, _| Vec::new(),
        // Infeasible below 200 poses (docs/diagnosis.md): tallied only.
        |n| if n >= 200 { 16 } else { 0 },
    );
}

/// Shapes outside the dictionary (a sawtooth pitch error, legs bent as
/// `|x|^1.5`) are never dressed up as a catalogue effect, and are reported
/// as partially explained, unexplained or explained by a generic form; a
/// curved leg never gets a worn segment (a step) beside its polynomial.
#[test]
fn unknown_forms_are_not_dressed_up() {
    let shapes: [(&str, u64); 2] = [
        ("sawtooth pitch 4 um, 10 mm", 0x5a37),
        ("legs |x|^1.5, 5-15 um", 0x1e15),
    ];
    let mut failures = Vec::new();
    for (k, (name, base)) in shapes.iter().enumerate() {
        let res = run_case(SETS, |i| {
            let seed = base + i;
            let r = &mut rng(*base, seed);
            let e = if k == 0 {
                Effect::from(tricept_plant::effects::LegPeriodic {
                    um: [4.0; 3],
                    period_mm: 10.0,
                    phase_deg: std::array::from_fn(|_| uniform(r, 0.0, 360.0)),
                    waveform: Waveform::Sawtooth,
                })
            } else {
                Effect::from(tricept_plant::effects::LegPower {
                    um: std::array::from_fn(|_| sign(r) * uniform(r, 5.0, 15.0)),
                    exponent: 1.5,
                    centre_mm: 845.0,
                    half_width_mm: 250.0,
                })
            };
            simulate(80, seed, vec![e], CampaignOptions::default())
        });
        let (mut dressed, mut honest, mut stepped) = (0, 0, 0);
        for (i, (_, d)) in res.iter().enumerate() {
            // Neither shape has a step: a worn segment in the final model
            // would only mop up what another form leaves.
            let step = d.model_terms.iter().any(|t| t.effect == G::LegStep);
            stepped += usize::from(step);
            if step && k == 1 {
                failures.push(format!(
                    "{name} set {i}: a step beside the polynomial: {}",
                    summary(d)
                ));
            }
            let bad = dressed_up(d, &[E::LegLead]);
            dressed += usize::from(bad);
            let generic = d.causes.iter().any(|c| c.effect.is_generic());
            let ok = matches!(
                d.verdict,
                Verdict::PartiallyExplained | Verdict::Unexplained
            ) || (d.verdict == Verdict::Explained && generic);
            honest += usize::from(ok);
            if bad || !ok {
                failures.push(format!("{name} set {i}: {}", summary(d)));
            }
            failures.extend(invariants(d));
        }
        tally(
            name,
            80,
            "catalogue effect named with final_adequate true",
            dressed,
            SETS as usize,
        );
        tally(
            name,
            80,
            "partially explained, unexplained or explained by a generic term",
            honest,
            SETS as usize,
        );
        tally(
            name,
            80,
            "a worn segment (leg-step) in the final model",
            stepped,
            SETS as usize,
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn clean_sets_are_adequate() {
    let mut failures = Vec::new();
    for n in SIZES {
        let res = run_case(40, |i| {
            simulate(n, 0xc1ea + i, Vec::new(), CampaignOptions::default())
        });
        let adequate = res.iter().filter(|(_, d)| d.adequate).count();
        let generic = res
            .iter()
            .filter(|(_, d)| d.causes.iter().any(|c| c.effect.is_generic()))
            .count();
        tally("no hidden effect", n, "adequate", adequate, 40);
        tally("no hidden effect", n, "a generic term named", generic, 40);
        for (i, (_, d)) in res.iter().enumerate() {
            if !d.adequate {
                eprintln!("clean n={n} set {i}: {}", summary(d));
            }
        }
        if adequate < 38 || generic > 0 {
            failures.push(format!(
                "n={n}: adequate {adequate}/40, generic named {generic}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
