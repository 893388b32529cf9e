//! Criterion benchmarks of the CPU hot paths: ray casting, photon tracing,
//! the photon-map queries and a whole photon-cpu frame.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec2;
use hikari_core::estimate::{FixedRadius, fixed_radius_radiance, k_nearest_radiance, volume_radiance_along};
use hikari_core::geometry::{Ray, packet::LANES};
use hikari_core::photon::{PhotonMap, TraceSettings, VolumePhotonMap, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
use hikari_core::sampling::{Rng, cosine_hemisphere, local_to_world, uniform_sphere};
use hikari_core::scene::Scene;
use std::hint::black_box;

fn ray_casting(c: &mut Criterion) {
    let scene = Scene::load("cornell-box").unwrap();
    let mut rng = Rng::for_item(1, 0);
    // Rays from points on the walls into the box, as photon bounces cast them.
    let rays: Vec<_> = (0..4096)
        .filter_map(|_| {
            let ray = scene.camera.ray(Vec2::new(rng.next_f32() * 512.0, rng.next_f32() * 512.0));
            let hit = scene.accel.intersect(&ray)?;
            let n = if ray.dir.dot(hit.geometric_normal) < 0.0 { hit.geometric_normal } else { -hit.geometric_normal };
            Some(Ray::new(hit.point, local_to_world(cosine_hemisphere(rng.next_2d()), n)))
        })
        .collect();
    let mut group = c.benchmark_group("ray_casting");
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("closest_hit_cornell_box", |b| {
        b.iter(|| rays.iter().filter(|r| scene.accel.intersect(r).is_some()).count())
    });
    group.bench_function("occlusion_cornell_box", |b| {
        b.iter(|| rays.iter().filter(|r| scene.accel.occluded(r)).count())
    });
    // The same rays eight at a time (`geometry::packet`; ray by ray where
    // the CPU has no AVX2).
    let packets: Vec<[Option<Ray>; LANES]> =
        rays.chunks(LANES).map(|c| std::array::from_fn(|l| c.get(l).copied())).collect();
    group.bench_function("closest_hit_cornell_box_packets", |b| {
        b.iter(|| {
            packets
                .iter()
                .map(|p| {
                    let mut h = [None; LANES];
                    scene.accel.intersect_packet(p, &mut h);
                    h.iter().flatten().count()
                })
                .sum::<usize>()
        })
    });

    group.finish();
}

fn photon_tracing(c: &mut Criterion) {
    let mut group = c.benchmark_group("photon_tracing");
    group.sample_size(10);
    for name in ["cornell-box", "cornell-caustic"] {
        let scene = Scene::load(name).unwrap();
        let settings = TraceSettings { photons: 1_000_000, seed: 1, ..Default::default() };
        group.throughput(Throughput::Elements(settings.photons));
        group.bench_function(format!("{name}_1M_paths"), |b| {
            b.iter(|| trace_photons(&scene, &settings, &Silent).global.len())
        });
    }
    group.finish();
}

fn estimates(c: &mut Criterion) {
    let scene = Scene::load("cornell-box").unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 1, ..Default::default() }, &Silent);
    let map = PhotonMap::new(traced.indirect(), traced.power_unit);
    let mut rng = Rng::for_item(2, 0);
    let queries: Vec<_> = (0..1024)
        .filter_map(|_| {
            let ray = scene.camera.ray(Vec2::new(rng.next_f32() * 512.0, rng.next_f32() * 512.0));
            scene.accel.intersect(&ray).map(|h| (h.point, h.geometric_normal))
        })
        .collect();
    let params = FixedRadius { radius: 0.1039, normal_test: false };
    let mut group = c.benchmark_group("estimates");
    group.throughput(Throughput::Elements(queries.len() as u64));
    group.bench_function("fixed_radius_r0.104_157k_photons", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|(x, n)| fixed_radius_radiance(&map, None, *x, *n, glam::Vec3::ONE, &params).x)
                .sum::<f32>()
        })
    });
    group.bench_function("k_nearest_k100_157k_photons", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|(x, n)| k_nearest_radiance(&map, *x, *n, glam::Vec3::ONE, 100, 0.5, false).x)
                .sum::<f32>()
        })
    });
    group.finish();
    black_box(uniform_sphere(Vec2::ZERO));
}

/// The CPU volume estimate along view rays in fog-stage (camera in the fog):
/// the default 200k paths store about 553k volume photons.
fn volume_estimate(c: &mut Criterion) {
    let scene = Scene::load("fog-stage").unwrap();
    let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 1, ..Default::default() }, &Silent);
    let radius = hikari_core::render::photon_cpu::default_radius(&scene);
    let map = VolumePhotonMap::new(traced.volume.clone(), traced.power_unit, radius);
    let sigma_t = scene.media.sigma_t(scene.media.global_mask());
    let mut rng = Rng::for_item(3, 0);
    let rays: Vec<_> = (0..256)
        .map(|_| {
            let ray = scene.camera.ray(Vec2::new(rng.next_f32() * 512.0, rng.next_f32() * 384.0));
            let length = scene.accel.intersect(&ray).map_or(scene.diagonal() * 2.0, |h| h.t);
            (ray, length)
        })
        .collect();
    let mut group = c.benchmark_group("estimates");
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function(format!("volume_along_ray_fog_stage_{}k_photons", map.len() / 1000), |b| {
        b.iter(|| {
            rays.iter()
                .map(|(ray, length)| {
                    let transmittance = |s: f32| (-sigma_t * s).exp();
                    volume_radiance_along(&map, scene.media.phases(), ray.origin, ray.dir, *length, transmittance).x
                })
                .sum::<f32>()
        })
    });
    group.finish();
}

