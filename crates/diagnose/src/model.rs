//! The geometric model extended by unmodelled effects: the reading model
//! that the diagnosis fits for each candidate cause, effects of the
//! vocabulary and generic terms of the dictionary ([`crate::terms`]) alike.
//!
//! Each term adds its parameters with the physics of the registry
//! ([`tricept_model::effects`], the same as the plant simulator's): leg
//! terms change the actual leg lengths (their Jacobian columns are
//! `J1^-1 e_i dq_i/dparam`), reading terms change the readings (direct
//! columns), both through their `(parameter, Basis, value)` entries;
//! class-2 effects change the UP limb's kinematics (columns by central
//! differences of the exact model). Context-free constant parts (a leg's
//! mean thermal growth, a constant backlash...) are absorbed by the
//! geometric `dq_i` and the sensor offsets; thermal growth is referred to
//! the metrology reference temperature of 20 °C
//! ([`tricept_model::effects::REFERENCE_TEMPERATURE_C`]).

use std::sync::Arc;

use crate::terms::{Frame, Term, TermKind};
use tricept_data::MeasuredPose;
use tricept_engine::{
    model::GeometricModel, model::GeometricPredictor, model::PosePredictor, model::ReadingModel,
    model::solve_pose,
};
use tricept_kinematics::{KinematicsError, Machine, up_limb::UpJoints};
use tricept_model::effects::{Basis, CauseName, EffectName, Entries, Kind};

/// The geometric model plus the parameters of some terms: effects of the
/// vocabulary and generic terms of the dictionary.
#[derive(Debug, Clone)]
pub struct ExtendedModel {
    geometric: GeometricModel,
    terms: Vec<Term>,
    names: Vec<String>,
    /// The campaign frame of the generic terms.
    frame: Arc<Frame>,
    /// The same terms on the geometric model's rank reference, when it has
    /// one: the rank decision of a calibrated machine is the nominal's.
    rank_reference: Option<Box<ExtendedModel>>,
}

impl ExtendedModel {
    /// `geometric` extended by `effects` of the vocabulary.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_diagnose::ExtendedModel;
use tricept_engine::{model::GeometricModel, model::ReadingModel};
use tricept_model::effects::EffectName;
let g = GeometricModel::new(tricept_kinematics::Machine::paper(), tricept_model::ParameterSet::paper15());
let m = ExtendedModel::new(g, &[EffectName::Thermal]);
assert_eq!(m.names().last().unwrap(), "thermal.expansion_ppm_per_k");
```
"#
    )]
    pub fn new(geometric: GeometricModel, effects: &[EffectName]) -> ExtendedModel {
        let terms: Vec<Term> = effects.iter().map(|e| Term::Catalogue(*e)).collect();
        ExtendedModel::with_terms(geometric, &terms, Arc::new(Frame::empty()))
    }

    /// `geometric` extended by `terms`, the generic ones measured in `frame`.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use std::sync::Arc;
use tricept_diagnose::{ExtendedModel, terms::Frame, terms::GenericFamily, terms::GenericTerm, terms::Scope, terms::Term};
use tricept_engine::{model::GeometricModel, model::ReadingModel};
let m = tricept_kinematics::Machine::paper();
let data = tricept_data::read_path("../../fixtures/data/diagnose-pitch.csv".as_ref()).unwrap();
let pitch = Term::Generic(GenericTerm {
    family: GenericFamily::LegPeriodic,
    scope: Scope::AllLegs,
    period_mm: Some(10.0),
    edges_mm: None,
});
// A worn segment of leg 2's screw from 750 to 900 mm of command.
let step = Term::Generic(GenericTerm {
    edges_mm: Some([750.0, 900.0]),
    ..GenericTerm::new(GenericFamily::LegStep, Scope::Leg(1))
});
let g = GeometricModel::new(m.clone(), tricept_model::ParameterSet::paper15());
let model = ExtendedModel::with_terms(g, &[pitch, step], Arc::new(Frame::of(&m, &data)));
assert_eq!(model.names().len(), 15 + 6 + 1);
assert_eq!(model.names()[15], "leg-periodic.leg1_sin_um");
assert_eq!(model.names()[21], "leg-step.leg2_um");
```
"#
    )]
    pub fn with_terms(
        geometric: GeometricModel,
        terms: &[Term],
        frame: Arc<Frame>,
    ) -> ExtendedModel {
        let mut names = geometric.names().to_vec();
        let mut seen: Vec<CauseName> = Vec::new();
        for t in terms {
            let n = t.name();
            let count = seen.iter().filter(|s| **s == n).count();
            seen.push(n);
            let prefix = if count == 0 {
                n.to_string()
            } else {
                format!("{n}#{}", count + 1)
            };
            names.extend(t.params().iter().map(|p| format!("{prefix}.{p}")));
        }
        let rank_reference = geometric.rank_reference_machine().map(|m| {
            Box::new(ExtendedModel::with_terms(
                GeometricModel::new(m.clone(), geometric.parameter_set().clone()),
                terms,
                frame.clone(),
            ))
        });
        ExtendedModel {
            geometric,
            terms: terms.to_vec(),
            names,
            frame,
            rank_reference,
        }
    }

    /// The same geometric model and frame with other terms.
    pub fn with(&self, terms: &[Term]) -> ExtendedModel {
        ExtendedModel::with_terms(self.geometric.clone(), terms, self.frame.clone())
    }

    /// The geometric part.
    pub fn geometric(&self) -> &GeometricModel {
        &self.geometric
    }

    /// The effects of the vocabulary included.
    pub fn effects(&self) -> Vec<EffectName> {
        self.terms
            .iter()
            .filter_map(|t| match t {
                Term::Catalogue(e) => Some(*e),
                Term::Generic(_) => None,
            })
            .collect()
    }

    /// Every term included.
    pub fn terms(&self) -> &[Term] {
        &self.terms
    }

    /// The campaign frame of the generic terms.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Number of geometric parameters.
    pub fn n_geometric(&self) -> usize {
        self.geometric.names().len()
    }

    /// Index of the first parameter of each term.
    pub fn offsets(&self) -> Vec<usize> {
        let mut at = self.n_geometric();
        self.terms
            .iter()
            .map(|e| {
                let here = at;
                at += e.param_count();
                here
            })
            .collect()
    }

    /// The machine at parameters `p` (geometric errors and class-2 effects).
    pub fn machine_at(&self, p: &[f64]) -> Machine {
        let g = self.n_geometric();
        let mut m = self.geometric.machine_at(&p[..g]);
        for (t, at) in self.terms.iter().zip(self.offsets()) {
            if let Term::Catalogue(e) = t
                && let Kind::Kinematic(apply) = e.spec().kind
            {
                apply(&mut m, &p[at..at + e.parameter_count()]);
            }
        }
        m
    }
}

