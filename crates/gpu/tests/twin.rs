//! Twin tests: the GPU splat and the tiled estimator against the CPU
//! fixed-radius estimate, on the same photons, the same radius and the
//! G-buffer pixels read back from the GPU (METHOD.md §3: the same sum in a
//! different order).

use glam::Vec3;
use hikari_core::bsdf::ShadingFrame;
use hikari_core::bsdf::bump::BumpShadow;
use hikari_core::estimate::{FixedRadius, fixed_radius_radiance, fixed_radius_radiance_brdf, shading_normal_factor};
use hikari_core::material::Material;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::{DEFAULT_ALPHA, Schedules, pass_seed};
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::scene::Scene;
use hikari_gpu::gbuffer::geometric_normal::{pixel_kind, pixel_smooth_normal, unpack_geometric_normal};
use hikari_gpu::gbuffer::layer_texels::LayerTexels;
use hikari_gpu::readback::read_rgba32uint;
use hikari_gpu::test_support::test_context;
use hikari_gpu::tiled::Estimator;
use hikari_gpu::{GpuRenderer, GpuSettings};

const ESTIMATORS: [Estimator; 2] = [Estimator::Raster, Estimator::Tiled];

struct TwinStats {
    lit: usize,
    /// Pixels within `tolerance` (relative) of the CPU.
    within: usize,
    worst: f32,
    tolerance: f32,
    /// Surface pixels whose shading normal is bent (the G-buffer's
    /// position.w < 0): their photons weigh shading_normal_factor.
    bent: usize,
    /// Lit pixels a normal texture bends whose estimate the bump shadowing
    /// changes by more than 1%.
    shadowed: usize,
}

fn twin(scene_name: &str, photons: u64, normal_test: bool, estimator: Estimator) -> Option<(TwinStats, TwinStats)> {
    let mut scene = Scene::load(scene_name).unwrap();
    scene.camera = scene.camera.with_resolution(64, 64).unwrap();
    twin_scene(scene, photons, normal_test, estimator)
}

fn twin_scene(scene: Scene, photons: u64, normal_test: bool, estimator: Estimator) -> Option<(TwinStats, TwinStats)> {
    twin_pass(scene, photons, normal_test, 1, estimator)
}

