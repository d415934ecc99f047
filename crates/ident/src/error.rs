//! The door's one error type and the one mapping from a library error's
//! kind to the process exit code, for every verb.
//!
//! Every error of the crates behind the door is [`Classify`]: its kind
//! says whether the user's input is at fault ([`ErrorKind::Input`], exit
//! code 2) or not ([`ErrorKind::Other`], exit code 1). The mapping lives
//! here alone, so the same library error exits with the same code from
//! every verb that can meet it.

use std::fmt;
use std::sync::Arc;

use crate::Setting;

/// Exit code of a result that can be trusted.
///
/// # Example
/// ```
/// use tricept_ident::{EXIT_OK, ErrorKind};
/// use tricept_ident::kinematics::Machine;
/// // Only a workflow that succeeded with a good verdict exits with it.
/// assert!(Machine::load("no/such/machine.json").is_err_and(|e| e.exit_code() != EXIT_OK));
/// assert_ne!(ErrorKind::Input.exit_code(), EXIT_OK);
/// ```
pub const EXIT_OK: u8 = 0;
/// Exit code of anything that is not the input's fault.
///
/// # Example
/// ```
/// use tricept_ident::{EXIT_OTHER, ErrorKind};
/// assert_eq!(ErrorKind::Other.exit_code(), EXIT_OTHER);
/// assert_eq!(ErrorKind::of_exit_code(EXIT_OTHER), ErrorKind::Other);
/// ```
pub const EXIT_OTHER: u8 = 1;
/// Exit code of bad input: a file, a flag, a request.
///
/// # Example
/// ```
/// use tricept_ident::EXIT_INPUT;
/// use tricept_ident::kinematics::Machine;
/// // A file that is not there: the user's input is at fault.
/// let e = Machine::load("no/such/machine.json").unwrap_err();
/// assert_eq!(e.exit_code(), EXIT_INPUT);
/// ```
pub const EXIT_INPUT: u8 = 2;
/// Exit code of a fit that converged but whose model does not explain the
/// data, or of a campaign too small to calibrate.
///
/// # Example
/// ```
/// use tricept_ident::{EXIT_INADEQUATE, ErrorKind};
/// assert_eq!(ErrorKind::Inadequate.exit_code(), EXIT_INADEQUATE);
/// assert_eq!(ErrorKind::of_exit_code(EXIT_INADEQUATE), ErrorKind::Inadequate);
/// ```
pub const EXIT_INADEQUATE: u8 = 3;
/// Exit code of a fit that did not converge.
///
/// # Example
/// ```
/// use tricept_ident::{EXIT_NOT_CONVERGED, ErrorKind};
/// assert_eq!(ErrorKind::NotConverged.exit_code(), EXIT_NOT_CONVERGED);
/// ```
pub const EXIT_NOT_CONVERGED: u8 = 4;

/// Whose fault a failure is, which decides the exit code.
///
/// # Example
/// ```
/// use tricept_ident::{ErrorKind, EXIT_INPUT};
/// assert_eq!(ErrorKind::Input.exit_code(), EXIT_INPUT);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input is at fault: a file, a flag, data that cannot be used
    /// (exit code 2).
    Input,
    /// Anything else: a numerical failure, an I/O failure of an output
    /// (exit code 1).
    Other,
    /// A result that is not to be trusted because its model does not
    /// explain the data (exit code 3): a refused write, say.
    Inadequate,
    /// A result that is not to be trusted because its fit did not converge
    /// (exit code 4).
    NotConverged,
}

impl ErrorKind {
    /// The process exit code of a failure of this kind.
    pub fn exit_code(self) -> u8 {
        match self {
            ErrorKind::Input => EXIT_INPUT,
            ErrorKind::Other => EXIT_OTHER,
            ErrorKind::Inadequate => EXIT_INADEQUATE,
            ErrorKind::NotConverged => EXIT_NOT_CONVERGED,
        }
    }

