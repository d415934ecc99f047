//! Families of generic terms: physically readable forms that are not
//! effects of the vocabulary, searched by the diagnosis when the vocabulary
//! leaves a misfit, with their functional forms (which the simulator's
//! effects outside the vocabulary use too).
//!
//! | name | form | a machine builder reads it as |
//! |---|---|---|
//! | `leg-periodic` | `a_i sin(2 pi q_i / P) + b_i cos(2 pi q_i / P)` per leg | ball-screw pitch error (period = lead) |
//! | `leg-polynomial` | `c1_i x_i + c2_i P2(x_i) + c3_i P3(x_i)`, `x_i` the leg's stroke over the campaign on `[-1, 1]` | mean travel deviation and travel variation of a screw, a bent guide |
//! | `leg-step` | `h_i` while leg `i`'s command is inside `[a, b]` (edges scanned; an edge at the end of the campaign's stroke: a single step) | a worn screw segment, a step of the drive |
//! | `reading-drift` | reading drifts linearly with time (or pose order) | sensor or mounting drift |
//! | `reading-temperature` | reading changes with the logged temperature | thermal drift of the sensor path |
//! | `leg-drift` | leg lengths drift linearly with time | creep, drive warm-up |
//! | `encoder-gain` | encoder reads `(1 + g) angle` | encoder scaling or interpolation fault |
//! | `scale-polynomial` | `h2 P2(x_4) + h3 P3(x_4)` on the scale | scale bending or mounting |
//! | `reading-hysteresis` | reading offset by `h/2` in the direction the sensor moved | sensor reversal error |
//!
//! Each family's [`GenericSpec`] says what it acts on, what the campaign
//! must log, its physical ranges and known aliases, and where it is
//! deployed: the leg families that are functions of the leg command alone
//! ([`GenericFamily::leg_command_entries`]: periodic, polynomial, step) as
//! per-leg compensation tables, the reading families as sensor
//! corrections (recorded, they do not move the platform), the legs'
//! drift over time recorded with the campaign's middle, not applied.

use serde::{Deserialize, Serialize};
use tricept_kinematics::up_limb::UpJoints;

use super::forms::{
    encoder_gain_error_rad, legendre_p2, legendre_p3, normalised_coordinate, periodic_extra_mm,
    segment_extra_mm,
};
use super::spec::{
    Basis, CHANNELS, CheckColumns, CheckRole, CheckWhen, Deployment, Entries, Judgement,
    KnownAlias, Measure, Needs, PlausibleRange, PlotAxes, XAxis, YAxis,
};

/// Families of generic terms: physically readable forms that are not
/// effects of the vocabulary, searched when the vocabulary leaves a misfit
/// (the table of the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GenericFamily {
    /// Leg-length error periodic in the leg length.
    LegPeriodic,
    /// Leg-length error quadratic and cubic in the leg length.
    LegPolynomial,
    /// Leg-length error constant over a segment of the leg's commands (a
    /// worn screw segment).
    LegStep,
    /// A reading drifting with time.
    ReadingDrift,
    /// A reading changing with temperature.
    ReadingTemperature,
    /// Leg lengths drifting with time.
    LegDrift,
    /// Gain error of an encoder.
    EncoderGain,
    /// Quadratic and cubic error of the linear scale.
    ScalePolynomial,
    /// Reversal error of a sensor.
    ReadingHysteresis,
}

/// What the registry says about a generic family.
#[derive(Debug, Clone, Copy)]
pub struct GenericSpec {
    /// The report name (`leg-periodic`).
    pub name: &'static str,
    /// Whether its terms change leg lengths (else readings).
    pub acts_on_legs: bool,
    /// What the campaign must log for it to be seen.
    pub needs: Needs,
    /// Its physical ranges, each for the reading channel given (`None`:
    /// any), in the order its quantities are judged.
    pub ranges: &'static [(Option<usize>, PlausibleRange)],
    /// Causes it is known to be confused with.
    pub aliases: &'static [KnownAlias],
    /// Where a fitted term goes in a machine file.
    pub deployment: Deployment,
    /// Whether `tricept check` considers it a candidate change, and how.
    pub check: Option<CheckRole>,
}

const fn range(
    quantity: &'static str,
    min: f64,
    max: f64,
    unit: &'static str,
    why: &'static str,
) -> PlausibleRange {
    PlausibleRange {
        quantity,
        min,
        max,
        unit,
        why,
        if_negated: "",
    }
}

const DRIFT: &str = "beyond: a sensor fault, not a drift";
const MOUNT: &str = "thermal bending of a sensor mount";

