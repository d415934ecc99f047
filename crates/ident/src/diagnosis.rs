//! The diagnose-and-deploy workflow (`tricept diagnose`): does the
//! geometric model explain the data, and if not, which unmodelled effect
//! of the vocabulary (or generic term) does; then the final model deployed
//! into a calibrated machine ([`DiagnoseResult::deploy`]) and written as a
//! machine file with its calibration record
//! ([`DiagnoseResult::write_machine`], under the one write rule of every
//! machine file written).
//!
//! The request takes the machine as every request does
//! ([`crate::MachineInput`]) and the data as a file or in memory
//! ([`DataInput`]); the result carries the
//! verdict and its exit code (0 the final model explains the data, 3 it
//! does not), the JSON and the text report the CLI prints.
//!
//! # Example
//! ```no_run
//! use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
//! let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
//! if !result.explained() {
//!     for cause in &result.diagnosis().causes {
//!         println!("{}: {}", cause.effect, cause.description);
//!     }
//! }
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::{Map, json};
use tricept_data::Dataset;
use tricept_diagnose::{DiagnoseError, DiagnoseOptions, plausibility::Plausibility};
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::ParameterSet;

use crate::Setting;
use crate::data_input::DataInput;
use crate::error::{EXIT_INADEQUATE, EXIT_OK, Error};
use crate::inputs::LoadedMachine;
use crate::machine_file;
use crate::machine_input::MachineInput;

mod model_docs;
mod report_docs;
mod terms_docs;

pub use self::model_docs::*;
pub use self::report_docs::*;
pub use self::terms_docs::*;
pub use crate::accuracy::Accuracy;
pub use crate::machine_file::MachineFile;
pub use crate::outcome::{WriteOptions, Written};
/// A diagnosis' final model deployed ([`DiagnoseResult::deploy`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// use tricept_ident::kinematics::{Machine, Vector3};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// let deployed = result.deploy()?;
/// let machine = Machine::from(deployed);
/// let legs_mm = machine.inverse(&Vector3::new(0.0, 0.0, 750.0))?.legs_mm;
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::Deployed;
/// A diagnosis ([`DiagnoseResult::diagnosis`]).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// let diagnosis = result.diagnosis();
/// println!("chi-square {} on {} dof", diagnosis.chi_square, diagnosis.dof);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::Diagnosis;
/// When a diagnosis deploys its final model.
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::{DeployRule, DiagnoseRequest};
/// let request = DiagnoseRequest::new("campaign.csv").machine("calibrated.json");
/// assert_eq!(request.deploy_rule, DeployRule::ExpectedError);
/// ```
#[doc(inline)]
pub use tricept_diagnose::options::DeployRule;
/// A cause a diagnosis names ([`Diagnosis`]'s `causes`).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose, Cause};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// let diagnosis = result.diagnosis();
/// let causes: &[Cause] = &diagnosis.causes;
/// for cause in causes.iter().filter(|c| c.plausible) {
///     println!("{}: {}", cause.effect, cause.description);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Cause;
/// What the final model gains on held-out poses ([`Diagnosis`]'s `gain`).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose, Gain};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// let diagnosis = result.diagnosis();
/// let gain: &Gain = &diagnosis.gain;
/// println!("held-out rms {} -> {}", gain.holdout_rms_geometric, gain.holdout_rms_extended);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Gain;
/// An identification, the estimates of a fit and their covariance ([`Deployed`]'s `id`).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, Identification, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// let deployed = result.deploy()?;
/// let id: &Identification = &deployed.id;
/// for ((name, value), sigma) in id.names.iter().zip(&id.estimate).zip(&id.std_dev) {
///     println!("{name} = {value} ({sigma:?})");
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::Identification;
/// The identification design of a fit ([`Identification::design`]): its
/// numerical rank, the parameters estimated and those held at their prior.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{Design, DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// let deployed = result.deploy()?;
/// let design: &Design = deployed.id.design();
/// let held: Vec<&String> = design.fixed().iter().map(|&i| &deployed.id.names[i]).collect();
/// println!("rank {}, held at their prior: {held:?}", design.rank());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_engine::identify::Design;

