//! The GPU renderer's whole image against `photon-cpu` with the same photon
//! maps: per-pixel relative difference, away from shadow edges.

use glam::{Vec2, Vec3};
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::{DEFAULT_ALPHA, ImageMean, Schedules, pass_jitter, pass_seed, photon_cpu_pass};
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::sampling::Rng;
use hikari_core::scene::Scene;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

const SIZE: u32 = 64;

/// Fraction of each light that a point sees, by shadow rays (64 per area light).
fn visibility(scene: &Scene, x: Vec3) -> Vec<f32> {
    let mut rng = Rng::for_item(99, 0);
    scene
        .lights
        .iter()
        .map(|light| {
            let count = if light.is_area() { 64 } else { 1 };
            let (mut seen, mut total) = (0, 0);
            for _ in 0..count {
                let Some(s) = light.sample_incident(x, rng.next_2d()) else { continue };
                total += 1;
                // As direct_diffuse casts it: from the point itself (the BVH skips t < epsilon).
                let mut ray = hikari_core::geometry::Ray::new(x, s.wi);
                ray.t_max = s.distance * (1.0 - 1e-4);
                seen += (!scene.accel.occluded(&ray)) as u32;
            }
            if total == 0 { 1.0 } else { seen as f32 / total as f32 }
        })
        .collect()
}

/// Pixels to compare: a diffuse surface in both renderers, and no change of
/// light visibility within 2 pixels (shadow-map edges and penumbrae differ
/// by construction: texel-sized steps, N hard shadows for a soft one).
fn comparison_mask(scene: &Scene, gpu_albedo: &[glam::Vec4]) -> Vec<bool> {
    let n = (SIZE * SIZE) as usize;
    let mut vis: Vec<Option<Vec<f32>>> = vec![None; n];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            if let Some(hit) = scene.accel.intersect(&ray) {
                if scene.material(&hit).is_diffuse() && gpu_albedo[(y * SIZE + x) as usize].w == 0.0 {
                    vis[(y * SIZE + x) as usize] = Some(visibility(scene, hit.point));
                }
            }
        }
    }
    let mut mask = vec![false; n];
    for y in 0..SIZE as i32 {
        for x in 0..SIZE as i32 {
            let Some(v) = &vis[(y * SIZE as i32 + x) as usize] else { continue };
            let steady = (-2..=2).all(|dy| {
                (-2..=2).all(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= SIZE as i32 || ny >= SIZE as i32 {
                        return true;
                    }
                    match &vis[(ny * SIZE as i32 + nx) as usize] {
                        Some(w) => w.iter().zip(v).all(|(a, b)| (a - b).abs() < 0.02),
                        None => true,
                    }
                })
            });
            mask[(y * SIZE as i32 + x) as usize] = steady;
        }
    }
    mask
}

fn compare(scene_name: &str) -> Option<(f64, usize, Option<(f64, usize)>)> {
    compare_scene(scene_name, Scene::load(scene_name).unwrap())
}

fn compare_scene(scene_name: &str, scene: Scene) -> Option<(f64, usize, Option<(f64, usize)>)> {
    compare_passes(scene_name, scene, 50_000, 1)
}

/// The mean of `passes` progressive passes of `photons` paths each
/// (docs/progressive.md) on the GPU (accumulated there) and on the CPU.
fn compare_passes(
    scene_name: &str,
    mut scene: Scene,
    photons: u64,
    passes: u32,
) -> Option<(f64, usize, Option<(f64, usize)>)> {
    let ctx = test_context(scene_name);
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    let trace = |pass| {
        let seed = pass_seed(5, pass);
        trace_photons(&scene, &TraceSettings { photons, seed, ..Default::default() }, &Silent)
    };
    // One sample at the pixel centre, as the rasterizer sees it; many shadow
    // rays per area light so the CPU's direct light is nearly noise-free.
    let cpu_settings = PhotonCpuSettings { spp: 1, area_light_samples: 64, seed: 5, ..Default::default() };
    let (global, caustic) = cpu_settings.estimate_params(&scene);
    let schedules = Schedules::new([global.radius, caustic.radius, global.radius], DEFAULT_ALPHA);
    // Both sample each pixel once per pass, at the pass's jitter.
    let jittered = |pass| {
        let mut s = scene.clone();
        s.camera.jitter = pass_jitter(pass);
        s
    };
    let mut cpu_mean = ImageMean::new(SIZE, SIZE);
    for pass in 1..=passes {
        cpu_mean.add(&photon_cpu_pass(&jittered(pass), &cpu_settings, photons, &schedules, pass).0);
    }
    let cpu_image = cpu_mean.mean();
    let settings = GpuSettings { area_light_samples: 16, shadow_map_size: 1024, ..GpuSettings::new(global, caustic) };
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &trace(1), settings).expect("GPU renderer");
    let mut gpu_mean = hikari_gpu::accumulate::AccumulatePass::new(&ctx.device, gpu.resolved());
    for pass in 1..=passes {
        if pass > 1 {
            let [r_global, r_caustic, _] = schedules.radii(pass);
            (gpu.settings.global.radius, gpu.settings.caustic.radius) = (r_global, r_caustic);
            gpu.set_photons(&scene, &trace(pass)).expect("the pass's photons");
            gpu.set_camera(&jittered(pass).camera).unwrap();
        }
        gpu.render().expect("GPU frame");
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        gpu_mean.record(&ctx.queue, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
    }
    let mut gpu_image = hikari_core::render::Image::new(SIZE, SIZE);
    for (p, v) in gpu_image.pixels.iter_mut().zip(gpu.read(&gpu_mean.mean).unwrap()) {
        assert!(v.is_finite());
        *p = v.truncate();
    }
    let albedo = gpu.read(&gpu.targets.gbuffer.albedo).unwrap();
    let mask = comparison_mask(&scene, &albedo);
    let (mut sum, mut count) = (0.0f64, 0usize);
    for i in 0..mask.len() {
        if !mask[i] {
            continue;
        }
        let (g, c) = (gpu_image.pixels[i], cpu_image.pixels[i]);
        let (gl, cl) = ((g.x + g.y + g.z) / 3.0, (c.x + c.y + c.z) / 3.0);
        if cl > 1e-6 {
            sum += ((gl - cl).abs() / cl) as f64;
            count += 1;
        }
    }
    let mean = sum / count.max(1) as f64;
    eprintln!("{scene_name}: {count} pixels compared, mean relative difference {:.3}%", mean * 100.0);
    Some((mean, count, specular_difference(&gpu_image, &cpu_image, &albedo)))
}

