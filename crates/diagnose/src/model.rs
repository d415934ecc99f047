//! The geometric model extended by unmodelled effects: the reading model
//! that the diagnosis fits for each candidate cause, effects of the
//! vocabulary and generic terms of the dictionary ([`crate::terms`]) alike.
//!
//! Each [`Candidate`] adds the parameters of one effect, with the same
//! physics as the plant simulator ([`tricept_model::effects`]): leg effects
//! change the actual leg lengths (their Jacobian columns are
//! `J1^-1 e_i dq_i/dparam`), reading effects change the readings (direct
//! columns), class-2 effects change the UP limb's kinematics (columns by
//! central differences of the exact model). Context-free constant parts
//! (a leg's mean thermal growth, a constant backlash...) are absorbed by the
//! geometric `dq_i` and the sensor offsets; thermal growth is referred to
//! the metrology reference temperature of 20 °C.

use std::sync::Arc;

use crate::terms::{Basis, Frame, Term};
use tricept_data::{Dataset, MeasuredPose};
use tricept_ident::{GeometricModel, GeometricPredictor, PosePredictor, ReadingModel, solve_pose};
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{KinematicsError, Machine, UpJoints};
use tricept_model::effects::{
    CauseName, EffectName, add_tube_twist, add_ujoint_axis_errors, backlash_extra_mm,
    compliance_extra_mm, gravity_leg_tension_n, leg_lead_extra_mm, scale_gain_error_mm,
    thermal_extra_mm,
};

/// An effect the diagnosis can fit (every name of the vocabulary except
/// `outliers`, which is handled by row screening).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Candidate(pub EffectName);

/// A logged temperature that varies by less than this over the campaign
/// (K) carries no usable thermal signature: a logger's own noise (0.02 K in
/// the plant simulator) spans about 0.1 K over a few hundred readings.
pub const MIN_TEMPERATURE_RANGE_K: f64 = 0.25;

/// How a parameter enters the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Leg,
    Reading,
    Kinematic,
}

impl Candidate {
    /// Every fittable candidate.
    pub const ALL: [Candidate; 8] = [
        Candidate(EffectName::LegLead),
        Candidate(EffectName::Backlash),
        Candidate(EffectName::Thermal),
        Candidate(EffectName::ScaleGain),
        Candidate(EffectName::EncoderEccentricity),
        Candidate(EffectName::UjointAxes),
        Candidate(EffectName::TubeTwist),
        Candidate(EffectName::Compliance),
    ];

    /// Parameter names (with their unit in the name).
    pub fn params(self) -> &'static [&'static str] {
        self.0.parameter_names()
    }

    pub(crate) fn kind(self) -> Kind {
        match self.0 {
            EffectName::LegLead
            | EffectName::Backlash
            | EffectName::Thermal
            | EffectName::Compliance => Kind::Leg,
            EffectName::ScaleGain | EffectName::EncoderEccentricity => Kind::Reading,
            _ => Kind::Kinematic,
        }
    }

    /// The data column the effect needs, if any.
    pub fn needs(self) -> Option<&'static str> {
        match self.0 {
            EffectName::Backlash => Some("dir1,dir2,dir3"),
            EffectName::Thermal => Some("temp_c"),
            _ => None,
        }
    }

    /// Whether `data` has what the effect needs (and, for the context
    /// columns, some variation in it).
    pub fn available(self, data: &Dataset) -> bool {
        match self.0 {
            EffectName::Backlash => {
                data.poses.iter().all(|p| p.approach.is_some())
                    && (0..3).any(|i| {
                        let dirs: Vec<i8> = data
                            .poses
                            .iter()
                            .filter_map(|p| p.approach.map(|a| a[i]))
                            .collect();
                        dirs.contains(&1) && dirs.contains(&-1)
                    })
            }
            EffectName::Thermal => {
                let t: Vec<f64> = data.poses.iter().filter_map(|p| p.temp_c).collect();
                t.len() == data.poses.len()
                    && t.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                        - t.iter().copied().fold(f64::INFINITY, f64::min)
                        > MIN_TEMPERATURE_RANGE_K
            }
            _ => true,
        }
    }
}

