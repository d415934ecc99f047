//! The one table from the door's request settings to this binary's flags:
//! a library error about a setting ([`tricept_ident::Error::setting`])
//! names its request field (`tolerance_mm`); the CLI shows the flag that
//! sets it (`--tolerance-mm`).

use tricept_ident::{Error, Setting};

/// The flag that sets `setting`.
pub fn flag(setting: Setting) -> &'static str {
    match setting {
        Setting::AngleNoiseArcsec => "--angle-noise-arcsec",
        Setting::LengthNoiseUm => "--length-noise-um",
        Setting::ReadingsPerPose => "--readings-per-pose",
        Setting::Poses => "--poses",
        Setting::TruthEffect => "--truth-effect",
        Setting::Truth => "--truth",
        Setting::TrackerTarget => "--tracker-target",
        Setting::TrackerTargetSigmaUm => "--tracker-target-sigma-um",
        Setting::Tracker => "--tracker",
        Setting::Ballbar => "--ballbar",
        Setting::EvalGrid => "--eval-grid",
        Setting::EvalHeadAnglesDeg => "--eval-head-angles-deg",
        Setting::Prior => "--prior",
        Setting::WriteMachine => "--write-machine",
        Setting::WritePrior => "--write-prior",
        Setting::Force => "--force",
        Setting::ToleranceMm => "--tolerance-mm",
        Setting::Data => "--data",
        Setting::Machine => "--machine",
        Setting::Plausibility => "--plausibility",
        Setting::ToolAxisWarnArcsec => "--tool-axis-warn-arcsec",
        Setting::TrackerSigmaUm => "--tracker-sigma-um",
        Setting::BallbarBallMm => "--ballbar-ball-mm",
        Setting::BallbarSigmaUm => "--ballbar-sigma-um",
        Setting::Touch => "--touch",
        Setting::Features => "--features",
        Setting::TouchSigmaUm => "--touch-sigma-um",
        Setting::TemperatureNoise => "--temperature-noise",
        Setting::TemperatureDrift => "--temperature-drift",
        Setting::HeadErrors => "--head-errors",
        Setting::NoiseFactor => "--noise-factor",
        Setting::TouchStylusRadiusMm => "--touch-stylus-radius-mm",
        Setting::TouchStylusSigmaUm => "--touch-stylus-sigma-um",
        Setting::TouchSphereRadiusMm => "--touch-sphere-radius-mm",
        Setting::TouchSphereMm => "--touch-sphere-mm",
        Setting::SigmaUm => "--sigma-um",
        Setting::TargetUm => "--target-um",
        Setting::Passes => "--passes",
        Setting::RandomBaseline => "--random-baseline",
        Setting::Extensions => "--extensions",
        Setting::Candidates => "--candidates",
        Setting::HeadAnglesDeg => "--head-angles-deg",
        Setting::BallbarPivotMm => "--ballbar-pivot-mm",
        Setting::BallbarLengthMm => "--ballbar-length-mm",
        Setting::BallbarCandidates => "--ballbar-candidates",
        Setting::DetectUm => "--detect-um",
        Setting::Power => "--power",
        Setting::K => "--k",
        Setting::Alpha => "--alpha",
        Setting::History => "--history",
        Setting::Spacing => "--spacing",
        Setting::TableSpacing => "--table-spacing",
        Setting::PlaneZ => "--plane-z",
        Setting::Input => "--input",
        Setting::Export => "--export",
        Setting::Effects => "--effects",
        Setting::NoiseFromData => "--noise-from-data",
        Setting::Revisit => "--revisit",
        Setting::Instrument => "--instrument",
        Setting::Controller => "--controller",
        Setting::AxisNames => "--axis-names",
        Setting::MaxPoints => "--max-points",
        Setting::DetectionUnitUm => "--detection-unit-um",
        Setting::MaxIncrement => "--max-increment",
        Setting::ToleranceUm => "--tolerance-um",
        Setting::ReferenceMm => "--reference-mm",
        Setting::Out => "--out",
        // A setting newer than this table: its request field's name.
        _ => setting.name(),
    }
}

/// The error's message as the CLI shows it: the setting it is about named
/// by its flag.
pub fn message(e: &Error) -> String {
    e.message_naming(flag)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;
    use std::collections::BTreeSet;

    /// Every long flag of every verb.
    fn flags_of(c: &clap::Command, out: &mut BTreeSet<String>) {
        for a in c.get_arguments() {
            if let Some(l) = a.get_long() {
                out.insert(format!("--{l}"));
            }
        }
        for s in c.get_subcommands() {
            flags_of(s, out);
        }
    }

    #[test]
    fn every_setting_is_a_flag_of_some_verb() {
        let mut known = BTreeSet::new();
        flags_of(&crate::Cli::command(), &mut known);
        for s in Setting::ALL {
            let f = flag(*s);
            assert!(known.contains(f), "{s:?}: {f} is no flag of the CLI");
            // The flag is the request field's name, spelled as a flag.
            assert_eq!(f, format!("--{}", s.name().replace('_', "-")), "{s:?}");
        }
    }

    #[test]
    fn an_error_about_a_setting_names_its_flag() {
        let e = Error::invalid(Setting::ToleranceMm, "must be above 0, got 0").in_file("fleet");
        assert_eq!(e.message(), "fleet: tolerance_mm: must be above 0, got 0");
        assert_eq!(message(&e), "fleet: --tolerance-mm: must be above 0, got 0");
        assert_eq!(message(&Error::input("plain")), "plain");
    }
}
