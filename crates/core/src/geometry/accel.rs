//! The scene BVH over triangles and analytic spheres, answering
//! closest-hit and occlusion queries: on x86-64 with AVX2 through `wide`'s
//! eight-wide float BVH, one ray at a time or eight (`packet`); elsewhere
//! through obvhs's compressed wide BVH (CWBVH), ray by ray.
//!
//! Primitives are addressed by one index space: triangles first, then spheres.
//! Each primitive carries the id of the surface (object) it belongs to.

use super::packet::{LANES, RayLanes};
use super::wide::WideBvh;
use super::{Ray, Sphere, Triangle};
use crate::texture::Texturing;
use glam::{UVec2, Vec2, Vec3, Vec3A};
use obvhs::{Boundable, BvhBuildParams, aabb::Aabb, bvh2::Bvh2, cwbvh::CwBvh};
use std::borrow::Borrow;
use std::sync::{Arc, OnceLock};

/// What a closest-hit query found.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub point: Vec3,
    /// Unit geometric normal, as the primitive defines it (outward for spheres,
    /// by winding for triangles); not flipped toward the ray.
    pub geometric_normal: Vec3,
    /// Unit shading normal on the same side as `geometric_normal`.
    pub shading_normal: Vec3,
    pub surface: u32,
    /// The primitive hit, in the joint index space (triangles, then spheres):
    /// what per-triangle side tables (texture coordinates) are indexed by.
    pub prim: u32,
    /// Barycentric weights of the triangle's vertices 1 and 2 at the hit
    /// (zero for spheres).
    pub barycentrics: Vec2,
}

pub(super) struct PrimBounds(pub Aabb);

/// A primitive as the traversal loop reads it, stored in BVH leaf order so
/// the loop needs no index indirection: a triangle as (v0, e1, e2), a sphere
/// as (centre, (radius, 0, 0), unused). 40 bytes.
#[derive(Clone, Copy)]
pub(super) struct PackedPrim {
    pub a: Vec3,
    pub b: Vec3,
    pub c: Vec3,
    /// Index in the joint primitive space; `SPHERE_BIT` marks spheres,
    /// `MASKED_BIT` triangles of `alphaMode` MASK cut-outs and BLEND.
    pub prim: u32,
}

pub(super) const SPHERE_BIT: u32 = 1 << 31;

/// How much more a refitted BVH may cost traversals (`relative_cost`) than
/// the tree it was refitted from before a moved scene builds its own
/// (`Accel::build_moved`): a refit costs a linear pass, a build of 100,000
/// triangles ~25 ms on one core, and the tracing of one photon set or
/// frame pays the difference in cost.
const REFIT_COST_LIMIT: f32 = 1.5;
/// The triangle is a cut-out or BLEND: a hit counts only where its alpha
/// says the surface is there (`Texturing::is_there_at`; BLEND by the ray's
/// `blend_threshold`). Only flagged primitives pay for the test, so scenes
/// without them cost nothing more.
pub(super) const MASKED_BIT: u32 = 1 << 30;
pub(super) const INDEX_BITS: u32 = MASKED_BIT - 1;

/// What the hit record needs per primitive, precomputed so that a hit costs
/// no normalisation: the unit geometric normal of a triangle (unused for
/// spheres), whether it has smooth normals to interpolate, and its surface.
#[derive(Clone, Copy)]
struct PrimInfo {
    normal: Vec3,
    smooth: bool,
    surface: u32,
}

impl PackedPrim {
    /// Ray parameter of the nearest hit in (t_min, ray.t_max), with the
    /// triangle's barycentrics; INFINITY on a miss.
    #[inline(always)]
    pub(super) fn intersect(&self, ray: &Ray, t_min: f32) -> (f32, f32, f32) {
        if self.prim & SPHERE_BIT != 0 {
            let sphere = Sphere { center: self.a, radius: self.b.x };
            return (sphere.intersect(ray, t_min).unwrap_or(f32::INFINITY), 0.0, 0.0);
        }
        // Möller–Trumbore with precomputed edges.
        let (e1, e2) = (self.b, self.c);
        let p = ray.dir.cross(e2);
        let det = e1.dot(p);
        let inv = 1.0 / det;
        let s = ray.origin - self.a;
        let b1 = s.dot(p) * inv;
        let q = s.cross(e1);
        let b2 = ray.dir.dot(q) * inv;
        let t = e2.dot(q) * inv;
        // NaN (det = 0) fails every comparison and so misses.
        if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && t > t_min && t < ray.t_max {
            (t, b1, b2)
        } else {
            (f32::INFINITY, 0.0, 0.0)
        }
    }
}

/// The bounds of every primitive, in the joint index space (triangles,
/// then spheres): what both BVHs are built over.
fn prim_bounds(triangles: &[Triangle], spheres: &[Sphere]) -> Vec<PrimBounds> {
    let mut bounds: Vec<PrimBounds> =
        triangles.iter().map(|t| PrimBounds(Aabb::from_points(&t.v.map(Vec3A::from)))).collect();
    bounds.extend(spheres.iter().map(|s| {
        let r = Vec3A::splat(s.radius);
        let c: Vec3A = s.center.into();
        PrimBounds(Aabb::new(c - r, c + r))
    }));
    bounds
}

