//! Coverage-guided fuzzing of the scene loader: TOML text → validated
//! `Scene` with its BVH built. Any panic (or abort, or hang past libFuzzer's
//! -timeout) is a failure; an `Err(SceneError)` is a correct answer.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        // A `builtin:` name lets `meshes/fog-layer.obj` resolve to the copy
        // embedded in the binary, so the layered-fog seed loads its region.
        match hikari_core::scene::Scene::from_toml(text, "builtin:fuzz", None) {
            Ok(scene) => assert!(scene.diagonal().is_finite()),
            Err(e) => assert!(!e.message.is_empty()),
        }
    }
});
