//! Realistic campaigns for the diagnosis' tests: random poses, one
//! approach direction, the mean of 3 readings (the paper's sensors), unknown
//! sensor offsets, random class-1 errors of up to 0.25 mm, a temperature
//! logged while it drifts 2 K (the legs grow only when `thermal` is the
//! hidden effect). Every data set is seeded; data sets are diagnosed in
//! parallel and collected in order, so tallies are bit-identical at any
//! thread count.
#![allow(dead_code)]

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_diagnose::{DiagnoseOptions, Diagnosis, diagnose};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_model::effects::{CauseName, EffectName};
use tricept_plant::effects::Effect;
use tricept_plant::{Campaign, Plant, random_errors};

/// A simulated data set with the simulator's inputs.
pub struct Simulated {
    /// The data.
    pub data: Dataset,
    /// The hidden effects (besides the temperature log).
    pub effects: Vec<Effect>,
    /// The stated noise of one logged reading.
    pub sigma: [f64; 3],
}

/// Campaign options beyond the defaults.
#[derive(Debug, Clone, Copy)]
pub struct CampaignOptions {
    /// Targets revisited at the end.
    pub revisits: usize,
    /// True noise over stated noise.
    pub noise_factor: f64,
}

impl Default for CampaignOptions {
    fn default() -> Self {
        CampaignOptions {
            revisits: 0,
            noise_factor: 1.0,
        }
    }
}

/// The generator of a case's magnitudes for data set `seed`.
pub fn rng(case: u64, seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(case ^ seed.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// Uniform in `[a, b)`.
pub fn uniform(rng: &mut Pcg64Mcg, a: f64, b: f64) -> f64 {
    a + (b - a) * rng.random::<f64>()
}

/// A random sign.
pub fn sign(rng: &mut Pcg64Mcg) -> f64 {
    if rng.random::<bool>() { 1.0 } else { -1.0 }
}

/// Simulates `n` random poses with `effects` hidden.
pub fn simulate(n: usize, seed: u64, effects: Vec<Effect>, c: CampaignOptions) -> Simulated {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&random_errors(15, 0.25, seed)));
    let thermal = effects.iter().any(|e| e.tag() == "thermal");
    if !thermal {
        plant
            .effects
            .push(Effect::from(tricept_plant::effects::Thermal {
                drift_k: 2.0,
                expansion_ppm_per_k: 0.0,
            }));
    }
    plant.effects.extend(effects.iter().cloned());
    let mut campaign = Campaign::random(&m, n, 7 * seed + 1);
    campaign.revisits = c.revisits;
    campaign.noise_factor = c.noise_factor;
    let sigma = campaign.noise.logged_sigma();
    let mut data = plant.simulate(&campaign).expect("simulated campaign");
    for (j, p) in data.poses.iter_mut().enumerate() {
        p.line = j as u64 + 2;
    }
    Simulated {
        data,
        effects,
        sigma,
    }
}

/// The diagnosis' options for a simulated data set.
pub fn options(sigma: [f64; 3]) -> DiagnoseOptions {
    let mut o = DiagnoseOptions::for_machine(&Machine::paper());
    o.sigma = sigma;
    o
}

/// Diagnoses data sets `0..count` of a case in parallel (in order).
pub fn run_case<F>(count: u64, make: F) -> Vec<(Simulated, Diagnosis)>
where
    F: Fn(u64) -> Simulated + Sync,
{
    run_case_with(count, make, |s| options(s.sigma))
}

/// As [`run_case`] with options per data set.
pub fn run_case_with<F, O>(count: u64, make: F, opts: O) -> Vec<(Simulated, Diagnosis)>
where
    F: Fn(u64) -> Simulated + Sync,
    O: Fn(&Simulated) -> DiagnoseOptions + Sync,
{
    (0..count)
        .into_par_iter()
        .map(|i| {
            let s = make(i);
            let d = diagnose(&Machine::paper(), &s.data, &opts(&s)).expect("diagnosis");
            (s, d)
        })
        .collect()
}

/// The catalogue effects named as causes (outliers excluded).
pub fn catalogue_named(d: &Diagnosis) -> Vec<EffectName> {
    d.causes
        .iter()
        .filter_map(|c| c.effect.catalogue())
        .filter(|e| *e != EffectName::Outliers)
        .collect()
}