    /// The kind whose exit code is `code` (a verdict's code: 3 inadequate,
    /// 4 not converged, 2 input; anything else is [`ErrorKind::Other`]).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{ErrorKind, EXIT_INADEQUATE};
    /// assert_eq!(ErrorKind::of_exit_code(EXIT_INADEQUATE), ErrorKind::Inadequate);
    /// assert_eq!(ErrorKind::of_exit_code(EXIT_INADEQUATE).exit_code(), EXIT_INADEQUATE);
    /// ```
    pub fn of_exit_code(code: u8) -> ErrorKind {
        match code {
            EXIT_INPUT => ErrorKind::Input,
            EXIT_INADEQUATE => ErrorKind::Inadequate,
            EXIT_NOT_CONVERGED => ErrorKind::NotConverged,
            _ => ErrorKind::Other,
        }
    }
}

/// What failed, for a program to match on (the message says it for
/// people): a file not found or unreadable, a parse error at a line and
/// column, a file of a newer format, a sealed file edited, a write
/// refused by the rule that only a trusted result is written, a fit that
/// did not converge or does not explain its data, another invalid input,
/// or anything else. [`Error::cause`] gives it.
///
/// # Example
/// ```
/// use tricept_ident::{ErrorCause, MachineInput};
/// use tricept_ident::kinematics::Machine;
/// let e = Machine::load("no/such/machine.json").unwrap_err();
/// assert!(matches!(e.cause(), ErrorCause::NotFound { path } if path == "no/such/machine.json"));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorCause {
    /// A file that does not exist.
    NotFound {
        /// The file, as given.
        path: String,
    },
    /// A file that exists but cannot be read or written (permissions, a
    /// directory, an I/O error).
    Unreadable {
        /// The file, as given.
        path: String,
    },
    /// A file that does not parse: where (1-based; `None` when the reader
    /// cannot say).
    Parse {
        /// The line.
        line: Option<u64>,
        /// The column (a 1-based character column of a JSON file; `None`
        /// for a CSV row, whose column is named in the message).
        column: Option<u64>,
    },
    /// A file whose `format_version` is newer than this tricept reads.
    NewerFormat {
        /// The version the file declares.
        found: u64,
        /// The newest this tricept reads.
        supported: u32,
    },
    /// A sealed file (a calibrated machine file) edited after it was
    /// written: the fields that differ.
    SealBroken {
        /// The edited fields, as named in the file.
        fields: Vec<String>,
    },
    /// A write refused: the result is not to be trusted (its exit code
    /// says why) and writing was not forced.
    RefusedWrite,
    /// A fit that did not converge (exit code 4), when nothing more is
    /// known. No workflow of this version fails this way: a fit that does
    /// not converge is a *result* whose `exit_code()` is 4, and writing its
    /// file unforced is a [`ErrorCause::RefusedWrite`] of kind
    /// [`ErrorKind::NotConverged`]. Kept for errors of that kind a later
    /// version may raise, so that a program's match already covers them.
    NotConverged,
    /// A model that does not explain the data (exit code 3), when nothing
    /// more is known. As with [`ErrorCause::NotConverged`], an inadequate
    /// fit is a result (exit code 3) and writing it unforced is a
    /// [`ErrorCause::RefusedWrite`] of kind [`ErrorKind::Inadequate`].
    Inadequate,
    /// Another input that cannot be used (exit code 2).
    Invalid,
    /// Anything else (exit code 1).
    Other,
}

impl ErrorCause {
    /// The cause a failure of `kind` has when nothing more is known.
    fn of_kind(kind: ErrorKind) -> ErrorCause {
        match kind {
            ErrorKind::Input => ErrorCause::Invalid,
            ErrorKind::Other => ErrorCause::Other,
            ErrorKind::Inadequate => ErrorCause::Inadequate,
            ErrorKind::NotConverged => ErrorCause::NotConverged,
        }
    }
}

