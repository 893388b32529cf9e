//! The GPU photon tracer against the CPU tracer: the same random streams,
//! encodings and sampling bit for bit or within rounding; the same photons
//! for nearly every path; the same flux per path class and per bounce; the
//! same images; and maps that do not depend on batching or scheduling.

use glam::Vec3;
use hikari_core::photon::{PathClass, Photon, TraceSettings, TracedPhotons, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::compare;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::sampling::Rng;
use hikari_core::scene::Scene;
use hikari_core::test_scenes::{cornell_quad_light, glossy_box, glossy_lights, gltf_textures, quad_lights_as_meshes};
use hikari_gpu::GpuContext;
use hikari_gpu::test_support::{run_kernel, sky_over_a_box, sun_and_sky_in_fog, sun_over_a_box, test_context};
use hikari_gpu::trace::GpuTracer;
use hikari_gpu::wgsl::{PHOTON_ENCODING, RANDOM, SAMPLING};
use std::collections::HashMap;

/// random.wgsl draws the same numbers as `Rng::for_item`.
#[test]
fn random_streams_match_the_cpu() {
    let ctx = test_context("random_streams_match_the_cpu");
    let (seed, draws, streams) = (0x1234_5678_9abc_def0u64, 8usize, 64usize);
    let (mixed, increment) = Rng::seed_constants(seed);
    // Stream i is path index 2^32 − 7 + 977·i: low and high words both move.
    let index = |i: usize| (1u64 << 32) - 7 + 977 * i as u64;
    let main = format!(
        "let i = id.x / {draws}u; let k = id.x % {draws}u;\n\
         if (i >= {streams}u) {{ return; }}\n\
         let index = add_u64(vec2<u32>(0xfffffff9u, 0u), vec2<u32>(977u * i, 0u));\n\
         var rng = rng_for_item(vec2<u32>({}u, {}u), vec2<u32>({}u, {}u), index);\n\
         var x = 0u;\n\
         for (var j = 0u; j <= k; j++) {{ x = rng_next_u32(&rng); }}\n\
         io[id.x] = x;",
        mixed as u32,
        (mixed >> 32) as u32,
        increment as u32,
        (increment >> 32) as u32
    );
    let gpu = run_kernel(&ctx, &[&RANDOM], &main, &vec![0; draws * streams]);
    for i in 0..streams {
        let mut rng = Rng::for_item(seed, index(i));
        for k in 0..draws {
            assert_eq!(gpu[i * draws + k], rng.next_u32(), "stream {i}, draw {k}");
        }
    }
}

/// photon_encoding.wgsl encodes power and direction to the CPU's bits.
#[test]
fn photon_encoding_matches_the_cpu() {
    let ctx = test_context("photon_encoding_matches_the_cpu");
    let mut rng = Rng::for_item(4, 0);
    let mut input = Vec::new();
    for i in 0..4096 {
        let scale = 2f32.powf(rng.next_f32() * 40.0 - 20.0);
        let v = if i % 2 == 0 {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale
        } else {
            hikari_core::sampling::uniform_sphere(rng.next_2d())
        };
        input.extend(v.to_array().map(f32::to_bits));
        input.push(0);
    }
    let main = "let b = 4u * id.x; if (b >= arrayLength(&io)) { return; }\n\
                let v = vec3<f32>(bitcast<f32>(io[b]), bitcast<f32>(io[b + 1u]), bitcast<f32>(io[b + 2u]));\n\
                if (id.x % 2u == 0u) { io[b + 3u] = encode_rgb9e5(v); } else { io[b + 3u] = encode_octahedral_15(v); }";
    let gpu = run_kernel(&ctx, &[&PHOTON_ENCODING], main, &input);
    for (i, item) in input.chunks(4).enumerate() {
        let v = Vec3::new(f32::from_bits(item[0]), f32::from_bits(item[1]), f32::from_bits(item[2]));
        let cpu = if i % 2 == 0 {
            Photon::new(v, v, Vec3::Z, PathClass::Direct).power_rgb9e5
        } else {
            Photon::new(Vec3::ZERO, Vec3::ONE, v, PathClass::Direct).direction_and_class
        };
        assert_eq!(gpu[4 * i + 3], cpu, "item {i}: {v}");
    }
}

/// sampling.wgsl's directions agree with hikari_core::sampling and the
/// phase samplers to float rounding.
#[test]
fn sampling_matches_the_cpu() {
    use hikari_core::medium::Phase;
    use hikari_core::sampling::{cosine_hemisphere, local_to_world, uniform_cone, uniform_sphere};
    let ctx = test_context("sampling_matches_the_cpu");
    let mut rng = Rng::for_item(6, 0);
    let n = 2048;
    // Per item: u (2), an axis (3), then 3 outputs × 3 words.
    let mut input = vec![0u32; n * 16];
    for item in input.chunks_mut(16) {
        let u = rng.next_2d();
        let axis = uniform_sphere(rng.next_2d());
        item[0] = u.x.to_bits();
        item[1] = u.y.to_bits();
        item[2..5].copy_from_slice(&axis.to_array().map(f32::to_bits));
    }
    let main = "let b = 16u * id.x; if (b >= arrayLength(&io)) { return; }\n\
                let u = vec2<f32>(bitcast<f32>(io[b]), bitcast<f32>(io[b + 1u]));\n\
                let axis = vec3<f32>(bitcast<f32>(io[b + 2u]), bitcast<f32>(io[b + 3u]), bitcast<f32>(io[b + 4u]));\n\
                let outs = array<vec3<f32>, 3>(\n\
                    uniform_sphere(u),\n\
                    local_to_world(cosine_hemisphere(u), axis) + uniform_cone(u, 0.3),\n\
                    phase_sample(1.0, 0.6, axis, u) + phase_sample(0.0, -0.4, axis, u));\n\
                for (var k = 0u; k < 3u; k++) {\n\
                    io[b + 5u + 3u * k] = bitcast<u32>(outs[k].x);\n\
                    io[b + 6u + 3u * k] = bitcast<u32>(outs[k].y);\n\
                    io[b + 7u + 3u * k] = bitcast<u32>(outs[k].z);\n\
                }";
    let gpu = run_kernel(&ctx, &[&SAMPLING], main, &input);
    let mut worst = 0.0f32;
    for (i, item) in gpu.chunks(16).enumerate() {
        let f = |k: usize| f32::from_bits(item[k]);
        let u = glam::Vec2::new(f(0), f(1));
        let axis = Vec3::new(f(2), f(3), f(4));
        let cpu = [
            uniform_sphere(u),
            local_to_world(cosine_hemisphere(u), axis) + uniform_cone(u, 0.3),
            Phase::HenyeyGreenstein { g: 0.6 }.sample(axis, u) + Phase::Schlick { k: -0.4 }.sample(axis, u),
        ];
        for (k, want) in cpu.iter().enumerate() {
            let got = Vec3::new(f(5 + 3 * k), f(6 + 3 * k), f(7 + 3 * k));
            let err = (got - *want).abs().max_element();
            worst = worst.max(err);
            assert!(err < 2e-6, "item {i}, sampler {k}: {got} vs {want}");
        }
    }
    eprintln!("sampling: worst difference {worst:e}");
}

/// Every light type, mirror, glass, diffuse + mirror, a smooth-normal mesh
/// and (optionally) two media filling the box with different phase functions.
/// The features scene's four lights, one TOML entry each.
const FEATURE_LIGHTS: [&str; 4] = [
    "[[light]]\ntype = \"point\"\nposition = [0.0, 0.9, 0.0]\nintensity = [2.0, 2.0, 2.0]\n",
    "[[light]]\ntype = \"spot\"\nposition = [-0.8, 0.9, 0.8]\ndirection = [0.5, -1.0, -0.4]\nintensity = [6.0, 5.0, 4.0]\ncutoff_angle = 30.0\nfalloff_start_angle = 15.0\n",
    "[[light]]\ntype = \"sphere\"\ncenter = [0.7, 0.8, 0.6]\nradius = 0.08\nradiance = [20.0, 20.0, 20.0]\n",
    "[[light]]\ntype = \"quad\"\ncorner = [-0.3, 1.15, -0.3]\nedge_u = [0.6, 0.0, 0.0]\nedge_v = [0.0, 0.0, 0.6]\nradiance = [8.0, 8.0, 8.0]\n",
];

fn feature_scene(media: bool) -> Scene {
    feature_scene_lit(media, &FEATURE_LIGHTS)
}

/// The features scene lit by `lights` (entries of `FEATURE_LIGHTS`).
fn feature_scene_lit(media: bool, lights: &[&str]) -> Scene {
    let lights_text = lights.join("\n");
    let dir = std::env::temp_dir().join(format!("hikari-trace-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A tetrahedron-like mesh with normals that differ from its faces.
    std::fs::write(
        dir.join("smooth.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
         vn -1 -1 -1\nvn 1 -0.2 -0.2\nvn -0.2 1 -0.2\nvn -0.2 -0.2 1\n\
         f 1//1 3//3 2//2\nf 1//1 2//2 4//4\nf 1//1 4//4 3//3\nf 2//2 3//3 4//4\n",
    )
    .unwrap();
    let media_text = if media {
        r#"
[[medium]]
sigma_a = [0.02, 0.03, 0.05]
sigma_s = [0.15, 0.2, 0.25]
phase = "hg"
g = 0.4

[[medium]]
sigma_s = [0.05, 0.05, 0.05]
phase = "schlick"
k = -0.3
"#
    } else {
        ""
    };
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, 3.5]
look_at = [0.0, 0.0, 0.0]
fov_y = 45.0
resolution = [32, 32]

[[material]]
name = "white"
type = "diffuse"
albedo = [0.7, 0.7, 0.65]

[[material]]
name = "shiny"
type = "diffuse"
albedo = [0.3, 0.5, 0.2]
specular_reflectance = [0.4, 0.3, 0.5]

[[material]]
name = "mirror"
type = "mirror"
reflectance = [0.9, 0.85, 0.8]

[[material]]
name = "glass"
type = "glass"
ior = 1.5
# Tinted: what crosses loses power by roulette, the same draws on both.
base_color = [0.9, 0.75, 0.6]

[[object]]
shape = "box"
center = [0.0, 0.0, 0.0]
size = [2.4, 2.4, 2.4]
material = "white"

[[object]]
shape = "sphere"
center = [0.4, -0.6, 0.2]
radius = 0.4
material = "glass"

[[object]]
shape = "quad"
corner = [-1.15, -1.0, -1.0]
edge_u = [0.0, 0.0, 1.2]
edge_v = [0.0, 1.4, 0.0]
material = "mirror"

[[object]]
shape = "box"
center = [-0.5, -0.8, -0.3]
size = [0.5, 0.4, 0.5]
rotate_y = 20.0
material = "shiny"

[[object]]
mesh = "smooth.obj"
scale = 0.5
translate = [0.3, 0.2, -0.6]
material = "white"

{lights_text}
{media_text}
"#
    );
    Scene::from_toml(&text, "features", Some(&dir)).unwrap()
}

fn gpu_trace(ctx: &GpuContext, scene: &Scene, settings: &TraceSettings) -> TracedPhotons {
    let mut tracer = GpuTracer::new(ctx, scene).unwrap();
    tracer.per_bounce_statistics = true;
    tracer.trace(ctx, settings).unwrap().0
}

/// Photons of `a` found (as exact bits) in `b`, as a fraction of `a`.
fn shared_fraction(a: &[Photon], b: &[Photon]) -> f64 {
    let key = |p: &Photon| bytemuck::cast::<Photon, [u32; 5]>(*p);
    let mut pool: HashMap<[u32; 5], usize> = HashMap::new();
    for p in b {
        *pool.entry(key(p)).or_default() += 1;
    }
    let shared = a
        .iter()
        .filter(|p| match pool.get_mut(&key(p)) {
            Some(n) if *n > 0 => {
                *n -= 1;
                true
            }
            _ => false,
        })
        .count();
    if a.is_empty() { 1.0 } else { shared as f64 / a.len() as f64 }
}

/// Photons of `a` that some photon of `b` matches within float rounding (each
/// used once): position within `tolerance`, the same class or phase slot,
/// power within 1% and direction within 0.1°, as a fraction of `a`. Free
/// flights use ln and exp, which WGSL does not round as Rust's libm does, so
/// in media the paths agree to rounding rather than bit for bit.
fn near_fraction(a: &[Photon], b: &[Photon], tolerance: f32) -> f64 {
    let cell = |p: Vec3| (p / tolerance).floor().as_ivec3();
    let mut grid: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
    for (i, p) in b.iter().enumerate() {
        grid.entry(cell(p.position())).or_default().push(i);
    }
    let mut used = vec![false; b.len()];
    let mut matched = 0usize;
    for p in a {
        let c = cell(p.position());
        let mut found = None;
        'search: for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    for &j in grid.get(&(c + glam::IVec3::new(dx, dy, dz))).map_or(&[][..], |v| &v[..]) {
                        let q = &b[j];
                        let close = !used[j]
                            && p.position().distance(q.position()) <= tolerance
                            && p.direction_and_class >> 30 == q.direction_and_class >> 30
                            && (p.power_in_units() - q.power_in_units()).abs().max_element()
                                <= 0.01 * q.power_in_units().max_element()
                            && p.direction().dot(q.direction()) > 0.999_998;
                        if close {
                            found = Some(j);
                            break 'search;
                        }
                    }
                }
            }
        }
        if let Some(j) = found {
            used[j] = true;
            matched += 1;
        }
    }
    if a.is_empty() { 1.0 } else { matched as f64 / a.len() as f64 }
}

