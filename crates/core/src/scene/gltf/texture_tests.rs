//! Textures and cut-outs of glTF files written here, through the loader
//! and the CPU renderers.

use super::export::{GltfBuilder, PbrMaterial, glb, looking, png};
use super::*;
use crate::geometry::Ray;
use crate::photon::{TraceSettings, trace_photons};
use crate::progress::Silent;
use crate::render::path::{PathSettings, radiance as path_radiance};
use crate::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use crate::sampling::Rng;
use crate::scene::Scene;
use crate::texture::srgb_to_linear;
use gltf::json::texture::WrappingMode;
use std::f32::consts::PI;

use crate::test_scenes::gltf_textures::{
    GREYS, checker_glb, cutout_glb, density_under_the_quad, folder, grey_checker, load, quad,
};

fn checker_scene(tag: &str) -> Scene {
    load(tag, &checker_glb())
}

fn mask_scene() -> Scene {
    load("mask", &cutout_glb())
}

/// The mean red of 16 vcm passes of 16×16 pixels seen from `eye` looking
/// at `target` (up `up`, 20° field).
fn vcm_mean(scene: &Scene, eye: Vec3, target: Vec3, up: Vec3) -> f32 {
    let mut viewed = scene.clone();
    viewed.camera = crate::camera::Camera::new(eye, target, up, 20.0, 16, 16).unwrap();
    let passes = 16;
    (1..=passes)
        .map(|pass| {
            let image = crate::render::vcm::render_pass(&viewed, &Default::default(), pass).unwrap().0;
            image.pixels.iter().map(|p| p.x).sum::<f32>() / image.pixels.len() as f32
        })
        .sum::<f32>()
        / passes as f32
}

/// Looking straight down −z at (x, y).
fn down_at(x: f32, y: f32) -> Ray {
    Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z)
}

fn albedo_at(scene: &Scene, x: f32, y: f32) -> f32 {
    let hit = scene.accel.intersect(&down_at(x, y)).expect("the quad");
    match *scene.material_at(&hit) {
        Material::Diffuse { albedo, .. } => {
            assert!(albedo.x == albedo.y && albedo.y == albedo.z, "{albedo}");
            albedo.x
        }
        other => panic!("{other:?}"),
    }
}

/// sRGB decoding, the image's top row at v = 0, bilinear filtering between
/// texel centres, REPEAT against CLAMP_TO_EDGE.
#[test]
fn a_checker_texture_is_looked_up_where_the_ray_hits() {
    let scene = checker_scene("checker-lookup");
    assert!(scene.notes.iter().all(|n| !n.contains("textur")), "{:?}", scene.notes);
    let texel = GREYS.map(|g| srgb_to_linear(g as f32 / 255.0));
    let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
    // Texel centres: (u, v) = (¼ or ¾, ¼ or ¾) is world (u, 1 − v).
    for (x, y, t) in [(0.25, 0.75, 0), (0.75, 0.75, 1), (0.25, 0.25, 2), (0.75, 0.25, 3)] {
        let a = albedo_at(&scene, x, y);
        assert!(close(a, texel[t]), "({x}, {y}): {a} vs texel {t} = {}", texel[t]);
    }
    assert!((texel[2] - 0.2158).abs() < 1e-3, "sRGB 128 is linear 0.216");
    // Halfway between the two top texel centres, and in the middle of all four.
    assert!(close(albedo_at(&scene, 0.5, 0.75), (texel[0] + texel[1]) / 2.0));
    assert!(close(albedo_at(&scene, 0.5, 0.5), texel.iter().sum::<f32>() / 4.0));
    // At u = 0 REPEAT blends with the texel across the edge (the right column).
    assert!(close(albedo_at(&scene, 0.001, 0.75), (texel[0] + texel[1]) / 2.0 + 0.002 * (texel[0] - texel[1])));
    // Second quad, u = 2·s: at s = 0.625 (u = 1.25) REPEAT would show texel
    // 0 again; CLAMP_TO_EDGE shows the last column (texel 1).
    assert!(close(albedo_at(&scene, 2.625, 0.875), texel[1]));
    assert!(close(albedo_at(&scene, 2.125, 0.875), texel[0]));
    assert!(close(albedo_at(&scene, 2.875, 0.125), texel[3]));
}

/// `KHR_texture_transform`, required by the file as Blender writes it, is
/// read: the checker is read at (1.5 − y, 1 − 2x) (offset (½, 1), rotation
/// π/2, scale (2, 1), worked by hand), so texel centres show where the
/// hand computation puts them, the image repeated twice across x; the
/// untransformed texel (at (x, 1 − y)) and the opposite rotation would
/// show others.
#[test]
fn a_texture_transform_moves_the_checker() {
    use crate::test_scenes::gltf_textures::transformed_checker_glb;
    let scene = load("checker-transform", &transformed_checker_glb());
    assert!(scene.notes.iter().all(|n| !n.contains("KHR_texture_transform")), "{:?}", scene.notes);
    let texel = GREYS.map(|g| srgb_to_linear(g as f32 / 255.0));
    // (x, y) → image (u', v') → texel (0: top-left, 1: top-right, 2, 3).
    for (x, y, t) in [
        (0.125, 0.25, 2), // (1.25, 0.75) → (0.25, 0.75)
        (0.375, 0.75, 1), // (0.75, 0.25)
        (0.125, 0.75, 3), // (0.75, 0.75)
        (0.375, 0.25, 0), // (1.25, 0.25) → (0.25, 0.25)
        (0.625, 0.25, 2), // (1.25, −0.25) → (0.25, 0.75)
        (0.875, 0.75, 1), // (0.75, −0.75) → (0.75, 0.25)
    ] {
        let a = albedo_at(&scene, x, y);
        assert!((a - texel[t]).abs() < 1e-5, "({x}, {y}): {a} vs texel {t} = {}", texel[t]);
    }
}

/// Under the white sky (radiance 1) a Lambertian point shows its albedo:
/// the texel, in the path tracer and in photon-cpu.
#[test]
fn a_checker_texture_shows_in_the_renderers() {
    let scene = checker_scene("checker-render");
    let texel = GREYS.map(|g| srgb_to_linear(g as f32 / 255.0));
    let settings = PathSettings { spp: 1, ..Default::default() };
    let traced = trace_photons(&scene, &TraceSettings { photons: 2_000, ..Default::default() }, &Silent);
    let photon_settings = PhotonCpuSettings { area_light_samples: 64, ..Default::default() };
    let renderer = PhotonCpuRenderer::new(&scene, &traced, &photon_settings);
    let mut rng = Rng::for_item(7, 0);
    for (x, y, t) in [(0.25, 0.75, 0), (0.75, 0.75, 1), (0.25, 0.25, 2), (2.625, 0.875, 1)] {
        let n = 4_000;
        let path: f32 =
            (0..n).map(|_| path_radiance(&scene, down_at(x, y), &settings, &mut rng).x).sum::<f32>() / n as f32;
        let photon: f32 = (0..200).map(|_| renderer.radiance(&down_at(x, y), 0, &mut rng).x).sum::<f32>() / 200.0;
        eprintln!("({x}, {y}): texel {}, path {path}, photon-cpu {photon}", texel[t]);
        for (name, l) in [("path", path), ("photon-cpu", photon)] {
            assert!((l - texel[t]).abs() < 0.03 * texel[t] + 1e-6, "{name} at ({x}, {y}): {l} vs {}", texel[t]);
        }
    }
}

