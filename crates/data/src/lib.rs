//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The measured-data contract of the Tricept self-calibration: one CSV row
//! per pose, written by logging tools and the plant simulator, read by
//! identification and diagnosis.
//!
//! Columns (header required, `#` lines are comments, any order):
//!
//! | column | unit | required | meaning |
//! |---|---|---|---|
//! | `q1,q2,q3` | mm | yes | commanded leg lengths sent to the drives |
//! | `phi,theta` | rad | yes | U-joint encoder readings of the UP limb (unknown zero offsets) |
//! | `s` | mm | yes | linear-scale reading of the UP limb (unknown zero offset) |
//! | `temp_c` | °C | no | structure temperature |
//! | `time_s` | s | no | time of the reading |
//! | `dir1,dir2,dir3` | ±1 | no (all three or none) | sign of each leg's last motion before the pose |
//!
//! Other columns are ignored. The reader is strict: every problem is a
//! [`DataError`] that names the file, the line and the column, never a
//! panic and never a silently skipped row. Target lists (columns `x,y,z`,
//! [`read_targets`](crate::targets::read_targets)) follow the same rules and get the same messages.
//!
//! External measurements (laser tracker or CMM points, ballbar lengths,
//! touch-offs on spheres and planes, with the leg commands and head angles
//! they were taken at) have their own CSV contracts, read by the same
//! machinery with the same messages ([`read_external_path`](crate::external::read_external_path), [`Features`](crate::external::Features)).
//!
//! Modules: `pose` (the types: [`Readings`], [`MeasuredPose`], [`Dataset`]),
//! `error` ([`DataError`]), `records` (the line and record machinery every
//! reader shares), `read` (the measured-data reader), `targets` (the
//! target-list reader), `external` (the external-measurement files), `write`
//! (the writer), `atomic` (every file written whole or not at all). Everything is re-exported
//! here: use `tricept_data::X`.
//!
//! # Example
//! ```
//! let csv = "q1,q2,q3,phi,theta,s\n796.5,796.5,796.5,0.001,-0.002,12.5\n";
//! let data = tricept_data::read_from(csv.as_bytes(), "poses.csv").unwrap();
//! let mut out = Vec::new();
//! tricept_data::write_to(&mut out, &data, &[]).unwrap();
//! assert_eq!(String::from_utf8(out).unwrap(), csv);
//! ```
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod atomic;
pub mod bounded;
mod error;
pub mod external;
pub mod message;
pub mod pose;
pub mod read;
mod records;
pub mod targets;
mod write;

pub use atomic::write_atomic;
pub use error::DataError;
pub use pose::{Dataset, MeasuredPose, Readings};
pub use read::{read_from, read_path};
pub use write::{write_path, write_to};