/// What to diagnose and how.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("data.csv").machine(MachineInput::default()))?;
/// println!("{}", result.report());
/// std::process::exit(i32::from(result.exit_code()));
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct DiagnoseRequest {
    /// The machine the data were measured on (a calibrated machine file
    /// keeps the rank decision of its nominal machine).
    pub machine: MachineInput,
    /// The measured data (context columns temp_c, time_s, dir1..3 are used
    /// when present).
    pub data: DataInput,
    /// Estimate the sensor noise from repeated poses and test against it
    /// (F tests) instead of the stated noise.
    pub noise_from_data: bool,
    /// Standard deviation of the logged temperature, K (default 0.02).
    pub temperature_noise_k: Option<f64>,
    /// A JSON file overriding physical ranges of the plausibility table.
    pub plausibility: Option<PathBuf>,
    /// Search the generic dictionary as well as the vocabulary (default).
    pub dictionary: bool,
    /// How a term is judged worth deploying (default
    /// [`DeployRule::ExpectedError`]: the file the report expects to be
    /// best; JSON `deploy_rule`).
    pub deploy_rule: DeployRule,
}

impl DiagnoseRequest {
    /// A diagnosis of `data` measured on the Table 1 machine, with the
    /// default options.
    pub fn new(data: impl Into<DataInput>) -> DiagnoseRequest {
        DiagnoseRequest {
            machine: MachineInput::default(),
            data: data.into(),
            noise_from_data: false,
            temperature_noise_k: None,
            plausibility: None,
            dictionary: true,
            deploy_rule: DeployRule::default(),
        }
    }
}

crate::request::setters!(DiagnoseRequest {
    machine: into MachineInput,
    noise_from_data: bool,
    temperature_noise_k: some f64,
    plausibility: some into PathBuf,
    dictionary: bool,
    deploy_rule: DeployRule,
});

/// A diagnosis with what it needs to deploy its final model.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// if !result.explained() {
///     for cause in &result.diagnosis().causes {
///         println!("{}: {}", cause.effect, cause.description);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct DiagnoseResult {
    diagnosis: Diagnosis,
    source: String,
    data_path: Option<PathBuf>,
    data: Dataset,
    machine: LoadedMachine,
    rank_reference: Option<Machine>,
    deploy_rule: DeployRule,
    /// Why the exit code is not 0.
    reason: Option<String>,
    /// The final model deployed and the accuracy of its machine file,
    /// made once when first needed.
    deployment: OnceLock<Result<Deployment, Error>>,
}

crate::outcome::outcome!(writes DiagnoseResult);

/// The final model deployed, with the accuracy its machine file promises.
#[derive(Debug, Clone)]
struct Deployment {
    deployed: Deployed,
    promise: Accuracy,
}

/// Diagnoses the request's data: every problem of the input is an error of
/// kind input (exit code 2) naming the data.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv").machine("calibrated.json"))?;
/// if !result.explained() {
///     for cause in &result.diagnosis().causes {
///         println!("{}: {}", cause.effect, cause.description);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn diagnose(request: DiagnoseRequest) -> Result<DiagnoseResult, Error> {
    let DiagnoseRequest {
        machine: loaded,
        data,
        noise_from_data,
        temperature_noise_k,
        plausibility,
        dictionary,
        deploy_rule,
    } = request;
    let loaded = loaded.load()?;
    let m = loaded.machine();
    let source = data.name();
    let data_path = data.path().map(Path::to_path_buf);
    let dataset = data.load(m)?;
    let mut options = DiagnoseOptions::for_machine(m);
    options.noise_from_data = noise_from_data;
    options.rank_reference = loaded.rank_reference()?;
    options.dictionary.enabled = dictionary;
    options.deploy_rule = deploy_rule;
    if let Some(k) = temperature_noise_k {
        if !(k.is_finite() && k >= 0.0) {
            return Err(Error::invalid(
                Setting::TemperatureNoise,
                format!("must be a non-negative number of kelvin, got {k}"),
            ));
        }
        options.temperature_sigma_k = k;
    }
    if let Some(path) = &plausibility {
        let file = path.display().to_string();
        let text =
            tricept_data::bounded::read_json_text(path).map_err(|e| Error::unreadable(&file, e))?;
        options.plausibility = Plausibility::with_overrides(&text)
            .map_err(|e| Error::input(format!("{file}: {e}")))?;
    }
    let diagnosis = tricept_diagnose::diagnose(m, &dataset, &options)
        .map_err(|e| diagnose_error(&source, e))?;
    let reason = (!diagnosis.final_adequate).then(|| {
        format!(
            "the final model does not explain the data: {}",
            diagnosis
                .unexplained
                .as_deref()
                .unwrap_or("a remainder is reported (see the report)")
        )
    });
    Ok(DiagnoseResult {
        diagnosis,
        source,
        data_path,
        data: dataset,
        rank_reference: options.rank_reference,
        deploy_rule,
        machine: loaded,
        reason,
        deployment: OnceLock::new(),
    })
}

