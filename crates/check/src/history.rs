//! A machine's checks over time: one JSON object per line
//! (`tricept check --history FILE.jsonl`), and the trend of the key
//! quantities against their bands.
//!
//! Each entry keeps the verdict and, for every leg, the estimated length
//! change (fitted alone, so that checks compare; a change of another leg
//! or a joint moves it too, and the check's verdict says which it was;
//! fitting the three legs together is no remedy, since their sum is the
//! weak direction of the calibration and its uncertainty would widen every
//! band fourfold) with its standard deviation and its *band*: the change beyond
//! which that check flags the parameter on its own (its standard deviation
//! alone times the family-wise critical value). A value inside its band is noise; a drift is
//! reported once it leaves the band, and its slope (weighted least squares
//! over the entries, per day) is given with its uncertainty.
//!
//! Each line carries its `format_version` ([`HISTORY_FORMAT_VERSION`]); a
//! line without it is version 1, and a line of a newer version is refused,
//! naming it, before the history is appended to.
//!
//! The file is rewritten whole at every append through
//! [`tricept_data::write_atomic`], so that a crash never leaves half a
//! line; a line that does not parse is an error naming it. Appends hold an
//! exclusive lock on the history file itself (no lock file is left beside
//! it) from the read to the rename, so that checks appending to the same
//! history at once keep every record, whatever name each gives it (a
//! symbolic link, another relative path).

use serde::{Deserialize, Serialize};

use crate::check::CheckReport;
use crate::error::CheckError;

/// The format version of a history line this tricept writes, and the
/// newest it reads (`format_version` key).
pub const HISTORY_FORMAT_VERSION: u32 = 1;

/// serde's default of `format_version`: a line without it is version 1.
fn unversioned() -> u32 {
    tricept_kinematics::description::UNVERSIONED
}

/// One check in the history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    /// The line's format version ([`HISTORY_FORMAT_VERSION`] as written;
    /// absent: 1).
    #[serde(default = "unversioned")]
    pub format_version: u32,
    /// When the check ran, UTC (ISO 8601).
    pub time: String,
    /// The same, seconds since 1970-01-01.
    pub unix_s: f64,
    /// The machine file checked against.
    pub machine: String,
    /// The check campaign's data file.
    pub data_file: String,
    /// `unchanged`, `changed` or `changed-unexplained`.
    pub verdict: String,
    /// The most likely change, when changed.
    pub most_likely: Option<String>,
    /// What the check could not tell apart from it.
    pub shortlist: Vec<String>,
    /// The consistency statistic, its degrees of freedom and p-value.
    pub consistency: (f64, usize, f64),
    /// The key quantities.
    pub quantities: Vec<Quantity>,
    /// The calibration checked against: its digest
    /// (`MachineDescription::calibration_digest`); absent in lines written
    /// before histories named it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration_digest: Option<String>,
}

/// A key quantity of one check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Quantity {
    /// `dq1`, ...
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// The estimate.
    pub value: f64,
    /// Its standard deviation.
    pub std_dev: f64,
    /// The change beyond which this check flags the quantity on its own.
    pub band: f64,
}

impl Entry {
    /// The entry of `report`, checked at `time` (`unix_s` seconds).
    pub fn of(
        report: &CheckReport,
        time: &str,
        unix_s: f64,
        machine: &str,
        data_file: &str,
    ) -> Entry {
        let quantities = report
            .candidates
            .iter()
            .filter(|c| {
                c.name.starts_with("leg ") || c.kind == crate::candidates::CandidateKind::Thermal
            })
            .filter_map(|c| {
                let (p, (v, sd), d) = (
                    c.parameters.first()?,
                    (*c.alone.first()?)?,
                    (*c.flagged_beyond.first()?)?,
                );
                let (name, value, unit) = crate::report::shown(p, v);
                Some(Quantity {
                    name,
                    unit: unit.to_string(),
                    value,
                    std_dev: crate::report::shown(p, sd).1,
                    band: crate::report::shown(p, d).1,
                })
            })
            .collect();
        Entry {
            format_version: HISTORY_FORMAT_VERSION,
            time: time.to_string(),
            unix_s,
            machine: machine.to_string(),
            data_file: data_file.to_string(),
            verdict: report.verdict.as_str().to_string(),
            most_likely: report
                .most_likely
                .map(|i| report.candidates[i].name.clone()),
            shortlist: report.shortlist.clone(),
            consistency: (
                report.consistency.statistic,
                report.consistency.dof,
                report.consistency.p_value,
            ),
            quantities,
            calibration_digest: None,
        }
    }
}

