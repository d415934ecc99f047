//! The campaigns of one machine pooled: one fit of every pose, the
//! geometry shared, each campaign with its own sensor offsets (the engine's
//! campaigns, [`tricept_data::MeasuredPose::campaign`]); what each campaign
//! contributes, and whether it agrees with the rest.
//!
//! **Agreement.** A campaign that does not share the others' geometry (the
//! machine changed between them, a crash, a campaign taken cold) must be
//! named, not averaged in. Campaign `i` is tested by what it adds to the
//! fit of the others: `Delta = chi2(all) - chi2(all but i)`, chi-square
//! with `3 n_i - 3` degrees of freedom (its readings less its own offsets)
//! for a campaign of the same machine. When the campaign can also be
//! fitted alone (it determines every parameter the pool does), its own
//! misfit `chi2(i alone)` is taken out: `D = Delta - chi2(i alone)`,
//! chi-square with `rank` degrees of freedom, the disagreement proper
//! (Chow's test); a campaign that fits neither alone nor with the rest is
//! the verdict's business. A campaign disagrees when its p-value is below
//! `alpha / C` (Bonferroni over the `C` campaigns); the worst one leaves
//! and the rest are tested again, while three or more remain. Of two
//! campaigns that disagree neither can be preferred: both are named.

use tricept_data::Dataset;
use tricept_engine::{Identification, IdentifyOptions, identify, model::ReadingModel};
use tricept_numerics::stats::chi2_sf;

use crate::error::FleetError;

/// Campaigns given as data sets, pooled into one: the poses of data set
/// `i` tagged campaign `i`, its lines kept.
///
/// # Example
/// ```
/// use tricept_data::{Dataset, MeasuredPose};
/// let a = Dataset { poses: vec![MeasuredPose::default(); 2], source: "a.csv".into() };
/// let b = Dataset { poses: vec![MeasuredPose::default(); 3], source: "b.csv".into() };
/// let pooled = tricept_fleet::campaigns::pool(&[a, b]);
/// assert_eq!(pooled.poses.iter().map(|p| p.campaign).collect::<Vec<_>>(), vec![0, 0, 1, 1, 1]);
/// assert_eq!(pooled.source, "a.csv + b.csv");
/// ```
pub fn pool(datasets: &[Dataset]) -> Dataset {
    Dataset {
        poses: datasets
            .iter()
            .enumerate()
            .flat_map(|(i, d)| {
                d.poses.iter().map(move |p| tricept_data::MeasuredPose {
                    campaign: i as u32,
                    ..*p
                })
            })
            .collect(),
        source: datasets
            .iter()
            .map(|d| d.source.as_str())
            .collect::<Vec<_>>()
            .join(" + "),
    }
}

/// A campaign's test against the others.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// The statistic: `D` (its own misfit taken out) or `Delta`.
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// `P(chi2_dof > chi_square)`.
    pub p_value: f64,
    /// Whether its own misfit was taken out (it could be fitted alone).
    pub own_misfit_removed: bool,
}

/// Which campaigns agree (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Agreements {
    /// Every campaign's test: within the last set tested, or the test it
    /// left on (`None`: a single campaign).
    pub tests: Vec<Option<Agreement>>,
    /// The campaigns that disagree with the rest, in the order they left.
    pub disagreeing: Vec<u32>,
}

/// Tests campaigns `0..count` of `data` (pooled, gross readings removed)
/// against each other with `model` at level `alpha` (module docs).
pub fn agreements(
    model: &dyn ReadingModel,
    data: &Dataset,
    count: usize,
    options: &IdentifyOptions,
    alpha: f64,
) -> Result<Agreements, FleetError> {
    let mut inside: Vec<u32> = (0..count as u32).collect();
    let mut disagreeing = Vec::new();
    let mut tests = vec![None; count];
    let fail = |e| FleetError::Identification {
        source_name: data.source.clone(),
        error: e,
    };
    while inside.len() >= 2 {
        let set = data.subset(|j| inside.contains(&data.poses[j].campaign));
        let all = identify(model, &set, options).map_err(fail)?;
        // A campaign that left keeps the test it left on.
        for &c in &inside {
            tests[c as usize] = Some(test(model, &set, &all, c, options)?);
        }
        let crit = alpha / inside.len() as f64;
        // The worst by its statistic in standard deviations: p-values of
        // gross disagreements all round to zero.
        let z = |t: &Agreement| (t.chi_square - t.dof as f64) / (2.0 * t.dof.max(1) as f64).sqrt();
        let worst = inside
            .iter()
            .filter_map(|&c| tests[c as usize].map(|t| (c, t)))
            .filter(|(_, t)| t.p_value < crit)
            .max_by(|a, b| z(&a.1).total_cmp(&z(&b.1)));
        match worst {
            None => break,
            Some(_) if inside.len() == 2 => {
                disagreeing.extend(inside.iter().copied());
                break;
            }
            Some((c, _)) => {
                disagreeing.push(c);
                inside.retain(|&x| x != c);
            }
        }
    }
    Ok(Agreements { tests, disagreeing })
}

/// Campaign `c` of `set` against the rest (module docs); `all` is the fit
/// of `set`.
fn test(
    model: &dyn ReadingModel,
    set: &Dataset,
    all: &Identification,
    c: u32,
    options: &IdentifyOptions,
) -> Result<Agreement, FleetError> {
    let fail = |e| FleetError::Identification {
        source_name: set.source.clone(),
        error: e,
    };
    let rest =
        identify(model, &set.subset(|j| set.poses[j].campaign != c), options).map_err(fail)?;
    let own = set.subset(|j| set.poses[j].campaign == c);
    let delta = (all.stats.chi_square - rest.stats.chi_square).max(0.0);
    let alone = if model.prior().is_none() {
        identify(model, &own, options)
            .ok()
            .filter(|a| a.design().identifiable() == all.design().identifiable())
    } else {
        None
    };
    let (chi_square, dof, removed) = match alone {
        Some(a) => (
            (delta - a.stats.chi_square).max(0.0),
            all.design().rank(),
            true,
        ),
        None => (delta, (3 * own.poses.len()).saturating_sub(3), false),
    };
    Ok(Agreement {
        chi_square,
        dof,
        p_value: chi2_sf(chi_square, dof as f64),
        own_misfit_removed: removed,
    })
}

/// Each campaign's share of a pooled fit: its readings and their
/// chi-square at the fit (`id` of `data`, noise `sigma`).
pub fn campaign_chi_squares(
    id: &Identification,
    data: &Dataset,
    count: usize,
    sigma: &[f64; 3],
) -> Vec<(usize, f64)> {
    let mut out = vec![(0, 0.0); count];
    for (pose, r) in data.poses.iter().zip(&id.residuals) {
        if let Some(slot) = out.get_mut(pose.campaign as usize) {
            slot.0 += 3;
            slot.1 += (0..3).map(|c| (r[c] / sigma[c]).powi(2)).sum::<f64>();
        }
    }
    out
}