/// A failed diagnosis, naming the data; an unreachable pose names its line.
fn diagnose_error(source: &str, e: DiagnoseError) -> Error {
    match &e {
        DiagnoseError::Ident(tricept_engine::IdentError::Kinematics {
            line, source: k, ..
        }) => Error::input(format!(
            "{source}: line {line}: the commands of this pose cannot be reached: {k}"
        ))
        .with_source(e),
        _ => Error::with_context(source, e),
    }
}

impl DiagnoseResult {
    /// The diagnosis: verdict, causes, aliases, remainder, model terms.
    pub fn diagnosis(&self) -> &Diagnosis {
        &self.diagnosis
    }

    /// Whether the final model (geometric plus the named causes) explains
    /// the data.
    pub fn explained(&self) -> bool {
        self.diagnosis.final_adequate
    }

    /// 0 when the final model explains the data, 3 when it does not.
    pub fn exit_code(&self) -> u8 {
        if self.explained() {
            EXIT_OK
        } else {
            EXIT_INADEQUATE
        }
    }

    /// Why the exit code is not 0, in one phrase (`None` when it is 0):
    /// what the final model leaves unexplained. The `tricept` binary
    /// prints it after `diagnose: exit 3: `.
    pub fn reason(&self) -> Option<&str> {
        self.reason.as_deref()
    }

    /// The residual plots of the named causes (before and after).
    pub fn plots(&self) -> &[ResidualPlot] {
        &self.diagnosis.plots
    }

    /// The report as JSON (what `tricept diagnose --json` prints,
    /// `format_version` first), with the `accuracy` of the machine file
    /// once it is made ([`DiagnoseResult::accuracy`],
    /// [`DiagnoseResult::write_machine`]).
    pub fn to_json(&self) -> serde_json::Value {
        let mut v = self.diagnosis.to_json();
        if let serde_json::Value::Object(o) = &mut v {
            o.insert("deploy_rule".into(), self.deploy_rule.name().into());
            if let Some(a) = self.made_accuracy() {
                o.insert("accuracy".into(), a.to_json());
            }
        }
        crate::outcome::versioned(v)
    }

    /// The report as text (what `tricept diagnose` prints), the accuracy
    /// of the machine file first once it is made.
    pub fn report(&self) -> String {
        let text = self.diagnosis.to_text(&self.source);
        match self.made_accuracy() {
            // After the verdict's line.
            Some(a) => match text.split_once('\n') {
                Some((first, rest)) => format!("{first}\n{}\n{rest}", a.line()),
                None => format!("{text}\n{}\n", a.line()),
            },
            None => text,
        }
    }

    /// The accuracy the machine file of the final model promises: the
    /// final model is deployed once, when first needed (here, by
    /// [`DiagnoseResult::write_machine`] or
    /// [`DiagnoseResult::machine_file`]), and kept. `None` when it cannot
    /// be deployed ([`DiagnoseResult::deploy`] says why).
    pub fn accuracy(&self) -> Option<&Accuracy> {
        self.deployment().ok().map(|d| &d.promise)
    }

    /// The accuracy, once the final model has been deployed (the report
    /// and the JSON state it then).
    fn made_accuracy(&self) -> Option<&Accuracy> {
        match self.deployment.get() {
            Some(Ok(d)) => Some(&d.promise),
            _ => None,
        }
    }

    /// The final model deployed: each term worth deploying where the
    /// registry says it goes, generic leg errors as compensation tables,
    /// the controller parameters of dynamic effects. Deployed once, when
    /// first needed, and kept.
    pub fn deploy(&self) -> Result<&Deployed, Error> {
        self.deployment().map(|d| &d.deployed)
    }

    fn deployment(&self) -> Result<&Deployment, Error> {
        self.deployment
            .get_or_init(|| {
                let nominal = self.machine.machine();
                let deployed = tricept_diagnose::deploy(
                    nominal,
                    self.rank_reference.as_ref(),
                    &self.data,
                    &self.diagnosis,
                )?;
                let (promise, _) = crate::accuracy::of_fit(
                    nominal,
                    &ParameterSet::paper15(),
                    &deployed.model,
                    &deployed.id,
                    &deployed.clean,
                    &tricept_engine::IdentifyOptions::for_machine(nominal),
                    tricept_engine::accuracy::DEFAULT_TOLERANCE_MM,
                )?;
                Ok(Deployment { deployed, promise })
            })
            .as_ref()
            .map_err(Error::clone)
    }

