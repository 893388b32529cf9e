//! Eight rays at once: a packet traversal of the wide BVH (`wide`) in
//! AVX2, for the path tracer's closest hits (`render::path` runs eight
//! paths side by side).
//!
//! A single ray pays for each box's loads and each triangle's on its own;
//! eight rays that go through the tree together pay for them once, each
//! child box and each triangle tested against all eight in one set of
//! 8-wide instructions. Counted on the path tracer (cachegrind, Cornell
//! box, per path): closest hits one ray at a time through the wide BVH
//! cost 2,311 instructions and 16 mispredicted branches, in packets 1,683
//! and 7.9 (through the binary BVH packets had before, 1,889 and 9.3).
//!
//! The triangle test is `PackedPrim::intersect`'s Möller–Trumbore,
//! operation for operation (`simd8::triangle`), so a lane finds the same t,
//! bit for bit, as a single ray (checked by a test); spheres and alpha
//! cut-outs take the single-ray test lane by lane. Only x86-64 with AVX2
//! (checked at run time) runs packets; elsewhere, and for a BVH deeper than
//! the traversal stack, each lane is cast on its own (`Accel::intersect`,
//! through the CWBVH). Packets and the CWBVH differ only at the rarest
//! edges: a ray leaving a surface right at a corner of the box meets the
//! other wall within 1e-4 of its origin, which the CWBVH's quantised boxes
//! miss and the wide BVH's float boxes find (34 of 1.6 M camera and bounce
//! rays in the Cornell box), and of two primitives at exactly the same
//! distance either may be reported.

// Elsewhere than on x86-64 the traversal is compiled out.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]

use super::Ray;
use std::borrow::Borrow;

/// Rays per packet.
pub const LANES: usize = 8;

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
/// primitive in `WideBvh::prims` order (`u32::MAX` where nothing), and
/// the barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug)]
pub(super) struct LaneHits {
    pub t: [f32; LANES],
    pub prim: [u32; LANES],
    pub b1: [f32; LANES],
    pub b2: [f32; LANES],
}

/// A packet's rays component by component: lane l holds the ray
/// `origin + t·dir`, t < `t_max[l]`, where bit l of `active` is set.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayLanes {
    pub origin: [[f32; LANES]; 3],
    pub dir: [[f32; LANES]; 3],
    pub t_max: [f32; LANES],
    pub active: u32,
}

impl RayLanes {
    /// The rays of the lanes that hold one. Always inlined: where the
    /// compiler left it a call of its own (perf: 2% of the Cornell box's
    /// samples) its rows went through memory once more.
    #[inline(always)]
    pub fn gather<R: Borrow<Ray>>(rays: &[Option<R>; LANES]) -> RayLanes {
        let mut lanes = RayLanes::default();
        for (l, ray) in rays.iter().enumerate() {
            let Some(ray) = ray.as_ref().map(R::borrow) else { continue };
            let (o, d) = (ray.origin, ray.dir);
            for (k, (o, d)) in [(o.x, d.x), (o.y, d.y), (o.z, d.z)].into_iter().enumerate() {
                (lanes.origin[k][l], lanes.dir[k][l]) = (o, d);
            }
            lanes.t_max[l] = ray.t_max;
            lanes.active |= 1 << l;
        }
        lanes
    }

