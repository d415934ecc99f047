//! Measured data as a workflow takes it: a CSV file the door reads (and
//! whose bytes a written machine file's record hashes), or a [`Dataset`]
//! already in memory (built by a program, or numpy columns from a Python
//! binding). Either way the commands are checked against the machine's
//! stroke before any computation. Reading the file and checking the
//! commands live here, so that loading the data is one room of the
//! identify walk.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use tricept_data::Dataset;
use tricept_kinematics::{KinematicsError, Machine};

use crate::error::{Error, FileFailure};

/// Measured data: a file to read, a file already read, or a data set in
/// memory.
///
/// # Example
/// ```
/// use tricept_ident::DataInput;
/// let d = DataInput::from("data.csv");
/// assert_eq!(d.name(), "data.csv");
/// assert_eq!(d.path().map(|p| p.display().to_string()).as_deref(), Some("data.csv"));
/// ```
#[derive(Debug, Clone)]
pub enum DataInput {
    /// A measured-data CSV file (docs/data-format.md).
    File(PathBuf),
    /// Data already in memory; its `source` names it in messages.
    Memory(Dataset),
    /// A measured-data file the caller has read already (with a progress
    /// display, say): the data are used, the file names them and is what
    /// a calibration record hashes.
    Read {
        /// The file the data were read from.
        file: PathBuf,
        /// Its data.
        data: Dataset,
    },
}

impl From<&str> for DataInput {
    fn from(path: &str) -> DataInput {
        DataInput::File(PathBuf::from(path))
    }
}

impl From<PathBuf> for DataInput {
    fn from(path: PathBuf) -> DataInput {
        DataInput::File(path)
    }
}

impl From<&Path> for DataInput {
    fn from(path: &Path) -> DataInput {
        DataInput::File(path.to_path_buf())
    }
}

impl From<String> for DataInput {
    fn from(path: String) -> DataInput {
        DataInput::File(PathBuf::from(path))
    }
}

impl From<&String> for DataInput {
    fn from(path: &String) -> DataInput {
        DataInput::File(PathBuf::from(path))
    }
}

/// A data file by any name a program holds: `&str`, `String`, `&Path`,
/// `PathBuf` or `&PathBuf`.
///
/// # Example
/// ```
/// use std::path::PathBuf;
/// use tricept_ident::DataInput;
/// let file = PathBuf::from("campaign.csv");
/// for input in [
///     DataInput::from(&file),
///     DataInput::from(file.clone()),
///     DataInput::from(file.as_path()),
///     DataInput::from("campaign.csv"),
///     DataInput::from(String::from("campaign.csv")),
/// ] {
///     assert_eq!(input.name(), "campaign.csv");
/// }
/// ```
impl From<&PathBuf> for DataInput {
    fn from(path: &PathBuf) -> DataInput {
        DataInput::File(path.clone())
    }
}

impl From<Dataset> for DataInput {
    fn from(data: Dataset) -> DataInput {
        DataInput::Memory(data)
    }
}

impl DataInput {
    /// The name messages and reports use: the file as given, or the data
    /// set's source.
    pub fn name(&self) -> String {
        match self {
            DataInput::File(p) | DataInput::Read { file: p, .. } => p.display().to_string(),
            DataInput::Memory(d) => d.source.clone(),
        }
    }

    /// The file, when the data come from one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            DataInput::File(p) | DataInput::Read { file: p, .. } => Some(p),
            DataInput::Memory(_) => None,
        }
    }

    /// The data, read (a file) or as given, with every command checked
    /// against `machine`'s stroke (input errors naming file, line and
    /// column).
    pub fn load(&self, machine: &Machine) -> Result<Dataset, Error> {
        match self {
            DataInput::File(p) => read_data(p, machine),
            DataInput::Memory(d) | DataInput::Read { data: d, .. } => {
                check_commands(
                    &d.source,
                    d.poses.iter().map(|p| (p.line, p.commands_mm)),
                    machine,
                )?;
                Ok(d.clone())
            }
        }
    }
}

/// Reads a measured-data file and refuses commands outside the machine's
/// stroke; every problem is an input error naming file, line and column.
pub fn read_data(path: &Path, machine: &Machine) -> Result<Dataset, Error> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|e| {
        Error::input(format!("{file}: {e}")).with_file_failure(FileFailure::new(file.clone(), &e))
    })?;
    read_data_from(std::io::BufReader::new(f), &file, machine)
}

/// The measured data (docs/data-format.md) read from a reader (a file
/// wrapped in a progress display, say); `file` names it in messages.
///
/// # Example
/// ```
/// use tricept_ident::advanced::read_data_from;
/// use tricept_ident::kinematics::GeometricMachine;
/// let csv = "q1,q2,q3,phi,theta,s\n700,700,700,0,0,5\n";
/// let data = read_data_from(csv.as_bytes(), "memory", &GeometricMachine::paper())?;
/// assert_eq!(data.poses.len(), 1);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn read_data_from(
    reader: impl BufRead,
    file: &str,
    machine: &Machine,
) -> Result<Dataset, Error> {
    let data = tricept_data::read_from(reader, file)?;
    // Commands the machine cannot take are input errors too, found here
    // with their line rather than deep inside the solver.
    check_commands(
        &data.source,
        data.poses.iter().map(|p| (p.line, p.commands_mm)),
        machine,
    )?;
    Ok(data)
}

/// Refuses leg commands outside the machine's stroke: an input error naming
/// the file, the line and the column (`records` give line and commands).
pub fn check_commands(
    file: &str,
    records: impl Iterator<Item = (u64, [f64; 3])>,
    machine: &Machine,
) -> Result<(), Error> {
    for (line, q) in records {
        if let Err(e) = machine.check_commands(&q) {
            let message = match e {
                KinematicsError::OutOfStroke {
                    leg,
                    length_mm,
                    min_mm,
                    max_mm,
                } => format!(
                    "{file}: line {line}, column `q{leg}`: command {length_mm} mm is outside the leg stroke [{min_mm}, {max_mm}] mm"
                ),
                e => format!("{file}: line {line}: {e}"),
            };
            return Err(Error::input(message));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_in_memory_are_checked_against_the_stroke_like_a_file() {
        let m = Machine::paper();
        let mut data = Dataset {
            source: "numpy".into(),
            ..Dataset::default()
        };
        let mut pose = tricept_data::MeasuredPose {
            line: 7,
            ..Default::default()
        };
        pose.commands_mm = [773.0, 773.0, 773.0];
        data.poses.push(pose);
        let ok = DataInput::from(data.clone()).load(&m).unwrap();
        assert_eq!(ok, data);
        data.poses[0].commands_mm[1] = 5000.0;
        let input = DataInput::from(data.clone());
        assert_eq!(input.name(), "numpy");
        assert!(input.path().is_none());
        let e = input.load(&m).unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert!(
            e.message().starts_with("numpy: line 7, column `q2`"),
            "{}",
            e.message()
        );
        let read = DataInput::Read {
            file: PathBuf::from("read.csv"),
            data,
        };
        assert_eq!(read.name(), "read.csv");
        assert_eq!(read.path(), Some(Path::new("read.csv")));
        let e = read.load(&m).unwrap_err();
        assert!(e.message().starts_with("numpy: line 7"), "{}", e.message());
        let missing = DataInput::from("no-such-dir/data.csv")
            .load(&m)
            .unwrap_err();
        assert_eq!(missing.exit_code(), crate::EXIT_INPUT);
        assert!(missing.message().starts_with("no-such-dir/data.csv: "));
    }
}
