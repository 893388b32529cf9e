//! A sky image on the GPU: pixels that see no surface show the image's
//! texel (the resolve pass), mirrors reflect it (the specular pass), and a
//! floor lit by it, a sun in the image included, matches photon-cpu's.

use glam::{Vec2, Vec3};
use hikari_core::envmap::EnvironmentMap;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::scene::Scene;
use hikari_gpu::gbuffer::geometric_normal::pixel_kind;
use hikari_gpu::test_support::{open_floor, test_context};
use hikari_gpu::{GpuRenderer, GpuSettings};

/// A 32×16 sky: blue, a warm sun patch 40° above the horizon, dark ground.
fn sky() -> EnvironmentMap {
    let (w, h) = (32u32, 16u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            // Columns 6–7: the sun where columns 22–23 put it before the
            // maps turned to Blender's layout (half a turn), so the box's
            // shadow falls where these tests' bounds were measured.
            if (6..8).contains(&x) && y == 4 {
                Vec3::new(400.0, 300.0, 200.0)
            } else if y >= h / 2 {
                Vec3::splat(0.05)
            } else {
                Vec3::new(0.3, 0.4, 0.6)
            }
        })
        .collect();
    EnvironmentMap::new(w, h, texels).unwrap()
}

/// `test_support::open_floor` with a box and a mirror ball under the sky
/// image, seen so that the top rows see the sky.
fn scene(size: u32) -> Scene {
    let objects = "[[object]]\nshape = \"box\"\ncenter = [-0.5, 0.25, -0.3]\nsize = [0.5, 0.5, 0.5]\nmaterial = \"grey\"\n\n\
                   [[object]]\nshape = \"sphere\"\ncenter = [0.6, 0.3, 0.2]\nradius = 0.3\nmaterial = \"mirror\"\n";
    let mut scene = open_floor(size, objects, "[environment]\nradiance = [1.0, 1.0, 1.0]\n");
    scene.set_environment_map(std::sync::Arc::new(sky()), "sky");
    scene
}

#[test]
fn a_sky_image_lights_and_shows_on_the_gpu() {
    let size = 48;
    let scene = scene(size);
    let ctx = test_context("a_sky_image_lights_and_shows_on_the_gpu");
    let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, ..Default::default() }, &Silent);
    let cpu_settings = PhotonCpuSettings { spp: 1, area_light_samples: 256, ..Default::default() };
    let (global, caustic) = cpu_settings.estimate_params(&scene);
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &cpu_settings).render(&Silent).0;
    let settings = GpuSettings { area_light_samples: 64, ..GpuSettings::new(global, caustic) };
    let gpu = GpuRenderer::new(ctx, &scene, &traced, settings).expect("the GPU draws sky images");
    gpu.render().unwrap();
    let image = gpu.read(gpu.resolved()).unwrap();
    let albedo = gpu.read(&gpu.targets.gbuffer.albedo).unwrap();
    let (mut sky, mut mirror, mut floor) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..size {
        for x in 0..size {
            let i = (y * size + x) as usize;
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let (g, c): (Vec3, Vec3) = (image[i].truncate(), cpu.pixels[i]);
            let relative = (g - c).abs().max_element() / c.max_element().max(1e-3);
            match scene.accel.intersect(&ray) {
                None => sky.push(relative),
                Some(_) if pixel_kind(albedo[i].w) == 1 => mirror.push(relative),
                Some(_) => floor.push(((g - c).element_sum() / c.element_sum().max(1e-6)) as f64),
            }
        }
    }
    let worst = |v: &[f32]| v.iter().copied().fold(0.0f32, f32::max);
    let mirror_mean = mirror.iter().sum::<f32>() / mirror.len().max(1) as f32;
    let floor_mean = floor.iter().sum::<f64>() / floor.len() as f64;
    let floor_abs = floor.iter().map(|d| d.abs()).sum::<f64>() / floor.len() as f64;
    eprintln!(
        "sky image: {} sky pixels (worst {:e}), {} mirror pixels (mean {:.2}%), {} lit pixels: mean signed {:.2}%, mean |difference| {:.2}%",
        sky.len(),
        worst(&sky),
        mirror.len(),
        100.0 * mirror_mean,
        floor.len(),
        100.0 * floor_mean,
        100.0 * floor_abs
    );
    assert!(sky.len() > 100, "{} pixels see the sky", sky.len());
    assert!(worst(&sky) < 1e-5, "the sky's texels");
    // The ball reflects the sky's texels and the floor (whose shadows
    // differ by shadow-map texels at their edges).
    assert!(mirror.len() > 50 && mirror_mean < 0.05, "mirror: {mirror_mean}");
    // The floor lit by K = 256 directions drawn from the image against 256
    // shadow rays a point: the same light, the sun's shadow edges aside.
    assert!(floor.len() > 500 && floor_mean.abs() < 0.03 && floor_abs < 0.05, "floor: {floor_mean}, {floor_abs}");
}

