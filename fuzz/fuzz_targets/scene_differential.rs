#![no_main]
#[path = "../scene.rs"]
mod scene;
libfuzzer_sys::fuzz_target!(|data: &[u8]| scene::scene_differential(data));
