//! The photon renderer against analytic answers and against the path tracer.
//!
//! These are statistical tests with fixed seeds: each tolerance is several
//! standard deviations of the estimate it bounds, stated next to it.

use glam::Vec3;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{Components, PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;
use hikari_core::test_scenes::furnace;

fn photon_cpu(scene: &Scene, photons: u64, settings: PhotonCpuSettings) -> Image {
    let traced = trace_photons(scene, &TraceSettings { photons, seed: 7, ..Default::default() }, &Silent);
    let (image, nonfinite) = PhotonCpuRenderer::new(scene, &traced, &settings).render(&Silent);
    assert_eq!(nonfinite, 0);
    image
}

fn path_traced(scene: &Scene, spp: u32) -> Image {
    let (image, nonfinite) = path::render(scene, &path::PathSettings { spp, seed: 3, ..Default::default() }, &Silent);
    assert_eq!(nonfinite, 0);
    image
}

/// Mean over the pixels that do not see an emitter directly. A pixel that
/// does is worth (covered fraction × emitted radiance), which says nothing
/// about light transport and, for a tiny bright light, swamps the mean; the
/// mask is built from 8×8 rays per pixel against the scene geometry.
fn mean_off_emitters(scene: &Scene, image: &Image) -> f32 {
    let cam = &scene.camera;
    let (mut sum, mut count) = (0.0f64, 0usize);
    for y in 0..image.height {
        for x in 0..image.width {
            let sees_light = (0..64).any(|i| {
                let offset = glam::Vec2::new((i % 8) as f32 + 0.5, (i / 8) as f32 + 0.5) / 8.0;
                let ray = cam.ray(glam::Vec2::new(x as f32, y as f32) + offset);
                scene.accel.intersect(&ray).is_some_and(|h| scene.emitter(&h).is_some())
            });
            if !sees_light {
                let p = image.get(x, y);
                sum += (p.x + p.y + p.z) as f64 / 3.0;
                count += 1;
            }
        }
    }
    assert!(count > 0);
    (sum / count as f64) as f32
}

fn small(name: &str, size: u32) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(size, size).unwrap();
    scene
}

/// Closed sphere, albedo 0.5, point light of intensity π at the centre:
/// radiance 1 everywhere (direct 0.5 + indirect 0.5).
#[test]
fn furnace_path_tracer_gives_radiance_one() {
    let image = path_traced(&furnace(Vec3::splat(0.5), 1.0), 64);
    let mean = image.mean();
    eprintln!("path furnace {mean}");
    assert!((mean - 1.0).abs() < 0.02, "path tracer furnace radiance {mean}");
}

#[test]
fn furnace_photon_cpu_gives_radiance_one() {
    let scene = furnace(Vec3::splat(0.5), 1.0);
    // r = 0.05 against a sphere of radius 1. On a sphere the ball of radius r
    // around a surface point cuts a cap of area exactly πr², so the estimate
    // has no curvature bias; ~24,000 indirect photons fall in view (0.7% noise).
    let settings = PhotonCpuSettings { radius: Some(0.05), spp: 1, ..Default::default() };
    let image = photon_cpu(&scene, 400_000, settings.clone());
    let mean = image.mean();
    eprintln!("photon-cpu furnace {mean}");
    assert!((mean - 1.0).abs() < 0.02, "photon-cpu furnace radiance {mean}");
    // Direct light alone is exactly albedo/π · I/R² = 0.5.
    let direct = photon_cpu(
        &scene,
        1_000,
        PhotonCpuSettings {
            components: Components { indirect: false, caustic: false, direct: true, volume: false },
            ..settings
        },
    );
    assert!((direct.mean() - 0.5).abs() < 1e-4, "direct {}", direct.mean());
}

/// Direct + global + caustic must partition the light paths: the photon
/// renderer's image mean matches the path tracer's.
#[test]
fn cornell_box_photon_cpu_matches_path_tracer() {
    let scene = small("cornell-box", 64);
    let photon = photon_cpu(&scene, 200_000, PhotonCpuSettings { spp: 4, ..Default::default() });
    let truth = path_traced(&scene, 64);
    let (p, t) = (mean_off_emitters(&scene, &photon), mean_off_emitters(&scene, &truth));
    eprintln!("photon-cpu mean {p} vs path {t}: {:+.2}%", (p - t) / t * 100.0);
    assert!((p - t).abs() / t < 0.03, "photon-cpu mean {p} vs path {t}");
}

#[test]
fn cornell_caustic_photon_cpu_matches_path_tracer() {
    let scene = small("cornell-caustic", 64);
    let photon = photon_cpu(&scene, 200_000, PhotonCpuSettings { spp: 4, ..Default::default() });
    let truth = path_traced(&scene, 64);
    let (p, t) = (mean_off_emitters(&scene, &photon), mean_off_emitters(&scene, &truth));
    eprintln!("photon-cpu mean {p} vs path {t}: {:+.2}%", (p - t) / t * 100.0);
    assert!((p - t).abs() / t < 0.03, "photon-cpu mean {p} vs path {t}");
}
