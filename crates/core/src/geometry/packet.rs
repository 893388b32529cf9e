//! Eight rays at once: a packet traversal of a binary BVH in AVX2, for
//! the path tracer's closest hits (`render::path` runs eight paths side
//! by side).
//!
//! A single ray pays for each node's loads and each triangle's on its own;
//! eight rays that go through the tree together pay for them once, each
//! node's box and each triangle tested against all eight in one set of
//! 8-wide instructions. On the Cornell box with incoherent bounce rays this
//! found a closest hit in about 37 ns a ray in the bare loop, against
//! 57–63 ns through the CWBVH (BENCHMARKS.md, "Eight rays at once"); the
//! single-ray `wide` BVH that replaced the CWBVH does not beat it either
//! (cachegrind, path tracer on the Cornell box: 2,311 instructions and 16
//! mispredicted branches a path for closest hits one ray at a time,
//! against 1,889 and 9 in packets).
//!
//! The triangle test is `PackedPrim::intersect`'s Möller–Trumbore,
//! operation for operation (`simd8::triangle`), so a lane finds the same t,
//! bit for bit, as a single ray (checked by a test); spheres and alpha
//! cut-outs take the single-ray test lane by lane. Only x86-64 with AVX2
//! (checked at run time) runs packets; elsewhere, and for a BVH deeper than
//! the traversal stack, each lane is cast on its own (`Accel::intersect`).
//! Packets and the CWBVH differ only at the rarest edges: a ray leaving a
//! surface right at a corner of the box meets the other wall within 1e-4
//! of its origin, which the CWBVH's quantised boxes miss and this traversal
//! finds (34 of 1.6 M camera and bounce rays in the Cornell box), and of
//! two primitives at exactly the same distance either may be reported.

// Elsewhere than on x86-64 the traversal is compiled out and nothing builds
// a packet BVH.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]

use super::accel::{PackedPrim, PrimBounds};
use obvhs::BvhBuildParams;

/// Rays per packet.
pub const LANES: usize = 8;

/// Nodes a traversal can hold pending: deeper trees are cast ray by ray.
const STACK: usize = 64;

/// A node of the binary BVH: inner when `count` is 0 (children at `first`
/// and `first + 1`), else a leaf of primitives `first .. first + count`.
#[derive(Clone, Copy, Debug)]
pub(super) struct PacketNode {
    pub min: [f32; 3],
    pub count: u32,
    pub max: [f32; 3],
    pub first: u32,
    /// Axis along which the children's centres lie furthest apart, and
    /// whether the first child's is the lower: a packet whose directions
    /// sum positive along it visits the first child first.
    pub axis: u8,
    pub first_is_lower: bool,
}

/// The packet traversal's BVH: nodes, and primitives in leaf order.
#[derive(Clone)]
pub(super) struct PacketBvh {
    pub nodes: Vec<PacketNode>,
    pub prims: Vec<PackedPrim>,
}

impl PacketBvh {
    /// A BVH over `prims` (in the joint index space, with their bounds), or
    /// None where packets cannot run: no AVX2, no primitives, or a tree
    /// deeper than the traversal stack.
    pub fn build(prims: &[PackedPrim], bounds: &[PrimBounds]) -> Option<PacketBvh> {
        if !avx2_available() || prims.is_empty() {
            return None;
        }
        let bvh = super::bvh_build::build_bvh2(bounds, BvhBuildParams::medium_build());
        if super::bvh_build::depth(&bvh) + 2 > STACK {
            return None;
        }
        let center = |i: u32| {
            let b = bvh.nodes[i as usize].aabb();
            (b.min + b.max) * 0.5
        };
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| {
                let (mut axis, mut first_is_lower) = (0u8, true);
                if n.prim_count == 0 {
                    let d = center(n.first_index + 1) - center(n.first_index);
                    let a = d.abs();
                    axis = if a.x >= a.y && a.x >= a.z {
                        0
                    } else if a.y >= a.z {
                        1
                    } else {
                        2
                    };
                    first_is_lower = d[axis as usize] >= 0.0;
                }
                PacketNode {
                    min: n.aabb().min.to_array(),
                    count: n.prim_count,
                    max: n.aabb().max.to_array(),
                    first: n.first_index,
                    axis,
                    first_is_lower,
                }
            })
            .collect();
        let prims = bvh.primitive_indices.iter().map(|&i| prims[i as usize]).collect();
        Some(PacketBvh { nodes, prims })
    }
}

