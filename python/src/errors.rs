//! The door's errors as Python exceptions: `tricept.InputError` (a
//! `ValueError`) for the input's fault, the operating system's `OSError`
//! subclass for a file-system failure (built from its `errno`, so
//! `FileNotFoundError`, `PermissionError`, ...), `tricept.UntrustedError`
//! (a `RuntimeError` carrying the exit code) for a write the rule refuses,
//! `RuntimeError` for anything else, `MemoryError` for an allocation the
//! memory cannot hold. The classes are imported from `tricept._errors`, a
//! pure-Python module, so that they pickle by their public name
//! (`tricept.InputError`).

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

static INPUT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static UNTRUSTED_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// The exception of class `name` of `tricept._errors` with `args`.
fn raise<A>(py: Python<'_>, cell: &PyOnceLock<Py<PyType>>, name: &str, args: A) -> PyErr
where
    A: pyo3::PyErrArguments + Send + Sync + 'static,
{
    match cell.import(py, "tricept._errors", name) {
        Ok(ty) => PyErr::from_type(ty.clone(), args),
        Err(e) => e,
    }
}

/// `tricept.InputError(message)`.
pub(crate) fn input_error(py: Python<'_>, message: impl Into<String>) -> PyErr {
    raise(py, &INPUT_ERROR, "InputError", (message.into(),))
}

/// `MemoryError(message)`.
pub(crate) fn memory_error(message: String) -> PyErr {
    pyo3::exceptions::PyMemoryError::new_err(message)
}

/// A door error as a Python exception (see the module docs).
pub(crate) fn door_error(py: Python<'_>, e: tricept_ident::Error) -> PyErr {
    door_error_in(py, e, None)
}

/// [`door_error`] for a workflow whose data were column arrays named
/// `arrays` in messages: the CSV's line numbers become the arrays' rows.
pub(crate) fn door_error_in(
    py: Python<'_>,
    e: tricept_ident::Error,
    arrays: Option<&str>,
) -> PyErr {
    let message = match arrays {
        Some(name) if e.message().contains(name) => as_array_rows(e.message()),
        _ => e.message().to_string(),
    };
    if let Some(f) = e.file_failure()
        && let Some(errno) = f.os_error()
    {
        return pyo3::exceptions::PyOSError::new_err((errno, message, f.path().to_string()));
    }
    match e.kind() {
        tricept_ident::ErrorKind::Input => input_error(py, message),
        tricept_ident::ErrorKind::Inadequate | tricept_ident::ErrorKind::NotConverged => raise(
            py,
            &UNTRUSTED_ERROR,
            "UntrustedError",
            (message, e.exit_code()),
        ),
        _ => pyo3::exceptions::PyRuntimeError::new_err(message),
    }
}

/// A message about data the Python half wrote as CSV text from column
/// arrays (the column names on line 1, array row `i` on line `i + 2`),
/// with each `line N` said as the array's `row N-2` (line 1: the column
/// names).
fn as_array_rows(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find("line ") {
        let word_start = at == 0 || !rest[..at].ends_with(|c: char| c.is_alphanumeric());
        let digits: String = rest[at + 5..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        out.push_str(&rest[..at]);
        match digits.parse::<u64>() {
            Ok(line) if word_start => {
                if line >= 2 {
                    out.push_str(&format!("row {}", line - 2));
                } else {
                    out.push_str("the column names");
                }
                rest = &rest[at + 5 + digits.len()..];
            }
            _ => {
                out.push_str("line ");
                rest = &rest[at + 5..];
            }
        }
    }
    out.push_str(rest);
    out
}
