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

/// Runs `main` of `source` (composed after `modules`) over `count`
/// invocations with one read-write buffer `io` of `words` u32 initialised
/// from `input`, and returns the buffer.
pub fn run_kernel(ctx: &GpuContext, modules: &[&crate::wgsl::Module], main: &str, input: &[u32]) -> Vec<u32> {
    run_kernel_on(ctx, modules, main, "io", input)
}

/// `run_kernel` with the buffer named `buffer` (what `modules` read).
pub fn run_kernel_on(
    ctx: &GpuContext,
    modules: &[&crate::wgsl::Module],
    main: &str,
    buffer: &str,
    input: &[u32],
) -> Vec<u32> {
    let composed = crate::wgsl::compose(modules);
    // Kernels over the surface modules get the surfaces buffer's sheen
    // table (bsdf.wgsl reads it), as every pass does; the phony read keeps
    // the binding in the pipeline's layout when the kernel never shades.
    let with_surfaces = composed.contains("struct Surfaces {");
    let (surfaces_decl, touch) = if with_surfaces {
        ("@group(0) @binding(1) var<storage, read> surfaces: Surfaces;\n", "_ = surfaces.sheen_albedo[0];\n")
    } else {
        ("", "")
    };
    let kernel = format!(
        "@group(0) @binding(0) var<storage, read_write> {buffer}: array<u32>;\n{surfaces_decl}\
         @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n{touch}{main}\n}}\n"
    );
    let source = composed + &kernel;
    let device = &ctx.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("kernel"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    use wgpu::util::DeviceExt;
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(input),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    });
    let surfaces = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: &crate::scene_upload::surfaces_contents(&[bytemuck::Zeroable::zeroed()]),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let mut entries = vec![wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }];
    if with_surfaces {
        entries.push(wgpu::BindGroupEntry { binding: 1, resource: surfaces.as_entire_binding() });
    }
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((input.len() as u32).div_ceil(64), 1, 1);
    }
    ctx.queue.submit([encoder.finish()]);
    crate::readback::read_u32s(ctx, &buffer, input.len() as u64).unwrap()
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

/// An open 4×4 floor at y = 0 (albedo 0.5) with `objects` on it and
/// `lights`, seen at `size`² from above and in front, so that the top rows
/// see past the floor's far edge (the sky, where there is one).
pub fn open_floor(size: u32, objects: &str, lights: &str) -> Scene {
    let text = format!(
        r#"
[camera]
position = [0.0, 1.2, 2.5]
look_at = [0.0, 0.2, 0.0]
fov_y = 40.0
resolution = [{size}, {size}]

[[material]]
name = "floor"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[material]]
name = "grey"
type = "diffuse"
albedo = [0.6, 0.55, 0.5]

[[material]]
name = "mirror"
type = "mirror"
reflectance = [0.9, 0.9, 0.9]

[[object]]
shape = "quad"
corner = [-2.0, 0.0, -2.0]
edge_u = [0.0, 0.0, 4.0]
edge_v = [4.0, 0.0, 0.0]
material = "floor"

{objects}
{lights}"#
    );
    Scene::from_toml(&text, "open-floor", None).expect("a valid test scene")
}

/// A grey box floating over an open floor under a sun 30° from the zenith:
/// its hard shadow, its lit top and the light it reflects are in view.
pub fn sun_over_a_box(size: u32) -> Scene {
    open_floor(
        size,
        "[[object]]\nshape = \"box\"\ncenter = [-0.2, 0.5, 0.0]\nsize = [0.4, 0.3, 0.4]\nmaterial = \"grey\"\n",
        "[[light]]\ntype = \"directional\"\ndirection = [0.5, -0.866, -0.2]\nirradiance = [3.0, 3.0, 3.0]\n",
    )
}

/// A grey box and a mirror ball on an open floor under a uniform sky of
/// radiance 1: the box's soft shadow, the sky seen past the floor and in
/// the ball.
pub fn sky_over_a_box(size: u32) -> Scene {
    open_floor(
        size,
        "[[object]]\nshape = \"box\"\ncenter = [-0.35, 0.25, 0.0]\nsize = [0.5, 0.5, 0.5]\nmaterial = \"grey\"\n\n\
         [[object]]\nshape = \"sphere\"\ncenter = [0.45, 0.25, 0.3]\nradius = 0.25\nmaterial = \"mirror\"\n",
        "[environment]\nradiance = [1.0, 1.0, 1.0]\n",
    )
}

/// [`sun_over_a_box`] also under a sky, in absorbing and scattering fog
/// that fills the scene: distant lights in a medium.
pub fn sun_and_sky_in_fog(size: u32) -> Scene {
    open_floor(
        size,
        "[[object]]\nshape = \"box\"\ncenter = [-0.2, 0.5, 0.0]\nsize = [0.4, 0.3, 0.4]\nmaterial = \"grey\"\n",
        "[[light]]\ntype = \"directional\"\ndirection = [0.5, -0.866, -0.2]\nirradiance = [3.0, 3.0, 3.0]\n\n\
         [environment]\nradiance = [0.3, 0.4, 0.5]\n\n\
         [[medium]]\nsigma_a = [0.02, 0.03, 0.04]\nsigma_s = [0.1, 0.1, 0.1]\nphase = \"hg\"\ng = 0.3\n",
    )
}
