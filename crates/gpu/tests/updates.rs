//! What the viewer changes between frames: a moved camera
//! (`GpuRenderer::set_camera`) or a new photon set (`set_photons`) draws
//! what a renderer built for it draws.

use glam::Vec3;
use hikari_core::camera::Camera;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::test_support::media_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

fn moved(camera: &Camera) -> Camera {
    let position = camera.position + Vec3::new(0.4, -0.2, -0.6);
    Camera::new(
        position,
        camera.look_at + Vec3::new(0.1, 0.1, 0.0),
        camera.up,
        camera.fov_y * 0.9,
        camera.width,
        camera.height,
    )
    .unwrap()
}

fn assert_moved_camera_draws_as_built(name: &str) {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(48, 40).unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 5_000, seed: 2, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let settings = GpuSettings::new(global, caustic);
    let Some(ctx) = media_context(name, &scene) else { return };

    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &traced, settings.clone()).expect("GPU renderer");
    gpu.render().expect("first frame");
    let target = moved(&scene.camera);
    gpu.set_camera(&target).unwrap();
    gpu.render().expect("moved frame");
    let (moved_image, _) = gpu.read_image().unwrap();

    let mut built_scene = scene;
    built_scene.camera = target;
    let built = GpuRenderer::new(ctx, &built_scene, &traced, settings).expect("GPU renderer");
    built.render().expect("frame");
    let (built_image, _) = built.read_image().unwrap();

    let mut differing = 0;
    for (a, b) in moved_image.pixels.iter().zip(&built_image.pixels) {
        if (*a - *b).abs().max_element() > 1e-5 * a.max_element().max(1e-3) {
            differing += 1;
        }
    }
    let lit = built_image.pixels.iter().filter(|p| p.max_element() > 0.0).count();
    eprintln!("{name}: {differing} of {} pixels differ ({lit} lit)", built_image.pixels.len());
    assert!(lit > built_image.pixels.len() / 2);
    assert_eq!(differing, 0);
}

#[test]
fn moved_camera_draws_as_built_in_cornell_caustic() {
    assert_moved_camera_draws_as_built("cornell-caustic");
}

#[test]
fn moved_camera_draws_as_built_in_layered_fog() {
    assert_moved_camera_draws_as_built("fog-stage-layered");
}

/// Frames from a new photon set equal a renderer's built with that set:
/// the specular grids, LOD outputs and power unit all follow.
fn assert_new_photons_draw_as_built(name: &str) {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(48, 40).unwrap();
    let trace = |seed| trace_photons(&scene, &TraceSettings { photons: 5_000, seed, ..Default::default() }, &Silent);
    let (first, second) = (trace(2), trace(3));
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let settings = GpuSettings::new(global, caustic);
    let Some(ctx) = media_context(name, &scene) else { return };
    let mut gpu = GpuRenderer::new(ctx.clone(), &scene, &first, settings.clone()).expect("GPU renderer");
    gpu.render().expect("first frame");
    let (first_image, _) = gpu.read_image().unwrap();
    gpu.set_photons(&scene, &second).unwrap();
    gpu.render().expect("frame of the second set");
    let (updated, _) = gpu.read_image().unwrap();
    let built = GpuRenderer::new(ctx, &scene, &second, settings).expect("GPU renderer");
    built.render().expect("frame");
    let (built_image, _) = built.read_image().unwrap();
    let differing = updated.pixels.iter().zip(&built_image.pixels).filter(|(a, b)| **a != **b).count();
    let changed = updated.pixels.iter().zip(&first_image.pixels).filter(|(a, b)| **a != **b).count();
    eprintln!("{name}: {differing} pixels differ from the built renderer, {changed} changed from the first set");
    assert_eq!(differing, 0);
    assert!(changed > updated.pixels.len() / 2, "the second set changed only {changed} pixels");
}

#[test]
fn new_photons_draw_as_built_in_cornell_caustic() {
    assert_new_photons_draw_as_built("cornell-caustic");
}

#[test]
fn new_photons_draw_as_built_in_layered_fog() {
    assert_new_photons_draw_as_built("fog-stage-layered");
}

