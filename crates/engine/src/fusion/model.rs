//! The fused model: global parameters to an exact machine (module errors,
//! the effects a diagnosis named, head errors), with the analytic Jacobians
//! of the UP limb's readings and of any point fixed to the spindle.
//!
//! Parameters are ordered `[module | effects | head]`. The module is a
//! [`ParameterSet`] (`paper15`, `full21`); effects are the parameters of
//! the registry's effects that say they can be fused
//! ([`EffectSpec::fused`](tricept_model::effects::EffectSpec): a leg or
//! reading term linear in its parameters), with the columns their specs
//! give, the physics of [`tricept_model::effects`] that the plant simulator
//! and the diagnosis use; the head is
//! [`HeadParameterSet::head13`]. A reading or a spindle point is computed
//! on the exact model: FK of the actual module at the actual leg lengths
//! (commands plus `dq` plus the leg effects), then the actual head at the
//! commanded angles plus their zero offsets. Module columns are
//! `point_error_jacobian J E` (eq. 9 composed with the point's derivative),
//! leg effects `dx/dup J1^-1 e_i dL_i`, head columns the head's own
//! analytic Jacobian turned into the base frame.

use std::ops::Range;

use nalgebra::{DMatrix, Matrix3, Vector3};
use tricept_data::external::ExternalPose;
use tricept_kinematics::{KinematicsError, Machine, head::HeadBranch, up_limb::UpJoints};
use tricept_model::effects::{Basis, EffectName, Kind, LegContext as EffectContext};
use tricept_model::{
    ParameterSet, actual::actual_machine, head_errors::Effector, head_errors::HeadAt,
    head_errors::HeadParameterSet, jacobian::point_error_jacobian, params::N_FULL,
};

use crate::error::IdentError;
use crate::model::{GeometricPredictor, solve_pose};

/// The effects the fused model can carry, in registry order: those whose
/// spec says so ([`EffectSpec::fused`](tricept_model::effects::EffectSpec)),
/// leg or reading terms linear in their parameters that need no context
/// column.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::fusion::fusable_effects;
let names: Vec<&str> = fusable_effects().map(|e| e.as_str()).collect();
assert_eq!(names, ["leg-lead", "scale-gain", "compliance"]);
```
"#
)]
pub fn fusable_effects() -> impl Iterator<Item = EffectName> {
    EffectName::ALL.into_iter().filter(|e| e.spec().fused)
}

/// Module errors, effects and head errors of one machine, as one parameter
/// vector.
///
/// # Example
/// ```
/// use tricept_engine::fusion::FusedModel;
/// use tricept_kinematics::Machine;
/// use tricept_model::{ParameterSet, effects::EffectName};
/// let m = FusedModel::new(Machine::paper(), ParameterSet::paper15(), &[EffectName::ScaleGain], true).unwrap();
/// assert_eq!(m.names().len(), 15 + 1 + 13);
/// assert_eq!(m.names()[15], "scale-gain.scale_gain_ppm");
/// assert_eq!(m.head_range(), 16..29);
/// ```
#[derive(Debug, Clone)]
pub struct FusedModel {
    nominal: Machine,
    module: ParameterSet,
    effects: Vec<EffectName>,
    head: Option<HeadParameterSet>,
    names: Vec<String>,
    rank_reference: Option<Box<FusedModel>>,
}

/// What the leg effects need at one record, computed once from the
/// commands on the nominal machine: the extra leg lengths per unit of each
/// leg-effect parameter (the entries of its spec).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct LegContext {
    /// `(global column, d(leg lengths)/d(parameter), mm per unit)`, the
    /// effects in registry order.
    columns: Vec<(usize, Vector3<f64>)>,
}