/// Pass `pass` of progressive photon mapping (docs/progressive.md): the
/// renderer is built with pass 1's photons and radii, then given pass
/// `pass`'s photons and radii (`set_photons`), as `render --passes` does;
/// pass 1 is the seed's single pass.
fn twin_pass(
    scene: Scene,
    photons: u64,
    normal_test: bool,
    pass: u32,
    estimator: Estimator,
) -> Option<(TwinStats, TwinStats)> {
    let ctx = test_context("twin");
    // Splats add in the radiance format: f32, or f16 where the adapter
    // cannot blend f32 (Mesa's GL), whose running sums round to 2^-11 at
    // every add (measured there: worst pixel 1.6% on cornell-box, 3.2% on
    // cornell-caustic, at 20,000 photons).
    let tolerance = if ctx.float32_blend { 1e-4 } else { 1e-2 };
    let trace = |pass| {
        let seed = pass_seed(11, pass);
        trace_photons(&scene, &TraceSettings { photons, seed, ..Default::default() }, &Silent)
    };
    let first_settings = PhotonCpuSettings { normal_test, ..Default::default() };
    let (global, caustic) = first_settings.estimate_params(&scene);
    let schedules = Schedules::new([global.radius, caustic.radius, global.radius], DEFAULT_ALPHA);
    let settings = GpuSettings { estimator, ..GpuSettings::new(global, caustic) };
    let mut gpu = GpuRenderer::new(ctx, &scene, &trace(1), settings).expect("GPU renderer");
    let traced = trace(pass);
    let [r_global, r_caustic, _] = schedules.radii(pass);
    if pass > 1 {
        gpu.settings.global.radius = r_global;
        gpu.settings.caustic.radius = r_caustic;
        gpu.set_photons(&scene, &traced).expect("the pass's photons");
    }
    let cpu_settings = PhotonCpuSettings { radius: Some(r_global), caustic_radius: Some(r_caustic), ..first_settings };
    let cpu = PhotonCpuRenderer::new(&scene, &traced, &cpu_settings);
    gpu.render().expect("GPU frame");
    let t = &gpu.targets;
    let position = gpu.read(&t.gbuffer.position).unwrap();
    let normal = gpu.read(&t.gbuffer.normal).unwrap();
    let albedo = gpu.read(&t.gbuffer.albedo).unwrap();
    let indirect = gpu.read(&t.indirect).unwrap();
    // Where clear-coat, sheen or specular textures vary the material, the
    // pixel's texels as the G-buffer keeps them (layer_textures_reach_the_gbuffer
    // pins those to the CPU's): the gathers must weigh by that material.
    let layered = scene.texturing.as_ref().is_some_and(|t| t.materials.iter().flatten().any(|m| m.layers.any()));
    let layers = layered.then(|| read_rgba32uint(&gpu.ctx, &t.gbuffer.layers).unwrap());
    let caustic = gpu.read(&t.caustic).unwrap();

    let compare = |gpu_image: &[glam::Vec4], map, params: &FixedRadius| {
        let mut stats = TwinStats { lit: 0, within: 0, worst: 0.0, tolerance, bent: 0, shadowed: 0 };
        for i in 0..position.len() {
            if position[i].w == 0.0 || pixel_kind(albedo[i].w) != 0 {
                continue; // no surface, or not diffuse
            }
            let (x, n) = (position[i].truncate(), normal[i].truncate());
            // Where the shading normal is bent (position.w < 0), each
            // photon also weighs shading_normal_factor across the
            // geometric normal the G-buffer keeps, as photon-cpu's do.
            let bent = position[i].w < 0.0;
            stats.bent += bent as usize;
            let ng = unpack_geometric_normal(position[i].w, n);
            let across = |wi: Vec3| if bent { shading_normal_factor(wi, n, ng) } else { 1.0 };
            // Where a normal texture bent the normal, the diffuse lobes'
            // bump shadowing of the photon's side, from the smooth normal
            // the G-buffer keeps (as photon-cpu's gathers weigh it).
            let bump = pixel_smooth_normal(albedo[i].w).and_then(|unbent| BumpShadow::new(unbent, n));
            // The glTF BRDF weights each photon by f at its own direction
            // (the lobes the maps stand for); Lambertian surfaces by ρ/π.
            let index = scene.surfaces[normal[i].w as usize].material;
            let material = match (scene.materials[index as usize], &layers) {
                (Material::Pbr(bsdf), Some(words))
                    if scene.texturing.as_ref().unwrap().materials[index as usize]
                        .is_some_and(|t| t.layers.any() || t.coat_apart()) =>
                {
                    Material::Pbr(LayerTexels::unpack(words[i]).apply(bsdf))
                }
                (material, _) => material,
            };
            let frame = ShadingFrame::new(n);
            let estimate = |bump: Option<BumpShadow>| {
                let k = |wi: Vec3| bump.map_or(1.0, |b| b.term(wi));
                match material {
                    Material::Pbr(bsdf) if bsdf.is_glossy() => {
                        let wo = frame.to_local((scene.camera.position - x).normalize());
                        fixed_radius_radiance_brdf(map, x, n, params, |wi| {
                            bsdf.f_gathered_bumped(wo, frame.to_local(wi), k(wi)) * across(wi)
                        })
                    }
                    _ if bent => {
                        let lambert = albedo[i].truncate() / std::f32::consts::PI;
                        fixed_radius_radiance_brdf(map, x, n, params, |wi| lambert * across(wi) * k(wi))
                    }
                    _ => fixed_radius_radiance(map, None, x, n, albedo[i].truncate(), params),
                }
            };
            let want = estimate(bump);
            if bump.is_some() && (want - estimate(None)).abs().max_element() > 0.01 * want.max_element() {
                stats.shadowed += 1;
            }
            let got: Vec3 = gpu_image[i].truncate();
            if want.max_element() == 0.0 && got.max_element() == 0.0 {
                continue;
            }
            stats.lit += 1;
            let err = ((got - want).abs() / want.max(Vec3::splat(1e-30))).max_element();
            let err = if want.max_element() == 0.0 { f32::INFINITY } else { err };
            stats.within += (err < tolerance) as usize;
            stats.worst = stats.worst.max(err);
        }
        stats
    };
    Some((
        compare(&indirect, cpu.global_map(), &cpu.global_params),
        compare(&caustic, cpu.caustic_map(), &cpu.caustic_params),
    ))
}