impl Boundable for PrimBounds {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

#[derive(Clone)]
pub struct Accel {
    triangles: Vec<Triangle>,
    spheres: Vec<Sphere>,
    /// Surface id per primitive, in the joint index space.
    surface_of: Vec<u32>,
    /// Hit-record data per primitive, in the joint index space.
    info: Vec<PrimInfo>,
    /// Every primitive as the traversals test it, in the joint index space.
    packed: Vec<PackedPrim>,
    /// Self-intersection offset along rays leaving a surface.
    pub epsilon: f32,
    bounds_min: Vec3,
    bounds_max: Vec3,
    /// The textures of cut-outs, when the scene has any (`set_alpha_mask`).
    alpha: Option<Arc<Texturing>>,
    /// The binary BVH over the primitives' bounds (joint index space),
    /// built on first use ([`Accel::binary_bvh`]): the wide BVH and the
    /// GPU's flat BVH are both laid out from it, so a scene posed anew
    /// (every frame of an animation) pays for one build, not one each.
    bvh2: OnceLock<Bvh2>,
    /// The wide BVH of single-ray and packet queries, built on the first
    /// one (None where it cannot run: `WideBvh::build`; the CWBVH answers
    /// then, ray by ray).
    wide: OnceLock<Option<WideBvh>>,
    /// The CWBVH, built only where the wide BVH cannot run (or a test
    /// compares the two): a scene whose objects move is rebuilt every
    /// frame, and building both would cost twice.
    cwbvh: OnceLock<Option<Cwbvh>>,
}

/// obvhs's CWBVH with the primitives in its leaf order: `packed[i]` is
/// primitive `bvh.primitive_indices[i]`.
#[derive(Clone)]
struct Cwbvh {
    bvh: CwBvh,
    packed: Vec<PackedPrim>,
}

impl Accel {
    /// The primitives, ready for a BVH built on the first query (`wide`,
    /// else the CWBVH). `triangle_surfaces[i]` / `sphere_surfaces[i]` give the
    /// surface id of each primitive.
    pub fn build(
        triangles: Vec<Triangle>,
        triangle_surfaces: Vec<u32>,
        spheres: Vec<Sphere>,
        sphere_surfaces: Vec<u32>,
    ) -> Self {
        assert_eq!(triangles.len(), triangle_surfaces.len());
        assert_eq!(spheres.len(), sphere_surfaces.len());
        let bounds = prim_bounds(&triangles, &spheres);
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for b in &bounds {
            lo = lo.min(b.0.min.into());
            hi = hi.max(b.0.max.into());
        }
        let scale = if bounds.is_empty() { 1.0 } else { (hi - lo).max_element().max(1e-3) };
        let mut surface_of = triangle_surfaces;
        surface_of.extend(sphere_surfaces);
        let n_tri = triangles.len();
        let info = triangles
            .iter()
            .map(|t| (t.geometric_normal().normalize(), t.normals.is_some()))
            .chain(spheres.iter().map(|_| (Vec3::ZERO, false)))
            .zip(&surface_of)
            .map(|((normal, smooth), &surface)| PrimInfo { normal, smooth, surface })
            .collect();
        let packed = (0..bounds.len())
            .map(|i| {
                if i < n_tri {
                    let v = triangles[i].v;
                    PackedPrim { a: v[0], b: v[1] - v[0], c: v[2] - v[0], prim: i as u32 }
                } else {
                    let s = spheres[i - n_tri];
                    PackedPrim {
                        a: s.center,
                        b: Vec3::new(s.radius, 0.0, 0.0),
                        c: Vec3::ZERO,
                        prim: i as u32 | SPHERE_BIT,
                    }
                }
            })
            .collect();
        Accel {
            triangles,
            spheres,
            surface_of,
            info,
            packed,
            epsilon: super::ray_epsilon(scale),
            bounds_min: lo,
            bounds_max: hi,
            alpha: None,
            bvh2: OnceLock::new(),
            wide: OnceLock::new(),
            cwbvh: OnceLock::new(),
        }
    }

    /// [`Accel::build`] for `rest`'s primitives moved (the same ones, in the
    /// same order: a scene posed anew, its meshes deformed or moved), whose
    /// binary BVH is `rest`'s refitted to where they are now
    /// (`bvh_build::refit`, a linear pass) rather than built afresh, unless
    /// the refitted tree would cost traversals more than
    /// `REFIT_COST_LIMIT` times what `rest`'s does (then it is built anew
    /// on first use, as `build` does). Builds `rest`'s BVH if it has none.
    pub fn build_moved(
        triangles: Vec<Triangle>,
        triangle_surfaces: Vec<u32>,
        spheres: Vec<Sphere>,
        sphere_surfaces: Vec<u32>,
        rest: &Accel,
    ) -> Self {
        let accel = Accel::build(triangles, triangle_surfaces, spheres, sphere_surfaces);
        if accel.triangles.len() != rest.triangles.len() || accel.spheres.len() != rest.spheres.len() {
            return accel;
        }
        if let Some(bvh) = rest.binary_bvh() {
            let refitted = super::bvh_build::refit(bvh, &prim_bounds(&accel.triangles, &accel.spheres));
            let limit = REFIT_COST_LIMIT * super::bvh_build::relative_cost(bvh);
            if super::bvh_build::relative_cost(&refitted) <= limit {
                let _ = accel.bvh2.set(refitted);
            }
        }
        accel
    }