/// B is metallic and G roughness, each times its factor; R is ignored.
#[test]
fn metallic_roughness_texture_channels_reach_the_brdf() {
    let mut b = GltfBuilder::new();
    let image = b.image(&png(1, 1, &[255, 128, 51, 255]), "image/png");
    let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
    let m = b.material(&PbrMaterial {
        metallic: 1.0,
        roughness: 0.5,
        base_color: Vec3::splat(0.8),
        metallic_roughness_texture: Some(t),
        ..Default::default()
    });
    let node = quad(&mut b, Vec3::new(0.0, 1.0, 0.0), Vec3::X, -Vec3::Y, 1.0, m);
    let scene = load("mr", &b.to_glb(vec![node]));
    let hit = scene.accel.intersect(&down_at(0.5, 0.5)).unwrap();
    let Material::Pbr(bsdf) = *scene.material_at(&hit) else { panic!("{:?}", scene.material_at(&hit)) };
    assert!((bsdf.metallic - 0.2).abs() < 1e-6, "metallic 1 × B (51/255): {}", bsdf.metallic);
    assert!((bsdf.roughness - 0.5 * 128.0 / 255.0).abs() < 1e-6, "roughness 0.5 × G (linear): {}", bsdf.roughness);
    assert_eq!(bsdf.base_color, Vec3::splat(0.8));
    // The factors alone, as the GPU renderer uploads them.
    let Material::Pbr(factors) = *scene.material(&hit) else { panic!() };
    assert_eq!((factors.metallic, factors.roughness), (1.0, 0.5));
}

#[test]
fn a_cutout_lets_light_through_where_alpha_is_below_the_cutoff() {
    let scene = mask_scene();
    assert!(scene.notes.iter().all(|n| !n.contains("opaque")), "{:?}", scene.notes);
    let lit = 0.5 / PI * 2.0;
    let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, ..Default::default() }, &Silent);
    let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    let settings = PathSettings { spp: 1, ..Default::default() };
    let mut rng = Rng::for_item(3, 0);
    let look = |x: f32, z: f32| Ray::new(Vec3::new(x, 2.0, z), -Vec3::Y);
    // Texel centres: opaque (alpha 1) at (u, v) = (¼, ¼) and (¾, ¾), open at the others.
    for (u, v, open) in [(0.25, 0.25, false), (0.75, 0.25, true), (0.25, 0.75, true), (0.75, 0.75, false)] {
        let (x, z) = (u - 0.5, v - 0.5);
        let expected = if open { lit } else { 0.0 };
        let path = path_radiance(&scene, look(x, z), &settings, &mut rng).x;
        let photon = renderer.radiance(&look(x, z), 0, &mut rng).x;
        assert!((path - expected).abs() < 1e-5 && (photon - expected).abs() < 1e-5, "({u}, {v}): {path} {photon}");
        // Shadow rays alone: from the floor up to the sun.
        let up = Ray::new(Vec3::new(x, 0.0, z), Vec3::Y);
        assert_eq!(scene.accel.occluded(&up), !open, "({u}, {v})");
        // And in packets (the path tracer's closest hits), lane by lane.
        let lanes = [Some(up), None, Some(look(x, z)), Some(up), None, None, None, Some(up)];
        let mut hits = [None; 8];
        scene.accel.intersect_packet(&lanes, &mut hits);
        let found = hits.map(|h| h.is_some());
        assert_eq!(found, [!open, false, true, !open, false, false, false, !open], "({u}, {v})");
        assert_eq!(
            hits[2].map(|h| h.point.y.to_bits()),
            scene.accel.intersect(&look(x, z)).map(|h| h.point.y.to_bits())
        );
    }
    // Over a grid of the quad the lit fraction is exactly ½ (bilinear alpha
    // below ½ on half of it, by the checker's symmetry).
    let n = 32;
    let (mut path_sum, mut photon_sum) = (0.0, 0.0);
    for i in 0..n * n {
        let (x, z) = (((i % n) as f32 + 0.5) / n as f32 - 0.5, ((i / n) as f32 + 0.5) / n as f32 - 0.5);
        path_sum += path_radiance(&scene, look(x, z), &settings, &mut rng).x;
        photon_sum += renderer.radiance(&look(x, z), 0, &mut rng).x;
    }
    let (path, photon) = (path_sum / (n * n) as f32 / lit, photon_sum / (n * n) as f32 / lit);
    assert!((path - 0.5).abs() < 1e-4 && (photon - 0.5).abs() < 1e-4, "lit fraction: path {path}, photon-cpu {photon}");
    // Photons: the density on the floor under the quad is half that beside it.
    let (under, beside, ratio) = density_under_the_quad(&traced.global);
    eprintln!("photons under the cut-out {under}, beside {beside}: density ratio {ratio}");
    assert!((ratio - 0.5).abs() < 0.05, "{ratio}");
}

