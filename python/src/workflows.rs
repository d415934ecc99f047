//! The workflows: `identify`, `diagnose`, `check` and `simulate`, each the
//! door's own call, and their results (`Calibration`, `Diagnosis`,
//! `CheckResult`). A result hands out what survives it: its JSON and
//! report, and the machine file it may write (`machine_file_json`, the
//! door's `MachineFile`), which `write_machine_file` writes later by the
//! same rule: what the Python half pickles.

use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use tricept_ident::advanced::{ParameterSet, Poses, SensorNoise, TrueErrors};
use tricept_ident::calibrate::{CalibrateRequest, MachineFile};
use tricept_ident::check::CheckRequest;
use tricept_ident::diagnosis::DiagnoseRequest;
use tricept_ident::simulate::SimulateRequest;
use tricept_ident::{DataInput, LoadedMachine, MachineInput, WriteOptions};

use crate::Machine;
use crate::errors::{door_error, door_error_in, input_error};

/// The machine argument of a workflow: `None` (the built-in Table 1
/// machine), a machine file's path, or a `Machine`; with the noise
/// overrides. Anything else is an `InputError`.
fn machine_input(
    py: Python<'_>,
    machine: Option<&Bound<'_, PyAny>>,
    noise: SensorNoise,
) -> PyResult<MachineInput> {
    let Some(m) = machine else {
        return Ok(MachineInput::new(None, noise));
    };
    if let Ok(m) = m.cast::<Machine>() {
        return m.get().input(&noise).map_err(|e| door_error(py, e));
    }
    match m.extract::<PathBuf>() {
        Ok(path) => Ok(MachineInput::new(Some(path), noise)),
        Err(_) => Err(input_error(
            py,
            format!(
                "machine: expected a machine file (a path) or a tricept.Machine, got {}",
                m.get_type()
                    .name()
                    .map_or_else(|_| "?".to_string(), |n| n.to_string())
            ),
        )),
    }
}

/// The data of a workflow: a CSV file, or CSV text written from column
/// arrays (named `name` in messages), read against `machine`'s stroke.
fn data_input(
    py: Python<'_>,
    path: Option<PathBuf>,
    csv_text: Option<&str>,
    name: &str,
    machine: &LoadedMachine,
) -> PyResult<DataInput> {
    match (path, csv_text) {
        (Some(path), None) => Ok(DataInput::File(path)),
        (None, Some(text)) => Ok(DataInput::Memory(
            tricept_ident::advanced::read_data_from(text.as_bytes(), name, machine.geometry())
                .map_err(|e| door_error_in(py, e, Some(name)))?,
        )),
        _ => Err(input_error(
            py,
            "data: give a CSV path or a mapping of column arrays",
        )),
    }
}

/// The name of array data in messages (`None`: a file).
fn arrays<'a>(csv_text: &Option<String>, name: &'a str) -> Option<&'a str> {
    csv_text.as_ref().map(|_| name)
}

/// The machine file a result may write, as the door keeps it: its JSON,
/// or the input error that says why there is none.
fn machine_file_json(
    py: Python<'_>,
    file: Result<MachineFile, tricept_ident::Error>,
) -> PyResult<String> {
    file.map(|f| f.to_json()).map_err(|e| door_error(py, e))
}

/// A calibration (`tricept identify`): its verdict, estimates, covariance,
/// JSON and report, the machine file it may write, and its machine.
#[pyclass(module = "tricept._tricept")]
struct Calibration {
    inner: tricept_ident::calibrate::Calibration,
}

#[pymethods]
impl Calibration {
    /// 0 trusted, 3 the model does not explain the data or the campaign
    /// is too small, 4 not converged: the CLI's exit code.
    #[getter]
    fn exit_code(&self) -> u8 {
        self.inner.exit_code()
    }

