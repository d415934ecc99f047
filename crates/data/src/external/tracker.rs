//! Laser-tracker and CMM points (`q1,q2,q3,h1,h2,x,y,z`).

use super::{ExternalData, ExternalPose, ExternalRow, MAX_EXTENSION_MM, Row, instrument_record};
use crate::DataError;

/// One point measured by a laser tracker or a CMM.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrackerPoint {
    /// Where the machine stood.
    pub pose: ExternalPose,
    /// The measured point in the instrument's frame, mm.
    pub position_mm: [f64; 3],
    /// Standard deviation of each coordinate, um (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Known extension of the target along the tool axis beyond the tool
    /// tip, mm (0 when the column is absent).
    pub extension_mm: f64,
    /// Instrument station, from 1.
    pub setup: u32,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// Points of a laser tracker or CMM.
pub type TrackerData = ExternalData<TrackerPoint>;

impl ExternalRow for TrackerPoint {
    const MEASURED: &'static [&'static str] = &["x", "y", "z"];
    const OPTIONAL: &'static [&'static str] = &["sigma_um", "extension_mm", "setup", "temp_c"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let position_mm = [
            row.measured_mm(0)?,
            row.measured_mm(1)?,
            row.measured_mm(2)?,
        ];
        // A row's first bad column is named: `sigma_um` comes before
        // `extension_mm`, which comes before `setup` and `temp_c`.
        row.sigma_um()?;
        let extension_mm = row
            .optional("extension_mm", |v| {
                (v.abs() > MAX_EXTENSION_MM).then_some("an extension beyond ±1000 mm (mm?)")
            })?
            .unwrap_or(0.0);
        Ok(TrackerPoint {
            position_mm,
            extension_mm,
            ..TrackerPoint::with_reading(row.reading(pose)?)
        })
    }

    fn own_value(&self, column: &str) -> Option<f64> {
        match column {
            "x" => Some(self.position_mm[0]),
            "y" => Some(self.position_mm[1]),
            "z" => Some(self.position_mm[2]),
            "extension_mm" => (self.extension_mm != 0.0).then_some(self.extension_mm),
            _ => None,
        }
    }
}

instrument_record!(TrackerPoint, setup);