fn scenes() -> Vec<(&'static str, Scene)> {
    vec![
        ("cornell-box", Scene::load("cornell-box").unwrap()),
        ("cornell-caustic", Scene::load("cornell-caustic").unwrap()),
        ("fog-stage", Scene::load("fog-stage").unwrap()),
        ("fog-stage-layered", Scene::load("fog-stage-layered").unwrap()),
        ("features", feature_scene(false)),
        ("features + media", feature_scene(true)),
        ("sun over a box", sun_over_a_box(32)),
        ("sky over a box", sky_over_a_box(32)),
        ("sun and sky in fog", sun_and_sky_in_fog(32)),
        ("cornell mesh light", quad_lights_as_meshes(&cornell_quad_light(16))),
        ("cornell two-sided mesh light", two_sided(quad_lights_as_meshes(&cornell_quad_light(16)))),
        ("glossy box, quad light", glossy_box(glossy_lights::QUAD, 16)),
        ("glossy box, point light", glossy_box(glossy_lights::POINT, 16)),
        ("textured cut-out", gltf_textures::load("trace-cutout", &gltf_textures::cutout_glb())),
        ("rough tinted glass", rough_caustic("")),
        ("normal map before a mirror", gltf_textures::normal_map_before_a_mirror("trace-normal-map", 16)),
        ("normal-mapped floors", gltf_textures::normal_mapped_floors("trace-normal-floors", 16)),
        ("layered floor", gltf_textures::layered_floor("trace-layered-floor", 16)),
    ]
}

