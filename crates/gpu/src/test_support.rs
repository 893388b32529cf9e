//! Shared by the GPU tests: the adapter they run on.

use crate::context::GpuContext;

/// The GPU context for a test. A missing or unusable adapter fails the
/// test: a GPU test that passes without a GPU tests nothing. (The test
/// script installs lavapipe where there is no GPU; `WGPU_BACKEND=gl` runs
/// the same tests on Mesa's OpenGL.)
pub fn test_context(test: &str) -> GpuContext {
    GpuContext::new().unwrap_or_else(|e| {
        panic!("{test}: {e} (scripts/test.sh installs Mesa's Vulkan driver; run the tests through it)")
    })
}
