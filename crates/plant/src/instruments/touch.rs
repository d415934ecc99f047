//! A touch probe on reference spheres and planes.

use nalgebra::Vector3;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;
use tricept_data::{
    external::ExternalPose, external::Feature, external::Features, external::Stylus,
    external::TouchData, external::TouchReading,
};
use tricept_model::head_errors::Effector;

use super::{commanded, kinematics_error, measure_each};
use crate::{Plant, PlantError};
use tricept_kinematics::Machine;

/// Tag mixed into the seed, so that instruments measuring with the same
/// seed draw independent noise.
const TOUCH_TAG: u64 = 0x70c4_0ff0;

/// A reference feature as it truly is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TouchFeature {
    /// A sphere.
    Sphere {
        /// Id in the features file.
        id: u32,
        /// Centre, base frame, mm.
        centre_mm: Vector3<f64>,
        /// Radius, mm.
        radius_mm: f64,
    },
    /// A plane `normal . x = offset_mm` (unit normal pointing out of the
    /// material, towards the probe).
    Plane {
        /// Id in the features file.
        id: u32,
        /// Unit normal.
        normal: Vector3<f64>,
        /// Distance of the plane from the origin along the normal, mm.
        offset_mm: f64,
    },
}

impl TouchFeature {
    fn id(&self) -> u32 {
        match self {
            TouchFeature::Sphere { id, .. } | TouchFeature::Plane { id, .. } => *id,
        }
    }

    /// Signed distance of a stylus centre `x` with radius `r` from contact
    /// (positive: not yet touching).
    fn clearance(&self, x: &Vector3<f64>, r: f64) -> f64 {
        match self {
            TouchFeature::Sphere {
                centre_mm,
                radius_mm,
                ..
            } => (x - centre_mm).norm() - radius_mm - r,
            TouchFeature::Plane {
                normal, offset_mm, ..
            } => normal.dot(x) - offset_mm - r,
        }
    }
}

/// Where and how to touch: the stylus centre at nominal contact, the tool
/// axis, and the direction of the probing motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TouchTarget {
    /// Feature id.
    pub feature: u32,
    /// Nominal stylus-centre position at contact, mm.
    pub tip_mm: Vector3<f64>,
    /// Tool axis (any length).
    pub axis: Vector3<f64>,
    /// Unit direction of the probing motion (into the surface).
    pub approach: Vector3<f64>,
}

/// A touch probe in the spindle and the features it touches.
#[derive(Debug, Clone, PartialEq)]
pub struct TouchProbe {
    /// Nominal effective stylus radius, mm (written to the features file).
    pub stylus_radius_mm: f64,
    /// Its true value minus the nominal one, um.
    pub stylus_radius_error_um: f64,
    /// Standard deviation of the stylus radius written to the features file, um.
    pub stylus_radius_sigma_um: f64,
    /// Standard deviation of a touch along the surface normal (trigger
    /// repeatability), um.
    pub sigma_um: f64,
    /// The true features.
    pub features: Vec<TouchFeature>,
}

/// How far before and beyond the nominal contact the probing motion runs, mm.
const PROBING_STROKE_MM: f64 = 10.0;

impl TouchProbe {
    /// The features file a user would write: sphere radii and the stylus
    /// radius as nominal values with their standard deviations (um).
    pub fn features_file(&self, sphere_radius_sigma_um: f64) -> Features {
        Features {
            stylus: Stylus {
                radius_mm: self.stylus_radius_mm,
                radius_sigma_um: self.stylus_radius_sigma_um,
            },
            features: self
                .features
                .iter()
                .map(|f| match f {
                    TouchFeature::Sphere { id, radius_mm, .. } => Feature::Sphere {
                        id: *id,
                        radius_mm: *radius_mm,
                        radius_sigma_um: sphere_radius_sigma_um,
                    },
                    TouchFeature::Plane { id, .. } => Feature::Plane { id: *id },
                })
                .collect(),
        }
    }

    /// Probes each target: the nominal tool IK moves the stylus along the
    /// approach line through the target; the probe triggers where the
    /// actual stylus touches the true feature, late or early by the trigger
    /// noise; the record holds the commands latched at the trigger.
    pub fn measure(
        &self,
        plant: &Plant,
        targets: &[TouchTarget],
        seed: u64,
    ) -> Result<TouchData, PlantError> {
        let r = self.stylus_radius_mm + 1e-3 * self.stylus_radius_error_um;
        let touch = |actual: &Machine, j: usize, t: &TouchTarget, rng: &mut Pcg64Mcg| {
            let feature = self
                .features
                .iter()
                .find(|f| f.id() == t.feature)
                .ok_or_else(|| {
                    PlantError::Invalid(format!("touch {j}: no feature {}", t.feature))
                })?;
            let err = kinematics_error(j, t.tip_mm);
            let at = |s: f64| -> Result<(ExternalPose, f64), PlantError> {
                let pose = commanded(&plant.nominal, &(t.tip_mm + t.approach * s), &t.axis)
                    .map_err(&err)?;
                let x = plant
                    .spindle_point_on(
                        actual,
                        &pose.commands_mm,
                        pose.head_rad,
                        &Effector::default(),
                    )
                    .map_err(&err)?;
                Ok((pose, feature.clearance(&x, r)))
            };
            let (mut lo, mut hi) = (-PROBING_STROKE_MM, PROBING_STROKE_MM);
            if at(lo)?.1 <= 0.0 || at(hi)?.1 >= 0.0 {
                return Err(PlantError::Invalid(format!(
                    "touch {j}: the probe does not meet feature {} within ±{PROBING_STROKE_MM} mm of the target",
                    t.feature
                )));
            }
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if at(mid)?.1 > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let z: f64 = StandardNormal.sample(rng);
            let (pose, _) = at(0.5 * (lo + hi) + 1e-3 * self.sigma_um * z)?;
            Ok(TouchReading {
                pose,
                feature: t.feature,
                sigma_um: Some(self.sigma_um),
                temp_c: None,
                line: 0,
            })
        };
        measure_each(
            plant,
            targets,
            seed,
            TOUCH_TAG,
            "simulated touch probe",
            touch,
        )
    }
}