/// `alphaMode` BLEND is stochastic transparency: a black pane of alpha 0.4
/// over a lit floor stops 40% of the sun's light (shadow rays, photons) and
/// of the eye's rays, so from above the floor under it shows (1 − 0.4)² of
/// the lit floor in path, photon-cpu and vcm; the packet traversals decide
/// as single rays do, to the bit.
#[test]
fn a_blend_surface_lets_through_one_minus_alpha_of_light_and_eye() {
    use crate::test_scenes::gltf_textures::blend_glb;
    let alpha = 0.4;
    let scene = load("blend", &blend_glb(alpha));
    assert!(scene.notes.iter().all(|n| !n.contains("BLEND")), "{:?}", scene.notes);
    let lit = 0.5 / PI * 2.0;
    let mut rng = Rng::for_item(11, 0);
    let under = |rng: &mut Rng| {
        let p = rng.next_2d() - 0.5;
        (p.x, p.y)
    };
    // Shadow rays from the floor under the pane toward the sun, single and packed.
    let n = 20_000;
    let mut blocked = 0;
    for _ in 0..n / 8 {
        let rays: [Ray; 8] = std::array::from_fn(|_| {
            let (x, z) = under(&mut rng);
            Ray::new(Vec3::new(x, 0.0, z), Vec3::Y)
        });
        let lanes = crate::geometry::packet::RayLanes::gather(&rays.map(Some));
        let packed = scene.accel.occluded_packet(&lanes);
        let single = (0..8).fold(0u32, |bits, l| bits | (scene.accel.occluded(&rays[l]) as u32) << l);
        assert_eq!(packed, single);
        let mut hits = [None; 8];
        scene.accel.intersect_packet(&rays.map(Some), &mut hits);
        for (hit, ray) in hits.iter().zip(&rays) {
            assert_eq!(hit.map(|h| h.t.to_bits()), scene.accel.intersect(ray).map(|h| h.t.to_bits()));
        }
        blocked += single.count_ones();
    }
    let blocked = blocked as f64 / n as f64;
    eprintln!("BLEND alpha {alpha}: {blocked} of shadow rays blocked");
    assert!((blocked - alpha as f64).abs() < 0.015, "{blocked}");
    // From above: each renderer's mean over the pane.
    let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, ..Default::default() }, &Silent);
    let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    let settings = PathSettings { spp: 1, ..Default::default() };
    let look = |rng: &mut Rng| {
        let (x, z) = under(rng);
        Ray::new(Vec3::new(x, 2.0, z), -Vec3::Y)
    };
    let expected = (1.0 - alpha) * (1.0 - alpha) * lit;
    let m = 20_000;
    let mean = |f: &mut dyn FnMut(&mut Rng) -> f32, rng: &mut Rng| (0..m).map(|_| f(rng)).sum::<f32>() / m as f32;
    let path = mean(&mut |rng| path_radiance(&scene, look(rng), &settings, rng).x, &mut rng);
    let photon = mean(&mut |rng| renderer.radiance(&look(rng), 0, rng).x, &mut rng);
    // vcm: 16×16 pixels looking down at the pane's middle, all under it.
    let vcm = vcm_mean(&scene, Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, Vec3::Z);
    eprintln!(
        "BLEND from above over (1 − α)² lit: path {}, photon-cpu {}, vcm {}",
        path / expected,
        photon / expected,
        vcm / expected
    );
    for (name, l) in [("path", path), ("photon-cpu", photon), ("vcm", vcm)] {
        assert!((l / expected - 1.0).abs() < 0.03, "{name}: {l} against {expected}");
    }
    // Photons: the density under the pane is 1 − α of that beside it.
    let (below, beside, ratio) = density_under_the_quad(&traced.global);
    eprintln!("photons under the BLEND pane {below}, beside {beside}: density ratio {ratio}");
    assert!((ratio - (1.0 - alpha)).abs() < 0.03, "{ratio}");
}

/// `KHR_materials_transmission` below 1 is drawn per hit: a pane letting
/// 30% through as white glass over a black floor under a sun shows, from
/// above, 70% of a white Lambertian's radiance in path, photon-cpu and vcm
/// (the glass shows the black sky and floor); a grey floor under it gets
/// 0.3 × (1 − F(0)) of the sun's photons straight through; and the photons stored on the
/// pane (on its base's draws only) carry the sun's whole power there, as
/// on a pane of transmission 0 (each weighted by 1 / 0.7), where unweighted
/// they would carry 70% of it; none is stored on its underside, which
/// photon-cpu shows by a sampled bounce, as bright as vcm within 8%.
#[test]
fn a_partly_transmissive_pane_is_glass_and_base_in_proportion() {
    use crate::test_scenes::gltf_textures::mixed_pane_glb;
    let share = 0.3;
    let scene = load("mixed-pane", &mixed_pane_glb(share, 0.0));
    // Every renderer draws the mix (the GPU's test: gpu/tests/textures.rs): nothing to note.
    assert!(!scene.notes.iter().any(|n| n.contains("transmission")), "{:?}", scene.notes);
    assert!(matches!(scene.materials[1], Material::Pbr(_)), "{:?}", scene.materials[1]);
    let opaque = load("mixed-pane-0", &mixed_pane_glb(0.0, 0.0));
    assert!(opaque.texturing.is_none() && !opaque.notes.iter().any(|n| n.contains("light through")));
    let lit = 2.0 / PI;
    let expected = (1.0 - share) * lit;
    let mut rng = Rng::for_item(12, 0);
    let look = |rng: &mut Rng| {
        let p = rng.next_2d() - 0.5;
        Ray::new(Vec3::new(p.x, 2.0, p.y), -Vec3::Y)
    };
    let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, ..Default::default() }, &Silent);
    let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    let settings = PathSettings { spp: 1, ..Default::default() };
    let m = 20_000;
    let mean = |f: &mut dyn FnMut(&mut Rng) -> f32, rng: &mut Rng| (0..m).map(|_| f(rng)).sum::<f32>() / m as f32;
    let path = mean(&mut |rng| path_radiance(&scene, look(rng), &settings, rng).x, &mut rng);
    let photon = mean(&mut |rng| renderer.radiance(&look(rng), 0, rng).x, &mut rng);
    let vcm = vcm_mean(&scene, Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::Z);
    eprintln!(
        "transmission {share} from above over (1 − share) lit: path {}, photon-cpu {}, vcm {}",
        path / expected,
        photon / expected,
        vcm / expected
    );
    for (name, l) in [("path", path), ("photon-cpu", photon), ("vcm", vcm)] {
        assert!((l / expected - 1.0).abs() < 0.03, "{name}: {l} against {expected}");
    }
    // Photons straight from the sun or through the glass on a grey floor:
    // under the pane (|x|, |z| < 0.75) and beside it.
    let grey = load("mixed-pane-grey", &mixed_pane_glb(share, 0.2));
    let grey_traced = trace_photons(&grey, &TraceSettings { photons: 1_000_000, ..Default::default() }, &Silent);
    let on_floor = |inner: f32, outer: f32| {
        let r = |p: &&crate::photon::Photon| p.position[0].abs().max(p.position[2].abs());
        let floor = grey_traced.global.iter().filter(|p| p.position[1].abs() < 1e-3);
        let first = floor.filter(|p| p.class() != crate::photon::PathClass::Indirect);
        first.filter(|p| (inner..outer).contains(&r(p))).map(|p| p.power_in_units().x).sum::<f32>()
            / (4.0 * (outer * outer - inner * inner))
    };
    let through = on_floor(0.0, 0.75) / on_floor(1.5, 3.0);
    eprintln!("photons under the pane over beside it: {through} (want {})", share * 0.96);
    assert!((through / (share * 0.96) - 1.0).abs() < 0.04, "{through}");
    // Behind the pane (its underside, lit by the grey floor) no photon is
    // stored: behind a partly transmissive surface is inside its body,
    // where trapped light would leak onto what the body touches; photon-cpu
    // shows it by a sampled bounce, as bright as path's.
    let underneath = grey_traced.global.iter().filter(|p| (p.position[1] - 1.0).abs() < 1e-3);
    assert_eq!(underneath.filter(|p| p.direction().y > 0.0).count(), 0);
    let grey_renderer =
        PhotonCpuRenderer::new(&grey, &grey_traced, &PhotonCpuSettings { spp: 1, ..Default::default() });
    // The middle of the underside (|x|, |z| < 0.08), which vcm's camera below sees.
    let up = |rng: &mut Rng| {
        let p = 0.16 * (rng.next_2d() - 0.5);
        Ray::new(Vec3::new(p.x, 0.5, p.y), Vec3::Y)
    };
    // vcm is the reference here (0.0500; by hand, the light the floor sends
    // up there makes 0.0501 before interreflections, which add a few per
    // cent; photon-cpu 0.0535): path cannot find the sun's light through
    // the glass share onto the floor (a delta light through a smooth
    // interface), which the underside reflects.
    let photon_below = mean(&mut |rng| grey_renderer.radiance(&up(rng), 0, rng).x, &mut rng);
    let vcm_below = vcm_mean(&grey, Vec3::new(0.0, 0.5, 0.0), Vec3::Y, Vec3::Z);
    eprintln!("the pane from below: vcm {vcm_below}, photon-cpu {photon_below}");
    assert!((photon_below / vcm_below - 1.0).abs() < 0.08, "{photon_below} against {vcm_below}");
    // Photons on the pane: the sun's power whatever its transmission.
    let on_pane = |traced: &crate::photon::TracedPhotons| {
        let pane = traced.global.iter().filter(|p| (p.position[1] - 1.0).abs() < 1e-3);
        pane.map(|p| p.power_in_units().x).sum::<f32>() / 4.0
    };
    let opaque_traced = trace_photons(&opaque, &TraceSettings { photons: 200_000, ..Default::default() }, &Silent);
    let stored = on_pane(&traced) / on_pane(&opaque_traced);
    eprintln!("power stored on the pane over that on an opaque pane: {stored}");
    assert!((stored - 1.0).abs() < 0.03, "{stored}");
}