    /// The parameter names, in the order of the covariance.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner
            .estimates()
            .into_iter()
            .map(|(n, _, _)| n)
            .collect()
    }

    /// The estimates by name (mm, rad).
    #[getter]
    fn estimates(&self) -> Vec<(String, f64)> {
        self.inner
            .estimates()
            .into_iter()
            .map(|(n, v, _)| (n, v))
            .collect()
    }

    /// Their standard deviations by name (mm, rad; `None`: held).
    #[getter]
    fn sd(&self) -> Vec<(String, Option<f64>)> {
        self.inner
            .estimates()
            .into_iter()
            .map(|(n, _, s)| (n, s))
            .collect()
    }

    /// The estimates' covariance (mm^2, rad^2), in the order of `names`.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let c = self.inner.covariance();
        Array2::from_shape_fn((c.nrows(), c.ncols()), |(i, j)| c[(i, j)]).into_pyarray(py)
    }

    /// The warnings of the fit, one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings().to_vec()
    }

    /// The JSON `tricept identify --json` prints.
    fn to_json(&self) -> String {
        versioned(&self.inner.to_json().to_string())
    }

    /// The text report `tricept identify` prints.
    fn report(&self) -> String {
        self.inner.report()
    }

    /// Writes the calibrated machine file by the CLI's rule: a fit whose
    /// exit code is not 0 raises `UntrustedError` unless `force`; data
    /// given as arrays cannot be recorded and raise `InputError`.
    #[pyo3(signature = (path, force=false))]
    fn write_machine(&mut self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<String> {
        let written = self
            .inner
            .write_machine(&path, WriteOptions::default().force(force))
            .map_err(|e| door_error(py, e))?;
        Ok(written.path().display().to_string())
    }

    /// The machine file it may write, as JSON (the door's `MachineFile`);
    /// `InputError` for data given as arrays.
    fn machine_file_json(&self, py: Python<'_>) -> PyResult<String> {
        machine_file_json(py, self.inner.machine_file())
    }

    /// The calibrated machine, in memory: with its calibration record
    /// (sealed, as the file would be) when the data came from a file,
    /// the identified geometry alone when they came as arrays.
    fn machine(&self, py: Python<'_>) -> PyResult<Machine> {
        let data = self
            .inner
            .to_json()
            .get("data_file")
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let source = format!("the calibration of {data}");
        let description = match self.inner.machine_file() {
            Ok(f) => f.sealed(),
            Err(_) => {
                let mut d = self.inner.identified().to_description();
                d.calibration = None;
                d
            }
        };
        LoadedMachine::from_description(description, source, &SensorNoise::default())
            .map(Machine::of)
            .map_err(|e| door_error(py, e))
    }
}

/// Identifies the machine from measured data (`tricept identify`).
#[pyfunction]
#[pyo3(signature = (path=None, csv_text=None, name="<arrays>".to_string(), machine=None, params="paper15".to_string(), robust=true, tolerance_mm=None, angle_noise_arcsec=None, length_noise_um=None, readings_per_pose=None, campaigns=Vec::new(), prior=None))]
#[allow(clippy::too_many_arguments)]
fn identify(
    py: Python<'_>,
    path: Option<PathBuf>,
    csv_text: Option<String>,
    name: String,
    machine: Option<Bound<'_, PyAny>>,
    params: String,
    robust: bool,
    tolerance_mm: Option<f64>,
    angle_noise_arcsec: Option<f64>,
    length_noise_um: Option<f64>,
    readings_per_pose: Option<u32>,
    campaigns: Vec<PathBuf>,
    prior: Option<PathBuf>,
) -> PyResult<Calibration> {
    let noise = SensorNoise {
        angle_noise_arcsec,
        length_noise_um,
        readings_per_pose,
    };
    let machine = machine_input(py, machine.as_ref(), noise)?;
    let rows = arrays(&csv_text, &name);
    let data = match &csv_text {
        Some(_) => {
            let loaded = machine.clone().load().map_err(|e| door_error(py, e))?;
            data_input(py, path, csv_text.as_deref(), &name, &loaded)?
        }
        None => data_input_file(py, path)?,
    };
    let mut request = CalibrateRequest::new(data);
    request.machine = machine;
    request.parameter_set =
        ParameterSet::by_label(&params).map_err(|e| input_error(py, format!("params: {e}")))?;
    request.robust = robust;
    if let Some(t) = tolerance_mm {
        request.tolerance_mm = t;
    }
    request.campaigns = campaigns.into_iter().map(DataInput::File).collect();
    request.prior = prior;
    let inner = py
        .detach(|| tricept_ident::calibrate::calibrate(request))
        .map_err(|e| door_error_in(py, e, rows))?;
    Ok(Calibration { inner })
}