/// Mean relative difference over pixels whose first surface is a mirror or
/// glass (G-buffer kind 1 or 2): the GPU's ray-traced specular chain against
/// photon-cpu's Whitted recursion, whose diffuse hits differ only by shadow
/// maps against shadow rays.
fn specular_difference(
    gpu: &hikari_core::render::Image,
    cpu: &hikari_core::render::Image,
    albedo: &[glam::Vec4],
) -> Option<(f64, usize)> {
    let (mut sum, mut count) = (0.0f64, 0usize);
    for i in 0..albedo.len() {
        if albedo[i].w == 1.0 || albedo[i].w == 2.0 {
            let (g, c) = (gpu.pixels[i], cpu.pixels[i]);
            let (gl, cl) = ((g.x + g.y + g.z) / 3.0, (c.x + c.y + c.z) / 3.0);
            if cl > 1e-6 {
                sum += ((gl - cl).abs() / cl) as f64;
                count += 1;
            }
        }
    }
    (count > 0).then(|| (sum / count as f64, count))
}

#[test]
fn gpu_image_matches_photon_cpu_on_cornell_box() {
    let Some((mean, count, _)) = compare("cornell-box") else { return };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
}

#[test]
fn gpu_image_matches_photon_cpu_on_cornell_caustic() {
    let Some((mean, count, specular)) = compare("cornell-caustic") else { return };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
    let (specular_mean, specular_count) = specular.expect("the glass ball is in view");
    eprintln!("cornell-caustic glass: {specular_count} pixels, mean relative difference {:.3}%", specular_mean * 100.0);
    assert!(specular_count > 100);
    assert!(specular_mean < 0.05, "glass pixels: mean relative difference {specular_mean}");
}

/// Progressive passes: the mean of 6 passes accumulated on the GPU matches
/// photon-cpu's mean of the same passes as closely as one frame does.
#[test]
fn progressive_gpu_image_matches_photon_cpu_on_cornell_caustic() {
    let mut scene = Scene::load("cornell-caustic").unwrap();
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    let Some((mean, count, specular)) = compare_passes("cornell-caustic passes", scene, 20_000, 6) else { return };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
    let (specular_mean, _) = specular.expect("the glass ball is in view");
    assert!(specular_mean < 0.05, "glass pixels: mean relative difference {specular_mean}");
}

/// A floor that is part diffuse, part mirror: the raster passes shade the
/// diffuse part, the specular pass follows the mirror part (photon-cpu does
/// both by recursion).
#[test]
fn gpu_image_matches_photon_cpu_with_a_diffuse_mirror_floor() {
    let text = hikari_core::scene::builtin::source("cornell-box").unwrap().replacen(
        "[[material]]",
        "[[material]]\nname = \"glossy\"\ntype = \"diffuse\"\nalbedo = [0.2, 0.2, 0.2]\nspecular_reflectance = [0.75, 0.75, 0.75]\n\n[[material]]",
        1,
    );
    // The floor is the first object; make it glossy.
    let text = text.replacen(
        "edge_v = [2.0, 0.0, 0.0]\nmaterial = \"white\"",
        "edge_v = [2.0, 0.0, 0.0]\nmaterial = \"glossy\"",
        1,
    );
    let scene = Scene::from_toml(&text, "glossy-floor", None).unwrap();
    assert!(scene.materials.iter().any(|m| m.mirror_reflectance().max_element() > 0.0));
    let Some((mean, count, _)) = compare_scene("glossy floor", scene) else { return };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
}