/// The entries of a history file (none when it does not exist).
pub fn read(path: &std::path::Path) -> Result<Vec<Entry>, CheckError> {
    let file = path.display();
    if let Ok(m) = std::fs::metadata(path)
        && !m.is_file()
    {
        return Err(CheckError::HistoryLine(format!(
            "{file}: not a regular file (a history is one, appended and replaced whole)"
        )));
    }
    let text = match tricept_data::bounded::read_json_text(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(CheckError::HistoryLine(format!("{file}: {e}"))),
    };
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let newer = tricept_kinematics::description::newer_format(
                l,
                "check history line",
                HISTORY_FORMAT_VERSION,
            );
            if let Some(newer) = newer {
                return Err(CheckError::HistoryLine(format!(
                    "{file}: line {}: {newer}",
                    i + 1
                )));
            }
            serde_json::from_str(l).map_err(|e| {
                CheckError::HistoryLine(format!(
                    "{file}: line {}: not a check of this history: {e}",
                    i + 1
                ))
            })
        })
        .collect()
}

/// Refuses a history of another calibration: every check of `entries`
/// that names its calibration (`calibration_digest`; lines written before
/// histories named it do not) must name `digest`. A history follows one
/// calibration: after a recalibration, start a new one.
///
/// # Example
/// ```
/// use tricept_check::history::{Entry, belongs_to};
/// let mut e: Entry = serde_json::from_str(r#"{"time": "2026-12-03T06:30:00Z", "unix_s": 0.0,
///     "machine": "m.json", "data_file": "d.csv", "verdict": "unchanged", "most_likely": null,
///     "shortlist": [], "consistency": [1.0, 3, 0.8], "quantities": []}"#).unwrap();
/// let path = std::path::Path::new("h.jsonl");
/// // A line without a digest belongs to any calibration.
/// assert!(belongs_to(path, &[e.clone()], Some("abc")).is_ok());
/// e.calibration_digest = Some("def".into());
/// assert!(belongs_to(path, &[e], Some("abc")).is_err());
/// ```
pub fn belongs_to(
    path: &std::path::Path,
    entries: &[Entry],
    digest: Option<&str>,
) -> Result<(), CheckError> {
    let Some(digest) = digest else {
        return Ok(());
    };
    let other = entries.iter().enumerate().find_map(|(i, e)| {
        e.calibration_digest
            .as_deref()
            .filter(|d| *d != digest)
            .map(|d| (i, d))
    });
    match other {
        None => Ok(()),
        Some((i, d)) => Err(CheckError::HistoryLine(format!(
            "{}: check {} of the history ({}) is of another calibration (digest {}, the machine file's {}): a history follows one calibration; start a new one after a recalibration",
            path.display(),
            i + 1,
            entries[i].time,
            d.get(..12).unwrap_or(d),
            digest.get(..12).unwrap_or(digest)
        ))),
    }
}

/// Appends `entry` to the history file `path` (rewritten atomically,
/// under an exclusive lock on the history file itself: concurrent appends
/// all land, whatever name, link or relative path each gives it). A
/// history of another calibration than the entry's is refused
/// ([`belongs_to`]).
pub fn append(path: &std::path::Path, entry: &Entry) -> Result<Vec<Entry>, CheckError> {
    let failed = |e: std::io::Error| CheckError::History(format!("{}: {e}", path.display()));
    // Held until the rename below has replaced the file.
    let _lock = lock(path).map_err(failed)?;
    let mut entries = read(path)?;
    belongs_to(path, &entries, entry.calibration_digest.as_deref())?;
    entries.push(entry.clone());
    let mut text = String::new();
    for e in &entries {
        let line = serde_json::to_string(e)
            .map_err(|e| CheckError::History(format!("{}: {e}", path.display())))?;
        text.push_str(&line);
        text.push('\n');
    }
    tricept_data::write_atomic(path, |w| w.write_all(text.as_bytes()))
        .map_err(|e| CheckError::History(format!("{}: not written: {e}", path.display())))?;
    Ok(entries)
}

/// An exclusive lock on the history file `path` itself (created empty when
/// it does not exist): the lock belongs to the file, not to the name, so
/// two names of one file (a symbolic link, `./h.jsonl` and `h.jsonl`) take
/// the same lock. An append replaces the file (a rename), so a lock taken
/// on the file just replaced is dropped and taken again on the new one:
/// the lock held is always that of the file the path names now.
fn lock(path: &std::path::Path) -> std::io::Result<std::fs::File> {
    let not_regular = || {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file: a history is one",
        )
    };
    for _ in 0..10_000 {
        // Opening a named pipe to write would wait for a reader.
        if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
            return Err(not_regular());
        }
        let file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .append(true)
            .open(path)?;
        if !file.metadata()?.is_file() {
            return Err(not_regular());
        }
        file.lock()?;
        if same_file(&file.metadata()?, &std::fs::metadata(path)?) {
            return Ok(file);
        }
    }
    Err(std::io::Error::other(
        "the history was replaced 10000 times while waiting for its lock",
    ))
}

