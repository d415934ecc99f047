//! Gauss-Newton with step halving on the exact model, under a rank decision
//! taken once: the iteration shared by [`crate::identify`] (the UP limb's
//! readings alone) and [`crate::fusion`] (several sources, some with
//! nuisance parameters that the model depends on nonlinearly).
//!
//! Each iteration solves the reduced weighted problem for a step, then
//! halves it until the cost after a linear re-fit of the nuisance
//! parameters ([`ReducedProblem::cost_without_parameters`]) does not
//! increase. The iteration has converged when every identifiable
//! parameter's step (and every step of a nuisance parameter carried from
//! one evaluation to the next) is below 1e-3 of its standard deviation.
//! The estimate is then the last point evaluated, with the nuisance
//! re-fitted at it, so that the residuals, chi-square and covariance
//! reported are all of the estimate; the step not taken is below the
//! tolerance (evaluating it too would cost one more pass over the data,
//! a quarter of an exact Monte Carlo trial).

use tricept_numerics::lsq::{RankDecision, ReducedProblem, Solution};

use crate::error::IdentError;

/// One identification problem as the iteration sees it.
pub(crate) trait Iteration {
    /// What is carried between evaluations besides the parameters (FK
    /// seeds, nuisance values).
    type State: Clone;
    /// One evaluation of the model over the data.
    type Eval;

    /// Evaluates at parameters `p`, updating `state`'s seeds.
    fn evaluate(&self, p: &[f64], state: &mut Self::State) -> Result<Self::Eval, IdentError>;

    /// The reduced weighted problem of an evaluation.
    fn problem<'e>(&self, eval: &'e Self::Eval) -> &'e ReducedProblem;

    /// The state a trial step of length `t` (times the solution's step) is
    /// evaluated at: the nuisance carried in the state moved by `t` times
    /// its step. Default: the state unchanged (all nuisance is linear and
    /// re-solved at every evaluation).
    fn trial_state(&self, state: &Self::State, _solution: &Solution, _t: f64) -> Self::State {
        state.clone()
    }

    /// Whether the step of every nuisance parameter carried in the state is
    /// below `fraction` of its standard deviation. Default: there is none.
    fn nuisance_step_within(&self, _solution: &Solution, _fraction: f64) -> bool {
        true
    }
}

/// The moving parts of a run.
pub(crate) struct Run<S, E> {
    /// Parameters.
    pub p: Vec<f64>,
    /// Seeds and carried nuisance.
    pub state: S,
    /// The evaluation at `p`.
    pub eval: E,
    /// The solution of that evaluation's reduced problem (the next step).
    pub solution: Solution,
    /// Iterations performed.
    pub iterations: u32,
    /// Whether the tolerance was met.
    pub converged: bool,
}

/// Gauss-Newton with step halving from `run` under `decision`.
pub(crate) fn iterate<I: Iteration>(
    problem: &I,
    run: &mut Run<I::State, I::Eval>,
    decision: &RankDecision,
    max_iterations: u32,
) {
    let within = |run: &Run<I::State, I::Eval>, step: &[f64], fraction: f64| {
        step_is_within(step, &run.solution, decision, fraction)
            && problem.nuisance_step_within(&run.solution, fraction)
    };
    for it in 1..=max_iterations {
        run.iterations = it;
        let step = run.solution.parameters.clone();
        if within(run, &step, 1e-3) {
            run.converged = true;
            hold_at_current(problem, run);
            return;
        }
        let cost = problem.problem(&run.eval).cost_without_parameters();
        let mut t = 1.0;
        let accepted = loop {
            let trial: Vec<f64> = run.p.iter().zip(&step).map(|(a, b)| a + t * b).collect();
            let mut trial_state = problem.trial_state(&run.state, &run.solution, t);
            match problem.evaluate(&trial, &mut trial_state) {
                Ok(e)
                    if problem.problem(&e).cost_without_parameters()
                        <= cost * (1.0 + 1e-12) + 1e-300 =>
                {
                    run.p = trial;
                    run.state = trial_state;
                    break Some(e);
                }
                _ => {}
            }
            t *= 0.5;
            if t < 1e-6 {
                break None;
            }
        };
        match accepted {
            Some(e) => run.eval = e,
            None => {
                // No decrease along the step: at the minimum to rounding
                // if the step is small against the uncertainty. Either way
                // the rejected step is not part of the estimate.
                run.converged = within(run, &step, 1e-2);
                hold_at_current(problem, run);
                return;
            }
        }
        run.solution = problem.problem(&run.eval).solve(decision);
    }
    let step = run.solution.parameters.clone();
    run.converged = within(run, &step, 1e-3);
    // With no iteration allowed the result is the one linear solve at the
    // start point (the linearised estimator), which keeps its step.
    if max_iterations > 0 {
        hold_at_current(problem, run);
    }
}

/// A run ends where its last accepted step left it: the pending step
/// (never tested; below 1e-3 of every standard deviation when the run has
/// converged) is dropped and the nuisance re-fitted with the parameters
/// held, so that the estimate, the offsets and the residual statistics
/// reported all belong to one point, the last one evaluated.
fn hold_at_current<I: Iteration>(problem: &I, run: &mut Run<I::State, I::Eval>) {
    run.solution.nuisance = problem.problem(&run.eval).nuisance_without_parameters();
    run.solution.parameters.iter_mut().for_each(|x| *x = 0.0);
}

/// Whether every identifiable component of a parameter step is below
/// `fraction` of its standard deviation (or below 1e-12): further
/// iterations could not change any conclusion drawn from the estimate.
pub(crate) fn step_is_within(step: &[f64], s: &Solution, d: &RankDecision, fraction: f64) -> bool {
    let nn = s.nuisance.len();
    d.identifiable.iter().all(|&j| {
        let sd = s.covariance[(nn + j, nn + j)].max(0.0).sqrt();
        step[j].abs() <= (fraction * sd).max(1e-12)
    })
}
