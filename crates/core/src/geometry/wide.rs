//! One ray through eight boxes at once: a BVH of eight-wide nodes with
//! leaves of triangles in blocks of eight, for single closest-hit and
//! occlusion queries in AVX2 (the layout Embree uses on CPUs).
//!
//! obvhs's CWBVH is eight-wide too, but it stores each child's box
//! quantised to bytes, which a ray pays to decode at every node, and it
//! tests a leaf's triangles one at a time through an index. Here a node
//! holds its children's boxes as floats, component by component, tested
//! with six loads; a leaf's triangles sit in the same component-by-component
//! form and are tested eight at once (`simd8::triangle`, which finds the
//! same t to the bit as `PackedPrim::intersect`). Spheres and alpha
//! cut-outs take the single-ray test lane by lane. Only x86-64 with AVX2
//! (checked at run time) builds this BVH; elsewhere, and for a tree deeper
//! than the traversal stack holds, `Accel` casts through the CWBVH.

// Elsewhere than on x86-64 the traversal is compiled out and nothing builds
// a wide BVH.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]

use super::accel::{MASKED_BIT, PackedPrim, SPHERE_BIT};
use obvhs::bvh2::Bvh2;

/// Children per node, triangles per block.
pub(super) const WIDTH: usize = 8;

/// A child that is a leaf: the low bits are its first block.
pub(super) const LEAF: u32 = 1 << 31;

/// Children a traversal can hold pending: a tree whose depth could need
/// more is not built.
pub(super) const STACK: usize = 256;

/// Primitives per leaf of the binary BVH the wide one is made from
/// (`Accel::binary_bvh`): one block.
pub(super) const LEAF_PRIMS: u32 = 8;

/// An inner node: its children's boxes, component by component.
#[repr(C, align(32))]
#[derive(Clone, Copy)]
pub(super) struct WideNode {
    pub(super) lo: [[f32; WIDTH]; 3],
    pub(super) hi: [[f32; WIDTH]; 3],
    /// An inner child's node index, or `LEAF` | a leaf's first block.
    pub(super) child: [u32; WIDTH],
    /// Bit i is set where slot i holds a child.
    pub(super) valid: u8,
}

/// Up to eight primitives of a leaf: triangles as (v0, e1, e2), component
/// by component. Unused lanes, and lanes of primitives the single-ray test
/// takes, hold NaN and never hit.
#[repr(C, align(32))]
#[derive(Clone, Copy)]
pub(super) struct Block {
    pub(super) a: [[f32; WIDTH]; 3],
    pub(super) e1: [[f32; WIDTH]; 3],
    pub(super) e2: [[f32; WIDTH]; 3],
    /// Each lane's primitive, an index in `WideBvh::prims`.
    pub(super) prim: [u32; WIDTH],
    /// Lanes whose primitive is a sphere or a cut-out.
    pub(super) single: u8,
    /// Whether the next block belongs to the same leaf.
    pub(super) continues: bool,
}

/// The wide BVH: nodes (the root first), leaf blocks, and the primitives
/// in block order.
#[derive(Clone)]
pub(super) struct WideBvh {
    pub(super) nodes: Vec<WideNode>,
    pub(super) blocks: Vec<Block>,
    pub prims: Vec<PackedPrim>,
}

impl WideBvh {
    /// A wide BVH over `prims` (in the joint index space) laid out from
    /// `bvh`, their binary BVH (leaves of up to `LEAF_PRIMS`), or None where
    /// it cannot run: no AVX2, no primitives, or a tree deeper than the
    /// traversal stack holds.
    pub fn build(prims: &[PackedPrim], bvh: &Bvh2) -> Option<WideBvh> {
        if !super::packet::avx2_available() || prims.is_empty() {
            return None;
        }
        let mut wide = WideBvh { nodes: vec![], blocks: vec![], prims: vec![] };
        let mut deepest = 0;
        // (wide node to fill, binary node whose subtree it holds, depth)
        let mut todo = vec![(0usize, 0usize, 1usize)];
        wide.nodes.push(empty_node());
        while let Some((at, from, depth)) = todo.pop() {
            deepest = deepest.max(depth);
            let members = open_up(bvh, from);
            let mut node = empty_node();
            for (slot, &m) in members.iter().enumerate() {
                let b = &bvh.nodes[m];
                for axis in 0..3 {
                    node.lo[axis][slot] = b.aabb().min[axis];
                    node.hi[axis][slot] = b.aabb().max[axis];
                }
                node.valid |= 1 << slot;
                node.child[slot] = if b.is_leaf() {
                    let first = b.first_index as usize;
                    let leaf = &bvh.primitive_indices[first..first + b.prim_count as usize];
                    LEAF | wide.push_leaf(leaf.iter().map(|&i| prims[i as usize]))
                } else {
                    wide.nodes.push(empty_node());
                    todo.push((wide.nodes.len() - 1, m, depth + 1));
                    (wide.nodes.len() - 1) as u32
                };
            }
            wide.nodes[at] = node;
        }
        // Each node visited leaves at most WIDTH − 1 more children pending.
        ((WIDTH - 1) * deepest < STACK).then_some(wide)
    }