impl GenericFamily {
    /// Every family, in the order of the table.
    pub const ALL: [GenericFamily; 9] = [
        GenericFamily::LegPeriodic,
        GenericFamily::LegPolynomial,
        GenericFamily::LegStep,
        GenericFamily::ReadingDrift,
        GenericFamily::ReadingTemperature,
        GenericFamily::LegDrift,
        GenericFamily::EncoderGain,
        GenericFamily::ScalePolynomial,
        GenericFamily::ReadingHysteresis,
    ];

    /// What the registry says about the family.
    pub fn spec(self) -> &'static GenericSpec {
        use GenericFamily as G;
        const fn spec(
            name: &'static str,
            acts_on_legs: bool,
            needs: Needs,
            ranges: &'static [(Option<usize>, PlausibleRange)],
        ) -> GenericSpec {
            GenericSpec {
                name,
                acts_on_legs,
                needs,
                ranges,
                aliases: &[],
                check: None,
                deployment: if !acts_on_legs {
                    Deployment::Sensor
                } else if matches!(needs, Needs::PoseOrder) {
                    Deployment::Recorded
                } else {
                    Deployment::LegTable
                },
            }
        }
        const LEG_PERIODIC: GenericSpec = spec(
            "leg-periodic",
            true,
            Needs::Nothing,
            &[
                (
                    None,
                    range(
                        "amplitude_um",
                        0.0,
                        25.0,
                        "um",
                        "pitch errors of precision screws",
                    ),
                ),
                (None, range("period_mm", 1.0, 200.0, "mm", "a screw lead")),
            ],
        );
        const LEG_POLYNOMIAL: GenericSpec = spec(
            "leg-polynomial",
            true,
            Needs::LegStrokes,
            &[(
                None,
                range(
                    "peak_to_valley_um",
                    0.0,
                    50.0,
                    "um",
                    "travel variation of transport-grade screws",
                ),
            )],
        );
        const LEG_STEP: GenericSpec = spec(
            "leg-step",
            true,
            Needs::LegStrokes,
            &[(
                None,
                range(
                    "step_um",
                    -25.0,
                    25.0,
                    "um",
                    "a worn or damaged screw segment (beyond: a crash or a slipped coupling, not wear)",
                ),
            )],
        );
        const READING_DRIFT: GenericSpec = GenericSpec {
            aliases: &[KnownAlias {
                with: "leg-drift",
                why: "a drifting scale and uniformly growing legs move the readings alike",
                separate_by: "an external reading of the platform at a repeated pose (dial indicator or touch probe): the machine's own sensors cannot tell a drifting scale from growing legs",
                structural: None,
            }],
            ..spec(
                "reading-drift",
                false,
                Needs::PoseOrder,
                &[
                    (Some(0), range("phi_arcsec", -30.0, 30.0, "arcsec", DRIFT)),
                    (Some(1), range("theta_arcsec", -30.0, 30.0, "arcsec", DRIFT)),
                    (Some(2), range("s_um", -50.0, 50.0, "um", DRIFT)),
                ],
            )
        };
        const READING_TEMPERATURE: GenericSpec = spec(
            "reading-temperature",
            false,
            Needs::Temperature,
            &[
                (
                    Some(0),
                    range("phi_arcsec_per_k", -10.0, 10.0, "arcsec/K", MOUNT),
                ),
                (
                    Some(1),
                    range("theta_arcsec_per_k", -10.0, 10.0, "arcsec/K", MOUNT),
                ),
                (
                    Some(2),
                    range("s_um_per_k", -20.0, 20.0, "um/K", "a 2 m steel path"),
                ),
            ],
        );
        const LEG_DRIFT: GenericSpec = spec(
            "leg-drift",
            true,
            Needs::PoseOrder,
            &[(
                None,
                range(
                    "leg_um",
                    -50.0,
                    50.0,
                    "um",
                    "creep or drive warm-up over a campaign",
                ),
            )],
        );
        const ENCODER_GAIN: GenericSpec = GenericSpec {
            check: Some(CheckRole {
                name: "encoder gains",
                parameters: &["phi_gain_ppm", "theta_gain_ppm"],
                when: CheckWhen::Always,
                columns: CheckColumns::Readings(encoder_gain_entries),
            }),
            ..spec(
                "encoder-gain",
                false,
                Needs::Nothing,
                &[(
                    None,
                    range(
                        "gain_ppm",
                        -1000.0,
                        1000.0,
                        "ppm",
                        "encoder scaling or interpolation faults",
                    ),
                )],
            )
        };
        const SCALE_POLYNOMIAL: GenericSpec = spec(
            "scale-polynomial",
            false,
            Needs::ScaleStroke,
            &[(
                None,
                range(
                    "peak_to_valley_um",
                    0.0,
                    20.0,
                    "um",
                    "scale bending or mounting",
                ),
            )],
        );
        const READING_HYSTERESIS: GenericSpec = spec(
            "reading-hysteresis",
            false,
            Needs::SensorDirections,
            &[
                (
                    Some(0),
                    range(
                        "phi_arcsec",
                        0.0,
                        5.0,
                        "arcsec",
                        "encoder reversal error (lag)",
                    ),
                ),
                (
                    Some(1),
                    range(
                        "theta_arcsec",
                        0.0,
                        5.0,
                        "arcsec",
                        "encoder reversal error (lag)",
                    ),
                ),
                (
                    Some(2),
                    range("s_um", 0.0, 2.0, "um", "scale reversal error (lag)"),
                ),
            ],
        );
        match self {
            G::LegPeriodic => &LEG_PERIODIC,
            G::LegPolynomial => &LEG_POLYNOMIAL,
            G::LegStep => &LEG_STEP,
            G::ReadingDrift => &READING_DRIFT,
            G::ReadingTemperature => &READING_TEMPERATURE,
            G::LegDrift => &LEG_DRIFT,
            G::EncoderGain => &ENCODER_GAIN,
            G::ScalePolynomial => &SCALE_POLYNOMIAL,
            G::ReadingHysteresis => &READING_HYSTERESIS,
        }
    }

    /// The report name (`leg-periodic`, ...).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::GenericFamily;