/// `transmissionTexture`'s R (linear) multiplies the factor: over a
/// texture of R = 128/255 the glass is drawn at half the hits (sRGB
/// decoding would make it 21%), and over one of R = 0 never, though the
/// factor is 1.
#[test]
fn a_transmission_texture_scales_the_share_per_point() {
    let mut b = GltfBuilder::new();
    let mut nodes = Vec::new();
    for (i, red) in [128u8, 0].into_iter().enumerate() {
        let image = b.image(&png(1, 1, &[red, 255, 255, 255]), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let m = b.material(&PbrMaterial {
            glass_ior: Some(1.5),
            roughness: 0.2,
            transmission_texture: Some(t),
            ..Default::default()
        });
        nodes.push(quad(&mut b, Vec3::new(2.0 * i as f32, 1.0, 0.0), Vec3::X, -Vec3::Y, 1.0, m));
    }
    let scene = load("transmission-texture", &b.to_glb(nodes));
    assert!(!scene.notes.iter().any(|n| n.contains("not read")), "{:?}", scene.notes);
    let mut rng = Rng::for_item(3, 0);
    let glass_share = |x0: f32, rng: &mut Rng| {
        let n = 4_000;
        let glass = (0..n)
            .filter(|_| {
                let p = rng.next_2d();
                let hit = scene.accel.intersect(&down_at(x0 + p.x, p.y)).expect("the quad");
                matches!(*scene.material_at(&hit), Material::Glass(_))
            })
            .count();
        glass as f32 / n as f32
    };
    let (half, none) = (glass_share(0.0, &mut rng), glass_share(2.0, &mut rng));
    eprintln!("glass drawn under R = 128/255: {half}; under R = 0: {none}");
    assert!((half - 128.0 / 255.0).abs() < 0.03, "{half}");
    assert_eq!(none, 0.0);
}

/// Drawing a transmission mix: glass with probability T·(1 − m), of the
/// base's colour, roughness and IOR; else the base with metallic
/// m / (1 − T·(1 − m)), so that the mean is (1 − T)(1 − m) dielectric,
/// T(1 − m) glass and m metal, as the extension's layering has them.
#[test]
fn a_transmission_mix_draws_glass_and_base_by_share() {
    use crate::bsdf::{Bsdf, dielectric::Dielectric};
    use crate::texture::{MaterialTextures, Texturing, Transmission};
    let (share, metallic) = (0.4, 0.25);
    let glass = Dielectric { ior: 1.4, roughness: 0.3, tint: Vec3::new(0.9, 0.8, 0.7), absorption: Vec3::ZERO };
    let base = Material::Pbr(Bsdf::new(glass.tint, metallic, 0.3, 1.0).with_ior(1.4));
    let textures = MaterialTextures {
        alpha_factor: 1.0,
        transmission: Some(Transmission { factor: share, texture: None, ior: 1.4 }),
        ..Default::default()
    };
    let texturing = Texturing { materials: vec![Some(textures)], ..Default::default() };
    let n = 10_000;
    let mut glasses = 0;
    for i in 0..n {
        let u = (i as f32 + 0.5) / n as f32;
        let drawn = texturing.apply(base, 0, 0, glam::Vec2::ZERO, || u);
        let p_glass = share * (1.0 - metallic);
        match *drawn.material {
            Material::Glass(g) => {
                glasses += 1;
                assert_eq!(g, glass);
                assert!((drawn.probability - p_glass).abs() < 1e-6);
            }
            Material::Pbr(b) => {
                assert!((b.metallic - metallic / (1.0 - p_glass)).abs() < 1e-6, "{}", b.metallic);
                assert!((drawn.probability - (1.0 - p_glass)).abs() < 1e-6);
                assert!((drawn.probability * b.metallic - metallic).abs() < 1e-6);
            }
            other => panic!("{other:?}"),
        }
        assert!(drawn.other.is_some_and(|o| o != *drawn.material));
    }
    assert_eq!(glasses, (n as f32 * share * (1.0 - metallic)).round() as usize);
    // A photon stored on the base's draw stands for the glass's too.
    let drawn = texturing.apply(base, 0, 0, glam::Vec2::ZERO, || 0.99);
    let stores = |m: &Material| matches!(m, Material::Pbr(_));
    assert!((drawn.store_weight(stores) - 1.0 / (1.0 - share * (1.0 - metallic))).abs() < 1e-5);
}

/// A texture that reads an image file that is not there, or bytes that
/// are no PNG, is an error naming `images[0]`.
#[test]
fn missing_and_corrupt_images_are_located_errors() {
    let mut b = GltfBuilder::new();
    let image = b.image(b"not a png at all", "image/png");
    let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
    let m = b.material(&PbrMaterial { base_color_texture: Some(t), ..Default::default() });
    let node = quad(&mut b, Vec3::ZERO, Vec3::X, Vec3::Y, 1.0, m);
    let (root, bin) = b.finish(vec![node]);
    let dir = folder("broken-images");
    let load_err = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = Scene::load(path.to_str().unwrap()).err().expect("an error").to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        e
    };
    let e = load_err("corrupt.glb", &glb(&root, bin.clone()));
    for w in ["images[0]", "materials[0].pbrMetallicRoughness.baseColorTexture", "bufferViews["] {
        assert!(e.contains(w), "`{e}` does not say `{w}`");
    }
    let mut r = root.clone();
    r.images[0].buffer_view = None;
    r.images[0].uri = Some("missing.png".into());
    let e = load_err("missing.glb", &glb(&r, bin));
    for w in ["images[0]", "missing.png"] {
        assert!(e.contains(w), "`{e}` does not say `{w}`");
    }
}

