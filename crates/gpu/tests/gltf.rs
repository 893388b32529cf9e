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
