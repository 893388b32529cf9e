//! Ray-casting geometry: primitives (triangles, analytic spheres) and the BVH
//! that answers closest-hit and occlusion queries over them.

mod accel;
mod bvh_build;
mod flat_bvh;
pub mod packet;
mod shapes;
mod simd8;
mod wide;

pub use accel::{Accel, Hit};
pub(crate) use bvh_build::build_cwbvh;
pub use flat_bvh::{FlatBvh, FlatNode, FlatPrim, FlatShading};
pub use shapes::{Sphere, Triangle, TriangleNormals};

use glam::Vec3;

/// A ray `origin + t·dir`, t in (t_min, t_max).
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub t_max: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Ray { origin, dir, t_max: f32::INFINITY }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Offset for spawning rays off a surface, relative to the scene's size, so
/// that a ray does not re-hit the surface it leaves.
pub fn ray_epsilon(scene_scale: f32) -> f32 {
    scene_scale * 1e-5
}

/// A ray as obvhs sees it for node tests. Its CWBVH slab test turns an
/// exactly zero direction component into inf·0 = NaN and misses every box,
/// so such components are nudged to a tiny value; primitive tests still use
/// the exact ray.
pub(crate) fn obvhs_ray(origin: Vec3, dir: Vec3, t_max: f32) -> obvhs::ray::Ray {
    let nudge = |d: f32| {
        if d.abs() < 1e-20 { 1e-20f32.copysign(d) } else { d }
    };
    let dir = glam::Vec3A::new(nudge(dir.x), nudge(dir.y), nudge(dir.z));
    obvhs::ray::Ray::new(origin.into(), dir, 0.0, t_max)
}
