//! The linearisation's scores against explicit ones: the scans against
//! scoring each period and segment, scores without `Q` against an explicit
//! `Q`, the same bits at any thread count and vector width.

use nalgebra::{DMatrix, DVector};

use super::kernels::sums4;
use super::linearisation::Linearisation;
use super::score::{Score, score_from};
use super::subspace::canonical_correlation;
use rand::{RngExt, SeedableRng};
use tricept_model::effects::{periodic_extra_mm, segment_extra_mm};

/// An orthonormal basis of the column space of `a` (thin QR).
fn orthonormal_basis(a: &DMatrix<f64>) -> DMatrix<f64> {
    a.clone().qr().q()
}

/// A linearisation of `n` random poses: random fitted columns,
/// directions and target, and leg commands over 600-1000 mm.
fn synthetic(n: usize, seed: u64) -> (Linearisation, Vec<[f64; 3]>) {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut normal = || rng.random_range(-1.0..1.0);
    let width = 7;
    let rows: Vec<f64> = (0..3 * n * width).map(|_| normal()).collect();
    let target = DVector::from_fn(3 * n, |_, _| normal());
    let directions: Vec<[[f64; 3]; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| std::array::from_fn(|_| normal())))
        .collect();
    let weights = [2.0 + normal(), 0.5, 3.0];
    let commands: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| 800.0 + 200.0 * normal()))
        .collect();
    let mut lin = Linearisation {
        rows,
        width,
        x_params: (0..4).collect(),
        basis: Vec::new(),
        r: DMatrix::zeros(0, 0),
        target: target.clone(),
        ups: Vec::new(),
        directions,
        weights,
        qtt: DVector::zeros(0),
        extra: DMatrix::zeros(3 * n, 0),
        extra_terms: Vec::new(),
    };
    lin.set_basis(&[]);
    // A target with a periodic part on leg 2 (period 10 mm), so that
    // the scores range from noise to signal.
    let signal = lin.dense(&[(
        1,
        (0..n)
            .map(|j| 3.0 * periodic_extra_mm(1000.0, 300.0, 10.0, commands[j][1]))
            .collect(),
    )]);
    lin.set_target(target + signal.column(0));
    (lin, commands)
}

/// A scan's `(explained, rank)` equals the direct score to rounding.
fn assert_same_score(scan: (f64, usize), direct: &Score, what: &str) {
    assert_eq!(scan.1, direct.rank, "{what}");
    let tolerance = 1e-9 * direct.explained.max(1.0);
    assert!(
        (scan.0 - direct.explained).abs() <= tolerance,
        "{what}: scan {} against {}",
        scan.0,
        direct.explained
    );
}

#[test]
fn the_periodic_scan_equals_scoring_each_period() {
    // 700 poses: several blocks, the last one partial.
    let (lin, commands) = synthetic(700, 5);
    let (f0, step, count) = (1.0 / 50.0, 1.0 / 1600.0, 140);
    for legs in [vec![0, 1, 2], vec![1]] {
        let scan = lin.periodic_scan(&commands, &legs, f0, step, count);
        assert_eq!(scan.len(), count);
        let mut best = (0, f64::MIN);
        for (k, &(explained, rank)) in scan.iter().enumerate() {
            let period = 1.0 / (f0 + k as f64 * step);
            let cols: Vec<(usize, Vec<f64>)> = legs
                .iter()
                .flat_map(|&i| {
                    let at = |a: f64, b: f64| -> Vec<f64> {
                        commands
                            .iter()
                            .map(|q| periodic_extra_mm(a, b, period, q[i]))
                            .collect()
                    };
                    [(i, at(1.0, 0.0)), (i, at(0.0, 1.0))]
                })
                .collect();
            let direct = lin.score_columns(&cols);
            assert_same_score((explained, rank), &direct, &format!("frequency {k}"));
            let one = lin.periodic_score(&commands, &legs, f0 + k as f64 * step);
            assert_same_score(one, &direct, &format!("frequency {k} alone"));
            if explained > best.1 {
                best = (k, explained);
            }
        }
        // The hidden 10 mm period on leg 2 is grid frequency 128.
        assert_eq!(best.0, 128, "{legs:?}");
    }
}

