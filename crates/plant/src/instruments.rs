//! External instruments that measure the simulated machine from outside:
//! a laser tracker (or CMM) on a target in the spindle, a ballbar from the
//! tool-tip ball to a pivot on the table, and a touch probe on reference
//! spheres and planes. Each measures the exact spindle point of the actual
//! machine ([`Plant::spindle_point`]), adds its own noise from its own
//! seeded generator (PCG-64 MCG, the seed mixed with a tag per instrument)
//! and writes the external-measurement records of `tricept-data`.

use nalgebra::{Isometry3, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;
use tricept_data::{
    BallbarData, BallbarReading, ExternalData, ExternalPose, Feature, Features, Stylus, TouchData,
    TouchReading, TrackerData, TrackerPoint,
};
use tricept_kinematics::{HeadBranch, Machine};
use tricept_model::Effector;

use crate::{Plant, PlantError};

/// Tags mixed into the seed of each instrument, so that instruments
/// measuring with the same seed draw independent noise.
const TRACKER_TAG: u64 = 0x7ac4_e700;
const BALLBAR_TAG: u64 = 0xba11_ba40;
const TOUCH_TAG: u64 = 0x70c4_0ff0;

fn kinematics_error(
    index: usize,
    target: Vector3<f64>,
) -> impl Fn(tricept_kinematics::KinematicsError) -> PlantError {
    move |source| PlantError::Kinematics {
        index,
        target_mm: target.into(),
        source,
    }
}

/// A laser tracker (or a CMM) measuring a target mounted in the spindle.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracker {
    /// The tracker's frame: maps a point of the machine's base frame into
    /// the instrument's coordinates.
    pub frame: Isometry3<f64>,
    /// Offset of the target from the tool tip, mm, in the spindle frame at
    /// zero head angles (unknown to the identification unless stated).
    pub target_offset_mm: Vector3<f64>,
    /// Standard deviation of each measured coordinate, um.
    pub sigma_um: f64,
    /// Station number written to the records.
    pub setup: u32,
}

impl Tracker {
    /// Measures the target at each `(pose, extension_mm)`: the machine at
    /// the pose's commands and head angles, the target `extension_mm` along
    /// the tool beyond the tip plus the target offset.
    ///
    /// # Example
    /// ```
    /// use nalgebra::{Isometry3, Vector3};
    /// use tricept_data::ExternalPose;
    /// use tricept_kinematics::Machine;
    /// use tricept_plant::{Plant, Tracker};
    /// let m = Machine::paper();
    /// let plant = Plant::geometric(m.clone(), Default::default());
    /// let tracker = Tracker {
    ///     frame: Isometry3::translation(1500.0, 0.0, 0.0),
    ///     target_offset_mm: Vector3::zeros(),
    ///     sigma_um: 10.0,
    ///     setup: 1,
    /// };
    /// let q = m.inverse(&Vector3::new(0.0, 0.0, 750.0)).unwrap().legs_mm;
    /// let pose = ExternalPose { commands_mm: q, head_rad: [0.0, 0.0] };
    /// let data = tracker.measure(&plant, &[(pose, 0.0)], 1).unwrap();
    /// // The tool tip is 350 mm below O' = (0, 0, 750), seen from 1.5 m along x.
    /// let p = data.records[0].position_mm;
    /// assert!((p[0] - 1500.0).abs() < 0.1 && (p[2] - 1100.0).abs() < 0.1);
    /// ```
    pub fn measure(
        &self,
        plant: &Plant,
        poses: &[(ExternalPose, f64)],
        seed: u64,
    ) -> Result<TrackerData, PlantError> {
        let actual = plant.actual_machine();
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ TRACKER_TAG);
        let sigma_mm = self.sigma_um * 1e-3;
        let mut records = Vec::with_capacity(poses.len());
        for (j, (pose, extension_mm)) in poses.iter().enumerate() {
            let effector = Effector {
                extension_mm: *extension_mm,
                offset_mm: self.target_offset_mm,
            };
            let x = plant
                .spindle_point_on(&actual, &pose.commands_mm, pose.head_rad, &effector)
                .map_err(kinematics_error(j, Vector3::from(pose.commands_mm)))?;
            let y = self.frame * nalgebra::Point3::from(x);
            let position_mm: [f64; 3] = std::array::from_fn(|c| {
                let z: f64 = StandardNormal.sample(&mut rng);
                y[c] + sigma_mm * z
            });
            records.push(TrackerPoint {
                pose: *pose,
                position_mm,
                sigma_um: Some(self.sigma_um),
                extension_mm: *extension_mm,
                setup: self.setup,
                temp_c: None,
                line: 0,
            });
        }
        Ok(ExternalData {
            records,
            source: "simulated tracker".into(),
        })
    }
}

