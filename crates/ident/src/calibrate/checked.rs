//! A calibration request checked once, before any fit: the tolerance, the
//! machine, the data, and for a fused calibration its model, its options
//! and every instrument's noise and files' companions (`calibrate`'s
//! `check` makes them). The internal, pooled and fused fits take the one
//! [`Checked`] type and the work it holds ([`Work`]), and check nothing of
//! the request again.

use std::path::PathBuf;

use tricept_data::{Dataset, external::Features};
use tricept_engine::fusion::{
    BallbarOptions, FusedModel, FusionOptions, FusionPlausibility, TouchOptions, TrackerOptions,
    TrackerTarget,
};
use tricept_model::ParameterSet;

use super::values::{FusedSources, HeadModel, TrackerTargetSpec, eval_options, fused_model};
use crate::Setting;
use crate::error::Error;
use crate::inputs::{LoadedMachine, positive};
use crate::limits;

/// What every fit of a checked request shares.
#[derive(Debug)]
pub(crate) struct Checked {
    /// The machine, loaded.
    pub loaded: LoadedMachine,
    /// The geometric parameters to identify.
    pub set: ParameterSet,
    /// Reject poses with a gross reading error.
    pub robust: bool,
    /// Manufacturing tolerance of each geometric parameter, mm (checked:
    /// above 0, at most 10).
    pub tolerance_mm: f64,
}

/// The fit a checked request asks for.
#[derive(Debug)]
pub(crate) enum Work {
    /// One campaign of internal data.
    Internal(Dataset),
    /// Several campaigns, a batch's prior, or both.
    Pooled {
        /// The campaigns, loaded.
        datasets: Vec<Dataset>,
        /// The batch's prior file.
        prior: Option<PathBuf>,
    },
    /// Internal data fused with external measurements.
    Fused(Box<FusedWork>),
}

/// A fused calibration, checked: the internal data, the model, the
/// options and the external sources' settings.
#[derive(Debug)]
pub(crate) struct FusedWork {
    /// The internal data.
    pub data: Dataset,
    /// The fused model (with the rank rule of a calibrated machine).
    pub model: FusedModel,
    /// The head's parameters (of the richer model that checks the fit).
    pub head: HeadModel,
    /// The fusion options.
    pub options: FusionOptions,
    /// Tracker files and their settings.
    pub tracker: (Vec<PathBuf>, TrackerOptions),
    /// Ballbar files and their settings.
    pub ballbar: (Vec<PathBuf>, BallbarOptions),
    /// Touch-off files, the features touched and their settings.
    pub touch: Option<(Vec<PathBuf>, Features, TouchOptions)>,
}

/// Checks a fused calibration's settings `x`; `for_machine_file` refuses
/// up front fitted effects, which the machine format cannot carry.
pub(crate) fn fused(
    c: &Checked,
    data: Dataset,
    x: &FusedSources,
    for_machine_file: bool,
) -> Result<FusedWork, Error> {
    let machine = c.loaded.machine();
    if x.tracker.is_empty() && x.tracker_target.is_some() {
        return Err(Error::invalid(
            Setting::TrackerTarget,
            "there is no tracker file to state the target of",
        ));
    }
    let mut model = fused_model(machine, &c.set, &x.effects, x.head)?;
    if for_machine_file && !model.effects().is_empty() {
        let names: Vec<&str> = model.effects().iter().map(|e| e.as_str()).collect();
        return Err(Error::invalid(
            Setting::WriteMachine,
            format!(
                "{} fitted, but the machine format cannot carry {}; write a geometric fit (without effects) or compensate with the fused model",
                names.join(", "),
                if names.len() == 1 { "it" } else { "them" }
            ),
        ));
    }
    // A calibrated machine: the rank decision of its nominal machine, as in
    // the internal calibration (docs/identifiability.md).
    if let Some(reference) = c.loaded.rank_reference()? {
        model = model.with_rank_reference(reference)?;
    }
    let mut options = eval_options(machine, x.eval_grid, &x.eval_head_angles)?;
    if !c.robust {
        options.screen = None;
    }
    if let Some(path) = &x.plausibility {
        let text = tricept_data::bounded::read_json_text(path)
            .map_err(|e| Error::unreadable(path.display(), e).in_setting(Setting::Plausibility))?;
        options.plausibility = FusionPlausibility::with_overrides(&text)
            .map_err(|e| Error::invalid_value(Setting::Plausibility, path.display(), e))?;
    }
    options.tool_axis_arcsec = positive(Setting::ToolAxisWarnArcsec, x.tool_axis_warn_arcsec)?;
    let target = if x.tracker.is_empty() {
        TrackerTarget::Free
    } else {
        TrackerTargetSpec::required(x.tracker_target, x.tracker_target_sigma_um)?
    };
    let tracker = TrackerOptions {
        sigma_um: positive(Setting::TrackerSigmaUm, x.tracker_sigma_um)?,
        target,
    };
    let ball = match x.ballbar_ball_mm {
        Some(t) => {
            if let Some(v) = t.0.iter().find(|v| v.abs() > limits::MAX_TOOL_OFFSET_MM) {
                return Err(Error::invalid(
                    Setting::BallbarBallMm,
                    format!(
                        "{v} mm is beyond ±{} mm from the tool tip",
                        limits::MAX_TOOL_OFFSET_MM
                    ),
                ));
            }
            t.0
        }
        None => [0.0; 3],
    };
    let ballbar = BallbarOptions {
        sigma_um: positive(Setting::BallbarSigmaUm, x.ballbar_sigma_um)?,
        length_sigma_um: x.ballbar_length_sigma.sigma_um(),
        ball_offset_mm: ball,
    };
    let touch = if x.touch.is_empty() {
        None
    } else {
        let Some(features) = &x.features else {
            return Err(Error::invalid(
                Setting::Features,
                "needed with touch-off files: the spheres and planes touched (a JSON file)",
            ));
        };
        let features = Features::from_path(features)?;
        let options = TouchOptions {
            sigma_um: positive(Setting::TouchSigmaUm, x.touch_sigma_um)?,
        };
        Some((x.touch.clone(), features, options))
    };
    Ok(FusedWork {
        data,
        model,
        head: x.head,
        options,
        tracker: (x.tracker.clone(), tracker),
        ballbar: (x.ballbar.clone(), ballbar),
        touch,
    })
}