/// cornell-caustic with its ball of tinted glass made rough, and `extra`
/// TOML appended.
fn rough_caustic(extra: &str) -> Scene {
    let text = hikari_core::scene::builtin::source("cornell-caustic").unwrap().replacen(
        "type = \"glass\"\nior = 1.5",
        "type = \"glass\"\nior = 1.5\nroughness = 0.3\nbase_color = [0.9, 0.8, 0.6]",
        1,
    ) + extra;
    Scene::from_toml(&text, "rough-caustic.toml", None).unwrap()
}

/// `scene` with its emissive meshes made two-sided.
fn two_sided(mut scene: Scene) -> Scene {
    use hikari_core::light::{EmissiveMesh, Light};
    for light in &mut scene.lights {
        if let Light::Mesh(mesh) = light {
            let both = EmissiveMesh::new(mesh.triangles().to_vec(), mesh.radiance, true).unwrap();
            *light = Light::Mesh(std::sync::Arc::new(both));
        }
    }
    scene
}

/// With the same seed the GPU takes the CPU's paths: nearly every photon
/// is the same 20 bytes, and the maps have the same sizes.
#[test]
fn gpu_tracer_stores_the_cpu_photons() {
    let ctx = test_context("gpu_tracer_stores_the_cpu_photons");
    for (name, scene) in scenes() {
        let settings = TraceSettings { photons: 20_000, seed: 11, ..Default::default() };
        let cpu = trace_photons(&scene, &settings, &Silent);
        let gpu = gpu_trace(&ctx, &scene, &settings);
        assert_eq!(gpu.power_unit, cpu.power_unit, "{name}");
        let tolerance = 1e-5 * scene.accel.diagonal();
        let strict_float =
            ctx.adapter_info.backend == wgpu::Backend::Vulkan && ctx.adapter_info.device_type == wgpu::DeviceType::Cpu;
        for (map, g, c) in [
            ("global", &gpu.global, &cpu.global),
            ("caustic", &gpu.caustic, &cpu.caustic),
            ("volume", &gpu.volume, &cpu.volume),
        ] {
            let exact = shared_fraction(g, c);
            let near = near_fraction(g, c, tolerance);
            eprintln!(
                "{name} {map}: {} GPU photons, {} CPU; {:.3}% identical, {:.3}% within rounding",
                g.len(),
                c.len(),
                100.0 * exact,
                100.0 * near
            );
            if c.len() < 50 {
                continue;
            }
            let size_ratio = g.len() as f64 / c.len() as f64;
            assert!((size_ratio - 1.0).abs() < 0.01, "{name} {map}: {} vs {}", g.len(), c.len());
            assert!(near > 0.97, "{name} {map}: only {:.2}% within rounding", 100.0 * near);
            // Without media every path is the CPU's to rounding (100% of
            // the photons on lavapipe, over 99.5% on Mesa's GL): a power off by a
            // factor on a few per cent of paths (a bounce's bump shadowing
            // left out: 97.1% of the normal-mapped floors' photons) shows.
            if scene.media.is_empty() {
                assert!(near > 0.995, "{name} {map}: only {:.2}% within rounding", 100.0 * near);
            }
            // Without media and normal textures every operation is mirrored
            // exactly, and lavapipe (Vulkan) keeps the CPU's bits for > 99.99%
            // of photons. A normal texture's bend goes through cross products
            // and square roots WGSL may round otherwise (97.5% of the
            // normal-mapped scene's global photons identical, 100% within
            // rounding): only within rounding there.
            // Mesa's GL fuses some products into multiply-adds (cornell-caustic:
            // 92.6% of the global and 37.7% of the caustic map bit-identical,
            // 100% within rounding), as real GPUs may: only reported there.
            let bends =
                scene.texturing.as_ref().is_some_and(|t| t.materials.iter().flatten().any(|m| m.normal.is_some()));
            if scene.media.is_empty() && !bends && strict_float {
                assert!(exact > 0.97, "{name} {map}: only {:.2}% identical", 100.0 * exact);
            }
        }
        assert!(!gpu.global.is_empty());
    }
}