impl ExtendedModel {
    /// The extra length of each leg (mm) the leg terms add at parameters
    /// `p` for `pose` (its commands and logged context; a context the pose
    /// does not log contributes nothing: the campaign's middle).
    pub(crate) fn leg_extra_mm(
        &self,
        p: &[f64],
        pose: &MeasuredPose,
    ) -> Result<[f64; 3], KinematicsError> {
        let mut legs = [0.0; 3];
        let nominal = self.geometric.nominal();
        for (term, at) in self.terms.iter().zip(self.offsets()) {
            for (k, basis, v) in term.leg_entries(&self.frame, nominal, pose)? {
                if let (Basis::Leg(i), Some(value)) = (basis, p.get(at + k)) {
                    legs[i] += value * v;
                }
            }
        }
        Ok(legs)
    }
}

fn is_kinematic(t: &Term) -> bool {
    t.kind() == TermKind::Kinematic
}

impl ReadingModel for ExtendedModel {
    fn names(&self) -> &[String] {
        &self.names
    }

    fn at<'a>(&'a self, p: &[f64]) -> Box<dyn PosePredictor + 'a> {
        let kinematic: Vec<(usize, Machine, Machine)> = self
            .terms
            .iter()
            .zip(self.offsets())
            .filter(|(e, _)| is_kinematic(e))
            .flat_map(|(e, at)| (at..at + e.param_count()).collect::<Vec<_>>())
            .map(|j| {
                let h = FD_STEP;
                let mut plus = p.to_vec();
                let mut minus = p.to_vec();
                plus[j] += h;
                minus[j] -= h;
                (j, self.machine_at(&plus), self.machine_at(&minus))
            })
            .collect();
        Box::new(ExtendedPredictor {
            model: self,
            p: p.to_vec(),
            geometric: GeometricPredictor::new(self.machine_at(p), self.geometric.parameter_set()),
            kinematic,
        })
    }

    fn rank_reference(&self) -> Option<&dyn ReadingModel> {
        self.rank_reference
            .as_deref()
            .map(|m| m as &dyn ReadingModel)
    }

    /// The geometric model's prior (a batch's), the terms not covered.
    fn prior(&self) -> Option<tricept_engine::prior::Prior> {
        let geometric = self.geometric.prior()?;
        Some(geometric.padded(self.names.len() - geometric.parameters()))
    }
}

/// Step of the central differences for class-2 parameters (arcsec, um).
const FD_STEP: f64 = 1.0;

/// `(parameter index, derivative of the three legs or readings)`.
type Derivative = (usize, [f64; 3]);

