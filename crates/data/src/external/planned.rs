//! Poses to measure at (what `tricept plan` writes and `tricept simulate`
//! reads).

use super::{
    CommonFields, ExternalData, ExternalPose, ExternalRow, MAX_EXTENSION_MM, Reading, Row,
};
use crate::DataError;

/// A pose to measure at (what `tricept plan` writes and `tricept simulate`
/// reads): the commands and, for information, the nominal tool tip and
/// ballbar length there.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlannedPose {
    /// Where the machine is to stand.
    pub pose: ExternalPose,
    /// Known extension of a tracker target along the tool, mm.
    pub extension_mm: f64,
    /// The nominal tool tip there, mm (columns `x,y,z`).
    pub tip_mm: Option<[f64; 3]>,
    /// The nominal ballbar length there, mm (column `length`).
    pub length_mm: Option<f64>,
    /// The feature to touch there (column `feature`, touch-offs).
    pub feature: Option<u32>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// Poses to measure at.
pub type PlannedPoses = ExternalData<PlannedPose>;

impl ExternalRow for PlannedPose {
    const MEASURED: &'static [&'static str] = &[];
    const OPTIONAL: &'static [&'static str] = &["extension_mm", "x", "y", "z", "length", "feature"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let any = |_: f64| None;
        let tip = [
            row.optional("x", any)?,
            row.optional("y", any)?,
            row.optional("z", any)?,
        ];
        Ok(PlannedPose {
            pose,
            extension_mm: row
                .optional("extension_mm", |v| {
                    (v.abs() > MAX_EXTENSION_MM).then_some("an extension beyond ±1000 mm (mm?)")
                })?
                .unwrap_or(0.0),
            tip_mm: match tip {
                [Some(x), Some(y), Some(z)] => Some([x, y, z]),
                _ => None,
            },
            length_mm: row.optional("length", any)?,
            feature: row.whole_from_one("feature")?,
            line: row.record.line,
        })
    }

    fn own_value(&self, column: &str) -> Option<f64> {
        match column {
            "extension_mm" => (self.extension_mm != 0.0).then_some(self.extension_mm),
            "x" => self.tip_mm.map(|t| t[0]),
            "y" => self.tip_mm.map(|t| t[1]),
            "z" => self.tip_mm.map(|t| t[2]),
            "length" => self.length_mm,
            "feature" => self.feature.map(f64::from),
            _ => None,
        }
    }
}

impl CommonFields for PlannedPose {
    fn common(&self) -> Reading {
        Reading {
            pose: self.pose,
            line: self.line,
            ..Reading::default()
        }
    }
}
