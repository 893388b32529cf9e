//! Vertex connection and merging (`render::vcm`) against the path tracer:
//! without merging it is unbiased and converges to `path`; light tracing
//! alone does too; with merging its bias vanishes as the radius shrinks.
//! Errors are relative to the reference's mean (the project's metric,
//! `progressive::compare`'s `relative_to_mean`), the references' own
//! noise taken out.

use hikari_core::progress::Silent;
use hikari_core::progressive::{ImageMean, compare_where, without_lights};
use hikari_core::render::vcm::{Strategies, VcmSettings, render_pass};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;

fn small(name: &str, size: u32) -> Scene {
    let mut scene = Scene::load(name).unwrap();
    scene.camera = scene.camera.with_resolution(size, size).unwrap();
    scene
}

/// The mean of `passes` VCM passes.
fn vcm(scene: &Scene, settings: &VcmSettings, passes: u32) -> Image {
    let mut mean = ImageMean::new(scene.camera.width, scene.camera.height);
    for pass in 1..=passes {
        let (image, nonfinite) = render_pass(scene, settings, pass).unwrap();
        assert_eq!(nonfinite, 0);
        mean.add(&image);
    }
    mean.mean()
}

fn path_tracing(scene: &Scene, spp: u32, seed: u64) -> Image {
    path::render(scene, &path::PathSettings { spp, seed, ..Default::default() }, &Silent).0
}

/// (reference, the variance of its own noise relative to its mean²).
fn reference(scene: &Scene, spp: u32) -> (Image, f64) {
    let (a, b) = (path_tracing(scene, spp, 99), path_tracing(scene, spp, 98));
    let noise = compare_where(&a, &b, &without_lights(&a, &b)).unwrap().relative_to_mean;
    let mut mean = ImageMean::new(a.width, a.height);
    mean.add(&a);
    mean.add(&b);
    // The mean of two references carries a quarter of their difference's variance.
    (mean.mean(), noise * noise / 4.0)
}

/// The error of `image` against the reference, its noise removed, and the
/// mean ratio, the lights' own pixels left out (their edges' sub-pixel
/// noise would drown the rest).
fn error(image: &Image, (reference, variance): &(Image, f64)) -> (f64, f64) {
    let e = compare_where(image, reference, &without_lights(image, reference)).unwrap();
    ((e.relative_to_mean.powi(2) - variance).max(0.0).sqrt(), e.mean_ratio)
}

/// VCM with `strategies` after 4 and 32 passes against a long path-traced
/// reference: the mean within 2% and the error falling; after 32 passes at
/// most `factor` times the path tracer's at 32 samples per pixel (the same
/// number of camera paths).
fn converges(name: &str, scene: &Scene, settings: VcmSettings, factor: f64) {
    converges_with(name, scene, settings, factor, 2048, 0.02);
}

fn converges_with(name: &str, scene: &Scene, settings: VcmSettings, factor: f64, reference_spp: u32, bias: f64) {
    converges_to(name, scene, settings, factor, &reference(scene, reference_spp), bias);
}

fn converges_to(name: &str, scene: &Scene, settings: VcmSettings, factor: f64, reference: &(Image, f64), bias: f64) {
    let strategies = settings.strategies;
    let errors: Vec<(f64, f64)> = [4u32, 32].iter().map(|&n| error(&vcm(scene, &settings, n), reference)).collect();
    let (path_error, path_ratio) = error(&path_tracing(scene, 32, 5), reference);
    eprintln!(
        "{name} {strategies:?}: (error, mean ratio) after 4 and 32 passes: {errors:?}; path at 32 spp: {path_error:.4}, {path_ratio:.4}; reference noise {:.4}",
        reference.1.sqrt()
    );
    let ((first, _), (last, ratio)) = (errors[0], errors[1]);
    assert!((ratio - 1.0).abs() < bias, "{name} {strategies:?}: mean ratio {ratio}");
    assert!(last < 0.6 * first, "{name} {strategies:?}: {errors:?}");
    assert!(last < factor * path_error, "{name} {strategies:?}: error {last} after 32 passes, path's {path_error}");
}

fn with(strategies: Strategies) -> VcmSettings {
    VcmSettings { strategies, seed: 7, ..Default::default() }
}

#[test]
fn bidirectional_converges_to_path_on_the_cornell_box() {
    converges("cornell-box", &small("cornell-box", 48), with(Strategies::Connections), 1.2);
}

#[test]
fn light_tracing_converges_to_path_on_the_cornell_box() {
    converges("cornell-box", &small("cornell-box", 48), with(Strategies::LightTracing), 2.0);
}

#[test]
fn vcm_converges_to_path_on_the_cornell_box() {
    converges("cornell-box", &small("cornell-box", 48), with(Strategies::All), 1.2);
}

/// Through glass, merging carries the caustic: VCM beats the path tracer.
#[test]
fn vcm_converges_to_path_through_glass() {
    converges_with("cornell-caustic", &small("cornell-caustic", 32), with(Strategies::All), 1.0, 16384, 0.02);
}

/// Merging alone (progressive photon mapping at every eye vertex), at the
/// photon maps' first radius, 3% of the diagonal: its bias (light spread
/// across corners) is still 2% of the mean after 32 passes.
#[test]
fn merging_alone_converges_to_path_on_the_cornell_box() {
    let scene = small("cornell-box", 48);
    let settings = VcmSettings { radius: Some(0.03 * scene.diagonal()), ..with(Strategies::Merging) };
    converges_with("cornell-box", &scene, settings, 3.0, 2048, 0.035);
}

