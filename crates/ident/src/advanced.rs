//! Beyond the workflows' modules: the typed values several requests are
//! made of, the machine loaded ahead of a workflow, and the few low-level
//! items of the internal crates that code beside the door (the `tricept`
//! binary, the Python binding, the benchmarks) needs. Most users need only
//! the root and a workflow's module; everything here may change with the
//! workflows that use it.
//!
//! - **Request values**: each parses from the text of the CLI flag that
//!   sets it ([`std::str::FromStr`], so the binary's clap value parsers
//!   are these types): [`Triple`] (`X,Y,Z`), [`HeadAngles`],
//!   [`TrueErrors`] (`--truth`), [`FrameMmRad`] (`--tracker-frame-mm-rad`),
//!   [`Poses`], [`TrackerTargetSpec`], [`LengthSigma`], [`HeadModel`],
//!   [`EffectNames`], [`EvalGrid`]; the sensor-noise overrides
//!   ([`SensorNoise`]) and the parameter set ([`ParameterSet`]).
//! - **The machine loaded ahead**: [`load_machine`] gives a
//!   [`crate::LoadedMachine`] (its description, its warnings), which
//!   converts into the [`crate::MachineInput`] every request takes (as
//!   [`crate::MachineInput::load`] does).
//! - **Output format**: the `format_version` of the JSON outputs
//!   ([`OUTPUT_FORMAT_VERSION`]) and the one way it is put into one
//!   ([`versioned_json`]: what `--json` prints).
//! - **Result parts**: the machine file a result may write
//!   ([`crate::calibrate::MachineFile`], kept apart from it, to write later
//!   by the same rule). The result's shape
//!   ([`crate::Outcome`], [`crate::WritesMachine`]), how it writes
//!   ([`crate::WriteOptions`], [`crate::Written`]) and the accuracy a
//!   written file promises ([`crate::calibrate::Accuracy`]) are at the root
//!   and in the workflows' modules.
//! - **Low level**: the error mapping of the internal crates' errors
//!   ([`Classify`]; the file-system failure under one is the root's
//!   [`crate::FileFailure`]), the reader of data in memory
//!   ([`read_data_from`], giving the root's [`crate::Dataset`]),
//!   and the foreign crates whose types results hold (`nalgebra`,
//!   `serde_json`).
//! - **Beside the door**: files written as every verb writes them
//!   ([`files`]), the figures ([`plot`]), and the defaults the binary's
//!   flags show ([`DEFAULT_TOLERANCE_MM`], [`DEFAULT_POWER`],
//!   [`fusable_effects`]).
//!
//! # Example
//! ```
//! use tricept_ident::LoadedMachine;
//! use tricept_ident::advanced::{SensorNoise, load_machine};
//! let noise = SensorNoise { length_noise_um: Some(2.0), ..SensorNoise::default() };
//! let loaded: LoadedMachine = load_machine(None, &noise)?;
//! assert!(loaded.warnings().is_empty());
//! # Ok::<(), tricept_ident::Error>(())
//! ```

pub use crate::calibrate::values::{
    EffectNames, EvalGrid, HeadModel, LengthSigma, TrackerTargetSpec,
};
pub use crate::data_input::read_data_from;
pub use crate::error::Classify;
pub use crate::inputs::{
    FrameMmRad, HeadAngles, Poses, SensorNoise, Triple, TrueErrors, load_machine, parse_effects,
    parse_numbers,
};
pub use crate::json_version::{OUTPUT_FORMAT_VERSION, versioned_json};
pub use nalgebra;
pub use serde_json;

