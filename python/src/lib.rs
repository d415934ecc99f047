//! `tricept._tricept`: the Python module over `tricept-ident`, the
//! library door. Machines and batch kinematics on numpy arrays: the input
//! is read in place when it is C-contiguous (else copied once), the output
//! is one array built in Rust and handed to numpy without a copy; the
//! points are solved in parallel (rayon) with the GIL released, each point
//! independently, so the result is the same at any thread count. An output
//! sized by the input is allocated fallibly: an allocation the memory
//! cannot hold raises `MemoryError` instead of aborting the interpreter.
//!
//! The workflows (identify, diagnose, check, simulate) are the door's, the
//! same calls the CLI's verbs make (`workflows.rs`): their JSON is the
//! CLI's `--json`, their exit codes the CLI's. Data come as a CSV file or
//! as CSV text the Python half writes from column arrays (shortest
//! round-trip numbers: the same bits as the arrays), read by the same
//! strict reader.
//!
//! Errors (`errors.rs`): the input's fault raises `tricept.InputError` (a
//! `ValueError`) with the one-line message the CLI prints; a file-system
//! failure the operating system's `OSError` subclass (`FileNotFoundError`,
//! `PermissionError`, ...); a machine file refused by the write rule
//! `tricept.UntrustedError` with the exit code. The exception classes live
//! in the Python package (`tricept._errors`), so that they pickle.

mod errors;
mod workflows;

use std::borrow::Cow;
use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;
use tricept_ident::LoadedMachine;
use tricept_ident::MachineInput;
use tricept_ident::advanced::SensorNoise;
use tricept_ident::kinematics::{ExtendedMachine, HeadBranch, KinematicsError, Vector3};

use crate::errors::{door_error, input_error, memory_error};

/// A machine: the embedded Table 1 machine, a description file, a
/// description's JSON text, or a calibration's result; a calibrated one
/// with its leg effects and compensation tables applied.
#[pyclass(module = "tricept._tricept", frozen)]
pub(crate) struct Machine {
    loaded: LoadedMachine,
    machine: ExtendedMachine,
}

impl Machine {
    /// The Python machine of a loaded one.
    pub(crate) fn of(loaded: LoadedMachine) -> Machine {
        Machine {
            machine: loaded.commanding().extended().clone(),
            loaded,
        }
    }

    /// The machine as a workflow takes it, with the noise overrides.
    pub(crate) fn input(&self, noise: &SensorNoise) -> Result<MachineInput, tricept_ident::Error> {
        Ok(MachineInput::from(self.loaded.clone().with_noise(noise)?))
    }
}

/// A vector of `n` zeros allocated fallibly: `MemoryError` when the
/// memory cannot hold it (or `n` overflows).
fn zeros(n: Option<usize>, what: &str) -> PyResult<Vec<f64>> {
    let n = n.ok_or_else(|| memory_error(format!("{what}: too many values")))?;
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|e| {
        memory_error(format!(
            "{what}: cannot allocate {n} values ({} bytes): {e}",
            n.saturating_mul(8)
        ))
    })?;
    v.resize(n, 0.0);
    Ok(v)
}

/// The rows of an `(n, width)` float array, in place when C-contiguous
/// (else copied into a fallibly allocated vector).
fn rows<'a>(
    py: Python<'_>,
    array: &'a PyReadonlyArray2<'_, f64>,
    width: usize,
    what: &str,
) -> PyResult<Cow<'a, [f64]>> {
    let shape = array.shape();
    if shape[1] != width {
        return Err(input_error(
            py,
            format!(
                "{what}: expected an (n, {width}) array, got shape ({}, {})",
                shape[0], shape[1]
            ),
        ));
    }
    Ok(match array.as_slice() {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => {
            let mut v = zeros(shape[0].checked_mul(width), what)?;
            for (o, x) in v.iter_mut().zip(array.as_array().iter()) {
                *o = *x;
            }
            Cow::Owned(v)
        }
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
    let mut out = zeros(n.checked_mul(out_width), what)?;
    let failure = py.detach(|| {
        out.par_chunks_mut(out_width)
            .zip(input.par_chunks(width))
            .enumerate()
            .filter_map(|(i, (o, x))| solve(x, o).err().map(|e| (i, e)))
            .min_by_key(|(i, _)| *i)
    });
    match failure {
        None => Array2::from_shape_vec((n, out_width), out)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string())),
        Some((i, e)) => Err(input_error(py, format!("{what}: row {i}: {e}"))),
    }
}

