//! A calibrated machine file checked against its own calibration record:
//! [`check_calibration_record`].
//!
//! A calibrated file carries its geometry twice: as the description every
//! `--machine` loads (joint positions, leg offsets, the head, leg effects),
//! and as the `calibration` record it came from (the machine the estimates
//! are relative to, and `estimates_mm`). A hand edit of one without the
//! other (5 mm added to `leg_offsets_mm[0]` while the record still says
//! `dq1 = 0.366`) would otherwise command the machine with numbers nobody
//! identified, silently. The check rebuilds the geometry from the record,
//! exactly as the writer built it, and names every field that differs.
//!
//! What is rebuilt: the base and platform joints and the leg offsets (the
//! module's parameter set on the machine the estimates are relative to),
//! the head (a fused calibration's `head13` estimates), and the static leg
//! effects a diagnosis deploys (every effect the registry deploys into the
//! machine's leg effects, [`tricept_model::effects::Deployment::LegEffects`],
//! by its `effect.parameter` names in `calibration.effects`; the base
//! machine's values for those the record does not name).

use tricept_kinematics::description::{CalibrationRecord, SealCheck};
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::effects::{Deployment, EffectName};
use tricept_model::{ParameterSet, actual::actual_machine, head_errors::HeadParameterSet};

/// The methods that write calibration records.
pub const RECORD_METHODS: [&str; 3] = ["identify", "diagnose", "identify (fused)"];

/// Largest difference (mm, ppm, or um/kN) between the file and the rebuilt
/// geometry that counts as equal: far below any edit, far above rounding.
const TOLERANCE: f64 = 1e-9;

/// Why a calibrated machine file does not match its record.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RecordError {
    /// The record cannot be read as one this version writes.
    #[error("calibration record: {0}")]
    Unreadable(String),
    /// Fields of the file differ from the values the record was sealed
    /// with (every field is sealed: the geometry, the estimates, the
    /// nominal machine, the UP limb, the workspace, the standard
    /// deviations, noise and temperature).
    #[error(
        "{} edited after the calibration (the record's seal does not match){}: every verb that loads the file commands, checks or exports by {}; restore the file, or calibrate again",
        named(.fields),
        .detail.as_ref().map(|d| format!("; {d}")).unwrap_or_default(),
        if .fields.len() == 1 { "it" } else { "them" }
    )]
    Edited {
        /// The edited fields, as named in the file (`leg_offsets_mm`,
        /// `calibration.estimates_mm.dq2`).
        fields: Vec<String>,
        /// What the rebuild from the record says besides (`None` when the
        /// file's geometry agrees with its record): where they differ,
        /// with both values, or why the record cannot be read.
        detail: Option<String>,
    },
    /// The record has no seal: written before records were sealed, or the
    /// seal was removed.
    #[error(
        "the calibration record has no `seal` (written by a tricept before 0.1.0's sealed records, or the seal was removed), so edits of its standard deviations, noise or temperature cannot be seen; calibrate again, or remove the `calibration` record to use the file as a plain description"
    )]
    Unsealed,
    /// Fields of the description differ from the geometry rebuilt from the
    /// record.
    #[error(
        "the machine does not match its calibration record (the geometry rebuilt from `calibration.{base}` and `calibration.estimates_mm`): {}; restore the file, or remove its `calibration` record to use it as a plain description",
        .fields.join("; ")
    )]
    Mismatch {
        /// The record field the estimates are relative to.
        base: &'static str,
        /// Each differing field: name, file value, rebuilt value.
        fields: Vec<String>,
    },
}

/// The edited fields as a message names them: at most 12, then how many
/// more.
fn named(fields: &[String]) -> String {
    const SHOWN: usize = 12;
    let mut s = fields
        .iter()
        .take(SHOWN)
        .map(|f| format!("`{f}`"))
        .collect::<Vec<_>>()
        .join(", ");
    if fields.len() > SHOWN {
        s.push_str(&format!(" and {} more fields", fields.len() - SHOWN));
    }
    s
}

/// What loading a calibrated file has to say beside refusing it: a seal
/// written before the seal covered every field.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct RecordNotes {
    /// The record's seal covers a chosen list of fields only (a file
    /// written before every field was sealed): an edit of the geometry
    /// with its estimates cannot be seen.
    pub partial_seal: bool,
}

impl RecordNotes {
    /// The warning a loader prints, if any.
    pub fn warning(&self) -> Option<&'static str> {
        self.partial_seal.then_some(
            "its calibration record was sealed by an earlier tricept, whose seal did not cover the geometry, the estimates, the nominal machine, the UP limb or the workspace: an edit of those that agree with each other cannot be seen; write it again with this version (identify's `write_machine`) to seal every field",
        )
    }
}

