//! A flat binary BVH for GPU traversal: `Accel`'s own binary BVH (obvhs's
//! Bvh2, `Accel::binary_bvh`) over its primitives, nodes and primitives in plain `#[repr(C)]` arrays.
//! `FlatBvh::intersect` is the CPU mirror of the WGSL traversal.

use super::{Accel, Ray};
use bytemuck::Zeroable;
use glam::Vec3;

/// A node: inner when `prim_count` is 0 (children at `first` and `first + 1`),
/// else a leaf holding primitives `first .. first + prim_count`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FlatNode {
    pub min: [f32; 3],
    pub prim_count: u32,
    pub max: [f32; 3],
    pub first: u32,
}

/// A primitive in leaf order: a triangle as (v0, e1, e2) or a sphere as
/// (centre, (radius, 0, 0)); `is_sphere` tells which.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FlatPrim {
    pub a: [f32; 3],
    pub is_sphere: u32,
    pub b: [f32; 3],
    pub surface: u32,
    pub c: [f32; 3],
    /// Its index in `Accel`'s joint primitive space (`FlatBvh::source`),
    /// which a BLEND surface's threshold hashes (`texture::blend_threshold`).
    pub source: u32,
}

/// What a hit on a primitive needs beyond its distance, in the same order as
/// `FlatBvh::prims`: the unit geometric normal exactly as `Accel` computes it
/// (so CPU and GPU photon paths see the same bits), and the vertex normals
/// of smooth triangles. Spheres compute their normal from the hit point.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FlatShading {
    pub geometric_normal: [f32; 3],
    /// 1 when `vertex_normals` hold the triangle's smooth normals.
    pub has_vertex_normals: u32,
    /// n0, n1, n2 (w unused).
    pub vertex_normals: [[f32; 4]; 3],
}

pub struct FlatBvh {
    pub nodes: Vec<FlatNode>,
    pub prims: Vec<FlatPrim>,
    /// Per primitive, in `prims` order.
    pub shading: Vec<FlatShading>,
    /// Per primitive, in `prims` order, its index in `Accel`'s joint
    /// primitive space (triangles, then spheres): what `Hit::prim` and the
    /// scene's texture coordinates are indexed by.
    pub source: Vec<u32>,
    pub epsilon: f32,
}

