//! Environment maps (`[environment] map = "sky.exr"`): an open floor lit by
//! a sky image with a bright patch gives the irradiance the map's own
//! integral gives, in the path tracer and in photon-cpu; a constant map
//! lights as the uniform sky of the same radiance; bad maps are located
//! errors.

use glam::{Vec2, Vec3};
use hikari_core::envmap::EnvironmentMap;
use hikari_core::geometry::Ray;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::path::{PathSettings, radiance as path_radiance};
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::sampling::Rng;
use hikari_core::scene::Scene;
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

fn folder(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hikari-envmap-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 32×16 sky: dim blue, a warm patch above the horizon (a low sun), the
/// lower half dark ground.
fn patchy_texels() -> (u32, u32, Vec<Vec3>) {
    let (w, h) = (32u32, 16u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (10..13).contains(&x) && (3..5).contains(&y) {
                Vec3::new(60.0, 45.0, 30.0)
            } else if y >= h / 2 {
                Vec3::splat(0.05)
            } else {
                Vec3::new(0.3, 0.4, 0.6)
            }
        })
        .collect();
    (w, h, texels)
}

fn write_exr(path: &Path, w: u32, h: u32, texels: &[Vec3]) {
    let data: Vec<f32> = texels.iter().flat_map(|t| t.to_array()).collect();
    let image = image::Rgb32FImage::from_raw(w, h, data).unwrap();
    image::DynamicImage::ImageRgb32F(image).save(path).unwrap();
}

/// A 4×4 grey floor (albedo 0.5) at y = 0 under `environment`, seen from above.
fn floor_scene(dir: &Path, environment: &str) -> Scene {
    let text = format!(
        r#"
[camera]
position = [0.0, 3.0, 0.01]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
resolution = [16, 16]

[[material]]
name = "floor"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[object]]
shape = "quad"
corner = [-2.0, 0.0, -2.0]
edge_u = [0.0, 0.0, 4.0]
edge_v = [4.0, 0.0, 0.0]
material = "floor"

[environment]
{environment}
"#
    );
    let path = dir.join("floor.toml");
    std::fs::write(&path, &text).unwrap();
    Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"))
}

/// E on a floor facing `normal` (±Y): ∫ L(ω) (n·ω) dω over its
/// hemisphere, each texel integrated on a fine grid of its directions.
fn irradiance(map: &EnvironmentMap, normal: Vec3) -> Vec3 {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let n = 16;
    let mut sum = Vec3::ZERO;
    for y in 0..h * n {
        for x in 0..w * n {
            let uv = Vec2::new((x as f32 + 0.5) / (w * n) as f32, (y as f32 + 0.5) / (h * n) as f32);
            let d = EnvironmentMap::direction(uv);
            let cos = d.dot(normal);
            if cos <= 0.0 {
                continue;
            }
            // dω = sin θ dθ dφ = 2π² sin θ du dv.
            let d_omega = 2.0 * PI * PI * (uv.y * PI).sin() / ((w * n * h * n) as f32);
            sum += map.radiance(d) * cos * d_omega;
        }
    }
    sum
}

#[test]
fn a_sky_image_lights_a_floor_as_its_integral_says() {
    let dir = folder("patchy");
    let (w, h, texels) = patchy_texels();
    write_exr(&dir.join("sky.exr"), w, h, &texels);
    let scene = floor_scene(&dir, "map = \"sky.exr\"");
    let map = EnvironmentMap::new(w, h, texels).unwrap();
    let expected = 0.5 / PI * irradiance(&map, Vec3::Y);
    let look = Ray::new(Vec3::new(0.3, 1.0, -0.2), -Vec3::Y);
    let mut rng = Rng::for_item(9, 0);
    let n = 20_000;
    let settings = PathSettings { spp: 1, ..Default::default() };
    let path = (0..n).map(|_| path_radiance(&scene, look, &settings, &mut rng)).sum::<Vec3>() / n as f32;
    let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, ..Default::default() }, &Silent);
    let renderer =
        PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { area_light_samples: 64, ..Default::default() });
    let m = 300;
    let photon = (0..m).map(|_| renderer.radiance(&look, 0, &mut rng)).sum::<Vec3>() / m as f32;
    eprintln!("floor under the sky image: expected {expected}, path {path}, photon-cpu {photon}");
    for (name, got) in [("path", path), ("photon-cpu", photon)] {
        let rel = ((got - expected) / expected).abs().max_element();
        assert!(rel < 0.03, "{name}: {got} vs {expected}");
    }
    // The eye looking up sees the texel's radiance.
    let up = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
    assert_eq!(path_radiance(&scene, up, &settings, &mut rng), map.radiance(Vec3::Y));
    // Photons carry the map's power: the floor's stored flux is E·A on
    // each face (the ground's light reaches its underside).
    let stored: Vec3 = traced.global.iter().map(|p| p.power_in_units()).sum::<Vec3>() * traced.power_unit;
    let want = (irradiance(&map, Vec3::Y) + irradiance(&map, -Vec3::Y)) * 16.0;
    let rel = ((stored - want) / want).abs().max_element();
    eprintln!("stored flux {stored} vs E·A {want}");
    assert!(rel < 0.03, "stored {stored} vs {want}");
}

/// A constant map of radiance L and the uniform sky of radiance L give the
/// same floor (ρL), and `radiance` scales a map.
#[test]
fn a_constant_map_is_the_uniform_sky() {
    let dir = folder("constant");
    write_exr(&dir.join("grey.exr"), 8, 4, &[Vec3::splat(0.5); 32]);
    let mapped = floor_scene(&dir, "map = \"grey.exr\"\nradiance = [2.0, 2.0, 2.0]");
    let look = Ray::new(Vec3::new(0.0, 1.0, 0.0), -Vec3::Y);
    let mut rng = Rng::for_item(4, 0);
    let settings = PathSettings { spp: 1, ..Default::default() };
    let n = 20_000;
    let l = (0..n).map(|_| path_radiance(&mapped, look, &settings, &mut rng)).sum::<Vec3>() / n as f32;
    // Exactly ρ·L = 0.5 for the uniform sky (the path tracer's estimate is
    // exact per sample there); within noise for the map's sampling.
    assert!((l - Vec3::splat(0.5)).abs().max_element() < 0.01, "{l}");
}

#[test]
fn bad_environment_maps_are_located_errors() {
    let dir = folder("bad");
    std::fs::write(dir.join("broken.exr"), b"not an exr").unwrap();
    for (environment, words) in [
        ("map = \"missing.hdr\"", "missing.hdr"),
        ("map = \"broken.exr\"", "broken.exr"),
        ("radiance = [1.0, 1.0, 1.0]\nmap = \"missing.hdr\"", "cannot read"),
        ("", "`radiance` or `map`"),
    ] {
        let text = format!(
            "[camera]\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 40.0\nresolution = [8, 8]\n\n\
             [[material]]\nname = \"m\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n\
             [[object]]\nshape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 0.5\nmaterial = \"m\"\n\n\
             [environment]\n{environment}\n"
        );
        let path = dir.join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let Err(e) = Scene::load(path.to_str().unwrap()) else { panic!("{environment}: loaded") };
        let e = e.to_string();
        assert!(e.contains("[environment]") && e.contains(words), "{environment}: {e}");
    }
}
