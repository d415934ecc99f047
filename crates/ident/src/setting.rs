//! The settings of the door's requests that a message can name: an
//! [`Error`](crate::Error) about one setting carries it
//! ([`Error::setting`](crate::Error::setting)), so that a program shows it
//! in its own words (the `tricept` binary as its flag, the Python package
//! as its keyword argument) while the library's own message names the
//! request field.

use std::fmt;

macro_rules! settings {
    ($($(#[$doc:meta])* $variant:ident => $name:literal,)*) => {
        /// A setting of a request that an error can be about, named by
        /// [`Setting::name`] after the request's field (`tolerance_mm`,
        /// `alpha`, ...), which is also the Python package's keyword
        /// argument where it has one.
        ///
        /// # Example
        /// ```
        /// use tricept_ident::{Error, Setting};
        /// let e = Error::invalid(Setting::Alpha, "must lie between 0 and 0.5, got 2");
        /// assert_eq!(e.setting(), Some(Setting::Alpha));
        /// assert_eq!(e.message(), "alpha: must lie between 0 and 0.5, got 2");
        /// assert_eq!(e.message_naming(|_| "--alpha"), "--alpha: must lie between 0 and 0.5, got 2");
        /// ```
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[non_exhaustive]
        pub enum Setting {
            $($(#[$doc])* $variant,)*
        }

        impl Setting {
            /// Every setting, in declaration order.
            pub const ALL: &'static [Setting] = &[$(Setting::$variant,)*];

            /// The setting's name: the request field that holds it.
            pub fn name(self) -> &'static str {
                match self {
                    $(Setting::$variant => $name,)*
                }
            }

            /// The setting named `name` ([`Setting::name`]), if there is one.
            ///
            /// # Example
            /// ```
            /// use tricept_ident::Setting;
            /// assert_eq!(Setting::from_name("max_points"), Some(Setting::MaxPoints));
            /// assert_eq!(Setting::from_name("--max-points"), None);
            /// ```
            pub fn from_name(name: &str) -> Option<Setting> {
                match name {
                    $($name => Some(Setting::$variant),)*
                    _ => None,
                }
            }
        }
    };
}

settings! {
    /// The stated angle noise of the joint sensors (arcsec).
    AngleNoiseArcsec => "angle_noise_arcsec",
    /// The stated length noise of the leg sensors (um).
    LengthNoiseUm => "length_noise_um",
    /// The readings averaged into each logged pose.
    ReadingsPerPose => "readings_per_pose",
    /// The poses of a campaign (a spec: `grid`, `optimal:N`, ...).
    Poses => "poses",
    /// The errors of a simulated machine given as effects.
    TruthEffect => "truth_effect",
    /// The true errors of a simulated machine.
    Truth => "truth",
    /// Where a laser tracker's target sits.
    TrackerTarget => "tracker_target",
    /// The uncertainty of a stated tracker target (um).
    TrackerTargetSigmaUm => "tracker_target_sigma_um",
    /// A laser-tracker file.
    Tracker => "tracker",
    /// A ballbar file.
    Ballbar => "ballbar",
    /// The grid of the accuracy evaluation.
    EvalGrid => "eval_grid",
    /// The head angles of the accuracy evaluation (deg).
    EvalHeadAnglesDeg => "eval_head_angles_deg",
    /// A fleet prior file.
    Prior => "prior",
    /// The machine file a calibration writes.
    WriteMachine => "write_machine",
    /// The prior file a fleet writes.
    WritePrior => "write_prior",
    /// Writing a result that is not to be trusted anyway.
    Force => "force",
    /// The manufacturing tolerance (mm).
    ToleranceMm => "tolerance_mm",
    /// The campaign's data.
    Data => "data",
    /// The machine file.
    Machine => "machine",
    /// A plausibility file.
    Plausibility => "plausibility",
    /// The tool-axis accuracy above which a fit warns (arcsec).
    ToolAxisWarnArcsec => "tool_axis_warn_arcsec",
    /// The noise of a laser tracker (um).
    TrackerSigmaUm => "tracker_sigma_um",
    /// Where the ballbar's ball sits on the tool (mm).
    BallbarBallMm => "ballbar_ball_mm",
    /// The noise of a ballbar (um).
    BallbarSigmaUm => "ballbar_sigma_um",
    /// A touch-off file.
    Touch => "touch",
    /// The features a touch probe touched.
    Features => "features",
    /// The noise of a touch probe (um).
    TouchSigmaUm => "touch_sigma_um",
    /// The noise of the temperature readings (K).
    TemperatureNoise => "temperature_noise",
    /// The temperature change over a campaign (K).
    TemperatureDrift => "temperature_drift",
    /// The errors of a simulated 2-DOF head.
    HeadErrors => "head_errors",
    /// The factor on a simulation's sensor noise.
    NoiseFactor => "noise_factor",
    /// The radius of a touch probe's stylus (mm).
    TouchStylusRadiusMm => "touch_stylus_radius_mm",
    /// The uncertainty of the stylus radius (um).
    TouchStylusSigmaUm => "touch_stylus_sigma_um",
    /// The radius of a touched sphere (mm).
    TouchSphereRadiusMm => "touch_sphere_radius_mm",
    /// Where a touched sphere sits (mm).
    TouchSphereMm => "touch_sphere_mm",
    /// The noise of an external instrument (um).
    SigmaUm => "sigma_um",
    /// The accuracy a plan is to reach (um).
    TargetUm => "target_um",
    /// The passes of a plan's search.
    Passes => "passes",
    /// The random campaigns a plan is compared with.
    RandomBaseline => "random_baseline",
    /// The extensions along the tool (mm).
    Extensions => "extensions",
    /// The candidate poses of a plan.
    Candidates => "candidates",
    /// The head angles of a plan's candidates (deg).
    HeadAnglesDeg => "head_angles_deg",
    /// Where a ballbar's pivot sits (mm).
    BallbarPivotMm => "ballbar_pivot_mm",
    /// The length of a ballbar (mm).
    BallbarLengthMm => "ballbar_length_mm",
    /// The candidate ballbar placements of a plan.
    BallbarCandidates => "ballbar_candidates",
    /// The change a check is to detect (um).
    DetectUm => "detect_um",
    /// The probability of detecting that change.
    Power => "power",
    /// The measurement budget of a plan.
    K => "k",
    /// The false-alarm probability of a check.
    Alpha => "alpha",
    /// A check history file.
    History => "history",
    /// The spacing of a compensation map (mm).
    Spacing => "spacing",
    /// The spacing of a compensation table (mm).
    TableSpacing => "table_spacing",
    /// The height of a compensation map's plane (mm).
    PlaneZ => "plane_z",
    /// The input file of a batch of commands.
    Input => "input",
    /// An export folder a report shows.
    Export => "export",
    /// The effects a fit includes.
    Effects => "effects",
    /// Estimating the sensor noise from the data.
    NoiseFromData => "noise_from_data",
    /// The poses a simulation visits again.
    Revisit => "revisit",
    /// The instrument a plan is for.
    Instrument => "instrument",
    /// The control an export writes for.
    Controller => "controller",
    /// The names of an export's three axes.
    AxisNames => "axis_names",
    /// The compensation points per axis of an export.
    MaxPoints => "max_points",
    /// The detection unit of a FANUC control (um).
    DetectionUnitUm => "detection_unit_um",
    /// The largest increment between two FANUC points.
    MaxIncrement => "max_increment",
    /// The format error an export accepts (um).
    ToleranceUm => "tolerance_um",
    /// The legs' reference points of an export (mm).
    ReferenceMm => "reference_mm",
    /// The folder an export writes.
    Out => "out",
}

impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
