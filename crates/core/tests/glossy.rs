//! Glossy photon mapping (the glTF metallic–roughness BRDF, `pbr`): the
//! mean of progressive photon-cpu passes converges to the path tracer on a
//! Cornell box of metals and dielectrics from roughness 0.1 to 1 — lobes
//! followed by the eye (0.1, 0.2) and lobes gathered from the photon maps
//! (0.5, 0.7, 1) — under each light type.

use hikari_core::progress::Silent;
use hikari_core::progressive::{DEFAULT_ALPHA, ImageMean, Schedules, compare, photon_cpu_pass};
use hikari_core::render::photon_cpu::{PhotonCpuSettings, default_radius};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;
use hikari_core::test_scenes::{coated_box, glossy_box, glossy_lights::*, quad_lights_as_meshes, sheen_box};

/// The mean of passes 1..=n of `photons` paths each, at the default first radii.
fn progressive(scene: &Scene, photons: u64, passes: u32) -> Image {
    let settings = PhotonCpuSettings::default();
    let (global, caustic) = settings.estimate_params(scene);
    let schedules = Schedules::new([global.radius, caustic.radius, default_radius(scene)], DEFAULT_ALPHA);
    let mut mean = ImageMean::new(scene.camera.width, scene.camera.height);
    for pass in 1..=passes {
        let (image, nonfinite) = photon_cpu_pass(scene, &settings, photons, &schedules, pass);
        assert_eq!(nonfinite, 0);
        mean.add(&image);
    }
    mean.mean()
}

fn converges(name: &str, scene: Scene) {
    let reference_with = |seed| {
        let (image, nonfinite) =
            path::render(&scene, &path::PathSettings { spp: 2048, seed, ..Default::default() }, &Silent);
        assert_eq!(nonfinite, 0);
        image
    };
    let reference = reference_with(99);
    let noise = compare(&reference_with(98), &reference).unwrap().relative_rmse;
    eprintln!("{name}: two path references differ by {noise:.4}");
    // Each reference carries noise of relative RMSE noise/√2: taken out of
    // each error in quadrature, what is left is photon-cpu's own error.
    let reference_variance = noise * noise / 2.0;
    let errors: Vec<(f64, f64)> = [1u32, 4, 16]
        .iter()
        .map(|&n| {
            let e = compare(&progressive(&scene, 20_000, n), &reference).unwrap();
            ((e.relative_rmse.powi(2) - reference_variance).max(0.0).sqrt(), e.mean_ratio)
        })
        .collect();
    eprintln!("{name}: (own relative RMSE, mean ratio) after 1, 4, 16 passes: {errors:?}");
    let ((first, _), (last, ratio)) = (errors[0], errors[2]);
    // Unbiased in the mean, and converging: the error after 16 passes is
    // well under the first pass's (noise alone would fall to 1/4).
    assert!((ratio - 1.0).abs() < 0.03, "{name}: mean ratio {ratio} after 16 passes");
    assert!(last < 0.6 * first, "{name}: {errors:?}");
    assert!(last < 0.15, "{name}: relative RMSE {last} after 16 passes");
}

#[test]
fn glossy_box_under_a_point_light() {
    converges("point", glossy_box(POINT, 32));
}

#[test]
fn glossy_box_under_a_spot_light() {
    converges("spot", glossy_box(SPOT, 32));
}

#[test]
fn glossy_box_under_a_quad_light() {
    converges("quad", glossy_box(QUAD, 32));
}

#[test]
fn glossy_box_under_a_sun() {
    converges("sun", glossy_box(SUN, 32));
}

#[test]
fn glossy_box_under_a_sky() {
    converges("sky", glossy_box(SKY, 32));
}

#[test]
fn glossy_box_under_a_sphere_light() {
    converges("sphere", glossy_box(SPHERE, 32));
}

#[test]
fn glossy_box_under_an_emissive_mesh() {
    converges("mesh", quad_lights_as_meshes(&glossy_box(QUAD, 32)));
}

/// Clear coats (smooth, followed and gathered) over dielectric, metal and
/// satin bases: photon-cpu splits each coated BRDF into what the photon
/// maps stand for and what the eye follows, and still converges to the
/// path tracer, which samples the whole.
#[test]
fn coated_box_under_a_quad_light() {
    converges("coated, quad", coated_box(QUAD, 32));
}

/// Sheens (velvet over a Lambertian, over a rough metal, and a smooth one
/// under a coat): gathered from the photon maps, sampled by the path tracer.
#[test]
fn sheen_box_under_a_quad_light() {
    converges("sheen, quad", sheen_box(QUAD, 32));
}

#[test]
fn sheen_box_under_a_point_light() {
    converges("sheen, point", sheen_box(POINT, 32));
}

#[test]
fn coated_box_under_a_point_light() {
    converges("coated, point", coated_box(POINT, 32));
}
