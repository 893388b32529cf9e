//! The panel's starting values for a scene, the GPU renderer's settings
//! made from them, and how edits and converging passes change them: one
//! rule for the window and the web page.

use crate::panel::Controls;
use glam::Vec2;
use hikari_core::progressive::{DEFAULT_ALPHA, Schedules, pass_jitter};
use hikari_core::render::photon_cpu::{PhotonCpuSettings, default_radius};
use hikari_core::scene::Scene;
use hikari_gpu::present::PresentMode;
use hikari_gpu::{GpuContext, GpuError, GpuRenderer, GpuSettings};

/// The panel's starting values for `scene` (its lights and objects unedited).
pub fn controls_for_scene(scene: &Scene, exposure: f32, photons: u64, trace_every_frame: bool) -> Controls {
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(scene);
    let rest = scene.rest_pose();
    Controls {
        exposure,
        global_radius: global.radius,
        caustic_radius: caustic.radius,
        volume_radius: default_radius(scene),
        volume_slices: GpuSettings::new(global, caustic).volume_slices,
        terms: hikari_gpu::resolve::Terms::ALL,
        lod: None,
        mode: PresentMode::Radiance,
        photons,
        trace_every_frame,
        progressive: true,
        playing: true,
        lights: rest.lights,
        offsets: rest.offsets,
    }
}

/// The renderer's settings for `scene` as `applied` sets them on `ctx`.
pub fn gpu_settings(scene: &Scene, applied: &Controls, ctx: &GpuContext) -> GpuSettings {
    let (mut global, mut caustic) = PhotonCpuSettings::default().estimate_params(scene);
    global.radius = applied.global_radius;
    caustic.radius = applied.caustic_radius;
    // Converging frames use the normal test, as `render --passes` does.
    (global.normal_test, caustic.normal_test) = (applied.progressive, applied.progressive);
    GpuSettings {
        volume_radius: applied.volume_radius,
        volume_slices: applied.volume_slices,
        terms: applied.terms,
        lod: applied.lod,
        // The documented rule (`render --estimator auto`).
        estimator: hikari_gpu::tiled::Estimator::for_adapter(ctx),
        ..GpuSettings::new(global, caustic)
    }
}

/// Applies the panel's edits that start the mean over (terms, LOD, radii,
/// converging on or off) to `renderer`, `applied` being what it had.
/// `None`: none of them changed; `Some(true)`: the radii (or the normal
/// test) changed, so the specular pass's photon grids, cells of the radii,
/// need the photons again.
pub fn restart_for_edits(renderer: &mut GpuRenderer, c: &Controls, applied: &Controls) -> Option<bool> {
    let a = applied;
    let restart = c.terms != a.terms
        || c.lod != a.lod
        || c.global_radius != a.global_radius
        || c.caustic_radius != a.caustic_radius
        || c.volume_radius != a.volume_radius
        || c.progressive != a.progressive;
    if !restart {
        return None;
    }
    let settings = &mut renderer.settings;
    settings.terms = c.terms;
    settings.lod = c.lod;
    let radii_changed = settings.global.radius != c.global_radius
        || settings.caustic.radius != c.caustic_radius
        || settings.volume_radius != c.volume_radius;
    settings.global.radius = c.global_radius;
    settings.caustic.radius = c.caustic_radius;
    settings.volume_radius = c.volume_radius;
    let test_changed = settings.global.normal_test != c.progressive;
    (settings.global.normal_test, settings.caustic.normal_test) = (c.progressive, c.progressive);
    Some(radii_changed || test_changed)
}

/// Sets `renderer` up to draw pass `pass` of a converging mean: that
/// pass's radii and sub-pixel jitter, as `hikari render --passes` draws it
/// (docs/progressive.md), or the first pass's while converging is off.
pub fn set_pass(renderer: &mut GpuRenderer, c: &Controls, pass: u32) -> Result<(), GpuError> {
    let progressive = c.progressive;
    let schedules = Schedules::new([c.global_radius, c.caustic_radius, c.volume_radius], DEFAULT_ALPHA);
    let [global, caustic, volume] = schedules.radii(if progressive { pass } else { 1 });
    let settings = &mut renderer.settings;
    (settings.global.radius, settings.caustic.radius, settings.volume_radius) = (global, caustic, volume);
    (settings.global.normal_test, settings.caustic.normal_test) = (progressive, progressive);
    // Glossy lobes and area lights draw new samples each pass.
    settings.pass = pass;
    let mut camera = renderer.camera().clone();
    camera.jitter = if progressive { pass_jitter(pass) } else { Vec2::ZERO };
    renderer.set_camera(&camera)
}
