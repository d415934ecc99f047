//! The CI-sized rates: 10 campaigns per scenario and pose count on 4
//! machines from the independent generator, held to what issue 31 asks of
//! the check.

use std::sync::OnceLock;

use super::*;

/// Campaigns per scenario and pose count.
const N: usize = 10;
/// Machines calibrated.
const MACHINES: usize = 4;
/// The pose counts of the check.
const POSES: [usize; 2] = [10, 20];
/// The seed of machines and campaigns.
const SEED: u64 = 7;

/// The machines, calibrated once for every test of this binary.
fn machines() -> &'static [Calibrated] {
    static MACHINES_CELL: OnceLock<Vec<Calibrated>> = OnceLock::new();
    MACHINES_CELL.get_or_init(|| {
        let dir =
            std::env::temp_dir().join(format!("tricept-check-rates-test-{}", std::process::id()));
        let m = calibrate_machines(SEED, MACHINES, &POSES, &dir);
        let _ = std::fs::remove_dir_all(&dir);
        m.unwrap()
    })
}

/// Every scenario's tallies, computed once.
fn all() -> &'static [Tally] {
    static TALLIES: OnceLock<Vec<Tally>> = OnceLock::new();
    TALLIES.get_or_init(|| {
        let scenarios: Vec<usize> = (0..SCENARIOS.len()).collect();
        let o = outcomes(machines(), &scenarios, &POSES, N, SEED).unwrap();
        let t = tallies(&o);
        eprintln!("{}", table(&t));
        t
    })
}

/// The tally of the scenario named `name` at `poses`.
fn tally(name: &str, poses: usize) -> &'static Tally {
    all()
        .iter()
        .find(|t| SCENARIOS[t.scenario].name == name && t.poses == poses)
        .unwrap_or_else(|| panic!("no tally of {name} at {poses} poses"))
}

/// `count` is at least `share` of the campaigns.
fn at_least(count: usize, share: f64) -> bool {
    count as f64 >= share * N as f64 - 1e-9
}

#[test]
fn an_unchanged_machine_raises_at_most_one_alarm_in_ten() {
    for name in [
        "nothing changed",
        "nothing changed, temperature log 0.3 K jitter",
    ] {
        for k in POSES {
            let t = tally(name, k);
            assert_eq!(t.campaigns, N);
            assert!(at_least(t.exit_ok, 0.9), "{name}, {k} poses: {t:?}");
        }
    }
}

#[test]
fn a_single_change_is_found_and_named_alone() {
    // Issue 31 asks 10 of 10 at the 20 poses of a planned check; 10 poses
    // may miss one in 10.
    let found = |k: usize, t: &Tally| match k {
        20 => t.exit_changed == N,
        _ => at_least(t.exit_changed, 0.9),
    };
    for k in POSES {
        let t = tally("a leg slipped 20-25 um", k);
        assert!(found(k, t), "{k} poses: {t:?}");
        assert!(at_least(t.right, 0.9), "{k} poses: {t:?}");
        // A joint moved along its leg reads as the leg: the check says it
        // cannot tell them apart, the shortlist names both.
        let t = tally("a joint moved 50-60 um", k);
        assert!(found(k, t), "{k} poses: {t:?}");
        assert!(at_least(t.listed, 0.9), "{k} poses: {t:?}");
        assert!(at_least(t.right, 0.7), "{k} poses: {t:?}");
    }
}

#[test]
fn a_change_under_more_noise_is_still_found() {
    let t = tally("a leg slipped + 1.5x noise", 20);
    assert_eq!(t.exit_changed, N, "{t:?}");
    assert!(at_least(t.right, 0.9), "{t:?}");
}

#[test]
fn warm_legs_with_a_precise_temperature_log_are_named_thermal_growth() {
    for k in POSES {
        let t = tally("legs 4 K warmer, precise log", k);
        assert!(at_least(t.right, 0.9), "{k} poses: {t:?}");
    }
}

#[test]
fn noisier_sensors_are_not_a_change() {
    for k in POSES {
        let t = tally("nothing changed, 1.5x noise", k);
        assert!(t.exit_changed <= 1, "{k} poses: {t:?}");
    }
    // 20 poses see the larger noise (today they exit 3 on 18 of 20): the
    // check says what it sees.
    let t = tally("nothing changed, 1.5x noise", 20);
    let noisier = t.verdicts.get("noisier-than-stated").copied().unwrap_or(0);
    assert!(at_least(noisier, 0.5), "{t:?}");
}

#[test]
fn a_bad_reading_is_set_aside() {
    for k in POSES {
        for name in [
            "nothing changed, one bad reading (s +25 um)",
            "nothing changed, one bad reading (phi +40 arcsec)",
        ] {
            let t = tally(name, k);
            assert!(at_least(t.exit_ok, 0.9), "{name}, {k} poses: {t:?}");
            assert!(at_least(t.bad_set_aside, 0.9), "{name}, {k} poses: {t:?}");
        }
    }
    let t = tally("a leg slipped + one bad reading (s)", 20);
    assert!(at_least(t.right, 0.9), "{t:?}");
    assert!(at_least(t.bad_set_aside, 0.9), "{t:?}");
}

#[test]
fn two_slipped_legs_are_both_named() {
    for k in POSES {
        let t = tally("two legs slipped +25, -25 um", k);
        assert!(at_least(t.right, 0.9), "{k} poses: {t:?}");
    }
}

