//! The design rows of the fused identification: every source's weighted
//! rows at the nominal machine and the information they carry on the
//! global parameters, what planning scores candidate measurements with.

use nalgebra::DMatrix;
use tricept_numerics::linalg::TriangularAccumulator;

use crate::error::IdentError;
use crate::fusion::estimate::in_source;
use crate::fusion::model::FusedModel;
use crate::fusion::source::{Sink, Source};

/// The weighted rows of one source at the nominal machine, with its
/// nuisance at its starting values: what planning scores candidate
/// measurements with (the rows' Jacobians do not depend on the measured
/// values, only on where the machine stood).
#[derive(Debug, Clone, PartialEq)]
pub struct DesignRows {
    /// The source's nuisance parameter names (with its label).
    pub nuisance_names: Vec<String>,
    /// Per record, its rows `[nuisance | global parameters]`, each weighted
    /// by `1 / sigma` (`rows per record x (nuisance + parameters)`).
    pub records: Vec<DMatrix<f64>>,
    /// The source's prior rows (bar length, target offset, stylus), weighted.
    pub priors: DMatrix<f64>,
    /// The redundancy its rows need to check a fit
    /// ([`SourceFit::min_redundancy`](crate::fusion::SourceFit::min_redundancy)).
    pub min_redundancy: f64,
}

/// The rows of `source` at the nominal machine (see [`DesignRows`]).
pub fn design_rows(model: &FusedModel, source: &Source) -> Result<DesignRows, IdentError> {
    let k = model.len();
    let p = vec![0.0; k];
    let at = model.at(&p);
    let rows = source.rows();
    let contexts = source.leg_contexts(model)?;
    let mut seeds = vec![None; rows.records()];
    let nu = rows
        .initial(&at, &contexts, &mut seeds, &vec![true; rows.records()])
        .map_err(|e| in_source(source, e))?;
    let nn = nu.values.len();
    let mut sink = Sink::new(nn, k, rows.data_rows());
    rows.evaluate(&at, &contexts, &nu, &mut seeds, &mut sink)
        .map_err(|e| in_source(source, e))?;
    let kept = sink.take_kept();
    let width = nn + k;
    let mut records: Vec<Vec<f64>> = vec![Vec::new(); rows.records()];
    let mut priors = Vec::new();
    for (record, row) in kept {
        match record {
            Some(j) => records[j].extend_from_slice(&row[..width]),
            None => priors.extend_from_slice(&row[..width]),
        }
    }
    Ok(DesignRows {
        nuisance_names: source.nuisance_names(),
        records: records
            .into_iter()
            .map(|r| DMatrix::from_row_slice(r.len() / width.max(1), width, &r))
            .collect(),
        priors: DMatrix::from_row_slice(priors.len() / width.max(1), width, &priors),
        min_redundancy: rows.min_redundancy(),
    })
}

/// The information the `sources` together carry on the global parameters
/// at the nominal machine, their nuisance projected out, as a square-root
/// factor: rows whose `F^T F` is the information (every source's parameter
/// block of its triangular factor, stacked; `rows x k`, in the
/// parameters' units).
///
/// # Example
/// ```
/// use tricept_engine::fusion::{FusedModel, Source, information, information_factor};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let model = FusedModel::new(m.clone(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
/// let poses = m.workspace.polar_grid(3, 8, 3).iter()
///     .map(|r| tricept_data::MeasuredPose { commands_mm: m.inverse(r).unwrap().legs_mm, ..Default::default() })
///     .collect();
/// let data = tricept_data::Dataset { poses, source: "grid".into() };
/// let sources = [Source::internal(&data, m.sensors.logged_sigma())];
/// let r = information_factor(&model, &sources).unwrap();
/// let f = information(&model, &sources).unwrap();
/// assert!(((r.transpose() * &r) - &f).norm() <= 1e-9 * f.norm());
/// ```
pub fn information_factor(
    model: &FusedModel,
    sources: &[Source],
) -> Result<DMatrix<f64>, IdentError> {
    let k = model.len();
    let parts = sources
        .iter()
        .map(|source| {
            let d = design_rows(model, source)?;
            let nn = d.nuisance_names.len();
            let mut acc = TriangularAccumulator::new(nn + k);
            for m in d.records.iter().chain(std::iter::once(&d.priors)) {
                for i in 0..m.nrows() {
                    let row: Vec<f64> = m.row(i).iter().copied().collect();
                    acc.push_row(&row);
                }
            }
            Ok((nn, acc.finish()))
        })
        .collect::<Result<Vec<_>, IdentError>>()?;
    let mut factor = DMatrix::zeros(k * parts.len(), k);
    for (s, (nn, r)) in parts.iter().enumerate() {
        for i in 0..k {
            for j in 0..k {
                factor[(s * k + i, j)] = r[(nn + i, nn + j)];
            }
        }
    }
    Ok(factor)
}

/// The information the `sources` together carry on the global parameters
/// at the nominal machine, their nuisance projected out: `R^T R` of the
/// union's parameter block (`k x k`, in the parameters' units;
/// [`information_factor`] gives `R`).
///
/// # Example
/// ```
/// use tricept_engine::fusion::{FusedModel, Source, information};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let model = FusedModel::new(m.clone(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
/// let poses = m.workspace.polar_grid(3, 8, 3).iter()
///     .map(|r| tricept_data::MeasuredPose { commands_mm: m.inverse(r).unwrap().legs_mm, ..Default::default() })
///     .collect();
/// let data = tricept_data::Dataset { poses, source: "grid".into() };
/// let f = information(&model, &[Source::internal(&data, m.sensors.logged_sigma())]).unwrap();
/// // The UP limb's readings carry nothing on the head.
/// let head = model.index_of("tool_length_mm").unwrap();
/// assert_eq!(f[(head, head)], 0.0);
/// assert!(f[(0, 0)] > 0.0);
/// ```
pub fn information(model: &FusedModel, sources: &[Source]) -> Result<DMatrix<f64>, IdentError> {
    let r = information_factor(model, sources)?;
    Ok(r.transpose() * r)
}
