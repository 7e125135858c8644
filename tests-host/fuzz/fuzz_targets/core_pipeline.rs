#![no_main]
//! See `gaitclip_host::fuzzing::core_pipeline`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| gaitclip_host::fuzzing::core_pipeline(data));