#[test]
fn scores_without_q_equal_those_with_an_explicit_q() {
    let (mut lin, commands) = synthetic(900, 11);
    // Columns of very different sizes, as offsets (rad) and parameters
    // (mm) are in noise units.
    let width = lin.width;
    for (i, v) in lin.rows.iter_mut().enumerate() {
        *v *= 10f64.powi((i % width) as i32 - 2);
    }
    let n = lin.poses();
    let x = DMatrix::from_fn(3 * n, width, |i, c| lin.row(i)[c]);
    let cols: Vec<(usize, Vec<f64>)> = [(0, 0.0), (0, 1.0), (2, 0.0), (4, 0.0)]
        .iter()
        .map(|&(b, phase)| {
            let leg = if b < 3 { b } else { 1 };
            let values = commands
                .iter()
                .map(|q| periodic_extra_mm(1.0 - phase, phase, 37.0, q[leg]))
                .collect();
            (b, values)
        })
        .collect();
    for drop in [vec![], vec![1]] {
        lin.set_basis(&drop);
        let keep: Vec<usize> = (0..width)
            .filter(|&c| c < 3 || !drop.contains(&(c - 3)))
            .collect();
        let q = orthonormal_basis(&x.select_columns(&keep));
        let g = lin.dense(&cols);
        let t = &lin.target;
        let explicit = score_from(
            &(q.transpose() * &g),
            &(g.transpose() * &g),
            &(g.transpose() * t),
            &(q.transpose() * t),
        );
        for s in [lin.score_columns(&cols), lin.score_dense(&g)] {
            assert_eq!(s.rank, explicit.rank, "{drop:?}");
            let tolerance = 1e-9 * explicit.explained.max(1.0);
            assert!(
                (s.explained - explicit.explained).abs() <= tolerance,
                "{drop:?}: {} against {}",
                s.explained,
                explicit.explained
            );
            let dc = (&s.coefficients - &explicit.coefficients).norm();
            assert!(dc <= 1e-9 * explicit.coefficients.norm(), "{drop:?}: {dc}");
        }
        let projected = &g - &q * (q.transpose() * &g);
        let dp = (lin.project(&g) - &projected).norm();
        assert!(dp <= 1e-9 * g.norm(), "{drop:?}: {dp}");
        // A design column projects to nothing once in the basis, and to
        // its own residual when dropped.
        let own = lin.projected_columns(&[1]);
        let column = x.column(4).into_owned();
        let expected = if drop.is_empty() {
            DVector::zeros(3 * n)
        } else {
            &column - &q * (q.transpose() * &column)
        };
        assert!((own.column(0) - expected).norm() <= 1e-9 * column.norm());
    }
}

#[test]
fn the_step_scan_equals_scoring_each_segment() {
    // 700 poses over 600-1000 mm; cuts every 25 mm over that range.
    let (lin, commands) = synthetic(700, 11);
    let cuts: Vec<f64> = (0..=16).map(|k| 600.0 + 25.0 * f64::from(k)).collect();
    for leg in 0..3 {
        let prefix = lin.step_prefix(&commands, leg, &cuts);
        assert_eq!(prefix.len(), cuts.len());
        for u in 0..cuts.len() {
            for v in u + 1..cuts.len() {
                let (explained, rank, inside) = lin.step_score(&prefix, u, v);
                let column: Vec<f64> = commands
                    .iter()
                    .map(|q| segment_extra_mm(1.0, cuts[u], cuts[v], q[leg]))
                    .collect();
                let expected_inside = column.iter().filter(|v| **v != 0.0).count();
                assert_eq!(inside, expected_inside, "leg {leg} cuts {u}-{v}");
                let direct = lin.score_columns(&[(leg, column)]);
                assert_same_score(
                    (explained, rank),
                    &direct,
                    &format!("leg {leg} cuts {u}-{v}"),
                );
            }
        }
        // A segment the wrong way round, or of one cut, is empty.
        assert_eq!(lin.step_score(&prefix, 5, 3), (0.0, 0, 0));
        assert_eq!(lin.step_score(&prefix, 4, 4), (0.0, 0, 0));
    }
}