fn assert_twin(name: &str, stats: &TwinStats, min_lit: usize) {
    eprintln!(
        "{name}: {} lit pixels ({} bent, {} bump-shadowed), {} within {:e}, worst relative error {:e}",
        stats.lit, stats.bent, stats.shadowed, stats.within, stats.tolerance, stats.worst
    );
    assert!(stats.lit >= min_lit, "{name}: only {} lit pixels", stats.lit);
    assert!(
        stats.within as f64 >= if stats.tolerance < 1e-3 { 0.999 } else { 0.95 } * stats.lit as f64,
        "{name}: {} of {} within {}",
        stats.within,
        stats.lit,
        stats.tolerance
    );
    let worst = if stats.tolerance < 1e-3 { 1e-2 } else { 5e-2 };
    assert!(stats.worst < worst, "{name}: worst relative error {}", stats.worst);
}

#[test]
fn gpu_splat_equals_cpu_estimate_on_cornell_box() {
    for estimator in ESTIMATORS {
        let (indirect, _) = twin("cornell-box", 20_000, false, estimator).expect("a twin");
        assert_twin(&format!("cornell-box indirect ({estimator:?})"), &indirect, 2000);
    }
}

#[test]
fn gpu_splat_equals_cpu_estimate_on_cornell_caustic() {
    for estimator in ESTIMATORS {
        let (indirect, caustic) = twin("cornell-caustic", 20_000, false, estimator).expect("a twin");
        assert_twin(&format!("cornell-caustic indirect ({estimator:?})"), &indirect, 2000);
        assert_twin(&format!("cornell-caustic caustic ({estimator:?})"), &caustic, 20);
    }
}

#[test]
fn gpu_splat_equals_cpu_estimate_with_normal_test() {
    for estimator in ESTIMATORS {
        let (indirect, _) = twin("cornell-box", 20_000, true, estimator).expect("a twin");
        assert_twin(&format!("cornell-box indirect, normal test ({estimator:?})"), &indirect, 2000);
    }
}

/// The eye close to the floor inside the box: photon spheres cross the near
/// plane and lie behind the eye, so the splat's conservative quads must still
/// cover every pixel each photon reaches.
#[test]
fn gpu_splat_equals_cpu_estimate_with_photons_around_the_eye() {
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = hikari_gpu::test_support::eye_near_the_floor(64);
    for estimator in ESTIMATORS {
        let (indirect, _) = twin_scene(scene.clone(), 20_000, false, estimator).expect("a twin");
        assert_twin(&format!("eye among photons ({estimator:?})"), &indirect, 2000);
    }
}

/// Progressive passes: pass i of the GPU splat is photon-cpu's estimate at
/// r_i on pass i's photons, pixel by pixel (the radii shrink to 86% and 71%
/// of the first by passes 3 and 10).
#[test]
fn gpu_passes_equal_cpu_estimates_at_their_radii() {
    // With the normal test too: `render --passes` turns it on (the guard
    // against light gathered across edges and corners).
    for (pass, normal_test) in [(3, false), (10, false), (10, true)] {
        let mut scene = Scene::load("cornell-caustic").unwrap();
        scene.camera = scene.camera.with_resolution(64, 64).unwrap();
        // The tiled estimator on the last of them.
        let estimator = if normal_test { Estimator::Tiled } else { Estimator::Raster };
        let (global, caustic) = twin_pass(scene, 20_000, normal_test, pass, estimator).expect("a twin");
        let name =
            format!("cornell-caustic pass {pass}{} ({estimator:?})", if normal_test { " (normal test)" } else { "" });
        assert_twin(&format!("{name}, global map"), &global, 2000);
        assert_twin(&format!("{name}, caustic map"), &caustic, 20);
    }
}

