//! A term's columns scored against the linearisation: a generic term's
//! per-pose values, columns given as (direction, per-pose value), dense
//! weighted columns, and the kept columns of the extra terms.

use nalgebra::DMatrix;
use tricept_data::Dataset;
use tricept_model::effects::Basis;

use super::linearisation::Linearisation;
use super::score::{Score, score_from};
use crate::terms::{Frame, GenericTerm, Term};

fn basis_index(b: Basis) -> usize {
    match b {
        Basis::Leg(i) => i,
        Basis::Reading(c) => 3 + c,
    }
}

impl Linearisation {
    /// Per-pose values of every parameter of a generic term, with its
    /// direction.
    pub(crate) fn generic_columns(
        &self,
        term: &GenericTerm,
        frame: &Frame,
        data: &Dataset,
    ) -> Vec<(usize, Vec<f64>)> {
        let mut cols: Vec<(usize, Vec<f64>)> = Vec::new();
        for (j, pose) in data.poses.iter().enumerate() {
            let values = if term.acts_on_legs() {
                term.leg_values(frame, pose)
            } else {
                term.reading_values(frame, pose, &self.ups[j])
            };
            if cols.is_empty() {
                cols = values
                    .iter()
                    .map(|(_, b, _)| (basis_index(*b), vec![0.0; data.poses.len()]))
                    .collect();
            }
            // A generic term has one entry per parameter, in order.
            for (k, (_, _, v)) in values.into_iter().enumerate() {
                if let Some(c) = cols.get_mut(k) {
                    c.1[j] = v;
                }
            }
        }
        cols
    }

    /// The score of a generic term's columns ([`Linearisation::generic_columns`]),
    /// evaluated pose by pose within the sums (no column is kept).
    pub(crate) fn score_generic(&self, term: &GenericTerm, frame: &Frame, data: &Dataset) -> Score {
        let n = self.poses().min(data.poses.len());
        let values_at = |j: usize| {
            if term.acts_on_legs() {
                term.leg_values(frame, &data.poses[j])
            } else {
                term.reading_values(frame, &data.poses[j], &self.ups[j])
            }
        };
        // The directions of the first pose's entries, one per parameter.
        let directions: Vec<usize> = match n {
            0 => Vec::new(),
            _ => values_at(0)
                .iter()
                .map(|(_, b, _)| basis_index(*b))
                .collect(),
        };
        let values = |j: usize, out: &mut [f64]| {
            out.iter_mut().for_each(|o| *o = 0.0);
            for (o, (_, _, v)) in out.iter_mut().zip(values_at(j)) {
                *o = v;
            }
        };
        self.score_of(self.sums(n, &directions, &values), 1.0)
    }

    /// The score of columns given as (direction, per-pose value).
    pub(crate) fn score_columns(&self, cols: &[(usize, Vec<f64>)]) -> Score {
        let n = self
            .poses()
            .min(cols.iter().map(|c| c.1.len()).min().unwrap_or(0));
        let directions: Vec<usize> = cols.iter().map(|c| c.0).collect();
        let values = |j: usize, out: &mut [f64]| {
            for (o, (_, f)) in out.iter_mut().zip(cols) {
                *o = f[j];
            }
        };
        self.score_of(self.sums(n, &directions, &values), 1.0)
    }

    /// Dense weighted columns (`3n x k`) of per-pose values.
    pub(crate) fn dense(&self, cols: &[(usize, Vec<f64>)]) -> DMatrix<f64> {
        let n = self.poses();
        let mut g = DMatrix::zeros(3 * n, cols.len());
        for (a, (b, f)) in cols.iter().enumerate() {
            for j in 0..n {
                for c in 0..3 {
                    g[(3 * j + c, a)] = f[j] * self.direction(j, *b)[c];
                }
            }
        }
        g
    }

    /// The score of dense weighted columns.
    pub(crate) fn score_dense(&self, g: &DMatrix<f64>) -> Score {
        let qtg = self.qt(&self.xt_dense(g));
        let gtg = g.transpose() * g;
        let gtt = g.transpose() * &self.target;
        score_from(&qtg, &gtg, &gtt, &self.qtt)
    }

    /// The columns of an extra term.
    pub(crate) fn extra_columns(&self, term: &Term) -> Option<DMatrix<f64>> {
        self.extra_terms
            .iter()
            .find(|(t, _)| t == term)
            .map(|(_, r)| self.extra.columns(r.start, r.len()).into_owned())
    }
}
