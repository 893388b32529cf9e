//! The GPU renderer's whole image against `photon-cpu` with the same photon
//! maps: per-pixel relative difference, away from shadow edges.

use glam::{Vec2, Vec3};
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::{DEFAULT_ALPHA, ImageMean, Schedules, pass_jitter, pass_seed, photon_cpu_pass};
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::sampling::Rng;
use hikari_core::scene::Scene;
use hikari_gpu::gbuffer::geometric_normal::pixel_kind;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

const SIZE: u32 = 64;

/// Fraction of each light that a point sees, by shadow rays (64 per area
/// light and sky).
fn visibility(scene: &Scene, x: Vec3, normal: Vec3) -> Vec<f32> {
    let mut rng = Rng::for_item(99, 0);
    scene
        .lights
        .iter()
        .map(|light| {
            let count = if light.is_delta() { 1 } else { 64 };
            let (mut seen, mut total) = (0, 0);
            for _ in 0..count {
                let Some(s) = light.sample_incident(x, rng.next_2d()) else { continue };
                // Samples of the sky that graze the floor (at the horizon)
                // carry almost no light, and whether such a ray meets its
                // own floor, from a point a rounding error below it, is no
                // edge of light: left out.
                if light.distant_disc().is_some() && s.wi.dot(normal).abs() < 0.01 {
                    continue;
                }
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
    let size = scene.camera.width;
    let n = (size * size) as usize;
    let mut vis: Vec<Option<Vec<f32>>> = vec![None; n];
    for y in 0..size {
        for x in 0..size {
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            if let Some(hit) = scene.accel.intersect(&ray) {
                if scene.material(&hit).is_diffuse() && pixel_kind(gpu_albedo[(y * size + x) as usize].w) == 0 {
                    vis[(y * size + x) as usize] = Some(visibility(scene, hit.point, hit.geometric_normal));
                }
            }
        }
    }
    let mut mask = vec![false; n];
    for y in 0..size as i32 {
        for x in 0..size as i32 {
            let Some(v) = &vis[(y * size as i32 + x) as usize] else { continue };
            let steady = (-2..=2).all(|dy| {
                (-2..=2).all(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= size as i32 || ny >= size as i32 {
                        return true;
                    }
                    match &vis[(ny * size as i32 + nx) as usize] {
                        Some(w) => w.iter().zip(v).all(|(a, b)| (a - b).abs() < 0.02),
                        None => true,
                    }
                })
            });
            mask[(y * size as i32 + x) as usize] = steady;
        }
    }
    mask
}

fn compare(scene_name: &str) -> Option<(f64, usize, Option<(f64, usize)>)> {
    compare_scene(scene_name, Scene::load(scene_name).unwrap())
}

fn compare_scene(scene_name: &str, scene: Scene) -> Option<(f64, usize, Option<(f64, usize)>)> {
    compare_passes(scene_name, scene, 50_000, 1, Samples { cpu: 64, gpu: 16 })
}

/// The mean of `passes` progressive passes of `photons` paths each
/// (docs/progressive.md) on the GPU (accumulated there) and on the CPU.
fn compare_passes(
    scene_name: &str,
    mut scene: Scene,
    photons: u64,
    passes: u32,
    samples: Samples,
) -> Option<(f64, usize, Option<(f64, usize)>)> {
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    let frames = render_both(scene_name, &scene, photons, passes, samples);
    let mask = comparison_mask(&scene, &frames.albedo);
    let (mean, count) = mean_relative_difference(&frames.gpu, &frames.cpu, &mask);
    eprintln!("{scene_name}: {count} pixels compared, mean relative difference {:.3}%", mean * 100.0);
    Some((mean, count, specular_difference(&frames.gpu, &frames.cpu, &frames.albedo)))
}

/// Light samples per area light (and sky) at each shaded point: shadow rays
/// for photon-cpu, shadow-mapped samples for the GPU.
#[derive(Clone, Copy)]
struct Samples {
    cpu: u32,
    gpu: u32,
}

/// Both renderers' images of the same passes, and the GPU's G-buffer albedo.
struct Frames {
    gpu: hikari_core::render::Image,
    cpu: hikari_core::render::Image,
    albedo: Vec<glam::Vec4>,
}

/// Mean relative difference of the pixel luminances of `gpu` against `cpu`
/// over the pixels of `mask` that the CPU lights, and their count.
fn mean_relative_difference(
    gpu: &hikari_core::render::Image,
    cpu: &hikari_core::render::Image,
    mask: &[bool],
) -> (f64, usize) {
    let (mut sum, mut count) = (0.0f64, 0usize);
    for i in 0..mask.len() {
        if !mask[i] {
            continue;
        }
        let (g, c) = (gpu.pixels[i], cpu.pixels[i]);
        let (gl, cl) = ((g.x + g.y + g.z) / 3.0, (c.x + c.y + c.z) / 3.0);
        if cl > 1e-6 {
            sum += ((gl - cl).abs() / cl) as f64;
            count += 1;
        }
    }
    (sum / count.max(1) as f64, count)
}

/// The mean of `passes` passes on the GPU and on the CPU, `scene` at its resolution.
fn render_both(scene_name: &str, scene: &Scene, photons: u64, passes: u32, samples: Samples) -> Frames {
    let ctx = test_context(scene_name);
    let size = scene.camera.width;
    let trace = |pass| {
        let seed = pass_seed(5, pass);
        trace_photons(&scene, &TraceSettings { photons, seed, ..Default::default() }, &Silent)
    };
    // One sample at the pixel centre, as the rasterizer sees it; many shadow
    // rays per area light so the CPU's direct light is nearly noise-free.
    let cpu_settings = PhotonCpuSettings { spp: 1, area_light_samples: samples.cpu, seed: 5, ..Default::default() };
    let (global, caustic) = cpu_settings.estimate_params(&scene);
    let schedules = Schedules::new([global.radius, caustic.radius, global.radius], DEFAULT_ALPHA);
    // Both sample each pixel once per pass, at the pass's jitter.
    let jittered = |pass| {
        let mut s = scene.clone();
        s.camera.jitter = pass_jitter(pass);
        s
    };
    let mut cpu_mean = ImageMean::new(size, size);
    for pass in 1..=passes {
        cpu_mean.add(&photon_cpu_pass(&jittered(pass), &cpu_settings, photons, &schedules, pass).0);
    }
    let cpu_image = cpu_mean.mean();
    let settings =
        GpuSettings { area_light_samples: samples.gpu, shadow_map_size: 1024, ..GpuSettings::new(global, caustic) };
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &trace(1), settings).expect("GPU renderer");
    let mut gpu_mean = hikari_gpu::accumulate::AccumulatePass::new(&ctx.device, gpu.resolved());
    for pass in 1..=passes {
        if pass > 1 {
            let [r_global, r_caustic, _] = schedules.radii(pass);
            (gpu.settings.global.radius, gpu.settings.caustic.radius) = (r_global, r_caustic);
            gpu.settings.pass = pass;
            gpu.set_photons(&scene, &trace(pass)).expect("the pass's photons");
            gpu.set_camera(&jittered(pass).camera).unwrap();
        }
        gpu.render().expect("GPU frame");
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        gpu_mean.record(&ctx.queue, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
    }
    let mut gpu_image = hikari_core::render::Image::new(size, size);
    for (p, v) in gpu_image.pixels.iter_mut().zip(gpu.read(&gpu_mean.mean).unwrap()) {
        assert!(v.is_finite());
        *p = v.truncate();
    }
    let albedo = gpu.read(&gpu.targets.gbuffer.albedo).unwrap();
    Frames { gpu: gpu_image, cpu: cpu_image, albedo }
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
        if pixel_kind(albedo[i].w) == 1 || pixel_kind(albedo[i].w) == 2 {
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
    let Some((mean, count, specular)) =
        compare_passes("cornell-caustic passes", scene, 20_000, 6, Samples { cpu: 64, gpu: 16 })
    else {
        return;
    };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
    let (specular_mean, _) = specular.expect("the glass ball is in view");
    assert!(specular_mean < 0.05, "glass pixels: mean relative difference {specular_mean}");
}

/// Tinted glass around a white ball: the specular pass tints what crosses
/// the glass and carries radiance out of it scaled by 1/η² per crossing in
/// (photons carry power, unscaled), as photon-cpu does. Carried as power,
/// the white ball seen through the glass is about 2.2× too bright.
#[test]
fn gpu_image_matches_photon_cpu_through_tinted_glass_around_a_ball() {
    let text = hikari_core::scene::builtin::source("cornell-caustic").unwrap().replacen(
        "type = \"glass\"\nior = 1.5",
        "type = \"glass\"\nior = 1.5\nbase_color = [0.95, 0.8, 0.6]",
        1,
    ) + "\n[[material]]\nname = \"inner\"\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\n[[object]]\nshape = \"sphere\"\ncenter = [0.15, -0.6, 0.1]\nradius = 0.25\nmaterial = \"inner\"\n";
    let scene = Scene::from_toml(&text, "tinted-caustic.toml", None).unwrap();
    assert!(matches!(scene.materials.iter().find(|m| matches!(m, hikari_core::material::Material::Glass(_))),
        Some(hikari_core::material::Material::Glass(g)) if g.tint.z == 0.6));
    let Some((mean, count, specular)) = compare_scene("tinted glass around a ball", scene) else { return };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
    let (specular_mean, specular_count) = specular.expect("the glass ball is in view");
    eprintln!("tinted glass: {specular_count} pixels, mean relative difference {:.3}%", specular_mean * 100.0);
    assert!(specular_count > 100);
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

/// A sun: E cos θ unshadowed times one orthographic shadow map, against
/// photon-cpu's shadow rays; the box's hard shadow edge masked, the light
/// the box reflects onto the floor from the same photons.
#[test]
fn gpu_image_matches_photon_cpu_under_a_sun() {
    let scene = hikari_gpu::test_support::sun_over_a_box(SIZE);
    let Some((mean, count, _)) = compare_scene("sun over a box", scene) else { return };
    assert!(count > 2000, "only {count} pixels compared");
    assert!(mean < 0.02, "mean relative difference {mean}");
}

/// An emissive mesh (the Cornell box's quad light as two triangles over a
/// black surface) on the GPU matches photon-cpu as closely as the quad
/// light itself does, though it is sampled point by point where the quad
/// has Lambert's closed form.
#[test]
fn gpu_image_matches_photon_cpu_with_an_emissive_mesh() {
    use hikari_core::test_scenes::{cornell_quad_light, quad_lights_as_meshes};
    // 1024 shadow rays a pixel: with 64, photon-cpu's own noise near the
    // light (grazing, close) is 2% a pixel on the walls' upper half.
    let samples = Samples { cpu: 1024, gpu: 16 };
    let quad = cornell_quad_light(SIZE);
    let Some((quad_mean, quad_count, _)) = compare_passes("quad light", quad.clone(), 50_000, 1, samples) else {
        return;
    };
    let mesh = quad_lights_as_meshes(&quad);
    let Some((mesh_mean, mesh_count, _)) = compare_passes("emissive mesh", mesh, 50_000, 1, samples) else { return };
    assert!(quad_count > 2000 && mesh_count > 2000, "only {quad_count} and {mesh_count} pixels compared");
    assert!(quad_mean < 0.02, "quad light: mean relative difference {quad_mean}");
    assert!(mesh_mean < 0.02, "emissive mesh: mean relative difference {mesh_mean}");
}

/// A sky: πL times the cosine-weighted fraction of its K shadow-mapped
/// directions that see a point, against photon-cpu's 4096 shadow rays per
/// pixel (whose own noise is about 2% a pixel). Where the box hides part
/// of the sky, K hard shadows stand for a soft one; the sky itself shows
/// past the floor and in the mirror ball.
#[test]
fn gpu_image_matches_photon_cpu_under_a_sky() {
    let size = 32;
    let scene = hikari_gpu::test_support::sky_over_a_box(size);
    let frames = render_both("sky over a box", &scene, 20_000, 1, Samples { cpu: 4096, gpu: 16 });
    // The diffuse pixels, and those that see less than 95% of the sky.
    let n = (size * size) as usize;
    let (mut diffuse, mut shaded) = (vec![false; n], vec![false; n]);
    for y in 0..size {
        for x in 0..size {
            let i = (y * size + x) as usize;
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = scene.accel.intersect(&ray) else { continue };
            if !scene.material(&hit).is_diffuse() || pixel_kind(frames.albedo[i].w) != 0 {
                continue;
            }
            let normal = if ray.dir.dot(hit.geometric_normal) < 0.0 { hit.shading_normal } else { -hit.shading_normal };
            diffuse[i] = true;
            shaded[i] = sky_seen(&scene, hit.point, normal) < 0.95;
        }
    }
    let (all_mean, all_count) = mean_relative_difference(&frames.gpu, &frames.cpu, &diffuse);
    let (shaded_mean, shaded_count) = mean_relative_difference(&frames.gpu, &frames.cpu, &shaded);
    let ratio = |mask: &[bool]| {
        let sum = |image: &hikari_core::render::Image| {
            (0..n).filter(|&i| mask[i]).map(|i| image.pixels[i].element_sum() as f64).sum::<f64>()
        };
        sum(&frames.gpu) / sum(&frames.cpu)
    };
    eprintln!(
        "sky: {all_count} diffuse pixels, mean relative difference {:.2}%, means' ratio {:.4}; \
         {shaded_count} seeing under 95% of the sky: {:.2}%, ratio {:.4}",
        100.0 * all_mean,
        ratio(&diffuse),
        100.0 * shaded_mean,
        ratio(&shaded)
    );
    assert!(all_count > 500 && shaded_count > 100, "{all_count} diffuse and {shaded_count} shaded pixels");
    // photon-cpu's noise alone is about 1.6% (mean absolute) a pixel.
    assert!(all_mean < 0.04 && (ratio(&diffuse) - 1.0).abs() < 0.01, "all: {all_mean}, ratio {}", ratio(&diffuse));
    assert!(shaded_mean < 0.06 && (ratio(&shaded) - 1.0).abs() < 0.03, "partly hidden: {shaded_mean}");
    // Pixels that see no surface show the sky, radiance 1.
    let background: Vec<usize> = (0..n).filter(|&i| frames.albedo[i] == glam::Vec4::ZERO).collect();
    assert!(background.len() > 20, "{} background pixels", background.len());
    for &i in &background {
        assert!((frames.gpu.pixels[i] - Vec3::ONE).abs().max_element() < 1e-5, "pixel {i}: {}", frames.gpu.pixels[i]);
        assert_eq!(frames.cpu.pixels[i], Vec3::ONE);
    }
    let (mirror_mean, mirror_count) =
        specular_difference(&frames.gpu, &frames.cpu, &frames.albedo).expect("the mirror ball is in view");
    eprintln!("sky: mirror ball {mirror_count} pixels, mean relative difference {:.2}%", 100.0 * mirror_mean);
    assert!(mirror_count > 20 && mirror_mean < 0.05, "mirror ball: {mirror_mean}");
}

/// The cosine-weighted fraction of the sky a point with `normal` sees
/// (shadow rays over a stratified cosine-weighted hemisphere).
fn sky_seen(scene: &Scene, x: Vec3, normal: Vec3) -> f32 {
    let n = 16;
    let mut seen = 0;
    for i in 0..n * n {
        let u = Vec2::new(((i % n) as f32 + 0.5) / n as f32, ((i / n) as f32 + 0.5) / n as f32);
        let dir = hikari_core::sampling::local_to_world(hikari_core::sampling::cosine_hemisphere(u), normal);
        seen += !scene.accel.occluded(&hikari_core::geometry::Ray::new(x, dir)) as u32;
    }
    seen as f32 / (n * n) as f32
}

/// A sun and a sky in fog that fills the scene: light is attenuated from
/// the distant lights' disc, view rays that leave the scene cross the fog
/// up to it (and then see the sky), and the volume map's in-scattering is
/// gathered along them, as photon-cpu does.
#[test]
fn gpu_image_matches_photon_cpu_under_a_sun_and_a_sky_in_fog() {
    let size = 32;
    let scene = hikari_gpu::test_support::sun_and_sky_in_fog(size);
    if hikari_gpu::test_support::media_context("sun and sky in fog", &scene).is_none() {
        return;
    }
    let frames = render_both("sun and sky in fog", &scene, 50_000, 1, Samples { cpu: 1024, gpu: 16 });
    let mask = comparison_mask(&scene, &frames.albedo);
    let (mean, count) = mean_relative_difference(&frames.gpu, &frames.cpu, &mask);
    let background: Vec<bool> = frames.albedo.iter().map(|a| *a == glam::Vec4::ZERO).collect();
    let (sky_mean, sky_count) = mean_relative_difference(&frames.gpu, &frames.cpu, &background);
    eprintln!(
        "sun and sky in fog: {count} surface pixels, mean relative difference {:.2}%; \
         {sky_count} sky pixels through the fog, {:.2}%",
        100.0 * mean,
        100.0 * sky_mean
    );
    assert!(count > 300 && sky_count > 20, "{count} surface and {sky_count} sky pixels");
    assert!(mean < 0.03, "surfaces: mean relative difference {mean}");
    assert!(sky_mean < 0.02, "sky through fog: mean relative difference {sky_mean}");
}

/// An emissive mesh in a mirror: the specular pass adds the light's
/// radiance where its rays hit the mesh's front and its light at the
/// diffuse hits beyond, as photon-cpu's recursion does (the Cornell box of
/// `cornell_quad_light`, its light as a mesh, its back wall a mirror).
/// A normal-mapped quad (one texel tilting its normal 45°, a skewed
/// parallelogram so the tangent frame is neither axis-aligned nor
/// orthogonal) seen in a smooth metal mirror, lit by a point light between
/// them: the specular pass bends the normal where the mirror's reflection
/// meets the quad (bent_normal_at_hit: the triangle's own frame, the texel
/// at level 0), as photon-cpu does. Without the bend 294 of the 300
/// mirror pixels that show the quad were more than 1% from photon-cpu's,
/// with it none (lavapipe, when this test was written); the same photons
/// on both sides.
#[test]
fn a_normal_mapped_surface_shows_bent_in_a_mirror() {
    let scene = hikari_core::test_scenes::gltf_textures::normal_map_before_a_mirror("normal-map-in-a-mirror", SIZE);
    let frames = render_both("normal map, mirror", &scene, 20_000, 1, Samples { cpu: 16, gpu: 16 });
    // The pixels whose first surface is the mirror (z = 0) and whose
    // reflection meets the quad.
    let (mut shown, mut off) = (0, Vec::new());
    for i in 0..SIZE * SIZE {
        let ray = scene.camera.ray(Vec2::new((i % SIZE) as f32 + 0.5, (i / SIZE) as f32 + 0.5));
        let Some(hit) = scene.accel.intersect(&ray) else { continue };
        if hit.point.z.abs() > 1e-3 {
            continue;
        }
        let reflected = hikari_core::geometry::Ray::new(hit.point, ray.dir - 2.0 * ray.dir.dot(Vec3::Z) * Vec3::Z);
        if !scene.accel.intersect(&reflected).is_some_and(|h| h.point.z > 0.5) {
            continue;
        }
        shown += 1;
        let (g, c) = (frames.gpu.pixels[i as usize], frames.cpu.pixels[i as usize]);
        if (g - c).element_sum().abs() > 0.01 * c.element_sum().max(1e-6) {
            off.push((i % SIZE, i / SIZE));
        }
    }
    eprintln!("normal map in a mirror: {shown} mirror pixels show the quad, {} more than 1% off: {off:?}", off.len());
    assert!(shown > 40, "{shown} mirror pixels show the quad");
    assert!(off.len() * 20 <= shown, "{} of {shown} pixels more than 1% from photon-cpu", off.len());
}

/// The built-in Cornell box's TOML with its back wall a mirror (reflectance 0.9).
fn cornell_box_with_a_mirror_back_wall() -> String {
    hikari_core::scene::builtin::source("cornell-box")
        .unwrap()
        .replacen(
            "[[material]]",
            "[[material]]\nname = \"mirror\"\ntype = \"mirror\"\nreflectance = [0.9, 0.9, 0.9]\n\n[[material]]",
            1,
        )
        .replacen(
            "edge_u = [2.0, 0.0, 0.0]\nedge_v = [0.0, 2.0, 0.0]\nmaterial = \"white\"",
            "edge_u = [2.0, 0.0, 0.0]\nedge_v = [0.0, 2.0, 0.0]\nmaterial = \"mirror\"",
            1,
        )
}

#[test]
fn an_emissive_mesh_shows_in_a_mirror() {
    use hikari_core::test_scenes::quad_lights_as_meshes;
    let text = cornell_box_with_a_mirror_back_wall();
    let start = text.find("[[light]]").unwrap();
    let quad = "[[light]]\ntype = \"quad\"\ncorner = [-0.25, 0.999, -0.25]\nedge_u = [0.5, 0.0, 0.0]\n\
                edge_v = [0.0, 0.0, 0.5]\nradiance = [12.0, 12.0, 12.0]\n";
    let scene = Scene::from_toml(&format!("{}{quad}", &text[..start]), "mirror-quad", None).unwrap();
    let mut scene = quad_lights_as_meshes(&scene);
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    let frames = render_both("mesh light, mirror", &scene, 50_000, 1, Samples { cpu: 1024, gpu: 16 });
    let (mirror_mean, mirror_count) =
        specular_difference(&frames.gpu, &frames.cpu, &frames.albedo).expect("the mirror is in view");
    // The light itself in the mirror: radiance 12 × 0.9.
    let mirror = |i: &usize| pixel_kind(frames.albedo[*i].w) == 1;
    let brightest = (0..frames.albedo.len()).filter(mirror).map(|i| frames.gpu.pixels[i].x).fold(0.0f32, f32::max);
    eprintln!(
        "mesh light in a mirror: {mirror_count} mirror pixels, mean relative difference {:.2}%, brightest {brightest}",
        mirror_mean * 100.0
    );
    assert!(mirror_count > 300 && (brightest - 10.8).abs() < 0.1, "{mirror_count} pixels, brightest {brightest}");
    assert!(mirror_mean < 0.05, "mirror pixels: mean relative difference {mirror_mean}");
}

/// A coarse sphere (8 rings of 12 facets) shaded smoothly by its vertex
/// normals, seen in a mirror: the specular pass shades what mirrors show
/// with the shading normals (hit_normals.wgsl, the tracer's), as photon-cpu
/// does. With the facets' own normals 24 of the mirror's 428 pixels (the
/// sphere's reflection) were more than 1% from photon-cpu's; with the
/// shading normals one on lavapipe and two on GL (an edge pixel each),
/// measured when this test was written. The same photons on both sides.
#[test]
fn a_smooth_mesh_shows_smooth_in_a_mirror() {
    let dir = std::env::temp_dir().join(format!("hikari-smooth-mirror-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (rings, segments) = (8, 12);
    let mut obj = String::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            obj += &format!("v {} {} {}\nvn {} {} {}\n", n.x, n.y, n.z, n.x, n.y, n.z);
        }
    }
    let at = |i: usize, j: usize| i * segments + j % segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            if i > 0 {
                obj += &format!("f {a}//{a} {b}//{b} {c}//{c}\n");
            }
            if i + 1 < rings {
                obj += &format!("f {a}//{a} {c}//{c} {d}//{d}\n");
            }
        }
    }
    std::fs::write(dir.join("sphere.obj"), obj).unwrap();
    let text = cornell_box_with_a_mirror_back_wall();
    let start = text.find("[[light]]").unwrap();
    let sphere =
        "[[object]]\nmesh = \"sphere.obj\"\nscale = 0.25\ntranslate = [0.6, 0.4, 0.8]\nmaterial = \"white\"\n\n";
    let text = format!("{}{sphere}{}", &text[..start], &text[start..]);
    let mut scene = Scene::from_toml(&text, "smooth-mirror.toml", Some(&dir)).unwrap();
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    let frames = render_both("smooth sphere, mirror", &scene, 50_000, 1, Samples { cpu: 64, gpu: 16 });
    let (mirror_mean, mirror_count) =
        specular_difference(&frames.gpu, &frames.cpu, &frames.albedo).expect("the mirror is in view");
    eprintln!("smooth sphere in a mirror: {mirror_count} mirror pixels, mean relative difference {mirror_mean:e}");
    // The facets show as a patch of pixels each off by several per cent;
    // the same photons and shadow rays leave one or two pixels on edges.
    let off: Vec<(u32, u32)> = (0..frames.albedo.len() as u32)
        .filter(|&i| {
            let (g, c) = (frames.gpu.pixels[i as usize], frames.cpu.pixels[i as usize]);
            pixel_kind(frames.albedo[i as usize].w) == 1
                && ((g - c).element_sum().abs() > 0.01 * c.element_sum().max(1e-6))
        })
        .map(|i| (i % SIZE, i / SIZE))
        .collect();
    eprintln!("mirror pixels more than 1% off: {off:?}");
    assert!(mirror_count > 300, "{mirror_count} mirror pixels");
    assert!(off.len() <= 3, "{} mirror pixels more than 1% from photon-cpu: {off:?}", off.len());
    std::fs::remove_dir_all(&dir).ok();
}

/// Mean relative difference of `gpu` against `cpu` after averaging each
/// image over `block`×`block` pixel blocks (the noise of one sampled lobe
/// direction per pixel and pass averages out; a bias would not), over the
/// blocks whose pixels are all in `mask`.
fn block_difference(
    gpu: &hikari_core::render::Image,
    cpu: &hikari_core::render::Image,
    mask: &[bool],
    block: u32,
) -> (f64, usize) {
    let size = gpu.width;
    let (mut sum, mut count) = (0.0f64, 0usize);
    for by in 0..size / block {
        for bx in 0..size / block {
            let pixels: Vec<usize> = (0..block * block)
                .map(|k| ((by * block + k / block) * size + bx * block + k % block) as usize)
                .collect();
            if !pixels.iter().all(|&i| mask[i]) {
                continue;
            }
            let mean = |image: &hikari_core::render::Image| {
                pixels.iter().map(|&i| image.pixels[i].element_sum() as f64 / 3.0).sum::<f64>() / pixels.len() as f64
            };
            let (g, c) = (mean(gpu), mean(cpu));
            if c > 1e-6 {
                sum += (g - c).abs() / c;
                count += 1;
            }
        }
    }
    (sum / count.max(1) as f64, count)
}

/// The glTF BRDF on the GPU: metals and dielectrics from roughness 0.1 to 1
/// under each kind of light match photon-cpu's mean of the same passes
/// (direct light through every lobe, photons weighted by the BRDF, the
/// smoother lobes followed one sampled direction per pass).
#[test]
fn gpu_image_matches_photon_cpu_on_a_glossy_box_under_every_light() {
    use hikari_core::test_scenes::{glossy_box, glossy_lights, quad_lights_as_meshes, quad_lights_as_split_meshes};
    let mut scenes: Vec<(&str, _)> =
        glossy_lights::ALL.iter().map(|&(light, text)| (light, glossy_box(text, SIZE))).collect();
    scenes.push(("emissive mesh", quad_lights_as_meshes(&glossy_box(glossy_lights::QUAD, SIZE))));
    // Over `MESH_MIS_TRIANGLES`: light samples alone.
    let split = quad_lights_as_split_meshes(&glossy_box(glossy_lights::QUAD, SIZE), 8);
    scenes.push(("emissive mesh of 128 triangles", split));
    for (light, scene) in scenes {
        let name = format!("glossy box, {light}");
        let frames = render_both(&name, &scene, 20_000, 8, Samples { cpu: 64, gpu: 16 });
        let mask = comparison_mask(&scene, &frames.albedo);
        let (pixel, count) = mean_relative_difference(&frames.gpu, &frames.cpu, &mask);
        let (block, blocks) = block_difference(&frames.gpu, &frames.cpu, &mask, 4);
        let ratio = frames.gpu.mean() / frames.cpu.mean();
        eprintln!(
            "{name}: {count} pixels, mean relative difference {:.2}%; {blocks} 4×4 blocks, {:.2}%; image mean ratio {ratio:.4}",
            100.0 * pixel,
            100.0 * block
        );
        assert!((ratio - 1.0).abs() < 0.02, "{name}: image mean ratio {ratio}");
        // The sky's glossy light is sampled through the lobe, 4 directions a
        // pass (light_eval.wgsl's `sky_glossy`): its pixels are noisy after 8
        // passes; tests/glossy.rs follows it to convergence.
        if light != "sky" {
            assert!(count > 2000 && pixel < 0.03, "{name}: {count} pixels, {pixel}");
            assert!(blocks > 80 && block < 0.01, "{name}: {blocks} blocks, {block}");
        }
    }
}

/// Rough tinted glass under a sphere light: the GPU's specular pass follows
/// one sampled direction of the glass per pass (photon-cpu: one per eye
/// ray, with shadow rays through its reflection), and the GPU tracer
/// samples it as the CPU's does. Over the glass pixels the two sums agree
/// once passes add up: the GPU finds the light only by sampled directions,
/// so its few-pass sums are noisy (the light made larger than
/// cornell-caustic's, same power, so that they settle: measured on lavapipe
/// with clear rough glass 9% apart after 8 passes, 2.6% after 16, 0.5%
/// after 64; with this tint 1.4% after 64).
#[test]
fn gpu_image_matches_photon_cpu_through_rough_glass() {
    let sphere = "radius = 0.04\nradiance = [600.0, 600.0, 600.0]";
    rough_glass_matches("rough glass", (sphere, "radius = 0.15\nradiance = [42.7, 42.7, 42.7]"), 0.05);
}

/// The same ball under a point light where the sphere light was: the
/// specular pass samples it through the glass's reflection and
/// transmission by shadow maps (photon-cpu by shadow rays), so the glass
/// pixels converge like the diffuse ones.
#[test]
fn gpu_image_matches_photon_cpu_through_rough_glass_under_a_point_light() {
    let sphere = "type = \"sphere\"\ncenter = [-0.45, 0.8, -0.3]\nradius = 0.04\nradiance = [600.0, 600.0, 600.0]";
    let point = "type = \"point\"\nposition = [-0.45, 0.8, -0.3]\nintensity = [3.0, 3.0, 3.0]";
    rough_glass_matches("rough glass, point light", (sphere, point), 0.03);
}

/// cornell-caustic with a rough (0.3) tinted ball and `light.0` (part of
/// its light's lines) replaced by `light.1`: the GPU against
/// photon-cpu after 64 passes, on the diffuse pixels (3%) and on the sum
/// over the glass pixels (within `glass_tolerance`).
fn rough_glass_matches(name: &str, light: (&str, &str), glass_tolerance: f64) {
    let text = hikari_core::scene::builtin::source("cornell-caustic").unwrap().replacen(
        "type = \"glass\"\nior = 1.5",
        "type = \"glass\"\nior = 1.5\nroughness = 0.3\nbase_color = [0.9, 0.8, 0.6]",
        1,
    );
    assert!(text.contains(light.0), "cornell-caustic's light changed");
    let text = text.replacen(light.0, light.1, 1);
    let mut scene = Scene::from_toml(&text, "rough-caustic.toml", None).unwrap();
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).unwrap();
    let frames = render_both(name, &scene, 10_000, 64, Samples { cpu: 16, gpu: 16 });
    let mask = comparison_mask(&scene, &frames.albedo);
    let (mean, count) = mean_relative_difference(&frames.gpu, &frames.cpu, &mask);
    eprintln!("{name}: {count} diffuse pixels, mean relative difference {:.3}%", mean * 100.0);
    assert!(count > 2000 && mean < 0.03, "{count} pixels, mean relative difference {mean}");
    let (gpu_sum, cpu_sum, glass) = glass_sums(&frames);
    let difference = (gpu_sum - cpu_sum).abs() / cpu_sum;
    eprintln!("{name}: {glass} glass pixels, their sums differ by {:.2}%", difference * 100.0);
    assert!(glass > 100 && difference < glass_tolerance, "{glass} glass pixels, sums differ by {difference}");
}

/// A frosted pane (a closed slab of rough glass) before a point light:
/// everything its pixels show is the light glowing through the pane's
/// two rough boundaries, sampled at the far one (the specular pass by
/// shadow maps, photon-cpu by shadow rays). Before the specular pass
/// sampled delta lights, the GPU refused this scene.
#[test]
fn gpu_image_matches_photon_cpu_through_a_frosted_pane() {
    let scene = hikari_core::test_scenes::frosted_pane(SIZE);
    let frames = render_both("frosted pane", &scene, 10_000, 32, Samples { cpu: 1, gpu: 1 });
    let (gpu_sum, cpu_sum, glass) = glass_sums(&frames);
    let difference = (gpu_sum - cpu_sum).abs() / cpu_sum;
    eprintln!(
        "frosted pane: {glass} glass pixels, mean {:.3}, sums differ by {:.2}%",
        cpu_sum / glass as f64,
        difference * 100.0
    );
    assert!(glass > 1000 && cpu_sum / glass as f64 > 0.3 && difference < 0.05, "{glass} pixels, {difference}");
}

/// The sums of the GPU's and the CPU's pixels (all three channels) over the
/// pixels whose first surface is glass, and their count.
fn glass_sums(frames: &Frames) -> (f64, f64, usize) {
    let (mut gpu_sum, mut cpu_sum, mut glass) = (0.0f64, 0.0f64, 0);
    for i in 0..frames.albedo.len() {
        if pixel_kind(frames.albedo[i].w) == 2 {
            let (g, c) = (frames.gpu.pixels[i], frames.cpu.pixels[i]);
            gpu_sum += (g.x + g.y + g.z) as f64;
            cpu_sum += (c.x + c.y + c.z) as f64;
            glass += 1;
        }
    }
    (gpu_sum, cpu_sum, glass)
}
