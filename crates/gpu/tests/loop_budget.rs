//! The specular pass never cuts work silently: its loops are counted
//! against a budget below llvmpipe's 65,535-iteration cap, gathers that would
//! pass it are split over more dispatches, and a frame that cannot fit is an
//! error, not an image with light missing.

use hikari_core::photon::{TraceSettings, TracedPhotons, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::scene::Scene;
use hikari_gpu::gbuffer::geometric_normal::pixel_kind;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuError, GpuRenderer, GpuSettings};

const SIZE: u32 = 64;

fn caustic_scene() -> Scene {
    let mut scene = Scene::load("cornell-caustic").unwrap();
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    scene
}

/// The GPU frame and its specular slices, with the loop budget `budget`
/// (None: the adapter's own).
fn gpu_frame(
    scene: &Scene,
    traced: &TracedPhotons,
    cpu: &PhotonCpuRenderer,
    budget: Option<u32>,
) -> Result<(Vec<glam::Vec4>, Vec<glam::Vec4>, u32), GpuError> {
    let mut ctx = test_context("loop budget");
    if let Some(budget) = budget {
        ctx.loop_budget = budget;
    }
    let settings = GpuSettings { area_light_samples: 16, ..GpuSettings::new(cpu.global_params, cpu.caustic_params) };
    let gpu = GpuRenderer::new(ctx, scene, traced, settings)?;
    gpu.render()?;
    let specular = gpu.read(gpu.specular_output())?;
    let albedo = gpu.read(&gpu.targets.gbuffer.albedo)?;
    Ok((specular, albedo, gpu.specular_slices()))
}

/// Pixels whose first surface is glass or a mirror (G-buffer kind 1 or 2).
fn specular_pixels(albedo: &[glam::Vec4]) -> Vec<usize> {
    (0..albedo.len()).filter(|&i| pixel_kind(albedo[i].w) == 1 || pixel_kind(albedo[i].w) == 2).collect()
}

/// The regression of issue #9: at 1,000,000 photons the glass ball of
/// cornell-caustic was drawn dark and blocky on lavapipe (its gathers
/// passed the driver's loop cap). Now the ball matches photon-cpu on the
/// same photons.
#[test]
fn glass_ball_at_a_million_photons_matches_photon_cpu() {
    let scene = caustic_scene();
    let traced = trace_photons(&scene, &TraceSettings { photons: 1_000_000, seed: 3, ..Default::default() }, &Silent);
    let cpu_settings = PhotonCpuSettings { spp: 1, area_light_samples: 64, ..Default::default() };
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &cpu_settings);
    let (cpu_image, _) = cpu.render(&Silent);
    let (specular, albedo, slices) = gpu_frame(&scene, &traced, &cpu, None).expect("GPU frame");
    let pixels = specular_pixels(&albedo);
    assert!(pixels.len() > 100, "only {} glass pixels", pixels.len());
    // The specular target holds the whole radiance of glass pixels.
    let (mut sum, mut count) = (0.0f64, 0);
    for &i in &pixels {
        let (g, c) = (specular[i].truncate(), cpu_image.pixels[i]);
        let (gl, cl) = (g.element_sum() / 3.0, c.element_sum() / 3.0);
        if cl > 1e-6 {
            sum += ((gl - cl).abs() / cl) as f64;
            count += 1;
        }
    }
    let mean = sum / count as f64;
    eprintln!("1M photons: {count} glass pixels, mean relative difference {:.3}%, {slices} slice(s)", mean * 100.0);
    assert!(mean < 0.05, "glass pixels differ from photon-cpu by {mean}");
}

/// Splitting the gathers over slices changes nothing but the order of the
/// sums: a budget that forces many slices gives the unsplit image.
#[test]
fn split_gathers_sum_to_the_unsplit_frame() {
    let scene = caustic_scene();
    let traced = trace_photons(&scene, &TraceSettings { photons: 100_000, seed: 4, ..Default::default() }, &Silent);
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    let (whole, albedo, whole_slices) = gpu_frame(&scene, &traced, &cpu, None).expect("unsplit frame");
    let (split, _, slices) = gpu_frame(&scene, &traced, &cpu, Some(2_500)).expect("split frame");
    eprintln!("budget 2500: {slices} slices (adapter's budget: {whole_slices})");
    assert_eq!(whole_slices, 1);
    assert!(slices > 1, "a budget of 2,500 iterations should need slices");
    let pixels = specular_pixels(&albedo);
    assert!(pixels.len() > 100);
    for i in pixels {
        let (a, b) = (whole[i].truncate(), split[i].truncate());
        assert!((a - b).abs().max_element() <= 1e-4 * a.max_element().max(1e-3), "pixel {i}: {a} vs {b}");
    }
}

/// A budget that not even the ray traversal fits is an error naming the
/// budget, never an image; one probe of the finest split finds it out,
/// without splitting the gathers ever finer first (each split retraces
/// every pixel: on lavapipe's budget a deep glass scene took ~40 s).
#[test]
fn a_budget_that_cannot_fit_is_an_error() {
    let scene = caustic_scene();
    let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, seed: 4, ..Default::default() }, &Silent);
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    let mut ctx = test_context("loop budget");
    ctx.loop_budget = 30;
    let settings = GpuSettings { area_light_samples: 16, ..GpuSettings::new(cpu.global_params, cpu.caustic_params) };
    let gpu = GpuRenderer::new(ctx, &scene, &traced, settings).expect("GPU renderer");
    match gpu.render() {
        Err(GpuError::LoopBudget(why)) => assert!(why.contains("30 shader loop iterations"), "{why}"),
        Err(other) => panic!("unexpected error {other}"),
        Ok(_) => panic!("a 30-iteration budget cannot draw glass"),
    }
    assert_eq!(gpu.specular_slices(), 1, "split before the probe said no split fits");
}