/// A library error that knows whose fault it is.
///
/// # Example
/// ```
/// use tricept_ident::ErrorKind;
/// use tricept_ident::advanced::Classify;
/// use tricept_ident::export::ExportError;
/// let e = ExportError::Options("max_points: must be at least 2".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// ```
pub trait Classify {
    /// Whose fault this error is.
    fn kind(&self) -> ErrorKind;

    /// The file-system failure under it, if there is one.
    fn file_failure(&self) -> Option<FileFailure> {
        None
    }

    /// What failed, when it says more than its kind.
    fn cause(&self) -> Option<ErrorCause> {
        None
    }

    /// The request setting the error is about, by its name
    /// ([`Setting::name`]), and why it is refused: the message is then
    /// `NAME: WHY`.
    fn setting(&self) -> Option<(&'static str, String)> {
        None
    }
}

/// A failure of a workflow: a one-line message (naming the file, line and
/// column where there is one), its [`ErrorKind`], what failed
/// ([`Error::cause`]), the request setting it is about
/// ([`Error::setting`]) and the library error under it
/// ([`source`](std::error::Error::source)).
///
/// # Example
/// ```
/// use tricept_ident::{Error, EXIT_INPUT};
/// let e = Error::input("the false-alarm probability must lie between 0 and 0.5, got 2").in_file("check");
/// assert_eq!(e.exit_code(), EXIT_INPUT);
/// assert_eq!(e.to_string(), "check: the false-alarm probability must lie between 0 and 0.5, got 2");
/// ```
#[derive(Debug, Clone)]
pub struct Error {
    kind: ErrorKind,
    message: String,
    file: Option<Box<FileFailure>>,
    cause: Option<ErrorCause>,
    setting: Option<Box<Named>>,
    source: Option<Arc<dyn std::error::Error + Send + Sync + 'static>>,
}

/// Where an [`Error`]'s message names its setting: the message is
/// `before`, the setting's name, `after`.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Named {
    setting: Setting,
    before: String,
    after: String,
}

impl Named {
    fn render(&self, name: &str) -> String {
        tricept_data::message::one_line(&format!("{}{name}{}", self.before, self.after))
    }
}

/// Two errors are equal when their kind, message, file failure and cause
/// are (the underlying error is not compared).
impl PartialEq for Error {
    fn eq(&self, other: &Error) -> bool {
        self.kind == other.kind
            && self.message == other.message
            && self.file == other.file
            && self.cause == other.cause
            && self.setting == other.setting
    }
}

impl Eq for Error {}

/// The file-system failure under an [`Error`] (a file that cannot be
/// opened, read or written): the file and the operating system's error,
/// for a caller that raises the platform's own error (Python's `OSError`
/// subclasses: `FileNotFoundError`, `PermissionError`, ...).
///
/// # Example
/// ```
/// use tricept_ident::advanced::load_machine;
/// use tricept_ident::advanced::SensorNoise;
/// let e = load_machine(Some("no/such.json".as_ref()), &SensorNoise::default()).unwrap_err();
/// let f = e.file_failure().unwrap();
/// assert_eq!(f.path(), "no/such.json");
/// assert_eq!(f.io_kind(), std::io::ErrorKind::NotFound);
/// assert_eq!(f.os_error(), Some(2)); // ENOENT
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileFailure {
    path: String,
    os_error: Option<i32>,
    io_kind: std::io::ErrorKind,
}

impl FileFailure {
    /// The failure of `path` with the I/O error `e`.
    pub fn new(path: impl Into<String>, e: &std::io::Error) -> FileFailure {
        FileFailure {
            path: path.into(),
            os_error: e.raw_os_error(),
            io_kind: e.kind(),
        }
    }

    /// The file, as given.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The operating system's error number (`errno`), when the failure
    /// came from the operating system.
    pub fn os_error(&self) -> Option<i32> {
        self.os_error
    }

    /// The kind of the I/O error.
    pub fn io_kind(&self) -> std::io::ErrorKind {
        self.io_kind
    }
}