/// Independent seeds: the flux stored per path class and per bounce agrees
/// within its statistics (as `trace_photons`'s own roulette test), scene by
/// scene, each lit by a different kind of light.
#[test]
fn stored_flux_matches_per_class_and_bounce() {
    let ctx = test_context("stored_flux_matches_per_class_and_bounce");
    for (name, scene) in scenes() {
        let photons = 100_000;
        let cpu = trace_photons(&scene, &TraceSettings { photons, seed: 21, ..Default::default() }, &Silent);
        let gpu = gpu_trace(&ctx, &scene, &TraceSettings { photons, seed: 22, ..Default::default() });
        assert_flux_per_class(name, &gpu, &cpu);
        let per_bounce = |t: &TracedPhotons| t.stats.stored_flux_per_bounce.clone();
        let first = per_bounce(&cpu)[0].max_element();
        for (k, (g, c)) in per_bounce(&gpu).iter().zip(per_bounce(&cpu).iter()).enumerate().take(3) {
            let rel = ((*g - *c) / *c).abs().max_element();
            eprintln!("{name} bounce {k}: GPU {g} CPU {c}");
            // Open scenes lose most photons to the sky: a bounce with under
            // 2% of the first one's flux holds too few photons to compare.
            if c.max_element() < 0.02 * first {
                continue;
            }
            assert!(rel < 0.05, "{name} bounce {k}: GPU {g} vs CPU {c}");
        }
        let volume = |t: &TracedPhotons| t.volume.iter().map(|p| p.power_in_units().element_sum() as f64).sum::<f64>();
        if cpu.volume.len() > 1000 {
            let (g, c) = (volume(&gpu), volume(&cpu));
            assert!((g / c - 1.0).abs() < 0.05, "{name} volume flux: GPU {g} vs CPU {c}");
        }
    }
}

