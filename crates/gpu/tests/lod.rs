//! Level of detail on the GPU: culled photons are not drawn (the count the
//! LOD pass leaves for the indirect draw equals the CPU's prediction), and
//! the image keeps its brightness.

use hikari_core::lod::{LodSettings, detail_level, group_of, power_scale};
use hikari_core::photon::Photon;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

use hikari_gpu::renderer::SEED_CORNELL_LOD;

/// How many photons the CPU's LOD (hikari_core::lod) keeps.
fn predicted_survivors(photons: &[Photon], eye: glam::Vec3, lod: &LodSettings) -> usize {
    let n = photons.len() as u32;
    photons
        .iter()
        .enumerate()
        .filter(|(i, p)| {
            let q = detail_level((p.position() - eye).length(), lod);
            power_scale(q, group_of(*i as u32, n, lod.groups), lod.groups) > 0.0
        })
        .count()
}

#[test]
fn lod_draws_the_predicted_photons_and_keeps_the_image_mean() {
    let ctx = test_context("lod");
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = scene.camera.with_resolution(64, 64).unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 10_000, seed: 3, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let mut gpu = GpuRenderer::new(ctx, &scene, &traced, GpuSettings::new(global, caustic)).expect("GPU renderer");

    // LOD off: every photon is drawn.
    gpu.render().expect("GPU frame");
    let photons = traced.indirect();
    assert_eq!(gpu.drawn_photons().unwrap().0 as usize, photons.len());
    let mean = |v: &[glam::Vec4]| v.iter().map(|p| (p.x + p.y + p.z) as f64).sum::<f64>() / v.len() as f64;
    let off = mean(&gpu.read(&gpu.targets.indirect).unwrap());

    // LOD on: the drawn count is the CPU's prediction.
    let lod = SEED_CORNELL_LOD;
    gpu.settings.lod = Some(lod);
    gpu.render().expect("GPU frame");
    let predicted = predicted_survivors(&photons, scene.camera.position, &lod);
    let drawn = gpu.drawn_photons().unwrap().0 as usize;
    eprintln!("LOD: {drawn} of {} photons drawn (predicted {predicted})", photons.len());
    // Float rounding may move a photon sitting exactly on a group boundary.
    assert!(drawn.abs_diff(predicted) <= photons.len() / 1000 + 1, "drawn {drawn}, predicted {predicted}");
    assert!(drawn < photons.len() * 3 / 4, "LOD culled too little: {drawn} of {}", photons.len());

    let first = gpu.read(&gpu.targets.indirect).unwrap();
    let on = mean(&first);
    eprintln!("indirect image mean: LOD off {off:.5}, on {on:.5} ({:+.2}%)", (on - off) / off * 100.0);
    assert!((on - off).abs() / off < 0.05);

    // The compaction keeps storage order, so a second frame blends the same
    // instances in the same order: bit-identical radiance.
    gpu.render().expect("GPU frame");
    let second = gpu.read(&gpu.targets.indirect).unwrap();
    assert!(first.iter().zip(&second).all(|(a, b)| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits)));
}

/// LOD applies to volume photons too: the volume splat draws the CPU's
/// predicted survivors, and the in-scattered light keeps its mean roughly.
#[test]
fn lod_culls_volume_photons_and_keeps_the_mean() {
    let mut scene = Scene::load("fog-stage").unwrap();
    scene.camera = scene.camera.with_resolution(64, 48).unwrap();
    let Some(ctx) = hikari_gpu::test_support::media_context("volume lod", &scene) else { return };
    let traced = trace_photons(&scene, &TraceSettings { photons: 4_000, seed: 3, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let mut gpu = GpuRenderer::new(ctx, &scene, &traced, GpuSettings::new(global, caustic)).expect("GPU renderer");
    gpu.render().expect("GPU frame");
    let photons = &traced.volume;
    assert_eq!(gpu.drawn_volume_photons().unwrap() as usize, photons.len());
    let mean = |v: &[glam::Vec4]| v.iter().map(|p| (p.x + p.y + p.z) as f64).sum::<f64>() / v.len() as f64;
    let off = mean(&gpu.read(&gpu.targets.volume).unwrap());
    // The seed's fog setting n = 25, f = 3.
    let lod = LodSettings { near: 25.0, far: 3.0, groups: 20 };
    gpu.settings.lod = Some(lod);
    gpu.render().expect("GPU frame");
    let predicted = predicted_survivors(photons, scene.camera.position, &lod);
    let drawn = gpu.drawn_volume_photons().unwrap() as usize;
    let on = mean(&gpu.read(&gpu.targets.volume).unwrap());
    eprintln!("volume LOD: {drawn} of {} drawn (predicted {predicted}); mean off {off:.5}, on {on:.5}", photons.len());
    assert!(drawn.abs_diff(predicted) <= photons.len() / 1000 + 1, "drawn {drawn}, predicted {predicted}");
    assert!(drawn < photons.len() * 9 / 10, "LOD culled too little: {drawn} of {}", photons.len());
    // LOD keeps the expected power, but the few photons within reach of
    // the eye (in the fog) reach every pixel, so one culled or rescaled
    // changes the mean by percents: a loose bound.
    assert!((on - off).abs() / off < 0.10);
}

/// The LOD compaction over more than 65,536 photons (more than 256
/// workgroups, so the one-workgroup scan sums several counts per
/// invocation, the path the CLI's default 200,000 photons take): the GPU's
/// instances are exactly the CPU's survivors, in storage order, with the
/// CPU's power scales.
#[test]
fn lod_compaction_over_many_workgroups_equals_the_cpu() {
    let ctx = test_context("lod twin");
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = scene.camera.with_resolution(16, 16).unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 120_000, seed: 8, ..Default::default() }, &Silent);
    let photons = traced.indirect();
    assert!(photons.len() > 65_536, "only {} photons", photons.len());
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let lod = SEED_CORNELL_LOD;
    let settings = GpuSettings { lod: Some(lod), ..GpuSettings::new(global, caustic) };
    let gpu = GpuRenderer::new(ctx, &scene, &traced, settings).expect("GPU renderer");
    gpu.render().expect("GPU frame");
    let eye = scene.camera.position;
    let n = photons.len() as u32;
    let want: Vec<(usize, f32)> = photons
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let q = detail_level((p.position() - eye).length(), &lod);
            (i, power_scale(q, group_of(i as u32, n, lod.groups), lod.groups))
        })
        .filter(|(_, scale)| *scale > 0.0)
        .collect();
    let got = gpu.global_survivors().unwrap();
    eprintln!("LOD twin: {} of {} photons survive on the GPU, {} on the CPU", got.len(), photons.len(), want.len());
    // A photon exactly on a group boundary may round the other way.
    assert!(got.len().abs_diff(want.len()) <= photons.len() / 10_000 + 1);
    let mut cpu = want.iter().peekable();
    let mut matched = 0;
    for instance in &got {
        let position = [instance.position_x, instance.position_y, instance.position_z].map(f32::to_bits);
        // Skip CPU survivors the GPU rounded away, keeping storage order.
        while let Some((i, scale)) = cpu.next() {
            if photons[*i].position.map(f32::to_bits) == position {
                assert!(
                    (instance.scale - scale).abs() <= 1e-3 * scale,
                    "photon {i}: scale {} vs {scale}",
                    instance.scale
                );
                matched += 1;
                break;
            }
        }
    }
    assert!(matched + photons.len() / 10_000 + 1 >= want.len(), "only {matched} of {} matched in order", want.len());
}