/// Checks a calibrated machine description against its `calibration`
/// record (see the module docs); `Ok` for a description without one, with
/// what a loader should say of an intact record ([`RecordNotes`]).
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, record::check_calibration_record, identify};
/// use tricept_kinematics::Machine;
/// use tricept_kinematics::description::*;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let model = GeometricModel::new(m.clone(), set.clone());
/// let p: Vec<f64> = set.table2();
/// let mut d = model.machine_at(&p).to_description();
/// let mut estimates = serde_json::Map::new();
/// for (n, v) in set.names().iter().zip(&p) {
///     estimates.insert(n.clone(), (*v).into());
/// }
/// let nominal = Box::new(m.to_description());
/// d.calibration = Some(Box::new(CalibrationRecord {
///     method: "identify".into(), parameter_set: "paper15".into(),
///     estimates_mm: estimates, std_dev_mm: Default::default(),
///     correlations: CorrelationsDescription { names: vec![], matrix: vec![] },
///     effects: Default::default(),
///     sensor_offsets: SensorOffsetsDescription { phi_rad: 0.0, theta_rad: 0.0, s_mm: 0.0, std_dev: [0.0; 3] }, accuracy: None,
///     applies: vec![], records: vec![], held: vec![], chi2_per_dof: 1.0, dof: 1, converged: true, adequate: true, forced: false,
///     warnings: vec![], poses_used: 75, temperature_c: None, rejected_lines: vec![], leg_tables_digest: None, seal: None, external_sources: vec![],
///     data_file: "d.csv".into(), data_sha256: String::new(), date: String::new(),
///     tool_version: String::new(), relative_to: m.name.clone(), relative_to_machine: None,
///     nominal,
/// }));
/// // Written files are sealed; an unsealed record is refused.
/// assert!(check_calibration_record(&d).is_err());
/// d.seal();
/// assert!(check_calibration_record(&d).is_ok());
/// // An edit of any field is caught and named.
/// let mut edited = d.clone();
/// edited.sensors.length_noise_um *= 2.0;
/// let e = check_calibration_record(&edited).unwrap_err().to_string();
/// assert!(e.contains("`sensors.length_noise_um` edited"), "{e}");
/// // An edit of the geometry without the record is caught and named,
/// // with both values.
/// d.leg_offsets_mm[0] += 5.0;
/// let e = check_calibration_record(&d).unwrap_err().to_string();
/// assert!(e.contains("`leg_offsets_mm` edited"), "{e}");
/// assert!(e.contains("leg_offsets_mm[0] is 5.450000 in the file but 0.450000 from the record"), "{e}");
/// ```
pub fn check_calibration_record(d: &MachineDescription) -> Result<RecordNotes, RecordError> {
    let partial_seal = match d.seal_check() {
        SealCheck::NoRecord => return Ok(RecordNotes::default()),
        SealCheck::Unsealed => return Err(RecordError::Unsealed),
        SealCheck::Edited(fields) => {
            let detail = match rebuilt_differences(d) {
                Err(RecordError::Mismatch { fields, .. }) => Some(format!(
                    "the machine does not match its calibration record: {}",
                    fields.join("; ")
                )),
                Err(e) => Some(e.to_string()),
                Ok(()) => None,
            };
            return Err(RecordError::Edited { fields, detail });
        }
        SealCheck::Intact { partial } => partial,
    };
    rebuilt_differences(d)?;
    Ok(RecordNotes { partial_seal })
}

/// The record's geometry rebuilt and compared with the file's: `Ok` when
/// they agree, else the differences ([`RecordError::Mismatch`]) or why the
/// record cannot be rebuilt.
fn rebuilt_differences(d: &MachineDescription) -> Result<(), RecordError> {
    let Some(c) = &d.calibration else {
        return Ok(());
    };
    let unreadable = |why: String| RecordError::Unreadable(why);
    if !RECORD_METHODS.contains(&c.method.as_str()) {
        return Err(unreadable(format!(
            "unknown method `{}` (this version writes {})",
            c.method,
            RECORD_METHODS.join(", ")
        )));
    }
    let (module_label, with_head) = match c.parameter_set.strip_suffix(" + head") {
        Some(label) => (label, true),
        None => (c.parameter_set.as_str(), false),
    };
    let set = ParameterSet::by_label(module_label).map_err(|_| {
        unreadable(format!(
            "unknown parameter set `{}` (this version writes paper15, full21, or either + head)",
            c.parameter_set
        ))
    })?;
    let base_field = if c.relative_to_machine.is_some() {
        "relative_to_machine"
    } else {
        "nominal"
    };
    let base = base_description(c)
        .build()
        .map_err(|e| unreadable(format!("`calibration.{base_field}`: {e}")))?;
    let file = d
        .build()
        .map_err(|e| unreadable(format!("the description: {e}")))?;
    let value = |name: &str| -> Result<f64, RecordError> {
        c.estimates_mm
            .get(name)
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| unreadable(format!("`estimates_mm` has no number `{name}`")))
    };
    let module: Vec<f64> = set
        .names()
        .iter()
        .map(|n| value(n))
        .collect::<Result<_, _>>()?;
    let mut rebuilt = actual_machine(&base, &set.to_errors(&module));
    if with_head {
        let head = HeadParameterSet::head13(&base.head);
        let p: Vec<f64> = head
            .names()
            .iter()
            .map(|n| value(n))
            .collect::<Result<_, _>>()?;
        rebuilt.head = head.head_at(&p);
    }
    rebuilt.leg_effects = base.leg_effects;
    for e in EffectName::ALL {
        let Deployment::LegEffects(d) = e.spec().deployment else {
            continue;
        };
        for (index, p) in e.spec().parameters.iter().enumerate() {
            if let Some(v) = effect(c, &format!("{e}.{p}")) {
                (d.set)(&mut rebuilt.leg_effects, index, v);
            }
        }
    }
    let mut fields = differences(&file, &rebuilt, c);
    // The compensation tables are checked against the digest the record
    // kept of them (a record without one: the base machine's tables).
    let recorded = match &c.leg_tables_digest {
        Some(digest) => Some(digest.clone()),
        None => base_description(c).leg_effects.tables_digest(),
    };
    let in_file = d.leg_effects.tables_digest();
    if in_file != recorded {
        let shown = |x: &Option<String>| x.clone().unwrap_or_else(|| "no tables".into());
        fields.push(format!(
            "leg_effects.tables differ from the tables the record was written with (digest {} in the file, {} in the record)",
            shown(&in_file),
            shown(&recorded)
        ));
    }
    if fields.is_empty() {
        Ok(())
    } else {
        Err(RecordError::Mismatch {
            base: base_field,
            fields,
        })
    }
}

