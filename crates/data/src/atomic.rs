//! Files written whole or not at all: [`write_atomic`].
//!
//! A calibration is worth hours of machine time; a full disk, a crash or a
//! `kill -9` in the middle of writing it must not leave a truncated file in
//! its place. Every file the project writes goes through [`write_atomic`]:
//!
//! 1. the content goes to a new temporary file in the target's directory
//!    (`.NAME.tmp-PID-N`, created exclusively, so two writers never share
//!    one);
//! 2. it is flushed and synced to the disk (`fsync`);
//! 3. it is renamed over the target, which on POSIX file systems replaces
//!    the target in one step: a reader sees the old file or the new one,
//!    never a mixture;
//! 4. the directory is synced, so that the rename itself survives a power
//!    loss.
//!
//! On any failure before the rename the temporary file is removed and the
//! target is untouched, byte for byte. A target that is a symbolic link is
//! resolved first: the file it points to is replaced, the link stays. The
//! permissions of a replaced file are kept. Only a regular file is ever
//! replaced: a device node, a named pipe or a socket at the target (or at
//! the end of its links) is refused before anything is written
//! ([`check_output_file`]).

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes a file atomically: `content` writes the whole file into the
/// writer it is given; the target is replaced only when that and the
/// flush, sync and rename all succeed (see the module docs).
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use std::io::Write;
let path = std::env::temp_dir().join(format!("tricept-atomic-doc-{}.txt", std::process::id()));
tricept_data::write_atomic(&path, |w| w.write_all(b"first\n")).unwrap();
// A writer that fails half-way leaves the previous file as it was.
let failed = tricept_data::write_atomic(&path, |w| {
    w.write_all(b"sec")?;
    Err(std::io::Error::other("disk full"))
});
assert!(failed.is_err());
assert_eq!(std::fs::read_to_string(&path).unwrap(), "first\n");
# std::fs::remove_file(&path).unwrap();
```
"#
)]
pub fn write_atomic<F>(path: &Path, content: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    write_atomic_through(path, |file| file, content)
}

/// [`write_atomic`] with the temporary file seen through `wrap` (tests put
/// a writer there that fails as a full disk does).
pub(crate) fn write_atomic_through<W, G, F>(path: &Path, wrap: G, content: F) -> io::Result<()>
where
    W: Write,
    G: FnOnce(File) -> W,
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    check_output_file(path)?;
    let target = resolve(path)?;
    let dir = directory_of(&target);
    let (tmp_path, file) = create_temporary(&dir, &target)?;
    let result = (|| {
        if let Ok(meta) = std::fs::metadata(&target) {
            // Keep the permissions of the file being replaced.
            file.set_permissions(meta.permissions())?;
        }
        let sync_handle = file.try_clone()?;
        let mut w = BufWriter::new(wrap(file));
        content(&mut w)?;
        w.flush()?;
        drop(w);
        sync_handle.sync_all()?;
        std::fs::rename(&tmp_path, &target)
    })();
    match result {
        Ok(()) => {
            // The rename is durable once the directory is synced; a file
            // system that cannot sync a directory has replaced the file all
            // the same.
            if let Ok(d) = File::open(&dir) {
                let _ = d.sync_all();
            }
            Ok(())
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp_path);
            Err(e)
        }
    }
}

/// The directory `target` lies in, the one synced after the rename: its
/// parent, `.` for a bare file name (whose parent is empty).
fn directory_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The file a write to `path` replaces: `path` itself, or what a symbolic
/// link at `path` points to (followed to the end).
fn resolve(path: &Path) -> io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(parent) if link.is_relative() => parent.join(link),
                    _ => link,
                };
            }
            Ok(m) if m.is_dir() => {
                return Err(io::Error::new(
                    io::ErrorKind::IsADirectory,
                    "is a directory, not a file",
                ));
            }
            Ok(m) if !m.is_file() => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "is {}, not a regular file: only a regular file is replaced",
                        special_kind(&m.file_type())
                    ),
                ));
            }
            _ => return Ok(p),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// Refuses an output path that [`write_atomic`] would not write: a name
/// ending in a separator (`out/`: a directory's name, not a file's), an
/// existing directory, or anything but a regular file at its end
/// (following symbolic links): a device node, a named pipe or a socket is
/// never replaced by a file. The errors are `InvalidInput` (or
/// `IsADirectory`) and say why.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use std::path::Path;
let e = tricept_data::atomic::check_output_file(Path::new("/dev/null")).unwrap_err();
assert!(e.to_string().contains("character device"), "{e}");
assert!(tricept_data::atomic::check_output_file(Path::new("out/")).is_err());
assert!(tricept_data::atomic::check_output_file(Path::new("new-file.json")).is_ok());
```
"#
)]
pub fn check_output_file(path: &Path) -> io::Result<()> {
    let text = path.as_os_str().to_string_lossy();
    // The text's last name, not `Path::file_name` (which reads `a/.` as
    // `a`): every path without a file name (`/`, `..`, ``) ends in one of
    // these.
    let last = text
        .rsplit(['/', std::path::MAIN_SEPARATOR])
        .next()
        .unwrap_or_default();
    if last.is_empty() || last == "." || last == ".." {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "names a directory (it ends with a separator or is `.` or `..`), not a file: give a file name",
        ));
    }
    resolve(path).map(|_| ())
}

