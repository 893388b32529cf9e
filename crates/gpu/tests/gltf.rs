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
