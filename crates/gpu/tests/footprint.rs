//! footprint_rect.wgsl: the screen rectangle of a photon's sphere holds
//! every point of the sphere's projection (no pixel a photon lights is left
//! out) and is the projection's own bounding box within the 1% margin (not
//! the looser box of the sphere's bounding cube).

use glam::{Mat4, Vec3, Vec4};
use hikari_core::camera::Camera;
use hikari_core::sampling::{Rng, uniform_sphere};
use hikari_gpu::test_support::{run_kernel, test_context};

/// Words per case: the matrix, the centre and radius, one spare.
const ITEM: u32 = 21;

static PARAMS: hikari_gpu::wgsl::Module = hikari_gpu::wgsl::Module {
    name: "footprint params",
    source: "struct FootprintParams { clip_from_world: mat4x4<f32>, radius: f32 }\n\
             var<private> params: FootprintParams;\n",
    requires: &[],
};

/// GPU rectangles (lo.xy, hi.xy) for `(clip_from_world, centre, radius)`.
fn footprints(cases: &[(Mat4, Vec3, f32)]) -> Vec<Vec4> {
    let ctx = test_context("footprint");
    let mut input = Vec::new();
    for (m, c, r) in cases {
        input.extend(m.to_cols_array().map(f32::to_bits));
        input.extend([c.x, c.y, c.z, *r].map(f32::to_bits));
        input.push(0);
    }
    let main = format!(
        "let o = {ITEM}u * id.x; if (o >= arrayLength(&io)) {{ return; }}\n\
         var w: array<f32, 20>;\n\
         for (var k = 0u; k < 20u; k++) {{ w[k] = bitcast<f32>(io[o + k]); }}\n\
         params.clip_from_world = mat4x4<f32>(w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7],\n\
             w[8], w[9], w[10], w[11], w[12], w[13], w[14], w[15]);\n\
         params.radius = w[19];\n\
         let f = photon_footprint(vec3<f32>(w[16], w[17], w[18]));\n\
         io[o + 16u] = bitcast<u32>(f.x); io[o + 17u] = bitcast<u32>(f.y);\n\
         io[o + 18u] = bitcast<u32>(f.z); io[o + 19u] = bitcast<u32>(f.w);"
    );
    let out = run_kernel(&ctx, &[&PARAMS, &hikari_gpu::splat::FOOTPRINT_RECT], &main, &input);
    out.chunks(ITEM as usize).map(|w| Vec4::from_array([16, 17, 18, 19].map(|k| f32::from_bits(w[k])))).collect()
}

#[test]
fn the_rectangle_holds_the_projected_sphere_and_no_more() {
    let mut rng = Rng::for_item(7, 0);
    let mut cases = Vec::new();
    for k in 0..400 {
        let eye = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 8.0;
        let look = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 2.0;
        let fov = (20.0 + 70.0 * rng.next_f32()).to_radians();
        let camera = Camera::new(eye, look, Vec3::Y, fov, 512, 384).unwrap();
        let m = camera.clip_from_view(0.01, 40.0) * camera.view_from_world();
        // Spheres around the view direction, some crossing the eye plane.
        let forward = (look - eye).normalize();
        let side = uniform_sphere(glam::Vec2::new(rng.next_f32(), rng.next_f32()));
        let depth = 0.05 + 6.0 * rng.next_f32();
        // One in ten behind the eye.
        let depth = if k % 10 == 0 { -depth } else { depth };
        let centre = eye + forward * depth + side * (0.15 * depth.abs() * rng.next_f32());
        let radius = 0.01 + 0.3 * rng.next_f32() * rng.next_f32();
        cases.push((m, centre, radius));
    }
    let rects = footprints(&cases);
    let (mut inside_checked, mut whole_screen, mut behind) = (0, 0, 0);
    for ((m, c, r), rect) in cases.iter().zip(&rects) {
        let (lo, hi) = (rect.truncate().truncate(), glam::Vec2::new(rect.z, rect.w));
        let project = |scale: f32| -> Vec<Vec4> {
            (0..4000)
                .map(|k| {
                    let u = glam::Vec2::new((k as f32 + 0.5) / 4000.0, (k as f32 * 0.618_034).fract());
                    *m * (*c + uniform_sphere(u) * (*r * scale)).extend(1.0)
                })
                .collect()
        };
        let points = project(1.0);
        if project(1.02).iter().all(|p| p.w <= 0.0) {
            assert!(lo.x > hi.x, "a sphere behind the eye draws nothing: {rect}");
            behind += 1;
            continue;
        }
        if points.iter().any(|p| p.w <= 0.0) {
            assert_eq!(*rect, Vec4::new(-1.0, -1.0, 1.0, 1.0), "a sphere across the eye plane: the screen");
            whole_screen += 1;
            continue;
        }
        let bounds = |points: &[Vec4]| {
            let (a, b) = points
                .iter()
                .map(|p| p.truncate().truncate() / p.w)
                .fold((glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN)), |(a, b), p| (a.min(p), b.max(p)));
            (a.clamp(glam::Vec2::NEG_ONE, glam::Vec2::ONE), b.clamp(glam::Vec2::NEG_ONE, glam::Vec2::ONE))
        };
        let (plo, phi) = bounds(&points);
        if plo.x >= phi.x || plo.y >= phi.y {
            continue; // off screen
        }
        // Holds every sampled point of the projection.
        assert!(lo.cmple(plo + 1e-6).all() && hi.cmpge(phi - 1e-6).all(), "{rect} misses [{plo}, {phi}]");
        // And lies within the projection of a sphere 2% larger (the 1%
        // margin, with room for the samples' spacing): not the cube's box.
        if project(1.02).iter().all(|p| p.w > 0.0) {
            let (qlo, qhi) = bounds(&project(1.02));
            assert!(lo.cmpge(qlo - 1e-6).all() && hi.cmple(qhi + 1e-6).all(), "{rect} is loose around [{qlo}, {qhi}]");
        }
        inside_checked += 1;
    }
    eprintln!("{inside_checked} on screen, {whole_screen} across the eye plane, {behind} behind");
    assert!(inside_checked > 150 && whole_screen > 0 && behind > 20);
}