/// What a file that is neither regular nor a directory is, as a message
/// says it.
fn special_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = t;
    "a special file"
}

/// The number of the next temporary file of this process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A new, exclusively created temporary file beside `target`.
fn create_temporary(dir: &Path, target: &Path) -> io::Result<(PathBuf, File)> {
    let name = target
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.tmp-{}-{n}", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disk that holds `room` more bytes, then fails as a full one does.
    struct FullAfter<W> {
        inner: W,
        room: usize,
    }

    impl<W: Write> Write for FullAfter<W> {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.room == 0 {
                return Err(io::Error::from_raw_os_error(28)); // ENOSPC
            }
            let n = buf.len().min(self.room);
            self.room -= n;
            self.inner.write(&buf[..n])
        }
        fn flush(&mut self) -> io::Result<()> {
            self.inner.flush()
        }
    }

    /// A test's own scratch folder, removed when the test ends (passed or
    /// failed).
    struct Scratch(PathBuf);

    impl std::ops::Deref for Scratch {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl AsRef<Path> for Scratch {
        fn as_ref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn dir(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("tricept-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_directory_is_not_replaced() {
        let d = dir("isdir");
        let e = write_atomic(&d, |w| w.write_all(b"x")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::IsADirectory);
        assert_eq!(e.to_string(), "is a directory, not a file");
        assert!(d.is_dir());
    }

    #[test]
    fn a_full_disk_at_any_byte_leaves_the_old_file_and_no_temporary() {
        let d = dir("full");
        let target = d.join("machine.json");
        let old = b"{\"old\": true}\n".repeat(100);
        std::fs::write(&target, &old).unwrap();
        let new = b"{\"new\": 1}\n".repeat(1000);
        // The disk fills at byte 0, in the middle, and one byte short.
        for room in [0, 1, 4096, 8191, new.len() - 1] {
            let r = write_atomic_through(
                &target,
                |f| FullAfter { inner: f, room },
                |w| w.write_all(&new),
            );
            let e = r.unwrap_err();
            assert_eq!(e.raw_os_error(), Some(28), "room {room}: {e}");
            assert_eq!(std::fs::read(&target).unwrap(), old, "room {room}");
            assert_eq!(entries(&d), vec!["machine.json".to_string()]);
        }
        // With room enough the new content replaces the old.
        write_atomic_through(
            &target,
            |f| FullAfter {
                inner: f,
                room: new.len(),
            },
            |w| w.write_all(&new),
        )
        .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), new);
        assert_eq!(entries(&d), vec!["machine.json".to_string()]);
    }

    #[test]
    fn a_failing_producer_leaves_no_file_where_there_was_none() {
        let d = dir("producer");
        let target = d.join("out.csv");
        let r = write_atomic(&target, |w| {
            w.write_all(b"q1,q2\n")?;
            Err(io::Error::other("computation failed"))
        });
        assert!(r.is_err());
        assert!(entries(&d).is_empty(), "{:?}", entries(&d));
    }

    /// Runs `f` on its own thread and returns its result, failing the test
    /// when it takes more than 10 s (a writer that retries forever).
    fn promptly<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let _ = tx.send(f());
        });
        rx.recv_timeout(std::time::Duration::from_secs(10))
            .expect("the write did not return within 10 s")
    }

    #[test]
    fn a_missing_directory_is_an_error_at_once() {
        let d = dir("missing");
        let target = d.join("no").join("such").join("machine.json");
        let e = promptly(move || write_atomic(&target, |w| w.write_all(b"x")).unwrap_err());
        assert_eq!(e.kind(), io::ErrorKind::NotFound, "{e}");
        assert!(entries(&d).is_empty(), "{:?}", entries(&d));
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_keeps_pointing_at_the_replaced_file() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("link");
        let real = d.join("real.json");
        std::fs::write(&real, "old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_atomic(&link, |w| w.write_all(b"new")).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        let mode = std::fs::metadata(&real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }

    #[cfg(unix)]
    #[test]
    fn a_read_only_directory_is_an_error_at_once() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("readonly");
        std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o555)).unwrap();
        // A privileged user writes into a read-only directory all the same;
        // a file system that refuses even root (sysfs) stands in then.
        let privileged = std::fs::write(d.join("probe"), "").is_ok();
        let read_only = if privileged {
            PathBuf::from("/sys")
        } else {
            d.to_path_buf()
        };
        if read_only.is_dir() {
            let target = read_only.join(format!("tricept-atomic-{}.json", std::process::id()));
            let written = target.clone();
            let e = promptly(move || write_atomic(&written, |w| w.write_all(b"x")).unwrap_err());
            assert_eq!(e.kind(), io::ErrorKind::PermissionDenied, "{e}");
            assert!(!target.exists());
        }
        std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o755)).unwrap();
    }

    #[test]
    fn the_temporary_file_lies_beside_its_target() {
        let d = dir("beside");
        let target = d.join("machine.json");
        let mut seen = Vec::new();
        write_atomic(&target, |w| {
            // While the content is written, the target's directory holds
            // the temporary file and nothing else.
            seen = entries(&d);
            w.write_all(b"new")
        })
        .unwrap();
        assert_eq!(seen.len(), 1, "{seen:?}");
        assert!(seen[0].starts_with(".machine.json.tmp-"), "{seen:?}");
        assert_eq!(entries(&d), vec!["machine.json".to_string()]);
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    }

    #[test]
    fn the_directory_of_a_bare_file_name_is_the_current_one() {
        assert_eq!(directory_of(Path::new("machine.json")), Path::new("."));
        assert_eq!(directory_of(Path::new("out/m.json")), Path::new("out"));
        assert_eq!(directory_of(Path::new("/data/m.json")), Path::new("/data"));
    }

    #[test]
    fn a_temporary_name_already_taken_is_skipped() {
        let d = dir("taken");
        let target = d.join("machine.json");
        // Every name the next 200 temporary files of this process would take.
        let next = COUNTER.load(Ordering::Relaxed);
        for n in next..next + 200 {
            let name = format!(".machine.json.tmp-{}-{n}", std::process::id());
            std::fs::write(d.join(name), "someone else's").unwrap();
        }
        write_atomic(&target, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        // The other files are left alone.
        assert_eq!(entries(&d).len(), 201);
    }

    #[cfg(unix)]
    #[test]
    fn a_device_a_named_pipe_or_a_link_to_one_is_never_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let d = dir("special");
        let fifo = d.join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        let link = d.join("null.json");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        for (target, kind) in [
            (fifo.as_path(), "a named pipe"),
            (link.as_path(), "a character device"),
            (Path::new("/dev/null"), "a character device"),
        ] {
            let e = write_atomic(target, |w| w.write_all(b"x")).unwrap_err();
            assert_eq!(e.kind(), io::ErrorKind::InvalidInput, "{e}");
            assert!(e.to_string().contains(kind), "{e}");
        }
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert!(
            std::fs::metadata("/dev/null")
                .unwrap()
                .file_type()
                .is_char_device()
        );
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        // Nothing but the pipe and the link in the directory: no temporary.
        assert_eq!(entries(&d), ["null.json", "pipe"]);
        for name in ["sub/", "sub/.", "sub/..", ".", "..", ""] {
            let e = write_atomic(&d.join(name), |w| w.write_all(b"x")).unwrap_err();
            assert!(e.to_string().contains("names a directory"), "{name}: {e}");
        }
    }
}
