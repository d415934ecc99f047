//! The files a verb writes: each one atomically (a temporary file in the
//! same directory, synced, renamed over the target:
//! [`tricept_ident::advanced::files::write_atomic`]), and never one of the verb's inputs.
//!
//! [`FileRoles`] lists a verb's input and output files; [`FileRoles::check`]
//! runs before any computation and refuses (exit 2) an output that is an
//! input, whether by the same name, through a symbolic link or as a hard
//! link: `identify --data data.csv --write-machine data.csv` would
//! otherwise replace the measured data by a machine file. Every file
//! written is named on stderr (`wrote PATH`), so that stdout stays data.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::cli_error::CliError;

/// Writes `path` atomically; on failure the previous file is intact and
/// the error (exit 1) names the file.
pub fn write_with<F>(path: &Path, content: F) -> Result<(), CliError>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    written(
        path,
        tricept_ident::advanced::files::write_atomic(path, content),
    )
}

/// The outcome of an atomic write of `path` by a library writer
/// (`tricept_data::write_path`, ...), as the CLI reports it: `wrote PATH`
/// on stderr (stdout stays data), or exit 1 naming the file, which is as it
/// was before.
pub fn written(path: &Path, result: std::io::Result<()>) -> Result<(), CliError> {
    match result {
        Ok(()) => {
            errln!("wrote {}", path.display());
            Ok(())
        }
        Err(e) => Err(CliError::other(format!(
            "{}: not written: {e}",
            path.display()
        ))),
    }
}

/// The outcome of a figure drawn into `path` (`tricept_plot`, atomic
/// too): `wrote PATH` on stderr, or exit 1 with the plotter's message.
pub fn plotted(
    path: &Path,
    result: Result<(), tricept_ident::advanced::plot::PlotError>,
) -> Result<(), CliError> {
    result.map_err(|e| CliError::other(e.to_string()))?;
    errln!("wrote {}", path.display());
    Ok(())
}

/// Writes `text` to `path` atomically (see [`write_with`]).
pub fn write_text(path: &Path, text: &str) -> Result<(), CliError> {
    write_with(path, |w| w.write_all(text.as_bytes()))
}

/// Creates an output directory and its parents (exit 1 naming it on
/// failure).
pub fn create_dir(dir: &Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir).map_err(|e| {
        CliError::other(format!(
            "{}: cannot create the directory: {e}",
            dir.display()
        ))
    })
}

/// The files a verb reads and writes, by the flag that names them.
#[derive(Debug, Default)]
pub struct FileRoles {
    inputs: Vec<(String, PathBuf)>,
    outputs: Vec<(String, PathBuf)>,
    /// Output directories the verb creates when they do not exist.
    created_dirs: Vec<PathBuf>,
    /// Output directories whose file names the results decide: flag,
    /// directory, and the names' prefix and suffix (`residual-`, `.svg`).
    named_later: Vec<(String, PathBuf, &'static str, &'static str)>,
}

/// How a command line names stdin and stdout.
pub const STDIO: &str = "-";

impl FileRoles {
    /// A file the verb reads.
    pub fn input(&mut self, flag: &str, path: &Path) -> &mut Self {
        self.inputs.push((flag.to_string(), path.to_path_buf()));
        self
    }

