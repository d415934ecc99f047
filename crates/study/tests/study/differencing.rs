//! Differencing against a reference pose, as the paper's solve does,
//! against estimating the sensor offsets: with the covariance the
//! differencing introduces, the two are the same estimator (whatever the
//! reference); with the differenced rows treated as independent, the
//! estimate is noisier, as Gauss-Markov says it must be.

use nalgebra::DMatrix;
use tricept_kinematics::{Machine, description::AxisOrder};
use tricept_study::Scenario;
use tricept_study::paper::{Differenced, DifferencedSolve, NominalLinearisation, RowWeights};

fn formed(
    lin: &NominalLinearisation,
    columns: &[usize],
    reference: usize,
    w: RowWeights,
) -> DMatrix<f64> {
    match DifferencedSolve::form(lin, columns, reference, w).unwrap() {
        Differenced::Formed(d) => d.operator,
        Differenced::Singular { condition } => panic!("singular (condition {condition:.1e})"),
    }
}

/// `Op diag(sigma^2) Op^T`: the covariance of an estimate `Op y`.
fn covariance(op: &DMatrix<f64>, sigma: [f64; 3]) -> DMatrix<f64> {
    let scaled = DMatrix::from_fn(op.nrows(), op.ncols(), |i, r| op[(i, r)] * sigma[r % 3]);
    &scaled * scaled.transpose()
}

#[test]
fn differencing_with_its_covariance_is_estimating_the_offsets() {
    let m = Machine::paper().with_axis_order(AxisOrder::YFirst);
    let s = Scenario::paper(m.clone(), m.workspace.polar_grid(2, 8, 3)).unwrap();
    let lin = NominalLinearisation::new(&s).unwrap();
    let sigma = s.logged_sigma(0.8);
    let k = s.set.len();
    let all: Vec<usize> = (0..k).collect();
    let rows = lin.rows();

    // Offsets as unknowns: A = diag(1 / sigma) [E | J], E picking each
    // reading's sensor; the parameter rows of (A^T A)^{-1} A^T diag(1 / sigma).
    let a = DMatrix::from_fn(rows, 3 + k, |r, t| {
        let value = if t < 3 {
            f64::from(u8::from(r % 3 == t))
        } else {
            lin.jacobian[(r, t - 3)]
        };
        value / sigma[r % 3]
    });
    let ata_inv = (a.transpose() * &a).try_inverse().unwrap();
    let weighted_at = DMatrix::from_fn(3 + k, rows, |t, r| a[(r, t)] / sigma[r % 3]);
    let offsets = (ata_inv * weighted_at).rows(3, k).into_owned();

    for reference in [0, rows / 6] {
        let gls = formed(
            &lin,
            &all,
            reference,
            RowWeights::DifferencedCovariance(sigma),
        );
        let gap = (&gls - &offsets).amax() / offsets.amax();
        assert!(gap < 1e-8, "reference {reference}: relative gap {gap:.1e}");
    }

    // Treating the differenced rows as independent: a valid estimator
    // (exact on noise-free data) whose covariance exceeds the optimum's by
    // a positive semi-definite matrix, and not by rounding.
    let gls_cov = covariance(&offsets, sigma);
    let independent = formed(
        &lin,
        &all,
        0,
        RowWeights::PerSensor(sigma.map(|x| 1.0 / (x * x))),
    );
    let excess = covariance(&independent, sigma) - &gls_cov;
    let lowest = excess.symmetric_eigenvalues().min();
    assert!(
        lowest >= -1e-9 * gls_cov.amax(),
        "lowest eigenvalue {lowest:.2e}"
    );
    let ratio = covariance(&independent, sigma).trace() / gls_cov.trace();
    assert!(ratio > 1.2, "variance ratio {ratio:.3}");
}
