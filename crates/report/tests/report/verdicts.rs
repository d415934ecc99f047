//! The verdict for what was hidden in the campaigns: a slipped leg found by
//! the last check turns the page red (exit code 3), noisier sensors amber,
//! a forced calibration red, a clean calibration with unchanged checks and
//! its export green; each expectation from the simulator's inputs.

use tricept_ident::advanced::TrueErrors;
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::report::Level;
use tricept_ident::{EXIT_INADEQUATE, EXIT_OK};

use crate::support::{
    Dir, campaign, check_into, export_of, fixture, page, table2_machine, table2_slipped,
};

#[test]
fn a_slipped_leg_found_by_the_last_check_turns_the_page_red() {
    let dir = Dir::new("slip");
    let machine = table2_machine(&dir);
    let history = dir.join("checks.jsonl");
    let day1 = campaign(&dir, "day1.csv", TrueErrors::Table2, &[], 11, 1.0);
    assert_eq!(check_into(&machine, &day1, &history), "unchanged");
    // Leg 2 slips by 25 um.
    let day2 = campaign(&dir, "day2.csv", table2_slipped(&dir, 0.025), &[], 12, 1.0);
    assert!(check_into(&machine, &day2, &history).starts_with("changed"));
    let out = dir.join("page.html");
    let r = page(&machine, None, Some(&history), None, &out).unwrap();
    assert_eq!(r.verdict().level, Level::DoNotTrust);
    assert_eq!(r.exit_code(), EXIT_INADEQUATE);
    let first = &r.verdict().reasons[0];
    assert_eq!(
        first.says,
        "the last check found the machine changed since its calibration"
    );
    let paths: Vec<&str> = first.shows.iter().map(|s| s.path.as_str()).collect();
    assert_eq!(paths, ["/1/verdict", "/1/time", "/1/most_likely"]);
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.contains("<div class=\"verdict\" id=\"verdict\" data-level=\"do-not-trust\">"));
    assert!(html.contains(">DO NOT TRUST</span>"));
    // The change the check named is on the page, by its pointer.
    assert!(
        html.contains("data-src=\"history\" data-path=\"/1/most_likely\">leg 2<"),
        "leg 2 is not named"
    );
}

#[test]
fn noisier_sensors_at_the_last_check_are_a_caution() {
    let dir = Dir::new("noisy");
    let machine = table2_machine(&dir);
    let history = dir.join("checks.jsonl");
    let day = campaign(&dir, "day.csv", TrueErrors::Table2, &[], 13, 2.0);
    assert_eq!(check_into(&machine, &day, &history), "noisier-than-stated");
    let r = page(&machine, None, Some(&history), None, &dir.join("page.html")).unwrap();
    assert_eq!(r.verdict().level, Level::Caution);
    assert_eq!(r.exit_code(), EXIT_OK);
}

#[test]
fn a_forced_calibration_is_not_trusted() {
    let dir = Dir::new("forced");
    // The pitch fixture identified as geometry alone: not adequate,
    // written with --force.
    let data = fixture("fixtures/data/diagnose-pitch.csv");
    let machine = dir.join("forced.json");
    let fit = calibrate(CalibrateRequest::new(data.as_path())).unwrap();
    assert_ne!(fit.exit_code(), EXIT_OK);
    fit.write_machine(&machine, tricept_ident::WriteOptions::default().force(true))
        .unwrap();
    let r = page(&machine, Some(&data), None, None, &dir.join("page.html")).unwrap();
    assert_eq!(r.verdict().level, Level::DoNotTrust);
    assert_eq!(r.exit_code(), EXIT_INADEQUATE);
    let says = crate::support::reasons(&r);
    assert!(says.iter().any(|s| s.contains("(forced)")), "{says:?}");
    // The campaign's diagnosis names the pitch error the file lacks.
    assert!(
        says.iter().any(|s| s.contains("does not deploy")),
        "{says:?}"
    );
}

#[test]
fn a_clean_calibration_with_unchanged_checks_and_its_export_is_trusted() {
    let dir = Dir::new("clean");
    let machine = table2_machine(&dir);
    let history = dir.join("checks.jsonl");
    for (k, seed) in [14u64, 15].into_iter().enumerate() {
        let day = campaign(
            &dir,
            &format!("day{k}.csv"),
            TrueErrors::Table2,
            &[],
            seed,
            1.0,
        );
        assert_eq!(check_into(&machine, &day, &history), "unchanged");
    }
    let cnc = export_of(&machine, &dir, "cnc");
    let data = fixture("fixtures/data/table2-grid-seed1.csv");
    let r = page(
        &machine,
        Some(&data),
        Some(&history),
        Some(&cnc),
        &dir.join("page.html"),
    )
    .unwrap();
    assert_eq!(r.verdict().level, Level::Trusted, "{:?}", r.verdict());
    assert_eq!(r.exit_code(), EXIT_OK);
    assert!(r.report().starts_with("report written to "));
}