/// The power a planned check detects its stated change with by default.
///
/// # Example
/// ```
/// use tricept_ident::advanced::DEFAULT_POWER;
/// use tricept_ident::plan::{Instrument, PlanRequest};
/// assert_eq!(PlanRequest::new(Instrument::Check).power, DEFAULT_POWER);
/// ```
#[doc(inline)]
pub use tricept_check::check::DEFAULT_POWER;
/// One pose of measured data (a [`crate::Dataset`]'s `poses`).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{MeasuredPose, read_data_from};
/// use tricept_ident::kinematics::GeometricMachine;
/// let csv = "q1,q2,q3,phi,theta,s\n700,701,702,0,0,5\n";
/// let data = read_data_from(csv.as_bytes(), "memory", &GeometricMachine::paper())?;
/// let pose: &MeasuredPose = &data.poses[0];
/// assert_eq!(pose.commands_mm, [700.0, 701.0, 702.0]);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::MeasuredPose;
/// The three UP-limb sensor readings of one pose: encoders `phi` and
/// `theta` (rad) and the linear scale `s` (mm).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{Readings, read_data_from};
/// use tricept_ident::kinematics::GeometricMachine;
/// let csv = "q1,q2,q3,phi,theta,s\n700,700,700,0.001,-0.002,5\n";
/// let data = read_data_from(csv.as_bytes(), "memory", &GeometricMachine::paper())?;
/// let r: Readings = data.poses[0].readings;
/// assert_eq!((r.phi_rad, r.theta_rad, r.s_mm), (0.001, -0.002, 5.0));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::Readings;

