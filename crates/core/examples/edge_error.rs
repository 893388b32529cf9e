//! How much of progressive photon-cpu's remaining error sits at edges and
//! corners (issue #11): the squared error and the signed excess against a
//! reference, split between pixels whose first surface has another surface
//! (or another face) within the first radius and the rest.
//!
//!   cargo run --release --example edge_error -- SCENE REF.exr [PASSES...]
//!
//! REF.exr: a long path-traced render of SCENE at the reference's size
//! (scripts/error-curves.sh makes them).

use glam::Vec2;
use hikari_core::output::read_exr;
use hikari_core::progressive::{DEFAULT_ALPHA, ImageMean, Schedules, photon_cpu_pass};
use hikari_core::render::photon_cpu::{PhotonCpuSettings, default_radius};
use hikari_core::scene::Scene;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(name), Some(reference)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: edge_error SCENE REF.exr [PASSES...]");
        std::process::exit(2);
    };
    let reference = read_exr(std::path::Path::new(reference)).expect("a reference EXR");
    let mut scene = Scene::load(name).expect("a scene");
    scene.camera = scene.camera.with_resolution(reference.width, reference.height).unwrap();
    let passes: Vec<u32> = args[3..].iter().map(|p| p.parse().expect("a pass count")).collect();
    let passes = if passes.is_empty() { vec![1, 16, 256] } else { passes };
    // NORMAL_TEST=1: the existing guard (photons from behind the surface
    // do not count), to compare.
    let normal_test = std::env::var("NORMAL_TEST").is_ok_and(|v| v == "1");
    let settings = PhotonCpuSettings { normal_test, ..Default::default() };
    let (global, caustic) = settings.estimate_params(&scene);
    let schedules = Schedules::new([global.radius, caustic.radius, default_radius(&scene)], DEFAULT_ALPHA);
    let edge = edge_pixels(&scene, global.radius);
    let (w, h) = (reference.width, reference.height);
    println!(
        "{name} {w}x{h}: {} of {} pixels within r1 = {:.4} of another surface or face",
        edge.iter().filter(|&&e| e).count(),
        edge.len(),
        global.radius
    );
    let mut mean = ImageMean::new(w, h);
    let mut done = 0;
    for &n in &passes {
        while done < n {
            done += 1;
            mean.add(&photon_cpu_pass(&scene, &settings, 100_000, &schedules, done).0);
        }
        let image = mean.mean();
        let (mut sq, mut excess) = ([0.0f64; 2], [0.0f64; 2]);
        let mut total = 0.0f64;
        for i in 0..image.pixels.len() {
            let d = image.pixels[i] - reference.pixels[i];
            let k = edge[i] as usize;
            sq[k] += d.length_squared() as f64;
            excess[k] += (d.x + d.y + d.z) as f64;
            total += (reference.pixels[i].x + reference.pixels[i].y + reference.pixels[i].z) as f64;
        }
        let rmse = hikari_core::progressive::compare(&image, &reference).unwrap().relative_rmse;
        println!(
            "{n} passes of 100,000 (r = {:.4}): relative RMSE {rmse:.4}, squared error {:.0}% at edges; excess light {:+.2}% of the image at edges, {:+.2}% elsewhere",
            schedules.global.radius(n),
            100.0 * sq[1] / (sq[0] + sq[1]),
            100.0 * excess[1] / total,
            100.0 * excess[0] / total,
        );
    }
}

/// Pixels whose first hit has, within `radius`, a point of another surface
/// or of a face turned more than 10° away: probed by short rays from the
/// hit along 16 tangent directions and back into the surface.
fn edge_pixels(scene: &Scene, radius: f32) -> Vec<bool> {
    let cam = &scene.camera;
    let mut out = Vec::new();
    for y in 0..cam.height {
        for x in 0..cam.width {
            let ray = cam.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = scene.accel.intersect(&ray) else {
                out.push(false);
                continue;
            };
            let n = if hit.geometric_normal.dot(ray.dir) < 0.0 { hit.geometric_normal } else { -hit.geometric_normal };
            let (t, b) = n.any_orthonormal_pair();
            let lifted = hit.point + n * (radius * 0.05);
            let near = (0..16).any(|k| {
                let a = k as f32 / 16.0 * std::f32::consts::TAU;
                let dir = (t * a.cos() + b * a.sin()).normalize();
                let other = |h: &hikari_core::geometry::Hit| {
                    h.surface != hit.surface || h.geometric_normal.dot(hit.geometric_normal).abs() < 0.985
                };
                let mut probe = hikari_core::geometry::Ray::new(lifted, dir);
                probe.t_max = radius;
                if scene.accel.intersect(&probe).is_some_and(|h| other(&h)) {
                    return true; // a wall or face rising within r (an inside corner)
                }
                // Back down onto the surface r away: nothing or another face
                // there is an outside edge within r.
                let mut down = hikari_core::geometry::Ray::new(lifted + dir * radius, -n);
                down.t_max = radius * 0.1;
                scene.accel.intersect(&down).is_none_or(|h| other(&h))
            });
            out.push(near);
        }
    }
    out
}