fn photon_cpu_frame(c: &mut Criterion) {
    let scene = Scene::load("cornell-box").unwrap();
    let mut group = c.benchmark_group("photon_cpu");
    group.sample_size(10);
    group.bench_function("cornell_box_512x512_200k_photons_1spp_end_to_end", |b| {
        b.iter(|| {
            let traced =
                trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 1, ..Default::default() }, &Silent);
            let settings = PhotonCpuSettings { spp: 1, ..Default::default() };
            PhotonCpuRenderer::new(&scene, &traced, &settings).render(&Silent).0.mean()
        })
    });
    group.finish();
}

/// A 100,352-triangle sheet (225 × 225 vertices, normals) bent by two
/// joints, the second turning through a keyframed quarter turn, every
/// vertex weighted on both: what `Scene::posed` redoes per frame for an
/// animated skinned character before it rebuilds the BVH.
fn skinning(c: &mut Criterion) {
    use glam::{Affine3A, Mat4, Quat, Vec3};
    use hikari_core::scene::deformation::{DeformedMesh, Influences, Joint};
    use hikari_core::scene::keyframes::{Keyframes, NodeTrack, Track};
    let n = 225u32;
    let positions: Vec<Vec3> =
        (0..n * n).map(|i| Vec3::new((i % n) as f32 / n as f32, (i / n) as f32 / n as f32, 0.0)).collect();
    let mut triangles = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let i = y * n + x;
            triangles.push([i, i + 1, i + n + 1]);
            triangles.push([i, i + n + 1, i + n]);
        }
    }
    let mut influences = Influences { starts: vec![0], entries: Vec::new() };
    for p in &positions {
        influences.entries.extend([(0, 1.0 - p.y), (1, p.y)]);
        influences.starts.push(influences.entries.len() as u32);
    }
    let turn = NodeTrack {
        translation: Vec3::Y * 0.5,
        rotation: Quat::IDENTITY,
        scale: Vec3::ONE,
        translation_track: None,
        rotation_track: Some(Track {
            times: vec![0.0, 1.0],
            values: vec![Quat::IDENTITY, Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)],
            step: false,
        }),
        scale_track: None,
    };
    let rest = Affine3A::from_translation(Vec3::Y * 0.5);
    let keys = Keyframes::new(Affine3A::IDENTITY, vec![turn], rest);
    let joint = |motion, at: Vec3| Joint {
        inverse_bind: Mat4::from_translation(-at),
        rest_world: Mat4::from_translation(at),
        motion,
    };
    let mesh = DeformedMesh {
        normals: Some(vec![Vec3::Z; positions.len()]),
        positions,
        triangles,
        influences,
        joints: vec![joint(None, Vec3::ZERO), joint(keys, Vec3::Y * 0.5)],
        fallback: Mat4::IDENTITY,
        morph: None,
    };
    let mut group = c.benchmark_group("skinning");
    group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
    group.bench_function("sheet_100k_triangles_2_joints", |b| {
        b.iter(|| black_box(mesh.triangles_at(black_box(0.5), &Affine3A::IDENTITY)).len())
    });
    // What a new pose costs the CPU before photons are traced: the skinning
    // above, the acceleration structure and its BVHs (`Accel::build_bvhs`:
    // the binary BVH the GPU's flat BVH is laid out from, and the wide one).
    group.bench_function("sheet_100k_triangles_skinned_and_bvh_built", |b| {
        b.iter(|| {
            let triangles = mesh.triangles_at(black_box(0.5), &Affine3A::IDENTITY);
            let surfaces = vec![0; triangles.len()];
            let accel = hikari_core::geometry::Accel::build(triangles, surfaces, Vec::new(), Vec::new());
            accel.build_bvhs();
            black_box(accel.bounds())
        })
    });
    // The same through `Accel::build_moved`, as the viewers pose a frame:
    // the rest pose's binary BVH refitted, the wide BVH laid out from it.
    let at_rest = mesh.triangles_at(0.0, &Affine3A::IDENTITY);
    let rest = hikari_core::geometry::Accel::build(at_rest.clone(), vec![0; at_rest.len()], Vec::new(), Vec::new());
    rest.build_bvhs();
    group.bench_function("sheet_100k_triangles_skinned_and_bvh_refitted", |b| {
        b.iter(|| {
            let triangles = mesh.triangles_at(black_box(0.5), &Affine3A::IDENTITY);
            let surfaces = vec![0; triangles.len()];
            let accel = hikari_core::geometry::Accel::build_moved(triangles, surfaces, Vec::new(), Vec::new(), &rest);
            accel.build_bvhs();
            black_box(accel.bounds())
        })
    });
    group.finish();
}

criterion_group!(benches, ray_casting, photon_tracing, estimates, volume_estimate, photon_cpu_frame, skinning);
criterion_main!(benches);