    /// Makes the triangles of `texturing`'s MASK cut-out surfaces
    /// transparent where their alpha is below the cutoff, and those of its
    /// BLEND surfaces where it is below each ray's threshold, for closest-hit
    /// and occlusion queries alike (None, or a texturing without cut-outs:
    /// every primitive is opaque).
    pub fn set_alpha_mask(&mut self, texturing: Option<Arc<Texturing>>) {
        let texturing = texturing.filter(|t| t.has_masks());
        let n_tri = self.triangles.len();
        for p in &mut self.packed {
            let i = (p.prim & INDEX_BITS) as usize;
            let masked = p.prim & SPHERE_BIT == 0
                && i < n_tri
                && texturing.as_ref().is_some_and(|t| t.is_masked(self.info[i].surface));
            p.prim = if masked { p.prim | MASKED_BIT } else { p.prim & !MASKED_BIT };
        }
        self.alpha = texturing;
        // The binary BVH stays: cut-outs change the primitives' flags, not
        // their bounds.
        self.wide = OnceLock::new();
        self.cwbvh = OnceLock::new();
    }

    /// The texturing set by [`Accel::set_alpha_mask`], if the scene has cut-outs.
    pub fn alpha_mask(&self) -> Option<&Arc<Texturing>> {
        self.alpha.as_ref()
    }

    /// Whether a candidate hit on packed primitive `prim` (with its bits)
    /// counts: always, unless it is a cut-out transparent there.
    #[inline(always)]
    fn counts(&self, prim: u32, b1: f32, b2: f32, ray: &Ray) -> bool {
        if prim & MASKED_BIT == 0 {
            return true;
        }
        let i = prim & INDEX_BITS;
        self.alpha.as_ref().is_none_or(|t| {
            let u = || crate::texture::blend_threshold(ray.origin, ray.dir, i);
            t.is_there_at(self.info[i as usize].surface, i, Vec2::new(b1, b2), u)
        })
    }

    /// Primitive `p`'s hit (t, b1, b2) in (epsilon, ray.t_max) where it
    /// counts ([`Accel::counts`]): the single-ray test of packed primitives.
    #[inline(always)]
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    fn counted_hit(&self, p: &PackedPrim, ray: &Ray) -> Option<(f32, f32, f32)> {
        let (t, b1, b2) = p.intersect(ray, self.epsilon);
        (t < ray.t_max && self.counts(p.prim, b1, b2, ray)).then_some((t, b1, b2))
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.bounds_min, self.bounds_max)
    }

    /// Length of the scene's bounding-box diagonal (1 for an empty scene).
    pub fn diagonal(&self) -> f32 {
        if self.surface_of.is_empty() { 1.0 } else { (self.bounds_max - self.bounds_min).length() }
    }

    /// Every triangle with its surface id (for rasterization).
    pub fn triangles(&self) -> impl ExactSizeIterator<Item = (&Triangle, u32)> {
        self.triangles.iter().zip(self.surface_of.iter().copied())
    }

    /// Every analytic sphere with its surface id.
    pub fn spheres(&self) -> impl Iterator<Item = (&Sphere, u32)> {
        self.spheres.iter().zip(self.surface_of[self.triangles.len()..].iter().copied())
    }

    /// Triangle `prim` of the joint primitive space (None for a sphere).
    pub fn triangle(&self, prim: u32) -> Option<&Triangle> {
        self.triangles.get(prim as usize)
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn sphere_count(&self) -> usize {
        self.spheres.len()
    }

    /// Closest intersection in (epsilon, ray.t_max).
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if let Some(wide) = self.wide_bvh() {
            let eps = self.epsilon;
            let single = |k: usize, ray: &Ray| self.counted_hit(&wide.prims[k], ray);
            // SAFETY: a WideBvh exists only where the CPU has AVX2.
            let (t, k, b1, b2) = unsafe { super::wide::avx2::closest(wide, ray, eps, single) }?;
            let prim = (wide.prims[k as usize].prim & INDEX_BITS) as usize;
            let mut hit = None;
            self.hit_record(ray, t, prim, b1, b2, &mut hit);
            return hit;
        }
        self.intersect_cwbvh(ray)
    }

