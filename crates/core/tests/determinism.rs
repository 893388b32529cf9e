//! The same seed gives the same image whatever the thread count: photon
//! tracing, the photon-map indexes (kd-trees, the volume map's BVH), both
//! CPU renderers and VCM, bit for bit.

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;

fn small(name: &str, size: u32) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(size, size).unwrap();
    scene
}

fn with_threads<T: Send>(threads: usize, job: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(job)
}

fn photon_cpu(scene: &Scene) -> Image {
    let traced = trace_photons(scene, &TraceSettings { photons: 20_000, seed: 11, ..Default::default() }, &Silent);
    let settings = PhotonCpuSettings { spp: 2, ..Default::default() };
    PhotonCpuRenderer::new(scene, &traced, &settings).render(&Silent).0
}

fn bits(image: &Image) -> Vec<[u32; 3]> {
    image.pixels.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

/// Fog with a region mesh (free flights, volume map, its BVH) and glass
/// (Fresnel branches, caustic map).
#[test]
fn photon_cpu_images_do_not_depend_on_thread_count() {
    for name in ["fog-stage-layered", "cornell-caustic"] {
        let scene = small(name, 24);
        let (one, two) = (with_threads(1, || photon_cpu(&scene)), with_threads(2, || photon_cpu(&scene)));
        assert!(one.mean() > 0.0, "{name}: black image");
        assert!(bits(&one) == bits(&two), "{name}: images differ between 1 and 2 threads");
    }
}

#[test]
fn path_traced_images_do_not_depend_on_thread_count() {
    let scene = small("fog-stage-layered", 16);
    let settings = path::PathSettings { spp: 4, seed: 5, ..Default::default() };
    let render = || path::render(&scene, &settings, &Silent).0;
    let (one, two) = (with_threads(1, render), with_threads(2, render));
    assert!(one.mean() > 0.0);
    assert!(bits(&one) == bits(&two), "images differ between 1 and 2 threads");
}

/// VCM's light subpaths are traced in chunks joined in order and its
/// splats added in that order: the same bits on 1 and 3 threads.
#[test]
fn vcm_images_do_not_depend_on_thread_count() {
    use hikari_core::render::vcm::{VcmSettings, render_pass};
    let scene = small("cornell-caustic", 24);
    let settings = VcmSettings { seed: 3, ..Default::default() };
    let render = || render_pass(&scene, &settings, 2).unwrap().0;
    let (one, three) = (with_threads(1, render), with_threads(3, render));
    assert!(one.mean() > 0.0);
    assert!(bits(&one) == bits(&three), "images differ between 1 and 3 threads");
}