/// Whether two metadata are of the same file (device and inode).
#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

/// Whether two metadata are of the same file (size and time: no inode).
#[cfg(not(unix))]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    a.len() == b.len() && a.modified().ok() == b.modified().ok()
}

/// The trend of one key quantity over a history.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trend {
    /// The quantity.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Days since the first check of each entry.
    pub days: Vec<f64>,
    /// The estimates, their standard deviations and bands.
    pub values: Vec<f64>,
    /// See `values`.
    pub std_dev: Vec<f64>,
    /// See `values`.
    pub band: Vec<f64>,
    /// Weighted least-squares slope per day and its standard deviation
    /// (`None` with fewer than three checks or one day).
    pub slope_per_day: Option<(f64, f64)>,
    /// Entries whose value leaves its band.
    pub outside: Vec<usize>,
}

/// The trends of the key quantities of `entries` (in time order).
///
/// # Example
/// ```
/// use tricept_check::history::{Entry, Quantity, trends};
/// use tricept_check::history::HISTORY_FORMAT_VERSION;
/// let entry = |day: f64, v: f64| Entry {
///     format_version: HISTORY_FORMAT_VERSION,
///     time: String::new(), unix_s: day * 86_400.0, machine: "m".into(), data_file: "d".into(),
///     verdict: "unchanged".into(), most_likely: None, shortlist: vec![], consistency: (50.0, 57, 0.7),
///     quantities: vec![Quantity { name: "dq1".into(), unit: "um".into(), value: v, std_dev: 1.0, band: 5.0 }],
///     calibration_digest: None,
/// };
/// // A leg drifting 1 um a day: inside its band for four days, outside on the sixth.
/// let t = &trends(&[entry(0.0, 0.0), entry(2.0, 2.0), entry(4.0, 4.0), entry(6.0, 6.0)])[0];
/// assert_eq!(t.outside, vec![3]);
/// assert!((t.slope_per_day.unwrap().0 - 1.0).abs() < 1e-9);
/// ```
pub fn trends(entries: &[Entry]) -> Vec<Trend> {
    let t0 = entries.first().map_or(0.0, |e| e.unix_s);
    let mut names: Vec<(String, String)> = Vec::new();
    for e in entries {
        for q in &e.quantities {
            if !names.iter().any(|(n, _)| *n == q.name) {
                names.push((q.name.clone(), q.unit.clone()));
            }
        }
    }
    names
        .into_iter()
        .map(|(name, unit)| {
            let mut t = Trend {
                name: name.clone(),
                unit,
                days: Vec::new(),
                values: Vec::new(),
                std_dev: Vec::new(),
                band: Vec::new(),
                slope_per_day: None,
                outside: Vec::new(),
            };
            for e in entries {
                if let Some(q) = e.quantities.iter().find(|q| q.name == name) {
                    if q.value.abs() > q.band {
                        t.outside.push(t.values.len());
                    }
                    t.days.push((e.unix_s - t0) / 86_400.0);
                    t.values.push(q.value);
                    t.std_dev.push(q.std_dev);
                    t.band.push(q.band);
                }
            }
            t.slope_per_day = slope(&t.days, &t.values, &t.std_dev);
            t
        })
        .collect()
}