    /// [`Accel::intersect`] through the CWBVH (where the wide BVH cannot run).
    fn intersect_cwbvh(&self, ray: &Ray) -> Option<Hit> {
        let Cwbvh { bvh, packed } = self.cwbvh()?;
        let eps = self.epsilon;
        let node_ray = super::obvhs_ray(ray.origin, ray.dir, ray.t_max);
        // The primitive test is written into obvhs's traversal loop (its
        // `traverse!` macro) rather than passed as a closure, so the compiler
        // inlines it: photon tracing spends most of its time here.
        let (mut node_test_ray, mut prim_ray) = (node_ray, *ray);
        let mut best = (u32::MAX, 0.0f32, 0.0f32);
        let mut state = bvh.new_traversal(node_ray.direction);
        let mut node;
        obvhs::traverse!(bvh, node, state, node.intersect_ray(&node_test_ray, state.oct_inv4), {
            let packed = &packed[state.primitive_id as usize];
            let (t, b1, b2) = packed.intersect(&prim_ray, eps);
            if t < prim_ray.t_max && self.counts(packed.prim, b1, b2, ray) {
                best = (packed.prim & INDEX_BITS, b1, b2);
                prim_ray.t_max = t;
                node_test_ray.tmax = t;
            }
        });
        if best.0 == u32::MAX {
            return None;
        }
        let mut hit = None;
        self.hit_record(ray, prim_ray.t_max, best.0 as usize, best.1, best.2, &mut hit);
        hit
    }

    /// The hit of `ray` at `t` on primitive `prim` (joint index space) at
    /// barycentrics (b1, b2), written into `out`. Never inlined: inlined
    /// into the path tracer's step, the hit went through two temporaries,
    /// each copied with wider loads than its stores, and the copies
    /// stalled (perf put 7% of the step's samples there; -3.9% wall time
    /// without them). Written in place, not returned: the packet's caller
    /// copied a returned hit into its `Option` with 8- and 16-byte loads
    /// over this function's 4-byte stores, and waited on them (perf: 11%
    /// of `trace_in_packets`' samples after the lane step and packet
    /// shadow rays; -1.6% wall).
    #[inline(never)]
    fn hit_record(&self, ray: &Ray, t: f32, prim: usize, b1: f32, b2: f32, out: &mut Option<Hit>) {
        let point = ray.at(t);
        let info = self.info[prim];
        let (geometric_normal, shading_normal) = if prim >= self.triangles.len() {
            let s = &self.spheres[prim - self.triangles.len()];
            let n = ((point - s.center) / s.radius).normalize();
            (n, n)
        } else if info.smooth {
            let ng = info.normal;
            let ns = self.triangles[prim].shading_normal(b1, b2);
            // Keep the shading normal on the geometric side (OBJ normals may disagree).
            (ng, if ns.dot(ng) < 0.0 { -ns } else { ns })
        } else {
            (info.normal, info.normal)
        };
        *out = Some(Hit {
            t,
            point,
            geometric_normal,
            shading_normal,
            surface: info.surface,
            prim: prim as u32,
            barycentrics: Vec2::new(b1, b2),
        });
    }

    /// The wide BVH, built on first use.
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    fn wide_bvh(&self) -> Option<&WideBvh> {
        self.wide.get_or_init(|| WideBvh::build(&self.packed, self.binary_bvh()?)).as_ref()
    }

    /// Builds now what the first query would build: the binary BVH and,
    /// where the CPU runs it, the wide one (else the CWBVH). For timing a
    /// posed scene's cost, and for building off the thread that queries.
    pub fn build_bvhs(&self) {
        if self.wide_bvh().is_none() {
            self.cwbvh();
        }
        self.binary_bvh();
    }

    /// The binary BVH of obvhs's PLOC builder (medium build, leaves of up
    /// to `wide::LEAF_PRIMS`, one of its blocks) over the primitives, built on first use;
    /// None for an empty scene. `Bvh2::primitive_indices` are in the joint
    /// index space.
    pub(crate) fn binary_bvh(&self) -> Option<&Bvh2> {
        if self.packed.is_empty() {
            return None;
        }
        Some(self.bvh2.get_or_init(|| {
            let params =
                BvhBuildParams { max_prims_per_leaf: super::wide::LEAF_PRIMS, ..BvhBuildParams::medium_build() };
            super::bvh_build::build_bvh2(&prim_bounds(&self.triangles, &self.spheres), params)
        }))
    }

    /// The CWBVH, built on first use (None for an empty scene).
    fn cwbvh(&self) -> Option<&Cwbvh> {
        self.cwbvh
            .get_or_init(|| {
                let bounds = prim_bounds(&self.triangles, &self.spheres);
                if bounds.is_empty() {
                    return None;
                }
                let bvh = super::bvh_build::build_cwbvh(&bounds, BvhBuildParams::medium_build());
                let packed = bvh.primitive_indices.iter().map(|&i| self.packed[i as usize]).collect();
                Some(Cwbvh { bvh, packed })
            })
            .as_ref()
    }