/// One line per cause, for failure messages and tallies.
pub fn summary(d: &Diagnosis) -> String {
    let causes: Vec<String> = d
        .causes
        .iter()
        .map(|c| format!("{} [{}]", c.effect, c.description))
        .collect();
    let aliases: Vec<String> = d
        .aliases
        .iter()
        .map(|a| a.descriptions.join(" ~ "))
        .collect();
    format!(
        "{:?}; geo chi2 {:.0}/{} final {:.0}/{}; cv {:.2} -> {:.2}; causes: {}; aliases: {}",
        d.verdict,
        d.chi_square,
        d.dof,
        d.final_fit.chi_square,
        d.final_fit.dof,
        d.gain.holdout_rms_geometric,
        d.gain.holdout_rms_extended,
        causes.join(" | "),
        aliases.join(" | ")
    )
}

/// Whether `name` is among the causes.
pub fn named(d: &Diagnosis, name: CauseName) -> bool {
    d.causes.iter().any(|c| c.effect == name)
}

/// Whether `name` is a member of an alias set.
pub fn in_alias(d: &Diagnosis, name: CauseName) -> bool {
    d.aliases.iter().any(|a| a.effects.contains(&name))
}

/// Checks every diagnosis must pass: each named cause plausible, and a
/// named cause never makes the held-out fit worse. Returns the failures.
pub fn invariants(d: &Diagnosis) -> Vec<String> {
    let mut out = Vec::new();
    for c in &d.causes {
        if !c.plausible {
            out.push(format!("{} named but not plausible", c.effect));
        }
    }
    let physical =
        d.causes.iter().any(|c| c.effect != EffectName::Outliers) || !d.aliases.is_empty();
    if physical && d.gain.holdout_rms_extended > d.gain.holdout_rms_geometric {
        out.push(format!(
            "held-out rms worse with the causes: {} -> {}",
            d.gain.holdout_rms_geometric, d.gain.holdout_rms_extended
        ));
    }
    out
}

/// Prints a tally line (quoted in docs/diagnosis.md).
pub fn tally(case: &str, n: usize, what: &str, k: usize, of: usize) {
    eprintln!("TALLY {case} n={n}: {what} {k}/{of}");
}

/// Whether a generic group (`reading-drift:s`) is named or in an alias set.
pub fn group_found(d: &Diagnosis, label: &str) -> bool {
    d.aliases
        .iter()
        .any(|a| a.descriptions.iter().any(|x| x == label))
        || d.causes.iter().any(|c| {
            c.effect.is_generic()
                && c.channel.is_some()
                && format!("{}:{}", c.effect, c.channel.unwrap_or_default()) == label
        })
}

/// The simulator's parameters in the diagnosis' parameterisation.
pub fn true_parameters(e: &Effect) -> Option<Vec<f64>> {
    use tricept_plant::effects::{
        Backlash, Compliance, EncoderEccentricity, LegLead, ScaleGain, Thermal, TubeTwist,
        UjointAxes,
    };
    if let Some(LegLead { ppm }) = e.input() {
        return Some(ppm.to_vec());
    }
    if let Some(Backlash { um }) = e.input() {
        return Some(um.to_vec());
    }
    if let Some(Thermal {
        expansion_ppm_per_k,
        ..
    }) = e.input()
    {
        return Some(vec![*expansion_ppm_per_k]);
    }
    if let Some(ScaleGain { ppm }) = e.input() {
        return Some(vec![*ppm]);
    }
    if let Some(EncoderEccentricity {
        phi_arcsec,
        phi_phase_deg,
        theta_arcsec,
        theta_phase_deg,
    }) = e.input()
    {
        let (sp, cp) = phi_phase_deg.to_radians().sin_cos();
        let (st, ct) = theta_phase_deg.to_radians().sin_cos();
        return Some(vec![
            phi_arcsec * cp,
            phi_arcsec * sp,
            theta_arcsec * ct,
            theta_arcsec * st,
        ]);
    }
    if let Some(UjointAxes {
        skew_arcsec,
        offset_um,
    }) = e.input()
    {
        return Some(vec![*skew_arcsec, *offset_um]);
    }
    if let Some(TubeTwist { arcsec_per_100mm }) = e.input() {
        return Some(vec![*arcsec_per_100mm]);
    }
    if let Some(Compliance {
        stiffness_n_per_um_at_1m,
    }) = e.input()
    {
        return Some(vec![1000.0 / stiffness_n_per_um_at_1m]);
    }
    None
}
