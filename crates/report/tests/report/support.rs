//! What the tests make their pages from, through the door as a user
//! would: calibrated machine files (the Table 2 fixture identified, the
//! pitch fixture diagnosed and deployed), check campaigns simulated from
//! the calibrations' own truths (a slipped leg, noisier sensors), check
//! histories, exports, and the page.

use std::path::{Path, PathBuf};

use serde_json::Value;
use tricept_ident::advanced::{ParameterSet, Poses, TrueErrors, parse_effects};
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::check::{CheckRequest, check};
use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
use tricept_ident::export::{ControlModel, ExportOptions, ExportRequest, export};
use tricept_ident::report::{Report, ReportRequest, report};
use tricept_ident::simulate::{SimulateRequest, simulate};
use tricept_ident::{Error, MachineInput};

/// The workspace's root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fixture of the workspace, by its path there.
pub fn fixture(path: &str) -> PathBuf {
    workspace().join(path)
}

/// A temporary folder of this test, removed when dropped.
pub struct Dir(pub PathBuf);

impl Dir {
    pub fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("tricept-report-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }

    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The Table 2 fixture identified (`identify --write-machine`).
pub fn table2_machine(dir: &Dir) -> PathBuf {
    let out = dir.join("table2.json");
    let fit = calibrate(CalibrateRequest::new(
        fixture("fixtures/data/table2-grid-seed1.csv").as_path(),
    ))
    .unwrap();
    fit.write_machine(&out, tricept_ident::WriteOptions::default())
        .unwrap();
    out
}

/// The pitch fixture diagnosed and deployed (`diagnose --write-machine`:
/// three per-leg compensation tables).
pub fn pitch_machine(dir: &Dir) -> PathBuf {
    let out = dir.join("pitch.json");
    let d = diagnose(
        DiagnoseRequest::new(fixture("fixtures/data/diagnose-pitch.csv").as_path())
            .machine(MachineInput::default()),
    )
    .unwrap();
    d.write_machine(&out, tricept_ident::WriteOptions::default())
        .unwrap();
    out
}

/// The Table 2 errors with leg 2 slipped by `slip_mm`, as a `--truth`
/// file.
pub fn table2_slipped(dir: &Dir, slip_mm: f64) -> TrueErrors {
    let set = ParameterSet::paper15();
    let mut values = set.table2();
    let k = set.names().iter().position(|n| n == "dq2").unwrap();
    values[k] += slip_mm;
    let path = dir.join(&format!("slipped-{slip_mm}.json"));
    let map = set.values_to_map(&values);
    std::fs::write(&path, Value::Object(map).to_string()).unwrap();
    TrueErrors::File(path)
}

/// A check campaign of 20 random poses of the Table 2 machine (or the
/// truth given), written as `name`.
pub fn campaign(
    dir: &Dir,
    name: &str,
    truth: TrueErrors,
    effects: &[&str],
    seed: u64,
    noise_factor: f64,
) -> PathBuf {
    let mut r = SimulateRequest::new().machine(MachineInput::default());
    r.truth = truth;
    r.truth_effects =
        parse_effects(&effects.iter().map(|e| e.to_string()).collect::<Vec<_>>()).unwrap();
    r.poses = format!("random:20,{seed}").parse::<Poses>().unwrap();
    r.seed = seed;
    r.noise_factor = noise_factor;
    let s = simulate(r).unwrap();
    let path = dir.join(name);
    tricept_data::write_path(&path, s.data(), s.comments()).unwrap();
    path
}

/// The check of `data` against `machine`, appended to `history`; its
/// verdict.
pub fn check_into(machine: &Path, data: &Path, history: &Path) -> String {
    let mut r = CheckRequest::new(machine, data);
    r.history = Some(history.to_path_buf());
    let c = check(r).unwrap();
    c.check_report().verdict.as_str().to_string()
}

/// The export of `machine` for the SINUMERIK 840D sl into `dir/name`.
pub fn export_of(machine: &Path, dir: &Dir, name: &str) -> PathBuf {
    let out = dir.join(name);
    let e = export(ExportRequest::new(
        machine,
        ExportOptions::for_model(ControlModel::default()),
        out.clone(),
    ))
    .unwrap();
    assert!(e.written());
    out
}

/// The page of `machine` with the inputs given, written to `out`.
pub fn page(
    machine: &Path,
    data: Option<&Path>,
    history: Option<&Path>,
    export: Option<&Path>,
    out: &Path,
) -> Result<Report, Error> {
    let mut r = ReportRequest::new(machine, out);
    r.data = data.map(Path::to_path_buf);
    r.history = history.map(Path::to_path_buf);
    r.export = export.map(Path::to_path_buf);
    report(r)
}

/// A JSON file read.
pub fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// What each reason of a page's verdict says.
pub fn reasons(r: &Report) -> Vec<String> {
    r.verdict().reasons.iter().map(|x| x.says.clone()).collect()
}
