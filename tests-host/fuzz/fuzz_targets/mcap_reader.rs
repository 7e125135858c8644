#![no_main]
//! See `gaitclip_host::fuzzing::mcap_reader`.

libfuzzer_sys::fuzz_target!(|data: &[u8]| gaitclip_host::fuzzing::mcap_reader(data));