/// The flux stored per path class by independent GPU and CPU runs agrees
/// within its statistics.
fn assert_flux_per_class(name: &str, gpu: &TracedPhotons, cpu: &TracedPhotons) {
    let flux = |t: &TracedPhotons, class: PathClass| -> f64 {
        t.global.iter().filter(|p| p.class() == class).map(|p| p.power_in_units().element_sum() as f64).sum::<f64>()
            * t.power_unit as f64
    };
    for class in [PathClass::Direct, PathClass::Caustic, PathClass::Indirect] {
        let (g, c) = (flux(gpu, class), flux(cpu, class));
        let count = cpu.global.iter().filter(|p| p.class() == class).count();
        if count < 400 {
            continue;
        }
        // A sum of `count` roughly equal terms: 5 standard deviations of both runs.
        let tolerance = 5.0 * (2.0 / count as f64).sqrt() + 0.01;
        eprintln!("{name} {class:?}: GPU {g:.4} CPU {c:.4} ({count} photons)");
        assert!((g / c - 1.0).abs() < tolerance, "{name} {class:?}: GPU {g} vs CPU {c}");
    }
}

/// Light by light: the features scene lit by each of its four lights
/// alone (point, spot, sphere, quad), in fog, stores the same flux per
/// path class on the GPU as on the CPU, and the same volume flux.
#[test]
fn stored_flux_matches_per_light() {
    let ctx = test_context("stored_flux_matches_per_light");
    for (k, light) in FEATURE_LIGHTS.iter().enumerate() {
        let scene = feature_scene_lit(true, &[light]);
        let name = format!("light {k}");
        let photons = 60_000;
        let cpu = trace_photons(&scene, &TraceSettings { photons, seed: 31, ..Default::default() }, &Silent);
        let gpu = gpu_trace(&ctx, &scene, &TraceSettings { photons, seed: 32, ..Default::default() });
        assert_flux_per_class(&name, &gpu, &cpu);
        let volume = |t: &TracedPhotons| {
            t.volume.iter().map(|p| p.power_in_units().element_sum() as f64).sum::<f64>() * t.power_unit as f64
        };
        let (g, c) = (volume(&gpu), volume(&cpu));
        eprintln!("{name} volume: GPU {g:.4} CPU {c:.4} ({} photons)", cpu.volume.len());
        assert!(cpu.volume.len() > 1000 && (g / c - 1.0).abs() < 0.05, "{name} volume flux: GPU {g} vs CPU {c}");
    }
}

