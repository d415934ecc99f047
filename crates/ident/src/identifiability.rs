//! What a pose set (or a logged campaign's commands) and the UP limb's
//! sensors can identify: rank, singular values, observability indices and
//! the unidentifiable combinations, before any measurement
//! (`tricept identifiability`).
//!
//! # Example
//! ```no_run
//! use tricept_ident::advanced::Poses;
//! use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
//! let request = IdentifiabilityRequest::new(Campaign::Poses(Poses::grid()));
//! let assessed = assess_identifiability(request)?;
//! assert!(assessed.machine_warnings().is_empty());
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use serde_json::Value;
use tricept_data::MeasuredPose;
use tricept_engine::{IdentifyOptions, model::GeometricModel};
use tricept_model::ParameterSet;

use crate::Setting;
use crate::calibrate::fit_error;
use crate::data_input::DataInput;
use crate::error::Error;
use crate::inputs::Poses;
use crate::machine_input::MachineInput;

/// A combination of parameters: `(name, coefficient)` terms, its singular
/// value, and its standard deviation when the data determine it.
///
/// # Example
/// ```
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
/// let request = IdentifiabilityRequest::new(Campaign::Poses(Poses::grid()));
/// let assessed = assess_identifiability(request)?;
/// let report = assessed.identifiability_report();
/// for c in report.unidentifiable.iter().chain(&report.weak) {
///     let size: Vec<f64> = c.terms.iter().map(|(_, k)| k.abs()).collect();
///     assert!(size.windows(2).all(|w| w[0] >= w[1]), "largest first");
/// }
/// assert!(report.unidentifiable.iter().all(|c| c.std_dev_mm.is_none()));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::report::Combination;
/// Two strongly correlated parameters (`|correlation| >= 0.9`).
///
/// # Example
/// ```
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
/// let request = IdentifiabilityRequest::new(Campaign::Poses(Poses::grid()));
/// let assessed = assess_identifiability(request)?;
/// let report = assessed.identifiability_report();
/// for pair in &report.correlated_pairs {
///     assert!(pair.correlation.abs() >= 0.9 && pair.a != pair.b);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::report::CorrelatedPair;
/// What a pose set and the UP limb's sensors can identify: rank, singular
/// values, observability, the combinations the data cannot see, the
/// predicted standard deviations.
///
/// # Example
/// ```
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
/// let request = IdentifiabilityRequest::new(Campaign::Poses(Poses::grid()));
/// let assessed = assess_identifiability(request)?;
/// let report = assessed.identifiability_report();
/// assert_eq!((report.n_params, report.names.len()), (15, 15)); // paper15
/// assert_eq!(report.singular_values.len(), report.n_params);
/// assert_eq!(report.unidentifiable.len(), report.fixed.len()); // one per held parameter
/// assert!(report.rank <= report.n_params);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::report::IdentifiabilityReport;
/// Optional values by parameter name, in parameter order (a JSON object,
/// `null` where there is none).
///
/// # Example
/// ```
/// use tricept_ident::identifiability::NamedValues;
/// let names = ["dq1".to_string(), "dq2".to_string()];
/// let sd = NamedValues::new(&names, &[Some(0.002), None]);
/// assert_eq!(sd.get("dq1"), Some(0.002));
/// assert_eq!(sd.get("dq2"), None); // held: no standard deviation
/// assert_eq!(sd.get("dq9"), None);
/// ```
#[doc(inline)]
pub use tricept_engine::report::NamedValues;
/// The observability indices of a pose set from the singular values of its
/// (scaled) identification matrix.
///
/// # Example
/// ```
/// use tricept_ident::identifiability::Observability;
/// let o = Observability::from_singular_values(&[4.0, 2.0, 1.0], 30);
/// assert!((o.o2 - 0.25).abs() < 1e-15); // inverse condition number
/// assert_eq!(o.o3, 1.0); // the smallest singular value
/// ```
#[doc(inline)]
pub use tricept_engine::report::Observability;

/// The poses to assess.
///
/// # Example
/// ```
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::identifiability::Campaign;
/// let planned = Campaign::Poses(Poses::grid());
/// let logged = Campaign::Data("campaign.csv".into());
/// assert!(matches!(planned, Campaign::Poses(_)) && matches!(logged, Campaign::Data(_)));
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Campaign {
    /// Target points of a pose set, commanded by the nominal inverse
    /// kinematics.
    Poses(Poses),
    /// The commands of a logged campaign (its readings are not used).
    Data(DataInput),
}

