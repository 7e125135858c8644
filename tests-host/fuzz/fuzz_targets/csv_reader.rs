#![no_main]
//! See `gaitclip_host::fuzzing::csv_reader`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| gaitclip_host::fuzzing::csv_reader(data));
