//! See `tricept_fuzz::identify` for the property checked.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| tricept_fuzz::identify(bytes));