impl Error {
    /// An error of the given kind. The message is made one bounded line
    /// ([`tricept_data::message::one_line`]): what it repeats of the input (a key,
    /// a value, a path) is cut and its control characters escaped.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{Error, ErrorKind};
    /// let e = Error::new(ErrorKind::Input, format!("unknown key `{}`", "k".repeat(1 << 20)));
    /// assert!(e.message().len() < 1000);
    /// assert_eq!(Error::input("a\nb\u{1b}[2J").message(), "a\\nb\\u{1b}[2J");
    /// ```
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Error {
        Error {
            kind,
            message: tricept_data::message::one_line(&message.into()),
            file: None,
            cause: None,
            setting: None,
            source: None,
        }
    }

    /// An error of the user's input about one setting of a request:
    /// `NAME: WHY`, with NAME the setting's [`Setting::name`] (a program
    /// names it its own way with [`Error::message_naming`]).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{Error, Setting, EXIT_INPUT};
    /// let e = Error::invalid(Setting::ToleranceMm, "must be above 0, got -1");
    /// assert_eq!(e.to_string(), "tolerance_mm: must be above 0, got -1");
    /// assert_eq!(e.exit_code(), EXIT_INPUT);
    /// ```
    pub fn invalid(setting: Setting, why: impl fmt::Display) -> Error {
        Error::naming(ErrorKind::Input, setting, format!(": {why}"))
    }

    /// An error of the user's input about one value of a setting:
    /// `NAME VALUE: WHY`.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{Error, Setting};
    /// let e = Error::invalid_value(Setting::Poses, "`grid:x`", "not a number");
    /// assert_eq!(e.to_string(), "poses `grid:x`: not a number");
    /// assert_eq!(e.message_naming(|_| "--poses"), "--poses `grid:x`: not a number");
    /// ```
    pub fn invalid_value(
        setting: Setting,
        value: impl fmt::Display,
        why: impl fmt::Display,
    ) -> Error {
        Error::naming(ErrorKind::Input, setting, format!(" {value}: {why}"))
    }

    /// An error of `kind` whose message is the setting's name, then
    /// `after`.
    pub(crate) fn naming(kind: ErrorKind, setting: Setting, after: String) -> Error {
        let named = Named {
            setting,
            before: String::new(),
            after,
        };
        Error {
            message: named.render(setting.name()),
            setting: Some(Box::new(named)),
            ..Error::new(kind, "")
        }
    }

    /// The request setting this error is about, if it is about one.
    pub fn setting(&self) -> Option<Setting> {
        self.setting.as_ref().map(|n| n.setting)
    }

