//! Media on the GPU: the optical-depth pass against analytic slabs, the
//! volume splat against its CPU twin, and the whole frame against photon-cpu.

use glam::{Vec2, Vec3, Vec4};
use hikari_core::estimate::volume_radiance_along;
use hikari_core::photon::{TraceSettings, TracedPhotons, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::scene::Scene;
use hikari_gpu::test_support::media_context;
use hikari_gpu::tiled::Estimator;
use hikari_gpu::{GpuRenderer, GpuSettings};
use std::path::Path;

/// An axis-aligned box as OBJ text, faces wound outward.
fn box_obj(min: Vec3, max: Vec3) -> String {
    let mut obj = String::new();
    for i in 0..8 {
        let c = |bit: usize, lo: f32, hi: f32| if i & bit != 0 { hi } else { lo };
        obj += &format!("v {} {} {}\n", c(1, min.x, max.x), c(2, min.y, max.y), c(4, min.z, max.z));
    }
    for f in [[1, 5, 7, 3], [2, 4, 8, 6], [1, 2, 6, 5], [3, 7, 8, 4], [1, 3, 4, 2], [5, 6, 8, 7]] {
        obj += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
    }
    obj
}

/// Two overlapping slabs across the view (z in [−2, −0.5], σ_t = 0.8, and
/// z in [−1, 0.5], σ_t = 0.3), a wall at z = −4, the eye at `eye_z`.
fn slab_scene(dir: &Path, eye_z: f32) -> Scene {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("a.obj"), box_obj(Vec3::new(-20.0, -20.0, -2.0), Vec3::new(20.0, 20.0, -0.5))).unwrap();
    std::fs::write(dir.join("b.obj"), box_obj(Vec3::new(-20.0, -20.0, -1.0), Vec3::new(20.0, 20.0, 0.5))).unwrap();
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, {eye_z}]
look_at = [0.0, 0.0, -4.0]
fov_y = 60.0
resolution = [48, 32]

[[material]]
name = "wall"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[object]]
shape = "quad"
corner = [-10.0, -10.0, -4.0]
edge_u = [20.0, 0.0, 0.0]
edge_v = [0.0, 20.0, 0.0]
material = "wall"

[[light]]
type = "point"
position = [0.0, 0.0, 2.0]
intensity = [5.0, 5.0, 5.0]

[[medium]]
sigma_a = [0.2, 0.2, 0.2]
sigma_s = [0.6, 0.6, 0.6]
region = "a.obj"

[[medium]]
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [0.2, 0.2, 0.2]
phase = "hg"
g = 0.4
region = "b.obj"
"#
    );
    Scene::from_toml(&text, "slabs.toml", Some(dir)).unwrap()
}

/// Length of [0, l] along `eye + t·dir` inside the slab z in [z0, z1].
fn slab_length(eye: Vec3, dir: Vec3, l: f32, z0: f32, z1: f32) -> f32 {
    let (ta, tb) = ((z0 - eye.z) / dir.z, (z1 - eye.z) / dir.z);
    let (t0, t1) = (ta.min(tb).max(0.0), ta.max(tb).min(l));
    (t1 - t0).max(0.0)
}