impl FlatBvh {
    pub fn new(accel: &Accel) -> Self {
        let mut prims: Vec<FlatPrim> = accel
            .triangles()
            .enumerate()
            .map(|(i, (t, surface))| FlatPrim {
                a: t.v[0].to_array(),
                is_sphere: 0,
                b: (t.v[1] - t.v[0]).to_array(),
                surface,
                c: (t.v[2] - t.v[0]).to_array(),
                source: i as u32,
            })
            .collect();
        let mut shading: Vec<FlatShading> = accel
            .triangles()
            .map(|(t, _)| {
                let normals = t.normals.map_or([Vec3::ZERO; 3], |n| n.0);
                FlatShading {
                    geometric_normal: t.geometric_normal().normalize().to_array(),
                    has_vertex_normals: t.normals.is_some() as u32,
                    vertex_normals: normals.map(|n| n.extend(0.0).to_array()),
                }
            })
            .collect();
        shading.extend(accel.spheres().map(|_| FlatShading::zeroed()));
        let first_sphere = prims.len() as u32;
        prims.extend(accel.spheres().enumerate().map(|(i, (s, surface))| FlatPrim {
            a: s.center.to_array(),
            is_sphere: 1,
            b: [s.radius, 0.0, 0.0],
            surface,
            c: [0.0; 3],
            source: first_sphere + i as u32,
        }));
        if prims.is_empty() {
            return FlatBvh { nodes: Vec::new(), prims, shading, source: Vec::new(), epsilon: accel.epsilon };
        }
        // The scene's own binary BVH (built once for the CPU's wide BVH
        // and this): the same tree, not a second build.
        let bvh = accel.binary_bvh().expect("a scene with primitives has a binary BVH");
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| FlatNode {
                min: n.aabb().min.to_array(),
                prim_count: n.prim_count,
                max: n.aabb().max.to_array(),
                first: n.first_index,
            })
            .collect();
        let ordered = bvh.primitive_indices.iter().map(|&i| prims[i as usize]).collect();
        let ordered_shading = bvh.primitive_indices.iter().map(|&i| shading[i as usize]).collect();
        let source = bvh.primitive_indices.clone();
        FlatBvh { nodes, prims: ordered, shading: ordered_shading, source, epsilon: accel.epsilon }
    }

    /// Closest hit: (t, primitive index in `prims`). The WGSL traversal
    /// follows this loop step by step.
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, usize)> {
        if self.nodes.is_empty() {
            return None;
        }
        // Zero components become ±1e-20 so the slab test never sees 0·∞.
        let safe = |d: f32| if d.abs() < 1e-20 { 1e-20f32.copysign(d) } else { d };
        let inv = Vec3::new(safe(ray.dir.x), safe(ray.dir.y), safe(ray.dir.z)).recip();
        let mut best: Option<(f32, usize)> = None;
        let mut t_max = ray.t_max;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !slab_hit(ray.origin, inv, Vec3::from(node.min), Vec3::from(node.max), t_max) {
                continue;
            }
            if node.prim_count == 0 {
                stack[top] = node.first;
                stack[top + 1] = node.first + 1;
                top += 2;
                continue;
            }
            for i in node.first..node.first + node.prim_count {
                let t = self.intersect_prim(i as usize, ray, t_max);
                if t < t_max {
                    t_max = t;
                    best = Some((t, i as usize));
                }
            }
        }
        best
    }

    fn intersect_prim(&self, i: usize, ray: &Ray, t_max: f32) -> f32 {
        let p = &self.prims[i];
        let mut r = *ray;
        r.t_max = t_max;
        if p.is_sphere != 0 {
            let s = super::Sphere { center: Vec3::from(p.a), radius: p.b[0] };
            return s.intersect(&r, self.epsilon).unwrap_or(f32::INFINITY);
        }
        let (v0, e1, e2) = (Vec3::from(p.a), Vec3::from(p.b), Vec3::from(p.c));
        let tri = super::Triangle { v: [v0, v0 + e1, v0 + e2], normals: None };
        tri.intersect(&r, self.epsilon).map_or(f32::INFINITY, |h| h.0)
    }
}

/// Ray–box slab test over [0, t_max], tolerant of infinite inverse directions.
fn slab_hit(origin: Vec3, inv: Vec3, min: Vec3, max: Vec3, t_max: f32) -> bool {
    let t0 = (min - origin) * inv;
    let t1 = (max - origin) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, uniform_sphere};

    /// The flat BVH's traversal finds the same closest hits as `Accel`.
    #[test]
    fn flat_bvh_matches_accel() {
        for name in ["cornell-box", "cornell-caustic"] {
            let scene = crate::scene::Scene::load(name).unwrap();
            let flat = FlatBvh::new(&scene.accel);
            let mut rng = Rng::for_item(77, 0);
            for _ in 0..3000 {
                let origin = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 1.9;
                let ray = Ray::new(origin, uniform_sphere(rng.next_2d()));
                let a = scene.accel.intersect(&ray);
                let f = flat.intersect(&ray);
                match (a, f) {
                    (None, None) => {}
                    (Some(h), Some((t, i))) => {
                        assert!((h.t - t).abs() < 1e-5 * h.t.max(1.0), "{name}: t {} vs {t}", h.t);
                        // Of two surfaces at exactly the same distance (a
                        // box standing on the floor) either may be reported.
                        if h.t != t {
                            assert_eq!(h.surface, flat.prims[i].surface, "{name}: {ray:?} t {} vs {t}", h.t);
                        }
                    }
                    (a, f) => panic!("{name}: accel {a:?} vs flat {f:?}"),
                }
            }
        }
    }
}
