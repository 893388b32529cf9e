//! The GPU renderer with the glTF metallic–roughness BRDF: the mean of its
//! progressive passes converges to the path tracer on a Cornell box of
//! metals and dielectrics from roughness 0.1 to 1 (lobes followed by the
//! eye and lobes gathered from the photon maps) under each kind of light,
//! as photon-cpu's does (hikari-core's tests/glossy.rs).

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::{DEFAULT_ALPHA, ImageMean, Schedules, compare, pass_jitter, pass_seed};
use hikari_core::render::photon_cpu::{PhotonCpuSettings, default_radius};
use hikari_core::render::{Image, path};
use hikari_core::scene::Scene;
use hikari_core::test_scenes::{coated_box, glossy_box, glossy_lights, quad_lights_as_meshes, sheen_box};
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

/// The means of passes 1..=n of `photons` paths each for each n in
/// `checkpoints`, as `render --renderer gpu --passes n` draws them.
fn gpu_progressive(scene: &Scene, photons: u64, checkpoints: &[u32], area_light_samples: u32) -> Vec<Image> {
    let ctx = test_context("gpu_progressive");
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(scene);
    let schedules = Schedules::new([global.radius, caustic.radius, default_radius(scene)], DEFAULT_ALPHA);
    let trace = |pass| {
        let settings = TraceSettings { photons, seed: pass_seed(3, pass), ..Default::default() };
        trace_photons(scene, &settings, &Silent)
    };
    let settings = GpuSettings { area_light_samples, ..GpuSettings::new(global, caustic) };
    let mut gpu = GpuRenderer::new(ctx, scene, &trace(1), settings).expect("GPU renderer");
    let (width, height) = (scene.camera.width, scene.camera.height);
    let mut mean = ImageMean::new(width, height);
    let mut images = Vec::new();
    for pass in 1..=*checkpoints.iter().max().unwrap() {
        if pass > 1 {
            let s = &mut gpu.settings;
            [s.global.radius, s.caustic.radius, s.volume_radius] = schedules.radii(pass);
            s.global.normal_test = true;
            s.pass = pass;
            gpu.set_photons(scene, &trace(pass)).expect("the pass's photons");
            let mut camera = scene.camera.clone();
            camera.jitter = pass_jitter(pass);
            gpu.set_camera(&camera).unwrap();
        }
        gpu.render().expect("GPU frame");
        let mut frame = Image::new(width, height);
        for (p, v) in frame.pixels.iter_mut().zip(gpu.read(gpu.resolved()).unwrap()) {
            assert!(v.is_finite(), "pass {pass}: {v}");
            *p = v.truncate();
        }
        mean.add(&frame);
        if checkpoints.contains(&pass) {
            images.push(mean.mean());
        }
    }
    images
}

fn converges(name: &str, scene: Scene, area_light_samples: u32) {
    let reference_with = |seed| {
        let (image, nonfinite) =
            path::render(&scene, &path::PathSettings { spp: 2048, seed, ..Default::default() }, &Silent);
        assert_eq!(nonfinite, 0);
        image
    };
    let reference = reference_with(99);
    let noise = compare(&reference_with(98), &reference).unwrap().relative_rmse;
    // Each reference carries noise of relative RMSE noise/√2: taken out of
    // each error in quadrature, what is left is the GPU's own error.
    let reference_variance = noise * noise / 2.0;
    let errors: Vec<(f64, f64)> = gpu_progressive(&scene, 20_000, &[1, 4, 16], area_light_samples)
        .iter()
        .map(|image| {
            let e = compare(image, &reference).unwrap();
            ((e.relative_rmse.powi(2) - reference_variance).max(0.0).sqrt(), e.mean_ratio)
        })
        .collect();
    eprintln!(
        "{name}: two path references differ by {noise:.4}; (own relative RMSE, mean ratio) after 1, 4, 16 GPU passes: {errors:?}"
    );
    let ((first, _), (last, ratio)) = (errors[0], errors[2]);
    assert!((ratio - 1.0).abs() < 0.03, "{name}: mean ratio {ratio} after 16 passes");
    assert!(last < 0.6 * first, "{name}: {errors:?}");
    // The sky's visibility comes from its K shadow-mapped directions (K =
    // 64 here): inside this box, lit through its open front, each stands
    // for 0.2 sr of the opening, which costs more than the photons' noise.
    let limit = if name == "sky" { 0.2 } else { 0.15 };
    assert!(last < limit, "{name}: relative RMSE {last} after 16 passes");
}

#[test]
fn glossy_box_on_the_gpu_under_a_point_light() {
    converges("point", glossy_box(glossy_lights::POINT, 32), 4);
}

#[test]
fn glossy_box_on_the_gpu_under_a_spot_light() {
    converges("spot", glossy_box(glossy_lights::SPOT, 32), 4);
}

#[test]
fn glossy_box_on_the_gpu_under_a_quad_light() {
    converges("quad", glossy_box(glossy_lights::QUAD, 32), 4);
}

#[test]
fn glossy_box_on_the_gpu_under_a_sun() {
    converges("sun", glossy_box(glossy_lights::SUN, 32), 4);
}

#[test]
fn glossy_box_on_the_gpu_under_a_sky() {
    converges("sky", glossy_box(glossy_lights::SKY, 32), 16);
}

#[test]
fn glossy_box_on_the_gpu_under_a_sphere_light() {
    converges("sphere", glossy_box(glossy_lights::SPHERE, 32), 4);
}

#[test]
fn glossy_box_on_the_gpu_under_an_emissive_mesh() {
    converges("mesh", quad_lights_as_meshes(&glossy_box(glossy_lights::QUAD, 32)), 4);
}

/// Clear coats (smooth, followed and gathered; bsdf.wgsl's coat): the
/// splat weights photons by the gathered part, the specular pass follows
/// the rest, the direct pass and the photon tracer use the whole.
#[test]
fn coated_box_on_the_gpu_under_a_quad_light() {
    converges("coated, quad", coated_box(glossy_lights::QUAD, 32), 4);
}

#[test]
fn coated_box_on_the_gpu_under_a_point_light() {
    converges("coated, point", coated_box(glossy_lights::POINT, 32), 4);
}

/// Sheens (bsdf.wgsl's, its albedo table read from the surfaces buffer):
/// gathered by the splat, evaluated whole by the direct pass and the tracer.
#[test]
fn sheen_box_on_the_gpu_under_a_quad_light() {
    converges("sheen, quad", sheen_box(glossy_lights::QUAD, 32), 4);
}

#[test]
fn sheen_box_on_the_gpu_under_a_point_light() {
    converges("sheen, point", sheen_box(glossy_lights::POINT, 32), 4);
}
