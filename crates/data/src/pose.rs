//! The measured-data types: the readings of one pose ([`Readings`]), one
//! logged pose with its commands and context ([`MeasuredPose`]), a set of
//! poses with the name of its source ([`Dataset`]), and the column names of
//! the CSV contract.

/// Required columns, in canonical order.
pub const REQUIRED_COLUMNS: [&str; 6] = ["q1", "q2", "q3", "phi", "theta", "s"];
/// Optional context columns, in canonical order.
pub const OPTIONAL_COLUMNS: [&str; 5] = ["temp_c", "time_s", "dir1", "dir2", "dir3"];

/// The three sensor readings of one pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Readings {
    /// Encoder reading of the U joint's x-type axis, rad.
    pub phi_rad: f64,
    /// Encoder reading of the U joint's y-type axis, rad.
    pub theta_rad: f64,
    /// Linear-scale reading of the UP limb's prismatic joint, mm.
    pub s_mm: f64,
}

impl Readings {
    /// `[phi, theta, s]` (rad, rad, mm).
    pub fn to_array(self) -> [f64; 3] {
        [self.phi_rad, self.theta_rad, self.s_mm]
    }

    /// From `[phi, theta, s]` (rad, rad, mm).
    pub fn from_array(v: [f64; 3]) -> Readings {
        Readings {
            phi_rad: v[0],
            theta_rad: v[1],
            s_mm: v[2],
        }
    }
}

/// One logged pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeasuredPose {
    /// Commanded leg lengths, mm.
    pub commands_mm: [f64; 3],
    /// Sensor readings.
    pub readings: Readings,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Time of the reading, s.
    pub time_s: Option<f64>,
    /// Sign (+1/-1) of each leg's last motion before the pose.
    pub approach: Option<[i8; 3]>,
    /// Line of the source file the pose came from (1-based; 0 if none).
    pub line: u64,
    /// The campaign of a pooled data set the pose belongs to (0 for a
    /// single file; no CSV column): the poses of one campaign share the
    /// sensors' zero offsets, every campaign has its own (the encoders and
    /// the scale are homed again between campaigns).
    pub campaign: u32,
}

/// A set of logged poses and where they came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Dataset {
    /// The poses in file order.
    pub poses: Vec<MeasuredPose>,
    /// File name (or a label) used in error messages.
    pub source: String,
}

impl Dataset {
    /// The poses whose index (0-based, in [`Dataset::poses`]) passes `keep`,
    /// in their order, with the same source. Each pose keeps its file line,
    /// so messages about the subset still point into the original file.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
let csv = "q1,q2,q3,phi,theta,s\n\
           700,700,700,0.01,0.02,5\n\
           701,700,700,0.01,0.02,5\n\
           702,700,700,0.01,0.02,5\n";
let data = tricept_data::read_from(csv.as_bytes(), "poses.csv").unwrap();
// Every other pose, e.g. for a two-fold cross-validation.
let even = data.subset(|i| i % 2 == 0);
assert_eq!(even.poses.len(), 2);
assert_eq!(even.poses[1].commands_mm[0], 702.0);
assert_eq!(even.poses[1].line, 4);
assert_eq!(even.source, "poses.csv");
```
"#
    )]
    pub fn subset(&self, keep: impl Fn(usize) -> bool) -> Dataset {
        Dataset {
            poses: self
                .poses
                .iter()
                .enumerate()
                .filter(|(i, _)| keep(*i))
                .map(|(_, p)| *p)
                .collect(),
            source: self.source.clone(),
        }
    }
}

#[cfg(test)]
impl Dataset {
    /// The dataset of `poses` held in memory (source `mem`), for tests.
    pub(crate) fn in_memory(poses: impl IntoIterator<Item = MeasuredPose>) -> Dataset {
        Dataset {
            poses: poses.into_iter().collect(),
            source: "mem".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subset_keeps_order_lines_and_source() {
        let data = Dataset::in_memory((0..5).map(|k| MeasuredPose {
            commands_mm: [700.0 + k as f64; 3],
            line: 10 + k,
            ..Default::default()
        }));
        let odd = data.subset(|i| i % 2 == 1);
        assert_eq!(odd.source, "mem");
        assert_eq!(odd.poses, vec![data.poses[1], data.poses[3]]);
        assert_eq!(data.subset(|_| true), data);
        assert!(data.subset(|_| false).poses.is_empty());
    }
}
