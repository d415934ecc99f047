//! The door's pages of a machine description's parts (the types a machine
//! file is made of), re-exported by [`crate::kinematics`]: kept here so the
//! workflow module stays short.

/// The accuracy a machine file promises (`calibration.accuracy`): the
/// predicted rms positioning error over the workspace, a 95 % upper bound
/// of it (mm), the point it is of, and its parts.
///
/// # Example
/// ```
/// use tricept_ident::WriteOptions;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// use tricept_ident::kinematics::MachineDescription;
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// let dir = std::env::temp_dir().join(format!("tricept-door-accuracyrecord-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// calibration.write_machine(&dir.join("m.json"), WriteOptions::default())?;
/// let description = MachineDescription::from_file(&dir.join("m.json"))?;
/// let record = description.calibration.clone().ok_or("no record")?;
/// let accuracy = record.accuracy.ok_or("no accuracy")?;
/// assert!(accuracy.upper_mm >= accuracy.rms_mm);
/// assert_eq!(accuracy.point, "platform"); // no head in this calibration
/// assert_eq!(Some(accuracy.upper_mm), calibration.accuracy().map(|a| a.upper_mm));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::AccuracyRecord;
/// Which axis of the UP limb's base U joint is fixed to the base (`x-first`,
/// the paper's, or `y-first`).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{AxisOrder, MachineDescription};
/// assert_eq!(MachineDescription::paper().up_limb.axis_order, AxisOrder::default());
/// assert_eq!(AxisOrder::XFirst.to_string(), "x-first");
/// assert_eq!(serde_json::to_string(&AxisOrder::YFirst)?, r#""y-first""#);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::AxisOrder;
/// The calibration record of a machine file (`calibration`): how it was
/// calibrated, from which data, its estimates with their uncertainty and
/// correlations, its verdict, its accuracy, its seal.
///
/// # Example
/// ```
/// use tricept_ident::WriteOptions;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// use tricept_ident::kinematics::MachineDescription;
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// let dir = std::env::temp_dir().join(format!("tricept-door-calibrationrecord-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// calibration.write_machine(&dir.join("m.json"), WriteOptions::default())?;
/// let description = MachineDescription::from_file(&dir.join("m.json"))?;
/// let record = description.calibration.clone().ok_or("no record")?;
/// assert_eq!(record.poses_used, 75); // the fixture's grid
/// assert!(record.converged && record.adequate && !record.forced);
/// assert_eq!(record.correlations.names.len(), record.correlations.matrix.len());
/// assert_eq!(description.seal_check(), tricept_ident::kinematics::SealCheck::Intact { partial: false });
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::CalibrationRecord;
/// Joints on two circles at the same angles on base and platform (mm, degrees).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{CircularPlacement, MachineDescription, Placement};
/// let d = MachineDescription::paper();
/// let Placement::Circular(c) = &d.placement else { unreachable!() };
/// let c: &CircularPlacement = c;
/// assert_eq!((c.base_radius_mm, c.platform_radius_mm), (288.7, 100.0)); // Table 1's b and a
/// let (base_mm, _) = d.joints_mm();
/// assert!((base_mm[2][0] - 288.7).abs() < 1e-12); // B3 at 0 degrees
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::CircularPlacement;
/// The controller's parameters a machine file carries: backlash (um per leg),
/// thermal expansion (ppm/K) and its reference temperature (°C).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{ControllerDescription, MachineDescription};
/// assert!(MachineDescription::paper().controller.is_none());
/// let c = ControllerDescription::default();
/// assert_eq!((c.backlash_um, c.reference_temperature_c), ([0.0; 3], 20.0)); // ISO 1
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::ControllerDescription;
/// The correlations of a calibration's estimates: names and their matrix
/// (rows in the names' order).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::CorrelationsDescription;
/// let c = CorrelationsDescription { names: vec!["dq1".into(), "dq2".into()], matrix: vec![vec![1.0, 0.2], vec![0.2, 1.0]] };
/// assert_eq!(c.matrix.len(), c.names.len());
/// assert_eq!(serde_json::from_str::<CorrelationsDescription>(&serde_json::to_string(&c)?)?, c);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::CorrelationsDescription;
/// Joint centres given coordinate by coordinate, mm: B1..B3 in the base frame,
/// A1..A3 in the platform frame.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{ExplicitPlacement, Machine, MachineDescription, Placement, Vector3};
/// let mut d = MachineDescription::paper();
/// let (base_joints_mm, platform_joints_mm) = d.joints_mm();
/// d.placement = Placement::Explicit(ExplicitPlacement { base_joints_mm, platform_joints_mm });
/// let p = Vector3::new(30.0, 40.0, 760.0);
/// let explicit = Machine::from_description(&d, "explicit")?.inverse(&p)?;
/// let circular = Machine::paper().inverse(&p)?;
/// assert!((explicit.legs_mm[1] - circular.legs_mm[1]).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::ExplicitPlacement;
/// An external instrument's file a fused calibration used (tracker,
/// ballbar, touch probe): its kind, file and digest, records, fit and
/// nuisance estimates; none for the UP sensors alone.
///
/// # Example
/// ```
/// use tricept_ident::WriteOptions;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// use tricept_ident::kinematics::MachineDescription;
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// let dir = std::env::temp_dir().join(format!("tricept-door-externalsourcerecord-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// calibration.write_machine(&dir.join("m.json"), WriteOptions::default())?;
/// let description = MachineDescription::from_file(&dir.join("m.json"))?;
/// let record = description.calibration.clone().ok_or("no record")?;
/// assert!(record.external_sources.is_empty()); // the UP limb's sensors alone
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::ExternalSourceRecord;
/// The 2-axis head in a description, in the platform frame at zero head
/// angles (the default: an A/C head, tool tip 350 mm below O').
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{HeadDescription, MachineDescription};
/// let h = HeadDescription::default();
/// assert_eq!(MachineDescription::paper().head, h);
/// assert_eq!(h.tool_tip_mm, [0.0, 0.0, 350.0]);
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::HeadDescription;
/// A parameter a calibration held at its prior, with why.
///
/// # Example
/// ```
/// use tricept_ident::WriteOptions;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// use tricept_ident::kinematics::{HeldParameter, MachineDescription};
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// let dir = std::env::temp_dir().join(format!("tricept-door-heldparameter-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// calibration.write_machine(&dir.join("m.json"), WriteOptions::default())?;
/// let description = MachineDescription::from_file(&dir.join("m.json"))?;
/// let record = description.calibration.clone().ok_or("no record")?;
/// for held in &record.held {
///     assert!(!held.reason.is_empty(), "{} held without a reason", held.name);
/// }
/// let written: HeldParameter = serde_json::from_str(r#"{"name": "dq1", "reason": "not identifiable"}"#)?;
/// assert_eq!((written.name.as_str(), written.reason.as_str()), ("dq1", "not identifiable"));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::HeldParameter;
/// How a leg table is read between its points (linear, the only one now).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{Interpolation, LegTableDescription};
/// let t = LegTableDescription::new(2, 700.0, 5.0, vec![0.0, 2.0]);
/// assert_eq!(t.interpolation, Interpolation::Linear);
/// assert_eq!(Interpolation::default(), Interpolation::Linear);
/// assert!((t.extra_mm(701.25) - 0.0005).abs() < 1e-15); // a quarter of the way: 0.5 um
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::Interpolation;
/// The static leg effects a calibrated machine file applies (ball-screw
/// lead, compliance, compensation tables); none in a nominal machine.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{LegEffectsDescription, Machine, MachineDescription, Vector3};
/// assert!(MachineDescription::paper().leg_effects.is_zero());
/// let mut d = MachineDescription::paper();
/// d.leg_effects = LegEffectsDescription { lead_ppm: [100.0, 0.0, 0.0], ..Default::default() };
/// let m = Machine::from_description(&d, "lead")?;
/// assert!(m.has_leg_effects());
/// let p = Vector3::new(0.0, 0.0, 750.0);
/// let (with, without) = (m.inverse(&p)?.legs_mm, Machine::paper().inverse(&p)?.legs_mm);
/// assert!(with[0] < without[0] && with[1] == without[1]); // a long leg is commanded shorter
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::LegEffectsDescription;
/// A leg's compensation table: the extra length (um) at commands
/// `start_mm + k step_mm`, read by linear interpolation, end values holding.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::LegTableDescription;
/// let t = LegTableDescription::new(1, 700.0, 5.0, vec![1.0, -1.0]);
/// assert!(t.extra_mm(702.5).abs() < 1e-15); // halfway: the mean
/// assert_eq!(t.extra_mm(600.0), 0.001); // the first value holds before the table
/// assert_eq!(t.end_mm(), 705.0);
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::LegTableDescription;
/// The joint limits in a description: leg and UP strokes (mm), largest tilt
/// of the UP limb (degrees).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{LimitsDescription, MachineDescription};
/// let l = LimitsDescription::default();
/// assert_eq!(MachineDescription::paper().limits, l);
/// assert_eq!((l.leg_stroke_mm, l.max_tilt_deg), ([450.0, 1250.0], 40.0));
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::LimitsDescription;
/// Masses (kg), leg stiffness (N/um at 1 m) and gravity for the legs'
/// gravity deflection.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{LoadsDescription, MachineDescription};
/// let l = LoadsDescription::default();
/// assert_eq!(MachineDescription::paper().loads, l);
/// assert_eq!(l.platform_mass_kg + l.head_mass_kg, 150.0);
/// assert_eq!(l.gravity_direction, [0.0, 0.0, 1.0]); // hanging from its base
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::LoadsDescription;
/// Where a description puts the joint centres: on circles or explicitly.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{MachineDescription, Placement};
/// let d = MachineDescription::paper();
/// assert!(matches!(d.placement, Placement::Circular(_)));
/// assert!(d.to_json().contains("\"circular\"")); // the key in a machine file
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::Placement;
/// What a description's seal says ([`MachineDescription::seal_check`](crate::kinematics::MachineDescription::seal_check)):
/// no record, unsealed, intact, or the fields edited since.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{MachineDescription, SealCheck};
/// assert_eq!(MachineDescription::paper().seal_check(), SealCheck::NoRecord);
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::SealCheck;
/// The UP limb's sensor noise in a description: one reading's encoder
/// (arcsec) and scale (um) noise, and readings averaged per logged value.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{MachineDescription, SensorDescription};
/// let s = SensorDescription::default(); // the paper's
/// assert_eq!(MachineDescription::paper().sensors, s);
/// assert_eq!((s.angle_noise_arcsec, s.length_noise_um, s.readings_per_pose), (0.8, 0.5, 3));
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::SensorDescription;
/// The UP sensors' offsets a calibration estimated (rad, rad, mm) with their
/// standard deviations; zero by default.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::SensorOffsetsDescription;
/// let o = SensorOffsetsDescription { s_mm: 0.02, ..Default::default() };
/// let text = serde_json::to_string(&o)?;
/// assert_eq!(serde_json::from_str::<SensorOffsetsDescription>(&text)?, o);
/// assert_eq!(o.phi_rad, 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::SensorOffsetsDescription;
/// The UP limb in a description: axis order and the class-2 errors the
/// paper's model leaves out (axis skew and offset, twist), zero by default.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{MachineDescription, UpLimbDescription};
/// let up = UpLimbDescription::default();
/// assert_eq!(MachineDescription::paper().up_limb, up);
/// assert_eq!((up.axis_skew_rad, up.axis_offset_mm, up.twist_rad_per_mm), (0.0, 0.0, 0.0));
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::UpLimbDescription;
/// The workspace cylinder in a description: radius `R`, height `h` and its
/// distance `H` from the base, mm (Table 1).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{MachineDescription, Workspace};
/// let w = MachineDescription::paper().workspace;
/// assert_eq!((w.radius_mm, w.height_mm, w.distance_mm), (400.0, 200.0, 650.0));
/// assert_eq!(Workspace::from_description(&w).z_max_mm, 850.0); // H + h
/// ```
#[doc(inline)]
pub use tricept_kinematics::description::WorkspaceDescription;
