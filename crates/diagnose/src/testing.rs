//! Fixtures of the crate's unit tests: a seeded campaign simulated by the
//! plant (`tricept-plant`, a dev-dependency), with the options that state
//! its noise.

use tricept_data::Dataset;
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::effects::Effect;
use tricept_plant::{Campaign, Plant, random_errors};

use crate::options::DiagnoseOptions;

/// `poses` random poses of the paper machine with random geometric errors
/// (uniform in +-0.25 mm) and `effects` hidden, and the diagnosis' options
/// at the campaign's stated noise.
pub(crate) fn campaign(
    poses: usize,
    seed: u64,
    effects: Vec<Effect>,
) -> (Dataset, DiagnoseOptions) {
    let machine = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(
        machine.clone(),
        set.to_errors(&random_errors(15, 0.25, seed)),
    );
    plant.effects = effects;
    let campaign = Campaign::random(&machine, poses, seed);
    let mut options = DiagnoseOptions::for_machine(&machine);
    options.sigma = campaign.noise.logged_sigma();
    match plant.simulate(&campaign) {
        Ok(data) => (data, options),
        Err(e) => panic!("the plant cannot simulate the campaign: {e}"),
    }
}
