//! Glass in every CPU renderer against an exact answer: a white furnace.
//!
//! A white (albedo 1) Lambertian sphere inside a clear glass ball, under a
//! uniform sky of radiance 1, is in equilibrium: radiance/η² is the same
//! everywhere, so the camera outside sees radiance 1 in every pixel,
//! through the glass, on the white sphere and beside them. An eye path
//! that gathers light inside the glass must carry 1/η² of it out (radiance
//! crossing a boundary); carried as power instead, the white sphere seen
//! through the ball shows about T·η² ≈ 2.1.
//!
//! Rough glass loses what single-scattering microfacets lose (a few per
//! cent at roughness 0.3): there the renderers are held to each other and
//! to a band just under 1.

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::ImageMean;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::render::vcm::{VcmSettings, render_pass};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;

fn furnace(roughness: f32) -> Scene {
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, 3.2]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
resolution = [20, 20]

[environment]
radiance = [1.0, 1.0, 1.0]

[[material]]
name = "glass"
type = "glass"
ior = 1.5
roughness = {roughness}

[[material]]
name = "white"
type = "diffuse"
albedo = [1.0, 1.0, 1.0]

[[object]]
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "glass"

[[object]]
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 0.6
material = "white"
"#
    );
    Scene::from_toml(&text, "glass-furnace.toml", None).unwrap()
}

/// The pixels whose centre ray meets the white sphere (seen through glass).
fn inner_mean(scene: &Scene, image: &Image) -> f32 {
    let (mut sum, mut count) = (0.0, 0);
    for y in 0..image.height {
        for x in 0..image.width {
            let ray = scene.camera.ray(glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            // The ball's centre is 3.2 away; the white sphere's silhouette through the glass is
            // at least its own (a ball magnifies): rays within 0.5 of the axis at the centre meet it.
            let closest = (ray.origin + ray.dir * ray.dir.dot(-ray.origin)).length();
            if closest < 0.5 {
                let p = image.get(x, y);
                sum += (p.x + p.y + p.z) / 3.0;
                count += 1;
            }
        }
    }
    assert!(count > 20, "{count}");
    sum / count as f32
}

fn path_traced(scene: &Scene) -> Image {
    let settings = path::PathSettings { spp: 64, seed: 5, max_depth: 256, ..Default::default() };
    let (image, nonfinite) = path::render(scene, &settings, &Silent);
    assert_eq!(nonfinite, 0);
    image
}

fn photon_cpu(scene: &Scene) -> Image {
    let traced = trace_photons(scene, &TraceSettings { photons: 200_000, seed: 11, max_bounces: 256 }, &Silent);
    let settings = PhotonCpuSettings {
        radius: Some(0.08),
        caustic_radius: Some(0.08),
        spp: 4,
        max_specular_depth: 24,
        ..Default::default()
    };
    let (image, nonfinite) = PhotonCpuRenderer::new(scene, &traced, &settings).render(&Silent);
    assert_eq!(nonfinite, 0);
    image
}

fn vcm(scene: &Scene) -> Image {
    let settings = VcmSettings { seed: 13, max_path_length: 256, ..Default::default() };
    let mut mean = ImageMean::new(scene.camera.width, scene.camera.height);
    for pass in 1..=16 {
        let (image, nonfinite) = render_pass(scene, &settings, pass).unwrap();
        assert_eq!(nonfinite, 0);
        mean.add(&image);
    }
    mean.mean()
}

#[test]
fn smooth_glass_in_a_white_furnace_is_invisible() {
    let scene = furnace(0.0);
    for (name, image) in [("path", path_traced(&scene)), ("photon-cpu", photon_cpu(&scene)), ("vcm", vcm(&scene))] {
        let (all, inner) = (image.mean(), inner_mean(&scene, &image));
        println!("{name}: mean {all:.4}, white sphere through glass {inner:.4}");
        assert!((all - 1.0).abs() < 0.03 && (inner - 1.0).abs() < 0.04, "{name}: {all} {inner}");
    }
}

#[test]
fn rough_glass_renders_alike_in_every_cpu_renderer() {
    let scene = furnace(0.3);
    let results: Vec<(&str, f32, f32)> =
        [("path", path_traced(&scene)), ("photon-cpu", photon_cpu(&scene)), ("vcm", vcm(&scene))]
            .into_iter()
            .map(|(name, image)| (name, image.mean(), inner_mean(&scene, &image)))
            .collect();
    for &(name, all, inner) in &results {
        println!("{name}: mean {all:.4}, white sphere through rough glass {inner:.4}");
        // Microfacet loss only darkens; nothing is created.
        assert!(all < 1.02 && all > 0.9 && inner < 1.03 && inner > 0.85, "{name}: {all} {inner}");
    }
    let (_, _, reference) = results[0];
    for &(name, _, inner) in &results[1..] {
        assert!((inner - reference).abs() < 0.04, "{name}: {inner} against path's {reference}");
    }
}

/// A frosted pane (a closed slab of rough glass) before a point light: the
/// light glows through it. Light sampling at the slab's far side sees the
/// light through the rough transmission (at its near side the slab itself
/// blocks the shadow ray); before, `path` and `photon-cpu` sampled lights
/// on the viewer's side only and drew the glow black, while `vcm`'s light
/// subpaths found it. The three agree on the glow and on the whole image.
#[test]
fn a_point_light_glows_through_frosted_glass() {
    let scene = hikari_core::test_scenes::frosted_pane(16);
    // The glow: the pane's central quarter.
    let glow = |image: &Image| {
        let mut sum = 0.0;
        for y in 6..10 {
            for x in 6..10 {
                sum += image.pixels[y * 16 + x].x;
            }
        }
        sum / 16.0
    };
    // The glow is the pane's rough transmission convolved with itself (in
    // at the near side, out at the far): a heavy-tailed integrand for one
    // sampled direction and one shadow ray, hence the many samples.
    let path = path::render(&scene, &path::PathSettings { spp: 1024, seed: 5, ..Default::default() }, &Silent).0;
    let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, seed: 11, max_bounces: 64 }, &Silent);
    let settings = PhotonCpuSettings { spp: 512, max_specular_depth: 24, ..Default::default() };
    let photon_cpu = PhotonCpuRenderer::new(&scene, &traced, &settings).render(&Silent).0;
    let mut vcm = ImageMean::new(16, 16);
    for pass in 1..=256 {
        vcm.add(&render_pass(&scene, &VcmSettings { seed: 13, ..Default::default() }, pass).unwrap().0);
    }
    let results: Vec<(&str, f32, f32)> = [("path", path), ("photon-cpu", photon_cpu), ("vcm", vcm.mean())]
        .into_iter()
        .map(|(name, image)| (name, glow(&image), image.mean()))
        .collect();
    for &(name, glow, mean) in &results {
        println!("{name}: glow {glow:.4}, mean {mean:.4}");
    }
    let (_, glow_path, mean_path) = results[0];
    assert!(glow_path > 0.2, "path draws no glow: {glow_path}");
    for &(name, glow, mean) in &results[1..] {
        assert!((glow / glow_path - 1.0).abs() < 0.1, "{name}: glow {glow} against path's {glow_path}");
        assert!((mean / mean_path - 1.0).abs() < 0.1, "{name}: mean {mean} against path's {mean_path}");
    }
}
