//! The typed values of the fused calibration and of the plan: where a
//! tracker's target sits, the ballbar's length uncertainty, the head model,
//! the fitted effects and the evaluation grid, each parsed by
//! [`std::str::FromStr`] (so the binary uses them as clap value parsers;
//! their messages name no flag: the caller's does), and the fused model and
//! evaluation options they build.

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use tricept_engine::fusion::{FusedModel, FusionOptions, TrackerTarget, evaluation_poses};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_model::effects::EffectName;

use crate::Setting;
use crate::error::Error;
use crate::inputs::{HeadAngles, Triple, parse_numbers, positive};
use crate::limits;

/// Where a tracker's target sits (`--tracker-target`): there is no default,
/// because the statement changes what is calibrated.
///
/// # Example
/// ```
/// use tricept_ident::advanced::TrackerTargetSpec;
/// assert_eq!("tip".parse::<TrackerTargetSpec>().unwrap(), TrackerTargetSpec::Tip);
/// assert_eq!("0,0,20".parse::<TrackerTargetSpec>().unwrap(), TrackerTargetSpec::Offset([0.0, 0.0, 20.0]));
/// assert!("1,2".parse::<TrackerTargetSpec>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackerTargetSpec {
    /// In a nest at the tool tip (a known zero offset).
    Tip,
    /// A known offset from the tip, mm, spindle frame at zero head angles.
    Offset([f64; 3]),
    /// Unknown: the tool tip is then not calibrated by the tracker.
    Free,
}

impl FromStr for TrackerTargetSpec {
    type Err = Error;

    fn from_str(text: &str) -> Result<TrackerTargetSpec, Error> {
        Ok(match text {
            "free" => TrackerTargetSpec::Free,
            "tip" => TrackerTargetSpec::Tip,
            text => {
                let v = parse_numbers(Setting::TrackerTarget.name(), text, 3).map_err(|_| {
                    Error::input(format!(
                        "expected `tip`, `free` or X,Y,Z in mm, got `{text}`"
                    ))
                })?;
                TrackerTargetSpec::Offset([v[0], v[1], v[2]])
            }
        })
    }
}

/// The error of a tracker given without a target statement.
fn target_required() -> Error {
    Error::naming(
        crate::ErrorKind::Input,
        Setting::TrackerTarget,
        " is required with a tracker: state where its target sits: `tip` (in a nest at the tool tip), `X,Y,Z` (a known offset from the tip, mm, spindle frame at zero head angles) or `free` (unknown: the tool tip is then not calibrated)".to_string(),
    )
}

impl TrackerTargetSpec {
    /// The engine's target statement, a known offset known to `sigma_um`.
    pub fn target(self, sigma_um: f64) -> Result<TrackerTarget, Error> {
        let offset_mm = match self {
            TrackerTargetSpec::Free => return Ok(TrackerTarget::Free),
            TrackerTargetSpec::Tip => [0.0; 3],
            TrackerTargetSpec::Offset(o) => o,
        };
        Ok(TrackerTarget::Known {
            offset_mm,
            sigma_um: positive(Setting::TrackerTargetSigmaUm, sigma_um)?,
        })
    }

    /// [`TrackerTargetSpec::target`] of a statement that must be given: an
    /// input error saying what to state when it is not.
    pub fn required(
        spec: Option<TrackerTargetSpec>,
        sigma_um: f64,
    ) -> Result<TrackerTarget, Error> {
        spec.ok_or_else(target_required)?.target(sigma_um)
    }
}

/// The standard deviation of the ballbar's length (its certificate), um, or
/// free (the machine's scale then stays invisible to the ballbar).
///
/// # Example
/// ```
/// use tricept_ident::advanced::LengthSigma;
/// assert_eq!("free".parse::<LengthSigma>().unwrap(), LengthSigma::Free);
/// assert_eq!("1".parse::<LengthSigma>().unwrap(), LengthSigma::Known(1.0));
/// assert!("0".parse::<LengthSigma>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LengthSigma {
    /// Free.
    Free,
    /// Known to this standard deviation, um.
    Known(f64),
}

impl FromStr for LengthSigma {
    type Err = Error;