/// In fog (a spot light in homogeneous fog, a box): volume vertices on
/// both subpaths, transmittance on every connection. Light tracing alone
/// sees the spot's beam from every light vertex in it.
#[test]
fn light_tracing_converges_to_path_in_fog() {
    converges_with("fog-stage", &small("fog-stage", 32), with(Strategies::LightTracing), 2.0, 1024, 0.02);
}

#[test]
fn bidirectional_converges_to_path_in_fog() {
    converges_with("fog-stage", &small("fog-stage", 32), with(Strategies::Connections), 1.2, 1024, 0.02);
}

/// Layered fog (thin fog and a denser region mesh of another phase
/// function): every strategy, merging in the volume with the ball kernel.
#[test]
fn vcm_converges_to_path_in_layered_fog() {
    let scene = small("fog-stage-layered", 32);
    let reference = reference(&scene, 1024);
    converges_to("fog-stage-layered", &scene, with(Strategies::All), 1.2, &reference, 0.02);
    // A ball twice as large, so that merges carry more of the weight (at 5%
    // of the diagonal its reach through the floor leaves 7% too little).
    let settings = VcmSettings { volume_radius: Some(0.02 * scene.diagonal()), ..with(Strategies::All) };
    converges_to("fog-stage-layered", &scene, settings, 1.2, &reference, 0.02);
}

/// Without connections VCM is progressive photon mapping: its passes and
/// progressive `photon-cpu`'s (as many light paths a pass, the same first
/// radius and schedule) make the same image up to the noise of each and
/// the difference of their blurs (photon-cpu takes direct light by shadow
/// rays, merging blurs it too): the means within 2%, the difference at most
/// 1.3 times what the two noise estimates add up to (measured: 1.14, at
/// 3% of the diagonal and 64 passes).
#[test]
fn merging_alone_agrees_with_progressive_photon_mapping() {
    use hikari_core::progressive::{DEFAULT_ALPHA, Schedules, photon_cpu_pass};
    use hikari_core::render::photon_cpu::PhotonCpuSettings;
    let scene = small("cornell-box", 48);
    let radius = 0.03 * scene.diagonal();
    let passes = 64;
    let settings = VcmSettings { radius: Some(radius), ..with(Strategies::Merging) };
    let mut merging = ImageMean::new(48, 48);
    for pass in 1..=passes {
        merging.add(&render_pass(&scene, &settings, pass).unwrap().0);
    }
    let photon_settings =
        PhotonCpuSettings { radius: Some(radius), caustic_radius: Some(radius), spp: 1, seed: 7, ..Default::default() };
    let schedules = Schedules::new([radius, radius, radius], DEFAULT_ALPHA);
    let mut photon = ImageMean::new(48, 48);
    for pass in 1..=passes {
        photon.add(&photon_cpu_pass(&scene, &photon_settings, 48 * 48, &schedules, pass).0);
    }
    let (a, b) = (merging.mean(), photon.mean());
    let e = compare_where(&a, &b, &without_lights(&a, &b)).unwrap();
    let (na, nb) = (merging.noise_estimate().unwrap(), photon.noise_estimate().unwrap());
    let expected = (na * na + nb * nb).sqrt();
    eprintln!(
        "merging alone against photon-cpu, {passes} passes: relRMSE {:.4}, mean ratio {:.4}; their noise {na:.4} and {nb:.4} (together {expected:.4})",
        e.relative_to_mean, e.mean_ratio
    );
    assert!((e.mean_ratio - 1.0).abs() < 0.02, "mean ratio {}", e.mean_ratio);
    assert!(e.relative_to_mean < 1.3 * expected, "difference {} against noise {expected}", e.relative_to_mean);
}

/// Without merging VCM is unbiased on every built-in scene (those the tests
/// above leave out here, small).
#[test]
fn bidirectional_converges_to_path_on_the_other_built_in_scenes() {
    for name in ["cornell-caustic", "cornell-orbit", "fog-stage-layered"] {
        converges_with(name, &small(name, 24), with(Strategies::Connections), 1.2, 1024, 0.02);
    }
}

/// Clear coats (smooth, followed and gathered) over every kind of base:
/// VCM's connections and merges evaluate the coated BRDF both ways, and
/// without merging it stays unbiased.
#[test]
fn vcm_converges_to_path_under_clear_coats() {
    use hikari_core::test_scenes::{coated_box, glossy_lights};
    let scene = coated_box(glossy_lights::QUAD, 24);
    let reference = reference(&scene, 1024);
    converges_to("coated-box", &scene, with(Strategies::Connections), 1.2, &reference, 0.02);
    converges_to("coated-box", &scene, with(Strategies::All), 1.2, &reference, 0.03);
}

/// Sheens, over a Lambertian, a rough metal and under a coat: VCM's
/// connections and merges evaluate them both ways.
#[test]
fn vcm_converges_to_path_under_sheens() {
    use hikari_core::test_scenes::{glossy_lights, sheen_box};
    let scene = sheen_box(glossy_lights::QUAD, 24);
    let reference = reference(&scene, 1024);
    converges_to("sheen-box", &scene, with(Strategies::Connections), 1.2, &reference, 0.02);
    converges_to("sheen-box", &scene, with(Strategies::All), 1.2, &reference, 0.03);
}
