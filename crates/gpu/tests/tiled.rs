//! The tiled estimator against the raster splat on the same frame, its
//! determinism, and the resizing that keeps it from ever dropping photons.
//! (Its twin tests against photon-cpu are in twin.rs.)

use glam::{Vec3, Vec4};
use hikari_core::photon::{TraceSettings, TracedPhotons, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::renderer::SEED_CORNELL_LOD;
use hikari_gpu::test_support::test_context;
use hikari_gpu::tiled::Estimator;
use hikari_gpu::{GpuContext, GpuRenderer, GpuSettings};

fn scene(name: &str) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(64, 48).unwrap();
    scene
}

/// The global and caustic targets of one frame.
fn frame(
    ctx: GpuContext,
    scene: &Scene,
    traced: &TracedPhotons,
    estimator: Estimator,
    lod: bool,
    radius: Option<f32>,
) -> (Vec<Vec4>, Vec<Vec4>, GpuRenderer) {
    let (global, caustic) = PhotonCpuSettings { radius, ..Default::default() }.estimate_params(scene);
    let settings = GpuSettings { estimator, lod: lod.then_some(SEED_CORNELL_LOD), ..GpuSettings::new(global, caustic) };
    let gpu = GpuRenderer::new(ctx, scene, traced, settings).unwrap();
    gpu.render().unwrap();
    let indirect = gpu.read(&gpu.targets.indirect).unwrap();
    let caustic = gpu.read(&gpu.targets.caustic).unwrap();
    (indirect, caustic, gpu)
}

/// Worst relative difference of lit pixels, and how many are lit.
fn difference(a: &[Vec4], b: &[Vec4]) -> (f32, usize) {
    let mut worst = 0.0f32;
    let mut lit = 0;
    for (x, y) in a.iter().zip(b) {
        let (x, y): (Vec3, Vec3) = (x.truncate(), y.truncate());
        if y.max_element() > 0.0 || x.max_element() > 0.0 {
            lit += 1;
            worst = worst.max(((x - y).abs() / y.max(Vec3::splat(1e-30))).max_element());
        }
    }
    (worst, lit)
}

/// Tiled equals raster pixel for pixel (in the radiance format's precision),
/// with LOD power scales too, and two tiled frames are the same bits.
#[test]
fn tiled_estimate_equals_the_splat_and_repeats_exactly() {
    let ctx = test_context("tiled_estimate_equals_the_splat_and_repeats_exactly");
    // Without f32 blending (Mesa's GL) the splat adds in f16, rounding at
    // every add (up to 3.2% on cornell-caustic, twin.rs); the tiled sum is
    // exact and rounds to f16 once.
    let tolerance = if ctx.float32_blend { 2e-4 } else { 5e-2 };
    for (name, lod) in [("cornell-caustic", false), ("cornell-box", true)] {
        let scene = scene(name);
        let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, seed: 5, ..Default::default() }, &Silent);
        let (raster_global, raster_caustic, _) = frame(ctx.clone(), &scene, &traced, Estimator::Raster, lod, None);
        let (tiled_global, tiled_caustic, gpu) = frame(ctx.clone(), &scene, &traced, Estimator::Tiled, lod, None);
        for (map, tiled, raster, min_lit) in
            [("global", &tiled_global, &raster_global, 1500), ("caustic", &tiled_caustic, &raster_caustic, 0)]
        {
            let (worst, lit) = difference(tiled, raster);
            eprintln!("{name} {map} (LOD {lod}): {lit} lit pixels, worst relative difference {worst:e}");
            assert!(lit >= min_lit, "{name} {map}: {lit} lit pixels");
            assert!(worst < tolerance, "{name} {map}: tiled differs from raster by {worst}");
        }
        assert!(tiled_caustic.iter().any(|p| p.x > 0.0) || name != "cornell-caustic");
        // The same frame again: the same bits, whatever order the atomics ran in.
        gpu.render().unwrap();
        assert_eq!(gpu.read(&gpu.targets.indirect).unwrap(), tiled_global, "{name}: a second frame differs");
    }
}

/// At a size where photons' quads span several 16-pixel tiles, the raster
/// splat trims them to the tiles whose depths meet the sphere and skips
/// pixels in front of it (splat.wgsl); the tiled estimator does neither:
/// the two still agree pixel for pixel, so no lit pixel was trimmed away.
#[test]
fn the_trimmed_splat_leaves_out_no_lit_pixel() {
    let ctx = test_context("the_trimmed_splat_leaves_out_no_lit_pixel");
    let tolerance = if ctx.float32_blend { 2e-4 } else { 5e-2 };
    for (name, radius) in [("cornell-box", None), ("cornell-caustic", Some(0.04))] {
        let mut scene = Scene::load(name).unwrap();
        scene.camera = scene.camera.with_resolution(256, 192).unwrap();
        let traced = trace_photons(&scene, &TraceSettings { photons: 8_000, seed: 9, ..Default::default() }, &Silent);
        let (raster, _, _) = frame(ctx.clone(), &scene, &traced, Estimator::Raster, false, radius);
        let (tiled, _, _) = frame(ctx.clone(), &scene, &traced, Estimator::Tiled, false, radius);
        let (worst, lit) = difference(&raster, &tiled);
        eprintln!("{name} at 256x192: {lit} lit pixels, worst relative difference {worst:e}");
        assert!(lit > 256 * 192 * 2 / 5, "{name}: {lit} lit pixels");
        assert!(worst < tolerance, "{name}: the trimmed splat differs from the tiled estimate by {worst}");
    }
}

/// A tiny loop budget and large photon spheres around the eye (each
/// covering most tiles): the first guess of the list size overflows and each list needs
/// many gather slices; `render` resizes and redraws until the frame is the
/// splat's.
#[test]
fn tiled_lists_and_slices_grow_until_the_frame_fits() {
    let mut ctx = test_context("tiled_lists_and_slices_grow_until_the_frame_fits");
    ctx.loop_budget = 400;
    // Without f32 blending (Mesa's GL) the splat adds in f16, rounding at
    // every add (up to 3.2% on cornell-caustic, twin.rs); the tiled sum is
    // exact and rounds to f16 once.
    let tolerance = if ctx.float32_blend { 2e-4 } else { 5e-2 };
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = hikari_gpu::test_support::eye_near_the_floor(48);
    let traced = trace_photons(&scene, &TraceSettings { photons: 10_000, seed: 9, ..Default::default() }, &Silent);
    // Photon spheres of radius 0.4 (a fifth of the box) cover most of the 9 tiles.
    let radius = Some(0.4);
    let (raster, _, _) = frame(ctx.clone(), &scene, &traced, Estimator::Raster, false, radius);
    let (tiled, _, gpu) = frame(ctx, &scene, &traced, Estimator::Tiled, false, radius);
    let (slices, entries) = gpu.tiled_sizes().expect("the tiled estimator ran");
    let photons = traced.indirect().len() as u32;
    eprintln!("{photons} photons: {slices} gather slices, {entries} list entries");
    assert!(slices > 1, "one slice under a 400-iteration budget");
    assert!(entries > 4 * photons, "the first guess (4 tiles a photon) was never exceeded");
    let (worst, lit) = difference(&tiled, &raster);
    assert!(lit > 1000 && worst < tolerance, "{lit} lit, worst {worst}");
}
