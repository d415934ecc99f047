//! `tricept._tricept`: the Python module over `tricept-ident`, the
//! library door. Machines and batch kinematics on numpy arrays: the input
//! is read in place when it is C-contiguous (else copied once), the output
//! is one array built in Rust and handed to numpy without a copy; the
//! points are solved in parallel (rayon) with the GIL released, each point
//! independently, so the result is the same at any thread count.
//!
//! The workflows (identify, diagnose, check, simulate, fleet) are the door's, the
//! same calls the CLI's verbs make: their JSON is the CLI's `--json`, their
//! exit codes the CLI's. Data come as a CSV file or as CSV text the Python
//! half writes from column arrays (shortest round-trip numbers: the same
//! bits as the arrays), read by the same strict reader.
//!
//! Errors the input causes raise `tricept.InputError` (a `ValueError`)
//! with the one-line message the CLI prints; a machine file refused by the
//! write rule raises `tricept.UntrustedError` with the exit code.

use std::borrow::Cow;
use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::prelude::*;
use rayon::prelude::*;
use tricept_ident::advanced::{LoadedMachine, ParameterSet, Poses, SensorNoise, TrueErrors};
use tricept_ident::calibrate::CalibrateRequest;
use tricept_ident::check::CheckRequest;
use tricept_ident::diagnosis::DiagnoseRequest;
use tricept_ident::kinematics::{ExtendedMachine, HeadBranch, KinematicsError, Vector3};
use tricept_ident::simulate::SimulateRequest;
use tricept_ident::{DataInput, MachineInput};

create_exception!(
    _tricept,
    InputError,
    pyo3::exceptions::PyValueError,
    "Bad input: a file, an array or an option; the message names the file, line and column, or the row."
);

create_exception!(
    _tricept,
    UntrustedError,
    pyo3::exceptions::PyRuntimeError,
    "A result that is not to be trusted was asked to be written (the CLI's refusal: exit code 3 or 4); `force=True` writes it, marked as forced."
);

/// The input error of a door error, or of any message.
fn input_error(message: impl Into<String>) -> PyErr {
    InputError::new_err(message.into())
}

/// A door error as a Python exception: input errors raise `InputError`,
/// anything else `RuntimeError`.
fn door_error(e: tricept_ident::Error) -> PyErr {
    match e.kind() {
        tricept_ident::ErrorKind::Input => input_error(e.message()),
        tricept_ident::ErrorKind::Inadequate | tricept_ident::ErrorKind::NotConverged => {
            UntrustedError::new_err((e.message().to_string(), e.exit_code()))
        }
        _ => pyo3::exceptions::PyRuntimeError::new_err(e.message().to_string()),
    }
}

/// A machine: the embedded Table 1 machine or a description file, a
/// calibrated one with its leg effects and compensation tables applied.
#[pyclass(module = "tricept._tricept", frozen)]
struct Machine {
    machine: ExtendedMachine,
    source: String,
}

/// The rows of an `(n, width)` float array, in place when C-contiguous.
fn rows<'a>(
    array: &'a PyReadonlyArray2<'_, f64>,
    width: usize,
    what: &str,
) -> PyResult<Cow<'a, [f64]>> {
    let shape = array.shape();
    if shape[1] != width {
        return Err(input_error(format!(
            "{what}: expected an (n, {width}) array, got shape ({}, {})",
            shape[0], shape[1]
        )));
    }
    Ok(match array.as_slice() {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(array.as_array().iter().copied().collect()),
    })
}

/// Solves every row of `input` (`width` values each) into `out_width`
/// values, in parallel with the GIL released; the first row that cannot
/// be solved (in row order) is the error.
fn solve_rows<'py, F>(
    py: Python<'py>,
    input: &[f64],
    width: usize,
    out_width: usize,
    what: &str,
    solve: F,
) -> PyResult<Bound<'py, PyArray2<f64>>>
where
    F: Fn(&[f64], &mut [f64]) -> Result<(), KinematicsError> + Sync,
{
    let n = input.len() / width;
    let result = py.detach(|| {
        let mut out = vec![0.0; n * out_width];
        let failures: Vec<(usize, KinematicsError)> = out
            .par_chunks_mut(out_width)
            .zip(input.par_chunks(width))
            .enumerate()
            .filter_map(|(i, (o, x))| solve(x, o).err().map(|e| (i, e)))
            .collect();
        match failures.into_iter().min_by_key(|(i, _)| *i) {
            Some(first) => Err(first),
            None => Ok(out),
        }
    });
    match result {
        Ok(out) => Array2::from_shape_vec((n, out_width), out)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string())),
        Err((i, e)) => Err(input_error(format!("{what}: row {i}: {e}"))),
    }
}