assert_eq!(GenericFamily::LegPeriodic.as_str(), "leg-periodic");
assert_eq!("encoder-gain".parse(), Ok(GenericFamily::EncoderGain));
```
"#
    )]
    pub fn as_str(self) -> &'static str {
        self.spec().name
    }

    /// The judged quantities of a term of this family on `legs` (0-2) or
    /// `channel`, with `period_mm` for a periodic term: the parameters are
    /// those of the term in order (per leg: sine and cosine of a periodic
    /// term, `P1`, `P2`, `P3` of a polynomial, one step, one drift).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::{GenericFamily, Measure};
let j = GenericFamily::LegPeriodic.judgements(&[0, 2], None, Some(10.0));
assert_eq!(j.len(), 3);
assert_eq!(j[1].label, "periodic amplitude of leg 3");
assert_eq!(j[1].measure, Measure::Amplitude(2, 3));
assert_eq!(j[2].measure, Measure::Exact(10.0));
```
"#
    )]
    pub fn judgements(
        self,
        legs: &[usize],
        channel: Option<usize>,
        period_mm: Option<f64>,
    ) -> Vec<Judgement> {
        use GenericFamily as G;
        let ranges = self.spec().ranges;
        let first = ranges[0].1;
        let judged = |range: PlausibleRange, measure: Measure, label: String| Judgement {
            range,
            measure,
            label,
        };
        let ch = CHANNELS[channel.unwrap_or(0).min(2)];
        match self {
            G::LegPeriodic => {
                let mut out: Vec<Judgement> = legs
                    .iter()
                    .enumerate()
                    .map(|(k, leg)| {
                        judged(
                            first,
                            Measure::Amplitude(2 * k, 2 * k + 1),
                            format!("periodic amplitude of leg {}", leg + 1),
                        )
                    })
                    .collect();
                if let (Some(p), Some((_, period))) = (period_mm, ranges.get(1)) {
                    out.push(judged(*period, Measure::Exact(p), "period".into()));
                }
                out
            }
            // The curvature coefficients (P2, P3) of a polynomial follow
            // its linear part (P1, a lead: judged by the leads' range
            // through the peak-to-valley of the curvature only).
            G::LegPolynomial => legs
                .iter()
                .enumerate()
                .map(|(k, leg)| {
                    judged(
                        first,
                        Measure::PeakToValley(3 * k + 1, 3 * k + 2),
                        format!("peak-to-valley of leg {}'s polynomial error", leg + 1),
                    )
                })
                .collect(),
            // One judged parameter per leg: a step's height, a drift.
            G::LegStep | G::LegDrift => legs
                .iter()
                .enumerate()
                .map(|(k, leg)| {
                    let label = if self == G::LegStep {
                        format!("step of leg {} over its segment", leg + 1)
                    } else {
                        format!("drift of leg {} over the campaign", leg + 1)
                    };
                    judged(first, Measure::Parameter(k), label)
                })
                .collect(),
            G::ScalePolynomial => vec![judged(
                first,
                Measure::PeakToValley(0, 1),
                "peak-to-valley of the scale's polynomial error".into(),
            )],
            G::EncoderGain => vec![judged(
                first,
                Measure::Parameter(0),
                format!("gain error of the {ch} encoder"),
            )],
            G::ReadingDrift | G::ReadingTemperature | G::ReadingHysteresis => ranges
                .iter()
                .filter(|(c, _)| *c == channel)
                .map(|(_, r)| {
                    judged(
                        *r,
                        Measure::Parameter(0),
                        format!("{} {}", self.as_str(), r.quantity),
                    )
                })
                .collect(),
        }
    }

    /// The residual plot of a term of this family, for its first leg or
    /// its channel.
    pub fn plot(self, leg: usize, channel: usize) -> PlotAxes {
        use GenericFamily as G;
        let (x, y) = match self {
            G::LegPeriodic => (XAxis::LegCommandModuloPeriod(leg), YAxis::LegResidual(leg)),
            G::LegPolynomial | G::LegStep => (XAxis::LegCommand(leg), YAxis::LegResidual(leg)),
            G::LegDrift => (XAxis::Order, YAxis::LegResidual(leg)),
            G::ReadingTemperature => (XAxis::Temperature, YAxis::Reading(channel)),
            G::EncoderGain => (XAxis::Angle(channel), YAxis::Reading(channel)),
            G::ScalePolynomial => (XAxis::Extension, YAxis::Reading(2)),
            G::ReadingDrift | G::ReadingHysteresis => (XAxis::Order, YAxis::Reading(channel)),
        };
        PlotAxes { x, y }
    }

    /// Per unit of each parameter of a leg term of this family on one leg
    /// (in order), the length it adds (mm) at leg command `command_mm`,
    /// for the families that are functions of the leg command alone: a
    /// periodic term of period `period_mm`, a polynomial over the stroke
    /// `stroke_mm` (`[lo, hi]`, normalised onto `[-1, 1]`), a step over the
    /// segment `edges_mm` (`[a, b]`, both included; zero without edges).
    /// `None` for the other families (a drift depends on time).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_model::effects::GenericFamily;
