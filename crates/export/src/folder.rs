//! An export folder written as one unit: a control loads every file of a
//! folder together, so a folder that mixes two calibrations' files is
//! worse than none.
//!
//! [`replace`] writes the files into a new folder beside the target
//! (`.NAME.tmp-PID-N`, created exclusively), syncs each file and the
//! folder, then puts it in the target's place in one step: a rename when
//! there is no target, else an exchange of the two folders
//! (`renameat2(RENAME_EXCHANGE)` on Linux), after which the previous export
//! (now under the temporary name) is removed. A `kill -9` at any moment
//! leaves the previous export or the new one whole, and at most a stray
//! `.NAME.tmp-*` folder beside it. Where the exchange is not available
//! (another system, a file system without it) the previous folder is
//! renamed aside first: a kill between the two renames leaves it as
//! `.NAME.old-PID-N` beside a missing target.
//!
//! [`check_out`] is the check before any work: the target is a folder (or
//! missing), holds nothing but a previous export (whose `export.json`
//! lists its files), and does not hold the machine file being exported
//! (by path, symbolic link or hard link): replacing the folder would
//! delete it.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::types::ExportError;

/// The summary JSON file's name: the file that says which files an export
/// folder holds.
pub const SUMMARY_FILE: &str = "export.json";

/// The number of the next temporary folder of this process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Checks, before any work, that `out` can take an export of the machine
/// file `machine`: a folder or nothing, holding at most a previous export,
/// not the machine file. Errors are [`ExportError::Out`] (bad input).
///
/// # Example
/// ```
/// use std::path::Path;
/// let dir = std::env::temp_dir().join(format!("tricept-check-out-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let machine = dir.join("cal.json");
/// std::fs::write(&machine, "{}").unwrap();
/// // A new folder beside the machine file is fine; the folder holding it
/// // is not (the export would replace it).
/// assert!(tricept_export::check_out(&dir.join("cnc"), &machine).is_ok());
/// assert!(tricept_export::check_out(&dir, &machine).is_err());
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn check_out(out: &Path, machine: &Path) -> Result<(), ExportError> {
    let refuse = |why: String| ExportError::Out {
        path: out.display().to_string(),
        why,
    };
    if out.as_os_str() == "-" {
        return Err(refuse(
            "an export is a folder of files: `-` (stdout) cannot hold it".into(),
        ));
    }
    let target = resolve(out).map_err(|e| refuse(e.to_string()))?;
    // The machine file, where it really is (links followed).
    let machine_real = fs::canonicalize(machine).ok();
    let target_real = fs::canonicalize(&target).ok();
    if let (Some(m), Some(t)) = (&machine_real, &target_real)
        && m.starts_with(t)
    {
        return Err(refuse(format!(
            "holds the machine file being exported ({}): the export replaces the folder; choose another output folder",
            machine.display()
        )));
    }
    if let (Ok(m), Ok(entries)) = (fs::metadata(machine), fs::read_dir(&target)) {
        for e in entries.flatten() {
            if let Ok(meta) = e.metadata()
                && same_file(&meta, &m)
            {
                return Err(refuse(format!(
                    "{} is the machine file being exported (a hard link): the export replaces the folder; choose another output folder",
                    e.file_name().to_string_lossy()
                )));
            }
        }
    }
    check_contents(&target).map_err(refuse)
}

