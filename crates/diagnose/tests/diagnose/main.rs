//! The diagnosis's integration tests, one binary: realistic campaigns, effects
//! outside the vocabulary, small campaigns, noise from data, time and
//! temperature, hidden effects, and deployment into the plant's truth
//! (one module per subject; shared helpers in `common`), and what a
//! deployment records and tabulates.

mod common;
mod deploy_in_truth;
mod deploy_pays;
mod deploy_records;
mod hidden_effects;
mod noise_from_data;
mod out_of_vocabulary;
mod realistic;
mod selection;
mod small_campaigns;
mod time_temperature;
