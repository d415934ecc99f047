//! One shape for every workflow's result, one convention for every request
//! (issue 49), tested through the door alone on the fixtures: each result's
//! exit code agrees with its reason, its JSON carries `format_version`, its
//! report says something; a machine file is written by one rule
//! ([`WriteOptions`]); requests are built by chained setters; both inputs
//! convert from every path-like type.

use std::path::{Path, PathBuf};

use tricept_ident::advanced::{OUTPUT_FORMAT_VERSION, files};
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::check::{CheckRequest, check};
use tricept_ident::compensate::{Calibrated, CompensateRequest, compensate};
use tricept_ident::detectability::{DetectabilityRequest, detectability};
use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
use tricept_ident::export::{ControlModel, ExportOptions, ExportRequest, export};
use tricept_ident::fleet::{FleetRequest, fleet};
use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
use tricept_ident::kinematics::{Verb, solve_point};
use tricept_ident::report::{ReportRequest, report};
use tricept_ident::simulate::{SimulateRequest, simulate};
use tricept_ident::{
    DataInput, EXIT_INADEQUATE, EXIT_OK, ErrorCause, MachineInput, Outcome, WriteOptions,
    WritesMachine,
};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// A fresh scratch folder of this test binary.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-shape-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The shape every result keeps: `reason` is `None` exactly when the exit
/// code is 0, the JSON (each object of an array) starts with
/// `format_version`, the report is not empty. Returns the exit code.
fn shaped(name: &str, r: &impl Outcome) -> u8 {
    let code = r.exit_code();
    assert_eq!(
        r.reason().is_none(),
        code == EXIT_OK,
        "{name}: exit {code}, reason {:?}",
        r.reason()
    );
    if let Some(why) = r.reason() {
        assert!(!why.trim().is_empty(), "{name}: an empty reason");
        assert!(
            !why.contains("exit"),
            "{name}: the reason names the exit: {why}"
        );
    }
    let json = r.to_json();
    let objects = match json.as_array() {
        Some(items) => items.clone(),
        None => vec![json],
    };
    assert!(!objects.is_empty(), "{name}: no JSON");
    for o in &objects {
        let first = o.as_object().and_then(|m| m.keys().next().cloned());
        assert_eq!(first.as_deref(), Some("format_version"), "{name}: {o}");
        assert_eq!(o["format_version"], OUTPUT_FORMAT_VERSION, "{name}");
    }
    assert!(!r.report().trim().is_empty(), "{name}: an empty report");
    code
}

#[test]
fn every_workflow_result_has_the_one_shape() {
    let dir = scratch("all");
    let grid = fixture("data/table2-grid-seed1.csv");
    let hidden = fixture("data/diagnose-hidden-effect.csv");

    // The grid campaign of a machine with Table 2's errors and the stated
    // noise: the geometric model explains it.
    let trusted = calibrate(CalibrateRequest::new(&grid)).unwrap();
    assert_eq!(shaped("calibrate", &trusted), EXIT_OK);
    // A campaign of a machine with an effect the geometry cannot explain.
    let untrusted = calibrate(CalibrateRequest::new(&hidden)).unwrap();
    assert_eq!(shaped("calibrate hidden", &untrusted), EXIT_INADEQUATE);

    let diagnosis = diagnose(DiagnoseRequest::new(&grid)).unwrap();
    assert_eq!(shaped("diagnose", &diagnosis), EXIT_OK);

    let machine = dir.join("calibrated.json");
    trusted
        .write_machine(&machine, WriteOptions::default())
        .unwrap();
    // Checked against its own calibration: unchanged.
    let checked = check(CheckRequest::new(&machine, &grid)).unwrap();
    assert_eq!(shaped("check", &checked), EXIT_OK);

    let compensation = compensate(CompensateRequest::new(Calibrated::MachineFile(
        MachineInput::from(&machine),
    )))
    .unwrap();
    assert_eq!(shaped("compensate", &compensation), EXIT_OK);

    let identifiability = assess_identifiability(IdentifiabilityRequest::new(Campaign::Data(
        grid.clone().into(),
    )))
    .unwrap();
    assert_eq!(shaped("identifiability", &identifiability), EXIT_OK);

    let detect = detectability(DetectabilityRequest::new("grid".parse().unwrap())).unwrap();
    assert_eq!(shaped("detectability", &detect), EXIT_OK);

    assert_eq!(
        shaped("effects", &tricept_ident::effects::effects(None).unwrap()),
        EXIT_OK
    );

    let out = dir.join("export");
    let exported = export(ExportRequest::new(
        &machine,
        ExportOptions::for_model(ControlModel::default()),
        &out,
    ))
    .unwrap();
    assert_eq!(exported.written(), exported.exit_code() == EXIT_OK);
    shaped("export", &exported);

    let page = report(ReportRequest::new(&machine, dir.join("page.html"))).unwrap();
    shaped("report", &page);

    let point = solve_point(
        Verb::Ik,
        &MachineInput::from(&machine).load().unwrap(),
        &[0.0, 0.0, 750.0],
    )
    .unwrap();
    assert_eq!(shaped("ik", &point), EXIT_OK);

    // Three machines of one batch, simulated with different noise seeds;
    // the simulation names the file it is written to.
    let mut files_of_batch = Vec::new();
    for seed in 1..=3u64 {
        let path = dir.join(format!("m{seed}.csv"));
        let sim = simulate(SimulateRequest::new().seed(seed).out(&path)).unwrap();
        assert_eq!(shaped("simulate", &sim), EXIT_OK);
        assert!(sim.report().contains(&path.display().to_string()));
        files::write_path(&path, sim.data(), sim.comments()).unwrap();
        files_of_batch.push(DataInput::from(path));
    }
    let batch = fleet(FleetRequest::new(files_of_batch)).unwrap();
    shaped("fleet", &batch);

    std::fs::remove_dir_all(&dir).ok();
}