#[test]
fn a_warm_machine_is_named_thermal_growth() {
    for name in [
        "legs 4 K warmer, log 0.3 K jitter",
        "structure 4 K warmer, log 0.3 K jitter",
    ] {
        let t = tally(name, 20);
        assert!(at_least(t.right, 0.9), "{name}: {t:?}");
    }
}

#[test]
fn the_outcomes_are_the_same_at_any_thread_count() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| outcomes(machines(), &[5, 8], &[20], 4, SEED).unwrap())
    };
    let one = run(1);
    assert_eq!(one.len(), 8);
    assert_eq!(one, run(3));
}

#[test]
fn the_named_changes_are_the_set_when_the_check_gives_one() {
    let v: Value = serde_json::json!({
        "most_likely": 1,
        "candidates": [{"name": "leg 1"}, {"name": "leg 2"}],
    });
    assert_eq!(named(&v), ["leg 2"]);
    let v: Value = serde_json::json!({
        "most_likely": 1,
        "candidates": [{"name": "leg 1"}, {"name": "leg 2"}],
        "changes": [{"name": "leg 1"}, {"name": "leg 3"}],
    });
    assert_eq!(named(&v), ["leg 1", "leg 3"]);
    assert!(named(&serde_json::json!({"most_likely": null})).is_empty());
    let v = serde_json::json!({"set_aside": [{"line": 7, "reading": "s"}, 9]});
    assert_eq!(set_aside_lines(&v), [7, 9]);
    let v = serde_json::json!({"rejected": [{"pose": 3, "line": 4}]});
    assert_eq!(set_aside_lines(&v), [4]);
    let v = serde_json::json!({
        "shortlist": ["leg 1", "platform joint A1"],
        "changes": [
            {"name": "leg 1", "aliases": ["base joint B1", "platform joint A1"]},
            {"name": "leg 2", "aliases": []},
        ],
    });
    assert_eq!(alike(&v), ["leg 1", "platform joint A1", "base joint B1"]);
    assert!(set_aside_lines(&serde_json::json!({})).is_empty());
}

#[test]
fn the_right_answer_is_exactly_the_hidden_change() {
    let o = |names: &[&str], exit: u8, named: &[&str], shortlist: &[&str]| Outcome {
        scenario: 0,
        poses: 20,
        campaign: 0,
        machine: 0,
        hidden: Hidden {
            names: names.iter().map(|s| s.to_string()).collect(),
            text: String::new(),
            bad_row: None,
        },
        exit,
        verdict: String::new(),
        named: named.iter().map(|s| s.to_string()).collect(),
        shortlist: shortlist.iter().map(|s| s.to_string()).collect(),
        bad_line: None,
        set_aside: Vec::new(),
    };
    assert!(o(&[], 0, &[], &[]).right());
    assert!(!o(&[], 3, &["leg 1"], &[]).right());
    assert!(o(&["leg 2"], 3, &["leg 2"], &["leg 2"]).right());
    assert!(!o(&["leg 2"], 0, &[], &[]).right());
    assert!(!o(&["leg 2"], 3, &["leg 2", "leg 1"], &[]).right());
    assert!(o(&["leg 1", "leg 3"], 3, &["leg 3", "leg 1"], &[]).right());
    assert!(!o(&["leg 1", "leg 3"], 3, &["leg 3"], &[]).right());
    assert!(
        o(
            &["thermal growth"],
            3,
            &["scale gain", "thermal growth"],
            &[]
        )
        .right()
    );
    assert!(!o(&["thermal growth"], 3, &["scale gain"], &[]).right());
    assert!(
        o(
            &["thermal growth"],
            3,
            &["thermal growth of the structure"],
            &[]
        )
        .right()
    );
    assert!(
        o(
            &["thermal growth"],
            3,
            &["scale gain"],
            &["thermal growth of the structure"]
        )
        .listed()
    );
    assert!(
        o(
            &["platform joint A3"],
            3,
            &["leg 3"],
            &["leg 3", "platform joint A3"]
        )
        .listed()
    );
    assert!(!o(&["platform joint A3"], 3, &["leg 3"], &["leg 3"]).listed());
    assert!(!o(&[], 3, &["leg 3"], &[]).listed());
    let mut bad = o(&[], 0, &[], &[]);
    assert!(!bad.bad_set_aside());
    bad.bad_line = Some(9);
    bad.set_aside = vec![4];
    assert!(!bad.bad_set_aside());
    bad.set_aside.push(9);
    assert!(bad.bad_set_aside());
}

#[test]
fn the_bad_reading_is_on_its_own_line_of_the_campaign() {
    let m = &machines()[0];
    let commands = m.commands(10).unwrap();
    let scenario = &SCENARIOS[3];
    assert_eq!(scenario.bad, Some(BadReading::ScaleUm(25.0)));
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let (rows, hidden) = m.campaign(scenario, commands, 0, &mut rng);
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let clean = m
        .campaign(&Scenario::unchanged("clean"), commands, 0, &mut rng)
        .0;
    let i = hidden.bad_row.unwrap();
    // The same draws but the one reading: 25 um on s, nothing else.
    assert!((rows[i].readings[2] - clean[i].readings[2] - 0.025).abs() < 1e-12);
    for (j, (a, b)) in rows.iter().zip(&clean).enumerate() {
        assert_eq!(a.readings[..2], b.readings[..2]);
        if j != i {
            assert_eq!(a.readings, b.readings);
        }
    }
    let o = outcomes(machines(), &[3], &[10], 1, SEED).unwrap();
    let line = o[0].bad_line.unwrap();
    assert!((2..=11).contains(&line), "{o:?}");
}
