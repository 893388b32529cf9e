//! The photons-as-points debug view: every drawn photon lands on a pixel of
//! its surface (none where the G-buffer is empty, none through walls), and
//! the detail-level colours follow the LOD's distances.

use hikari_core::lod::LodSettings;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::points::PointColors;
use hikari_gpu::readback::read_rgba8;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

#[test]
fn points_show_the_drawn_photons_with_their_detail_levels() {
    let ctx = test_context("points");
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = scene.camera.with_resolution(64, 48).unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 3_000, seed: 1, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &traced, GpuSettings::new(global, caustic)).unwrap();
    gpu.render().unwrap();
    let lit = |pixels: &[u8]| pixels.chunks(4).filter(|p| p[..3].iter().any(|&c| c > 0)).count();
    let shown = read_rgba8(&ctx, gpu.draw_points(PointColors::Power).unwrap()).unwrap();
    let stored = traced.indirect().len();
    eprintln!("{} pixels show some of {stored} photons", lit(&shown));
    // At most one pixel per photon; fewer, as photons share pixels and
    // those on the blocks' hidden sides do not show (measured: 854 of 2,305).
    assert!(lit(&shown) > stored / 4 && lit(&shown) <= stored, "{} lit", lit(&shown));

    // With the LOD on, near photons are full detail (blue) and far ones coarse (red).
    let diagonal = scene.diagonal();
    gpu.settings.lod = Some(LodSettings { near: 0.9 * diagonal, far: 1.6 * diagonal, groups: 20 });
    gpu.render().unwrap();
    let levels = read_rgba8(&ctx, gpu.draw_points(PointColors::DetailLevel).unwrap()).unwrap();
    let blue = levels.chunks(4).filter(|p| p[2] > 200 && p[0] < 50).count();
    let red = levels.chunks(4).filter(|p| p[0] > 200 && p[2] < 50).count();
    eprintln!("detail levels: {blue} full-detail (blue) and {red} coarse (red) pixels");
    assert!(blue > 50 && red > 50, "blue {blue}, red {red}");
}