/// The data of a workflow given as a file path.
fn data_input_file(py: Python<'_>, path: Option<PathBuf>) -> PyResult<DataInput> {
    path.map(DataInput::File)
        .ok_or_else(|| input_error(py, "data: give a CSV path or a mapping of column arrays"))
}

/// A diagnosis (`tricept diagnose`): its exit code, JSON, report, and the
/// extended machine file it may write.
#[pyclass(module = "tricept._tricept")]
struct Diagnosis {
    inner: tricept_ident::diagnosis::DiagnoseResult,
}

#[pymethods]
impl Diagnosis {
    /// 0 the final model explains the data, 3 it does not.
    #[getter]
    fn exit_code(&self) -> u8 {
        self.inner.exit_code()
    }

    /// The JSON `tricept diagnose --json` prints.
    fn to_json(&self) -> String {
        versioned(&self.inner.to_json().to_string())
    }

    /// The text report `tricept diagnose` prints.
    fn report(&self) -> String {
        self.inner.report()
    }

    /// Writes the deployed machine file by the CLI's rule (`UntrustedError`
    /// unless the final model explains the data, or `force`).
    #[pyo3(signature = (path, force=false))]
    fn write_machine(
        &self,
        py: Python<'_>,
        path: PathBuf,
        force: bool,
    ) -> PyResult<Option<String>> {
        let written = self
            .inner
            .write_machine(&path, WriteOptions::default().force(force))
            .map_err(|e| door_error(py, e))?;
        Ok(written.forced().map(|why| {
            format!(
                "{}: written although {why} (forced)",
                written.path().display()
            )
        }))
    }

    /// The machine file it may write, as JSON (the door's `MachineFile`);
    /// `InputError` for data given as arrays.
    fn machine_file_json(&self, py: Python<'_>) -> PyResult<String> {
        machine_file_json(py, self.inner.machine_file())
    }
}

/// Diagnoses measured data (`tricept diagnose`).
#[pyfunction]
#[pyo3(signature = (path=None, csv_text=None, name="<arrays>".to_string(), machine=None, noise_from_data=false, dictionary=true, deploy_rule="expected-error".to_string()))]
#[allow(clippy::too_many_arguments)]
fn diagnose(
    py: Python<'_>,
    path: Option<PathBuf>,
    csv_text: Option<String>,
    name: String,
    machine: Option<Bound<'_, PyAny>>,
    noise_from_data: bool,
    dictionary: bool,
    deploy_rule: String,
) -> PyResult<Diagnosis> {
    let deploy_rule = deploy_rule.parse().map_err(|e| input_error(py, e))?;
    let loaded = machine_input(py, machine.as_ref(), SensorNoise::default())?
        .load()
        .map_err(|e| door_error(py, e))?;
    let data = data_input(py, path, csv_text.as_deref(), &name, &loaded)?;
    let mut request = DiagnoseRequest::new(data).machine(loaded);
    request.noise_from_data = noise_from_data;
    request.dictionary = dictionary;
    request.deploy_rule = deploy_rule;
    let inner = py
        .detach(|| tricept_ident::diagnosis::diagnose(request))
        .map_err(|e| door_error_in(py, e, arrays(&csv_text, &name)))?;
    Ok(Diagnosis { inner })
}

/// A check against a calibration (`tricept check`).
#[pyclass(module = "tricept._tricept", frozen)]
struct CheckResult {
    inner: tricept_ident::check::CheckResult,
}

#[pymethods]
impl CheckResult {
    /// 0 unchanged, 3 changed: the CLI's exit code.
    #[getter]
    fn exit_code(&self) -> u8 {
        self.inner.exit_code()
    }

    /// The JSON `tricept check --json` prints.
    fn to_json(&self) -> String {
        versioned(&self.inner.to_json().to_string())
    }