    /// The message with the setting it is about named by `name` (a
    /// program's own name for it: a command-line flag, a keyword
    /// argument); the message itself when it is about no setting.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{Error, Setting};
    /// let e = Error::invalid(Setting::Alpha, "must lie between 0 and 0.5, got 2").in_file("check");
    /// assert_eq!(e.message_naming(|_| "--alpha"), "check: --alpha: must lie between 0 and 0.5, got 2");
    /// assert_eq!(Error::input("x").message_naming(|_| "--alpha"), "x");
    /// ```
    pub fn message_naming<'a>(&self, name: impl FnOnce(Setting) -> &'a str) -> String {
        match &self.setting {
            Some(n) => n.render(name(n.setting)),
            None => self.message.clone(),
        }
    }

    /// The same error, about `setting`: `NAME: ` before its message (a
    /// setting it was about already is then named by its request field).
    #[must_use]
    pub fn in_setting(self, setting: Setting) -> Error {
        self.about(setting, String::new())
    }

    /// The same error, about the value `value` of `setting`: `NAME VALUE: `
    /// before its message.
    #[must_use]
    pub fn in_setting_value(self, setting: Setting, value: impl fmt::Display) -> Error {
        self.about(setting, format!(" {value}"))
    }

    fn about(self, setting: Setting, value: String) -> Error {
        let named = Named {
            setting,
            before: String::new(),
            after: format!("{value}: {}", self.message),
        };
        Error {
            message: named.render(setting.name()),
            setting: Some(Box::new(named)),
            ..self
        }
    }

    /// What failed ([`ErrorCause`]): a file not found, a parse error at a
    /// line and column, a broken seal, a refused write, ...; else what
    /// the kind says ([`ErrorCause::Invalid`] for bad input).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{Error, ErrorCause};
    /// assert_eq!(Error::input("x").cause(), ErrorCause::Invalid);
    /// assert_eq!(Error::other("x").cause(), ErrorCause::Other);
    /// ```
    pub fn cause(&self) -> ErrorCause {
        if let Some(c) = &self.cause {
            return c.clone();
        }
        match &self.file {
            Some(f) if f.io_kind() == std::io::ErrorKind::NotFound => ErrorCause::NotFound {
                path: f.path().to_string(),
            },
            Some(f) => ErrorCause::Unreadable {
                path: f.path().to_string(),
            },
            None => ErrorCause::of_kind(self.kind),
        }
    }

    /// The same error, of cause `cause`.
    #[must_use]
    pub fn with_cause(mut self, cause: ErrorCause) -> Error {
        self.cause = Some(cause);
        self
    }

    /// The same error, caused by the library error `source`
    /// ([`std::error::Error::source`] returns it).
    #[must_use]
    pub fn with_source(mut self, source: impl std::error::Error + Send + Sync + 'static) -> Error {
        self.source = Some(Arc::new(source));
        self
    }

    /// The same error, caused by the file-system failure `file`.
    #[must_use]
    pub fn with_file_failure(mut self, file: FileFailure) -> Error {
        self.file = Some(Box::new(file));
        self
    }

    /// A file that could not be written: `PATH: not written: WHY`. Our own
    /// refusals of the path (a device, a named pipe, a directory, a name
    /// ending in a separator) are the input's fault (exit code 2); a
    /// failure of the file system (a full disk, a missing directory, no
    /// permission) is not (exit code 1) and carries its [`FileFailure`].
    pub fn not_written(path: &std::path::Path, e: &std::io::Error) -> Error {
        let refused = matches!(
            e.kind(),
            std::io::ErrorKind::InvalidInput | std::io::ErrorKind::IsADirectory
        ) && e.raw_os_error().is_none();
        let kind = if refused {
            ErrorKind::Input
        } else {
            ErrorKind::Other
        };
        let error = Error::new(kind, format!("{}: not written: {e}", path.display()));
        if refused {
            error
        } else {
            error.with_file_failure(FileFailure::new(path.display().to_string(), e))
        }
    }

    /// A file that cannot be read: `PATH: WHY`, an input error (exit code
    /// 2) with its file-system failure and the I/O error as its source.
    pub(crate) fn unreadable(path: impl fmt::Display, e: std::io::Error) -> Error {
        let path = path.to_string();
        Error::input(format!("{path}: {e}"))
            .with_file_failure(FileFailure::new(path, &e))
            .with_source(e)
    }

    /// The file-system failure that caused this error, if one did.
    pub fn file_failure(&self) -> Option<&FileFailure> {
        self.file.as_deref()
    }

    /// An error of the user's input (exit code 2).
    pub fn input(message: impl Into<String>) -> Error {
        Error::new(ErrorKind::Input, message)
    }

    /// Any other error (exit code 1).
    pub fn other(message: impl Into<String>) -> Error {
        Error::new(ErrorKind::Other, message)
    }

    /// A library error with its kind, its message and its cause, the
    /// library error its [`source`](std::error::Error::source).
    pub fn from_library(e: impl Classify + std::error::Error + Send + Sync + 'static) -> Error {
        let named = Classify::setting(&e).and_then(|(name, why)| {
            Some(Box::new(Named {
                setting: Setting::from_name(name)?,
                before: String::new(),
                after: format!(": {why}"),
            }))
        });
        Error {
            file: Classify::file_failure(&e).map(Box::new),
            cause: Classify::cause(&e),
            setting: named,
            ..Error::new(Classify::kind(&e), e.to_string())
        }
        .with_source(e)
    }

    /// A library error with `context: ` before its message, keeping its
    /// kind and its cause, the library error its
    /// [`source`](std::error::Error::source).
    ///
    /// # Example
    /// ```
    /// use std::error::Error as _;
    /// use tricept_ident::{Error, ErrorCause};
    /// use tricept_ident::export::ExportError;
    /// let e = Error::with_context("export", ExportError::Options("too many points".into()));
    /// assert_eq!(e.to_string(), "export: too many points");
    /// assert_eq!(e.source().unwrap().to_string(), "too many points");
    /// assert_eq!(e.cause(), ErrorCause::Invalid);
    /// ```
    pub fn with_context(
        context: impl fmt::Display,
        e: impl Classify + std::error::Error + Send + Sync + 'static,
    ) -> Error {
        Error::from_library(e).in_file(context)
    }

    /// The same error with `context: ` before its message (a file, a flag).
    #[must_use]
    pub fn in_file(self, context: impl fmt::Display) -> Error {
        let setting = self.setting.map(|n| {
            Box::new(Named {
                before: format!("{context}: {}", n.before),
                ..*n
            })
        });
        Error {
            file: self.file,
            cause: self.cause,
            source: self.source,
            setting,
            ..Error::new(self.kind, format!("{context}: {}", self.message))
        }
    }

    /// Whose fault it is.
    pub fn kind(&self) -> ErrorKind {
        self.kind
    }

    /// The process exit code: 2 for input, 3 and 4 for an untrusted
    /// result, 1 for anything else.
    pub fn exit_code(&self) -> u8 {
        self.kind.exit_code()
    }

    /// The one-line message.
    pub fn message(&self) -> &str {
        &self.message
    }
}