#[pymethods]
impl Machine {
    /// The paper's Table 1 machine (the CLI's default machine).
    #[staticmethod]
    fn paper() -> Machine {
        Machine {
            machine: ExtendedMachine::new(tricept_ident::kinematics::Machine::paper()),
            source: "the built-in Table 1 machine".into(),
        }
    }

    /// A machine description file, as every `--machine` of the CLI loads
    /// it: a calibrated file whose record does not match it (edited) is
    /// refused with `InputError`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Machine> {
        let loaded = MachineInput::from(path).load().map_err(door_error)?;
        Ok(Machine {
            machine: ExtendedMachine::new(loaded.machine().clone()),
            source: loaded.source().to_string(),
        })
    }

    /// Where the machine came from: the file name, or the built-in machine.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// Inverse kinematics of platform points: `points` is an `(n, 3)`
    /// array (mm); returns an `(n, 6)` array of `q1, q2, q3` (mm), `phi,
    /// theta` (rad) and `q4` (mm), the columns of `tricept ik --input`.
    fn ik<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let input = rows(&points, 3, "ik: points")?;
        let m = &self.machine;
        solve_rows(py, &input, 3, 6, "ik: points", |x, o| {
            let sol = m.inverse(&Vector3::new(x[0], x[1], x[2]))?;
            o[..3].copy_from_slice(&sol.legs_mm);
            o[3..].copy_from_slice(&[sol.up.phi_rad, sol.up.theta_rad, sol.up.q4_mm]);
            Ok(())
        })
    }

    /// Forward kinematics of leg commands: `q` is an `(n, 3)` array (mm);
    /// returns an `(n, 8)` array of `x, y, z` (mm), `phi, theta` (rad),
    /// `q4` (mm), the condition number and the iterations, the columns of
    /// `tricept fk --input`.
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let input = rows(&q, 3, "fk: q")?;
        let m = &self.machine;
        solve_rows(py, &input, 3, 8, "fk: q", |x, o| {
            let sol = m.forward(&[x[0], x[1], x[2]])?;
            let p = sol.position_mm;
            o.copy_from_slice(&[
                p.x,
                p.y,
                p.z,
                sol.up.phi_rad,
                sol.up.theta_rad,
                sol.up.q4_mm,
                sol.condition,
                f64::from(sol.iterations),
            ]);
            Ok(())
        })
    }

    /// 5-DOF tool-pose inverse kinematics: `points` (tool tips, mm) and
    /// `axes` (tool axes) are `(n, 3)` arrays; returns an `(n, 9)` array of
    /// `q1, q2, q3` (mm), `phi, theta` (rad), `q4` (mm), `h1, h2` (rad) and
    /// `head_singular` (0 or 1), the columns of `tricept tool-ik --input`.
    fn tool_ik<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        axes: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let tips = rows(&points, 3, "tool_ik: points")?;
        let dirs = rows(&axes, 3, "tool_ik: axes")?;
        if tips.len() != dirs.len() {
            return Err(input_error(format!(
                "tool_ik: points has {} rows and axes {}",
                tips.len() / 3,
                dirs.len() / 3
            )));
        }
        let input: Vec<f64> = tips
            .chunks(3)
            .zip(dirs.chunks(3))
            .flat_map(|(t, a)| t.iter().chain(a).copied())
            .collect();
        let m = &self.machine;
        solve_rows(py, &input, 6, 9, "tool_ik: points", |x, o| {
            let sol = m.tool_inverse(
                &Vector3::new(x[0], x[1], x[2]),
                &Vector3::new(x[3], x[4], x[5]),
                HeadBranch::default(),
            )?;
            o[..3].copy_from_slice(&sol.legs_mm);
            o[3..].copy_from_slice(&[
                sol.up.phi_rad,
                sol.up.theta_rad,
                sol.up.q4_mm,
                sol.head_rad[0],
                sol.head_rad[1],
                f64::from(u8::from(sol.head_singular)),
            ]);
            Ok(())
        })
    }

    fn __repr__(&self) -> String {
        format!("Machine({:?})", self.source)
    }
}

/// The machine of a workflow: a file, or the embedded Table 1 machine,
/// with sensor-noise overrides.
fn machine_of(path: Option<PathBuf>, noise: SensorNoise) -> PyResult<LoadedMachine> {
    MachineInput::new(path, noise).load().map_err(door_error)
}

