//! Fuzz target `urdf_stiffness`: the harness is `deflect_tests::fuzz::urdf_stiffness` (tests/support/fuzz.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    deflect_tests::fuzz::urdf_stiffness(data);
});