/// The write rule through [`WriteOptions`]: an untrusted calibration does
/// not overwrite the file at its path unless forced, and a forced file says
/// why; a diagnosis deploys its final model once however often it writes.
#[test]
fn a_machine_file_is_written_by_one_rule_and_deployed_once() {
    let dir = scratch("write");
    let file = dir.join("machine.json");
    let trusted = calibrate(CalibrateRequest::new(fixture("data/table2-grid-seed1.csv"))).unwrap();
    let written = trusted
        .write_machine(&file, WriteOptions::default())
        .unwrap();
    assert_eq!((written.path(), written.forced()), (file.as_path(), None));
    assert_eq!(written.what(), "machine file");
    let before = std::fs::read(&file).unwrap();
    // The record states the promise the calibration made.
    let loaded = MachineInput::from(&file).load().unwrap();
    let record = loaded.description().calibration.clone().unwrap();
    let promised = trusted.accuracy().unwrap();
    assert_eq!(
        record.accuracy.as_ref().map(|a| a.upper_mm),
        Some(promised.upper_mm)
    );

    let untrusted = calibrate(CalibrateRequest::new(fixture(
        "data/diagnose-hidden-effect.csv",
    )))
    .unwrap();
    let why = untrusted.reason().unwrap().to_string();
    // Refused: the file at the path is left as it was.
    let e = untrusted
        .write_machine(&file, WriteOptions::default())
        .unwrap_err();
    assert_eq!(e.cause(), ErrorCause::RefusedWrite, "{e}");
    assert_eq!(e.exit_code(), untrusted.exit_code());
    assert_eq!(std::fs::read(&file).unwrap(), before);
    // Forced: overwritten, and the file records that it was forced.
    let forced = untrusted
        .write_machine(&file, WriteOptions::default().force(true))
        .unwrap();
    assert!(forced.forced().is_some_and(|f| !f.is_empty()), "{why}");
    assert_ne!(std::fs::read(&file).unwrap(), before);
    let loaded = MachineInput::from(&file).load().unwrap();
    let record = loaded.description().calibration.clone().unwrap();
    assert!(record.forced && !record.adequate);

    // A diagnosis: the promise is known before any file is written, and
    // the deployment behind it is made once and kept.
    let diagnosis = diagnose(DiagnoseRequest::new(fixture("data/table2-grid-seed1.csv"))).unwrap();
    let deployed: *const _ = diagnosis.deploy().unwrap();
    let upper_mm = diagnosis.accuracy().unwrap().upper_mm;
    for name in ["a.json", "b.json"] {
        let path = dir.join(name);
        let w = WritesMachine::write_machine(&diagnosis, &path, WriteOptions::default()).unwrap();
        assert_eq!(w.forced(), None);
        let record = MachineInput::from(&path)
            .load()
            .unwrap()
            .description()
            .calibration
            .clone()
            .unwrap();
        assert_eq!(record.accuracy.map(|a| a.upper_mm), Some(upper_mm));
        assert!(std::ptr::eq(deployed, diagnosis.deploy().unwrap()));
    }
    assert_eq!(diagnosis.to_json()["accuracy"]["upper_mm"], upper_mm);
    std::fs::remove_dir_all(&dir).ok();
}

/// One request convention: `new` takes what a workflow cannot do without,
/// every other field has a chained setter of its own name.
#[test]
fn requests_are_built_by_chained_setters() {
    let r = CalibrateRequest::new("d.csv")
        .tolerance_mm(0.01)
        .robust(false)
        .machine("m.json")
        .prior("prior.json");
    assert_eq!(r.tolerance_mm, 0.01);
    assert!(!r.robust);
    assert_eq!(r.machine.path(), Some(Path::new("m.json")));
    assert_eq!(r.prior.as_deref(), Some(Path::new("prior.json")));
    assert_eq!(r.data.path(), Some(Path::new("d.csv")));
    let d = DiagnoseRequest::new("d.csv")
        .machine("m.json")
        .noise_from_data(true)
        .temperature_noise_k(0.1);
    assert!(d.noise_from_data);
    assert_eq!(d.temperature_noise_k, Some(0.1));
    assert_eq!(d.machine.path(), Some(Path::new("m.json")));
    let s = SimulateRequest::new().seed(7).revisit(3);
    assert_eq!((s.seed, s.revisit), (7, 3));
    assert_eq!(s.machine.path(), None);
    let c = CheckRequest::new("m.json", "d.csv")
        .alpha(0.01)
        .history("h.jsonl");
    assert_eq!(c.alpha, 0.01);
    assert_eq!(c.history.as_deref(), Some(Path::new("h.jsonl")));
}

/// Both inputs convert from every path-like type, naming the same file.
#[test]
fn inputs_convert_from_every_path_like_type() {
    let text = "campaign.csv";
    let owned = String::from(text);
    let buf = PathBuf::from(text);
    let want = Some(Path::new(text));
    // `&str`, `String`, `&String`, `PathBuf`, `&PathBuf`, `&Path`.
    macro_rules! every_path_like {
        ($input:ty) => {
            [
                <$input>::from(text),
                <$input>::from(owned.clone()),
                <$input>::from(&owned),
                <$input>::from(buf.clone()),
                <$input>::from(&buf),
                <$input>::from(buf.as_path()),
            ]
        };
    }
    for d in every_path_like!(DataInput) {
        assert_eq!(d.path(), want, "{d:?}");
    }
    for m in every_path_like!(MachineInput) {
        assert_eq!(m.path(), want, "{m:?}");
    }
}
