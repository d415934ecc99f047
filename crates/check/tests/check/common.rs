//! What the check's campaign tests share: a true machine calibrated from
//! 80 random poses, a check campaign of 20 random poses with freshly
//! re-referenced sensors, the check at its defaults.

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64Mcg;
use tricept_check::{CheckOptions, CheckReport, Reference, check};
use tricept_data::Dataset;
use tricept_engine::{IdentifyOptions, identify, model::GeometricModel};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, DEFAULT_SENSOR_OFFSETS, Plant};

/// Poses of the check campaign.
pub const CHECK_POSES: usize = 20;

/// The true machine of `seed` and its calibration.
pub fn calibrated(seed: u64) -> (Plant, Reference) {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let normal = Normal::new(0.0, 0.25).unwrap();
    let truth: Vec<f64> = (0..set.len()).map(|_| normal.sample(&mut rng)).collect();
    let plant = Plant::geometric(m.clone(), set.to_errors(&truth));
    let data = plant.simulate(&Campaign::random(&m, 80, seed)).unwrap();
    let model = GeometricModel::new(m.clone(), set.clone());
    let id = identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
    assert!(id.converged && id.verdict().adequate, "seed {seed}");
    let temperature = mean_temperature(&data);
    let reference = Reference::new(
        model.machine_at(&id.estimate),
        set,
        id.covariance.clone(),
        id.offsets,
        temperature,
    )
    .unwrap();
    (plant, reference)
}

pub fn mean_temperature(data: &Dataset) -> Option<f64> {
    let t: Vec<f64> = data.poses.iter().filter_map(|p| p.temp_c).collect();
    (t.len() == data.poses.len()).then(|| t.iter().sum::<f64>() / t.len() as f64)
}

/// The check campaign of `plant`: 20 random poses, the sensors
/// re-referenced (offsets moved by up to 0.01 rad and 5 mm), at `temp_c`.
pub fn check_campaign(plant: &Plant, seed: u64, temp_c: f64) -> Dataset {
    noisy_campaign(plant, seed, temp_c, 1.0)
}

/// [`check_campaign`] with the sensors' true noise `noise` times the
/// stated one.
pub fn noisy_campaign(plant: &Plant, seed: u64, temp_c: f64, noise: f64) -> Dataset {
    let mut plant = plant.clone();
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0xc4ec);
    let jump = [0.01, 0.01, 5.0];
    plant.sensor_offsets = std::array::from_fn(|c| {
        DEFAULT_SENSOR_OFFSETS[c] + jump[c] * (2.0 * rng.random::<f64>() - 1.0)
    });
    let mut campaign = Campaign::random(&plant.nominal, CHECK_POSES, seed + 1000);
    campaign.start_temp_c = temp_c;
    campaign.noise_factor = noise;
    plant.simulate(&campaign).unwrap()
}

pub fn run(reference: &Reference, data: &Dataset) -> CheckReport {
    check(
        reference,
        data,
        &CheckOptions::for_machine(reference.machine()),
    )
    .unwrap()
}

pub fn most_likely(r: &CheckReport) -> Option<&str> {
    r.most_likely.map(|i| r.candidates[i].name.as_str())
}

/// A unit vector of random direction.
pub fn direction(rng: &mut Pcg64Mcg) -> Vector3<f64> {
    let normal = Normal::new(0.0, 1.0).unwrap();
    Vector3::from_fn(|_, _| normal.sample(rng)).normalize()
}

/// The calibration campaign's temperature (the plant's default 20 °C).
pub const CALIBRATION_C: f64 = 20.0;