    /// Closest hits of up to `LANES` rays at once, written to `hits` (None
    /// lanes are skipped and their entries left as they were): the same
    /// hits as [`Accel::intersect`] lane by lane, cheaper where the CPU runs
    /// packets (`geometry::packet`). The rays may be borrowed (`&Ray`), so
    /// a caller need not copy rays it has just written: a wide load of a
    /// fresh copy stalls on its narrower stores.
    pub fn intersect_packet<R: Borrow<Ray>>(&self, rays: &[Option<R>; LANES], hits: &mut [Option<Hit>; LANES]) {
        #[cfg(target_arch = "x86_64")]
        if let Some(bvh) = self.wide_bvh() {
            let eps = self.epsilon;
            let single = |k: usize, ray: &Ray| self.counted_hit(&bvh.prims[k], ray);
            // SAFETY: a WideBvh exists only where the CPU has AVX2.
            let lanes = unsafe { super::packet::avx2::closest(bvh, rays, eps, single) };
            for (l, ray) in rays.iter().enumerate() {
                let Some(ray) = ray.as_ref().map(R::borrow) else { continue };
                let k = lanes.prim[l];
                if k == u32::MAX {
                    hits[l] = None;
                } else {
                    let prim = (bvh.prims[k as usize].prim & INDEX_BITS) as usize;
                    self.hit_record(ray, lanes.t[l], prim, lanes.b1[l], lanes.b2[l], &mut hits[l]);
                }
            }
            return;
        }
        for (ray, hit) in rays.iter().zip(hits) {
            if let Some(ray) = ray {
                *hit = self.intersect(ray.borrow());
            }
        }
    }

