//! Fuzz target `tool_table`: the harness is `deflect_tests::fuzz::tool_table`
//! (tests/support/fuzz.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    deflect_tests::fuzz::tool_table(data);
});
