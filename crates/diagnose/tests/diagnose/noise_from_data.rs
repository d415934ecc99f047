//! The noise of the data, from repeated poses: 60 random targets with the
//! first 20 revisited at the end of the campaign (80 logged poses, the
//! mean of 3 readings). When the true noise is 1.5 times the stated noise,
//! the diagnosis must say so, and with `noise_from_data` the data must be
//! found adequate with no cause named; when it is the stated noise, the
//! check must agree.
//!
//! `cargo test -p tricept-diagnose --test diagnose noise_from_data:: -- --nocapture`
//! prints the tallies.

use crate::common::*;
use tricept_diagnose::{diagnose, report::NoiseSource};
use tricept_kinematics::Machine;

const SETS: u64 = 20;

fn campaign(factor: f64) -> CampaignOptions {
    CampaignOptions {
        revisits: 20,
        noise_factor: factor,
    }
}

#[test]
fn worse_noise_is_detected() {
    let base = 0x0153;
    let make = |i: u64| simulate(60, base + i, Vec::new(), campaign(1.5));
    let stated = run_case(SETS, make);
    let disagrees = stated
        .iter()
        .filter(|(_, d)| d.noise.agrees == Some(false))
        .count();
    let adequate_stated = stated.iter().filter(|(_, d)| d.adequate).count();
    tally(
        "true noise 1.5x stated",
        80,
        "noise disagreement reported",
        disagrees,
        SETS as usize,
    );
    tally(
        "true noise 1.5x stated",
        80,
        "adequate against the stated noise",
        adequate_stated,
        SETS as usize,
    );
    let named_stated = stated
        .iter()
        .filter(|(_, d)| !d.causes.is_empty() || !d.aliases.is_empty())
        .count();
    tally(
        "true noise 1.5x stated",
        80,
        "a cause named against the stated noise",
        named_stated,
        SETS as usize,
    );
    for (i, (_, d)) in stated.iter().enumerate() {
        eprintln!("stated noise, set {i}: {}", summary(d));
    }
    let from_data = run_case_with(SETS, make, |s| {
        let mut o = options(s.sigma);
        o.noise_from_data = true;
        o
    });
    let mut failures = Vec::new();
    let mut adequate = 0;
    for (i, (_, d)) in from_data.iter().enumerate() {
        let ok = d.adequate && d.causes.is_empty() && d.noise.used == NoiseSource::Data;
        adequate += usize::from(ok);
        if !ok {
            failures.push(format!("set {i} with --noise-from-data: {}", summary(d)));
        }
        // The data's noise is reported: about 1.5 times the stated one.
        let ratio = d.noise.pure_error.as_ref().map_or(0.0, |p| p.ratio[2]);
        if !(1.0..2.2).contains(&ratio) {
            failures.push(format!("set {i}: s noise ratio {ratio}"));
        }
    }
    tally(
        "true noise 1.5x stated, --noise-from-data",
        80,
        "adequate, nothing named",
        adequate,
        SETS as usize,
    );
    if disagrees < 19 || adequate < 19 {
        failures.push(format!(
            "disagreement {disagrees}/20, adequate from data {adequate}/20"
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn stated_noise_is_confirmed() {
    let base = 0x0154;
    let res = run_case(SETS, |i| simulate(60, base + i, Vec::new(), campaign(1.0)));
    let agrees = res
        .iter()
        .filter(|(_, d)| d.noise.agrees == Some(true))
        .count();
    tally(
        "true noise = stated",
        80,
        "noise agreement reported",
        agrees,
        SETS as usize,
    );
    for (i, (_, d)) in res.iter().enumerate() {
        if d.noise.agrees != Some(true) {
            eprintln!("set {i}: {}", d.noise.note);
        }
    }
    assert!(agrees >= 19, "{agrees}/20 agree");
}

#[test]
fn noise_from_data_needs_repeats() {
    let s = simulate(60, 0x0155, Vec::new(), CampaignOptions::default());
    let mut o = options(s.sigma);
    o.noise_from_data = true;
    let e = diagnose(&Machine::paper(), &s.data, &o).unwrap_err();
    assert!(e.to_string().contains("repeated poses"), "{e}");
    // Without the option the report says the noise cannot be checked.
    let d = diagnose(&Machine::paper(), &s.data, &options(s.sigma)).unwrap();
    assert_eq!(d.noise.agrees, None);
    assert!(d.noise.note.contains("no repeated poses"));
}