    /// Why the final model cannot be written as a calibration: the misfit
    /// it leaves (empty when it explains the data).
    fn problems(&self) -> Vec<String> {
        let d = &self.diagnosis;
        if d.final_adequate {
            return Vec::new();
        }
        vec![match &d.unexplained {
            Some(u) => u.clone(),
            None => "the final model does not explain the data (a remainder is reported)".into(),
        }]
    }

    /// The calibrated machine of the final model as a description with its
    /// calibration record (method `diagnose`), under the write rule: refused
    /// (exit 3) when the data are not explained, unless `force`. Returns
    /// the description and, for a forced one, why it is not to be trusted.
    /// `what` names the output in messages.
    fn extended_description(
        &self,
        what: &str,
        force: bool,
    ) -> Result<(MachineDescription, Option<String>), Error> {
        let d = &self.diagnosis;
        let problems = self.problems();
        let code = if problems.is_empty() {
            EXIT_OK
        } else {
            EXIT_INADEQUATE
        };
        let forced = machine_file::write_rule(what, code, &problems.join("; "), force)?;
        let Some(data_file) = &self.data_path else {
            return Err(Error::input(format!(
                "{what}: the record hashes the data file: diagnose a data file to write a machine"
            )));
        };
        let Deployment { deployed, promise } = self.deployment()?;
        let g = ParameterSet::paper15().len();
        let mut description = machine_file::calibrated_description(
            &self.machine,
            &deployed.geometry,
            &machine_file::FitRecord::of_identification(&deployed.id),
            machine_file::Provenance {
                method: "diagnose",
                data_file,
                parameter_set: "paper15",
                rejected_lines: d.outlier_lines(),
                adequate: forced.is_none(),
                forced: forced.clone(),
                warnings: problems.into_iter().chain(alias_notes(d)).collect(),
                effects: effect_records(d, deployed, g),
                n_geometric: g,
                external: Vec::new(),
                temperature_c: machine_file::mean_temperature_c(&self.data),
                accuracy: Some(promise.record()),
            },
            deployed.controller,
        )?;
        if let Some(c) = description.calibration.as_mut() {
            c.applies = deployed.applied.clone();
            c.records = deployed.recorded.clone();
        }
        Ok((description, forced))
    }

    /// The machine file of the final model, kept apart from the result
    /// ([`MachineFile`]): the description (forced when
    /// the data are not explained) and the verdict the write rule applies.
    pub fn machine_file(&self) -> Result<crate::machine_file::MachineFile, Error> {
        let (description, forced) = self.extended_description("the machine file", true)?;
        let code = if forced.is_some() {
            EXIT_INADEQUATE
        } else {
            EXIT_OK
        };
        Ok(crate::machine_file::MachineFile::new(
            description,
            code,
            forced.unwrap_or_default(),
        ))
    }

    /// Writes the calibrated machine of the final model to `path`
    /// atomically, by the one write rule: refused (exit code 3) when the
    /// final model does not explain the data, unless
    /// [`WriteOptions::force`], and the file then says it was forced; an
    /// input error for data given in memory (the record hashes the data
    /// file). The final model is deployed once ([`DiagnoseResult::deploy`])
    /// however many files are written.
    ///
    /// # Example
    /// ```no_run
    /// use tricept_ident::{MachineInput, WriteOptions};
    /// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
    /// let result = diagnose(DiagnoseRequest::new("data.csv").machine("calibrated.json"))?;
    /// let written = result.write_machine("deployed.json".as_ref(), WriteOptions::default().force(true))?;
    /// if let Some(why) = written.forced() {
    ///     eprintln!("{} written although {why}", written.path().display());
    /// }
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn write_machine(&self, path: &Path, options: WriteOptions) -> Result<Written, Error> {
        let what = path.display().to_string();
        let (description, forced) = self.extended_description(&what, options.is_forced())?;
        crate::machine_file::write(path, &description).map_err(|e| Error::not_written(path, &e))?;
        Ok(Written::new("machine file", path, forced))
    }
}

/// An alias is deployed with the member the final model carries; the
/// file's warnings name the alternatives and what would separate them (an
/// exact alias, such as a lead common to all legs against a scale gain, is
/// never separated by the machine's own sensors).
fn alias_notes(d: &Diagnosis) -> Vec<String> {
    d.aliases
        .iter()
        .map(|a| {
            let names: Vec<&str> = a.effects.iter().map(|e| e.as_str()).collect();
            format!(
                "{} cannot be told apart{} ({}); the file deploys {}; to separate them: {}",
                names.join(" / "),
                if a.exact {
                    " by these sensors"
                } else {
                    " on this campaign"
                },
                a.why,
                a.in_model.as_str(),
                a.separate_by
            )
        })
        .collect()
}