/// The slab test of issue #4 on the GPU optical-depth pass: with the eye
/// outside both slabs and inside the second, every pixel's transmittance to
/// the wall equals e^(−Σ σ_t d) with d each slab's path length.
#[test]
fn optical_depth_pass_matches_slabs() {
    for (eye_z, label) in [(3.0, "eye outside"), (0.0, "eye inside a region")] {
        let dir = std::env::temp_dir().join(format!("hikari-slabs-{}-{}", std::process::id(), label.len()));
        let scene = slab_scene(&dir, eye_z);
        let Some(ctx) = media_context("optical depth", &scene) else { return };
        let traced = trace_photons(&scene, &TraceSettings { photons: 1000, seed: 1, ..Default::default() }, &Silent);
        let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
        let gpu = GpuRenderer::new(
            ctx,
            &scene,
            &traced,
            GpuSettings { volume_slices: 4, ..GpuSettings::new(global, caustic) },
        )
        .expect("GPU renderer");
        gpu.render().expect("GPU frame");
        let position = gpu.read(&gpu.targets.gbuffer.position).unwrap();
        let slices = gpu.read_slices().unwrap();
        assert_eq!(slices.len(), 4);
        let eye = scene.camera.position;
        let mut worst = 0.0f32;
        for (i, p) in position.iter().enumerate() {
            assert!(p.w != 0.0, "every pixel sees the wall");
            let to = p.truncate() - eye;
            let (l, dir) = (to.length(), to.normalize());
            for (k, layer) in slices.iter().enumerate() {
                let d = l * (k + 1) as f32 / 4.0;
                let tau = 0.8 * slab_length(eye, dir, d, -2.0, -0.5) + 0.3 * slab_length(eye, dir, d, -1.0, 0.5);
                let got = layer[i].x;
                // Compare transmittances: e^(−τ) to 1e-4 relative.
                let err = ((-got).exp() / (-tau).exp() - 1.0).abs();
                worst = worst.max(err);
                assert!(err < 1e-4, "{label}: pixel {i} slice {k}: τ {got} vs {tau}");
            }
        }
        // The wall: at least 2.5 units of slab in the centre pixel.
        let centre = slices[3][(16 * 48 + 24) as usize].x;
        assert!(centre > if eye_z > 0.5 { 0.8 * 1.5 + 0.3 * 1.5 } else { 0.8 * 1.5 + 0.3 * 1.0 } - 0.01, "{centre}");
        eprintln!("{label}: worst transmittance error {worst:e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

struct Twin {
    lit: usize,
    within: usize,
    worst: f32,
}

/// The volume splat against `volume_radiance_along` at the same pixels, with
/// the same photons, radius and transmittance: exact for media filling the
/// scene, the same slice interpolation for regions.
fn volume_twin(scene: &Scene, traced: &TracedPhotons, slices: u32, estimator: Estimator) -> Option<Twin> {
    let ctx = media_context("volume twin", scene)?;
    let cpu = PhotonCpuRenderer::new(scene, traced, &PhotonCpuSettings::default());
    let settings = GpuSettings {
        estimator,
        volume_radius: cpu.volume_radius,
        volume_slices: slices,
        ..GpuSettings::new(cpu.global_params, cpu.caustic_params)
    };
    let gpu = GpuRenderer::new(ctx, scene, traced, settings).expect("GPU renderer");
    gpu.render().expect("GPU frame");
    let position = gpu.read(&gpu.targets.gbuffer.position).unwrap();
    let volume = gpu.read(&gpu.targets.volume).unwrap();
    let params = *gpu.media_params();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let eye = scene.camera.position;
    let media = &scene.media;
    let mut twin = Twin { lit: 0, within: 0, worst: 0.0 };
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let p: Vec4 = position[i];
            let (dir, l) = if p.w != 0.0 {
                let to = p.truncate() - eye;
                (to / to.length(), to.length())
            } else {
                (scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)).dir, params.max_distance)
            };
            // The GPU's transmittance: τ exact at the slice ends, linear between
            // (exact everywhere without regions, where τ is linear in s).
            let s_count = params.slices.max(1);
            let ends: Vec<Vec3> =
                (1..=s_count).map(|k| media.optical_depth(eye, dir, l * k as f32 / s_count as f32)).collect();
            let transmittance = |s: f32| {
                let u = (s / l).clamp(0.0, 1.0) * s_count as f32;
                let k = (u as u32).min(s_count - 1) as usize;
                let lo = if k == 0 { Vec3::ZERO } else { ends[k - 1] };
                (-lo.lerp(ends[k], u - k as f32)).exp()
            };
            let want = volume_radiance_along(cpu.volume_map(), media.phases(), eye, dir, l, transmittance);
            let got = volume[i].truncate();
            if want.max_element() <= 0.0 && got.max_element() <= 0.0 {
                continue;
            }
            twin.lit += 1;
            let err = ((got - want).abs() / want.max(Vec3::splat(1e-30))).max_element();
            twin.within += (err < 1e-3) as usize;
            twin.worst = twin.worst.max(err);
        }
    }
    Some(twin)
}