/// Refuses an output file before any work (exit code 2): a path
/// [`tricept_data::atomic::check_output_file`] refuses (a device, a named pipe, a
/// directory, a name ending in a separator), or one whose directory does
/// not exist (with the file-system failure `NotFound`).
/// The one-line summary of a non-zero verdict (`VERB: exit CODE: WHY (see
/// the warnings)`) for 3 and 4, else `None`.
pub(crate) fn exit_reason(code: u8, why: &str) -> Option<String> {
    (code == EXIT_INADEQUATE || code == EXIT_NOT_CONVERGED)
        .then(|| format!("{why} (see the warnings)"))
}

pub(crate) fn check_output_path(setting: Setting, path: &std::path::Path) -> Result<(), Error> {
    let shown = path.display();
    tricept_data::atomic::check_output_file(path)
        .map_err(|e| Error::invalid_value(setting, &shown, e))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    if let Err(e) = std::fs::metadata(dir) {
        return Err(Error::invalid_value(
            setting,
            &shown,
            format!("the directory {} does not exist", dir.display()),
        )
        .with_file_failure(FileFailure::new(shown.to_string(), &e)));
    }
    Ok(())
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source
            .as_deref()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

impl<E: Classify + std::error::Error + Send + Sync + 'static> From<E> for Error {
    fn from(e: E) -> Error {
        Error::from_library(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tricept_diagnose::DiagnoseError;
    use tricept_engine::IdentError;
    use tricept_study::StudyError;

    #[test]
    fn the_same_library_error_has_one_exit_code_wherever_it_is_wrapped() {
        let direct = IdentError::Invalid("x".into());
        let via_diagnose = DiagnoseError::Ident(IdentError::Invalid("x".into()));
        let via_study = StudyError::Ident(IdentError::Invalid("x".into()));
        assert_eq!(Error::from(direct).exit_code(), EXIT_INPUT);
        assert_eq!(Error::from(via_diagnose).exit_code(), EXIT_INPUT);
        assert_eq!(Error::from(via_study).exit_code(), EXIT_INPUT);
        let numerical = IdentError::Numerical("rank");
        assert_eq!(Error::from(numerical).exit_code(), EXIT_OTHER);
        let wrapped = StudyError::Ident(IdentError::Numerical("rank"));
        assert_eq!(Error::from(wrapped).exit_code(), EXIT_OTHER);
    }
}