/// The furnace of `trace_photons`'s roulette test, traced on the GPU: the
/// flux at the k-th bounce is Φ ρ^k, channel by channel.
#[test]
fn gpu_roulette_keeps_stored_flux_per_bounce() {
    let ctx = test_context("gpu_roulette_keeps_stored_flux_per_bounce");
    let albedo = Vec3::new(0.8, 0.5, 0.2);
    let scene = hikari_core::test_scenes::furnace(albedo, 1.0);
    let phi = scene.lights[0].power();
    let traced = gpu_trace(&ctx, &scene, &TraceSettings { photons: 200_000, seed: 5, ..Default::default() });
    for k in 0..4 {
        let expected = phi * albedo.powf(k as f32);
        let got = traced.stats.stored_flux_per_bounce[k];
        let rel = ((got - expected) / expected).abs().max_element();
        assert!(rel < 0.03, "bounce {k}: stored {got}, expected {expected}");
    }
    assert_eq!(traced.stats.truncated, 0);
}

/// Two runs give the same bits; so do small batches and a record buffer too
/// small at first (every batch runs again), whatever order paths ran in.
#[test]
fn gpu_maps_are_deterministic_whatever_the_batching() {
    let ctx = test_context("gpu_maps_are_deterministic_whatever_the_batching");
    let scene = feature_scene(true);
    let settings = TraceSettings { photons: 12_345, seed: 3, ..Default::default() };
    let mut tracer = GpuTracer::new(&ctx, &scene).unwrap();
    let (a, _) = tracer.trace(&ctx, &settings).unwrap();
    let (b, _) = tracer.trace(&ctx, &settings).unwrap();
    let mut small = GpuTracer::new(&ctx, &scene).unwrap();
    small.batch_paths = 1000;
    small.records_per_path = 1;
    let (c, report) = small.trace(&ctx, &settings).unwrap();
    assert!(report.retried_batches > 0, "the small record buffer was never exceeded");
    for other in [&b, &c] {
        assert_eq!(a.global, other.global);
        assert_eq!(a.caustic, other.caustic);
        assert_eq!(a.volume, other.volume);
    }
    assert!(!a.volume.is_empty() && !a.caustic.is_empty());
    let sizes = tracer.trace_on_gpu(&ctx, &settings).unwrap();
    assert_eq!(sizes, [a.global.len() as u64, a.caustic.len() as u64, a.volume.len() as u64]);
    // Another seed, other photons.
    let (d, _) = tracer.trace(&ctx, &TraceSettings { seed: 4, ..settings }).unwrap();
    assert_ne!(a.global, d.global);
}

