//! The viewer's running mean: frames of independent photon sets averaged on
//! the GPU equal the mean of the same frames read back, and a reset starts
//! over.

use glam::Vec3;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::accumulate::AccumulatePass;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

#[test]
fn the_running_mean_is_the_mean_of_the_frames() {
    let ctx = test_context("accumulate");
    let mut scene = Scene::load("cornell-caustic").unwrap();
    scene.camera = scene.camera.with_resolution(40, 32).unwrap();
    let trace = |seed| trace_photons(&scene, &TraceSettings { photons: 3_000, seed, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &trace(1), GpuSettings::new(global, caustic)).unwrap();
    let mut mean = AccumulatePass::new(&ctx.device, gpu.resolved());
    let mut frames = Vec::new();
    for seed in 1..=4 {
        if seed > 1 {
            gpu.set_photons(&scene, &trace(seed)).unwrap();
        }
        gpu.render().unwrap();
        frames.push(gpu.read_image().unwrap().0);
        if seed == 3 {
            // What came before the reset is forgotten.
            mean.reset();
            frames.drain(..2);
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        mean.record(&ctx.queue, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
    }
    assert_eq!(mean.count(), 2);
    let got = gpu.read(&mean.mean).unwrap();
    let mut worst = 0.0f32;
    for (i, g) in got.iter().enumerate() {
        let want = frames.iter().map(|f| f.pixels[i]).sum::<Vec3>() / frames.len() as f32;
        worst = worst.max((g.truncate() - want).abs().max_element() / want.max_element().max(1e-3));
    }
    let differ = frames[0].pixels.iter().zip(&frames[1].pixels).filter(|(a, b)| a != b).count();
    assert!(differ > 500, "the two photon sets gave nearly the same frame ({differ} pixels differ)");
    assert!(worst < 1e-6, "worst relative difference {worst}");
}

/// The running mean's noise falls as 1/K: on cornell-box's back wall (flat,
/// lit by indirect light from everywhere), the variance of the difference
/// between two independent K-frame means is 2σ²/K, so it falls by 4 from
/// K = 1 to 4 and again to 16 (accepted: 2.5 to 6.4, for a test over
/// about 200 correlated pixels).
#[test]
fn the_mean_of_k_frames_has_a_kth_of_the_variance() {
    let ctx = test_context("accumulate variance");
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = scene.camera.with_resolution(40, 32).unwrap();
    let (w, h) = (40usize, 32usize);
    let trace = |seed| trace_photons(&scene, &TraceSettings { photons: 2_000, seed, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &trace(0), GpuSettings::new(global, caustic)).unwrap();
    let mut mean = AccumulatePass::new(&ctx.device, gpu.resolved());
    let mut mean_of = |first_seed: u64, k: u64| {
        mean.reset();
        for seed in first_seed..first_seed + k {
            gpu.set_photons(&scene, &trace(seed)).unwrap();
            gpu.render().unwrap();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            mean.record(&ctx.queue, &mut encoder);
            ctx.queue.submit([encoder.finish()]);
        }
        gpu.read(&mean.mean).unwrap()
    };
    // The back wall: above the blocks, between the side walls.
    let wall: Vec<usize> = (3..13).flat_map(|y| (12..28).map(move |x| y * w + x)).collect();
    assert!(wall.iter().all(|&i| i < w * h));
    let mut variance = |k: u64| {
        let (a, b) = (mean_of(1000, k), mean_of(2000, k));
        let diffs: Vec<f64> = wall.iter().map(|&i| (a[i].x - b[i].x) as f64).collect();
        let m = diffs.iter().sum::<f64>() / diffs.len() as f64;
        diffs.iter().map(|d| (d - m) * (d - m)).sum::<f64>() / diffs.len() as f64
    };
    let (v1, v4, v16) = (variance(1), variance(4), variance(16));
    eprintln!("variance of the difference: K=1 {v1:.3e}, K=4 {v4:.3e}, K=16 {v16:.3e}");
    for (ratio, what) in [(v1 / v4, "1 → 4"), (v4 / v16, "4 → 16")] {
        assert!((2.5..6.4).contains(&ratio), "variance fell by {ratio} from K = {what}");
    }
}

/// The odd frames' mean, kept beside the mean, gives the noise estimate
/// the CPU renderers give (`ImageMean::noise_estimate`, from the same
/// frames read back), after 2 to 5 frames, and none after a reset.
#[test]
fn the_noise_estimate_is_the_cpu_twins() {
    use hikari_core::progressive::ImageMean;
    let ctx = test_context("accumulate noise");
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = scene.camera.with_resolution(24, 20).unwrap();
    let trace = |seed| trace_photons(&scene, &TraceSettings { photons: 2_000, seed, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &trace(1), GpuSettings::new(global, caustic)).unwrap();
    let mut mean = AccumulatePass::new(&ctx.device, gpu.resolved());
    let mut cpu = ImageMean::new(24, 20);
    for seed in 1..=5 {
        gpu.set_photons(&scene, &trace(seed)).unwrap();
        gpu.render().unwrap();
        cpu.add(&gpu.read_image().unwrap().0);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        mean.record(&ctx.queue, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
        let (got, want) = (mean.read_noise(&ctx).unwrap(), cpu.noise_estimate());
        match (got, want) {
            (None, None) => assert_eq!(seed, 1),
            (Some(g), Some(w)) => assert!((g - w).abs() < 1e-4 * w, "after {seed} frames: {g} against {w}"),
            _ => panic!("after {seed} frames: {got:?} against {want:?}"),
        }
    }
    assert!(cpu.noise_estimate().unwrap() > 0.01, "the frames differ");
    mean.reset();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    mean.record(&ctx.queue, &mut encoder);
    ctx.queue.submit([encoder.finish()]);
    assert_eq!(mean.read_noise(&ctx).unwrap(), None);
}