fn assert_volume_twin(name: &str, slices: u32, photons: u64) {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(64, 48).unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons, seed: 12, ..Default::default() }, &Silent);
    // The volume splat, and the tiled estimator's volume gather.
    for estimator in [Estimator::Raster, Estimator::Tiled] {
        let Some(t) = volume_twin(&scene, &traced, slices, estimator) else { return };
        eprintln!(
            "{name} ({estimator:?}): {} volume photons, {} pixels with in-scattering, {} within 1e-3, worst {:e}",
            traced.volume.len(),
            t.lit,
            t.within,
            t.worst
        );
        assert!(t.lit > 2000, "{name}: only {} pixels", t.lit);
        assert!(t.within as f64 >= 0.999 * t.lit as f64, "{name}: {} of {} within 1e-3", t.within, t.lit);
    }
}

#[test]
fn volume_splat_equals_cpu_twin_in_homogeneous_fog() {
    assert_volume_twin("fog-stage", 8, 3000);
}

#[test]
fn volume_splat_equals_cpu_twin_with_regions() {
    assert_volume_twin("fog-stage-layered", 6, 3000);
}

/// The whole GPU frame against photon-cpu on the same photons: the mean
/// radiance of the image (surfaces attenuated through the fog, shadow-mapped
/// direct light with transmittance, in-scattering) agrees within 2%.
fn whole_frame_matches_photon_cpu(name: &str) {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(64, 48).unwrap();
    let Some(ctx) = media_context("media frame", &scene) else { return };
    let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, seed: 13, ..Default::default() }, &Silent);
    let cpu_settings = PhotonCpuSettings { spp: 4, ..Default::default() };
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &cpu_settings);
    let (reference, _) = cpu.render(&Silent);
    let mean = |img: &hikari_core::render::Image| {
        img.pixels.iter().map(|p| (p.x + p.y + p.z) as f64 / 3.0).sum::<f64>() / img.pixels.len() as f64
    };
    for estimator in [Estimator::Raster, Estimator::Tiled] {
        let settings = GpuSettings {
            estimator,
            volume_radius: cpu.volume_radius,
            ..GpuSettings::new(cpu.global_params, cpu.caustic_params)
        };
        let gpu = GpuRenderer::new(ctx.clone(), &scene, &traced, settings).expect("GPU renderer");
        gpu.render().expect("GPU frame");
        let (image, nonfinite) = gpu.read_image().unwrap();
        assert_eq!(nonfinite, 0);
        let (g, c) = (mean(&image), mean(&reference));
        eprintln!("{name} ({estimator:?}): GPU mean {g:.5}, photon-cpu {c:.5} ({:+.2}%)", (g / c - 1.0) * 100.0);
        assert!((g / c - 1.0).abs() < 0.02);
    }
}

#[test]
fn fog_stage_frame_matches_photon_cpu() {
    whole_frame_matches_photon_cpu("fog-stage");
}

#[test]
fn fog_stage_layered_frame_matches_photon_cpu() {
    whole_frame_matches_photon_cpu("fog-stage-layered");
}

