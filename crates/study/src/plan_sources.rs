//! The steps of `tricept plan` around [`crate::plan::plan`]: an
//! instrument's candidate measurements and the nominal source they make
//! ([`tracker_source`], [`ballbar_source`], [`touch_source`]), the planned
//! poses of a selection as records to write ([`planned_poses`]), and the
//! poses of a planned check as the CSV an operator drives
//! ([`check_poses_csv`]).

use nalgebra::Vector3;
use tricept_data::{
    external::ExternalPose, external::Feature, external::Features, external::PlannedPose,
    external::Stylus,
};
use tricept_engine::fusion::{
    BallbarOptions, FusedModel, Source, TouchOptions, TrackerOptions, head_angle_poses,
};
use tricept_kinematics::{KinematicsError, Machine};

use crate::StudyError;
use crate::plan::{
    nominal_ballbar_data, nominal_touch_data, nominal_tracker_data, with_extensions,
};

/// A candidate pose and its target's extension along the tool, mm.
pub type Candidate = (ExternalPose, f64);

/// A tracker's candidates: every platform point in `points_mm` at every
/// pair of head angles (`h1_deg` x `h2_deg`) and every extension along the
/// tool, and the nominal source they make.
pub fn tracker_source(
    model: &FusedModel,
    m: &Machine,
    points_mm: &[Vector3<f64>],
    (h1_deg, h2_deg): (&[f64], &[f64]),
    extensions_mm: &[f64],
    options: &TrackerOptions,
) -> Result<(Vec<Candidate>, Source), StudyError> {
    let poses = with_extensions(
        &head_angle_poses(m, points_mm, h1_deg, h2_deg),
        extensions_mm,
    );
    let data = nominal_tracker_data(model, &poses)?;
    let source = Source::tracker(&data, options)?;
    Ok((poses, source))
}

/// The nominal source of a ballbar pivoting about `pivot_mm` at `poses`.
pub fn ballbar_source(
    model: &FusedModel,
    poses: &[ExternalPose],
    pivot_mm: &Vector3<f64>,
    options: &BallbarOptions,
) -> Result<Source, StudyError> {
    let data = nominal_ballbar_data(model, poses, pivot_mm)?;
    Ok(Source::ballbar(&data, options)?)
}

/// The features of a touch plan: one sphere (id 1) and the stylus.
fn touch_features(sphere_radius_mm: f64, stylus_radius_mm: f64, stylus_sigma_um: f64) -> Features {
    Features {
        stylus: Stylus {
            radius_mm: stylus_radius_mm,
            radius_sigma_um: stylus_sigma_um,
        },
        features: vec![Feature::Sphere {
            id: 1,
            radius_mm: sphere_radius_mm,
            radius_sigma_um: 0.5,
        }],
    }
}

/// The nominal source of touch-offs at `poses` on one reference sphere
/// (feature 1) of radius `sphere_radius_mm` with a stylus of radius
/// `stylus_radius_mm` known to `stylus_sigma_um`.
pub fn touch_source(
    poses: &[ExternalPose],
    sphere_radius_mm: f64,
    (stylus_radius_mm, stylus_sigma_um): (f64, f64),
    options: &TouchOptions,
) -> Result<Source, StudyError> {
    let data = nominal_touch_data(poses, 1)?;
    let features = touch_features(sphere_radius_mm, stylus_radius_mm, stylus_sigma_um);
    Ok(Source::touch(&data, &features, options)?)
}

/// The planned candidates `selection` of `poses` as records to write: the
/// nominal tool tip of each, a ballbar's length to `ballbar_pivot_mm`, the
/// touched feature.
pub fn planned_poses(
    model: &FusedModel,
    poses: &[Candidate],
    selection: &[usize],
    ballbar_pivot_mm: Option<Vector3<f64>>,
    touch_feature: Option<u32>,
) -> Result<Vec<PlannedPose>, StudyError> {
    let p = vec![0.0; model.len()];
    selection
        .iter()
        .map(|&c| {
            let (pose, extension_mm) = poses[c];
            let effector = tricept_model::head_errors::Effector {
                extension_mm,
                ..Default::default()
            };
            let (x, _) = model.spindle_point(&p, &pose, &effector)?;
            Ok(PlannedPose {
                pose,
                extension_mm,
                tip_mm: Some(x.into()),
                length_mm: ballbar_pivot_mm.map(|c| (x - c).norm()),
                feature: touch_feature,
                line: 0,
            })
        })
        .collect()
}

/// The poses of a planned check of the machine `name` as CSV: each
/// platform target and the nominal commands that reach it.
pub fn check_poses_csv(
    m: &Machine,
    name: &str,
    targets_mm: &[Vector3<f64>],
) -> Result<String, KinematicsError> {
    let mut records = Vec::with_capacity(targets_mm.len());
    for r in targets_mm {
        let q = m.inverse(r)?.legs_mm;
        records.push(format!(
            "{},{},{},{},{},{}",
            r.x, r.y, r.z, q[0], q[1], q[2]
        ));
    }
    Ok(format!(
        "# tricept plan, instrument check: {} poses for `{name}`; drive the machine to the commands q1,q2,q3 (mm) and log its readings\nx,y,z,q1,q2,q3\n{}\n",
        targets_mm.len(),
        records.join("\n")
    ))
}
