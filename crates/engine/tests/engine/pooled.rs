//! Campaigns pooled in one fit (each with its own sensor offsets) and a
//! Gaussian prior on the parameters: checked against what each must equal.
//!
//! - Two campaigns of one machine re-homed between them (offsets apart by
//!   the plant's own choice): the pooled fit recovers each campaign's
//!   offsets and is more precise than either alone; it equals, to a small
//!   fraction of a standard deviation, the sequential fit that takes the
//!   first campaign's posterior as the second's prior (the two are the same
//!   estimator for a linear model: this checks the campaign offsets and the
//!   prior against each other).
//! - A prior a thousand times wider than the data's uncertainty changes
//!   nothing; a prior 1e5 times tighter holds the estimate at its mean
//!   (a thousand times is not enough: the data fix combinations of the
//!   weak parameters far better than their marginal deviations say); the prior's chi-square is reported apart.

use nalgebra::DMatrix;
use tricept_data::Dataset;
use tricept_engine::{
    IdentifyOptions, identify, model::GeometricModel, prior::Prior, robust::identify_robust,
};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant};

/// A campaign of `n` random poses (seed `seed`) of the Table 2 machine,
/// its sensors homed at `offsets`, tagged `campaign`.
fn campaign(n: usize, seed: u64, offsets: [f64; 3], tag: u32) -> Dataset {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&set.table2()));
    plant.sensor_offsets = offsets;
    let mut d = plant.simulate(&Campaign::random(&m, n, seed)).unwrap();
    d.poses.iter_mut().for_each(|p| p.campaign = tag);
    d
}

fn pooled(parts: &[&Dataset]) -> Dataset {
    Dataset {
        poses: parts.iter().flat_map(|d| d.poses.clone()).collect(),
        source: "pooled".into(),
    }
}

#[test]
fn pooled_campaigns_keep_their_own_offsets_and_equal_the_sequential_posterior() {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let homed_a = [0.0123, -0.0187, -612.5];
    let homed_b = [-0.0341, 0.0215, -598.25];
    let a = campaign(60, 1, homed_a, 0);
    let b = campaign(60, 2, homed_b, 1);
    let both = identify(&model, &pooled(&[&a, &b]), &options).unwrap();
    assert!(both.converged);
    assert_eq!(both.campaign_offsets.len(), 2);
    for (fit, truth) in both.campaign_offsets.iter().zip([homed_a, homed_b]) {
        for c in 0..3 {
            let z = (fit.offsets[c] - truth[c]) / fit.std_dev[c];
            assert!(
                z.abs() < 4.0,
                "campaign {} offset {c}: {z:.1} sd",
                fit.campaign
            );
        }
    }
    assert_eq!(both.stats.dof, 3 * 120 - 14 - 6);
    let alone_a = identify(&model, &a, &options).unwrap();
    let alone_b = identify(&model, &b, &options).unwrap();
    for j in both.design().identifiable() {
        let pooled_sd = both.std_dev[*j].unwrap();
        let best_alone = alone_a.std_dev[*j]
            .unwrap()
            .min(alone_b.std_dev[*j].unwrap());
        assert!(
            pooled_sd < best_alone,
            "{}: {pooled_sd} >= {best_alone}",
            set.names()[*j]
        );
        let truth = set.table2()[*j];
        assert!((both.estimate[*j] - truth).abs() < 4.0 * pooled_sd);
    }
    // Campaign A's posterior as campaign B's prior.
    let free = alone_a.design().identifiable().to_vec();
    let cov = DMatrix::from_fn(free.len(), free.len(), |r, c| {
        alone_a.covariance[(free[r], free[c])]
    });
    let prior = Prior::new(alone_a.estimate.clone(), &free, &cov).unwrap();
    let sequential = identify(&model.clone().with_prior(prior).unwrap(), &b, &options).unwrap();
    for j in &free {
        let sd = both.std_dev[*j].unwrap();
        let d = (sequential.estimate[*j] - both.estimate[*j]) / sd;
        assert!(d.abs() < 0.05, "{}: {d:.3} sd apart", set.names()[*j]);
        let ratio = sequential.std_dev[*j].unwrap() / sd;
        assert!(
            (ratio - 1.0).abs() < 0.01,
            "{}: sd ratio {ratio}",
            set.names()[*j]
        );
    }
    // The prior's share is apart and counted: 14 rows of pseudo-readings.
    let prior_fit = sequential.prior_fit.unwrap();
    assert_eq!(prior_fit.dof, 14);
    assert_eq!(sequential.stats.dof, 3 * 60 + 14 - 14 - 3);
}

#[test]
fn a_wide_prior_changes_nothing_and_a_tight_one_holds_its_mean() {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let data = campaign(40, 7, tricept_plant::DEFAULT_SENSOR_OFFSETS, 0);
    let plain = identify(&model, &data, &options).unwrap();
    let free = plain.design().identifiable().to_vec();
    let mean: Vec<f64> = (0..15).map(|j| 0.1 * (j as f64 - 7.0) / 7.0).collect();
    let with = |scale: f64| {
        let cov = DMatrix::from_fn(free.len(), free.len(), |r, c| {
            let (a, b) = (free[r], free[c]);
            if a == b {
                (scale * plain.std_dev[a].unwrap()).powi(2)
            } else {
                0.0
            }
        });
        let prior = Prior::new(mean.clone(), &free, &cov).unwrap();
        identify(&model.clone().with_prior(prior).unwrap(), &data, &options).unwrap()
    };
    let wide = with(1e3);
    let tight = with(1e-5);
    for &j in &free {
        let sd = plain.std_dev[j].unwrap();
        assert!(((wide.estimate[j] - plain.estimate[j]) / sd).abs() < 1e-3);
        assert!(((tight.estimate[j] - mean[j]) / sd).abs() < 1e-3);
        assert!(tight.std_dev[j].unwrap() < 1.1e-5 * sd);
    }
    assert_eq!(wide.report.fixed, plain.report.fixed);
    // The tight prior far from the truth: the readings no longer fit
    // (their share of the chi-square, the total less the prior's), while
    // the wide prior's fit is at the noise.
    let readings = |id: &tricept_engine::Identification| {
        id.stats.chi_square - id.prior_fit.unwrap().chi_square
    };
    assert!(readings(&tight) > 100.0 * tight.stats.dof as f64);
    assert!(wide.stats.reduced_chi_square < 1.5);
    assert!((readings(&wide) - plain.stats.chi_square).abs() < 1e-3 * plain.stats.chi_square);
}

#[test]
fn the_robust_screen_scales_each_campaign_on_its_own() {
    // Two campaigns re-homed 14 mm apart on the scale: one gross reading in
    // the second is found by its line, nothing else is rejected.
    let mut b = campaign(50, 12, [-0.0341, 0.0215, -598.25], 1);
    let a = campaign(50, 11, tricept_plant::DEFAULT_SENSOR_OFFSETS, 0);
    b.poses
        .iter_mut()
        .enumerate()
        .for_each(|(j, p)| p.line = j as u64 + 2);
    b.poses[17].readings.s_mm += 0.05;
    let m = Machine::paper();
    let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
    let (id, rejected) = identify_robust(
        &model,
        &pooled(&[&a, &b]),
        &IdentifyOptions::for_machine(&m),
    )
    .unwrap();
    assert_eq!(
        rejected.iter().map(|r| r.line).collect::<Vec<_>>(),
        vec![19]
    );
    assert!(id.stats.reduced_chi_square < 1.5);
}
