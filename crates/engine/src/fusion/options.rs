//! The settings of the fused identification ([`FusionOptions`], with its
//! gross-error screen's [`ScreenOptions`]) and the tool poses it evaluates
//! its predictions over.

use tricept_data::external::ExternalPose;
use tricept_kinematics::Machine;
use tricept_numerics::lsq::DEFAULT_RANK_TOLERANCE;

use crate::fusion::plausibility::FusionPlausibility;

/// Settings of [`identify_fused`](crate::fusion::identify_fused).
///
/// # Example
/// ```
/// use tricept_engine::fusion::FusionOptions;
/// let o = FusionOptions::for_machine(&tricept_kinematics::Machine::paper());
/// // 51 platform points x 4 x 2 head angle pairs.
/// assert_eq!(o.eval_poses.len(), 408);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FusionOptions {
    /// Relative singular-value tolerance of the rank decision.
    pub rank_tolerance: f64,
    /// `s_i / s_1` below which an identifiable direction is reported weak.
    pub weak_threshold: f64,
    /// Gauss-Newton iteration limit.
    pub max_iterations: u32,
    /// Tool poses over which the tool tip's predicted uncertainty and the
    /// tip impact of weak combinations are reported.
    pub eval_poses: Vec<ExternalPose>,
    /// A weak or invisible combination that moves the tool tip, after
    /// touch-off, by less than this per standard deviation (per unit
    /// coefficient when invisible) is reported as nearly harmless, um.
    pub harmless_um: f64,
    /// The gross-error screen of every source's records (`None`: every
    /// record is fitted).
    pub screen: Option<ScreenOptions>,
    /// Plausible ranges of the estimates.
    pub plausibility: FusionPlausibility,
    /// A predicted tool-axis uncertainty (RMS over the evaluation poses)
    /// above this is warned about, arcsec.
    pub tool_axis_arcsec: f64,
    /// Whether an implausible or unexplained fit is refitted with the
    /// usual mistakes undone to name the likely cause.
    pub likely_causes: bool,
}

impl FusionOptions {
    /// Defaults: the rank tolerance and weak threshold of
    /// [`crate::IdentifyOptions`], 30 iterations, 5 um, the screen at
    /// family-wise level 0.001 (at most 10 % of a source's records), the
    /// default plausibility table, 30 arcsec for the tool axis, the
    /// likely-cause search, and the evaluation
    /// grid [`evaluation_poses`] with 2 rings of 8 on 3 levels and head
    /// angles `h1` in {0, 90, 180, 270} deg, `h2` in {15, 35} deg (away
    /// from the head singularity at `h2 = 0`, where a calibrated head may
    /// not point exactly along its first axis).
    pub fn for_machine(machine: &Machine) -> FusionOptions {
        FusionOptions {
            rank_tolerance: DEFAULT_RANK_TOLERANCE,
            weak_threshold: 1e-2,
            max_iterations: 30,
            eval_poses: evaluation_poses(
                machine,
                (2, 8, 3),
                &[0.0, 90.0, 180.0, 270.0],
                &[15.0, 35.0],
            ),
            harmless_um: 5.0,
            screen: Some(ScreenOptions::default()),
            plausibility: FusionPlausibility::default(),
            tool_axis_arcsec: 30.0,
            likely_causes: true,
        }
    }
}

/// Tool poses for evaluation: the platform points of the workspace's
/// `polar_grid(rings, per_ring, levels)` with every pair of head angles from
/// `h1_deg` x `h2_deg` ([`head_angle_poses`]).
pub fn evaluation_poses(
    machine: &Machine,
    (rings, per_ring, levels): (usize, usize, usize),
    h1_deg: &[f64],
    h2_deg: &[f64],
) -> Vec<ExternalPose> {
    let points = machine.workspace.polar_grid(rings, per_ring, levels);
    head_angle_poses(machine, &points, h1_deg, h2_deg)
}

/// Each platform point (commanded by the nominal IK) with each pair of head
/// angles from `h1_deg` x `h2_deg` (degrees): evaluation poses, tracker
/// candidates. Points the IK cannot reach are left out.
///
/// # Example
/// ```
/// use tricept_engine::fusion::head_angle_poses;
/// let m = tricept_kinematics::Machine::paper();
/// let poses = head_angle_poses(&m, &[nalgebra::Vector3::new(0.0, 0.0, 750.0)], &[0.0, 90.0], &[30.0]);
/// assert_eq!(poses.len(), 2);
/// assert!((poses[1].head_rad[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn head_angle_poses(
    machine: &Machine,
    platform_mm: &[nalgebra::Vector3<f64>],
    h1_deg: &[f64],
    h2_deg: &[f64],
) -> Vec<ExternalPose> {
    let mut out = Vec::new();
    for r in platform_mm {
        let Ok(ik) = machine.inverse(r) else {
            continue;
        };
        for h1 in h1_deg {
            for h2 in h2_deg {
                out.push(ExternalPose {
                    commands_mm: ik.legs_mm,
                    head_rad: [h1.to_radians(), h2.to_radians()],
                });
            }
        }
    }
    out
}

/// Settings of the gross-error screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenOptions {
    /// Family-wise level of the test per source.
    pub alpha: f64,
    /// Largest share of a source's records that may be rejected.
    pub max_share: f64,
}

impl Default for ScreenOptions {
    /// Level 0.001, at most 10 % of the records (as `identify`).
    fn default() -> Self {
        ScreenOptions {
            alpha: 1e-3,
            max_share: 0.1,
        }
    }
}
