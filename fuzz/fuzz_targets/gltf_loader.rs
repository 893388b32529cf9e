//! Coverage-guided fuzzing of the glTF loader: bytes of a `.glb` or
//! `.gltf` → validated `Scene` with its BVH built. Any panic (or abort, or
//! hang past libFuzzer's -timeout) is a failure; an `Err(SceneError)` is a
//! correct answer.
#![no_main]
use hikari_core::scene::{LoadOptions, gltf};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // No base folder: a buffer given as a file path is an error, not a read.
    match gltf::scene_from_bytes(data, "fuzz.glb", None, &LoadOptions::default(), &hikari_core::progress::Silent) {
        Ok(scene) => assert!(scene.diagonal().is_finite()),
        Err(e) => assert!(!e.message.is_empty()),
    }
});
