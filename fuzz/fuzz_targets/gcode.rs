//! Fuzz target `gcode`: the harness is `deflect_tests::fuzz::gcode` (tests/support/fuzz.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    deflect_tests::fuzz::gcode(data);
});