/// An emissive texture: the eye sees the texel × factor; the light (its
/// power, photons and light sampling) emits the texture's mean.
#[test]
fn an_emissive_texture_varies_the_radiance_seen() {
    let mut b = GltfBuilder::new();
    let image = b.image(&grey_checker([255; 4]), "image/png");
    let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
    let m = b.material(&PbrMaterial { emission: Vec3::splat(4.0), emissive_texture: Some(t), ..Default::default() });
    let node = quad(&mut b, Vec3::new(0.0, 1.0, 0.0), Vec3::X, -Vec3::Y, 1.0, m);
    let scene = load("emissive", &b.to_glb(vec![node]));
    let texel = GREYS.map(|g| srgb_to_linear(g as f32 / 255.0));
    let mean = texel.iter().sum::<f32>() / 4.0;
    assert!(matches!(scene.lights[0], Light::Mesh(_)), "{:?}", scene.lights);
    assert!((scene.lights[0].emission().x - 4.0 * mean).abs() < 1e-5, "{:?}", scene.lights[0].emission());
    for (x, y, t) in [(0.25, 0.75, 0), (0.75, 0.75, 1), (0.25, 0.25, 2), (0.75, 0.25, 3)] {
        let hit = scene.accel.intersect(&down_at(x, y)).unwrap();
        let le = scene.emitted_radiance(&hit, -Vec3::Z).unwrap();
        assert!((le - Vec3::splat(4.0 * texel[t])).abs().max_element() < 1e-4, "({x}, {y}): {le}");
    }
}

/// A matte grey material (base 0.5, no specular lobe) whose normal
/// texture is one `texel`, at `scale`.
fn grey_normal_mapped(b: &mut GltfBuilder, texel: [u8; 4], scale: f32) -> gltf::json::Index<gltf::json::Material> {
    let image = b.image(&png(1, 1, &texel), "image/png");
    let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
    b.material(&PbrMaterial {
        base_color: Vec3::splat(0.5),
        specular: 0.0,
        normal_texture: Some((t, scale)),
        ..Default::default()
    })
}

/// A normal texture tilting the normal 45° toward +u (world +X) on a floor
/// under a sun 45° from the zenith toward +X: the path tracer shades with
/// the bent normal, which faces the sun (1/cos 45° more light than flat; a
/// tangent of the wrong sign would turn it away, no light), `scale` 0
/// flattens it back, and photon-cpu and vcm shade with the same bent
/// normal (photon-cpu's direct light; vcm's mean over its estimates).
#[test]
fn a_normal_texture_bends_every_cpu_renderers_normals() {
    use crate::render::path::radiance as path_radiance;
    // (sin 45°, 0, cos 45°) as 8-bit 2n − 1: 218, 128, 218.
    let texel = [218u8, 128, 218, 255];
    let decoded = glam::Vec3::new(218.0, 128.0, 218.0) / 255.0 * 2.0 - 1.0;
    let floor_with = |scale: f32, tag: &str| {
        let mut b = GltfBuilder::new();
        let m = grey_normal_mapped(&mut b, texel, scale);
        let floor = quad(&mut b, Vec3::new(-2.0, 0.0, 2.0), 4.0 * Vec3::X, -4.0 * Vec3::Z, 1.0, m);
        use gltf::json::extensions::scene::khr_lights_punctual::Type;
        let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
        let toward = Vec3::new(-1.0, -1.0, 0.0).normalize();
        let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(toward, Vec3::Z)));
        load(tag, &b.to_glb(vec![floor, sun]))
    };
    let look = Ray::new(Vec3::new(0.3, 1.0, 0.2), -Vec3::Y);
    let settings = PathSettings { spp: 1, ..Default::default() };
    let mut rng = Rng::for_item(2, 0);
    // ρ/π·E·cos 45° on the flat floor.
    let flat = 0.5 / PI * 2.0 * std::f32::consts::FRAC_1_SQRT_2;
    // Direct light only along one sample: the sun is a delta light, and the
    // floor alone reflects no indirect light. The bent normal (x, z, y) of
    // the texel (u along +X, v along −Z: the image's up, −v, is +Z)
    // against the sun's (1, 1, 0)/√2.
    let bent_floor = floor_with(1.0, "normal-1");
    let bent = path_radiance(&bent_floor, look, &settings, &mut rng).x;
    let n = Vec3::new(decoded.x, decoded.z, decoded.y).normalize();
    let sun = Vec3::new(1.0, 1.0, 0.0).normalize();
    // Times Cycles' bump shadowing of the sun's direction (bsdf::bump), of
    // the bend as the scene makes it (within 1° of `n`: the shadowing, unlike
    // n·sun at its maximum, feels that).
    let hit = bent_floor.accel.intersect(&look).expect("the floor");
    let shaded = bent_floor.shading_normal_at(&hit, look.dir);
    eprintln!("bent normal {shaded} against the texel's {n}");
    let term = crate::bsdf::bump::BumpShadow::new(hit.shading_normal, shaded).unwrap().term(sun);
    let want = 0.5 / PI * 2.0 * n.dot(sun) * term;
    assert!(want > 1.3 * flat, "the texel faces the sun");
    assert!((bent - want).abs() < 1e-4 * want, "bent: {bent} vs {want}");
    let unbent = path_radiance(&floor_with(0.0, "normal-0"), look, &settings, &mut rng).x;
    assert!((unbent - flat).abs() < 1e-4 * flat, "scale 0: {unbent} vs {flat}");
    let scene = floor_with(1.0, "normal-photon");
    let traced = trace_photons(&scene, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
    let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings::default());
    let photon = renderer.radiance(&look, 0, &mut rng).x;
    assert!((photon - want).abs() < 1e-4 * want, "photon-cpu: {photon} vs {want}");
    // vcm, looking straight down at the middle of the floor (16×16 pixels,
    // all floor): every pixel's value is `want`; its passes' mean is within
    // noise of it, far from the flat floor's.
    let mut scene = floor_with(1.0, "normal-vcm");
    scene.camera = crate::camera::Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, -Vec3::Z, 60.0, 16, 16).unwrap();
    let settings = crate::render::vcm::VcmSettings::default();
    let passes = 8;
    let mean = (1..=passes)
        .map(|pass| {
            let image = crate::render::vcm::render_pass(&scene, &settings, pass).unwrap().0;
            image.pixels.iter().map(|p| p.x).sum::<f32>() / image.pixels.len() as f32
        })
        .sum::<f32>()
        / passes as f32;
    assert!((mean - want).abs() < 0.03 * want, "vcm: {mean} vs {want} (flat {flat})");
}

