//! Shared by the GPU tests: the adapter they run on.

use crate::context::GpuContext;
use crate::renderer::GpuRenderer;
use hikari_core::scene::Scene;

/// The GPU context for a test. A missing or unusable adapter fails the
/// test: a GPU test that passes without a GPU tests nothing. (The test
/// script installs lavapipe where there is no GPU; `WGPU_BACKEND=gl` runs
/// the same tests on Mesa's OpenGL.)
pub fn test_context(test: &str) -> GpuContext {
    GpuContext::new().unwrap_or_else(|e| {
        panic!("{test}: {e} (scripts/test.sh installs Mesa's Vulkan driver; run the tests through it)")
    })
}

/// The context for a test of `scene`, or None when it has media and the
/// adapter cannot blend 32-bit floats (Mesa's GL): there the renderer must
/// refuse the scene (the CLI then renders it with photon-cpu), which this
/// asserts.
pub fn media_context(test: &str, scene: &Scene) -> Option<GpuContext> {
    let ctx = test_context(test);
    if ctx.float32_blend || scene.media.is_empty() {
        return Some(ctx);
    }
    let why = GpuRenderer::unsupported(&ctx, scene).expect("media refused without f32 blending");
    eprintln!("{test}: {why}");
    None
}

/// A camera at `size`×`size` with the eye close to `cornell-box`'s floor,
/// looking down into the corner: photon spheres there cross the near plane
/// and lie behind the eye, the hard case for a splat's or a tile's footprint.
pub fn eye_near_the_floor(size: u32) -> hikari_core::camera::Camera {
    hikari_core::camera::Camera::new(
        glam::Vec3::new(0.2, -0.93, 0.6),
        glam::Vec3::new(-0.5, -1.0, -0.6),
        glam::Vec3::Y,
        100.0,
        size,
        size,
    )
    .expect("a valid camera")
}