    fn from_str(text: &str) -> Result<LengthSigma, Error> {
        match text {
            "free" => Ok(LengthSigma::Free),
            text => match text.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(LengthSigma::Known(v)),
                Ok(v) => Err(Error::input(format!("must be a positive number, got {v}"))),
                Err(_) => Err(Error::input(format!(
                    "expected a number of um or `free`, got `{text}`"
                ))),
            },
        }
    }
}

impl LengthSigma {
    /// The engine's value: `None` when free.
    pub fn sigma_um(self) -> Option<f64> {
        match self {
            LengthSigma::Free => None,
            LengthSigma::Known(v) => Some(v),
        }
    }
}

/// The head's parameters in a fused model (`--head`).
///
/// # Example
/// ```
/// use tricept_ident::advanced::HeadModel;
/// assert_eq!("none".parse::<HeadModel>().unwrap(), HeadModel::Nominal);
/// assert!("head15".parse::<HeadModel>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HeadModel {
    /// The 13 parameters of the head (`head13`, the default).
    #[default]
    Head13,
    /// The head held nominal (`none`).
    Nominal,
}

impl FromStr for HeadModel {
    type Err = Error;

    fn from_str(text: &str) -> Result<HeadModel, Error> {
        match text {
            "head13" => Ok(HeadModel::Head13),
            "none" => Ok(HeadModel::Nominal),
            other => Err(Error::input(format!(
                "expected head13 or none, got `{other}`"
            ))),
        }
    }
}

/// A comma-separated list of effect names (`--effects`), from the
/// registry's vocabulary; empty names are skipped.
///
/// # Example
/// ```
/// use tricept_ident::advanced::EffectNames;
/// let e: EffectNames = "leg-lead,".parse().unwrap();
/// assert_eq!(e.0.len(), 1);
/// assert!("gravity".parse::<EffectNames>().unwrap_err().to_string().starts_with("unknown effect `gravity`"));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct EffectNames(pub Vec<EffectName>);

impl FromStr for EffectNames {
    type Err = Error;

    fn from_str(text: &str) -> Result<EffectNames, Error> {
        text.split(',')
            .filter(|n| !n.is_empty())
            .map(|n| {
                n.parse::<EffectName>()
                    .map_err(|e| Error::input(e.to_string()))
            })
            .collect::<Result<_, _>>()
            .map(EffectNames)
    }
}

/// The evaluation grid of the predicted tool tip: platform points of
/// `polar_grid(RINGS, PER_RING, LEVELS)` (`--eval-grid`).
///
/// # Example
/// ```
/// use tricept_ident::advanced::EvalGrid;
/// assert_eq!("2,8,3".parse::<EvalGrid>().unwrap(), EvalGrid { rings: 2, per_ring: 8, levels: 3 });
/// assert!("2,8,0".parse::<EvalGrid>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EvalGrid {
    /// Rings around the axis.
    pub rings: usize,
    /// Points per ring.
    pub per_ring: usize,
    /// Levels in z.
    pub levels: usize,
}

impl Default for EvalGrid {
    fn default() -> EvalGrid {
        EvalGrid {
            rings: 2,
            per_ring: 8,
            levels: 3,
        }
    }
}

impl FromStr for EvalGrid {
    type Err = Error;

    fn from_str(text: &str) -> Result<EvalGrid, Error> {
        let bad = || {
            Error::input(format!(
                "expected whole numbers RINGS,PER_RING,LEVELS, got `{text}`"
            ))
        };
        let g = parse_numbers(Setting::EvalGrid.name(), text, 3).map_err(|_| bad())?;
        if g.iter().any(|v| *v < 0.0 || v.fract() != 0.0) || g[2] < 1.0 {
            return Err(bad());
        }
        Ok(EvalGrid {
            rings: g[0] as usize,
            per_ring: g[1] as usize,
            levels: g[2] as usize,
        })
    }
}

impl fmt::Display for EvalGrid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{}", self.rings, self.per_ring, self.levels)
    }
}

/// The fused model of `params`, `effects` and the head on `machine`.
pub fn fused_model(
    machine: &Machine,
    params: &ParameterSet,
    effects: &[EffectName],
    head: HeadModel,
) -> Result<FusedModel, Error> {
    Ok(FusedModel::new(
        machine.clone(),
        params.clone(),
        effects,
        head == HeadModel::Head13,
    )?)
}