/// The description the record's estimates are relative to.
fn base_description(c: &CalibrationRecord) -> &MachineDescription {
    match &c.relative_to_machine {
        Some(b) => b,
        None => &c.nominal,
    }
}

/// The value of a diagnosed effect parameter in the record.
fn effect(c: &CalibrationRecord, name: &str) -> Option<f64> {
    c.effects
        .get(name)
        .and_then(|v| v.get("value"))
        .and_then(serde_json::Value::as_f64)
}

/// Every field where `file` and `rebuilt` differ, with both values.
fn differences(file: &Machine, rebuilt: &Machine, c: &CalibrationRecord) -> Vec<String> {
    let mut out = Vec::new();
    let mut compare = |field: String, a: f64, b: f64, source: String| {
        let equal = (a - b).abs() <= TOLERANCE * (1.0 + b.abs());
        if !equal {
            out.push(format!(
                "{field} is {a:.6} in the file but {b:.6} from the record{source}"
            ));
        }
    };
    let dq = |i: usize| match c
        .estimates_mm
        .get(&format!("dq{}", i + 1))
        .and_then(serde_json::Value::as_f64)
    {
        Some(v) => format!(" (dq{} = {v:.6})", i + 1),
        None => String::new(),
    };
    for i in 0..3 {
        for (a, axis) in ["x", "y", "z"].iter().enumerate() {
            compare(
                format!("base joint {} {axis}", i + 1),
                file.base_joints_mm[i][a],
                rebuilt.base_joints_mm[i][a],
                String::new(),
            );
            compare(
                format!("platform joint {} {axis}", i + 1),
                file.platform_joints_mm[i][a],
                rebuilt.platform_joints_mm[i][a],
                String::new(),
            );
        }
        compare(
            format!("leg_offsets_mm[{i}]"),
            file.leg_offsets_mm[i],
            rebuilt.leg_offsets_mm[i],
            dq(i),
        );
        compare(
            format!("leg_effects.lead_ppm[{i}]"),
            file.leg_effects.lead_ppm[i],
            rebuilt.leg_effects.lead_ppm[i],
            String::new(),
        );
    }
    compare(
        "leg_effects.compliance_um_per_kn_at_1m".into(),
        file.leg_effects.compliance_um_per_kn_at_1m,
        rebuilt.leg_effects.compliance_um_per_kn_at_1m,
        String::new(),
    );
    let (fh, rh) = (file.head.to_description(), rebuilt.head.to_description());
    let vectors = [
        (
            "head.axis1_direction",
            fh.axis1_direction,
            rh.axis1_direction,
        ),
        ("head.axis1_point_mm", fh.axis1_point_mm, rh.axis1_point_mm),
        (
            "head.axis2_direction",
            fh.axis2_direction,
            rh.axis2_direction,
        ),
        ("head.axis2_point_mm", fh.axis2_point_mm, rh.axis2_point_mm),
        ("head.tool_tip_mm", fh.tool_tip_mm, rh.tool_tip_mm),
        ("head.tool_direction", fh.tool_direction, rh.tool_direction),
    ];
    for (name, a, b) in vectors {
        for k in 0..3 {
            compare(format!("{name}[{k}]"), a[k], b[k], String::new());
        }
    }
    for k in 0..2 {
        compare(
            format!("head.angle_offsets_rad[{k}]"),
            fh.angle_offsets_rad[k],
            rh.angle_offsets_rad[k],
            String::new(),
        );
    }
    out
}