/// Photons from a sky and from an emissive mesh (traced from their discs
/// and triangles) splat to the CPU's estimate as any others do.
#[test]
fn gpu_splat_equals_cpu_estimate_under_a_sky_and_an_emissive_mesh() {
    use hikari_core::test_scenes::{cornell_quad_light, quad_lights_as_meshes};
    let scenes = [
        ("sky over a box", hikari_gpu::test_support::sky_over_a_box(64), 50_000, 500),
        ("emissive mesh", quad_lights_as_meshes(&cornell_quad_light(64)), 20_000, 2000),
    ];
    for (name, scene, photons, min_lit) in scenes {
        for estimator in ESTIMATORS {
            let (indirect, _) = twin_scene(scene.clone(), photons, false, estimator).expect("a twin");
            assert_twin(&format!("{name} indirect ({estimator:?})"), &indirect, min_lit);
        }
    }
}

/// The Cornell box with a white ball where cornell-caustic has its glass
/// one: the G-buffer draws the ball tessellated with smooth normals, so
/// its pixels' shading normals are bent off their facets' and each photon
/// also weighs shading_normal_factor (as photon-cpu's), in both estimators.
#[test]
fn gpu_estimates_on_bent_normals_equal_cpu_estimates() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-caustic.toml");
    let text = std::fs::read_to_string(path).unwrap();
    assert_eq!(text.matches("material = \"glass\"").count(), 1, "cornell-caustic changed: update this test");
    let text = text.replace("material = \"glass\"", "material = \"white\"");
    let mut scene = Scene::from_toml(&text, "cornell box with a white ball", None).unwrap();
    scene.camera = scene.camera.with_resolution(64, 64).unwrap();
    for estimator in ESTIMATORS {
        let (indirect, _) = twin_scene(scene.clone(), 20_000, false, estimator).expect("a twin");
        let name = format!("white ball indirect ({estimator:?})");
        assert_twin(&name, &indirect, 2000);
        assert!(indirect.bent > 200, "{name}: only {} bent pixels", indirect.bent);
    }
}

/// Normal-mapped floors (a texel tilting the normal 45°), one Lambertian
/// and one glossy, lit by a point light at a grazing angle and a white wall
/// it lights: each photon gathered there also weighs the bump shadowing of
/// its side, from the smooth normal the G-buffer keeps beside the kind, in
/// both estimators, as photon-cpu's gathers.
#[test]
fn gpu_estimates_on_normal_mapped_floors_equal_cpu_estimates() {
    let scene = hikari_core::test_scenes::gltf_textures::normal_mapped_floors("twin-normal-map", 64);
    for estimator in ESTIMATORS {
        let (indirect, _) = twin_scene(scene.clone(), 20_000, false, estimator).expect("a twin");
        let name = format!("normal-mapped floors indirect ({estimator:?})");
        assert_twin(&name, &indirect, 1500);
        assert!(indirect.shadowed > 300, "{name}: only {} pixels the bump shadowing changes", indirect.shadowed);
    }
}

/// The glTF BRDF: photons weighted by f for their own directions, on a box
/// of metals and dielectrics from roughness 0.1 to 1 (the smoother ones
/// gathering their diffuse lobe only), both estimators, with and without
/// the normal test, under a quad light and a sky.
#[test]
fn gpu_glossy_estimates_equal_cpu_estimates() {
    use hikari_core::test_scenes::{glossy_box, glossy_lights};
    for (light, text) in [("quad", glossy_lights::QUAD), ("sky", glossy_lights::SKY)] {
        for (estimator, normal_test) in [(Estimator::Raster, false), (Estimator::Tiled, true)] {
            let (indirect, caustic) = twin_scene(glossy_box(text, 64), 20_000, normal_test, estimator).expect("a twin");
            let name = format!("glossy box, {light} ({estimator:?}, normal test {normal_test})");
            assert_twin(&format!("{name} indirect"), &indirect, 2000);
            assert_twin(&format!("{name} caustic"), &caustic, 20);
        }
    }
}