/// A ballbar between a ball in the spindle and a pivot on the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Ballbar {
    /// Centre of the pivot ball, base frame, mm.
    pub pivot_mm: Vector3<f64>,
    /// The bar's reading minus the true centre distance, um (its length
    /// calibration error).
    pub length_error_um: f64,
    /// Offset of the spindle ball from the tool tip, mm (spindle frame at
    /// zero head angles).
    pub ball_offset_mm: Vector3<f64>,
    /// Standard deviation of one reading, um.
    pub sigma_um: f64,
    /// Setup number written to the records.
    pub setup: u32,
}

impl Ballbar {
    /// Reads the bar at each pose.
    ///
    /// # Example
    /// ```
    /// use nalgebra::Vector3;
    /// use tricept_data::ExternalPose;
    /// use tricept_kinematics::{HeadBranch, Machine};
    /// use tricept_plant::{Ballbar, Plant};
    /// let m = Machine::paper();
    /// let plant = Plant::geometric(m.clone(), Default::default());
    /// let bar = Ballbar { pivot_mm: Vector3::new(0.0, 0.0, 1250.0), length_error_um: 0.0,
    ///     ball_offset_mm: Vector3::zeros(), sigma_um: 1.0, setup: 1 };
    /// let ik = m.tool_inverse(&Vector3::new(150.0, 0.0, 1250.0), &Vector3::new(0.3, 0.0, 1.0),
    ///     HeadBranch::default()).unwrap();
    /// let pose = ExternalPose { commands_mm: ik.legs_mm, head_rad: ik.head_rad };
    /// let data = bar.measure(&plant, &[pose], 3).unwrap();
    /// assert!((data.records[0].length_mm - 150.0).abs() < 0.01);
    /// ```
    pub fn measure(
        &self,
        plant: &Plant,
        poses: &[ExternalPose],
        seed: u64,
    ) -> Result<BallbarData, PlantError> {
        let actual = plant.actual_machine();
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ BALLBAR_TAG);
        let effector = Effector {
            extension_mm: 0.0,
            offset_mm: self.ball_offset_mm,
        };
        let mut records = Vec::with_capacity(poses.len());
        for (j, pose) in poses.iter().enumerate() {
            let x = plant
                .spindle_point_on(&actual, &pose.commands_mm, pose.head_rad, &effector)
                .map_err(kinematics_error(j, Vector3::from(pose.commands_mm)))?;
            let z: f64 = StandardNormal.sample(&mut rng);
            records.push(BallbarReading {
                pose: *pose,
                length_mm: (x - self.pivot_mm).norm()
                    + 1e-3 * (self.length_error_um + self.sigma_um * z),
                sigma_um: Some(self.sigma_um),
                setup: self.setup,
                temp_c: None,
                line: 0,
            });
        }
        Ok(ExternalData {
            records,
            source: "simulated ballbar".into(),
        })
    }
}

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
        let actual = plant.actual_machine();
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ TOUCH_TAG);
        let r = self.stylus_radius_mm + 1e-3 * self.stylus_radius_error_um;
        let mut records = Vec::with_capacity(targets.len());
        for (j, t) in targets.iter().enumerate() {
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
                        &actual,
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
            let z: f64 = StandardNormal.sample(&mut rng);
            let (pose, _) = at(0.5 * (lo + hi) + 1e-3 * self.sigma_um * z)?;
            records.push(TouchReading {
                pose,
                feature: t.feature,
                sigma_um: Some(self.sigma_um),
                temp_c: None,
                line: 0,
            });
        }
        Ok(ExternalData {
            records,
            source: "simulated touch probe".into(),
        })
    }
}

/// The commands (legs and head angles) the nominal tool IK gives for a tool
/// tip and axis.
pub fn commanded(
    nominal: &Machine,
    tip_mm: &Vector3<f64>,
    axis: &Vector3<f64>,
) -> Result<ExternalPose, tricept_kinematics::KinematicsError> {
    let ik = nominal.tool_inverse(tip_mm, axis, HeadBranch::default())?;
    Ok(ExternalPose {
        commands_mm: ik.legs_mm,
        head_rad: ik.head_rad,
    })
}
