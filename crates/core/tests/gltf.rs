//! glTF scenes against the TOML scenes they were written from: the same
//! triangles, materials, lights and camera must give the same images.

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;
use hikari_core::scene::gltf::export::scene_to_glb;

fn photon_cpu(scene: &Scene) -> Image {
    let traced = trace_photons(scene, &TraceSettings { photons: 20_000, seed: 7, ..Default::default() }, &Silent);
    let settings = PhotonCpuSettings { spp: 2, seed: 5, ..Default::default() };
    PhotonCpuRenderer::new(scene, &traced, &settings).render(&Silent).0
}

fn path_traced(scene: &Scene) -> Image {
    path::render(scene, &path::PathSettings { spp: 4, seed: 3, ..Default::default() }, &Silent).0
}

/// The scene written as `.glb` by `scene_to_glb` (gltf-json) and loaded back.
fn through_gltf(scene: &Scene, tag: &str) -> Scene {
    let dir = std::env::temp_dir().join(format!("hikari-gltf-twin-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{tag}.glb"));
    std::fs::write(&path, scene_to_glb(scene).unwrap()).unwrap();
    let mut loaded = Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    loaded.camera = loaded.camera.with_resolution(scene.camera.width, scene.camera.height).unwrap();
    loaded
}

/// Largest per-pixel difference relative to the image's mean.
fn largest_difference(a: &Image, b: &Image) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut mean = 0.0f64;
    let mut worst = 0.0f32;
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.get(x, y), b.get(x, y));
            mean += (p.x + p.y + p.z) as f64 / 3.0;
            worst = worst.max((p - q).abs().max_element());
        }
    }
    worst / (mean / (a.width * a.height) as f64) as f32
}

fn small(name: &str, size: u32) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(size, size).unwrap();
    scene
}

/// cornell-box as glTF: same photons and pixels, so the images agree to
/// float rounding (the camera's basis goes through a quaternion, which can
/// move a ray by an ulp; a ray that grazes an edge may then land on the
/// other side, so a few pixels may differ by one sample's worth).
#[test]
fn gltf_cornell_box_renders_as_the_toml_one() {
    let toml = small("cornell-box", 24);
    let gltf = through_gltf(&toml, "cornell-box");
    assert_eq!(gltf.accel.triangle_count(), toml.accel.triangle_count());
    assert_eq!(gltf.lights, toml.lights);
    for (name, render) in [("photon-cpu", photon_cpu as fn(&Scene) -> Image), ("path", path_traced)] {
        let (a, b) = (render(&toml), render(&gltf));
        let d = largest_difference(&a, &b);
        eprintln!("{name}: largest difference {d:.2e} of the mean");
        assert!(d < 1e-3, "{name}: the glTF scene renders differently ({d:.2e} of the mean)");
    }
}