/// The manufacturing tolerance a calibration is judged against by default, mm.
///
/// # Example
/// ```
/// use tricept_ident::advanced::DEFAULT_TOLERANCE_MM;
/// use tricept_ident::calibrate::CalibrateRequest;
/// assert_eq!(CalibrateRequest::new("campaign.csv").tolerance_mm, DEFAULT_TOLERANCE_MM);
/// ```
#[doc(inline)]
pub use tricept_engine::accuracy::DEFAULT_TOLERANCE_MM;
// The internal crates' errors the door's [`Error`](crate::Error) is made
// from ([`Classify`]).
/// A check's failure ([`crate::check`]): an unreadable record or history, a
/// campaign that cannot see a change, a pose out of reach.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{CheckError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = CheckError::Blind("no leg moves".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("cannot see a change"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_check::CheckError;
/// A measured-data file's failure: unreadable, empty, a missing or bad
/// column (naming file, line and column).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{DataError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = DataError::NoRows { file: "today.csv".into() };
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("today.csv: header only"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_data::DataError;
/// Why a diagnosis' model cannot be deployed into a machine file.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{DeployError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = DeployError::NotDeployable("wobble_um".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("`wobble_um`"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_diagnose::DeployError;
/// A diagnosis' failure ([`crate::diagnosis`]): too few poses, a degenerate
/// campaign, an identification's failure (of its own kind).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{DiagnoseError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = DiagnoseError::TooFewPoses(12);
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("too few poses (12)"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_diagnose::DiagnoseError;
/// An identification's failure: too few or too similar poses, unreachable
/// poses, inconsistent options (the input's), a numerical failure (not).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{IdentError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = IdentError::Invalid("weights: must be positive".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("weights: must be positive"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_engine::IdentError;
/// What is known of a laser tracker's target offset from the tool tip:
/// free (a nuisance the fit estimates) or known to a standard deviation
/// ([`TrackerTargetSpec::target`]).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{TrackerTarget, TrackerTargetSpec};
/// let nest = "tip".parse::<TrackerTargetSpec>()?.target(5.0)?;
/// assert_eq!(nest, TrackerTarget::Known { offset_mm: [0.0; 3], sigma_um: 5.0 });
/// assert_eq!("free".parse::<TrackerTargetSpec>()?.target(5.0)?, TrackerTarget::Free);
/// assert!(TrackerTargetSpec::Tip.target(-1.0).is_err()); // a sigma is positive
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::fusion::TrackerTarget;
/// The effects a fused calibration (UP sensors with external instruments)
/// can fit: those whose spec says `fused`.
///
/// # Example
/// ```
/// use tricept_ident::advanced::fusable_effects;
/// use tricept_ident::effects::EffectName;
/// let fused: Vec<EffectName> = fusable_effects().collect();
/// assert!(fused.contains(&EffectName::LegLead));
/// let all = EffectName::ALL.iter().filter(|e| e.spec().fused).count();
/// assert_eq!(fused.len(), all);
/// ```
#[doc(inline)]
pub use tricept_engine::fusion::fusable_effects;
/// A calibration record that cannot be trusted: unreadable, edited since it
/// was sealed, or unsealed.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{RecordError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = RecordError::Unsealed;
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("no `seal`"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_engine::record::RecordError;
/// A fleet's failure ([`crate::fleet`]): what cannot be pooled (the
/// input's), a machine's identification, the pooled solve.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{FleetError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = FleetError::Input("two machines: at least 3 are needed".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("at least 3"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_fleet::FleetError;
/// The 21 geometric errors of the paper's model: base and platform joint
/// errors (mm, in their frames) and leg length errors (actual = command +
/// `dq_i`, mm), stored leg by leg (`db`, `da`, `dq`).
///
/// # Example
/// ```
/// use tricept_ident::advanced::GeometricErrors;
/// let mut v = [0.0; 21];
/// v[6] = 0.45; // dq1: the 7th value of leg 1's block
/// v[7] = 0.2; // db2.x: the first of leg 2's
/// let e = GeometricErrors::from_array(&v);
/// assert_eq!((e.dq_mm[0], e.db_mm[1].x), (0.45, 0.2));
/// assert_eq!(e.to_array(), v);
/// assert_eq!(GeometricErrors::default().to_array(), [0.0; 21]);
/// ```
#[doc(inline)]
pub use tricept_model::GeometricErrors;
/// A parameter set's or parameter values' failure: an unknown name or set,
/// values a model cannot represent.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{ModelError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = ModelError::UnknownParameterSet("paper16".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("paper16"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_model::ModelError;
/// Which geometric errors a calibration identifies.
///
/// # Example
/// ```
/// use tricept_ident::advanced::ParameterSet;
/// use tricept_ident::calibrate::CalibrateRequest;
/// let set = CalibrateRequest::new("campaign.csv").parameter_set;
/// assert_eq!(set.len(), set.names().len());
/// assert_eq!(ParameterSet::paper15().len(), 15);
/// ```
#[doc(inline)]
pub use tricept_model::ParameterSet;
/// Why the sparse solver of a fleet's joint fit failed: an unknown the
/// rows do not determine, a failed factorisation, blocks of the wrong
/// shape; a solver's failure, not the input's.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{BlockError, Classify, FleetError};
/// use tricept_ident::{EXIT_OTHER, Error, ErrorKind};
/// let e = FleetError::from(BlockError::NotDetermined { block: Some(2), column: 4 });
/// assert_eq!(e.kind(), ErrorKind::Other);
/// assert_eq!(Error::from_library(e).exit_code(), EXIT_OTHER);
/// ```
#[doc(inline)]
pub use tricept_numerics::sparse::BlockError;
/// A simulated plant's failure: a pose it cannot reach, an invalid
/// configuration.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{PlantError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = PlantError::Invalid("noise must be finite".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("invalid plant configuration"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_plant::PlantError;
/// The figures of the verbs that draw (SVG, written atomically): heat maps
/// of the workspace plane, curves, scatter plots.
///
/// # Example
/// ```
/// use tricept_ident::advanced::plot::plane_z;
/// assert_eq!(plane_z([750.0, 750.0]), "z = 750 mm"); // a map's title names its plane
/// assert_eq!(plane_z([700.0, 812.5]), "z = 700 to 812.5 mm");
/// ```
#[doc(inline)]
pub use tricept_plot as plot;
/// A study's failure (`tricept study`): its parts' errors, each of its own
/// kind, or an invalid study.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{StudyError, Classify};
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = StudyError::Invalid("trials: must be at least 1".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e); // as the door returns it
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("trials"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_study::StudyError;

/// Files written as every verb writes them (atomic: temporary file and
/// rename; `-` for stdout) and messages made one bounded line.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::one_line;
/// let message = one_line("a message\nover two lines");
/// assert!(!message.contains('\n'));
/// ```
pub mod files {
    /// Refuses an output path [`write_atomic`] would not write: a name
    /// ending in a separator, an existing directory, or anything but a
    /// regular file at its end (a device, a pipe, a socket).
    ///
    /// # Example
    /// ```
    /// use std::path::Path;
    /// use tricept_ident::advanced::files::check_output_file;
    /// assert!(check_output_file(Path::new("out/")).is_err()); // a directory's name
    /// assert!(check_output_file(&std::env::temp_dir()).is_err()); // a directory
    /// assert!(check_output_file(Path::new("new-file.json")).is_ok());
    /// ```
    #[doc(inline)]
    pub use tricept_data::atomic::check_output_file;
    /// Writes an external instrument's records (tracker, ballbar, touch
    /// probe) as the CSV `calibrate` reads, atomically ([`write_atomic`]).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::write_external_path;
    /// use tricept_ident::simulate::{ExternalData, ExternalPose, TrackerPoint};
    /// let point = TrackerPoint {
    ///     pose: ExternalPose { commands_mm: [800.0; 3], head_rad: [0.0; 2] },
    ///     position_mm: [10.0, 20.0, 1100.0],
    ///     ..Default::default()
    /// };
    /// let data = ExternalData { records: vec![point; 2], source: "tracker.csv".into() };
    /// let dir = std::env::temp_dir().join(format!("tricept-door-external-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// write_external_path(&dir.join("tracker.csv"), &data, &["simulated".into()])?;
    /// let text = std::fs::read_to_string(dir.join("tracker.csv"))?;
    /// assert!(text.starts_with("# simulated\n"));
    /// assert_eq!(text.lines().filter(|l| l.contains(",10,20,1100")).count(), 2);
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), std::io::Error>(())
    /// ```
    #[doc(inline)]
    pub use tricept_data::external::write_external_path;
    /// A message made one bounded line, as every error of the door is.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::one_line;
    /// assert_eq!(one_line("two\nlines"), one_line(&one_line("two\nlines")));
    /// assert!(!one_line("two\nlines").contains('\n'));
    /// ```
    #[doc(inline)]
    pub use tricept_data::message::one_line;
    /// A path as a message shows it (control characters escaped).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::shown_path;
    /// assert_eq!(shown_path(std::path::Path::new("a\nb.csv")), "a\\nb.csv");
    /// ```
    #[doc(inline)]
    pub use tricept_data::message::shown_path;
    /// Writes a file atomically: `content` writes the whole file into the
    /// writer it is given; the file is replaced only when that and the
    /// flush, sync and rename all succeed (every file the door writes).
    ///
    /// # Example
    /// ```
    /// use std::io::Write;
    /// use tricept_ident::advanced::files::write_atomic;
    /// let dir = std::env::temp_dir().join(format!("tricept-door-atomic-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let path = dir.join("note.txt");
    /// write_atomic(&path, |w| w.write_all(b"first\n"))?;
    /// let failed = write_atomic(&path, |w| {
    ///     w.write_all(b"sec")?;
    ///     Err(std::io::Error::other("disk full"))
    /// });
    /// assert!(failed.is_err());
    /// assert_eq!(std::fs::read_to_string(&path)?, "first\n"); // as it was
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), std::io::Error>(())
    /// ```
    #[doc(inline)]
    pub use tricept_data::write_atomic;
    /// Writes measured data to a file ([`write_to`]), atomically
    /// ([`write_atomic`]).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::write_path;
    /// use tricept_ident::advanced::read_data_from;
    /// use tricept_ident::kinematics::GeometricMachine;
    /// let machine = GeometricMachine::paper();
    /// let data = read_data_from("q1,q2,q3,phi,theta,s\n700,700,700,0,0,5\n".as_bytes(), "in", &machine)?;
    /// let dir = std::env::temp_dir().join(format!("tricept-door-write-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let path = dir.join("campaign.csv");
    /// write_path(&path, &data, &[])?;
    /// let back = read_data_from(std::fs::read(&path)?.as_slice(), "campaign.csv", &machine)?;
    /// assert_eq!(back.poses, data.poses);
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    #[doc(inline)]
    pub use tricept_data::write_path;
    /// Writes measured data as the CSV every verb reads
    /// (`docs/data-format.md`), comments first.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::write_to;
    /// use tricept_ident::advanced::read_data_from;
    /// use tricept_ident::kinematics::GeometricMachine;
    /// let csv = "q1,q2,q3,phi,theta,s\n700,700,700,0.001,-0.002,5\n";
    /// let data = read_data_from(csv.as_bytes(), "memory", &GeometricMachine::paper())?;
    /// let mut out = Vec::new();
    /// write_to(&mut out, &data, &["simulated".into()])?;
    /// let text = String::from_utf8(out)?;
    /// assert!(text.starts_with("# simulated\nq1,q2,q3,phi,theta,s\n"));
    /// let back = read_data_from(text.as_bytes(), "memory", &GeometricMachine::paper())?;
    /// assert_eq!(back.poses[0].readings, data.poses[0].readings);
    /// assert_eq!((data.poses[0].line, back.poses[0].line), (2, 3)); // after the comment
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    #[doc(inline)]
    pub use tricept_data::write_to;
}
