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
use hikari_gpu::features::SceneFeatures;
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuRenderer, GpuSettings};

/// The means of passes 1..=n of `photons` paths each for each n in
/// `checkpoints`, as `render --renderer gpu --passes n` draws them.
fn gpu_progressive(scene: &Scene, photons: u64, checkpoints: &[u32], area_light_samples: u32) -> Vec<Image> {
    gpu_progressive_with(scene, photons, checkpoints, area_light_samples, SceneFeatures::of_scene(scene))
}

/// `gpu_progressive` with pipelines for `features`.
fn gpu_progressive_with(
    scene: &Scene,
    photons: u64,
    checkpoints: &[u32],
    area_light_samples: u32,
    features: SceneFeatures,
) -> Vec<Image> {
    let ctx = test_context("gpu_progressive");
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(scene);
    let schedules = Schedules::new([global.radius, caustic.radius, default_radius(scene)], DEFAULT_ALPHA);
    let trace = |pass| {
        let settings = TraceSettings { photons, seed: pass_seed(3, pass), ..Default::default() };
        trace_photons(scene, &settings, &Silent)
    };
    let settings = GpuSettings { area_light_samples, ..GpuSettings::new(global, caustic) };
    let mut gpu = GpuRenderer::with_features(ctx, scene, &trace(1), settings, features).expect("GPU renderer");
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

/// Clear-coat, sheen and specular textures per point (the G-buffer's layer
/// texels in the raster passes, the tracer's and the specular pass's hits):
/// the layered quad (every factor times the grey checker; its base black,
/// so that the layers are what it shows) seen at 45° under its white sky
/// converges to the path tracer, and much closer than
/// the same renderer drawing each texture as its mean (what an adapter
/// without room for the fifth target does).
#[test]
fn layer_textures_on_the_gpu_converge_to_the_path_tracer() {
    use glam::Vec3;
    use hikari_core::test_scenes::gltf_textures::{layered_glb, load};
    let mut scene = load("gpu-layers-converge", &layered_glb());
    for material in &mut scene.materials {
        if let hikari_core::material::Material::Pbr(bsdf) = material {
            bsdf.base_color = Vec3::ZERO;
        }
    }
    scene.camera =
        hikari_core::camera::Camera::new(Vec3::new(0.5, -0.2, 0.7), Vec3::new(0.5, 0.5, 0.0), Vec3::Z, 35.0, 32, 32)
            .unwrap();
    let (reference, nonfinite) =
        path::render(&scene, &path::PathSettings { spp: 2048, seed: 99, ..Default::default() }, &Silent);
    assert_eq!(nonfinite, 0);
    let own = SceneFeatures::of_scene(&scene);
    assert!(own.layered);
    let error = |features| {
        let image = gpu_progressive_with(&scene, 5_000, &[16], 4, features).pop().unwrap();
        compare(&image, &reference).unwrap()
    };
    let (per_point, means) = (error(own), error(SceneFeatures { layered: false, ..own }));
    eprintln!("layered quad, 16 GPU passes against path: per point {per_point:?}; as means {means:?}");
    assert!((per_point.mean_ratio - 1.0).abs() < 0.03, "mean ratio {}", per_point.mean_ratio);
    // The 16×16 blocks' error: the pixels' own is mostly the passes' noise.
    let blocks = |e: &hikari_core::progressive::ImageError| e.block_relative_to_mean.unwrap();
    assert!(blocks(&per_point) < 0.6 * blocks(&means), "per point {per_point:?}, means {means:?}");
}