#[test]
fn the_periodic_scan_has_the_same_bits_at_any_thread_count() {
    let (lin, commands) = synthetic(3000, 8);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| lin.periodic_scan(&commands, &[0, 1, 2], 0.02, 1.0 / 1600.0, 40))
    };
    let one = run(1);
    for threads in [2, 3] {
        let other = run(threads);
        assert!(
            one.iter()
                .zip(&other)
                .all(|(a, b)| a.0.to_bits() == b.0.to_bits() && a.1 == b.1),
            "{threads} threads"
        );
    }
}

#[test]
fn vector_sums_have_the_bits_of_the_scalar_ones() {
    fn sums<S: pulp::Simd>(simd: S, x: &[f64], y: &[f64], w: &[f64]) -> [f64; 2] {
        sums4(
            simd,
            [x, y, w],
            |[x, y, w]| {
                [
                    simd.mul_f64s(*x, *y),
                    simd.mul_f64s(simd.mul_f64s(*x, *y), *w),
                ]
            },
            |[x, y, w]| [x * y, x * y * w],
        )
    }
    for len in [0, 3, 4, 9, 256, 1001] {
        let v = |k: f64| -> Vec<f64> { (0..len).map(|i| (i as f64 * k).sin()).collect() };
        let (x, y, w) = (v(0.3), v(1.7), v(2.9));
        let scalar = sums(pulp::Scalar::new(), &x, &y, &w);
        let naive: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        assert!(
            (scalar[0] - naive).abs() <= 1e-12 * (len as f64 + 1.0),
            "{len}"
        );
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            let vector = sums(simd, &x, &y, &w);
            assert_eq!(vector.map(f64::to_bits), scalar.map(f64::to_bits), "{len}");
        }
    }
}

#[test]
fn score_is_the_explained_sum_of_squares() {
    // x = [1, 1, 1, 1]^T (fitted), g = [0, 1, 2, 3]^T, t = g - mean(g) + noise.
    let x = DMatrix::from_column_slice(4, 1, &[1.0, 1.0, 1.0, 1.0]);
    let q = orthonormal_basis(&x);
    let g = DMatrix::from_column_slice(4, 1, &[0.0, 1.0, 2.0, 3.0]);
    let t = DVector::from_column_slice(&[-1.5, -0.5, 0.5, 1.5]) * 2.0;
    let s = score_from(
        &(q.transpose() * &g),
        &(g.transpose() * &g),
        &(g.transpose() * &t),
        &(q.transpose() * &t),
    );
    // t lies in span(x, g): everything is explained, with coefficient 2.
    assert!((s.explained - t.norm_squared()).abs() < 1e-12);
    assert_eq!(s.rank, 1);
    assert!((s.coefficients[0] - 2.0).abs() < 1e-12);
    // A column inside span(x) explains nothing and has no rank.
    let s = score_from(
        &(q.transpose() * &x),
        &(x.transpose() * &x),
        &(x.transpose() * &t),
        &(q.transpose() * &t),
    );
    assert_eq!(s.rank, 0);
    assert_eq!(s.explained, 0.0);
}

#[test]
fn canonical_correlation_of_shared_and_orthogonal_spaces() {
    let a = DMatrix::from_column_slice(3, 1, &[1.0, 0.0, 0.0]);
    let b = DMatrix::from_column_slice(3, 2, &[2.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let c = DMatrix::from_column_slice(3, 1, &[0.0, 0.0, 1.0]);
    assert!((canonical_correlation(&a, &b) - 1.0).abs() < 1e-12);
    assert!(canonical_correlation(&a, &c).abs() < 1e-12);
}