/// The fusion options of `machine` with the evaluation poses of `grid` at
/// the head angles `angles` (at most [`limits::MAX_EVAL_POSES`], at least
/// one reachable).
pub fn eval_options(
    machine: &Machine,
    grid: EvalGrid,
    angles: &HeadAngles,
) -> Result<FusionOptions, Error> {
    let poses = (grid.rings as f64 * grid.per_ring as f64 + 1.0)
        * grid.levels as f64
        * (angles.h1_deg.len() * angles.h2_deg.len()) as f64;
    if poses > limits::MAX_EVAL_POSES as f64 {
        return Err(Error::invalid_value(
            Setting::EvalGrid,
            grid,
            format!(
                "with the evaluation head angles {} deg: {poses} evaluation poses; at most {}",
                head_angles_text(angles),
                limits::MAX_EVAL_POSES
            ),
        ));
    }
    let mut options = FusionOptions::for_machine(machine);
    options.eval_poses = evaluation_poses(
        machine,
        (grid.rings, grid.per_ring, grid.levels),
        &angles.h1_deg,
        &angles.h2_deg,
    );
    if options.eval_poses.is_empty() {
        return Err(Error::invalid(
            Setting::EvalGrid,
            "no reachable evaluation pose",
        ));
    }
    Ok(options)
}

/// `H1,H1,...:H2,H2,...` of `angles`.
pub(crate) fn head_angles_text(angles: &HeadAngles) -> String {
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(",")
    };
    format!("{}:{}", list(&angles.h1_deg), list(&angles.h2_deg))
}

/// External measurements and the head model of a fused calibration.
///
/// # Example
/// ```
/// use tricept_ident::calibrate::{CalibrateRequest, FusedSources};
/// let mut fused = FusedSources::default();
/// fused.tracker.push("tracker.csv".into());
/// let mut request = CalibrateRequest::new("campaign.csv");
/// request.fused = Some(fused);
/// assert!(request.fused.is_some());
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct FusedSources {
    /// Laser-tracker or CMM point files.
    pub tracker: Vec<PathBuf>,
    /// Standard deviation of a tracker coordinate for rows without one, um.
    pub tracker_sigma_um: f64,
    /// Where the tracker's target sits (required with a tracker).
    pub tracker_target: Option<TrackerTargetSpec>,
    /// Standard deviation of a known target offset, um.
    pub tracker_target_sigma_um: f64,
    /// Ballbar reading files.
    pub ballbar: Vec<PathBuf>,
    /// Standard deviation of a ballbar reading for rows without one, um.
    pub ballbar_sigma_um: f64,
    /// The bar length's uncertainty.
    pub ballbar_length_sigma: LengthSigma,
    /// Offset of the spindle ball from the tool tip, mm.
    pub ballbar_ball_mm: Option<Triple>,
    /// Touch-off files (need `features`).
    pub touch: Vec<PathBuf>,
    /// The features file of the touch-offs.
    pub features: Option<PathBuf>,
    /// Standard deviation of a touch for rows without one, um.
    pub touch_sigma_um: f64,
    /// The head's parameters.
    pub head: HeadModel,
    /// Effects fitted with the geometry.
    pub effects: Vec<EffectName>,
    /// Evaluation grid of the predicted tool tip.
    pub eval_grid: EvalGrid,
    /// Head angles of the evaluation grid, deg.
    pub eval_head_angles: HeadAngles,
    /// Overrides of the plausible ranges (a JSON file).
    pub plausibility: Option<PathBuf>,
    /// Warn when the predicted tool-axis uncertainty exceeds this, arcsec.
    pub tool_axis_warn_arcsec: f64,
}

impl Default for FusedSources {
    fn default() -> FusedSources {
        FusedSources {
            tracker: Vec::new(),
            tracker_sigma_um: 10.0,
            tracker_target: None,
            tracker_target_sigma_um: 5.0,
            ballbar: Vec::new(),
            ballbar_sigma_um: 1.0,
            ballbar_length_sigma: LengthSigma::Known(1.0),
            ballbar_ball_mm: None,
            touch: Vec::new(),
            features: None,
            touch_sigma_um: 1.5,
            head: HeadModel::Head13,
            effects: Vec::new(),
            eval_grid: EvalGrid::default(),
            eval_head_angles: HeadAngles {
                h1_deg: vec![0.0, 90.0, 180.0, 270.0],
                h2_deg: vec![15.0, 35.0],
            },
            plausibility: None,
            tool_axis_warn_arcsec: 30.0,
        }
    }
}
