//! Pipelines specialised to what a scene uses (`SceneFeatures`) draw what
//! the general pipelines draw: the same pixels, the same photons; and a
//! scene edited to use more gets pipelines for it.

use hikari_core::bsdf::Bsdf;
use hikari_core::material::Material;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::Image;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::features::SceneFeatures;
use hikari_gpu::test_support::media_context;
use hikari_gpu::tiled::Estimator;
use hikari_gpu::trace::GpuTracer;
use hikari_gpu::{GpuContext, GpuRenderer, GpuSettings};

fn small(name: &str) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(48, 40).unwrap();
    scene
}

fn render(ctx: &GpuContext, scene: &Scene, estimator: Estimator, features: SceneFeatures) -> Image {
    let traced = trace_photons(scene, &TraceSettings { photons: 4_000, seed: 3, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(scene);
    let settings = GpuSettings { estimator, ..GpuSettings::new(global, caustic) };
    let gpu = GpuRenderer::with_features(ctx.clone(), scene, &traced, settings, features).expect("GPU renderer");
    gpu.render().expect("frame");
    gpu.read_image().unwrap().0
}

/// Pixels further apart than float rounding, and how many are lit.
fn differing(a: &Image, b: &Image) -> (usize, usize) {
    let far = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-5 * a.max_element().max(1e-3));
    (far.count(), b.pixels.iter().filter(|p| p.max_element() > 0.0).count())
}

fn assert_specialised_draws_as_general(name: &str, estimator: Estimator) {
    let scene = small(name);
    let Some(ctx) = media_context(name, &scene) else { return };
    let own = SceneFeatures::of_scene(&scene);
    let specialised = render(&ctx, &scene, estimator, own);
    let general = render(&ctx, &scene, estimator, SceneFeatures::ALL);
    let (far, lit) = differing(&specialised, &general);
    eprintln!("{name} ({own:?}, {estimator:?}): {far} pixels differ, {lit} lit");
    assert!(lit > general.pixels.len() / 2);
    assert_eq!(far, 0);
}

#[test]
fn a_plain_box_draws_as_with_every_feature() {
    assert_specialised_draws_as_general("cornell-box", Estimator::Raster);
    assert_specialised_draws_as_general("cornell-box", Estimator::Tiled);
}

#[test]
fn glass_and_fog_draw_as_with_every_feature() {
    assert_specialised_draws_as_general("cornell-caustic", Estimator::Raster);
    assert_specialised_draws_as_general("fog-stage", Estimator::Raster);
}

#[test]
fn a_glossy_textured_file_draws_as_with_every_feature() {
    let showcase = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/showcase.glb");
    assert_specialised_draws_as_general(showcase, Estimator::Raster);
}

/// cornell-box with its first diffuse material made a glossy metal.
fn with_glossy_material(mut scene: Scene) -> Scene {
    let diffuse = scene.materials.iter().position(|m| matches!(m, Material::Diffuse { .. })).unwrap();
    scene.materials[diffuse] = Material::Pbr(Bsdf::new(glam::Vec3::new(0.9, 0.6, 0.3), 1.0, 0.5, 1.0));
    scene
}

#[test]
fn a_scene_edited_to_use_more_gets_pipelines_for_it() {
    let plain = small("cornell-box");
    let glossy = with_glossy_material(plain.clone());
    assert!(!SceneFeatures::of_scene(&plain).glossy && SceneFeatures::of_scene(&glossy).glossy);
    let ctx = hikari_gpu::test_support::test_context("edited scene");
    let trace =
        |scene: &Scene| trace_photons(scene, &TraceSettings { photons: 4_000, seed: 3, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&plain);
    let settings = GpuSettings::new(global, caustic);
    let mut gpu = GpuRenderer::new(ctx.clone(), &plain, &trace(&plain), settings.clone()).unwrap();
    gpu.render().unwrap();
    gpu.set_scene(&glossy, &trace(&glossy)).unwrap();
    gpu.render().unwrap();
    let edited = gpu.read_image().unwrap().0;
    let built = GpuRenderer::new(ctx, &glossy, &trace(&glossy), settings).unwrap();
    built.render().unwrap();
    let built = built.read_image().unwrap().0;
    assert_eq!(differing(&edited, &built).0, 0);
    // And the glossy lobe shows: the plain box's image differs.
    let plain_image =
        render(&hikari_gpu::test_support::test_context("plain"), &plain, Estimator::Raster, SceneFeatures::ALL);
    assert!(differing(&plain_image, &built).0 > 100);
}

#[test]
fn the_specialised_tracer_stores_the_general_ones_photons() {
    let ctx = hikari_gpu::test_support::test_context("tracer features");
    let settings = TraceSettings { photons: 3_000, seed: 5, ..Default::default() };
    for name in ["cornell-box", "cornell-caustic"] {
        let scene = Scene::load(name).unwrap();
        let own = SceneFeatures::of_scene(&scene);
        let mut specialised = GpuTracer::with_features(&ctx, &scene, own).unwrap();
        let mut general = GpuTracer::with_features(&ctx, &scene, SceneFeatures::ALL).unwrap();
        let (a, _) = specialised.trace(&ctx, &settings).unwrap();
        let (b, _) = general.trace(&ctx, &settings).unwrap();
        for (x, y) in [(&a.indirect(), &b.indirect()), (&a.caustic, &b.caustic)] {
            assert!(!x.is_empty() || name == "cornell-box");
            assert_eq!(x.len(), y.len(), "{name}");
            for (p, q) in x.iter().zip(y.iter()) {
                assert_eq!(
                    (p.position, p.power_rgb9e5, p.direction_and_class),
                    (q.position, q.power_rgb9e5, q.direction_and_class)
                );
            }
        }
    }
}
