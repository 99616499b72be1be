#![no_main]
#[path = "../differential.rs"]
mod differential;
libfuzzer_sys::fuzz_target!(|data: &[u8]| differential::differential(data));