/// Data given as a file path or as CSV text (named `name` in messages),
/// checked against `machine`'s stroke.
fn data_of(
    path: Option<PathBuf>,
    csv_text: Option<&str>,
    name: &str,
    machine: &tricept_ident::kinematics::Machine,
) -> PyResult<DataInput> {
    match (path, csv_text) {
        (Some(path), None) => Ok(DataInput::File(path)),
        (None, Some(text)) => Ok(DataInput::Memory(
            tricept_ident::advanced::read_data_from(text.as_bytes(), name, machine)
                .map_err(door_error)?,
        )),
        _ => Err(input_error(
            "data: give a CSV path or a mapping of column arrays",
        )),
    }
}

/// A calibration (`tricept identify`): its verdict, estimates, covariance,
/// JSON and report, and the machine file it may write.
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
        self.inner.to_json().to_string()
    }

    /// The text report `tricept identify` prints.
    fn report(&self) -> String {
        self.inner.report()
    }

    /// Writes the calibrated machine file by the CLI's rule: a fit whose
    /// exit code is not 0 raises `UntrustedError` unless `force`; data
    /// given as arrays cannot be recorded and raise `InputError`.
    #[pyo3(signature = (path, force=false))]
    fn write_machine(&mut self, path: PathBuf, force: bool) -> PyResult<String> {
        let written = self.inner.write_machine(&path, force).map_err(door_error)?;
        Ok(written.path().display().to_string())
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
    machine: Option<PathBuf>,
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
    let data = match (path, csv_text) {
        (Some(path), None) => DataInput::File(path),
        (None, Some(text)) => {
            let loaded = machine_of(machine.clone(), noise)?;
            DataInput::Memory(
                tricept_ident::advanced::read_data_from(text.as_bytes(), &name, loaded.machine())
                    .map_err(door_error)?,
            )
        }
        _ => {
            return Err(input_error(
                "data: give a CSV path or a mapping of column arrays",
            ));
        }
    };
    let mut request = CalibrateRequest::new(data);
    request.machine = MachineInput::new(machine, noise);
    request.parameter_set =
        ParameterSet::by_label(&params).map_err(|e| input_error(format!("params: {e}")))?;
    request.robust = robust;
    if let Some(t) = tolerance_mm {
        request.tolerance_mm = t;
    }
    request.campaigns = campaigns.into_iter().map(DataInput::File).collect();
    request.prior = prior;
    let inner = py
        .detach(|| tricept_ident::calibrate::calibrate(request))
        .map_err(door_error)?;
    Ok(Calibration { inner })
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
        self.inner.to_json()
    }

    /// The text report `tricept diagnose` prints.
    fn report(&self) -> String {
        self.inner.to_text()
    }

    /// Writes the deployed machine file by the CLI's rule (`UntrustedError`
    /// unless the final model explains the data, or `force`).
    #[pyo3(signature = (path, force=false))]
    fn write_machine(&self, path: PathBuf, force: bool) -> PyResult<Option<String>> {
        self.inner.write_machine(&path, force).map_err(door_error)
    }
}

/// Diagnoses measured data (`tricept diagnose`).
#[pyfunction]
#[pyo3(signature = (path=None, csv_text=None, name="<arrays>".to_string(), machine=None, noise_from_data=false, dictionary=true, deploy_rule="confident".to_string()))]
#[allow(clippy::too_many_arguments)]
fn diagnose(
    py: Python<'_>,
    path: Option<PathBuf>,
    csv_text: Option<String>,
    name: String,
    machine: Option<PathBuf>,
    noise_from_data: bool,
    dictionary: bool,
    deploy_rule: String,
) -> PyResult<Diagnosis> {
    let deploy_rule = deploy_rule.parse().map_err(input_error)?;
    let loaded = machine_of(machine, SensorNoise::default())?;
    let data = data_of(path, csv_text.as_deref(), &name, loaded.machine())?;
    let mut request = DiagnoseRequest::new(loaded, data);
    request.noise_from_data = noise_from_data;
    request.dictionary = dictionary;
    request.deploy_rule = deploy_rule;
    let inner = py
        .detach(|| tricept_ident::diagnosis::diagnose(request))
        .map_err(door_error)?;
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
        self.inner.to_json()
    }

    /// The text report `tricept check` prints.
    fn report(&self) -> String {
        self.inner.to_text()
    }
}

