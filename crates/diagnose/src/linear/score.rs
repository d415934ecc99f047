//! How much a term explains of a target: the score from the three
//! products `Q^T G`, `G^T G` and `G^T t` (see the module docs of
//! [`crate::linear`]), and the sums over poses they are built from.

use nalgebra::{DMatrix, DVector};

/// Numerical rank threshold of a term's projected columns: an eigenvalue of
/// `M` below this share of the largest squared column norm of `G` is a
/// direction the fitted model already absorbs.
const ABSORBED: f64 = 1e-10;

/// Sums over poses of the products a score needs, for `k` columns and `p`
/// basis columns: `X^T G` (`p x k`, column-major), the upper triangle of
/// `G^T G` (row-major) and `G^T t`.
pub(super) struct Sums {
    pub(super) xtg: Vec<f64>,
    pub(super) gtg: Vec<f64>,
    pub(super) gtt: Vec<f64>,
}

impl Sums {
    pub(super) fn zero(p: usize, k: usize) -> Sums {
        Sums {
            xtg: vec![0.0; p * k],
            gtg: vec![0.0; k * k],
            gtt: vec![0.0; k],
        }
    }

    pub(super) fn add(&mut self, other: &Sums) {
        for (a, b) in [
            (&mut self.xtg, &other.xtg),
            (&mut self.gtg, &other.gtg),
            (&mut self.gtt, &other.gtt),
        ] {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
    }
}

/// How much a term explains of a target.
#[derive(Debug, Clone)]
pub(crate) struct Score {
    /// Explained sum of squares (noise units squared).
    pub(crate) explained: f64,
    /// Numerical rank of the term's new directions.
    pub(crate) rank: usize,
    /// Least-squares coefficients of the term's columns (its parameters).
    pub(crate) coefficients: DVector<f64>,
    /// Their covariance in noise units (`M^+`).
    pub(crate) covariance: DMatrix<f64>,
}

impl Score {
    fn none(k: usize) -> Score {
        Score {
            explained: 0.0,
            rank: 0,
            coefficients: DVector::zeros(k),
            covariance: DMatrix::zeros(k, k),
        }
    }
}

/// The score from the three products (see the module docs).
pub(crate) fn score_from(
    qtg: &DMatrix<f64>,
    gtg: &DMatrix<f64>,
    gtt: &DVector<f64>,
    qtt: &DVector<f64>,
) -> Score {
    let k = gtg.nrows();
    let m = gtg - qtg.transpose() * qtg;
    let v = gtt - qtg.transpose() * qtt;
    let scale = (0..k).map(|i| gtg[(i, i)]).fold(0.0, f64::max);
    let mut out = Score::none(k);
    if !(scale > 0.0 && scale.is_finite()) {
        return out;
    }
    let m = (&m + m.transpose()) * 0.5;
    let eig = m.symmetric_eigen();
    for (i, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda > ABSORBED * scale {
            let u = eig.eigenvectors.column(i);
            let c = u.dot(&v);
            out.explained += c * c / lambda;
            out.rank += 1;
            out.coefficients += u * (c / lambda);
            out.covariance += u * u.transpose() / lambda;
        }
    }
    out
}
