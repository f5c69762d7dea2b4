//! Fuzz target `map_csv`: the harness is `deflect_tests::fuzz::map_csv` (tests/support/fuzz.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    deflect_tests::fuzz::map_csv(data);
});