impl FusedModel {
    /// The model of `nominal` with the module errors of `module`, the
    /// parameters of `effects` (each of [`fusable_effects`], at most once)
    /// and, if `head`, the 13 head errors.
    pub fn new(
        nominal: Machine,
        module: ParameterSet,
        effects: &[EffectName],
        head: bool,
    ) -> Result<FusedModel, IdentError> {
        let mut names = module.names().to_vec();
        let mut seen: Vec<EffectName> = Vec::new();
        for e in effects {
            if !e.spec().fused {
                let can: Vec<&str> = fusable_effects().map(|e| e.as_str()).collect();
                return Err(IdentError::Invalid(format!(
                    "the fused model cannot carry `{e}` (it can: {})",
                    can.join(", ")
                )));
            }
            if seen.contains(e) {
                return Err(IdentError::Invalid(format!("effect `{e}` given twice")));
            }
            seen.push(*e);
            names.extend(e.parameter_names().iter().map(|p| format!("{e}.{p}")));
        }
        let head = head.then(|| HeadParameterSet::head13(&nominal.head));
        if let Some(h) = &head {
            names.extend(h.names().iter().cloned());
        }
        Ok(FusedModel {
            nominal,
            module,
            effects: seen,
            head,
            names,
            rank_reference: None,
        })
    }

    /// The same model, with the rank decision taken on `structural` (at
    /// zero errors) instead of on this model's machine: what a calibrated
    /// machine needs, whose perturbed geometry turns a structurally
    /// invisible parameter (`dyA3` of the paper's machine) into a weakly
    /// visible one that the fit would chase (docs/identifiability.md).
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::FusedModel;
    /// use tricept_kinematics::Machine;
    /// use tricept_model::ParameterSet;
    /// let m = FusedModel::new(Machine::paper(), ParameterSet::paper15(), &[], true)
    ///     .unwrap()
    ///     .with_rank_reference(Machine::paper())
    ///     .unwrap();
    /// assert!(m.rank_reference().is_some());
    /// ```
    pub fn with_rank_reference(mut self, structural: Machine) -> Result<FusedModel, IdentError> {
        let reference = FusedModel::new(
            structural,
            self.module.clone(),
            &self.effects,
            self.head.is_some(),
        )?;
        if reference.names != self.names {
            return Err(IdentError::Invalid(format!(
                "the rank reference has parameters {:?}, the model {:?}",
                reference.names, self.names
            )));
        }
        self.rank_reference = Some(Box::new(reference));
        Ok(self)
    }

    /// The model whose rank decision this one uses, when set by
    /// [`FusedModel::with_rank_reference`].
    pub fn rank_reference(&self) -> Option<&FusedModel> {
        self.rank_reference.as_deref()
    }

    /// Parameter names, `[module | effects | head]`.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Never true for a model with a module.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The nominal machine.
    pub fn nominal(&self) -> &Machine {
        &self.nominal
    }

    /// The module's parameter set.
    pub fn module(&self) -> &ParameterSet {
        &self.module
    }

    /// The effects carried.
    pub fn effects(&self) -> &[EffectName] {
        &self.effects
    }

    /// The head's parameter set, if the head is part of the model.
    pub fn head(&self) -> Option<&HeadParameterSet> {
        self.head.as_ref()
    }

    /// Columns of the module parameters.
    pub fn module_range(&self) -> Range<usize> {
        0..self.module.len()
    }

    /// Columns of the effect parameters.
    pub fn effect_range(&self) -> Range<usize> {
        let n: usize = self.effects.iter().map(|e| e.parameter_names().len()).sum();
        self.module.len()..self.module.len() + n
    }

    /// Columns of the head parameters (empty without a head).
    pub fn head_range(&self) -> Range<usize> {
        let start = self.effect_range().end;
        start..self.names.len()
    }

    /// Index of a parameter by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Column of the first parameter of `effect`, if carried.
    fn effect_column(&self, effect: EffectName) -> Option<usize> {
        let mut at = self.module.len();
        for e in &self.effects {
            if *e == effect {
                return Some(at);
            }
            at += e.parameter_names().len();
        }
        None
    }

    /// The machine described by parameters `p`: module errors and head
    /// errors (the effects are not part of a machine description).
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::FusedModel;
    /// use tricept_kinematics::Machine;
    /// let model = FusedModel::new(Machine::paper(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
    /// let mut p = vec![0.0; model.len()];
    /// p[model.index_of("h2_zero_rad").unwrap()] = 1e-3;
    /// assert_eq!(model.machine_at(&p).head.angle_offsets_rad, [0.0, 1e-3]);
    /// ```
    pub fn machine_at(&self, p: &[f64]) -> Machine {
        let k = self.module.len();
        let mut m = actual_machine(&self.nominal, &self.module.to_errors(&p[..k.min(p.len())]));
        if let Some(h) = &self.head {
            m.head = h.head_at(p.get(self.head_range()).unwrap_or(&[]));
        }
        m
    }

