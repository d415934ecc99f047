//! The door's pages of the external instruments' records (laser tracker,
//! ballbar, touch probe) a simulation writes beside the campaign,
//! re-exported by [`crate::simulate`]: kept here so the workflow module
//! stays short. The files are written with
//! [`crate::advanced::files::write_external_path`].

/// A ballbar's file: its readings ([`ExternalData`] of [`BallbarReading`]).
///
/// # Example
/// ```
/// use tricept_ident::simulate::{BallbarData, BallbarReading, ExternalData};
/// let data: BallbarData = ExternalData { records: vec![BallbarReading::default()], source: "b.csv".into() };
/// assert_eq!(data.records[0].sigma_um, None); // the instrument's stated noise applies
/// ```
#[doc(inline)]
pub use tricept_data::external::BallbarData;
/// A ballbar's reading: where the machine stood and the bar's length (mm),
/// with the setup it belongs to.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::write_external_path;
/// use tricept_ident::simulate::{BallbarData, BallbarReading, ExternalData, ExternalPose};
/// let reading = BallbarReading {
///     pose: ExternalPose { commands_mm: [800.0, 810.0, 790.0], head_rad: [0.5, -0.3] },
///     length_mm: 150.0012,
///     ..Default::default()
/// };
/// let data: BallbarData = ExternalData { records: vec![reading], source: "ballbar.csv".into() };
/// let dir = std::env::temp_dir().join(format!("tricept-door-ballbar-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// write_external_path(&dir.join("ballbar.csv"), &data, &[])?;
/// let text = std::fs::read_to_string(dir.join("ballbar.csv"))?;
/// assert!(text.starts_with("q1,q2,q3,h1,h2,length"));
/// assert!(text.contains("800,810,790,0.5,-0.3,150.0012"));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::external::BallbarReading;
/// The records of one external-measurement file, in file order, and the
/// file's name (or a label) for messages.
///
/// # Example
/// ```
/// use tricept_ident::simulate::{ExternalData, TrackerData, TrackerPoint};
/// let data: TrackerData = ExternalData { records: vec![TrackerPoint::default(); 2], source: "t.csv".into() };
/// assert_eq!(data.records.len(), 2);
/// assert_eq!(ExternalData::<TrackerPoint>::default().records.len(), 0);
/// ```
#[doc(inline)]
pub use tricept_data::external::ExternalData;
/// Where the machine stood when an instrument measured: leg commands (mm)
/// and head angles (rad), the first five columns of every external file.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::write_external_path;
/// use tricept_ident::simulate::{ExternalData, ExternalPose, TouchReading};
/// let pose = ExternalPose { commands_mm: [800.0, 810.0, 790.0], head_rad: [0.5, -0.3] };
/// let data = ExternalData {
///     records: vec![TouchReading { pose, feature: 2, ..Default::default() }],
///     source: "touch.csv".into(),
/// };
/// let dir = std::env::temp_dir().join(format!("tricept-door-pose-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// write_external_path(&dir.join("touch.csv"), &data, &[])?;
/// let text = std::fs::read_to_string(dir.join("touch.csv"))?;
/// assert!(text.starts_with("q1,q2,q3,h1,h2,"));
/// assert!(text.lines().nth(1).is_some_and(|row| row.starts_with("800,810,790,0.5,-0.3,")));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::external::ExternalPose;
/// A record type of an external file (tracker, ballbar, touch probe): what
/// [`crate::advanced::files::write_external_path`] writes.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::write_external_path;
/// use tricept_ident::simulate::{BallbarReading, ExternalData, ExternalRecord, TrackerPoint};
/// fn header<T: ExternalRecord>(record: T) -> std::io::Result<String> {
///     let dir = std::env::temp_dir().join(format!("tricept-door-record-{}", std::process::id()));
///     std::fs::create_dir_all(&dir)?;
///     let data = ExternalData { records: vec![record], source: "r.csv".into() };
///     write_external_path(&dir.join("r.csv"), &data, &[])?;
///     let text = std::fs::read_to_string(dir.join("r.csv"))?;
///     std::fs::remove_dir_all(&dir)?;
///     Ok(text.lines().next().unwrap_or("").to_string())
/// }
/// assert!(header(TrackerPoint::default())?.contains(",x,y,z"));
/// assert!(header(BallbarReading { length_mm: 100.0, ..Default::default() })?.contains(",length"));
/// # Ok::<(), std::io::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::external::ExternalRecord;
/// A touch probe's file: its readings ([`ExternalData`] of
/// [`TouchReading`]).
///
/// # Example
/// ```
/// use tricept_ident::simulate::{ExternalData, TouchData, TouchReading};
/// let data: TouchData = ExternalData { records: vec![TouchReading::default(); 3], source: "touch.csv".into() };
/// assert_eq!(data.records.iter().filter(|r| r.feature == 0).count(), 3);
/// ```
#[doc(inline)]
pub use tricept_data::external::TouchData;
/// A touch probe's reading: where the machine stood when the stylus touched
/// a feature (by its id in the features file).
///
/// # Example
/// ```
/// use tricept_ident::simulate::{ExternalPose, TouchReading};
/// let touch = TouchReading { pose: ExternalPose::default(), feature: 3, ..Default::default() };
/// assert_eq!((touch.feature, touch.temp_c), (3, None));
/// ```
#[doc(inline)]
pub use tricept_data::external::TouchReading;
/// A laser tracker's file: its points ([`ExternalData`] of
/// [`TrackerPoint`]).
///
/// # Example
/// ```
/// use tricept_ident::simulate::{ExternalData, TrackerData, TrackerPoint};
/// let data: TrackerData = ExternalData { records: vec![TrackerPoint::default()], source: "t.csv".into() };
/// assert_eq!(data.records[0].position_mm, [0.0; 3]);
/// ```
#[doc(inline)]
pub use tricept_data::external::TrackerData;
/// A laser tracker's point: where the machine stood, the target's measured
/// position (mm, the tracker's frame), the UP limb's extension, the setup.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::write_external_path;
/// use tricept_ident::simulate::{ExternalData, ExternalPose, TrackerPoint};
/// let point = TrackerPoint {
///     pose: ExternalPose { commands_mm: [800.0; 3], head_rad: [0.1, 0.2] },
///     position_mm: [1.0, 2.0, 3.0],
///     extension_mm: 100.0,
///     setup: 1,
///     ..Default::default()
/// };
/// let data = ExternalData { records: vec![point], source: "tracker.csv".into() };
/// let dir = std::env::temp_dir().join(format!("tricept-door-tracker-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// write_external_path(&dir.join("tracker.csv"), &data, &[])?;
/// let text = std::fs::read_to_string(dir.join("tracker.csv"))?;
/// assert_eq!(text, "q1,q2,q3,h1,h2,x,y,z,extension_mm\n800,800,800,0.1,0.2,1,2,3,100\n");
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::external::TrackerPoint;
