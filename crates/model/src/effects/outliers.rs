//! `outliers`: a few gross reading errors, screened row by row (never a
//! term of a model: the rows are set aside).

use super::spec::{Deployment, EffectSpec, Kind, Needs, PlotAxes, XAxis, YAxis};
use super::simulation::{EffectKey, Simulate, Simulation, parse_input};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "outliers",
    physics: "a few gross reading errors",
    quoted_in: "count",
    parameters: &[],
    kind: Kind::Rows,
    needs: Needs::Nothing,
    deployment: Deployment::SetAside,
    fused: false,
    plausible: &[],
    description: "gross reading errors",
    plot: PlotAxes {
        x: XAxis::Line,
        y: YAxis::LargestResidualSigma,
    },
    realistic: |_| Vec::new(),
    aliases: &[],
    simulation: SIMULATION,
    common_part: None,
    check: None,
};

/// The simulator's gross reading errors in a few rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outliers {
    /// Number of corrupted rows.
    pub count: usize,
    /// Size of each error in noise standard deviations (random sign).
    pub size_sigma: f64,
}

const SIMULATION: Simulation = Simulation {
    tag: "outliers",
    cause: "outliers",
        keys: &[
        EffectKey::new("count", "-", "number of corrupted rows"),
        EffectKey::new(
            "size_sigma",
            "sigma",
            "size of each error in noise standard deviations (random sign)",
        ),
    ],
    parse: parse_input::<Outliers>,
    typical: || {
        Box::new(Outliers {
            count: 2,
            size_sigma: 300.0,
        })
    },
};

impl Simulate for Outliers {
    fn simulation(&self) -> &'static Simulation {
        &SIMULATION
    }

    /// `count` distinct rows drawn from the campaign's seed, each with one
    /// channel off by `size_sigma` logged sigmas of random sign.
    fn corrupt_readings(&self, readings: &mut [[f64; 3]], seed: u64, sigma: &[f64; 3]) {
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x0071_1e25);
        let n = readings.len();
        let mut rows: Vec<usize> = Vec::new();
        while rows.len() < self.count.min(n) {
            let j = rng.random_range(0..n);
            if !rows.contains(&j) {
                rows.push(j);
            }
        }
        for j in rows {
            let channel = rng.random_range(0..3);
            let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
            readings[j][channel] += sign * self.size_sigma * sigma[channel];
        }
    }
}