    /// Stores a leaf's primitives in blocks; returns its first block.
    fn push_leaf(&mut self, prims: impl ExactSizeIterator<Item = PackedPrim>) -> u32 {
        let first = self.blocks.len();
        let count = prims.len().max(1).div_ceil(WIDTH);
        for k in 0..count {
            self.blocks.push(Block {
                a: [[f32::NAN; WIDTH]; 3],
                e1: [[f32::NAN; WIDTH]; 3],
                e2: [[f32::NAN; WIDTH]; 3],
                prim: [u32::MAX; WIDTH],
                single: 0,
                continues: k + 1 < count,
            });
        }
        for (n, p) in prims.enumerate() {
            let (block, lane) = (&mut self.blocks[first + n / WIDTH], n % WIDTH);
            block.prim[lane] = self.prims.len() as u32;
            if p.prim & (SPHERE_BIT | MASKED_BIT) != 0 {
                block.single |= 1 << lane;
            } else {
                for axis in 0..3 {
                    (block.a[axis][lane], block.e1[axis][lane], block.e2[axis][lane]) =
                        (p.a[axis], p.b[axis], p.c[axis]);
                }
            }
            self.prims.push(p);
        }
        first as u32
    }
}

fn empty_node() -> WideNode {
    WideNode { lo: [[0.0; WIDTH]; 3], hi: [[0.0; WIDTH]; 3], child: [0; WIDTH], valid: 0 }
}