    /// Every file of `paths`, read under `flag`.
    pub fn inputs<'a>(&mut self, flag: &str, paths: impl IntoIterator<Item = &'a PathBuf>) {
        for p in paths {
            self.input(flag, p);
        }
    }

    /// A file the verb reads if `path` is one (an option that is either a
    /// spec such as `table2` or a file name).
    pub fn input_if_file(&mut self, flag: &str, spec: &str) {
        let path = Path::new(spec.strip_prefix('@').unwrap_or(spec));
        if path.is_file() {
            self.input(flag, path);
        }
    }

    /// A file the verb writes.
    pub fn output(&mut self, flag: &str, path: &Path) -> &mut Self {
        self.outputs.push((flag.to_string(), path.to_path_buf()));
        self
    }

    /// The files `names` the verb writes into the directory `dir`.
    pub fn outputs_in(&mut self, flag: &str, dir: &Path, names: &[&str]) {
        self.created_dirs.push(dir.to_path_buf());
        for n in names {
            self.output(flag, &dir.join(n));
        }
    }

    /// A directory the verb creates if need be and writes files into whose
    /// names the results decide, each `PREFIX*SUFFIX` (a plot per effect).
    pub fn output_dir(
        &mut self,
        flag: &str,
        dir: &Path,
        prefix: &'static str,
        suffix: &'static str,
    ) {
        self.created_dirs.push(dir.to_path_buf());
        self.named_later
            .push((flag.to_string(), dir.to_path_buf(), prefix, suffix));
    }

    /// Refuses (exit 2), before anything is computed or appended: an input
    /// that does not exist, is a directory or is `-` (stdin is read only
    /// where a flag says so); an output named `-` (only a flag that says so
    /// writes stdout, and the verb takes it out before), whose name ends in
    /// a separator, that is a directory, a device, a named pipe or a
    /// socket (also at the end of its symbolic links), whose directory
    /// does not exist (unless the verb creates it), or that is one of the
    /// inputs or another output, by name, through a symbolic link or as a
    /// hard link; an output directory that is not a directory, or that
    /// holds something other than a regular file under a name the verb
    /// may write.
    pub fn check(&self) -> Result<(), CliError> {
        // Kept for the files whose names only the results decide (plots).
        let known = self
            .inputs
            .iter()
            .map(|(f, p)| (f.clone(), p.clone(), "input"));
        let known = known.chain(
            self.outputs
                .iter()
                .map(|(f, p)| (f.clone(), p.clone(), "output")),
        );
        let _ = KNOWN_FILES.set(known.collect());
        for (i, (flag, input)) in self.inputs.iter().enumerate() {
            check_input(flag, input)?;
            if let Some((_, first)) = self.inputs[..i]
                .iter()
                .find(|(f, p)| f == flag && same_file(p, input))
            {
                return Err(CliError::input(format!(
                    "{flag} {}: the same file as {flag} {} given before; each file counts once (a repeated tracker file would pass for a second station)",
                    shown(input),
                    shown(first)
                )));
            }
        }
        for dir in &self.created_dirs {
            let flag = self.flag_of_dir(dir);
            check_output_dir(flag, dir)?;
        }
        for (i, (out_flag, out)) in self.outputs.iter().enumerate() {
            check_output_file(out_flag, out)?;
            let dir = match out.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            let created = self.created_dirs.iter().any(|d| d == dir);
            if !created && !dir.is_dir() {
                return Err(CliError::input(format!(
                    "{out_flag} {}: the directory {} does not exist",
                    shown(out),
                    shown(dir)
                )));
            }
            let clash = self
                .inputs
                .iter()
                .map(|(f, p)| (f, p, "the input"))
                .chain(self.outputs[..i].iter().map(|(f, p)| (f, p, "the output")))
                .find(|(_, p, _)| same_file(out, p));
            if let Some((flag, path, role)) = clash {
                return Err(CliError::input(format!(
                    "{out_flag} {}: is also {role} {flag} {}; writing it would destroy that file: choose another name",
                    shown(out),
                    shown(path)
                )));
            }
        }
        for (flag, dir, prefix, suffix) in &self.named_later {
            self.check_named_later(flag, dir, prefix, suffix)?;
        }
        Ok(())
    }

    /// The flag of an output directory, for its messages.
    fn flag_of_dir(&self, dir: &Path) -> &str {
        let named = self.named_later.iter().find(|(_, d, _, _)| d == dir);
        let fixed = self.outputs.iter().find(|(_, p)| p.parent() == Some(dir));
        named
            .map(|(f, ..)| f.as_str())
            .or(fixed.map(|(f, _)| f.as_str()))
            .unwrap_or("output directory")
    }

    /// Refuses a file the verb may write into `dir` (a name `PREFIX*SUFFIX`
    /// there) that is not a regular file, or that is one of the inputs or
    /// outputs.
    fn check_named_later(
        &self,
        flag: &str,
        dir: &Path,
        prefix: &str,
        suffix: &str,
    ) -> Result<(), CliError> {
        let ours = |name: &std::ffi::OsStr| {
            let n = name.to_string_lossy();
            n.starts_with(prefix) && n.ends_with(suffix)
        };
        if let Ok(entries) = std::fs::read_dir(dir) {
            for entry in entries.flatten() {
                if ours(&entry.file_name()) {
                    check_output_file(flag, &entry.path())?;
                }
            }
        }
        let canonical_dir = canonical(dir);
        let known = self
            .inputs
            .iter()
            .map(|(f, p)| (f, p, "the input"))
            .chain(self.outputs.iter().map(|(f, p)| (f, p, "the output")));
        for (other, path, role) in known {
            let inside = canonical(path).parent().is_some_and(|d| d == canonical_dir);
            if inside && path.file_name().is_some_and(ours) {
                return Err(CliError::input(format!(
                    "{flag} {}: may write {role} {other} {} (the names {prefix}*{suffix} are its own); choose another directory",
                    shown(dir),
                    shown(path)
                )));
            }
        }
        Ok(())
    }
}