/// Whether two files' metadata name the same file (device and inode).
#[cfg(unix)]
fn same_file(a: &fs::Metadata, b: &fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(_: &fs::Metadata, _: &fs::Metadata) -> bool {
    false
}

/// What `out` names once symbolic links are followed (it need not exist).
fn resolve(out: &Path) -> io::Result<PathBuf> {
    let mut p = out.to_path_buf();
    for _ in 0..40 {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = fs::read_link(&p)?;
                p = match p.parent() {
                    Some(parent) if link.is_relative() => parent.join(link),
                    _ => link,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// Checks that `target` is missing, an empty folder, or a previous export:
/// a folder whose every entry its `export.json` lists (or the summary
/// itself).
fn check_contents(target: &Path) -> Result<(), String> {
    let meta = match fs::metadata(target) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e.to_string()),
        Ok(m) => m,
    };
    if !meta.is_dir() {
        return Err(
            "is not a folder: the output names the folder the control's files go into".into(),
        );
    }
    let entries: Vec<String> = fs::read_dir(target)
        .map_err(|e| e.to_string())?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect::<Result<_, _>>()
        .map_err(|e| e.to_string())?;
    if entries.is_empty() {
        return Ok(());
    }
    let listed = previous_export_files(target);
    let foreign: Vec<&String> = entries
        .iter()
        .filter(|n| *n != SUMMARY_FILE && !listed.contains(n))
        .collect();
    match foreign.first() {
        None => Ok(()),
        Some(name) => Err(format!(
            "holds {} file(s) that are not a tricept export (`{name}`{}): the export replaces the whole folder; choose an empty or new folder",
            foreign.len(),
            if foreign.len() > 1 { ", ..." } else { "" }
        )),
    }
}

/// The files a previous export in `dir` lists in its summary (none when
/// there is no readable summary).
fn previous_export_files(dir: &Path) -> Vec<String> {
    let Ok(text) = tricept_data::bounded::read_json_text(&dir.join(SUMMARY_FILE)) else {
        return Vec::new();
    };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    v.get("files")
        .and_then(|f| f.as_array())
        .map(|files| {
            files
                .iter()
                .filter_map(|f| f.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default()
}

/// Writes `files` (name, text) into `dir` as one unit (module docs).
pub(crate) fn replace(dir: &Path, files: &[(String, String)]) -> Result<(), ExportError> {
    let io_error = |path: &Path, source| ExportError::Io {
        path: path.display().to_string(),
        source,
    };
    let target = resolve(dir).map_err(|e| io_error(dir, e))?;
    check_contents(&target).map_err(|why| ExportError::Out {
        path: dir.display().to_string(),
        why,
    })?;
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&parent).map_err(|e| io_error(&parent, e))?;
    let tmp = create_temporary(&parent, &target).map_err(|e| io_error(&parent, e))?;
    let result = fill(&tmp, files).and_then(|()| put_in_place(&tmp, &target, &parent));
    match result {
        Ok(()) => {
            if let Ok(d) = File::open(&parent) {
                let _ = d.sync_all();
            }
            Ok(())
        }
        Err(e) => {
            let _ = fs::remove_dir_all(&tmp);
            Err(io_error(&target, e))
        }
    }
}

/// The next name `.NAME.KIND-PID-N` beside `target` in `parent`.
fn sibling(parent: &Path, target: &Path, kind: &str) -> PathBuf {
    let name = target
        .file_name()
        .map_or_else(|| "export".into(), |n| n.to_string_lossy().into_owned());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    parent.join(format!(".{name}.{kind}-{}-{n}", std::process::id()))
}

/// A new, exclusively created folder beside `target`.
fn create_temporary(parent: &Path, target: &Path) -> io::Result<PathBuf> {
    loop {
        let tmp = sibling(parent, target, "tmp");
        match fs::create_dir(&tmp) {
            Ok(()) => return Ok(tmp),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}

/// Writes each file into the new folder `tmp`, synced, then the folder.
fn fill(tmp: &Path, files: &[(String, String)]) -> io::Result<()> {
    for (name, text) in files {
        let mut f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(tmp.join(name))?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
    }
    // A file system that cannot sync a folder has written it all the same.
    if let Ok(d) = File::open(tmp) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Puts the complete folder `tmp` in `target`'s place (module docs).
fn put_in_place(tmp: &Path, target: &Path, parent: &Path) -> io::Result<()> {
    if fs::symlink_metadata(target).is_err() {
        return fs::rename(tmp, target);
    }
    if exchange(tmp, target).is_ok() {
        // `tmp` now holds the previous export.
        return fs::remove_dir_all(tmp);
    }
    let old = loop {
        let old = sibling(parent, target, "old");
        if fs::symlink_metadata(&old).is_err() {
            break old;
        }
    };
    fs::rename(target, &old)?;
    if let Err(e) = fs::rename(tmp, target) {
        // Put the previous export back.
        let _ = fs::rename(&old, target);
        return Err(e);
    }
    fs::remove_dir_all(&old)
}

/// Exchanges two folders in one step.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).map_err(io::Error::from)
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> io::Result<()> {
    Err(io::Error::from(io::ErrorKind::Unsupported))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("tricept-folder-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn export(tag: &str) -> Vec<(String, String)> {
        vec![
            ("A.TXT".into(), format!("{tag} a\n")),
            (
                SUMMARY_FILE.into(),
                format!("{{\"files\": [\"A.TXT\", \"{SUMMARY_FILE}\"], \"tag\": \"{tag}\"}}\n"),
            ),
        ]
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_new_export_replaces_the_previous_one_whole_and_leaves_nothing_beside() {
        let d = dir("replace");
        let out = d.join("cnc");
        replace(&out, &export("old")).unwrap();
        // The new set has a file fewer: the old file does not stay.
        let new = vec![(
            SUMMARY_FILE.to_string(),
            format!("{{\"files\": [\"{SUMMARY_FILE}\"]}}\n"),
        )];
        replace(&out, &new).unwrap();
        assert_eq!(entries(&out), [SUMMARY_FILE]);
        assert_eq!(entries(&d), ["cnc"]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_folder_with_files_not_of_an_export_is_refused_and_kept() {
        let d = dir("foreign");
        let out = d.join("cnc");
        replace(&out, &export("old")).unwrap();
        fs::write(out.join("notes.txt"), "mine").unwrap();
        let e = replace(&out, &export("new")).unwrap_err().to_string();
        assert!(e.contains("`notes.txt`"), "{e}");
        assert_eq!(fs::read_to_string(out.join("A.TXT")).unwrap(), "old a\n");
        let e = check_out(&out, &d.join("cal.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a tricept export"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_output_that_is_a_file_or_dash_is_refused() {
        let d = dir("file");
        let f = d.join("cnc");
        fs::write(&f, "x").unwrap();
        let e = check_out(&f, &d.join("cal.json")).unwrap_err().to_string();
        assert!(e.contains("is not a folder"), "{e}");
        let e = check_out(Path::new("-"), &d.join("cal.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("stdout"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn the_machine_file_inside_the_folder_by_any_name_is_refused() {
        let d = dir("machine");
        let out = d.join("q");
        replace(&out, &export("old")).unwrap();
        // The machine file copied in under an export's name, reached
        // through a symbolic link to the folder, or hard-linked into it.
        let inside = out.join(SUMMARY_FILE);
        assert!(check_out(&out, &inside).is_err());
        std::os::unix::fs::symlink(&out, d.join("link")).unwrap();
        assert!(check_out(&d.join("link"), &inside).is_err());
        let machine = d.join("cal.json");
        fs::write(&machine, "{}").unwrap();
        assert!(check_out(&out, &machine).is_ok());
        fs::remove_file(out.join("A.TXT")).unwrap();
        fs::hard_link(&machine, out.join("A.TXT")).unwrap();
        let e = check_out(&out, &machine).unwrap_err().to_string();
        assert!(e.contains("hard link"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_to_the_folder_stays_and_the_folder_is_replaced() {
        let d = dir("link");
        let real = d.join("real");
        replace(&real, &export("old")).unwrap();
        std::os::unix::fs::symlink(&real, d.join("link")).unwrap();
        replace(&d.join("link"), &export("new")).unwrap();
        assert!(
            fs::symlink_metadata(d.join("link"))
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read_to_string(real.join("A.TXT")).unwrap(), "new a\n");
        fs::remove_dir_all(&d).unwrap();
    }
}