/// The binary nodes that become the children of the wide node standing for
/// binary node `from`: its subtree opened, largest surface area first, until
/// there are `WIDTH` or only leaves are left (a leaf root is its own one
/// child).
fn open_up(bvh: &Bvh2, from: usize) -> Vec<usize> {
    let node = &bvh.nodes[from];
    if node.is_leaf() {
        return vec![from];
    }
    let mut members = vec![node.first_index as usize, node.first_index as usize + 1];
    while members.len() < WIDTH {
        let inner = (0..members.len()).filter(|&i| !bvh.nodes[members[i]].is_leaf()).max_by(|&i, &j| {
            bvh.nodes[members[i]].aabb().half_area().total_cmp(&bvh.nodes[members[j]].aabb().half_area())
        });
        let Some(i) = inner else { break };
        let opened = members.swap_remove(i);
        let first = bvh.nodes[opened].first_index as usize;
        members.extend([first, first + 1]);
    }
    members
}

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2 {
    //! The traversals in AVX2 intrinsics; callers must have checked
    //! `avx2_available` (a `WideBvh` exists only where it holds).

    use super::{Block, LEAF, STACK, WideBvh};
    use crate::geometry::Ray;
    use crate::geometry::simd8::{self, V3};
    use std::arch::x86_64::*;
    use std::mem::MaybeUninit;

    /// The ray, eight copies of each component, and 1 / its direction.
    struct Broadcast {
        origin: V3,
        dir: V3,
        inv_dir: V3,
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn broadcast(ray: &Ray) -> Broadcast {
        // One 4-byte load per component: the caller has usually just
        // written the ray, and a wider load across its stores waits for
        // them to reach the cache (perf put 8% of the query's samples on
        // that load; the whole change gained 1.5% of wall time).
        let splat = |v: &glam::Vec3| [_mm256_broadcast_ss(&v.x), _mm256_broadcast_ss(&v.y), _mm256_broadcast_ss(&v.z)];
        let dir = splat(&ray.dir);
        // One division for the three components: lanes (x, y, z, x, ...).
        let xyz = _mm256_blend_ps::<0b0000_0100>(_mm256_blend_ps::<0b0000_0010>(dir[0], dir[1]), dir[2]);
        let inv = simd8::inverse_direction(xyz);
        let lane = |k: i32| _mm256_permutevar8x32_ps(inv, _mm256_set1_epi32(k));
        Broadcast { origin: splat(&ray.origin), dir, inv_dir: [lane(0), lane(1), lane(2)] }
    }

    /// A node's children that the ray meets before `t_max`: (bit mask, near
    /// distances).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn children(r: &Broadcast, node: &super::WideNode, t_max: f32) -> (u32, [f32; 8]) {
        let (near, hit) =
            simd8::slab(simd8::load3(&node.lo), simd8::load3(&node.hi), r.origin, r.inv_dir, _mm256_set1_ps(t_max));
        let mut out = [0.0f32; 8];
        // SAFETY: `out` holds 8 floats.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), near) };
        (_mm256_movemask_ps(hit) as u32 & u32::from(node.valid), out)
    }

    /// A block's triangles against the ray in (`eps`, `t_max`): (lanes hit,
    /// t, b1, b2).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn block_hits(r: &Broadcast, block: &Block, eps: f32, t_max: f32) -> (u32, [[f32; 8]; 3]) {
        let [ok, t, b1, b2] = simd8::triangle(
            r.origin,
            r.dir,
            simd8::load3(&block.a),
            simd8::load3(&block.e1),
            simd8::load3(&block.e2),
            eps,
            _mm256_set1_ps(t_max),
        );
        let bits = _mm256_movemask_ps(ok) as u32;
        let mut out = [[0.0f32; 8]; 3];
        if bits != 0 {
            // SAFETY: each row holds 8 floats.
            unsafe {
                _mm256_storeu_ps(out[0].as_mut_ptr(), t);
                _mm256_storeu_ps(out[1].as_mut_ptr(), b1);
                _mm256_storeu_ps(out[2].as_mut_ptr(), b2);
            }
        }
        (bits, out)
    }

    /// The closest hit in (`eps`, `ray.t_max`): (t, primitive in
    /// `bvh.prims`, b1, b2). `single` tests a sphere or cut-out (index in
    /// `bvh.prims`) up to a t_max and returns (t, b1, b2) where it counts.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub unsafe fn closest(
        bvh: &WideBvh,
        ray: &Ray,
        eps: f32,
        single: impl Fn(usize, &Ray) -> Option<(f32, f32, f32)>,
    ) -> Option<(f32, u32, f32, f32)> {
        let r = broadcast(ray);
        let mut best: Option<(f32, u32, f32, f32)> = None;
        let mut t_max = ray.t_max;
        let (mut pending, mut near) = ([MaybeUninit::<u32>::uninit(); STACK], [MaybeUninit::<f32>::uninit(); STACK]);
        let (mut top, mut current) = (0, 0u32);
        loop {
            if current & LEAF == 0 {
                // Children pushed farthest first, so the nearest comes next.
                let (mut bits, distance) = children(&r, &bvh.nodes[current as usize], t_max);
                let child = &bvh.nodes[current as usize].child;
                let bottom = top;
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    let (c, d) = (child[i], distance[i]);
                    let mut j = top;
                    // SAFETY: entries below `top` are written.
                    while j > bottom && unsafe { near[j - 1].assume_init() } < d {
                        (pending[j], near[j]) = (pending[j - 1], near[j - 1]);
                        j -= 1;
                    }
                    (pending[j], near[j]) = (MaybeUninit::new(c), MaybeUninit::new(d));
                    top += 1;
                }
            } else {
                let mut b = (current & !LEAF) as usize;
                loop {
                    let block = &bvh.blocks[b];
                    let (mut bits, [t, b1, b2]) = block_hits(&r, block, eps, t_max);
                    while bits != 0 {
                        let lane = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        if t[lane] < t_max {
                            t_max = t[lane];
                            best = Some((t[lane], block.prim[lane], b1[lane], b2[lane]));
                        }
                    }
                    let mut bits = u32::from(block.single);
                    while bits != 0 {
                        let lane = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let k = block.prim[lane];
                        if let Some((t, b1, b2)) = single(k as usize, &Ray { t_max, ..*ray }) {
                            t_max = t;
                            best = Some((t, k, b1, b2));
                        }
                    }
                    if !block.continues {
                        break;
                    }
                    b += 1;
                }
            }
            // The nearest pending child that the closest hit so far does
            // not hide.
            loop {
                if top == 0 {
                    return best;
                }
                top -= 1;
                // SAFETY: entries below `top` are written.
                if unsafe { near[top].assume_init() } <= t_max {
                    current = unsafe { pending[top].assume_init() };
                    break;
                }
            }
        }
    }

    /// Whether anything counts as a hit in (`eps`, `ray.t_max`); `single`
    /// as for [`closest`].
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub unsafe fn occluded(bvh: &WideBvh, ray: &Ray, eps: f32, single: impl Fn(usize, &Ray) -> bool) -> bool {
        let r = broadcast(ray);
        let mut pending = [MaybeUninit::<u32>::uninit(); STACK];
        let (mut top, mut current) = (0, 0u32);
        loop {
            if current & LEAF == 0 {
                let (mut bits, _) = children(&r, &bvh.nodes[current as usize], ray.t_max);
                let child = &bvh.nodes[current as usize].child;
                while bits != 0 {
                    pending[top] = MaybeUninit::new(child[bits.trailing_zeros() as usize]);
                    bits &= bits - 1;
                    top += 1;
                }
            } else {
                let mut b = (current & !LEAF) as usize;
                loop {
                    let block = &bvh.blocks[b];
                    if block_hits(&r, block, eps, ray.t_max).0 != 0 {
                        return true;
                    }
                    let mut bits = u32::from(block.single);
                    while bits != 0 {
                        let lane = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        if single(block.prim[lane] as usize, ray) {
                            return true;
                        }
                    }
                    if !block.continues {
                        break;
                    }
                    b += 1;
                }
            }
            if top == 0 {
                return false;
            }
            top -= 1;
            // SAFETY: entries below `top` are written.
            current = unsafe { pending[top].assume_init() };
        }
    }
}
