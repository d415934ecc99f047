//! See `tricept_fuzz::machine_description` for the property checked.
#![no_main]

libfuzzer_sys::fuzz_target!(|text: &str| tricept_fuzz::machine_description(text));
