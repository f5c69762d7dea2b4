//! Fuzz target `drive_toml`: the harness is `deflect_tests::fuzz::drive_toml` (tests/support/fuzz.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    deflect_tests::fuzz::drive_toml(data);
});
