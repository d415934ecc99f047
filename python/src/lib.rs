//! `tricept._tricept`: the Python module over `tricept-ident`, the
//! library door. Machines and batch kinematics on numpy arrays: the input
//! is read in place when it is C-contiguous (else copied once), the output
//! is one array built in Rust and handed to numpy without a copy; the
//! points are solved in parallel (rayon) with the GIL released, each point
//! independently, so the result is the same at any thread count.
//!
//! Errors the input causes raise `tricept.InputError` (a `ValueError`)
//! with the one-line message the CLI prints.

use std::borrow::Cow;
use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::prelude::*;
use rayon::prelude::*;
use tricept_ident::nalgebra::Vector3;
use tricept_ident::{ExtendedMachine, HeadBranch, KinematicsError, SensorNoise};

create_exception!(
    _tricept,
    InputError,
    pyo3::exceptions::PyValueError,
    "Bad input: a file, an array or an option; the message names the file, line and column, or the row."
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
            machine: ExtendedMachine::new(tricept_ident::Machine::paper()),
            source: "the built-in Table 1 machine".into(),
        }
    }

    /// A machine description file, as every `--machine` of the CLI loads
    /// it: a calibrated file whose record does not match it (edited) is
    /// refused with `InputError`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Machine> {
        let loaded =
            tricept_ident::load_machine(Some(&path), &SensorNoise::default()).map_err(door_error)?;
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

/// The compiled half of the `tricept` package.
#[pymodule]
fn _tricept(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Machine>()?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    Ok(())
}
