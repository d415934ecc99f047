//! The diagnosis' model deployed into a machine file: the final model's
//! effects of the vocabulary refitted on the poses the diagnosis kept, and
//! every fitted parameter put where the registry says it goes
//! ([`tricept_model::effects::EffectSpec::deployment`]): the machine's leg
//! effects, its UP limb, the controller parameters, or, for sensor-side
//! effects, only the calibration record.

use tricept_data::Dataset;
use tricept_ident::{GeometricModel, Identification, IdentifyOptions, identify};
use tricept_kinematics::Machine;
use tricept_kinematics::description::ControllerDescription;
use tricept_model::ParameterSet;

use crate::error::DeployError;
use crate::model::ExtendedModel;
use crate::report::Diagnosis;

/// The deployable model of a diagnosis, refitted on its clean poses for
/// the record's offsets, covariance and fit quality.
#[derive(Debug, Clone)]
pub struct Deployed {
    /// The final model's identification (its names: the geometric
    /// parameters, then each effect's `effect.parameter`).
    pub id: Identification,
    /// The calibrated machine: geometry, class-2 effects, leg effects.
    pub machine: Machine,
    /// The controller parameters of the dynamic effects, when any is named.
    pub controller: Option<ControllerDescription>,
}

/// Fits the diagnosis' final model (the effects of the vocabulary it
/// carries, [`Diagnosis::model_effects`], on the geometric model) on the
/// poses it kept, with the rank decision of `rank_reference` when
/// `nominal` is itself calibrated, and puts every parameter where it goes
/// in a machine file. The generic terms of a diagnosis are not part of the
/// deployed model (their physics is not in the kinematics): a caller that
/// writes the machine should refuse a diagnosis that names one, as
/// `tricept diagnose --write-machine` does.
///
/// # Example
/// ```
/// use tricept_diagnose::{DiagnoseOptions, deploy, diagnose};
/// use tricept_kinematics::Machine;
/// use tricept_model::ExtendedMachine;
/// let nominal = Machine::paper();
/// let data = tricept_data::read_path("../../fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
/// let d = diagnose(&nominal, &data, &DiagnoseOptions::for_machine(&nominal)).unwrap();
/// assert!(d.final_adequate);
/// let deployed = deploy(&nominal, None, &data, &d).unwrap();
/// // The compliance the diagnosis named is in the machine's leg effects
/// // (the file was simulated with 33.6 N/um at 1 m: 29.8 um/kN).
/// let c = deployed.machine.leg_effects.compliance_um_per_kn_at_1m;
/// assert!((c - 1000.0 / 33.6).abs() < 2.0, "{c}");
/// // The calibrated machine with its leg effects, ready for IK.
/// let machine = ExtendedMachine::new(deployed.machine);
/// let q = machine.inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0)).unwrap().legs_mm;
/// assert!(q.iter().all(|q| (q - 773.4).abs() < 1.0));
/// ```
pub fn deploy(
    nominal: &Machine,
    rank_reference: Option<&Machine>,
    data: &Dataset,
    diagnosis: &Diagnosis,
) -> Result<Deployed, DeployError> {
    let flagged = diagnosis.outlier_lines();
    let clean = data.subset(|j| !flagged.contains(&data.poses[j].line));
    let effects = diagnosis.model_effects();
    let mut geometric = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    if let Some(reference) = rank_reference {
        geometric = geometric.with_rank_reference(reference.clone());
    }
    let model = ExtendedModel::new(geometric, &effects);
    let id = identify(&model, &clean, &IdentifyOptions::for_machine(nominal))?;
    let mut machine = model.machine_at(&id.estimate);
    let mut controller: Option<ControllerDescription> = None;
    for (e, at) in effects.iter().zip(model.offsets()) {
        for index in 0..e.parameter_count() {
            let name = id.names.get(at + index).map_or("", String::as_str);
            let value = id.estimate.get(at + index).copied().unwrap_or(f64::NAN);
            if !e.deploy(index, value, &mut machine, &mut controller) {
                return Err(DeployError::NotDeployable(name.to_string()));
            }
        }
    }
    Ok(Deployed {
        id,
        machine,
        controller,
    })
}