/// A path as messages show it (`tricept_data::message::shown_path`).
fn shown(p: &Path) -> String {
    tricept_ident::advanced::files::shown_path(p)
}

/// Refuses an input that is `-`, does not exist or is a directory (a
/// named pipe or a device is read: `--data <(zcat d.csv.gz)`).
fn check_input(flag: &str, input: &Path) -> Result<(), CliError> {
    if input.as_os_str() == STDIO {
        return Err(CliError::input(format!(
            "{flag} -: {flag} does not read stdin; give a file name (`./-` for a file named `-`)"
        )));
    }
    match std::fs::metadata(input) {
        Ok(m) if m.is_dir() => Err(CliError::input(format!(
            "{flag} {}: is a directory, not a file",
            shown(input)
        ))),
        Ok(_) => Ok(()),
        Err(e) => Err(CliError::input(format!("{flag} {}: {e}", shown(input)))),
    }
}

/// Refuses an output file the verb must not write (see
/// [`FileRoles::check`]; `tricept_data::atomic::check_output_file`).
fn check_output_file(flag: &str, out: &Path) -> Result<(), CliError> {
    if out.as_os_str() == STDIO {
        return Err(CliError::input(format!(
            "{flag} -: {flag} does not write stdout (stdout carries the report); give a file name (`./-` for a file named `-`)"
        )));
    }
    check_names(flag, out)?;
    tricept_ident::advanced::files::check_output_file(out).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::IsADirectory => "is a directory; give a file name".to_string(),
            _ => e.to_string(),
        };
        CliError::input(format!("{flag} {}: {why}", shown(out)))
    })
}

/// Refuses an output directory that is `-`, has a name too long for a
/// file system, exists as something other than a directory (following
/// symbolic links), or cannot be created: an ancestor that is a file, a
/// link that loops.
fn check_output_dir(flag: &str, dir: &Path) -> Result<(), CliError> {
    if dir.as_os_str() == STDIO {
        return Err(CliError::input(format!(
            "{flag} -: {flag} names a directory, not stdout; give a directory name"
        )));
    }
    check_names(flag, dir)?;
    let refused = |why: String| CliError::input(format!("{flag} {}: {why}", shown(dir)));
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => return Ok(()),
        Ok(_) => return Err(refused("is a file, not a directory".into())),
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(refused(format!("cannot be a directory: {e}")));
        }
        Err(_) => {}
    }
    // Created with its parents: its own name a name (`new/.` is none), and
    // the nearest that exists a directory.
    let text = dir.as_os_str().to_string_lossy();
    let last = text
        .trim_end_matches(['/', std::path::MAIN_SEPARATOR])
        .rsplit(['/', std::path::MAIN_SEPARATOR])
        .next()
        .unwrap_or_default();
    if last.is_empty() || last == "." || last == ".." {
        return Err(refused(
            "does not exist and ends in `.` or `..`: name the directory to create".into(),
        ));
    }
    for ancestor in dir.ancestors().skip(1) {
        let a = if ancestor.as_os_str().is_empty() {
            Path::new(".")
        } else {
            ancestor
        };
        match std::fs::metadata(a) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) => {
                return Err(refused(format!(
                    "cannot be created: {} is not a directory",
                    shown(a)
                )));
            }
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(refused(format!("cannot be created: {e}")));
            }
            Err(_) => {}
        }
    }
    Ok(())
}

/// The longest name of one file or directory most file systems take, in
/// bytes (`NAME_MAX`).
const NAME_MAX: usize = 255;