/// photon-cpu renders the same image from GPU-traced and CPU-traced maps.
#[test]
fn images_from_gpu_traced_maps_match() {
    let ctx = test_context("images_from_gpu_traced_maps_match");
    for (name, mut scene) in scenes() {
        scene.camera = scene.camera.with_resolution(32, 32).unwrap();
        let settings = TraceSettings { photons: 30_000, seed: 8, ..Default::default() };
        let render = |traced: &TracedPhotons| {
            let settings = PhotonCpuSettings { spp: 1, ..Default::default() };
            PhotonCpuRenderer::new(&scene, traced, &settings).render(&Silent).0
        };
        let cpu = render(&trace_photons(&scene, &settings, &Silent));
        let gpu = render(&gpu_trace(&ctx, &scene, &settings));
        let error = compare(&gpu, &cpu).unwrap();
        eprintln!("{name}: relative RMSE {:.2e}, mean ratio {:.6}", error.relative_rmse, error.mean_ratio);
        assert!(error.relative_rmse < 0.02 && (error.mean_ratio - 1.0).abs() < 0.005, "{name}: {error:?}");
    }
}

/// Rough glass under a point light is drawn and traced on the GPU (its
/// specular pass samples point, spot and sun lights through the glass;
/// it used to hand such scenes to the CPU).
#[test]
fn rough_glass_under_a_point_light_is_drawn() {
    let ctx = test_context("rough glass");
    let point = "\n[[light]]\ntype = \"point\"\nposition = [0.0, 0.9, 0.0]\nintensity = [1.0, 1.0, 1.0]\n";
    let scene = rough_caustic(point);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let settings = hikari_gpu::GpuSettings::new(global, caustic);
    hikari_gpu::GpuRenderer::check_fits(&ctx, &scene, &settings, [1000; 3]).expect("drawn");
    let mut tracer = GpuTracer::new(&ctx, &rough_caustic("")).expect("traced");
    tracer.set_scene(&ctx, &scene).expect("traced under a point light");
}
