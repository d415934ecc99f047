//! Ballbar lengths (`q1,q2,q3,h1,h2,length`).

use super::{ExternalData, ExternalPose, ExternalRow, Row, instrument_record};
use crate::DataError;

/// One reading of a ballbar between the tool-tip ball and a pivot on the table.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BallbarReading {
    /// Where the machine stood.
    pub pose: ExternalPose,
    /// The bar's reading: the ball-to-pivot distance, mm.
    pub length_mm: f64,
    /// Standard deviation of the reading, um (`None`: the default).
    pub sigma_um: Option<f64>,
    /// Pivot mounting, from 1.
    pub setup: u32,
    /// Structure temperature, °C.
    pub temp_c: Option<f64>,
    /// Line in the file (0 if none).
    pub line: u64,
}

/// Readings of a ballbar.
pub type BallbarData = ExternalData<BallbarReading>;

/// Plausible ballbar lengths, mm.
const BALLBAR_LENGTH_MM: (f64, f64) = (10.0, 2000.0);

impl ExternalRow for BallbarReading {
    const MEASURED: &'static [&'static str] = &["length"];
    const OPTIONAL: &'static [&'static str] = &["sigma_um", "setup", "temp_c"];

    fn from_row(pose: ExternalPose, row: &Row<'_>) -> Result<Self, DataError> {
        let length_mm = row.measured(0)?;
        if !(BALLBAR_LENGTH_MM.0..=BALLBAR_LENGTH_MM.1).contains(&length_mm) {
            return Err(row.bad(
                row.measured_column(0),
                "a ballbar length must be 10-2000 mm (um or m?)",
            ));
        }
        Ok(BallbarReading {
            length_mm,
            ..BallbarReading::with_reading(row.reading(pose)?)
        })
    }

    fn own_value(&self, column: &str) -> Option<f64> {
        (column == "length").then_some(self.length_mm)
    }
}

instrument_record!(BallbarReading, setup);