/// Clear-coat, sheen and specular textures: the splat and the tiled
/// estimator weigh each photon by the material the pixel's layer texels
/// make (the G-buffer's fifth target), as photon-cpu's gathers do with it.
#[test]
fn gpu_estimates_on_layer_textures_equal_cpu_estimates() {
    use hikari_core::test_scenes::gltf_textures::layered_floor;
    for (estimator, normal_test) in [(Estimator::Raster, false), (Estimator::Tiled, true)] {
        let scene = layered_floor("twin-layered-floor", 64);
        let (indirect, _) = twin_scene(scene, 20_000, normal_test, estimator).expect("a twin");
        assert_twin(&format!("layered floor ({estimator:?}) indirect"), &indirect, 1500);
    }
}

/// estimate.wgsl's `shading_normal_factor` against the CPU's, on random
/// directions and normals bent up to 60° (the cap and the zeros included).
#[test]
fn wgsl_shading_normal_factor_matches_the_cpu() {
    use hikari_core::estimate::shading_normal_factor;
    use hikari_core::sampling::{Rng, uniform_sphere};
    let ctx = test_context("wgsl_shading_normal_factor_matches_the_cpu");
    let mut rng = Rng::for_item(23, 0);
    let n = 4096;
    let mut cases = Vec::new();
    let mut input = vec![0u32; n * 10];
    for item in input.chunks_mut(10) {
        let wi = uniform_sphere(rng.next_2d());
        let ng = uniform_sphere(rng.next_2d());
        let ns = (ng + uniform_sphere(rng.next_2d()) * rng.next_f32()).normalize();
        for (k, v) in [wi, ns, ng].iter().flat_map(|v| v.to_array()).enumerate() {
            item[k] = v.to_bits();
        }
        cases.push((wi, ns, ng));
    }
    let main = "let o = 10u * id.x; if (o >= arrayLength(&io)) { return; }\n\
                let v = array<f32, 9>(bitcast<f32>(io[o]), bitcast<f32>(io[o + 1u]), bitcast<f32>(io[o + 2u]),\n\
                    bitcast<f32>(io[o + 3u]), bitcast<f32>(io[o + 4u]), bitcast<f32>(io[o + 5u]),\n\
                    bitcast<f32>(io[o + 6u]), bitcast<f32>(io[o + 7u]), bitcast<f32>(io[o + 8u]));\n\
                let f = shading_normal_factor(vec3<f32>(v[0], v[1], v[2]), vec3<f32>(v[3], v[4], v[5]), vec3<f32>(v[6], v[7], v[8]));\n\
                io[o + 9u] = bitcast<u32>(f);";
    let gpu = hikari_gpu::test_support::run_kernel(&ctx, &[&hikari_gpu::wgsl::ESTIMATE], main, &input);
    let (mut zeros, mut capped) = (0, 0);
    for (out, (wi, ns, ng)) in gpu.chunks(10).zip(&cases) {
        let (got, want) = (f32::from_bits(out[9]), shading_normal_factor(*wi, *ns, *ng));
        assert!((got - want).abs() <= 1e-5 * want.max(1.0), "wi {wi} ns {ns} ng {ng}: {got} vs {want}");
        zeros += (want == 0.0) as usize;
        capped += (want == hikari_core::estimate::MAX_SHADING_NORMAL_FACTOR) as usize;
    }
    assert!(zeros > 100 && capped > 0, "{zeros} zeros, {capped} capped of {n}");
}