/// The frame a normal texture is read in, on a floor (normal +Y; u along
/// +X, v along −Z, so the image's up, −v, is +Z) under a sun from
/// (1, 2, 0.5): without `TANGENT` MikkTSpace's, tangent +X and up +Z; with
/// the file's `TANGENT` (0, 0, 1, ±1) the tangent +Z and the up
/// ±(+Y × +Z) = ±X, which the path tracer's light must follow. The texel
/// tilts both ways, so a wrong tangent, side or up changes the light.
#[test]
fn the_files_tangents_set_the_normal_textures_frame() {
    use crate::render::path::radiance as path_radiance;
    let texel = [191u8, 160, 218, 255];
    let d = glam::Vec3::new(191.0, 160.0, 218.0) / 255.0 * 2.0 - 1.0;
    let sun = Vec3::new(1.0, 2.0, 0.5).normalize();
    let floor_with = |tangent: Option<glam::Vec4>, tag: &str| {
        let mut b = GltfBuilder::new();
        let m = grey_normal_mapped(&mut b, texel, 1.0);
        let origin = Vec3::new(-2.0, 0.0, 2.0);
        let positions =
            [origin, origin + 4.0 * Vec3::X, origin + 4.0 * Vec3::X - 4.0 * Vec3::Z, origin - 4.0 * Vec3::Z];
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        let tangents = tangent.map(|t| [t; 4]);
        let normals = [Vec3::Y; 4];
        let mesh = b.tangent_mesh(
            &positions,
            Some(&normals),
            Some(&uvs),
            tangents.as_ref().map(|t| &t[..]),
            Some(&[0, 1, 2, 0, 2, 3]),
            Some(m),
        );
        let floor = b.node(gltf::json::Node { mesh: Some(mesh), ..Default::default() });
        use gltf::json::extensions::scene::khr_lights_punctual::Type;
        let light = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
        let light = b.node(GltfBuilder::light_node(light, Vec3::ZERO, looking(-sun, Vec3::Z)));
        load(tag, &b.to_glb(vec![floor, light]))
    };
    let look = Ray::new(Vec3::new(0.3, 1.0, 0.2), -Vec3::Y);
    let settings = PathSettings { spp: 1, ..Default::default() };
    let mut rng = Rng::for_item(2, 0);
    let cases = [
        (None, Vec3::new(d.x, d.z, d.y)),
        (Some(glam::Vec4::new(0.0, 0.0, 1.0, 1.0)), Vec3::new(d.y, d.z, d.x)),
        (Some(glam::Vec4::new(0.0, 0.0, 1.0, -1.0)), Vec3::new(-d.y, d.z, d.x)),
    ];
    let mut seen = Vec::new();
    for (i, (tangent, n)) in cases.into_iter().enumerate() {
        let got = path_radiance(&floor_with(tangent, &format!("tangent-{i}")), look, &settings, &mut rng).x;
        let term = crate::bsdf::bump::BumpShadow::new(Vec3::Y, n.normalize()).unwrap().term(sun);
        let want = 0.5 / PI * 2.0 * n.normalize().dot(sun) * term;
        assert!((got - want).abs() < 2e-3 * want, "case {i}: {got} vs {want}");
        seen.push(want);
    }
    // The three frames light the floor differently (the test can tell them apart).
    assert!((seen[0] - seen[1]).abs() > 0.05 * seen[0] && (seen[1] - seen[2]).abs() > 0.05 * seen[1], "{seen:?}");
}

/// A floor (normal +Y) whose normal texture tilts its normals 60° toward
/// +X, lit by a sun from +X: from 10° above the floor it lights it in
/// every CPU renderer; from 10° below (still in front of the bent normal)
/// its light would come through the floor, and none arrives (path's and
/// photon-cpu's direct light and vcm alike, as in Cycles).
#[test]
fn no_light_comes_through_a_normal_mapped_surface() {
    use crate::render::path::radiance as path_radiance;
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    let floor_lit_from = |elevation_degrees: f32, tag: &str| {
        let mut b = GltfBuilder::new();
        let m = grey_normal_mapped(&mut b, [238, 128, 191, 255], 1.0);
        let floor = quad(&mut b, Vec3::new(-2.0, 0.0, 2.0), 4.0 * Vec3::X, -4.0 * Vec3::Z, 1.0, m);
        let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
        let e = elevation_degrees.to_radians();
        let toward = -Vec3::new(e.cos(), e.sin(), 0.0);
        let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(toward, Vec3::Z)));
        let mut scene = load(tag, &b.to_glb(vec![floor, sun]));
        scene.camera = crate::camera::Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, -Vec3::Z, 60.0, 8, 8).unwrap();
        scene
    };
    let look = Ray::new(Vec3::new(0.3, 1.0, 0.2), -Vec3::Y);
    let mut rng = Rng::for_item(3, 0);
    for (elevation, lit) in [(10.0, true), (-10.0, false)] {
        let scene = floor_lit_from(elevation, &format!("through-{lit}"));
        let path = path_radiance(&scene, look, &PathSettings { spp: 1, ..Default::default() }, &mut rng).x;
        let traced = trace_photons(&scene, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
        let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings::default());
        let photon = renderer.radiance(&look, 0, &mut rng).x;
        let vcm = crate::render::vcm::render_pass(&scene, &crate::render::vcm::VcmSettings::default(), 1).unwrap().0;
        let vcm = vcm.pixels.iter().map(|p| p.x).sum::<f32>();
        if lit {
            assert!(path > 0.01 && photon > 0.01 && vcm > 0.01, "lit from above: {path}, {photon}, {vcm}");
        } else {
            assert_eq!((path, photon, vcm), (0.0, 0.0, 0.0), "lit from below the floor");
        }
    }
}