struct ExtendedPredictor<'a> {
    model: &'a ExtendedModel,
    p: Vec<f64>,
    /// The geometric model at `p` (with the class-2 effects in its machine).
    geometric: GeometricPredictor<'a>,
    /// Class-2 parameters with their machines at `p +- FD_STEP`.
    kinematic: Vec<(usize, Machine, Machine)>,
}

impl ExtendedPredictor<'_> {
    /// Actual leg lengths at `pose` and their derivatives (per parameter,
    /// per leg) for the leg terms.
    fn legs(&self, pose: &MeasuredPose) -> Result<([f64; 3], Vec<Derivative>), KinematicsError> {
        let mut legs = pose.commands_mm;
        let mut derivs = Vec::new();
        let nominal = self.model.geometric.nominal();
        for (term, at) in self.model.terms.iter().zip(self.model.offsets()) {
            let entries = term.leg_entries(&self.model.frame, nominal, pose)?;
            add(&entries, at, &self.p, &mut legs, &mut derivs, |b| match b {
                Basis::Leg(i) => Some(i),
                Basis::Reading(_) => None,
            });
        }
        Ok((legs, derivs))
    }

    /// Readings from the UP joints, with the reading terms, and the
    /// derivatives of the readings with respect to the reading parameters.
    fn readings(
        &self,
        pose: &MeasuredPose,
        up: &UpJoints,
        p: &[f64],
    ) -> ([f64; 3], Vec<Derivative>) {
        let mut r = up.to_array();
        let mut derivs = Vec::new();
        for (term, at) in self.model.terms.iter().zip(self.model.offsets()) {
            let entries = term.reading_entries(&self.model.frame, pose, up);
            add(&entries, at, p, &mut r, &mut derivs, |b| match b {
                Basis::Reading(c) => Some(c),
                Basis::Leg(_) => None,
            });
        }
        (r, derivs)
    }
}

/// Adds a term's entries (parameters from `at` in `p`) to `values` and
/// their derivatives to `derivs`, one per parameter; `slot` says which of
/// the three values a basis is (entries of the other kind are skipped).
fn add(
    entries: &Entries,
    at: usize,
    p: &[f64],
    values: &mut [f64; 3],
    derivs: &mut Vec<Derivative>,
    slot: impl Fn(Basis) -> Option<usize>,
) {
    let first = derivs.len();
    for &(k, basis, v) in entries {
        let Some(i) = slot(basis) else { continue };
        values[i] += p[at + k] * v;
        match derivs[first..].iter_mut().find(|(j, _)| *j == at + k) {
            Some((_, d)) => d[i] += v,
            None => {
                let mut d = [0.0; 3];
                d[i] = v;
                derivs.push((at + k, d));
            }
        }
    }
}

impl PosePredictor for ExtendedPredictor<'_> {
    fn predict(
        &self,
        pose: &MeasuredPose,
        seed: &mut Option<UpJoints>,
        jacobian: &mut [f64],
    ) -> Result<[f64; 3], KinematicsError> {
        let k = self.p.len();
        let (legs, leg_derivs) = self.legs(pose)?;
        jacobian.iter_mut().for_each(|v| *v = 0.0);
        // The geometric columns, at the actual leg lengths.
        let (up, geometry) = self.geometric.solve(&legs, seed, jacobian, k)?;
        // Leg effects: d(up)/d(leg i) is column i of J1^-1.
        if !leg_derivs.is_empty() {
            let j1_inv = geometry
                .j1()
                .try_inverse()
                .ok_or(KinematicsError::Singular {
                    condition: f64::INFINITY,
                    limit: tricept_kinematics::error::SINGULARITY_CONDITION_LIMIT,
                })?;
            for (j, d) in &leg_derivs {
                let v = j1_inv * nalgebra::Vector3::from(*d);
                for c in 0..3 {
                    jacobian[c * k + j] = v[c];
                }
            }
        }
        let (r, reading_derivs) = self.readings(pose, &up, &self.p);
        for (j, d) in &reading_derivs {
            for c in 0..3 {
                jacobian[c * k + j] += d[c];
            }
        }
        // Class-2 effects by central differences of the exact model.
        for (j, plus, minus) in &self.kinematic {
            let mut s_plus = Some(up);
            let mut s_minus = Some(up);
            let up_p = solve_pose(plus, &legs, &mut s_plus)?;
            let up_m = solve_pose(minus, &legs, &mut s_minus)?;
            let (rp, _) = self.readings(pose, &up_p, &self.p);
            let (rm, _) = self.readings(pose, &up_m, &self.p);
            for c in 0..3 {
                jacobian[c * k + j] = (rp[c] - rm[c]) / (2.0 * FD_STEP);
            }
        }
        Ok(r)
    }
}
