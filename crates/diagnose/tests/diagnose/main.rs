//! The diagnosis's integration tests, one binary: realistic campaigns, effects
//! outside the vocabulary, small campaigns, noise from data, time and
//! temperature, hidden effects, and deployment into the plant's truth
//! (one module per subject; shared helpers in `common`).

mod common;
mod deploy_in_truth;
mod deploy_pays;
mod hidden_effects;
mod noise_from_data;
mod out_of_vocabulary;
mod realistic;
mod small_campaigns;
mod time_temperature;