/// The reference temperature of dimensional metrology (ISO 1), °C: the
/// nominal lengths of the machine are taken to hold at it. (Referring the
/// thermal growth to the campaign's own mean temperature instead would leave
/// `alpha (mean - 20 °C) q_i`, a uniform lead error of all legs, unmodelled.)
pub const REFERENCE_TEMPERATURE_C: f64 = 20.0;

/// The geometric model plus the parameters of some terms: effects of the
/// vocabulary and generic terms of the dictionary.
#[derive(Debug, Clone)]
pub struct ExtendedModel {
    geometric: GeometricModel,
    terms: Vec<Term>,
    names: Vec<String>,
    /// The campaign frame of the generic terms.
    frame: Arc<Frame>,
    /// Reference temperature of the nominal lengths, °C.
    temp_ref_c: f64,
    /// The same terms on the geometric model's rank reference, when it has
    /// one: the rank decision of a calibrated machine is the nominal's.
    rank_reference: Option<Box<ExtendedModel>>,
}

impl ExtendedModel {
    /// `geometric` extended by `effects` of the vocabulary.
    ///
    /// # Example
    /// ```
    /// use tricept_diagnose::{Candidate, ExtendedModel};
    /// use tricept_ident::{GeometricModel, ReadingModel};
    /// use tricept_model::effects::EffectName;
    /// let g = GeometricModel::new(tricept_kinematics::Machine::paper(), tricept_model::ParameterSet::paper15());
    /// let m = ExtendedModel::new(g, &[Candidate(EffectName::Thermal)]);
    /// assert_eq!(m.names().last().unwrap(), "thermal.expansion_ppm_per_k");
    /// ```
    pub fn new(geometric: GeometricModel, effects: &[Candidate]) -> ExtendedModel {
        let terms: Vec<Term> = effects.iter().map(|c| Term::Catalogue(*c)).collect();
        ExtendedModel::with_terms(geometric, &terms, Arc::new(Frame::empty()))
    }

    /// `geometric` extended by `terms`, the generic ones measured in `frame`.
    ///
    /// # Example
    /// ```
    /// use std::sync::Arc;
    /// use tricept_diagnose::{ExtendedModel, Frame, GenericFamily, GenericTerm, Scope, Term};
    /// use tricept_ident::{GeometricModel, ReadingModel};
    /// let m = tricept_kinematics::Machine::paper();
    /// let data = tricept_data::read_path("../../fixtures/data/diagnose-pitch.csv".as_ref()).unwrap();
    /// let pitch = Term::Generic(GenericTerm {
    ///     family: GenericFamily::LegPeriodic,
    ///     scope: Scope::AllLegs,
    ///     period_mm: Some(10.0),
    /// });
    /// let g = GeometricModel::new(m.clone(), tricept_model::ParameterSet::paper15());
    /// let model = ExtendedModel::with_terms(g, &[pitch], Arc::new(Frame::of(&m, &data)));
    /// assert_eq!(model.names().len(), 15 + 6);
    /// assert_eq!(model.names()[15], "leg-periodic.leg1_sin_um");
    /// ```
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
            temp_ref_c: REFERENCE_TEMPERATURE_C,
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
    pub fn effects(&self) -> Vec<Candidate> {
        self.terms
            .iter()
            .filter_map(|t| match t {
                Term::Catalogue(c) => Some(*c),
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
                at += e.params().len();
                here
            })
            .collect()
    }

    /// The machine at parameters `p` (geometric errors and class-2 effects).
    pub fn machine_at(&self, p: &[f64]) -> Machine {
        let g = self.n_geometric();
        let mut m = self.geometric.machine_at(&p[..g]);
        for (e, at) in self.terms.iter().zip(self.offsets()) {
            match e {
                Term::Catalogue(Candidate(EffectName::UjointAxes)) => {
                    add_ujoint_axis_errors(&mut m, p[at], p[at + 1])
                }
                Term::Catalogue(Candidate(EffectName::TubeTwist)) => add_tube_twist(&mut m, p[at]),
                _ => {}
            }
        }
        m
    }
}