    /// The machine-scale direction: the change of the parameters per unit
    /// `g` when the whole machine (joints, head) is scaled by `1 + g`, the
    /// legs read `1 + g` too long (a lead of `g` on every leg) and the UP
    /// limb's scale `1 / (1 + g)` (a gain of `-g`), to first order: the
    /// registry's structural alias ([`EffectName::structural_aliases`]).
    /// The UP limb's readings cannot see it; `None` unless the model
    /// carries both effects of the alias (`leg-lead` and `scale-gain`) and
    /// the module can represent a scaled machine.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::FusedModel;
    /// use tricept_kinematics::Machine;
    /// use tricept_model::{ParameterSet, effects::EffectName};
    /// let m = FusedModel::new(Machine::paper(), ParameterSet::paper15(),
    ///     &[EffectName::LegLead, EffectName::ScaleGain], true).unwrap();
    /// let v = m.scale_direction().unwrap();
    /// assert_eq!(v[m.index_of("leg-lead.lead2_ppm").unwrap()], 1e6);
    /// assert_eq!(v[m.index_of("dxB3").unwrap()], 288.7);
    /// ```
    pub fn scale_direction(&self) -> Option<Vec<f64>> {
        // The registry's structural alias: a scale gain reads like a scaled
        // machine with a lead on every leg.
        let (common, other, structural) = EffectName::structural_aliases().find(|(c, o, _)| {
            self.effect_column(*c).is_some() && self.effect_column(*o).is_some()
        })?;
        let (per_leg, per_other) = structural.scaled_machine;
        let lead = self.effect_column(common)?;
        let gain = self.effect_column(other)?;
        let errors = tricept_model::GeometricErrors {
            db_mm: self.nominal.base_joints_mm,
            da_mm: self.nominal.platform_joints_mm,
            dq_mm: [0.0; 3],
        };
        let module = self.module.from_errors(&errors).ok()?;
        let mut v = vec![0.0; self.len()];
        v[..module.len()].copy_from_slice(&module);
        for i in 0..common.parameter_count() {
            v[lead + i] = per_leg;
        }
        v[gain] = per_other;
        if let Some(h) = &self.head {
            let range = self.head_range();
            v[range].copy_from_slice(&h.scale_direction());
        }
        Some(v)
    }

    /// Typical sizes of the parameters as a machine is built, in their
    /// units: 0.3 mm for every module parameter (class-1 errors of a few
    /// tenths of a mm), each effect parameter's typical size in the
    /// registry (100 ppm for a lead or a scale gain, 30 um/kN at 1 m for the
    /// compliance: a 12 um sag on the default machine), and
    /// [`tricept_model::head_errors::TYPICAL_HEAD_ERRORS`] for the head. They size the
    /// report's invisible combinations and the priors of planning.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::FusedModel;
    /// let m = FusedModel::new(tricept_kinematics::Machine::paper(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
    /// let t = m.typical_sizes();
    /// assert_eq!((t[0], t[m.index_of("tool_length_mm").unwrap()]), (0.3, 0.3));
    /// ```
    pub fn typical_sizes(&self) -> Vec<f64> {
        let mut t = vec![0.3; self.module.len()];
        for e in &self.effects {
            t.extend(e.spec().parameters.iter().map(|p| p.typical));
        }
        if self.head.is_some() {
            t.extend_from_slice(&tricept_model::head_errors::TYPICAL_HEAD_ERRORS);
        }
        t
    }

    /// The effect whose parameter sits at column `j`, and the parameter's
    /// index in its spec.
    pub(crate) fn effect_parameter(&self, j: usize) -> Option<(EffectName, usize)> {
        let mut at = self.module.len();
        for e in &self.effects {
            let n = e.parameter_count();
            if (at..at + n).contains(&j) {
                return Some((*e, j - at));
            }
            at += n;
        }
        None
    }