/// `EXT_texture_webp` as gltfpack `-tw` writes it: required, the texture's
/// only image a WebP one (no PNG `source`). The grey checker, losslessly
/// WebP-encoded, shows the same texels at their centres as the PNG one.
#[test]
fn a_webp_texture_reads_as_the_png_one() {
    use crate::test_scenes::gltf_textures::quad;
    use image::ImageEncoder;
    let rgba: Vec<u8> = GREYS.iter().flat_map(|&g| [g, g, g, 255]).collect();
    let mut webp = Vec::new();
    image::codecs::webp::WebPEncoder::new_lossless(&mut webp)
        .write_image(&rgba, 2, 2, image::ExtendedColorType::Rgba8)
        .unwrap();
    let mut b = GltfBuilder::new();
    let image = b.image(&webp, "image/webp");
    let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
    let m = b.material(&PbrMaterial { specular: 0.0, base_color_texture: Some(t), ..Default::default() });
    let node = quad(&mut b, Vec3::Y, Vec3::X, -Vec3::Y, 1.0, m);
    let (mut root, bin) = b.finish(vec![node]);
    let texture = &mut root.textures[0];
    texture.source = gltf::json::Index::new(u32::MAX); // written as absent
    let extension = format!(r#"{{"{}": {{"source": {}}}}}"#, textures::WEBP, image.value());
    texture.extensions = Some(gltf::json::deserialize::from_str(&extension).unwrap());
    root.extensions_used.push(textures::WEBP.into());
    root.extensions_required.push(textures::WEBP.into());
    let json: gltf::json::Value = gltf::json::deserialize::from_slice(&root.to_vec().unwrap()).unwrap();
    assert!(json["textures"][0].get("source").is_none(), "{}", json["textures"][0]);
    let scene = load("webp", &glb(&root, bin));
    assert!(scene.notes.iter().all(|n| !n.contains("EXT_texture_webp")), "{:?}", scene.notes);
    let texel = GREYS.map(|g| srgb_to_linear(g as f32 / 255.0));
    for (x, y, t) in [(0.25, 0.75, 0), (0.75, 0.75, 1), (0.25, 0.25, 2), (0.75, 0.25, 3)] {
        let a = albedo_at(&scene, x, y);
        assert!((a - texel[t]).abs() < 1e-5, "({x}, {y}): {a} vs texel {t} = {}", texel[t]);
    }
}

/// Clear coat, sheen and specular textures each multiply their factor at
/// the point hit, read in their extension's channel and colour space: R
/// and G of the coat's (linear), the sheen colour's RGB (sRGB) and its
/// roughness's A, the specular's A (linear) and its colour's RGB (sRGB).
/// Every renderer reads them, so no note is left.
#[test]
fn layer_textures_multiply_their_factors_where_the_ray_hits() {
    use crate::test_scenes::gltf_textures::{LAYER_ALPHA, LAYER_FACTORS, layered_glb};
    let scene = load("layers", &layered_glb());
    let unread = |n: &String| n.contains("clear-coat") || n.contains("sheen") || n.contains("not read");
    assert!(!scene.notes.iter().any(unread), "{:?}", scene.notes);
    let (coat, coat_roughness, sheen, sheen_roughness, specular, specular_color) = LAYER_FACTORS;
    let linear = GREYS.map(|g| g as f32 / 255.0);
    let srgb = GREYS.map(|g| srgb_to_linear(g as f32 / 255.0));
    let alpha = LAYER_ALPHA.map(|a| a as f32 / 255.0);
    let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
    for (x, y, t) in [(0.25, 0.75, 0), (0.75, 0.75, 1), (0.25, 0.25, 2), (0.75, 0.25, 3)] {
        let hit = scene.accel.intersect(&down_at(x, y)).expect("the quad");
        let Material::Pbr(b) = *scene.material_at(&hit) else { panic!("{:?}", scene.material_at(&hit)) };
        let at = format!("texel {t}: {b:?}");
        assert!(close(b.clearcoat, coat * linear[t]), "{at}");
        assert!(close(b.clearcoat_roughness, coat_roughness * linear[t]), "{at}");
        assert!(b.sheen_color.abs_diff_eq(Vec3::from(sheen) * srgb[t], 1e-5), "{at}");
        assert!(close(b.sheen_roughness, sheen_roughness * alpha[t]), "{at}");
        assert!(close(b.specular, specular * alpha[t]), "{at}");
        let color = Vec3::from(specular_color) * srgb[t];
        assert!(b.specular_color.abs_diff_eq(color, 1e-5), "{at}");
        // The Fresnel reads the scaled colour (the cached F0 follows it).
        assert!(b.dielectric_f0.abs_diff_eq(color * b.f0, 1e-6), "{at}");
        // Untouched: what no texture here scales.
        assert!(close(b.roughness, 0.4) && b.base_color == Vec3::ONE, "{at}");
    }
    // The GPU's record (without the GPU: its material as uploaded).
    let texturing = scene.texturing.as_ref().unwrap();
    let surface = scene.surfaces.iter().find(|s| texturing.materials[s.material as usize].is_some()).unwrap();
    let Material::Pbr(mean) = texturing.with_layer_means(scene.materials[surface.material as usize], surface.material)
    else {
        panic!()
    };
    let avg = |v: [f32; 4]| v.iter().sum::<f32>() / 4.0;
    assert!(close(mean.clearcoat, coat * avg(linear)), "{mean:?}");
    assert!(mean.sheen_color.abs_diff_eq(Vec3::from(sheen) * avg(srgb), 1e-5), "{mean:?}");
    assert!(close(mean.specular, specular * avg(alpha)), "{mean:?}");
}

/// A floor (normal +Y; u along +X, image up +Z) of grey matte under a clear
/// coat of roughness 0.4 whose `clearcoatNormalTexture` is the one texel
/// `coat_texel` at `scale` (none if None), with a normal texture of its own
/// texel `base_texel` if given, under a sun 45° from the zenith toward +X.
fn coated_floor(coat_texel: Option<[u8; 4]>, scale: f32, base_texel: Option<[u8; 4]>, tag: &str) -> Scene {
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    let mut b = GltfBuilder::new();
    let mut one_texel = |texel: [u8; 4]| {
        let image = b.image(&png(1, 1, &texel), "image/png");
        b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat)
    };
    let coat_texture = coat_texel.map(&mut one_texel);
    let normal_texture = base_texel.map(|t| (one_texel(t), 1.0));
    let m = b.material(&PbrMaterial {
        base_color: Vec3::splat(0.5),
        specular: 0.0,
        clearcoat: 1.0,
        clearcoat_roughness: 0.4,
        normal_texture,
        ..Default::default()
    });
    let floor = quad(&mut b, Vec3::new(-2.0, 0.0, 2.0), 4.0 * Vec3::X, -4.0 * Vec3::Z, 1.0, m);
    let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
    let toward = Vec3::new(-1.0, -1.0, 0.0).normalize();
    let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(toward, Vec3::Z)));
    let (root, bin) = b.finish(vec![floor, sun]);
    let mut value = gltf::json::serialize::to_value(&root).unwrap();
    if let Some(texture) = coat_texture {
        let info = format!(r#"{{"index": {}, "scale": {scale}}}"#, texture.value());
        value["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"] =
            gltf::json::deserialize::from_str(&info).unwrap();
    }
    let root: gltf::json::Root = gltf::json::deserialize::from_value(value).unwrap();
    load(tag, &glb(&root, bin))
}

