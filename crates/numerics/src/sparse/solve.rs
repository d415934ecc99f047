//! The one entry point: a problem solved by the kind asked for, the block
//! elimination's pivot tests guarding the sparse kinds.

use std::time::Instant;

use super::problem::{BlockError, BlockProblem, BlockSolution, SolveStats, SolverKind};

impl BlockProblem {
    /// Solves the problem with `kind` (module docs).
    pub fn solve(&self, kind: SolverKind) -> Result<BlockSolution, BlockError> {
        let start = Instant::now();
        let w = self.n_global + 1;
        for (i, b) in self.blocks.iter().enumerate() {
            if b.rows.ncols() != b.n_local + w {
                return Err(BlockError::Shape(format!(
                    "block {i} has {} columns for {} locals, {} globals and the right-hand side",
                    b.rows.ncols(),
                    b.n_local,
                    self.n_global
                )));
            }
        }
        if kind != SolverKind::Schur {
            // faer's sparse factorisations do not pivot for rank: the block
            // elimination's pivot tests (cheap beside them) guard them.
            self.solve_schur()?;
        }
        let (global, local, global_covariance) = match kind {
            SolverKind::Schur => self.solve_schur()?,
            SolverKind::Dense => self.solve_dense()?,
            SolverKind::SparseCholesky => self.solve_cholesky()?,
            SolverKind::SparseQr => self.solve_qr()?,
        };
        let all_finite = global
            .iter()
            .chain(local.iter().flatten())
            .all(|v| v.is_finite());
        if !all_finite {
            return Err(BlockError::Factorisation(format!(
                "{}: the solution is not finite",
                kind.name()
            )));
        }
        let residual_norm2 = self.residual_norm2(&global, &local);
        Ok(BlockSolution {
            global,
            local,
            global_covariance,
            residual_norm2,
            stats: SolveStats {
                kind,
                unknowns: self.unknowns(),
                nonzeros: self.nonzeros(),
                rows: self.rows(),
                seconds: start.elapsed().as_secs_f64(),
            },
        })
    }
}