    /// The carried effects in registry order, each with the column of its
    /// first parameter.
    fn effect_columns(&self) -> impl Iterator<Item = (EffectName, usize)> + '_ {
        EffectName::ALL
            .into_iter()
            .filter_map(|e| self.effect_column(e).map(|at| (e, at)))
    }

    /// The leg effects' context at leg commands `q`: their specs' entries
    /// on the nominal machine at the commands (a compliance evaluates the
    /// gravity load there).
    pub(crate) fn leg_context(&self, q: &[f64; 3]) -> Result<LegContext, KinematicsError> {
        let mut ctx = LegContext::default();
        let at = EffectContext {
            nominal: &self.nominal,
            commands_mm: *q,
            approach: None,
            temperature_c: None,
        };
        for (e, column) in self.effect_columns() {
            let Kind::Leg(entries) = e.spec().kind else {
                continue;
            };
            let entries = entries(&at)?;
            for j in 0..e.parameter_count() {
                let mut d = Vector3::zeros();
                for (_, basis, value) in entries.iter().filter(|(p, _, _)| *p == j) {
                    if let Basis::Leg(i) = basis {
                        d[*i] += value;
                    }
                }
                ctx.columns.push((column + j, d));
            }
        }
        Ok(ctx)
    }

    /// The model at parameters `p`.
    pub(crate) fn at<'a>(&'a self, p: &'a [f64]) -> FusedAt<'a> {
        FusedAt {
            model: self,
            p,
            geometric: GeometricPredictor::new(self.machine_at(p), &self.module),
            head: self
                .head
                .as_ref()
                .map(|h| h.at(p.get(self.head_range()).unwrap_or(&[]))),
        }
    }

    /// A spindle point (base frame, mm) of the machine at parameters `p`
    /// for a record at `pose`, and its Jacobian with respect to the
    /// parameters (`3 x len`).
    ///
    /// # Example
    /// ```
    /// use tricept_data::external::ExternalPose;
    /// use tricept_engine::fusion::FusedModel;
    /// use tricept_kinematics::Machine;
    /// use tricept_model::head_errors::Effector;
    /// let model = FusedModel::new(Machine::paper(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
    /// let q = Machine::paper().inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0)).unwrap().legs_mm;
    /// let pose = ExternalPose { commands_mm: q, head_rad: [0.0, 0.0] };
    /// let (x, jac) = model.spindle_point(&vec![0.0; model.len()], &pose, &Effector::default()).unwrap();
    /// assert!((x.z - 1100.0).abs() < 1e-9);
    /// // One mm of tool length moves the tip one mm along the tool (here z).
    /// assert!((jac[(2, model.index_of("tool_length_mm").unwrap())] - 1.0).abs() < 1e-12);
    /// ```
    pub fn spindle_point(
        &self,
        p: &[f64],
        pose: &ExternalPose,
        effector: &Effector,
    ) -> Result<(Vector3<f64>, DMatrix<f64>), IdentError> {
        self.check_len(p)?;
        let ctx = self.leg_context(&pose.commands_mm).map_err(kinematics)?;
        let mut jac = vec![0.0; 3 * self.len()];
        let point = self
            .at(p)
            .spindle_point(pose, &ctx, effector, &mut None, &mut jac)
            .map_err(kinematics)?;
        Ok((
            point.position_mm,
            DMatrix::from_row_slice(3, self.len(), &jac),
        ))
    }

    /// The Jacobians (`3 x len`) of the spindle points of `effectors` at
    /// every pose of `poses` for parameters `p`: `[pose][effector]`, with one
    /// model and one FK per pose (the effectors after the first start from
    /// its joints). A pose the model cannot reach is an error naming it.
    ///
    /// # Example
    /// ```
    /// use tricept_data::external::ExternalPose;
    /// use tricept_engine::fusion::FusedModel;
    /// use tricept_kinematics::Machine;
    /// use tricept_model::head_errors::Effector;
    /// let model = FusedModel::new(Machine::paper(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
    /// let q = Machine::paper().inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0)).unwrap().legs_mm;
    /// let pose = ExternalPose { commands_mm: q, head_rad: [0.3, 0.2] };
    /// let p = vec![0.0; model.len()];
    /// let up = Effector { extension_mm: 100.0, ..Effector::default() };
    /// let j = model.spindle_jacobians(&p, &[pose], &[Effector::default(), up]).unwrap();
    /// assert_eq!(j[0][1], model.spindle_point(&p, &pose, &up).unwrap().1);
    /// ```
    pub fn spindle_jacobians(
        &self,
        p: &[f64],
        poses: &[ExternalPose],
        effectors: &[Effector],
    ) -> Result<Vec<Vec<DMatrix<f64>>>, IdentError> {
        self.check_len(p)?;
        let at = self.at(p);
        let mut jac = vec![0.0; 3 * self.len()];
        poses
            .iter()
            .enumerate()
            .map(|(i, pose)| {
                let ctx = self.leg_context(&pose.commands_mm).map_err(kinematics)?;
                let mut seed = None;
                effectors
                    .iter()
                    .map(|e| {
                        at.spindle_point(pose, &ctx, e, &mut seed, &mut jac)
                            .map_err(|source| IdentError::Kinematics {
                                pose: i,
                                line: 0,
                                source,
                            })?;
                        Ok(DMatrix::from_row_slice(3, self.len(), &jac))
                    })
                    .collect()
            })
            .collect()
    }

    /// Leg commands and commanded head angles that put the tool tip at
    /// `tip_mm` along `axis` on the machine at parameters `p`: the tool-pose
    /// IK of [`FusedModel::machine_at`], then the leg effects inverted
    /// (compensation).
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::FusedModel;
    /// use tricept_kinematics::{head::HeadBranch, Machine};
    /// use tricept_model::{ParameterSet, effects::EffectName};
    /// let model = FusedModel::new(Machine::paper(), ParameterSet::paper15(), &[EffectName::LegLead], true).unwrap();
    /// let mut p = vec![0.0; model.len()];
    /// p[model.index_of("leg-lead.lead1_ppm").unwrap()] = 120.0;
    /// p[model.index_of("h1_zero_rad").unwrap()] = 4e-4;
    /// let tip = nalgebra::Vector3::new(100.0, -50.0, 1100.0);
    /// let pose = model.tool_commands(&p, &tip, &nalgebra::Vector3::new(0.2, 0.1, 1.0), HeadBranch::default()).unwrap();
    /// // Commanded so, the model's tool tip is where it was asked to be.
    /// let (reached, _) = model.spindle_point(&p, &pose, &Default::default()).unwrap();
    /// assert!((reached - tip).norm() < 1e-9);
    /// ```
    pub fn tool_commands(
        &self,
        p: &[f64],
        tip_mm: &Vector3<f64>,
        axis: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<ExternalPose, IdentError> {
        self.check_len(p)?;
        let machine = self.machine_at(p);
        let ik = machine
            .tool_inverse(tip_mm, axis, branch)
            .map_err(kinematics)?;
        let at = self.at(p);
        let mut commands = ik.legs_mm;
        if !self.effects.is_empty() {
            // Commands c with c + effects(c) = the lengths the IK asks for;
            // the effects are ppm-sized, so a few fixed-point rounds suffice.
            for _ in 0..4 {
                let ctx = self.leg_context(&commands).map_err(kinematics)?;
                let legs = at.legs(&commands, &ctx);
                for i in 0..3 {
                    commands[i] -= legs[i] - ik.legs_mm[i];
                }
            }
        }
        Ok(ExternalPose {
            commands_mm: commands,
            head_rad: ik.head_rad,
        })
    }

    fn check_len(&self, p: &[f64]) -> Result<(), IdentError> {
        if p.len() == self.len() {
            Ok(())
        } else {
            Err(IdentError::Invalid(format!(
                "{} parameter values for {} parameters",
                p.len(),
                self.len()
            )))
        }
    }
}

