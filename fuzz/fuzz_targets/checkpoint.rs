//! Fuzz target: `moving_circles_fuzz::checkpoint` on every input (see `../run`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| moving_circles_fuzz::checkpoint(data));
