//! Helpers of the study's tests.

pub mod independent;
