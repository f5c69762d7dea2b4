//! Fuzz target `map_json`: the harness is `deflect_tests::fuzz::map_json` (tests/support/fuzz.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    deflect_tests::fuzz::map_json(data);
});
