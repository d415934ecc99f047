//! What every control's writer starts from ([`Setup`]: the legs'
//! corrections, the axis names, the controller parameters, the options)
//! and what each hands back ([`ControlFiles`]: its files, its axes, the
//! parameters to set, the limits past the tolerance, and how each axis
//! leaves its leg): the seam between `plan`'s shared steps and the
//! per-control writers.

use tricept_kinematics::description::ControllerDescription;

use crate::correction::LegCorrection;
use crate::types::{AxisSummary, ExportOptions};

/// The inputs of a control's writer.
pub(crate) struct Setup<'a> {
    /// The three legs' exact corrections over their strokes.
    pub legs: [LegCorrection; 3],
    /// The control's axis names of the three legs.
    pub names: [String; 3],
    /// The calibrated legs' offsets, mm (`leg_offsets_mm`).
    pub leg_offsets_mm: [f64; 3],
    /// The machine file's controller parameters.
    pub params: ControllerDescription,
    /// Each leg's backlash, mm.
    pub backlash_mm: [f64; 3],
    /// The options.
    pub options: &'a ExportOptions,
    /// The most points one axis takes.
    pub max_points: usize,
}

/// A leg's length as the control leaves it at a command, minus the exact
/// one, mm.
pub(crate) type Deviation = crate::correction::LegDeviation;

/// What a control's writer hands back.
pub(crate) struct ControlFiles {
    /// File name and text of each of the control's files.
    pub files: Vec<(String, String)>,
    /// The leg axes.
    pub axes: Vec<AxisSummary>,
    /// Parameters to set, one line each.
    pub parameters: Vec<String>,
    /// The limits past the tolerance or the control's ranges.
    pub limits: Vec<String>,
    /// Whether the files carry the legs' thermal growth.
    pub carries_thermal: bool,
    /// Per reading the control may make of the files (one for a linear
    /// table; two for a Fanuc staircase), each axis' deviation.
    pub readings: Vec<[Deviation; 3]>,
}

impl Setup<'_> {
    /// Axis `i`'s summary: `points` every `step_mm` from `min_mm` to
    /// `max_mm`, its format error, and the constant `shift_mm` the table
    /// took out (into the leg's zero).
    #[allow(clippy::too_many_arguments)]
    pub fn axis_summary(
        &self,
        i: usize,
        points: usize,
        step_mm: f64,
        (min_mm, max_mm): (f64, f64),
        format_error_um: f64,
        shift_mm: f64,
    ) -> AxisSummary {
        let l = &self.legs[i];
        let offset = l.extra_mm(l.reference_mm) + shift_mm;
        AxisSummary {
            leg: i as u8 + 1,
            axis: self.names[i].clone(),
            points,
            step_mm,
            min_mm,
            max_mm,
            format_error_um,
            reference_mm: l.reference_mm,
            offset_mm: offset,
            zero_mm: self.leg_offsets_mm[i] + offset - 0.5 * self.backlash_mm[i],
        }
    }
}
