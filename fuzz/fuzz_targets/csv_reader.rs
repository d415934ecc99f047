//! See `tricept_fuzz::csv_reader` for the property checked.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| tricept_fuzz::csv_reader(bytes));