/// Checks measured data against a calibrated machine file (`tricept check`).
#[pyfunction]
#[pyo3(signature = (machine, path=None, csv_text=None, name="<arrays>".to_string(), alpha=None, history=None))]
fn check(
    py: Python<'_>,
    machine: PathBuf,
    path: Option<PathBuf>,
    csv_text: Option<String>,
    name: String,
    alpha: Option<f64>,
    history: Option<PathBuf>,
) -> PyResult<CheckResult> {
    let loaded = machine_of(Some(machine), SensorNoise::default())?;
    let data = data_of(path, csv_text.as_deref(), &name, loaded.machine())?;
    let mut request = CheckRequest::new(loaded, data);
    if let Some(a) = alpha {
        request.alpha = a;
    }
    request.history = history;
    let inner = py
        .detach(|| tricept_ident::check::check(request))
        .map_err(door_error)?;
    Ok(CheckResult { inner })
}

/// Simulates a campaign (`tricept simulate`); returns the CSV text the CLI
/// writes (the Python half turns it into column arrays).
#[pyfunction]
#[pyo3(signature = (machine=None, truth="table2".to_string(), effects=Vec::new(), poses="grid".to_string(), seed=1, params="paper15".to_string(), both_directions=false, noise_factor=1.0))]
#[allow(clippy::too_many_arguments)]
fn simulate_csv(
    py: Python<'_>,
    machine: Option<PathBuf>,
    truth: String,
    effects: Vec<String>,
    poses: String,
    seed: u64,
    params: String,
    both_directions: bool,
    noise_factor: f64,
) -> PyResult<String> {
    let mut request = SimulateRequest::new(machine_of(machine, SensorNoise::default())?);
    request.truth = truth
        .parse::<TrueErrors>()
        .map_err(|e| input_error(format!("truth: {e}")))?;
    request.truth_effects = tricept_ident::advanced::parse_effects(&effects).map_err(door_error)?;
    request.poses = poses.parse::<Poses>().map_err(door_error)?;
    request.seed = seed;
    request.parameter_set =
        ParameterSet::by_label(&params).map_err(|e| input_error(format!("params: {e}")))?;
    request.both_directions = both_directions;
    request.noise_factor = noise_factor;
    let sim = py
        .detach(|| tricept_ident::simulate::simulate(request))
        .map_err(door_error)?;
    let mut text = Vec::new();
    tricept_data::write_to(&mut text, sim.data(), sim.comments())
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    String::from_utf8(text).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
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
        self.inner.to_json().to_string()
    }

    /// The text report `tricept fleet` prints.
    fn report(&self) -> String {
        self.inner.report()
    }

    /// Writes the batch's prior (`--write-prior`) by the CLI's rule:
    /// `UntrustedError` when the batch is not to be trusted, unless
    /// `force`. Returns why it was forced, if it was.
    #[pyo3(signature = (path, force=false))]
    fn write_prior(&self, path: PathBuf, force: bool) -> PyResult<Option<String>> {
        self.inner.write_prior(&path, force).map_err(door_error)
    }
}

/// Calibrates a batch of machines together, one data file each
/// (`tricept fleet`).
#[pyfunction]
#[pyo3(signature = (paths, machine=None, params="paper15".to_string(), tolerance_mm=None, solver="schur".to_string()))]
fn fleet(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    machine: Option<PathBuf>,
    params: String,
    tolerance_mm: Option<f64>,
    solver: String,
) -> PyResult<Fleet> {
    let mut request = tricept_ident::fleet::FleetRequest::new(
        paths.into_iter().map(DataInput::File).collect(),
    );
    request.machine = MachineInput::new(machine, SensorNoise::default());
    request.parameter_set =
        ParameterSet::by_label(&params).map_err(|e| input_error(format!("params: {e}")))?;
    if let Some(t) = tolerance_mm {
        request.tolerance_mm = t;
    }
    request.solver = solver
        .parse()
        .map_err(|e: String| input_error(format!("solver: {e}")))?;
    let inner = py
        .detach(|| tricept_ident::fleet::fleet(request))
        .map_err(door_error)?;
    Ok(Fleet { inner })
}

/// The compiled half of the `tricept` package.
#[pymodule]
fn _tricept(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Machine>()?;
    m.add_class::<Calibration>()?;
    m.add_class::<Diagnosis>()?;
    m.add_class::<CheckResult>()?;
    m.add_class::<Fleet>()?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(fleet, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_csv, m)?)?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("UntrustedError", m.py().get_type::<UntrustedError>())?;
    Ok(())
}
