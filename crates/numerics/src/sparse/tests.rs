//! The block-arrow solvers against each other and the dense reference.

use super::*;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};

/// A seeded problem of `blocks` blocks (`l` locals, `m` rows each) and
/// `g` globals, with rows of very different scales.
fn problem(blocks: usize, l: usize, g: usize, m: usize, seed: u64) -> BlockProblem {
    let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    BlockProblem {
        n_global: g,
        blocks: (0..blocks)
            .map(|_| {
                let scale: Vec<f64> = (0..l + g + 1)
                    .map(|j| 10f64.powi((j % 5) as i32 - 2))
                    .collect();
                RowBlock::new(l, Mat::from_fn(m, l + g + 1, |_, j| scale[j] * next()))
            })
            .collect(),
    }
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn every_kind_agrees_with_the_dense_reference_to_1e_9() {
    for (blocks, l, g, m) in [
        (1, 3, 2, 10),
        (7, 18, 15, 40),
        (25, 3, 14, 30),
        (4, 0, 5, 9),
    ] {
        let p = problem(blocks, l, g, m, blocks as u64);
        let dense = p.solve(SolverKind::Dense).unwrap();
        for kind in [
            SolverKind::Schur,
            SolverKind::SparseCholesky,
            SolverKind::SparseQr,
        ] {
            let s = p.solve(kind).unwrap();
            let worst = s
                .global
                .iter()
                .zip(&dense.global)
                .chain(s.local.iter().flatten().zip(dense.local.iter().flatten()))
                .map(|(a, b)| (a - b).abs() / b.abs().max(1e-3 * norm_inf(&dense)))
                .fold(0.0, f64::max);
            assert!(worst < 1e-9, "{kind:?} {blocks}x{l}+{g}: {worst:e}");
            assert!(
                relative(s.residual_norm2, dense.residual_norm2) < 1e-9,
                "{kind:?}"
            );
            if let (Some(c), Some(d)) = (&s.global_covariance, &dense.global_covariance) {
                for a in 0..g {
                    for b in 0..g {
                        let tol = 1e-9 * (d[(a, a)] * d[(b, b)]).sqrt();
                        assert!((c[(a, b)] - d[(a, b)]).abs() < tol, "{kind:?} cov");
                    }
                }
            }
            assert_eq!(s.stats.unknowns, blocks * l + g);
            assert_eq!(s.stats.rows, blocks * m);
        }
    }
}

fn norm_inf(s: &BlockSolution) -> f64 {
    s.global
        .iter()
        .chain(s.local.iter().flatten())
        .fold(0.0, |a, b| a.max(b.abs()))
}

#[test]
fn the_local_covariance_is_the_dense_inverse_block() {
    let p = problem(3, 4, 2, 12, 9);
    let s = p.solve(SolverKind::Schur).unwrap();
    let cov = s.global_covariance.unwrap();
    // The dense inverse of J^T J, locals of block 1 at columns 4..8.
    let n = p.unknowns();
    let mut j = Mat::<f64>::zeros(p.rows(), n);
    let mut at = 0;
    for (b, block) in p.blocks.iter().enumerate() {
        for i in 0..block.rows.nrows() {
            for c in 0..4 {
                j[(at, 4 * b + c)] = block.rows[(i, c)];
            }
            for c in 0..2 {
                j[(at, n - 2 + c)] = block.rows[(i, 4 + c)];
            }
            at += 1;
        }
    }
    let jtj = j.transpose() * &j;
    let inv = jtj.as_ref().llt(Side::Lower).unwrap().inverse();
    let r = ReducedBlock::new(&p.blocks[1], 2, 1).unwrap();
    let local = r.local_covariance(cov.as_ref());
    let cross = r.cross_covariance(cov.as_ref());
    for a in 0..4 {
        for b in 0..4 {
            assert!(relative(local[(a, b)], inv[(4 + a, 4 + b)]) < 1e-9);
        }
        for b in 0..2 {
            assert!(relative(cross[(a, b)], inv[(4 + a, n - 2 + b)]) < 1e-9);
        }
    }
}

#[test]
fn a_column_no_block_sees_is_refused_by_every_kind_never_filled() {
    // Global 1 has no entry in any row: no kind may return a number.
    let mut p = problem(5, 3, 3, 20, 4);
    for b in &mut p.blocks {
        for i in 0..b.rows.nrows() {
            b.rows[(i, 3 + 1)] = 0.0;
        }
    }
    for kind in SolverKind::ALL {
        assert_eq!(
            p.solve(kind).unwrap_err(),
            BlockError::NotDetermined {
                block: None,
                column: 1
            },
            "{kind:?}"
        );
    }
    // A global that is a combination of another (2 x global 0): every
    // kind says which (the sparse ones by the block elimination's test).
    let mut p = problem(5, 3, 3, 20, 5);
    for b in &mut p.blocks {
        for i in 0..b.rows.nrows() {
            b.rows[(i, 3 + 2)] = 2.0 * b.rows[(i, 3)];
        }
    }
    for kind in SolverKind::ALL {
        assert_eq!(
            p.solve(kind).unwrap_err(),
            BlockError::NotDetermined {
                block: None,
                column: 2
            },
            "{kind:?}"
        );
    }
    // A block's local that its rows do not see.
    let mut p = problem(3, 3, 2, 20, 6);
    for i in 0..p.blocks[2].rows.nrows() {
        p.blocks[2].rows[(i, 1)] = 0.0;
    }
    for kind in SolverKind::ALL {
        assert_eq!(
            p.solve(kind).unwrap_err(),
            BlockError::NotDetermined {
                block: Some(2),
                column: 1
            },
            "{kind:?}"
        );
    }
}

#[test]
fn a_block_of_the_wrong_width_is_a_shape_error() {
    let mut p = problem(2, 3, 2, 10, 1);
    p.blocks[1].rows = Mat::zeros(10, 4);
    assert!(matches!(
        p.solve(SolverKind::Schur),
        Err(BlockError::Shape(_))
    ));
}
