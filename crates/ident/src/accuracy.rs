//! The accuracy block: what a machine file will deliver, stated by every
//! verb that writes one (`identify`, fused or not, and `diagnose
//! --write-machine`) in its JSON (`accuracy`), its report's first lines and
//! the file's sealed `calibration.accuracy` (`docs/reliability.md`, "The
//! accuracy block"). `tricept_engine::accuracy` makes it; here are the
//! richer model that checks an internal fit's structure and the door's
//! errors.

use std::sync::Arc;

use tricept_data::Dataset;
use tricept_diagnose::{
    ExtendedModel, terms::Frame, terms::GenericFamily, terms::GenericTerm, terms::Scope,
    terms::Term,
};
use tricept_engine::accuracy::{Fit, PromiseError};
use tricept_engine::{Identification, IdentifyOptions, model::GeometricModel};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;

use crate::error::Error;

/// The accuracy a machine file will deliver: the predicted rms positioning
/// error over the workspace and a 95 % upper bound of it (mm), the point
/// positioned, and the parts it is made of (added in quadrature).
///
/// # Example
/// ```
/// use tricept_ident::calibrate::Accuracy;
/// let a = Accuracy::combine("platform", &[(0.003, 0.005), (0.004, 0.012)], serde_json::Map::new());
/// assert!((a.rms_mm - 0.005).abs() < 1e-15); // 3 and 4 um in quadrature
/// assert!((a.upper_mm - 0.013).abs() < 1e-15);
/// assert!(a.line().starts_with("accuracy this file will deliver: 0.0050 mm rms at the platform"));
/// ```
#[doc(inline)]
pub use tricept_engine::accuracy::Accuracy;
pub(crate) use tricept_engine::accuracy::fused::{fused_structure, head_scale, of_fusion};

/// The promise of `id`, fitted with `model` on `data` (logged noise in
/// `options`) on machine `m`: its first `set.len()` parameters are the
/// geometry of `set`, the rest deployed terms; the same model with every
/// leg also a polynomial in its command checks its geometric estimate;
/// with the report's line ([`Accuracy::line`]).
pub(crate) fn of_fit(
    m: &Machine,
    set: &ParameterSet,
    model: &ExtendedModel,
    id: &Identification,
    data: &Dataset,
    options: &IdentifyOptions,
    tolerance_mm: f64,
) -> Result<(Accuracy, String), Error> {
    let legs = Term::Generic(GenericTerm::new(
        GenericFamily::LegPolynomial,
        Scope::AllLegs,
    ));
    let rich = model.with(&[model.terms(), &[legs]].concat());
    let fit = Fit {
        machine: m,
        set,
        model,
        rich: &rich,
        id,
        data,
        options,
    };
    tricept_engine::accuracy::of_fit_stated(&fit, tolerance_mm).map_err(|e| match e {
        PromiseError::Ident(e) => Error::with_context("accuracy", e),
        e => Error::other(e.to_string()),
    })
}

/// The promise of an internal calibration: [`of_fit`] on the model of
/// `geometric`'s set on `m` alone ([`geometric_base`]), made in one call.
pub(crate) fn of_geometric_fit(
    geometric: &GeometricModel,
    m: &Machine,
    id: &Identification,
    data: &Dataset,
    options: &IdentifyOptions,
    tolerance_mm: f64,
) -> Result<(Accuracy, String), Error> {
    let base = geometric_base(geometric, m, data);
    of_fit(
        m,
        geometric.parameter_set(),
        &base,
        id,
        data,
        options,
        tolerance_mm,
    )
}

/// The model of `set` on `m` alone, in `data`'s frame: the base of an
/// internal calibration's structure part.
pub(crate) fn geometric_base(
    geometric: &GeometricModel,
    m: &Machine,
    data: &Dataset,
) -> ExtendedModel {
    ExtendedModel::with_terms(geometric.clone(), &[], Arc::new(Frame::of(m, data)))
}