/// geometric_normal.wgsl's packing of the G-buffer's geometric normal, bit
/// for bit as its Rust twin packs it, on random normals bent up to 30° and
/// on unbent ones.
#[test]
fn wgsl_geometric_normal_packing_matches_the_cpu() {
    use hikari_core::sampling::{Rng, uniform_sphere};
    use hikari_gpu::gbuffer::geometric_normal::{GEOMETRIC_NORMAL, pack_geometric_normal};
    let ctx = test_context("wgsl_geometric_normal_packing_matches_the_cpu");
    let mut rng = Rng::for_item(29, 0);
    let mut cases = Vec::new();
    let mut input = vec![0u32; 4096 * 7];
    for (k, item) in input.chunks_mut(7).enumerate() {
        let ng = uniform_sphere(rng.next_2d());
        let ns = if k % 4 == 0 { ng } else { (ng + uniform_sphere(rng.next_2d()) * 0.5 * rng.next_f32()).normalize() };
        for (j, v) in [ns, ng].iter().flat_map(|v| v.to_array()).enumerate() {
            item[j] = v.to_bits();
        }
        cases.push((ns, ng));
    }
    let main = "let o = 7u * id.x; if (o >= arrayLength(&io)) { return; }\n\
                let ns = vec3<f32>(bitcast<f32>(io[o]), bitcast<f32>(io[o + 1u]), bitcast<f32>(io[o + 2u]));\n\
                let ng = vec3<f32>(bitcast<f32>(io[o + 3u]), bitcast<f32>(io[o + 4u]), bitcast<f32>(io[o + 5u]));\n\
                io[o + 6u] = bitcast<u32>(pack_geometric_normal(ns, ng));";
    let gpu = hikari_gpu::test_support::run_kernel(&ctx, &[&GEOMETRIC_NORMAL], main, &input);
    let mut bent = 0;
    for (out, (ns, ng)) in gpu.chunks(7).zip(&cases) {
        let (got, want) = (f32::from_bits(out[6]), pack_geometric_normal(*ns, *ng));
        assert_eq!(got, want, "ns {ns} ng {ng}");
        bent += (want < 0.0) as usize;
    }
    assert!(bent > 2000, "{bent} bent of {}", cases.len());
}

/// geometric_normal.wgsl's albedo.a, the kind and a normal-mapped point's
/// smooth normal, bit for bit as its Rust twin packs it, and read back the
/// same (to an ulp of the decode's normalize).
#[test]
fn wgsl_kind_packing_matches_the_cpu() {
    use hikari_core::sampling::{Rng, uniform_sphere};
    use hikari_gpu::gbuffer::geometric_normal::{GEOMETRIC_NORMAL, pack_kind};
    let ctx = test_context("wgsl_kind_packing_matches_the_cpu");
    let mut rng = Rng::for_item(31, 0);
    let mut cases = Vec::new();
    let mut input = vec![0u32; 4096 * 9];
    for (k, item) in input.chunks_mut(9).enumerate() {
        let n = uniform_sphere(rng.next_2d());
        let (kind, bumped) = (k as u32 % 5, k % 3 != 0);
        for (j, v) in n.to_array().iter().enumerate() {
            item[j] = v.to_bits();
        }
        item[3] = kind;
        item[4] = bumped as u32;
        cases.push((n, kind, bumped));
    }
    let main = "let o = 9u * id.x; if (o >= arrayLength(&io)) { return; }\n\
                let n = vec3<f32>(bitcast<f32>(io[o]), bitcast<f32>(io[o + 1u]), bitcast<f32>(io[o + 2u]));\n\
                let packed = pack_kind(io[o + 3u], n, io[o + 4u] != 0u);\n\
                let back = pixel_smooth_normal(packed);\n\
                io[o + 5u] = bitcast<u32>(packed);\n\
                io[o + 6u] = pixel_kind(packed);\n\
                io[o + 7u] = bitcast<u32>(back.x);\n\
                io[o + 8u] = bitcast<u32>(back.z);";
    let gpu = hikari_gpu::test_support::run_kernel(&ctx, &[&GEOMETRIC_NORMAL], main, &input);
    for (out, (n, kind, bumped)) in gpu.chunks(9).zip(&cases) {
        let packed = f32::from_bits(out[5]);
        assert_eq!(packed, pack_kind(*kind, *n, *bumped), "{n} kind {kind} bumped {bumped}");
        assert_eq!(out[6], *kind);
        let back = pixel_smooth_normal(packed).unwrap_or(Vec3::ZERO);
        // The decode's normalize may round differently by an ulp.
        let got = Vec3::new(f32::from_bits(out[7]), 0.0, f32::from_bits(out[8]));
        assert!((got - Vec3::new(back.x, 0.0, back.z)).abs().max_element() < 1e-6, "{n}: {got} vs {back}");
    }
}