/// Whether this CPU runs the packet traversal.
pub fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// What a lane found: the nearest t (the ray's t_max where nothing), the
/// primitive in `PacketBvh::prims` order (`u32::MAX` where nothing), and
/// the barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug)]
pub(super) struct LaneHits {
    pub t: [f32; LANES],
    pub prim: [u32; LANES],
    pub b1: [f32; LANES],
    pub b2: [f32; LANES],
}

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2 {
    //! The traversal in AVX2 intrinsics; callers must have checked
    //! `avx2_available` (a `PacketBvh` exists only where it holds).

    use super::{LANES, LaneHits, PacketBvh, STACK};
    use crate::geometry::Ray;
    use crate::geometry::accel::{INDEX_BITS, MASKED_BIT, SPHERE_BIT};
    use crate::geometry::simd8;
    use std::arch::x86_64::*;

    /// The rays of a packet, one register per component; inactive lanes
    /// have an all-zero `active` lane and never report a hit.
    struct Lanes {
        ox: __m256,
        oy: __m256,
        oz: __m256,
        dx: __m256,
        dy: __m256,
        dz: __m256,
        ix: __m256,
        iy: __m256,
        iz: __m256,
        active: __m256,
        /// Sign of the packet's summed direction per axis (true: positive).
        positive: [bool; 3],
    }

    #[target_feature(enable = "avx2")]
    fn load(rays: &[Option<Ray>; LANES]) -> (Lanes, [f32; LANES]) {
        let mut c = [[0.0f32; LANES]; 9];
        let mut t_max = [0.0f32; LANES];
        let mut active = [0.0f32; LANES];
        let mut sum = [0.0f32; 3];
        for (lane, ray) in rays.iter().enumerate() {
            let Some(r) = ray else {
                for component in &mut c[3..] {
                    component[lane] = 1.0;
                }
                continue;
            };
            let v = [r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z];
            for k in 0..6 {
                c[k][lane] = v[k];
            }
            for k in 0..3 {
                c[6 + k][lane] = simd8::slab_safe(v[3 + k]);
                sum[k] += v[3 + k];
            }
            t_max[lane] = r.t_max;
            active[lane] = f32::from_bits(u32::MAX);
        }
        // SAFETY: each array holds LANES = 8 floats.
        let ld = |a: &[f32; LANES]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        let lanes = Lanes {
            ox: ld(&c[0]),
            oy: ld(&c[1]),
            oz: ld(&c[2]),
            dx: ld(&c[3]),
            dy: ld(&c[4]),
            dz: ld(&c[5]),
            ix: _mm256_div_ps(_mm256_set1_ps(1.0), ld(&c[6])),
            iy: _mm256_div_ps(_mm256_set1_ps(1.0), ld(&c[7])),
            iz: _mm256_div_ps(_mm256_set1_ps(1.0), ld(&c[8])),
            active: ld(&active),
            positive: sum.map(|s| s >= 0.0),
        };
        (lanes, t_max)
    }

    /// Lanes whose ray meets the node's box before `t_max`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn slab(r: &Lanes, min: [f32; 3], max: [f32; 3], t_max: __m256) -> __m256 {
        let (_, hit) =
            simd8::slab(simd8::splat3(min), simd8::splat3(max), [r.ox, r.oy, r.oz], [r.ix, r.iy, r.iz], t_max);
        _mm256_and_ps(hit, r.active)
    }

    /// Möller–Trumbore against all lanes (`simd8::triangle`, the same t
    /// to the bit as `PackedPrim::intersect`): (hit mask, t, b1, b2).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn triangle(r: &Lanes, a: [f32; 3], e1: [f32; 3], e2: [f32; 3], eps: f32, t_max: __m256) -> [__m256; 4] {
        let (origin, dir) = ([r.ox, r.oy, r.oz], [r.dx, r.dy, r.dz]);
        let [ok, t, b1, b2] =
            simd8::triangle(origin, dir, simd8::splat3(a), simd8::splat3(e1), simd8::splat3(e2), eps, t_max);
        [_mm256_and_ps(ok, r.active), t, b1, b2]
    }

    /// The order to push an inner node's children: (pushed first, pushed
    /// last), the last being visited first.
    #[inline(always)]
    fn push_order(r: &Lanes, node: &super::PacketNode) -> (u32, u32) {
        let first_near = r.positive[node.axis as usize] == node.first_is_lower;
        if first_near { (node.first + 1, node.first) } else { (node.first, node.first + 1) }
    }

    /// Closest hits of the packet's rays. `single` tests one lane against a
    /// sphere or cut-out primitive (index in `bvh.prims`) up to a t_max and
    /// returns (t, b1, b2) where it counts.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub unsafe fn closest(
        bvh: &PacketBvh,
        rays: &[Option<Ray>; LANES],
        eps: f32,
        single: impl Fn(usize, &Ray) -> Option<(f32, f32, f32)>,
    ) -> LaneHits {
        let (r, t_max0) = load(rays);
        // SAFETY (all loads and stores below): arrays of LANES = 8 lanes.
        let mut t_max = unsafe { _mm256_loadu_ps(t_max0.as_ptr()) };
        let mut prim = _mm256_set1_epi32(-1);
        let (mut b1s, mut b2s) = (_mm256_setzero_ps(), _mm256_setzero_ps());
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &bvh.nodes[stack[top] as usize];
            let hit = slab(&r, node.min, node.max, t_max);
            let hit_bits = _mm256_movemask_ps(hit);
            if hit_bits == 0 {
                continue;
            }
            if node.count == 0 {
                let (far, near) = push_order(&r, node);
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
                continue;
            }
            for k in node.first..node.first + node.count {
                let p = &bvh.prims[k as usize];
                if p.prim & (SPHERE_BIT | MASKED_BIT) != 0 {
                    let mut t = [0.0f32; LANES];
                    let mut lane_prim = [0u32; LANES];
                    let (mut b1, mut b2) = ([0.0f32; LANES], [0.0f32; LANES]);
                    unsafe {
                        _mm256_storeu_ps(t.as_mut_ptr(), t_max);
                        _mm256_storeu_si256(lane_prim.as_mut_ptr() as *mut __m256i, prim);
                        _mm256_storeu_ps(b1.as_mut_ptr(), b1s);
                        _mm256_storeu_ps(b2.as_mut_ptr(), b2s);
                    }
                    for lane in (0..LANES).filter(|l| hit_bits & (1 << l) != 0) {
                        let Some(ray) = &rays[lane] else { continue };
                        let ray = Ray { t_max: t[lane], ..*ray };
                        if let Some((th, u, v)) = single(k as usize, &ray) {
                            (t[lane], lane_prim[lane], b1[lane], b2[lane]) = (th, k, u, v);
                        }
                    }
                    unsafe {
                        t_max = _mm256_loadu_ps(t.as_ptr());
                        prim = _mm256_loadu_si256(lane_prim.as_ptr() as *const __m256i);
                        b1s = _mm256_loadu_ps(b1.as_ptr());
                        b2s = _mm256_loadu_ps(b2.as_ptr());
                    }
                    continue;
                }
                let [ok, t, b1, b2] = triangle(&r, p.a.to_array(), p.b.to_array(), p.c.to_array(), eps, t_max);
                t_max = _mm256_blendv_ps(t_max, t, ok);
                b1s = _mm256_blendv_ps(b1s, b1, ok);
                b2s = _mm256_blendv_ps(b2s, b2, ok);
                prim = _mm256_blendv_epi8(prim, _mm256_set1_epi32(k as i32), _mm256_castps_si256(ok));
            }
        }
        let mut out = LaneHits { t: [0.0; LANES], prim: [0; LANES], b1: [0.0; LANES], b2: [0.0; LANES] };
        unsafe {
            _mm256_storeu_ps(out.t.as_mut_ptr(), t_max);
            _mm256_storeu_si256(out.prim.as_mut_ptr() as *mut __m256i, prim);
            _mm256_storeu_ps(out.b1.as_mut_ptr(), b1s);
            _mm256_storeu_ps(out.b2.as_mut_ptr(), b2s);
        }
        debug_assert!(out.prim.iter().all(|&p| p == u32::MAX || p & INDEX_BITS == p));
        out
    }
}