/// `clearcoatNormalTexture` turns the coat alone, in every CPU renderer.
/// Its texel tilts the coat 22.5° toward +X, so that, seen from straight
/// above, the sun 45° toward +X lies at the tilted coat's mirror
/// direction: the coat's highlight, far brighter than the flat coat's.
/// Each renderer's radiance is the sun's irradiance × the coat's f with
/// the coat normal the texel gives by hand (the scene's own BSDF, tilted
/// by it), with the base's own normal texture (45°) or without; the coat
/// normal is bent from the unbent normal (the base's texture does not
/// move it), and a coat over the base's normal texture without one of its
/// own lies on the unbent normal (the extension's rule, and Cycles').
/// Scale 0 flattens the coat back; vcm's mean over an image agrees with
/// the path tracer's.
#[test]
fn a_clear_coat_normal_texture_turns_the_coat_alone() {
    use crate::bsdf::ShadingFrame;
    use crate::bsdf::bump::BumpShadow;
    // (sin 22.5°, 0, cos 22.5°) and (sin 45°, 0, cos 45°) as 8-bit 2n − 1.
    let (coat_texel, base_texel) = ([176u8, 128, 245, 255], [218u8, 128, 218, 255]);
    let world = |texel: [u8; 4]| {
        let d = Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) / 255.0 * 2.0 - 1.0;
        Vec3::new(d.x, d.z, d.y).normalize()
    };
    let coat_normal = world(coat_texel);
    let sun = Vec3::new(1.0, 1.0, 0.0).normalize();
    let look = Ray::new(Vec3::new(0.3, 1.0, 0.2), -Vec3::Y);
    let mut rng = Rng::for_item(5, 0);
    let settings = PathSettings { spp: 1, ..Default::default() };
    // The sun's light alone: a delta light over a lone floor.
    let expected = |scene: &Scene, base: Vec3, coat: Vec3| {
        let hit = scene.accel.intersect(&look).expect("the floor");
        let Material::Pbr(bsdf) = *scene.material_at(&hit) else { panic!("{:?}", scene.material_at(&hit)) };
        assert_eq!(bsdf.coat_normal, Vec3::Z, "material_at leaves the coat flat (the renderer's frame turns it)");
        let frame = ShadingFrame::new(base);
        let k = BumpShadow::new(Vec3::Y, base).map_or(1.0, |b| b.term(sun));
        let own = coat != Vec3::Y || base == Vec3::Y;
        let tilted =
            if own { bsdf.with_coat_normal(frame.to_local(coat)) } else { bsdf.with_unbent_coat(frame.to_local(coat)) };
        2.0 * tilted.f_bumped(frame.to_local(Vec3::Y), frame.to_local(sun), k).x * base.dot(sun)
    };
    let flat_scene = coated_floor(Some(coat_texel), 0.0, None, "coat-normal-0");
    let flat = path_radiance(&flat_scene, look, &settings, &mut rng).x;
    let want_flat = expected(&flat_scene, Vec3::Y, Vec3::Y);
    assert!((flat - want_flat).abs() < 1e-4 * want_flat, "scale 0: {flat} vs {want_flat}");
    // The last: the base's texture tilting 22.5° away from the sun.
    let away = [80u8, 128, 245, 255];
    let cases = [(Some(coat_texel), None), (Some(coat_texel), Some(base_texel)), (None, Some(away))];
    for (coat_texel, base_texel) in cases {
        let tag = match (coat_texel, base_texel) {
            (Some(_), None) => "coat",
            (Some(_), Some(_)) => "coat-and-base",
            _ => "base-only",
        };
        let scene = coated_floor(coat_texel, 1.0, base_texel, tag);
        assert!(!scene.notes.iter().any(|n| n.contains("clearcoatNormalTexture")), "{:?}", scene.notes);
        let hit = scene.accel.intersect(&look).unwrap();
        let base = base_texel.map_or(Vec3::Y, world);
        let shaded = scene.shading_normal_at(&hit, look.dir);
        assert!(shaded.abs_diff_eq(base, 1e-2), "{tag}: shading normal (lifted within 1°) {shaded} against {base}");
        let t = scene.texturing.as_ref().unwrap();
        let material = scene.surfaces[hit.surface as usize].material;
        let corners = scene.accel.triangle(hit.prim).unwrap().v;
        let (coat, own) = t.coat_normal(material, hit.prim, hit.barycentrics, corners, hit.shading_normal).unwrap();
        assert_eq!(own, coat_texel.is_some(), "{tag}");
        let want_coat = if coat_texel.is_some() { coat_normal } else { Vec3::Y };
        assert!(coat.abs_diff_eq(want_coat, 2e-3), "{tag}: coat normal {coat} against {want_coat}");
        let want = expected(&scene, shaded, coat);
        if coat_texel.is_some() {
            assert!(want > 1.5 * want_flat, "{tag}: the highlight ({want} against the flat coat's {want_flat})");
        } else {
            // Against the coat bent with the base: far apart.
            let with_base = expected(&scene, shaded, shaded);
            assert!((want - with_base).abs() > 0.05 * want, "{tag}: {want} against {with_base}");
        }
        let path = path_radiance(&scene, look, &settings, &mut rng).x;
        assert!((path - want).abs() < 1e-4 * want, "{tag}: path {path} vs {want}");
        let traced = trace_photons(&scene, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
        let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings::default());
        let photon = renderer.radiance(&look, 0, &mut rng).x;
        assert!((photon - want).abs() < 1e-4 * want, "{tag}: photon-cpu {photon} vs {want}");
    }
    // vcm against the path tracer over a 16×16 image of the floor's middle.
    let mut scene = coated_floor(Some(coat_texel), 1.0, None, "coat-vcm");
    scene.camera = crate::camera::Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, -Vec3::Z, 40.0, 16, 16).unwrap();
    let image_mean = |image: &crate::render::Image| image.pixels.iter().map(|p| p.x).sum::<f32>() / 256.0;
    let path =
        image_mean(&crate::render::path::render(&scene, &PathSettings { spp: 16, ..Default::default() }, &Silent).0);
    let passes = 8;
    let vcm = (1..=passes)
        .map(|pass| image_mean(&crate::render::vcm::render_pass(&scene, &Default::default(), pass).unwrap().0))
        .sum::<f32>()
        / passes as f32;
    assert!((vcm - path).abs() < 0.03 * path, "vcm {vcm} vs path {path}");
}