    /// The text report `tricept check` prints.
    fn report(&self) -> String {
        self.inner.report()
    }
}

/// Checks measured data against a calibrated machine (`tricept check`).
#[pyfunction]
#[pyo3(signature = (machine, path=None, csv_text=None, name="<arrays>".to_string(), alpha=None, history=None))]
fn check(
    py: Python<'_>,
    machine: Bound<'_, PyAny>,
    path: Option<PathBuf>,
    csv_text: Option<String>,
    name: String,
    alpha: Option<f64>,
    history: Option<PathBuf>,
) -> PyResult<CheckResult> {
    let loaded = machine_input(py, Some(&machine), SensorNoise::default())?
        .load()
        .map_err(|e| door_error(py, e))?;
    let data = data_input(py, path, csv_text.as_deref(), &name, &loaded)?;
    let mut request = CheckRequest::new(loaded, data);
    if let Some(a) = alpha {
        request.alpha = a;
    }
    request.history = history;
    let inner = py
        .detach(|| tricept_ident::check::check(request))
        .map_err(|e| door_error_in(py, e, arrays(&csv_text, &name)))?;
    Ok(CheckResult { inner })
}

/// Simulates a campaign (`tricept simulate`); returns the CSV text the CLI
/// writes (the Python half turns it into column arrays).
#[pyfunction]
#[pyo3(signature = (machine=None, truth="table2".to_string(), effects=Vec::new(), poses="grid".to_string(), seed=1, params="paper15".to_string(), both_directions=false, noise_factor=1.0, revisit=0))]
#[allow(clippy::too_many_arguments)]
fn simulate_csv(
    py: Python<'_>,
    machine: Option<Bound<'_, PyAny>>,
    truth: String,
    effects: Vec<String>,
    poses: String,
    seed: u64,
    params: String,
    both_directions: bool,
    noise_factor: f64,
    revisit: usize,
) -> PyResult<String> {
    let loaded = machine_input(py, machine.as_ref(), SensorNoise::default())?
        .load()
        .map_err(|e| door_error(py, e))?;
    let mut request = SimulateRequest::new().machine(loaded);
    request.truth = truth
        .parse::<TrueErrors>()
        .map_err(|e| input_error(py, format!("truth: {e}")))?;
    request.truth_effects =
        tricept_ident::advanced::parse_effects(&effects).map_err(|e| door_error(py, e))?;
    request.poses = poses.parse::<Poses>().map_err(|e| door_error(py, e))?;
    request.seed = seed;
    request.parameter_set =
        ParameterSet::by_label(&params).map_err(|e| input_error(py, format!("params: {e}")))?;
    request.both_directions = both_directions;
    request.noise_factor = noise_factor;
    request.revisit = revisit;
    let sim = py
        .detach(|| tricept_ident::simulate::simulate(request))
        .map_err(|e| door_error(py, e))?;
    let mut text = Vec::new();
    tricept_ident::advanced::files::write_to(&mut text, sim.data(), sim.comments())
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    String::from_utf8(text).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

/// Writes a machine file kept as JSON (`machine_file_json`) at `path` by
/// the write rule; returns the warning of a forced write.
#[pyfunction]
#[pyo3(signature = (file_json, path, force=false))]
fn write_machine_file(
    py: Python<'_>,
    file_json: &str,
    path: PathBuf,
    force: bool,
) -> PyResult<Option<String>> {
    let file = MachineFile::from_json(file_json).map_err(|e| door_error(py, e))?;
    file.write(&path, force).map_err(|e| door_error(py, e))
}

/// The calibrated machine of a machine file kept as JSON, in memory (its
/// record sealed as the file would be); `source` names it.
#[pyfunction]
fn machine_of_file(py: Python<'_>, file_json: &str, source: String) -> PyResult<Machine> {
    let file = MachineFile::from_json(file_json).map_err(|e| door_error(py, e))?;
    LoadedMachine::from_description(file.sealed(), source, &SensorNoise::default())
        .map(Machine::of)
        .map_err(|e| door_error(py, e))
}

/// A batch calibrated together (`tricept fleet`).
#[pyclass(module = "tricept._tricept", frozen)]
struct Fleet {
    inner: tricept_ident::fleet::FleetResult,
}

#[pymethods]
impl Fleet {
    /// 0 every machine fits and belongs, 3 a machine is kept out or the
    /// batch is not one population, 4 not converged: the CLI's exit code.
    #[getter]
    fn exit_code(&self) -> u8 {
        self.inner.exit_code()
    }

    /// The JSON `tricept fleet --json` prints.
    fn to_json(&self) -> String {
        versioned(&self.inner.to_json().to_string())
    }

    /// The text report `tricept fleet` prints.
    fn report(&self) -> String {
        self.inner.report()
    }

    /// Writes the batch's prior (`--write-prior`) by the CLI's rule:
    /// `UntrustedError` when the batch is not to be trusted, unless
    /// `force`. Returns why it was forced, if it was.
    #[pyo3(signature = (path, force=false))]
    fn write_prior(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<Option<String>> {
        self.inner
            .write_prior(&path, WriteOptions::default().force(force))
            .map(|written| written.forced().map(str::to_string))
            .map_err(|e| door_error(py, e))
    }
}

/// Calibrates a batch of machines together, one data file each
/// (`tricept fleet`).
#[pyfunction]
#[pyo3(signature = (paths, machine=None, params="paper15".to_string(), tolerance_mm=None, solver="schur".to_string()))]
fn fleet(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    machine: Option<Bound<'_, PyAny>>,
    params: String,
    tolerance_mm: Option<f64>,
    solver: String,
) -> PyResult<Fleet> {
    let mut request =
        tricept_ident::fleet::FleetRequest::new(paths.into_iter().map(DataInput::File).collect());
    request.machine = machine_input(py, machine.as_ref(), SensorNoise::default())?;
    request.parameter_set =
        ParameterSet::by_label(&params).map_err(|e| input_error(py, format!("params: {e}")))?;
    if let Some(t) = tolerance_mm {
        request.tolerance_mm = t;
    }
    request.solver = solver
        .parse()
        .map_err(|e: String| input_error(py, format!("solver: {e}")))?;
    let inner = py
        .detach(|| tricept_ident::fleet::fleet(request))
        .map_err(|e| door_error(py, e))?;
    Ok(Fleet { inner })
}

/// Writes the page of a calibrated machine (`tricept report`); returns the
/// verdict's JSON (`tricept report --json`) with the exit code.
#[pyfunction]
#[pyo3(signature = (machine, out, data=None, history=None, export=None))]
fn report(
    py: Python<'_>,
    machine: PathBuf,
    out: PathBuf,
    data: Option<PathBuf>,
    history: Option<PathBuf>,
    export: Option<PathBuf>,
) -> PyResult<String> {
    let mut request = tricept_ident::report::ReportRequest::new(machine.as_path(), out);
    request.data = data;
    request.history = history;
    request.export = export;
    let r = py
        .detach(|| tricept_ident::report::report(request))
        .map_err(|e| door_error(py, e))?;
    let mut v = r.to_json();
    if let Some(o) = v.as_object_mut() {
        // As it was: the verdict's keys without the output's version.
        o.shift_remove("format_version");
    }
    v["exit_code"] = r.exit_code().into();
    Ok(v.to_string())
}

/// Adds the workflows and their results to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Calibration>()?;
    m.add_class::<Diagnosis>()?;
    m.add_class::<CheckResult>()?;
    m.add_class::<Fleet>()?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(fleet, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_csv, m)?)?;
    m.add_function(wrap_pyfunction!(write_machine_file, m)?)?;
    m.add_function(wrap_pyfunction!(machine_of_file, m)?)?;
    m.add_function(wrap_pyfunction!(report, m)?)?;
    Ok(())
}

/// A workflow's JSON as `--json` prints it: `format_version` first
/// (`tricept_ident::advanced::versioned_json`), one line.
fn versioned(json: &str) -> String {
    tricept_ident::advanced::versioned_json(json)
        .map(|t| t.trim_end().to_string())
        .unwrap_or_else(|| json.to_string())
}