    /// Lane l's ray.
    pub fn ray(&self, l: usize) -> Ray {
        let component = |c: &[[f32; LANES]; 3]| glam::Vec3::new(c[0][l], c[1][l], c[2][l]);
        Ray { t_max: self.t_max[l], ..Ray::new(component(&self.origin), component(&self.dir)) }
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2 {
    //! The traversal in AVX2 intrinsics; callers must have checked
    //! `avx2_available` (a `WideBvh` exists only where it holds).

    use super::{LANES, LaneHits, RayLanes};
    use crate::geometry::Ray;
    use crate::geometry::simd8;
    use crate::geometry::wide::{Block, LEAF, STACK, WIDTH, WideBvh, WideNode};
    use std::arch::x86_64::*;
    use std::borrow::Borrow;

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
    }

    /// A packet's rays in registers, and their t_max. An inactive lane's
    /// direction is (1, 1, 1), so that its inverse is finite.
    #[target_feature(enable = "avx2")]
    fn load(rays: &RayLanes) -> (Lanes, __m256) {
        let active = lane_mask(rays.active);
        // SAFETY: each row holds LANES = 8 floats.
        let ld = |a: &[f32; LANES]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        let dir = |k: usize| _mm256_blendv_ps(_mm256_set1_ps(1.0), ld(&rays.dir[k]), active);
        let (dx, dy, dz) = (dir(0), dir(1), dir(2));
        let lanes = Lanes {
            ox: ld(&rays.origin[0]),
            oy: ld(&rays.origin[1]),
            oz: ld(&rays.origin[2]),
            dx,
            dy,
            dz,
            ix: simd8::inverse_direction(dx),
            iy: simd8::inverse_direction(dy),
            iz: simd8::inverse_direction(dz),
            active,
        };
        (lanes, ld(&rays.t_max))
    }

    /// Each child of `node` whose box one of `lanes` meets before its
    /// `t_max`, in stored order: `visit(child, the lanes that meet it as
    /// bits)`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn children_met(r: &Lanes, node: &WideNode, t_max: __m256, lanes: __m256, mut visit: impl FnMut(u32, u32)) {
        let mut bits = u32::from(node.valid);
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let lo = simd8::splat3([node.lo[0][i], node.lo[1][i], node.lo[2][i]]);
            let hi = simd8::splat3([node.hi[0][i], node.hi[1][i], node.hi[2][i]]);
            let (_, hit) = simd8::slab(lo, hi, [r.ox, r.oy, r.oz], [r.ix, r.iy, r.iz], t_max);
            let meet = _mm256_movemask_ps(_mm256_and_ps(hit, lanes)) as u32;
            if meet != 0 {
                visit(node.child[i], meet);
            }
        }
    }

    /// Möller–Trumbore of `lanes` against the triangle in lane `k` of
    /// `block` (`simd8::triangle`, the same t to the bit as
    /// `PackedPrim::intersect`): (hit mask, t, b1, b2).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn triangle(r: &Lanes, block: &Block, k: usize, eps: f32, t_max: __m256, lanes: __m256) -> [__m256; 4] {
        let corner = |v: &[[f32; WIDTH]; 3]| simd8::splat3([v[0][k], v[1][k], v[2][k]]);
        let (origin, dir) = ([r.ox, r.oy, r.oz], [r.dx, r.dy, r.dz]);
        let [ok, t, b1, b2] =
            simd8::triangle(origin, dir, corner(&block.a), corner(&block.e1), corner(&block.e2), eps, t_max);
        [_mm256_and_ps(ok, lanes), t, b1, b2]
    }

    /// Closest hits of the packet's rays through the wide BVH. `single`
    /// tests one lane against a sphere or cut-out primitive (index in
    /// `bvh.prims`) up to a t_max and returns (t, b1, b2) where it counts.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub unsafe fn closest<R: Borrow<Ray>>(
        bvh: &WideBvh,
        rays: &[Option<R>; LANES],
        eps: f32,
        single: impl Fn(usize, &Ray) -> Option<(f32, f32, f32)>,
    ) -> LaneHits {
        use std::mem::MaybeUninit;
        let (r, mut t_max) = load(&RayLanes::gather(rays));
        let mut prim = _mm256_set1_epi32(-1);
        let (mut b1s, mut b2s) = (_mm256_setzero_ps(), _mm256_setzero_ps());
        let mut pending = [MaybeUninit::<u32>::uninit(); STACK];
        let (mut top, mut current) = (0usize, 0u32);
        loop {
            if current & LEAF == 0 {
                // Children in the order they are stored: ordering them
                // along the packet's summed direction (an insertion sort)
                // mispredicted more than it culled (cachegrind: +3.7%
                // cycles a path on the Cornell box, +2.5% on showcase.glb).
                children_met(&r, &bvh.nodes[current as usize], t_max, r.active, |child, _| {
                    pending[top] = MaybeUninit::new(child);
                    top += 1;
                });
            } else {
                let mut b = (current & !LEAF) as usize;
                loop {
                    let block = &bvh.blocks[b];
                    for lane in 0..WIDTH {
                        let k = block.prim[lane];
                        if k == u32::MAX {
                            break;
                        }
                        if block.single & (1 << lane) != 0 {
                            let mut t = [0.0f32; LANES];
                            let mut lane_prim = [0u32; LANES];
                            let (mut b1, mut b2) = ([0.0f32; LANES], [0.0f32; LANES]);
                            unsafe {
                                _mm256_storeu_ps(t.as_mut_ptr(), t_max);
                                _mm256_storeu_si256(lane_prim.as_mut_ptr() as *mut __m256i, prim);
                                _mm256_storeu_ps(b1.as_mut_ptr(), b1s);
                                _mm256_storeu_ps(b2.as_mut_ptr(), b2s);
                            }
                            for (l, ray) in rays.iter().enumerate() {
                                let Some(ray) = ray.as_ref().map(R::borrow) else { continue };
                                let ray = Ray { t_max: t[l], ..*ray };
                                if let Some((th, u, v)) = single(k as usize, &ray) {
                                    (t[l], lane_prim[l], b1[l], b2[l]) = (th, k, u, v);
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
                        let [ok, t, b1, b2] = triangle(&r, block, lane, eps, t_max, r.active);
                        t_max = _mm256_blendv_ps(t_max, t, ok);
                        b1s = _mm256_blendv_ps(b1s, b1, ok);
                        b2s = _mm256_blendv_ps(b2s, b2, ok);
                        prim = _mm256_blendv_epi8(prim, _mm256_set1_epi32(k as i32), _mm256_castps_si256(ok));
                    }
                    if !block.continues {
                        break;
                    }
                    b += 1;
                }
            }
            if top == 0 {
                break;
            }
            top -= 1;
            // SAFETY: entries below `top` are written.
            current = unsafe { pending[top].assume_init() };
        }
        let mut out = LaneHits { t: [0.0; LANES], prim: [0; LANES], b1: [0.0; LANES], b2: [0.0; LANES] };
        unsafe {
            _mm256_storeu_ps(out.t.as_mut_ptr(), t_max);
            _mm256_storeu_si256(out.prim.as_mut_ptr() as *mut __m256i, prim);
            _mm256_storeu_ps(out.b1.as_mut_ptr(), b1s);
            _mm256_storeu_ps(out.b2.as_mut_ptr(), b2s);
        }
        out
    }

    /// Eight bits, lane l's set where bit l of `bits` is.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn lane_mask(bits: u32) -> __m256 {
        let each = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let set = _mm256_and_si256(_mm256_set1_epi32(bits as i32), each);
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, each))
    }

    /// Which of the packet's rays something blocks in (`eps`, t_max): bit
    /// l for lane l. Each lane goes down exactly the nodes a single ray
    /// would (a child is entered with the lanes that meet its box), so it
    /// tests the same triangles with the same arithmetic and gets
    /// [`wide::avx2::occluded`](crate::geometry::wide)'s answer; a lane
    /// stops at its first blocker, the packet when every lane has one.
    /// `single` tests one lane's ray against a sphere or cut-out.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub unsafe fn occluded(bvh: &WideBvh, rays: &RayLanes, eps: f32, single: impl Fn(usize, &Ray) -> bool) -> u32 {
        use std::mem::MaybeUninit;
        let (r, t_max_lanes) = load(rays);
        let active = rays.active & 0xff;
        let mut blocked = 0u32;
        // (node or leaf, lanes that reached it)
        let mut pending = [MaybeUninit::<(u32, u32)>::uninit(); STACK];
        let (mut top, mut current, mut reached) = (0usize, 0u32, active);
        loop {
            let live = reached & !blocked;
            if live != 0 && current & LEAF == 0 {
                children_met(&r, &bvh.nodes[current as usize], t_max_lanes, lane_mask(live), |child, meet| {
                    pending[top] = MaybeUninit::new((child, meet));
                    top += 1;
                });
            } else if live != 0 {
                let mut b = (current & !LEAF) as usize;
                'leaf: loop {
                    let block = &bvh.blocks[b];
                    for lane in 0..WIDTH {
                        let k = block.prim[lane];
                        let live = reached & !blocked;
                        if k == u32::MAX || live == 0 {
                            break 'leaf;
                        }
                        if block.single & (1 << lane) != 0 {
                            for l in (0..LANES).filter(|l| live & (1 << l) != 0) {
                                if single(k as usize, &rays.ray(l)) {
                                    blocked |= 1 << l;
                                }
                            }
                            continue;
                        }
                        let [ok, ..] = triangle(&r, block, lane, eps, t_max_lanes, lane_mask(live));
                        blocked |= _mm256_movemask_ps(ok) as u32;
                    }
                    if !block.continues {
                        break;
                    }
                    b += 1;
                }
                if blocked == active {
                    return blocked;
                }
            }
            if top == 0 {
                return blocked;
            }
            top -= 1;
            // SAFETY: entries below `top` are written.
            (current, reached) = unsafe { pending[top].assume_init() };
        }
    }
}
