//! The detectability workflow (`tricept detectability`): for a measurement
//! campaign, planned (a pose set) or logged (a data file's commands and
//! context), how large each unmodelled effect must be before the diagnosis
//! finds it, what it does to the geometric parameters below that, and
//! advice on the campaign.
//!
//! # Example
//! ```no_run
//! use tricept_ident::MachineInput;
//! use tricept_ident::advanced::Poses;
//! use tricept_ident::detectability::{DetectabilityRequest, detectability};
//! let report = detectability(DetectabilityRequest::new(Poses::grid()))?;
//! for (effect, _detectability, advice) in report.rows() {
//!     println!("{effect}: {advice}");
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use serde_json::{Value, json};
use tricept_diagnose::detect::{advise, realistic, term_detectability};
use tricept_engine::model::GeometricModel;
use tricept_model::{GeometricErrors, ParameterSet};
use tricept_plant::{Campaign, Effect, Plant, campaign::PoseOrder};

use crate::Setting;
use crate::data_input::DataInput;
use crate::error::{EXIT_OK, Error};
use crate::inputs::Poses;
use crate::machine_input::MachineInput;

/// How large an effect must be before a diagnosis finds it ([`DetectabilityReport::rows`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::detectability::{Detectability, DetectabilityRequest, detectability};
/// let report = detectability(DetectabilityRequest::new(Poses::grid()))?;
/// for (name, d, _) in report.rows() {
///     let d: &Detectability = d;
///     println!("{name}: power {} for {:?}", d.power, d.parameters);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::detect::Detectability;

/// The campaign to assess.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::detectability::DetectabilityRequest;
/// let request = DetectabilityRequest::new(Poses::grid());
/// assert!(request.data.is_none());
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct DetectabilityRequest {
    /// The machine and its sensor noise.
    pub machine: MachineInput,
    /// The planned poses (ignored when `data` is given).
    pub poses: Poses,
    /// A logged campaign instead: its commands and logged context
    /// (temperatures, times, approach directions); its readings are not
    /// used.
    pub data: Option<DataInput>,
    /// Visit every pose twice, approaching from both directions.
    pub both_directions: bool,
    /// Temperature change over the campaign, K (0: no thermal signature).
    pub temperature_drift_k: f64,
}

impl DetectabilityRequest {
    /// The planned campaign `poses` on the Table 1 machine, one
    /// direction, a drift of 2 K.
    pub fn new(poses: Poses) -> DetectabilityRequest {
        DetectabilityRequest {
            machine: MachineInput::default(),
            poses,
            data: None,
            both_directions: false,
            temperature_drift_k: 2.0,
        }
    }
}

crate::request::setters!(DetectabilityRequest {
    machine: into MachineInput,
    poses: Poses,
    data: some into DataInput,
    both_directions: bool,
    temperature_drift_k: f64,
});

/// Each effect's detectability on the campaign, with advice.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::detectability::{DetectabilityRequest, detectability};
/// let report = detectability(DetectabilityRequest::new(Poses::grid()))?;
/// for (effect, _detectability, advice) in report.rows() {
///     println!("{effect}: {advice}");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct DetectabilityReport {
    rows: Vec<(&'static str, Detectability, String)>,
    poses: usize,
    readings_per_pose: u32,
    campaign: String,
}

crate::outcome::outcome!(DetectabilityReport);

