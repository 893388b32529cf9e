//! A glTF scene on the GPU renders as the TOML scene it was written from.

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_core::scene::gltf::export::scene_to_glb;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

const SIZE: u32 = 32;

fn frame(scene: &Scene) -> Vec<glam::Vec4> {
    let ctx = test_context("gltf");
    let photons = trace_photons(scene, &TraceSettings { photons: 5_000, seed: 3, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(scene);
    let gpu = GpuRenderer::new(ctx, scene, &photons, GpuSettings::new(global, caustic)).expect("GPU renderer");
    gpu.render().expect("GPU frame");
    gpu.read(gpu.resolved()).expect("readback")
}

#[test]
fn gltf_cornell_box_renders_as_the_toml_one_on_the_gpu() {
    let mut toml = Scene::load("cornell-box").unwrap();
    toml.camera = toml.camera.with_resolution(SIZE, SIZE).unwrap();
    let dir = std::env::temp_dir().join(format!("hikari-gpu-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cornell-box.glb");
    std::fs::write(&path, scene_to_glb(&toml).unwrap()).unwrap();
    let mut gltf = Scene::load(path.to_str().unwrap()).unwrap();
    gltf.camera = gltf.camera.with_resolution(SIZE, SIZE).unwrap();
    let (a, b) = (frame(&toml), frame(&gltf));
    let mean = a.iter().map(|p| p.truncate().element_sum() as f64 / 3.0).sum::<f64>() / a.len() as f64;
    assert!(mean > 0.0);
    // Pixels that differ by more than rounding: a ray through an edge may
    // fall on the other side when the camera's basis went through a quaternion.
    let differing = a.iter().zip(&b).filter(|(p, q)| (**p - **q).abs().max_element() as f64 > 1e-3 * mean).count();
    eprintln!("{differing} of {} pixels differ beyond rounding", a.len());
    assert!(differing <= a.len() / 100, "{differing} pixels differ");
}

/// The showcase (a sun through a window, a glowing strip, a spot, metal
/// and glass) renders on the GPU: every pass takes its sun and its
/// emissive mesh, and the frame is finite and lit.
#[test]
fn the_showcase_renders_on_the_gpu() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/showcase.glb");
    let mut scene = Scene::load(path).unwrap();
    scene.camera = scene.camera.with_resolution(48, 32).unwrap();
    use hikari_core::light::Light;
    assert!(scene.lights.iter().any(|l| matches!(l, Light::Directional { .. })));
    assert!(scene.lights.iter().any(|l| matches!(l, Light::Mesh(_))));
    let pixels = frame(&scene);
    assert!(pixels.iter().all(|p| p.is_finite()));
    let mean = pixels.iter().map(|p| p.truncate().element_sum() as f64 / 3.0).sum::<f64>() / pixels.len() as f64;
    eprintln!("showcase: mean radiance {mean:.4}");
    assert!(mean > 0.01, "a dark showcase: {mean}");
}

/// `KHR_materials_volume` on the GPU: looking straight down through a
/// glass slab whose inside keeps c = (0.5, 0.8, 1) over its thickness, the
/// specular pass sees the white sky at T + R of the hand computation
/// (Fresnel 0.04 at each face, every inner reflection summed), and the GPU
/// tracer's photons under the slab carry what the CPU tracer's carry
/// (within 1%: through clear glass the two tracers' photons here already
/// differ by 0.3%, refraction's rounding flipping some decisions).
#[test]
fn an_absorbing_glass_slab_on_the_gpu() {
    use glam::Vec3;
    use hikari_core::test_scenes::gltf_textures::{absorbing_slab_glb, load};
    let c = Vec3::new(0.5, 0.8, 1.0);
    let (f, bounce) = (0.04, Vec3::ONE - 0.0016 * c * c);
    let want = (1.0 - f) * (1.0 - f) * c / bounce + f + (1.0 - f) * (1.0 - f) * f * c * c / bounce;
    let mut scene = load("gpu-volume-slab", &absorbing_slab_glb(c, false));
    let size = 32;
    scene.camera =
        hikari_core::camera::Camera::new(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::Z, 20.0, size, size).unwrap();
    let ctx = test_context("an_absorbing_glass_slab_on_the_gpu");
    let traced = trace_photons(&scene, &TraceSettings { photons: 2_000, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let gpu = GpuRenderer::new(ctx.clone(), &scene, &traced, GpuSettings::new(global, caustic)).unwrap();
    gpu.render().unwrap();
    let image = gpu.read(gpu.resolved()).unwrap();
    let mean = image.iter().map(|p| p.truncate()).sum::<Vec3>() / image.len() as f32;
    eprintln!("GPU through an absorbing slab: {mean} (hand {want})");
    assert!(((mean - want) / want).abs().max_element() < 0.01, "{mean} against {want}");
    // Photons from a sun through the slab onto a floor: the GPU tracer's
    // power under the slab against the CPU tracer's (the same photons).
    let scene = load("gpu-volume-slab-floor", &absorbing_slab_glb(c, true));
    let settings = TraceSettings { photons: 50_000, ..Default::default() };
    let mut tracer = hikari_gpu::trace::GpuTracer::new(&ctx, &scene).expect("GPU tracer");
    let (photons, _) = tracer.trace(&ctx, &settings).expect("photons");
    let cpu = trace_photons(&scene, &settings, &Silent);
    let under = |t: &hikari_core::photon::TracedPhotons| {
        let near = t
            .global
            .iter()
            .filter(|p| p.position[1].abs() < 1e-3 && p.position[0].abs().max(p.position[2].abs()) < 0.75);
        near.map(|p| p.power_in_units()).sum::<Vec3>() * t.power_unit
    };
    let (g, c) = (under(&photons), under(&cpu));
    eprintln!("photon power under the slab: GPU {g}, CPU {c}");
    assert!(((g - c) / c).abs().max_element() < 0.01, "GPU {g} against CPU {c}");
}