fn kinematics(source: KinematicsError) -> IdentError {
    IdentError::Kinematics {
        pose: 0,
        line: 0,
        source,
    }
}

/// A spindle point of the model and the rotation it turns with.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SpindlePoint {
    /// The point, base frame, mm.
    pub position_mm: Vector3<f64>,
    /// Rotation of the spindle relative to the base frame.
    pub rotation: Matrix3<f64>,
}

/// The fused model at fixed parameters.
pub(crate) struct FusedAt<'a> {
    model: &'a FusedModel,
    p: &'a [f64],
    geometric: GeometricPredictor<'a>,
    head: Option<HeadAt>,
}

impl FusedAt<'_> {
    /// Number of global parameters.
    pub fn len(&self) -> usize {
        self.model.len()
    }

    /// The tool direction of the machine's head at zero head angles.
    pub fn tool_direction(&self) -> Vector3<f64> {
        self.geometric.machine().head.tool_direction
    }

    /// Actual leg lengths at commands `q`: commands plus the leg effects
    /// (the geometric `dq` is part of the machine).
    pub fn legs(&self, q: &[f64; 3], ctx: &LegContext) -> [f64; 3] {
        let mut legs = *q;
        for (j, d) in &ctx.columns {
            for (i, leg) in legs.iter_mut().enumerate() {
                if d[i] != 0.0 {
                    *leg += self.p[*j] * d[i];
                }
            }
        }
        legs
    }

    /// The UP limb's readings without offsets at commands `q` (rad, rad,
    /// mm) and their derivatives, row-major `3 x len` into `jacobian`.
    pub fn readings(
        &self,
        q: &[f64; 3],
        ctx: &LegContext,
        seed: &mut Option<UpJoints>,
        jacobian: &mut [f64],
    ) -> Result<[f64; 3], KinematicsError> {
        let k = self.model.len();
        let has_effects = !self.model.effects.is_empty();
        let legs = if has_effects { self.legs(q, ctx) } else { *q };
        if k > self.model.module.len() {
            jacobian.iter_mut().for_each(|v| *v = 0.0);
        }
        let (up, geometry) = self.geometric.solve(&legs, seed, jacobian, k)?;
        let mut r = up.to_array();
        if has_effects {
            if !ctx.columns.is_empty() {
                let j1_inv = invert(&geometry.j1())?;
                for (j, d) in &ctx.columns {
                    let v = j1_inv * d;
                    for c in 0..3 {
                        jacobian[c * k + j] = v[c];
                    }
                }
            }
            for (e, at) in self.model.effect_columns() {
                let Kind::Reading(entries) = e.spec().kind else {
                    continue;
                };
                for (j, basis, value) in entries(&up) {
                    if let Basis::Reading(c) = basis {
                        r[c] += self.p[at + j] * value;
                        jacobian[c * k + at + j] += value;
                    }
                }
            }
        }
        Ok(r)
    }

    /// The point of `effector` at a record's pose (base frame) with its
    /// derivatives, row-major `3 x len` into `jacobian`.
    pub fn spindle_point(
        &self,
        pose: &ExternalPose,
        ctx: &LegContext,
        effector: &Effector,
        seed: &mut Option<UpJoints>,
        jacobian: &mut [f64],
    ) -> Result<SpindlePoint, KinematicsError> {
        let k = self.model.len();
        let machine = self.geometric.machine();
        let legs = self.legs(&pose.commands_mm, ctx);
        let up = solve_pose(machine, &legs, seed)?;
        let geometry = machine.legs_at(&up);
        let limb = geometry.limb;
        jacobian.iter_mut().for_each(|v| *v = 0.0);
        let local = match &self.head {
            Some(head) => {
                let (local, jh) = head.point_jacobian(pose.head_rad, effector);
                let base = limb.rotation * jh;
                let start = self.model.head_range().start;
                for c in 0..3 {
                    for j in 0..jh.ncols() {
                        jacobian[c * k + start + j] = base[(c, j)];
                    }
                }
                local
            }
            None => {
                let head = &machine.head;
                head.spindle_point(
                    pose.head_rad,
                    &(head.tool_tip_mm
                        + head.tool_direction * effector.extension_mm
                        + effector.offset_mm),
                )
            }
        };
        let x = limb.position_mm + limb.rotation * local;
        let j21 = point_error_jacobian(&geometry, &x)?;
        let km = self.model.module.len();
        let mut block = [0.0; 3 * N_FULL];
        self.model
            .module
            .project(3, |row, f| j21[(row, f)], &mut block[..3 * km]);
        for c in 0..3 {
            jacobian[c * k..c * k + km].copy_from_slice(&block[c * km..(c + 1) * km]);
        }
        if !ctx.columns.is_empty() {
            let dx = limb.point_jacobian(&x) * invert(&geometry.j1())?;
            for (j, d) in &ctx.columns {
                let v = dx * d;
                for c in 0..3 {
                    jacobian[c * k + j] = v[c];
                }
            }
        }
        Ok(SpindlePoint {
            position_mm: x,
            rotation: limb.rotation * machine.head.spindle_rotation(pose.head_rad),
        })
    }
}

fn invert(j1: &Matrix3<f64>) -> Result<Matrix3<f64>, KinematicsError> {
    j1.try_inverse().ok_or(KinematicsError::Singular {
        condition: f64::INFINITY,
        limit: tricept_kinematics::error::SINGULARITY_CONDITION_LIMIT,
    })
}