fn is_kinematic(t: &Term) -> bool {
    matches!(t, Term::Catalogue(c) if c.kind() == Kind::Kinematic)
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
            .flat_map(|(e, at)| (at..at + e.params().len()).collect::<Vec<_>>())
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
    /// per leg) for the leg effects.
    fn legs(&self, pose: &MeasuredPose) -> Result<([f64; 3], Vec<Derivative>), KinematicsError> {
        let mut legs = pose.commands_mm;
        let mut derivs = Vec::new();
        let q = pose.commands_mm;
        for (term, at) in self.model.terms.iter().zip(self.model.offsets()) {
            let e = match term {
                Term::Catalogue(c) => *c,
                Term::Generic(g) => {
                    for (k, (basis, v)) in g
                        .leg_values(&self.model.frame, pose)
                        .into_iter()
                        .enumerate()
                    {
                        if let Basis::Leg(i) = basis {
                            legs[i] += self.p[at + k] * v;
                            let mut d = [0.0; 3];
                            d[i] = v;
                            derivs.push((at + k, d));
                        }
                    }
                    continue;
                }
            };
            match e.0 {
                EffectName::LegLead => {
                    for i in 0..3 {
                        legs[i] += leg_lead_extra_mm(self.p[at + i], q[i]);
                        let mut d = [0.0; 3];
                        d[i] = leg_lead_extra_mm(1.0, q[i]);
                        derivs.push((at + i, d));
                    }
                }
                EffectName::Backlash => {
                    let dir = pose.approach.unwrap_or([1, 1, 1]);
                    for i in 0..3 {
                        legs[i] += backlash_extra_mm(self.p[at + i], dir[i]);
                        let mut d = [0.0; 3];
                        d[i] = backlash_extra_mm(1.0, dir[i]);
                        derivs.push((at + i, d));
                    }
                }
                EffectName::Thermal => {
                    let dt = pose.temp_c.map_or(0.0, |t| t - self.model.temp_ref_c);
                    let d: [f64; 3] = std::array::from_fn(|i| thermal_extra_mm(1.0, q[i], dt));
                    for i in 0..3 {
                        legs[i] += self.p[at] * d[i];
                    }
                    derivs.push((at, d));
                }
                EffectName::Compliance => {
                    let nominal = self.model.geometric.nominal();
                    let up = nominal.forward(&q)?.up;
                    let f = gravity_leg_tension_n(nominal, &up);
                    // compliance c (um/kN at 1 m) = 1000 / stiffness (N/um at 1 m).
                    let d: [f64; 3] =
                        std::array::from_fn(|i| compliance_extra_mm(1000.0, f[i], q[i]));
                    for i in 0..3 {
                        legs[i] += self.p[at] * d[i];
                    }
                    derivs.push((at, d));
                }
                _ => {}
            }
        }
        Ok((legs, derivs))
    }

    /// Readings from the UP joints, with the reading effects, and the
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
            let e = match term {
                Term::Catalogue(c) => *c,
                Term::Generic(g) => {
                    for (k, (basis, v)) in g
                        .reading_values(&self.model.frame, pose, up)
                        .into_iter()
                        .enumerate()
                    {
                        if let Basis::Reading(c) = basis {
                            r[c] += p[at + k] * v;
                            let mut d = [0.0; 3];
                            d[c] = v;
                            derivs.push((at + k, d));
                        }
                    }
                    continue;
                }
            };
            match e.0 {
                EffectName::ScaleGain => {
                    r[2] += scale_gain_error_mm(p[at], up.q4_mm);
                    derivs.push((at, [0.0, 0.0, scale_gain_error_mm(1.0, up.q4_mm)]));
                }
                EffectName::EncoderEccentricity => {
                    let a = RAD_PER_ARCSEC;
                    let (sp, cp) = up.phi_rad.sin_cos();
                    let (st, ct) = up.theta_rad.sin_cos();
                    r[0] += a * (p[at] * sp + p[at + 1] * cp);
                    r[1] += a * (p[at + 2] * st + p[at + 3] * ct);
                    derivs.push((at, [a * sp, 0.0, 0.0]));
                    derivs.push((at + 1, [a * cp, 0.0, 0.0]));
                    derivs.push((at + 2, [0.0, a * st, 0.0]));
                    derivs.push((at + 3, [0.0, a * ct, 0.0]));
                }
                _ => {}
            }
        }
        (r, derivs)
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
                    limit: tricept_kinematics::SINGULARITY_CONDITION_LIMIT,
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