/// Weighted least-squares slope of `y` against `x` with its standard
/// deviation.
fn slope(x: &[f64], y: &[f64], sd: &[f64]) -> Option<(f64, f64)> {
    if x.len() < 3 {
        return None;
    }
    let w: Vec<f64> = sd.iter().map(|s| 1.0 / (s * s).max(1e-300)).collect();
    let sw: f64 = w.iter().sum();
    let mx = x.iter().zip(&w).map(|(x, w)| x * w).sum::<f64>() / sw;
    let my = y.iter().zip(&w).map(|(y, w)| y * w).sum::<f64>() / sw;
    let sxx: f64 = x.iter().zip(&w).map(|(x, w)| w * (x - mx).powi(2)).sum();
    if sxx.is_nan() || sxx <= 0.0 || x.last().zip(x.first()).is_some_and(|(b, a)| b - a < 1.0) {
        return None;
    }
    let sxy: f64 = x
        .iter()
        .zip(y)
        .zip(&w)
        .map(|((x, y), w)| w * (x - mx) * (y - my))
        .sum();
    Some((sxy / sxx, (1.0 / sxx).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(writer: usize, i: usize) -> Entry {
        Entry {
            format_version: HISTORY_FORMAT_VERSION,
            time: format!("2026-12-03T00:00:{i:02}Z"),
            unix_s: i as f64,
            machine: format!("writer{writer}"),
            data_file: format!("day{i}.csv"),
            verdict: "unchanged".into(),
            most_likely: None,
            shortlist: Vec::new(),
            consistency: (1.0, 3, 0.8),
            quantities: Vec::new(),
            calibration_digest: None,
        }
    }

    #[test]
    fn a_line_without_a_version_is_version_1_and_a_newer_line_is_refused_by_number() {
        let dir = std::env::temp_dir().join(format!("tricept-history-v-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("h.jsonl");
        let mut old = serde_json::to_value(entry(1, 1)).unwrap();
        old.as_object_mut().unwrap().remove("format_version");
        std::fs::write(&path, format!("{old}\n")).unwrap();
        let read_back = read(&path).unwrap();
        assert_eq!(read_back, [entry(1, 1)]);
        let mut newer = serde_json::to_value(entry(1, 2)).unwrap();
        newer["format_version"] = 2.into();
        newer["a_key_of_version_2"] = true.into();
        std::fs::write(&path, format!("{old}\n{newer}\n")).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("line 2: format_version 2"), "{e}");
        assert!(append(&path, &entry(1, 3)).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_history_of_another_calibration_is_refused_and_kept() {
        let dir =
            std::env::temp_dir().join(format!("tricept-history-other-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("h.jsonl");
        let of = |digest: Option<&str>, i: usize| Entry {
            calibration_digest: digest.map(String::from),
            ..entry(0, i)
        };
        // A line written before histories named their calibration, then
        // two checks of calibration A.
        append(&path, &of(None, 0)).unwrap();
        append(&path, &of(Some("aaaaaaaaaaaaaaaa"), 1)).unwrap();
        append(&path, &of(Some("aaaaaaaaaaaaaaaa"), 2)).unwrap();
        let before = std::fs::read(&path).unwrap();
        // A check of calibration B: refused, naming the first check of A,
        // the history as it was.
        let e = append(&path, &of(Some("bbbbbbbbbbbbbbbb"), 3))
            .unwrap_err()
            .to_string();
        assert!(e.contains("check 2 of the history"), "{e}");
        assert!(e.contains("another calibration"), "{e}");
        assert_eq!(std::fs::read(&path).unwrap(), before);
        // A check that names no calibration is taken.
        assert_eq!(append(&path, &of(None, 4)).unwrap().len(), 4);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn concurrent_appends_through_any_name_keep_every_record() {
        let dir = std::env::temp_dir().join(format!("tricept-history-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let path = dir.join("h.jsonl");
        // One writer by the file's name, one through a symbolic link to it
        // (and one more through a path with `..` in it): one file, one
        // lock.
        #[cfg(unix)]
        let other = {
            let link = dir.join("link.jsonl");
            std::os::unix::fs::symlink("h.jsonl", &link).unwrap();
            link
        };
        #[cfg(not(unix))]
        let other = dir.join("sub").join("..").join("h.jsonl");
        let names = [
            path.clone(),
            other,
            dir.join("sub").join("..").join("h.jsonl"),
        ];
        std::thread::scope(|s| {
            for (writer, name) in names.iter().take(2).enumerate() {
                s.spawn(move || {
                    for i in 0..50 {
                        append(name, &entry(writer, i)).unwrap();
                    }
                });
            }
            let name = &names[2];
            s.spawn(move || {
                for i in 0..10 {
                    append(name, &entry(2, i)).unwrap();
                }
            });
        });
        // Nothing beside the history (no lock file), the link still a link.
        let mut left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        #[cfg(unix)]
        assert_eq!(left, ["h.jsonl", "link.jsonl", "sub"]);
        assert_eq!(read(&path).unwrap().len(), 110);
        let kept = read(&path).unwrap();
        for writer in 0..2 {
            let name = format!("writer{writer}");
            let days: Vec<String> = kept
                .iter()
                .filter(|e| e.machine == name)
                .map(|e| e.data_file.clone())
                .collect();
            let expected: Vec<String> = (0..50).map(|i| format!("day{i}.csv")).collect();
            assert_eq!(days, expected, "{name}: every append, in its order");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[cfg(unix)]
    #[test]
    fn a_history_that_is_not_a_regular_file_is_refused_without_waiting() {
        // A named pipe opened to read or write would wait for its other end.
        let dir = std::env::temp_dir().join(format!("tricept-history-fifo-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("h.jsonl");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()));
        assert!(
            read(&fifo)
                .unwrap_err()
                .to_string()
                .contains("not a regular file")
        );
        assert!(
            append(&fifo, &entry(0, 0))
                .unwrap_err()
                .to_string()
                .contains("not a regular file")
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
