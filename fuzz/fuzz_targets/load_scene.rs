//! Fuzzes the glTF/GLB loader: any input may be rejected, none may panic or hang.
//! Run: `cargo fuzz run load_scene fuzz/corpus/load_scene tests/data/bad scenes -- -max_total_time=60`,
//! or `tools/fuzz_corpus.sh grow 60` without cargo-fuzz.
//! The suite replays fuzz/corpus/load_scene on every `cargo test --release`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = restir_pt::scene::load_scene_from_bytes(data, None, std::path::Path::new("fuzz input"));
});