/// fog-stage with a mirror and a glass ball (and, with `layered`, the dense
/// ground layer of fog-stage-layered around them), in a closed room: every
/// ray ends on a wall, so a pixel's gathers walk a bounded segment (the
/// specular pass's loop budget splits them if needed: `SpecularPass`).
fn fog_with_specular(layered: bool) -> Scene {
    let name = if layered { "fog-stage-layered" } else { "fog-stage" };
    let quad = |corner: [f32; 3], u: [f32; 3], v: [f32; 3], material: &str| {
        format!(
            "[[object]]\nshape = \"quad\"\ncorner = {corner:?}\nedge_u = {u:?}\nedge_v = {v:?}\nmaterial = \"{material}\"\n"
        )
    };
    let mut text = hikari_core::scene::builtin::source(name).unwrap().to_owned();
    text += r#"
[[material]]
name = "test-mirror"
type = "mirror"
reflectance = [0.9, 0.9, 0.9]

[[material]]
name = "test-glass"
type = "glass"
ior = 1.5

[[object]]
shape = "sphere"
center = [-1.0, 0.5, 1.5]
radius = 0.5
material = "test-glass"
"#;
    text += &quad([-2.5, 0.0, -3.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0], "test-mirror");
    // Ceiling, sides, the wall behind the camera and the rest of the floor.
    text += &quad([-4.0, 5.0, -4.0], [8.0, 0.0, 0.0], [0.0, 0.0, 11.0], "wall");
    text += &quad([-4.0, 0.0, -4.0], [0.0, 5.0, 0.0], [0.0, 0.0, 11.0], "wall");
    text += &quad([4.0, 0.0, -4.0], [0.0, 0.0, 11.0], [0.0, 5.0, 0.0], "wall");
    text += &quad([-4.0, 0.0, 7.0], [0.0, 5.0, 0.0], [8.0, 0.0, 0.0], "wall");
    text += &quad([-4.0, 0.0, 4.0], [8.0, 0.0, 0.0], [0.0, 0.0, 3.0], "stage");
    let mut scene = Scene::from_toml(&text, &format!("builtin:{name}"), None).unwrap();
    scene.camera = scene.camera.with_resolution(64, 48).unwrap();
    scene
}

/// Mirrors and glass in fog: the specular pass attenuates every segment and
/// adds the in-scattering along it, so the pixels that see the mirror or the
/// ball (pixel-centre rays on both sides, the same photons) agree with
/// photon-cpu, and so does the whole frame.
fn specular_in_fog_matches_photon_cpu(layered: bool) {
    // (The layered fog's region transmittance loops over its triangles per photon.)
    let photons: u64 = if layered { 250 } else { 800 };
    let scene = fog_with_specular(layered);
    let Some(ctx) = media_context("specular in fog", &scene) else { return };
    // Few photons keep the CPU twin quick; larger counts are split into
    // more specular dispatches on lavapipe (tests/loop_budget.rs).
    let traced = trace_photons(&scene, &TraceSettings { photons, seed: 17, ..Default::default() }, &Silent);
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    let settings =
        GpuSettings { volume_radius: cpu.volume_radius, ..GpuSettings::new(cpu.global_params, cpu.caustic_params) };
    let gpu = GpuRenderer::new(ctx, &scene, &traced, settings).expect("GPU renderer");
    gpu.render().expect("GPU frame");
    let (image, nonfinite) = gpu.read_image().unwrap();
    assert_eq!(nonfinite, 0);
    let (reference, _) = cpu.render(&Silent);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let specular: Vec<usize> = (0..w * h)
        .filter(|&i| {
            let ray = scene.camera.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
            scene.accel.intersect(&ray).is_some_and(|hit| !scene.material(&hit).is_diffuse())
        })
        .map(|i| i as usize)
        .collect();
    let mean = |img: &hikari_core::render::Image, pixels: &mut dyn Iterator<Item = usize>| {
        let (sum, n) = pixels.fold((0.0f64, 0usize), |(s, n), i| {
            let p = img.pixels[i];
            (s + (p.x + p.y + p.z) as f64 / 3.0, n + 1)
        });
        sum / n as f64
    };
    let (g, c) = (mean(&image, &mut specular.iter().copied()), mean(&reference, &mut specular.iter().copied()));
    let (gw, cw) = (mean(&image, &mut (0..image.pixels.len())), mean(&reference, &mut (0..reference.pixels.len())));
    eprintln!(
        "layered {layered}: {} mirror/glass pixels: GPU {g:.5}, photon-cpu {c:.5} ({:+.2}%); whole frame {:+.2}%",
        specular.len(),
        (g / c - 1.0) * 100.0,
        (gw / cw - 1.0) * 100.0
    );
    assert!(specular.len() > 300, "the mirror and the ball should fill part of the frame");
    assert!((g / c - 1.0).abs() < 0.01 && (gw / cw - 1.0).abs() < 0.01);
}

#[test]
fn mirror_and_glass_in_fog_match_photon_cpu() {
    specular_in_fog_matches_photon_cpu(false);
}

#[test]
fn mirror_and_glass_in_layered_fog_match_photon_cpu() {
    specular_in_fog_matches_photon_cpu(true);
}