/// The record's effect parameters (`{name: {"value", "std_dev"}}`): the
/// deployed fit's beyond the `g` geometric ones, the period of each
/// periodic term beside its amplitudes and the edges of each step beside
/// its height.
fn effect_records(d: &Diagnosis, deployed: &Deployed, g: usize) -> Map<String, serde_json::Value> {
    let mut effects = Map::new();
    for ((name, v), sd) in deployed
        .id
        .names
        .iter()
        .zip(&deployed.id.estimate)
        .zip(&deployed.id.std_dev)
        .skip(g)
    {
        effects.insert(name.clone(), json!({"value": v, "std_dev": sd}));
    }
    for t in &d.model_terms {
        if let (true, Some(p)) = (t.deployed, t.period_mm) {
            effects.insert(
                format!("{}.period_mm", t.effect),
                json!({"value": p, "std_dev": serde_json::Value::Null}),
            );
        }
        if let (true, Some(edges), [leg]) = (t.deployed, t.edges_mm, t.legs.as_slice()) {
            for (side, value) in ["from", "to"].into_iter().zip(edges) {
                let name = format!("{}.leg{leg}_{side}_mm", t.effect);
                // Its profile-likelihood half-width, when the report has it.
                let sd = d
                    .causes
                    .iter()
                    .flat_map(|c| &c.parameters)
                    .find(|p| p.name == name && p.value == value)
                    .and_then(|p| p.std_dev);
                effects.insert(name, json!({"value": value, "std_dev": sd}));
            }
        }
    }
    effects
}

/// The vocabulary, from the registry: each effect, its physics, its
/// parameters (units in the names) and where a written machine puts it
/// (`tricept diagnose --help`).
///
/// # Example
/// ```
/// let help = tricept_ident::diagnosis::vocabulary_help();
/// assert!(help.contains("leg-lead"));
/// ```
pub fn vocabulary_help() -> String {
    let lines: Vec<String> = tricept_model::effects::EffectName::ALL
        .iter()
        .map(|e| {
            let s = e.spec();
            let params = e.parameter_names();
            format!(
                "  {}: {}{}; in a written machine file: {}",
                s.name,
                s.physics.replace('`', ""),
                if params.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", params.join(", "))
                },
                s.deployment.label()
            )
        })
        .collect();
    format!("Effects of the vocabulary:\n{}", lines.join("\n"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::EXIT_INPUT;
    use crate::inputs::{SensorNoise, load_machine};

    const DATA: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/data/table2-grid-seed1.csv"
    );

    #[test]
    fn data_in_memory_diagnose_as_their_file_and_only_a_file_is_recorded() {
        let m = load_machine(None, &SensorNoise::default()).unwrap();
        let from_file = diagnose(DiagnoseRequest::new(DATA).machine(m.clone())).unwrap();
        let data = tricept_data::read_path(Path::new(DATA)).unwrap();
        let from_memory = diagnose(DiagnoseRequest::new(data).machine(m)).unwrap();
        assert_eq!(from_file.to_json(), from_memory.to_json());
        assert_eq!(from_file.exit_code(), EXIT_OK);
        assert!(from_file.reason().is_none());
        let out =
            std::env::temp_dir().join(format!("tricept-door-diagnose-{}.json", std::process::id()));
        let e = from_memory
            .write_machine(&out, WriteOptions::default())
            .unwrap_err();
        assert_eq!(e.exit_code(), EXIT_INPUT);
        assert!(!out.exists());
        let written = from_file
            .write_machine(&out, WriteOptions::default())
            .unwrap();
        assert_eq!((written.path(), written.forced()), (out.as_path(), None));
        let written = load_machine(Some(&out), &SensorNoise::default()).unwrap();
        let record = written.description().calibration.as_ref().unwrap();
        assert_eq!(record.method, "diagnose");
        assert!(record.adequate && !record.forced);
        std::fs::remove_file(&out).ok();
    }

    #[test]
    fn a_bad_temperature_noise_is_an_input_error() {
        let m = load_machine(None, &SensorNoise::default()).unwrap();
        let mut r = DiagnoseRequest::new(DATA).machine(m);
        r.temperature_noise_k = Some(-1.0);
        let e = diagnose(r).unwrap_err();
        assert_eq!(e.exit_code(), EXIT_INPUT);
        assert_eq!(e.setting(), Some(Setting::TemperatureNoise));
        assert!(e.message().starts_with("temperature_noise: "));
    }
}
