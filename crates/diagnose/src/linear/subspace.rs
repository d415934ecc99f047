//! Column spaces compared: whether one term's columns lie inside
//! another's, and the largest canonical correlation between two.

use nalgebra::DMatrix;

/// Whether the column space of `a` lies inside that of `b` (every
/// canonical correlation 1 to `1e-6`): `b` generalises `a`.
pub(crate) fn nested(a: &DMatrix<f64>, b: &DMatrix<f64>) -> bool {
    let (Some(ua), Some(ub)) = (column_basis(a), column_basis(b)) else {
        return false;
    };
    ua.ncols() <= ub.ncols()
        && (ua.transpose() * ub)
            .singular_values()
            .iter()
            .all(|s| *s > 1.0 - 1e-6)
}

/// An orthonormal basis of the numerically independent columns of `m`.
fn column_basis(m: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let svd = m.clone().svd(true, false);
    let top = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > 1e-8 * top && top > 0.0)
        .collect();
    let u = svd.u?;
    (!keep.is_empty()).then(|| u.select_columns(&keep))
}

/// Largest canonical correlation between the column spaces of `a` and `b`
/// (1 when they share a direction).
pub(crate) fn canonical_correlation(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    match (column_basis(a), column_basis(b)) {
        (Some(ua), Some(ub)) => (ua.transpose() * ub)
            .singular_values()
            .iter()
            .copied()
            .fold(0.0, f64::max)
            .min(1.0),
        _ => 0.0,
    }
}