let v = GenericFamily::LegPeriodic.leg_command_entries(700.0, Some(10.0), None, [600.0, 900.0]).unwrap();
assert!((v[1] - 1e-3).abs() < 1e-12); // cos(2 pi 700 / 10) = 1, per um
let step = |q| GenericFamily::LegStep.leg_command_entries(q, None, Some([720.0, 960.0]), [600.0, 1000.0]).unwrap();
assert_eq!((step(700.0)[0], step(800.0)[0]), (0.0, 1e-3));
assert!(GenericFamily::LegDrift.leg_command_entries(700.0, None, None, [600.0, 900.0]).is_none());
```
"#
    )]
    pub fn leg_command_entries(
        self,
        command_mm: f64,
        period_mm: Option<f64>,
        edges_mm: Option<[f64; 2]>,
        stroke_mm: [f64; 2],
    ) -> Option<Vec<f64>> {
        use GenericFamily as G;
        match self {
            G::LegPeriodic => {
                let period = period_mm.unwrap_or(f64::INFINITY);
                Some(vec![
                    periodic_extra_mm(1.0, 0.0, period, command_mm),
                    periodic_extra_mm(0.0, 1.0, period, command_mm),
                ])
            }
            G::LegPolynomial => {
                let [lo, hi] = stroke_mm;
                let x = normalised_coordinate(command_mm, lo, hi);
                Some(vec![1e-3 * x, 1e-3 * legendre_p2(x), 1e-3 * legendre_p3(x)])
            }
            G::LegStep => {
                Some(vec![edges_mm.map_or(0.0, |[a, b]| {
                    segment_extra_mm(1.0, a, b, command_mm)
                })])
            }
            G::LegDrift
            | G::ReadingDrift
            | G::ReadingTemperature
            | G::EncoderGain
            | G::ScalePolynomial
            | G::ReadingHysteresis => None,
        }
    }
}

impl std::fmt::Display for GenericFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Per unit (ppm) of each encoder's gain error, its reading error with the
/// UP limb at `up` (the check's candidate `encoder gains`).
fn encoder_gain_entries(up: &UpJoints) -> Entries {
    vec![
        (
            0,
            Basis::Reading(0),
            encoder_gain_error_rad(1.0, up.phi_rad),
        ),
        (
            1,
            Basis::Reading(1),
            encoder_gain_error_rad(1.0, up.theta_rad),
        ),
    ]
}