/// What to assess.
///
/// # Example
/// ```no_run
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
/// let request = IdentifiabilityRequest::new(Campaign::Poses(Poses::grid()));
/// let assessed = assess_identifiability(request)?;
/// assert!(assessed.machine_warnings().is_empty());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct IdentifiabilityRequest {
    /// The poses.
    pub campaign: Campaign,
    /// The machine (default: the embedded Table 1 machine).
    pub machine: MachineInput,
    /// The geometric parameters (default `paper15`).
    pub parameter_set: ParameterSet,
}

impl IdentifiabilityRequest {
    /// The assessment of `campaign` on the Table 1 machine for `paper15`.
    pub fn new(campaign: Campaign) -> IdentifiabilityRequest {
        IdentifiabilityRequest {
            campaign,
            machine: MachineInput::default(),
            parameter_set: ParameterSet::paper15(),
        }
    }
}

crate::request::setters!(IdentifiabilityRequest {
    machine: into MachineInput,
    parameter_set: ParameterSet,
});

/// The identifiability of a campaign.
///
/// # Example
/// ```no_run
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
/// let request = IdentifiabilityRequest::new(Campaign::Poses(Poses::grid()));
/// let assessed = assess_identifiability(request)?;
/// assert!(assessed.machine_warnings().is_empty());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Identifiability {
    report: IdentifiabilityReport,
    machine_name: String,
    axis_order: String,
    parameter_set: String,
    campaign: String,
    warnings: Vec<String>,
}

crate::outcome::outcome!(Identifiability);

/// Assesses what `request`'s campaign can identify.
///
/// # Example
/// ```
/// use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
/// let r = assess_identifiability(IdentifiabilityRequest::new(Campaign::Poses("grid".parse()?)))?;
/// assert_eq!(r.to_json()["parameter_set"], "paper15");
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn assess_identifiability(request: IdentifiabilityRequest) -> Result<Identifiability, Error> {
    let loaded = request.machine.load()?;
    let m = loaded.machine();
    let set = &request.parameter_set;
    let (commands, campaign, source) = match &request.campaign {
        Campaign::Data(data) => (data.load(m)?.poses, data.name(), data.name()),
        Campaign::Poses(poses) => {
            let targets = poses.targets(m)?;
            let mut commands = Vec::with_capacity(targets.len());
            for (i, r) in targets.iter().enumerate() {
                let ik = m.inverse(r).map_err(|e| {
                    Error::invalid_value(
                        Setting::Poses,
                        poses,
                        format!(
                            "pose {} ({:.3}, {:.3}, {:.3} mm): {e}",
                            i + 1,
                            r.x,
                            r.y,
                            r.z
                        ),
                    )
                })?;
                commands.push(MeasuredPose {
                    commands_mm: ik.legs_mm,
                    ..Default::default()
                });
            }
            (commands, poses.to_string(), format!("poses {poses}"))
        }
    };
    let model = GeometricModel::new(m.clone(), set.clone());
    let report = tricept_engine::identify::identifiability(
        &model,
        &vec![0.0; set.len()],
        &commands,
        &IdentifyOptions::for_machine(m),
    )
    .map_err(|e| fit_error(&source, e))?;
    Ok(Identifiability {
        report,
        machine_name: m.name.clone(),
        axis_order: m.up_limb.axis_order.to_string(),
        parameter_set: set.label().to_string(),
        campaign,
        warnings: loaded.warnings().to_vec(),
    })
}

impl Identifiability {
    /// The engine's report (the text of [`Identifiability::report`] and
    /// the JSON of [`Identifiability::to_json`] are made from it).
    pub fn identifiability_report(&self) -> &IdentifiabilityReport {
        &self.report
    }

    /// The warnings of the machine file loaded.
    pub fn machine_warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Always 0: an assessment has no verdict.
    pub fn exit_code(&self) -> u8 {
        crate::error::EXIT_OK
    }

    /// Always `None`: an assessment has no verdict.
    pub fn reason(&self) -> Option<&str> {
        None
    }

    /// The JSON `tricept identifiability --json` prints (`format_version`
    /// first).
    pub fn to_json(&self) -> Value {
        let mut v = self.report.to_json();
        if let Value::Object(o) = &mut v {
            o.insert("parameter_set".into(), self.parameter_set.clone().into());
            o.insert("axis_order".into(), self.axis_order.clone().into());
        }
        crate::outcome::versioned(v)
    }

    /// The text report (what `tricept identifiability` prints).
    pub fn report(&self) -> String {
        format!(
            "{} ({} U joint), parameter set {}, pose set `{}`\n{}",
            self.machine_name,
            self.axis_order,
            self.parameter_set,
            self.campaign,
            self.report.to_text()
        )
    }
}