/// layer_texels.wgsl's packing of the G-buffer's fifth target against its
/// Rust twin: the same four words (a field may differ by one step where
/// the two round a tie apart), and the same texels and coat normal read
/// back.
#[test]
fn wgsl_layer_texel_packing_matches_the_cpu() {
    use hikari_core::sampling::Rng;
    use hikari_gpu::gbuffer::layer_texels::{LAYER_TEXELS, LayerTexels};
    let ctx = test_context("wgsl_layer_texel_packing_matches_the_cpu");
    let mut rng = Rng::for_item(37, 0);
    let mut cases = Vec::new();
    let mut input = vec![0u32; 4096 * 30];
    for item in input.chunks_mut(30) {
        // The coat normal's x and y from −0.7 to 0.7; on the unbent normal or not.
        let t = LayerTexels::from_array(std::array::from_fn(|k| match k {
            0..10 => rng.next_f32(),
            10..12 => 1.4 * rng.next_f32() - 0.7,
            _ => (rng.next_f32() < 0.5) as u32 as f32,
        }));
        for (slot, v) in item.iter_mut().zip(t.to_array()) {
            *slot = v.to_bits();
        }
        cases.push(t);
    }
    let main = "let o = 30u * id.x; if (o >= arrayLength(&io)) { return; }\n\
                var v: array<f32, 13>;\n\
                for (var i = 0u; i < 13u; i++) { v[i] = bitcast<f32>(io[o + i]); }\n\
                let n = vec3<f32>(v[10], v[11], sqrt(max(1.0 - (v[10] * v[10] + v[11] * v[11]), 0.0)));\n\
                let t = LayerTexels(v[0], v[1], v[2], v[3], vec3<f32>(v[4], v[5], v[6]), vec3<f32>(v[7], v[8], v[9]), n,\n\
                    v[12] >= 0.5);\n\
                let words = pack_layer_texels(t);\n\
                for (var i = 0u; i < 4u; i++) { io[o + 13u + i] = words[i]; }\n\
                let b = unpack_layer_texels(words);\n\
                let back = array<f32, 13>(b.clearcoat, b.clearcoat_roughness, b.sheen_roughness, b.specular,\n\
                    b.sheen_color.x, b.sheen_color.y, b.sheen_color.z, b.specular_color.x, b.specular_color.y,\n\
                    b.specular_color.z, b.coat_normal.x, b.coat_normal.y, select(0.0, 1.0, b.coat_unbent));\n\
                for (var i = 0u; i < 13u; i++) { io[o + 17u + i] = bitcast<u32>(back[i]); }";
    let gpu = hikari_gpu::test_support::run_kernel(&ctx, &[&LAYER_TEXELS], main, &input);
    let fields = |w: [u32; 4]| {
        (0..4)
            .map(|k| w[0] >> (8 * k) & 255)
            .chain([w[1] & 0xffff, w[1] >> 16].map(|h| h as u16 as i16 as i32 as u32))
            .chain([w[2], w[3]].into_iter().flat_map(|c| [c & 1023, c >> 10 & 1023, c >> 20 & 1023, c >> 30]))
            .collect::<Vec<u32>>()
    };
    let mut exact = 0;
    for (out, t) in gpu.chunks(30).zip(&cases) {
        let words = [out[13], out[14], out[15], out[16]];
        let want = t.pack();
        exact += (words == want) as usize;
        for (got, want) in fields(words).into_iter().zip(fields(want)) {
            assert!((got as i32).abs_diff(want as i32) <= 1, "{t:?}: field {got} vs {want}");
        }
        for (k, want) in LayerTexels::unpack(words).to_array().into_iter().enumerate() {
            let got = f32::from_bits(out[17 + k]);
            assert!((got - want).abs() <= 1e-6, "{t:?}: texel {k} read back {got} vs {want}");
        }
    }
    assert!(exact >= cases.len() * 99 / 100, "{exact} of {} packed alike", cases.len());
}