/// Assesses the request's campaign.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::detectability::{DetectabilityRequest, detectability};
/// let report = detectability(DetectabilityRequest::new(Poses::grid()))?;
/// for (effect, _detectability, advice) in report.rows() {
///     println!("{effect}: {advice}");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn detectability(request: DetectabilityRequest) -> Result<DetectabilityReport, Error> {
    let loaded = request.machine.clone().load()?;
    let m = loaded.machine();
    let mut campaign = Campaign::from_targets(m, Vec::new(), 1);
    let (data, described) = match &request.data {
        // A logged campaign: its poses with their own context.
        Some(input) => {
            let data = input.load(m)?;
            let described = format!(
                "{} logged poses of {}, mean of {} readings, with their logged context",
                data.poses.len(),
                input.name(),
                campaign.noise.readings_per_pose
            );
            (data, described)
        }
        None => {
            campaign.targets_mm = request.poses.targets(m)?;
            if request.both_directions {
                campaign.order = PoseOrder::BothDirections;
            }
            // The logged context of the campaign (times, temperature with
            // the stated drift, approach directions), on the nominal
            // machine.
            let mut plant = Plant::geometric(m.clone(), GeometricErrors::default());
            let drift_k = request.temperature_drift_k;
            if !(drift_k.is_finite() && drift_k.abs() <= 1000.0) {
                return Err(Error::invalid(
                    Setting::TemperatureDrift,
                    format!(
                        "the temperature change over the campaign must be a number of K within +-1000, got {drift_k}"
                    ),
                ));
            }
            if drift_k != 0.0 {
                plant.effects = vec![Effect::from(tricept_plant::effects::Thermal {
                    drift_k,
                    expansion_ppm_per_k: 0.0,
                })];
            }
            let data = plant
                .simulate(&campaign)
                .map_err(|e| Error::invalid_value(Setting::Poses, &request.poses, e))?;
            let described = format!(
                "{} logged poses ({}{}), mean of {} readings, temperature drift {} K",
                data.poses.len(),
                request.poses,
                if request.both_directions {
                    ", both approach directions"
                } else {
                    ""
                },
                campaign.noise.readings_per_pose,
                drift_k
            );
            (data, described)
        }
    };
    let sigma = campaign.noise.logged_sigma();
    let geometric = GeometricModel::new(m.clone(), ParameterSet::paper15());
    let mut rows = Vec::new();
    for (c, v, label) in realistic(m) {
        if let Some(d) = term_detectability(&geometric, &c, &v, &data.poses, sigma, 1e-3) {
            let advice = advise(&d, data.poses.len(), campaign.noise.readings_per_pose);
            rows.push((label, d, advice));
        }
    }
    Ok(DetectabilityReport {
        rows,
        poses: data.poses.len(),
        readings_per_pose: campaign.noise.readings_per_pose,
        campaign: described,
    })
}

impl DetectabilityReport {
    /// Each effect's analysis at its realistic magnitude (labelled), with
    /// its advice.
    pub fn rows(&self) -> impl Iterator<Item = (&str, &Detectability, &str)> {
        self.rows
            .iter()
            .map(|(label, d, advice)| (*label, d, advice.as_str()))
    }

    /// Always 0: an assessment has no verdict.
    pub fn exit_code(&self) -> u8 {
        EXIT_OK
    }

    /// Always `None`: an assessment has no verdict.
    pub fn reason(&self) -> Option<&str> {
        None
    }

    /// The report as JSON (what `tricept detectability --json` prints,
    /// `format_version` first).
    pub fn to_json(&self) -> Value {
        let v: Vec<Value> = self
            .rows
            .iter()
            .map(|(label, d, advice)| json!({"magnitude": label, "analysis": d, "advice": advice}))
            .collect();
        crate::outcome::versioned(
            json!({"poses": self.poses, "readings_per_pose": self.readings_per_pose, "effects": v}),
        )
    }

    /// The report as text (what `tricept detectability` prints): the
    /// campaign, a Markdown table, the noise note.
    pub fn report(&self) -> String {
        let mut out = format!("{}\n", self.campaign);
        out.push_str(
            "| effect | magnitude | power | detectable from | geometric held-out rms | halved from | largest bias (mm) | advice |\n",
        );
        out.push_str("|---|---|---|---|---|---|---|---|\n");
        for (label, d, advice) in &self.rows {
            let bias = d
                .bias
                .first()
                .map_or("-".to_string(), |(n, b)| format!("{n} {b:+.4}"));
            out.push_str(&format!(
                "| {} | {label} | {:.3} | x{:.2} | {:.2} | x{:.2} | {bias} | {advice} |\n",
                d.effect,
                d.power,
                d.detectable_multiple,
                d.expected_rms_geometric,
                d.halving_multiple
            ));
        }
        out.push_str(&format!(
            "the stated sensor noise can be checked only against repeated poses: revisit at least {} poses on separate visits (a simulation's `revisit`) to estimate the noise from the data (a diagnosis' `noise_from_data`)\n",
            tricept_diagnose::options::MIN_PURE_ERROR_DOF
        ));
        out
    }
}