/// Refuses a path with a name longer than [`NAME_MAX`] bytes: no file
/// system here would take it, and finding that out only when writing
/// would come after the work.
fn check_names(flag: &str, path: &Path) -> Result<(), CliError> {
    match path.components().find(|c| c.as_os_str().len() > NAME_MAX) {
        Some(c) => Err(CliError::input(format!(
            "{flag} {}: a name of {} bytes (a file system takes at most {NAME_MAX})",
            shown(path),
            c.as_os_str().len()
        ))),
        None => Ok(()),
    }
}

/// The run's inputs and outputs known beforehand (flag, path, role), set
/// by [`FileRoles::check`].
static KNOWN_FILES: std::sync::OnceLock<Vec<(String, PathBuf, &'static str)>> =
    std::sync::OnceLock::new();

/// `dir/name`, an output whose name the results decide (a plot per
/// effect or quantity), refused (exit 2) when it is one of the run's
/// inputs or other outputs (a history, a machine file), as
/// [`FileRoles::check`] refuses the outputs known beforehand.
pub fn output_in(flag: &str, dir: &Path, name: &str) -> Result<PathBuf, CliError> {
    let out = dir.join(name);
    let known = KNOWN_FILES.get().map_or(&[][..], Vec::as_slice);
    match known.iter().find(|(_, p, _)| same_file(&out, p)) {
        Some((other, p, role)) => Err(CliError::input(format!(
            "{flag} {}: is also the {role} {other} {}; writing it would destroy that file: choose another directory",
            shown(&out),
            shown(p)
        ))),
        None => {
            check_output_file(flag, &out)?;
            Ok(out)
        }
    }
}

/// Whether two paths name the same file: the same device and inode where
/// both exist (symbolic and hard links included), else the same path once
/// the directories are resolved.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(ma), Ok(mb)) => same_inode(&ma, &mb).unwrap_or_else(|| canonical(a) == canonical(b)),
        _ => canonical(a) == canonical(b),
    }
}

#[cfg(unix)]
fn same_inode(a: &std::fs::Metadata, b: &std::fs::Metadata) -> Option<bool> {
    use std::os::unix::fs::MetadataExt;
    Some(a.dev() == b.dev() && a.ino() == b.ino())
}

#[cfg(not(unix))]
fn same_inode(_: &std::fs::Metadata, _: &std::fs::Metadata) -> Option<bool> {
    None
}

/// `p` with its directory resolved (the file itself may not exist yet).
fn canonical(p: &Path) -> PathBuf {
    if let Ok(c) = std::fs::canonicalize(p) {
        return c;
    }
    match (p.parent(), p.file_name()) {
        (Some(dir), Some(name)) => {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            std::fs::canonicalize(dir).map_or_else(|_| p.to_path_buf(), |d| d.join(name))
        }
        _ => p.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_that_are_inputs_are_found_by_name_link_and_hard_link() {
        let d = std::env::temp_dir().join(format!("tricept-roles-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let data = d.join("data.csv");
        std::fs::write(&data, "x").unwrap();
        let hard = d.join("hard.csv");
        let _ = std::fs::remove_file(&hard);
        std::fs::hard_link(&data, &hard).unwrap();
        let mut roles = FileRoles::default();
        roles.input("--data", &data);
        assert!(roles.check().is_ok());
        for clash in [
            data.clone(),
            d.join(".").join("data.csv"),
            hard.clone(),
            d.join("sub").join("..").join("data.csv"),
        ] {
            let mut r = FileRoles::default();
            r.input("--data", &data).output("--write-machine", &clash);
            if clash.starts_with(d.join("sub")) {
                // A path through a directory that does not exist cannot be
                // written: refused as such.
                let e = r.check().unwrap_err();
                assert!(e.message().contains("does not exist"), "{}", e.message());
                continue;
            }
            let e = r.check().unwrap_err();
            assert_eq!(e.exit_code(), 2);
            assert!(
                e.message().contains("is also the input --data"),
                "{}",
                e.message()
            );
        }
        #[cfg(unix)]
        {
            let link = d.join("link.csv");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&data, &link).unwrap();
            let mut r = FileRoles::default();
            r.input("--data", &data).output("--out", &link);
            assert!(r.check().is_err());
        }
        let mut r = FileRoles::default();
        r.output("--out", &d.join("a.csv"))
            .output("--tracker-out", &d.join("a.csv"));
        assert!(
            r.check()
                .unwrap_err()
                .message()
                .contains("the output --out")
        );
        std::fs::remove_dir_all(&d).ok();
    }
}