#[pymethods]
impl Machine {
    /// The paper's Table 1 machine (the CLI's default machine).
    #[staticmethod]
    fn paper(py: Python<'_>) -> PyResult<Machine> {
        let loaded = MachineInput::default()
            .load()
            .map_err(|e| door_error(py, e))?;
        Ok(Machine::of(loaded))
    }

    /// A machine description file, as every `--machine` of the CLI loads
    /// it: a calibrated file whose record does not match it (edited) is
    /// refused with `InputError`, a missing file with `FileNotFoundError`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Machine> {
        let loaded = MachineInput::from(path)
            .load()
            .map_err(|e| door_error(py, e))?;
        Ok(Machine::of(loaded))
    }

    /// A machine from a description's JSON text (what `to_json` gives),
    /// checked as a file is; `source` names it in messages.
    #[staticmethod]
    #[pyo3(signature = (text, source="<json>".to_string()))]
    fn from_json(py: Python<'_>, text: &str, source: String) -> PyResult<Machine> {
        let d = tricept_ident::kinematics::MachineDescription::from_json(text)
            .map_err(|e| door_error(py, tricept_ident::Error::from(e).in_file(&source)))?;
        let loaded = LoadedMachine::from_description(d, source, &SensorNoise::default())
            .map_err(|e| door_error(py, e))?;
        Ok(Machine::of(loaded))
    }

    /// The machine's description as JSON text (with the calibration
    /// record of a calibrated machine): what `tricept machine --json`
    /// prints, and what `from_json` reads back.
    fn to_json(&self) -> String {
        self.loaded.description().to_json()
    }

    /// Where the machine came from: the file name, or the built-in machine.
    #[getter]
    fn source(&self) -> &str {
        self.loaded.source()
    }

    /// The machine's name (its description's `name`).
    #[getter]
    fn name(&self) -> &str {
        &self.loaded.description().name
    }

    /// The method of the calibration the machine holds (`identify`,
    /// `diagnose`, ...), `None` for a machine without a calibration record.
    #[getter]
    fn calibration(&self) -> Option<String> {
        self.loaded
            .description()
            .calibration
            .as_ref()
            .map(|c| c.method.clone())
    }

    /// What loading it warned of (a forced or inadequate calibration), one
    /// line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.warnings().to_vec()
    }

    /// Inverse kinematics of platform points: `points` is an `(n, 3)`
    /// array (mm); returns an `(n, 6)` array of `q1, q2, q3` (mm), `phi,
    /// theta` (rad) and `q4` (mm), the columns of `tricept ik --input`.
    fn ik<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let input = rows(py, &points, 3, "ik: points")?;
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
        let input = rows(py, &q, 3, "fk: q")?;
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
        let tips = rows(py, &points, 3, "tool_ik: points")?;
        let dirs = rows(py, &axes, 3, "tool_ik: axes")?;
        if tips.len() != dirs.len() {
            return Err(input_error(
                py,
                format!(
                    "tool_ik: points has {} rows and axes {}",
                    tips.len() / 3,
                    dirs.len() / 3
                ),
            ));
        }
        let mut input = zeros(tips.len().checked_mul(2), "tool_ik: points")?;
        for ((o, t), a) in input.chunks_mut(6).zip(tips.chunks(3)).zip(dirs.chunks(3)) {
            o[..3].copy_from_slice(t);
            o[3..].copy_from_slice(a);
        }
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
        let d = self.loaded.description();
        match &d.calibration {
            Some(c) => format!(
                "Machine({:?}, name={:?}, calibrated by {}{})",
                self.loaded.source(),
                d.name,
                c.method,
                if c.forced { ", forced" } else { "" }
            ),
            None => format!("Machine({:?}, name={:?})", self.loaded.source(), d.name),
        }
    }
}

/// The compiled half of the `tricept` package.
#[pymodule]
fn _tricept(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Machine>()?;
    workflows::register(m)
}