/// The viewer's term toggles: a frame without a term is the full frame less
/// that term's target (no media here, so no attenuation in between).
#[test]
fn terms_leave_out_what_is_toggled_off() {
    let mut scene = Scene::load("cornell-caustic").unwrap();
    scene.camera = scene.camera.with_resolution(40, 32).unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 5_000, seed: 4, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let ctx = hikari_gpu::test_support::test_context("terms");
    let mut gpu = GpuRenderer::new(ctx, &scene, &traced, GpuSettings::new(global, caustic)).expect("GPU renderer");
    gpu.render().unwrap();
    let all = gpu.read(gpu.resolved()).unwrap();
    let direct = gpu.read(&gpu.targets.direct).unwrap();
    let indirect = gpu.read(&gpu.targets.indirect).unwrap();
    gpu.settings.terms.direct = 0.0;
    gpu.settings.terms.indirect = 0.0;
    gpu.render().unwrap();
    let rest = gpu.read(gpu.resolved()).unwrap();
    let mut worst = 0.0f32;
    for i in 0..all.len() {
        let want = all[i].truncate() - direct[i].truncate() - indirect[i].truncate();
        worst = worst.max((rest[i].truncate() - want).abs().max_element() / all[i].max_element().max(1e-3));
    }
    let darker = all.iter().zip(&rest).filter(|(a, r)| a.x > r.x * 1.5).count();
    assert!(darker > all.len() / 2, "only {darker} pixels lost light");
    assert!(worst < 1e-5, "worst {worst}");
}

/// `cornell-caustic` with its glass ball and sphere light named and moving.
fn moving_caustic_scene() -> Scene {
    let text = hikari_core::scene::builtin::source("cornell-caustic")
        .unwrap()
        .replace("shape = \"sphere\"\ncenter = [0.15", "name = \"ball\"\nshape = \"sphere\"\ncenter = [0.15")
        .replace("[[light]]\ntype = \"sphere\"", "[[light]]\nname = \"lamp\"\ntype = \"sphere\"")
        + r#"
[[animation]]
target = "lamp"
type = "rotate"
center = [0.0, 0.8, 0.0]
period = 4.0

[[animation]]
target = "ball"
type = "move"
offset = [-0.3, 0.0, 0.2]
period = 2.0
"#;
    Scene::from_toml(&text, "moving-caustic.toml", None).unwrap()
}

/// A moved scene (`GpuRenderer::set_scene` with the posed scene and its
/// photons) draws what a renderer built for the posed scene draws: the
/// geometry, shadow views, BVH, lights and photon maps all follow.
fn assert_moved_scene_draws_as_built(scene: Scene) {
    let name = scene.source.clone();
    let pose = |t: f32| {
        let mut posed = scene.at_time(t);
        posed.camera = posed.camera.with_resolution(48, 40).unwrap();
        posed
    };
    let (before, after) = (pose(0.0), pose(1.3));
    let trace = |s: &Scene| trace_photons(s, &TraceSettings { photons: 5_000, seed: 2, ..Default::default() }, &Silent);
    let (first, second) = (trace(&before), trace(&after));
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&before);
    let settings = GpuSettings::new(global, caustic);
    let Some(ctx) = media_context(&name, &before) else { return };
    let mut gpu = GpuRenderer::new(ctx.clone(), &before, &first, settings.clone()).expect("GPU renderer");
    gpu.render().expect("first frame");
    let (first_image, _) = gpu.read_image().unwrap();
    gpu.set_scene(&after, &second).unwrap();
    gpu.render().expect("frame of the moved scene");
    let (updated, _) = gpu.read_image().unwrap();
    let built = GpuRenderer::new(ctx, &after, &second, settings).expect("GPU renderer");
    built.render().expect("frame");
    let (built_image, _) = built.read_image().unwrap();
    let differing = updated.pixels.iter().zip(&built_image.pixels).filter(|(a, b)| **a != **b).count();
    let changed = updated
        .pixels
        .iter()
        .zip(&first_image.pixels)
        .filter(|(a, b)| (**a - **b).abs().max_element() > 0.05 * b.max_element().max(1e-3))
        .count();
    eprintln!("{name}: {differing} pixels differ from the built renderer, {changed} changed by the motion");
    assert_eq!(differing, 0);
    assert!(changed > updated.pixels.len() / 4, "the motion changed only {changed} pixels");
}

#[test]
fn moved_scene_draws_as_built_in_cornell_orbit() {
    assert_moved_scene_draws_as_built(Scene::load("cornell-orbit").unwrap());
}

#[test]
fn moved_glass_and_area_light_draw_as_built() {
    assert_moved_scene_draws_as_built(moving_caustic_scene());
}