/// The GPU tracer emits from a sky image as `Light::emit` does (the same
/// random streams; directions within rounding of sin and cos): the same
/// number of stored photons and the same stored flux as the CPU tracer.
#[test]
fn the_gpu_tracer_emits_from_a_sky_image() {
    let scene = scene(16);
    let ctx = test_context("the_gpu_tracer_emits_from_a_sky_image");
    let settings = TraceSettings { photons: 50_000, seed: 3, ..Default::default() };
    let cpu = trace_photons(&scene, &settings, &Silent);
    let mut tracer = hikari_gpu::trace::GpuTracer::new(&ctx, &scene).expect("the GPU tracer samples sky images");
    let (gpu, _) = tracer.trace(&ctx, &settings).unwrap();
    let flux = |t: &hikari_core::photon::TracedPhotons| {
        t.global.iter().map(|p| p.power_in_units().as_dvec3()).sum::<glam::DVec3>() * t.power_unit as f64
    };
    let (g, c) = (flux(&gpu), flux(&cpu));
    eprintln!(
        "sky image photons: GPU {} stored, flux {g}; CPU {} stored, flux {c}",
        gpu.global.len(),
        cpu.global.len()
    );
    let count_ratio = gpu.global.len() as f64 / cpu.global.len() as f64;
    // The same photons but for rounding (measured: the same count, flux
    // within 3e-7).
    assert!((count_ratio - 1.0).abs() < 1e-3, "{} against {}", gpu.global.len(), cpu.global.len());
    assert!(((g - c) / c).abs().max_element() < 1e-3, "flux {g} against {c}");
}

/// The mean of `passes` GPU frames of `scene` (the same photons; each pass
/// its own light samples, `GpuLights::sampled`), and its mean absolute
/// difference from `reference` over 8×8-pixel blocks of lit surface.
fn mean_and_block_error(gpu: &mut GpuRenderer, scene: &Scene, passes: u32, reference: &[Vec3]) -> (Vec<Vec3>, f64) {
    let size = scene.camera.width as usize;
    let mut sum = vec![Vec3::ZERO; size * size];
    for pass in 1..=passes {
        gpu.settings.pass = pass;
        gpu.render().unwrap();
        for (s, v) in sum.iter_mut().zip(gpu.read(gpu.resolved()).unwrap()) {
            *s += v.truncate();
        }
    }
    let mean: Vec<Vec3> = sum.iter().map(|s| *s / passes as f32).collect();
    let (mut error, mut blocks) = (0.0, 0);
    for by in (0..size).step_by(8) {
        for bx in (0..size).step_by(8) {
            let block = |image: &[Vec3]| {
                let pixels = (by..by + 8).flat_map(|y| (bx..bx + 8).map(move |x| y * size + x));
                pixels.map(|i| image[i].element_sum() as f64).sum::<f64>()
            };
            let (g, c) = (block(&mean), block(reference));
            // Blocks that see the sky are the sky's texels on both sides.
            if c > 0.0 {
                error += ((g - c) / c).abs();
                blocks += 1;
            }
        }
    }
    (mean, error / blocks as f64)
}

/// Item 4 of #44: the sky's shadows on the GPU were 16 fixed hard shadows
/// that no number of passes changed (a 12% block error against Cycles on
/// a hall). Each pass now draws its own directions (the stratified set
/// rotated), so the mean of passes converges to photon-cpu's image, whose
/// every pixel samples the sky afresh: under a uniform sky and a sky image
/// with a sun, a box's soft shadow on the floor.
#[test]
fn sky_shadows_converge_over_passes() {
    let size = 48;
    let box_on_floor =
        "[[object]]\nshape = \"box\"\ncenter = [0.0, 0.3, 0.0]\nsize = [0.6, 0.6, 0.6]\nmaterial = \"grey\"\n";
    let uniform = open_floor(size, box_on_floor, "[environment]\nradiance = [1.0, 1.0, 1.0]\n");
    let mut image = uniform.clone();
    image.set_environment_map(std::sync::Arc::new(sky()), "sky");
    let ctx = test_context("sky_shadows_converge_over_passes");
    for (name, scene) in [("uniform sky", uniform), ("sky image", image)] {
        let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, ..Default::default() }, &Silent);
        let cpu_settings = PhotonCpuSettings { spp: 4, area_light_samples: 1024, ..Default::default() };
        let (global, caustic) = cpu_settings.estimate_params(&scene);
        let cpu = PhotonCpuRenderer::new(&scene, &traced, &cpu_settings).render(&Silent).0;
        // The default sample count: 16 directions a pass.
        let settings = GpuSettings { shadow_map_size: 512, ..GpuSettings::new(global, caustic) };
        let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &traced, settings).unwrap();
        let (_, one) = mean_and_block_error(&mut gpu, &scene, 1, &cpu.pixels);
        let (_, many) = mean_and_block_error(&mut gpu, &scene, 32, &cpu.pixels);
        eprintln!(
            "{name}: 8×8 block error against photon-cpu: 1 pass {:.2}%, 32 passes {:.2}%",
            100.0 * one,
            100.0 * many
        );
        // Measured on lavapipe: uniform 3.1% → 0.6%; image 11.1% → 3.9%
        // (8.7% → 4.0% before the maps turned to Blender's layout; then 128
        // passes stayed at 4.0% and 2048² maps reached 3.4%): the sun's
        // shadow edges in the maps' texels, a bias passes leave.
        let (ratio, floor) = if name == "uniform sky" { (0.3, 0.015) } else { (0.6, 0.05) };
        assert!(many < ratio * one && many < floor, "{name}: {many} after 32 passes against {one} after 1");
    }
}