    /// True if anything blocks the open segment (epsilon, ray.t_max).
    /// Not inlined: inlined into the path's step it saved 0.4% of a
    /// path's instructions and cost 5-10% of its wall time.
    pub fn occluded(&self, ray: &Ray) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(wide) = self.wide_bvh() {
            let eps = self.epsilon;
            let single = |k: usize, ray: &Ray| self.counted_hit(&wide.prims[k], ray).is_some();
            // SAFETY: a WideBvh exists only where the CPU has AVX2.
            return unsafe { super::wide::avx2::occluded(wide, ray, eps, single) };
        }
        self.occluded_cwbvh(ray)
    }

    /// Which of a packet's rays something blocks (bit l for lane l;
    /// inactive lanes are clear): [`Accel::occluded`] lane by lane, in one
    /// packet where the CPU runs packets (`geometry::packet`).
    pub fn occluded_packet(&self, rays: &RayLanes) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if let Some(wide) = self.wide_bvh() {
            let eps = self.epsilon;
            let single = |k: usize, ray: &Ray| self.counted_hit(&wide.prims[k], ray).is_some();
            // SAFETY: a WideBvh exists only where the CPU has AVX2.
            return unsafe { super::packet::avx2::occluded(wide, rays, eps, single) };
        }
        let active = (0..LANES).filter(|l| rays.active & (1 << l) != 0);
        active.filter(|&l| self.occluded(&rays.ray(l))).fold(0, |bits, l| bits | 1 << l)
    }

    /// [`Accel::occluded`] through the CWBVH.
    fn occluded_cwbvh(&self, ray: &Ray) -> bool {
        let Some(Cwbvh { bvh, packed }) = self.cwbvh() else {
            return false;
        };
        let eps = self.epsilon;
        let node_ray = super::obvhs_ray(ray.origin, ray.dir, ray.t_max);
        let mut state = bvh.new_traversal(node_ray.direction);
        let mut node;
        let mut blocked = false;
        'search: {
            obvhs::traverse!(bvh, node, state, node.intersect_ray(&node_ray, state.oct_inv4), {
                let packed = &packed[state.primitive_id as usize];
                let (t, b1, b2) = packed.intersect(ray, eps);
                if t < ray.t_max && self.counts(packed.prim, b1, b2, ray) {
                    blocked = true;
                    break 'search;
                }
            });
        }
        blocked
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, uniform_sphere};

    fn random_scene() -> (Vec<Triangle>, Vec<Sphere>) {
        let mut rng = Rng::for_item(11, 0);
        let mut tris = Vec::new();
        for _ in 0..300 {
            let c = (rng.next_2d().extend(rng.next_f32()) - 0.5) * 10.0;
            let v = [0, 1, 2].map(|_| c + uniform_sphere(rng.next_2d()) * 0.7);
            tris.push(Triangle { v, normals: None });
        }
        let spheres = (0..40)
            .map(|_| Sphere { center: (rng.next_2d().extend(rng.next_f32()) - 0.5) * 10.0, radius: 0.3 })
            .collect();
        (tris, spheres)
    }

    /// Rays along the axes hit flat, axis-aligned geometry (walls of a box).
    #[test]
    fn axis_aligned_rays_hit_flat_geometry() {
        for n in 1..6u32 {
            let tris: Vec<Triangle> = (0..n)
                .map(|i| {
                    let z = -(i as f32);
                    Triangle {
                        v: [Vec3::new(0.0, 0.0, z), Vec3::new(2.0, 0.0, z), Vec3::new(0.0, 2.0, z)],
                        normals: None,
                    }
                })
                .collect();
            let accel = Accel::build(tris, (0..n).collect(), vec![], vec![]);
            let hit = accel.intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z));
            assert!(hit.is_some_and(|h| (h.t - 1.0).abs() < 1e-6), "{n} triangles: {hit:?}");
            assert!(accel.occluded(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z)));
        }
    }

    /// Packets find what single rays find: the same t to the bit, the same
    /// surface, with lanes left empty and rays of finite length among them.
    fn packets_match_single_rays(accel: &Accel, rays: &[Ray]) {
        assert_eq!(accel.wide_bvh().is_some(), super::super::packet::avx2_available());
        for (n, chunk) in rays.chunks(LANES).enumerate() {
            // Every fifth packet has a hole; every third ray ends just
            // before or after its hit.
            let lanes: [Option<Ray>; LANES] = std::array::from_fn(|l| {
                let mut ray = *chunk.get(l)?;
                if (n * LANES + l).is_multiple_of(3) {
                    ray.t_max = accel.intersect(&ray).map_or(1.0, |h| h.t * if l % 2 == 0 { 0.999 } else { 1.001 });
                }
                (n % 5 != 0 || l != 3).then_some(ray)
            });
            let mut hits = [None; LANES];
            accel.intersect_packet(&lanes, &mut hits);
            let blocked = accel.occluded_packet(&RayLanes::gather(&lanes));
            for l in 0..LANES {
                let single = lanes[l].is_some_and(|r| accel.occluded(&r));
                assert_eq!(blocked & (1 << l) != 0, single, "lane {l}: {:?}", lanes[l]);
                let single = lanes[l].and_then(|r| accel.intersect(&r));
                match (single, hits[l]) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert_eq!(a.t.to_bits(), b.t.to_bits(), "lane {l}: t {} vs {}", a.t, b.t);
                        assert_eq!((a.surface, a.point, a.geometric_normal), (b.surface, b.point, b.geometric_normal));
                    }
                    (a, b) => panic!("lane {l}: single {a:?} vs packet {b:?}"),
                }
            }
        }
    }

    #[test]
    fn packets_match_single_rays_on_random_triangles_and_spheres() {
        let (tris, spheres) = random_scene();
        let accel = random_accel(&tris, &spheres);
        let mut rng = Rng::for_item(13, 0);
        let rays: Vec<Ray> = (0..4000)
            .map(|_| Ray::new((rng.next_2d().extend(rng.next_f32()) - 0.5) * 12.0, uniform_sphere(rng.next_2d())))
            .collect();
        packets_match_single_rays(&accel, &rays);
    }

    /// Axis-aligned walls (flat boxes), rays from them as bounces leave them.
    #[test]
    fn packets_match_single_rays_in_the_built_in_boxes() {
        for name in ["cornell-box", "cornell-caustic"] {
            let scene = crate::scene::Scene::load(name).unwrap();
            let rays = camera_and_bounce_rays(&scene, 14);
            packets_match_single_rays(&scene.accel, &rays);
        }
    }

    /// Up to 4,000 camera rays of `scene` and a diffuse bounce from each
    /// one's hit (found through the CWBVH): rays leaving flat walls, some
    /// at corners.
    fn camera_and_bounce_rays(scene: &crate::scene::Scene, seed: u64) -> Vec<Ray> {
        let mut rng = Rng::for_item(seed, 0);
        (0..4000)
            .filter_map(|_| {
                let ray = scene.camera.ray(glam::Vec2::new(rng.next_f32() * 64.0, rng.next_f32() * 64.0));
                let hit = scene.accel.intersect_cwbvh(&ray)?;
                let n = hit.geometric_normal * -ray.dir.dot(hit.geometric_normal).signum();
                let dir = crate::sampling::local_to_world(crate::sampling::cosine_hemisphere(rng.next_2d()), n);
                Some([ray, Ray::new(hit.point, dir)])
            })
            .flatten()
            .collect()
    }

    /// Shadow rays in packets, as the path tracer casts them: from points
    /// on the boxes' surfaces to a point just under the ceiling, each
    /// ending just short of it (the glass ball of `cornell-caustic` is a
    /// sphere, which a lane tests on its own). Both answers occur, and
    /// every lane's is a single ray's.
    #[test]
    fn shadow_packets_match_single_rays_in_the_built_in_boxes() {
        for name in ["cornell-box", "cornell-caustic"] {
            let scene = crate::scene::Scene::load(name).unwrap();
            let (lo, hi) = scene.accel.bounds();
            let light = Vec3::new((lo.x + hi.x) / 2.0, hi.y - 0.01 * (hi.y - lo.y), (lo.z + hi.z) / 2.0);
            let rays = camera_and_bounce_rays(&scene, 17);
            let shadow_rays: Vec<Ray> = rays
                .iter()
                .filter_map(|ray| scene.accel.intersect(ray))
                .map(|hit| {
                    let to = light - hit.point;
                    Ray { t_max: to.length() * (1.0 - 1e-4), ..Ray::new(hit.point, to.normalize()) }
                })
                .collect();
            let (mut blocked, mut clear) = (0, 0);
            for chunk in shadow_rays.chunks(LANES) {
                let lanes: [Option<&Ray>; LANES] = std::array::from_fn(|l| chunk.get(l));
                let bits = scene.accel.occluded_packet(&RayLanes::gather(&lanes));
                for (l, ray) in chunk.iter().enumerate() {
                    assert_eq!(bits & (1 << l) != 0, scene.accel.occluded(ray), "{name} lane {l}: {ray:?}");
                    if scene.accel.occluded(ray) { blocked += 1 } else { clear += 1 }
                }
                assert_eq!(bits >> chunk.len(), 0, "{name}: empty lanes are clear");
            }
            assert!(blocked > 20 && clear > shadow_rays.len() / 2, "{name}: {blocked} blocked, {clear} clear");
        }
    }

    /// The wide BVH finds what the CWBVH finds: the same t to the bit, the
    /// same surface, the same occlusion, on random triangles and spheres
    /// and on rays bouncing in the built-in boxes (flat walls, corners).
    #[test]
    fn the_wide_bvh_matches_the_cwbvh() {
        let (tris, spheres) = random_scene();
        let mut rng = Rng::for_item(15, 0);
        let random_rays: Vec<Ray> = (0..4000)
            .map(|i| {
                let mut ray =
                    Ray::new((rng.next_2d().extend(rng.next_f32()) - 0.5) * 12.0, uniform_sphere(rng.next_2d()));
                if i % 3 == 0 {
                    ray.t_max = rng.next_f32() * 6.0;
                }
                ray
            })
            .collect();
        let mut cases = vec![(random_accel(&tris, &spheres), random_rays)];
        for name in ["cornell-box", "cornell-caustic"] {
            let scene = crate::scene::Scene::load(name).unwrap();
            let rays = camera_and_bounce_rays(&scene, 16);
            cases.push((scene.accel, rays));
        }
        for (accel, rays) in cases {
            assert_eq!(accel.wide_bvh().is_some(), super::super::packet::avx2_available());
            let (mut hits, mut blocked, mut corners) = (0, 0, 0);
            for ray in &rays {
                match (accel.intersect_cwbvh(ray), accel.intersect(ray)) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        // Same t to the bit; of two surfaces at exactly the
                        // same distance either may be reported.
                        assert_eq!(a.t.to_bits(), b.t.to_bits(), "{ray:?}: t {} vs {}", a.t, b.t);
                        assert_eq!(a.point, b.point);
                        hits += 1;
                    }
                    // A ray leaving a wall right at a corner meets the
                    // other wall within 1e-4 of its origin, where the
                    // CWBVH's boxes, quantised outward to bytes, still miss
                    // (`geometry::packet`'s notes): the wide BVH's float
                    // boxes find it.
                    (None, Some(b)) if b.t < 1e-4 * accel.diagonal() => {
                        corners += 1;
                        continue;
                    }
                    (a, b) => panic!("{ray:?}: CWBVH {a:?} vs wide {b:?}"),
                }
                assert_eq!(accel.occluded_cwbvh(ray), accel.occluded(ray), "{ray:?}");
                blocked += usize::from(accel.occluded(ray));
            }
            // Both answers occur often enough to mean something, and the
            // corners are rare.
            assert!(hits > rays.len() / 10 && blocked > rays.len() / 10, "{hits} hits, {blocked} blocked");
            eprintln!("{} rays: {hits} hits, {blocked} blocked, {corners} corner hits the CWBVH missed", rays.len());
            assert!(corners * 500 < rays.len(), "{corners} corner hits the CWBVH missed");
        }
    }

    /// A tree too deep for the wide traversal's stack (PLOC on identical
    /// boxes makes a chain) is answered through the CWBVH instead.
    #[test]
    fn identical_triangles_are_found_whatever_the_tree() {
        let v = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let n = 3000;
        let tris = vec![Triangle { v, normals: None }; n];
        let accel = Accel::build(tris, (0..n as u32).collect(), vec![], vec![]);
        let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        assert!(accel.intersect(&ray).is_some_and(|h| (h.t - 1.0).abs() < 1e-6));
        assert!(accel.occluded(&ray));
        let miss = Ray::new(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z);
        assert!(accel.intersect(&miss).is_none() && !accel.occluded(&miss));
    }

    /// The BVH of `random_scene`: triangle i is surface i, sphere i 1000 + i.
    fn random_accel(tris: &[Triangle], spheres: &[Sphere]) -> Accel {
        Accel::build(
            tris.to_vec(),
            (0..tris.len() as u32).collect(),
            spheres.to_vec(),
            (0..spheres.len() as u32).map(|i| 1000 + i).collect(),
        )
    }

    /// `random_scene` bent: each primitive turned about the y axis by an
    /// angle growing with its height `bend` (radians a unit), as a skinned
    /// limb bends; the spheres moved the same way.
    fn bent_scene(bend: f32, shift: Vec3) -> (Vec<Triangle>, Vec<Sphere>) {
        let (tris, spheres) = random_scene();
        let move_point = |p: Vec3| glam::Quat::from_rotation_y(bend * p.y) * p + shift;
        let tris = tris.iter().map(|t| Triangle { v: t.v.map(move_point), normals: None }).collect();
        let spheres = spheres.iter().map(|s| Sphere { center: move_point(s.center), ..*s }).collect();
        (tris, spheres)
    }

    /// Closest hits and occlusion of random rays: the same in `a` and `b`.
    fn same_answers(a: &Accel, b: &Accel) {
        let mut rng = Rng::for_item(21, 0);
        let mut hits = 0;
        for _ in 0..3000 {
            let ray = Ray::new((rng.next_2d().extend(rng.next_f32()) - 0.5) * 12.0, uniform_sphere(rng.next_2d()));
            let (x, y) = (a.intersect(&ray), b.intersect(&ray));
            assert_eq!(x.map(|h| (h.t.to_bits(), h.prim)), y.map(|h| (h.t.to_bits(), h.prim)), "{ray:?}");
            assert_eq!(a.occluded(&ray), b.occluded(&ray), "{ray:?}");
            hits += x.is_some() as usize;
        }
        assert!(hits > 300, "{hits} hits of 3000");
    }

    /// A scene bent a little is answered through its rest BVH refitted
    /// (no build), exactly as through a tree built for it; bent or moved so
    /// far that the refitted tree would cost more than REFIT_COST_LIMIT
    /// times its rest tree, it builds its own.
    #[test]
    fn moved_primitives_refit_the_rest_bvh_unless_it_costs_too_much() {
        let (tris, spheres) = random_scene();
        let rest = random_accel(&tris, &spheres);
        let surfaces = |n: usize, first: u32| (first..first + n as u32).collect::<Vec<u32>>();
        let moved = |bend: f32, shift: Vec3| {
            let (t, s) = bent_scene(bend, shift);
            let (nt, ns) = (t.len(), s.len());
            let fresh = random_accel(&t, &s);
            (Accel::build_moved(t, surfaces(nt, 0), s, surfaces(ns, 1000), &rest), fresh)
        };
        let (a, fresh) = moved(0.05, Vec3::new(0.3, 0.0, 0.0));
        assert!(a.bvh2.get().is_some(), "a small bend refits the rest BVH");
        let refit_cost = super::super::bvh_build::relative_cost(a.bvh2.get().unwrap());
        let rest_cost = super::super::bvh_build::relative_cost(rest.binary_bvh().unwrap());
        assert!(
            refit_cost >= rest_cost * 0.9 && refit_cost <= REFIT_COST_LIMIT * rest_cost,
            "{refit_cost} {rest_cost}"
        );
        eprintln!("refitted after a small bend: {:.3}× the rest tree's cost", refit_cost / rest_cost);
        same_answers(&a, &fresh);
        // The flat BVH the GPU traverses is the refitted tree too.
        let flat = super::super::FlatBvh::new(&a);
        let mut rng = Rng::for_item(22, 0);
        for _ in 0..500 {
            let ray = Ray::new((rng.next_2d().extend(rng.next_f32()) - 0.5) * 12.0, uniform_sphere(rng.next_2d()));
            let want = fresh.intersect(&ray).map(|h| h.prim);
            assert_eq!(flat.intersect(&ray).map(|(_, k)| flat.source[k]), want, "{ray:?}");
        }
        // A quarter turn per unit of height scrambles the tree's boxes.
        let (b, fresh) = moved(1.6, Vec3::ZERO);
        assert!(b.bvh2.get().is_none(), "a refit costing {}× was kept", {
            let t = super::super::bvh_build::refit(rest.binary_bvh().unwrap(), &prim_bounds(&b.triangles, &b.spheres));
            super::super::bvh_build::relative_cost(&t) / rest_cost
        });
        same_answers(&b, &fresh);
        // Other primitives: no refit.
        let (t, s) = bent_scene(0.0, Vec3::ZERO);
        let fewer = Accel::build_moved(t[1..].to_vec(), surfaces(t.len() - 1, 0), s, surfaces(40, 1000), &rest);
        assert!(fewer.bvh2.get().is_none());
    }

    /// The BVH must find exactly what a brute-force loop over all primitives finds.
    #[test]
    fn bvh_matches_brute_force() {
        let (tris, spheres) = random_scene();
        let accel = random_accel(&tris, &spheres);
        let mut rng = Rng::for_item(12, 0);
        for _ in 0..2000 {
            let ray = Ray::new((rng.next_2d().extend(rng.next_f32()) - 0.5) * 12.0, uniform_sphere(rng.next_2d()));
            let mut best: Option<(f32, u32)> = None;
            for (i, t) in tris.iter().enumerate() {
                if let Some((th, _, _)) = t.intersect(&ray, accel.epsilon) {
                    if best.is_none_or(|b| th < b.0) {
                        best = Some((th, i as u32));
                    }
                }
            }
            for (i, s) in spheres.iter().enumerate() {
                if let Some(th) = s.intersect(&ray, accel.epsilon) {
                    if best.is_none_or(|b| th < b.0) {
                        best = Some((th, 1000 + i as u32));
                    }
                }
            }
            let got = accel.intersect(&ray);
            match (best, got) {
                (None, None) => assert!(!accel.occluded(&ray)),
                (Some((t, s)), Some(h)) => {
                    assert!((t - h.t).abs() < 1e-4, "t {t} vs {}", h.t);
                    assert_eq!(s, h.surface);
                    assert!(accel.occluded(&ray));
                    let mut short = ray;
                    short.t_max = t * 0.999;
                    assert!(!accel.occluded(&short));
                }
                (b, g) => panic!("brute force {b:?} vs bvh {g:?}"),
            }
        }
    }
}
