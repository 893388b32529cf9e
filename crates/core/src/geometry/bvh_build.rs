//! Builds obvhs CWBVHs whose depth its traversal can hold.
//!
//! obvhs traverses a CWBVH with a fixed stack of 32 entries; past that depth
//! its stack silently overwrites its last entry (in release builds) and the
//! traversal misses primitives. Its PLOC builder merges nearest neighbours
//! bottom-up, which on degenerate inputs (many identical boxes, such as
//! volume photons that all scattered at one point, or sizes that shrink
//! geometrically) makes a chain instead of a tree. So the binary BVH is
//! built with PLOC as obvhs's `build_cwbvh` does, its depth measured, and if
//! it is too deep rebuilt by median splits (depth ⌈log₂ n⌉) before the
//! conversion to a CWBVH.

use obvhs::aabb::Aabb;
use obvhs::bvh2::{Bvh2, leaf_collapser::collapse, node::Bvh2Node, reinsertion::ReinsertionOptimizer};
use obvhs::cwbvh::{CwBvh, bvh2_to_cwbvh::bvh2_to_cwbvh};
use obvhs::ploc::PlocBuilder;
use obvhs::{Boundable, BvhBuildParams};

/// Deepest binary BVH accepted from PLOC: the CWBVH made from it is no deeper,
/// so it stays below obvhs's traversal stack of 32.
const MAX_BVH2_DEPTH: usize = 31;

/// A CWBVH over `primitives` (at least one) with depth below 32.
pub(crate) fn build_cwbvh<T: Boundable>(primitives: &[T], params: BvhBuildParams) -> CwBvh {
    let mut bvh2 = ploc(primitives, &params);
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    if depth(&bvh2) > MAX_BVH2_DEPTH {
        bvh2 = median_split(primitives);
    }
    bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false)
}

/// A binary BVH as obvhs's `build_bvh2` makes it (PLOC, reinsertion, leaf
/// collapse, reinsertion), without its build timer: `std::time::Instant`
/// panics in a browser, where the GPU renderer builds this BVH too.
pub(crate) fn build_bvh2<T: Boundable>(primitives: &[T], params: BvhBuildParams) -> Bvh2 {
    let mut bvh2 = ploc(primitives, &params);
    let mut reinsertion = ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh2, params.reinsertion_batch_ratio, None);
    collapse(&mut bvh2, params.max_prims_per_leaf.clamp(1, 255), params.collapse_traversal_cost);
    reinsertion.run(
        &mut bvh2,
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    bvh2
}

/// The binary BVH of obvhs's PLOC builder, one primitive per leaf.
fn ploc<T: Boundable>(primitives: &[T], params: &BvhBuildParams) -> Bvh2 {
    PlocBuilder::with_capacity(primitives.len()).build(
        params.ploc_search_distance,
        primitives,
        (0..primitives.len() as u32).collect::<Vec<_>>(),
        params.sort_precision,
        params.search_depth_threshold,
    )
}

/// `bvh`, a binary BVH over primitives in the same order as `primitives`,
/// refitted to where they are now: each leaf takes the union of its
/// primitives' boxes, each inner node its children's. The tree keeps its
/// shape, so traversals cost more the further the primitives moved from
/// where it was built ([`relative_cost`] measures it).
pub(crate) fn refit<T: Boundable>(bvh: &Bvh2, primitives: &[T]) -> Bvh2 {
    let mut refitted = bvh.clone();
    let indices = &refitted.primitive_indices;
    for node in refitted.nodes.iter_mut().filter(|n| n.is_leaf()) {
        let first = node.first_index as usize;
        let leaf = &indices[first..first + node.prim_count as usize];
        node.set_aabb(leaf.iter().fold(Aabb::empty(), |b, &i| b.union(&primitives[i as usize].aabb())));
    }
    refitted.refit_all();
    refitted
}

/// A binary BVH's surface-area cost over its root's area: the expected
/// number of nodes and primitives a ray through the root meets (SAH, unit
/// costs), which grows as a refitted tree's boxes spread and overlap.
pub(crate) fn relative_cost(bvh: &Bvh2) -> f32 {
    let Some(root) = bvh.nodes.first() else { return 0.0 };
    let cost: f32 = bvh
        .nodes
        .iter()
        .map(|n| n.aabb().half_area().max(0.0) * if n.is_leaf() { n.prim_count as f32 } else { 1.0 })
        .sum();
    cost / root.aabb().half_area().max(f32::MIN_POSITIVE)
}

/// Number of levels of a binary BVH (a lone leaf: 1), without recursion.
pub(crate) fn depth(bvh: &Bvh2) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1usize)];
    while let Some((i, d)) = stack.pop() {
        let node = &bvh.nodes[i];
        deepest = deepest.max(d);
        if !node.is_leaf() {
            stack.push((node.first_index as usize, d + 1));
            stack.push((node.first_index as usize + 1, d + 1));
        }
    }
    deepest
}

/// A binary BVH by median splits of the centroids along the widest axis,
/// one primitive per leaf: depth ⌈log₂ n⌉ + 1 whatever the input.
fn median_split<T: Boundable>(primitives: &[T]) -> Bvh2 {
    let boxes: Vec<Aabb> = primitives.iter().map(|p| p.aabb()).collect();
    let mut indices: Vec<u32> = (0..boxes.len() as u32).collect();
    let mut nodes = vec![Bvh2Node::default(); (2 * boxes.len()).saturating_sub(1).max(1)];
    let mut next = 1;
    // (node, range of `indices` it holds)
    let mut stack = vec![(0usize, 0usize, boxes.len())];
    while let Some((node, start, end)) = stack.pop() {
        let mut aabb = Aabb::empty();
        let mut centroids = Aabb::empty();
        for &i in &indices[start..end] {
            aabb = aabb.union(&boxes[i as usize]);
            centroids.extend(boxes[i as usize].center());
        }
        if end - start == 1 {
            nodes[node] = Bvh2Node::new(aabb, 1, start as u32);
            continue;
        }
        let axis = centroids.diagonal().max_position();
        let mid = (start + end) / 2;
        indices[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            boxes[a as usize].center()[axis].total_cmp(&boxes[b as usize].center()[axis])
        });
        nodes[node] = Bvh2Node::new(aabb, 0, next as u32);
        stack.push((next, start, mid));
        stack.push((next + 1, mid, end));
        next += 2;
    }
    Bvh2 { nodes, primitive_indices: indices, ..Default::default() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{UVec2, Vec3A};

    struct Box3(Aabb);
    impl Boundable for Box3 {
        fn aabb(&self) -> Aabb {
            self.0
        }
    }

    /// Every primitive is reached exactly once by a ray through all of them.
    fn all_found(bvh: &CwBvh, n: usize) {
        let ray = obvhs::ray::Ray::new(Vec3A::new(-1e3, 0.01, 0.02), Vec3A::new(1.0, 1e-7, 1e-7), 0.0, 1e9);
        let mut state = bvh.new_traversal(ray.direction);
        let mut node;
        let mut seen = vec![0u32; n];
        obvhs::traverse!(bvh, node, state, node.intersect_ray(&ray, state.oct_inv4), {
            seen[bvh.primitive_indices[state.primitive_id as usize] as usize] += 1;
        });
        assert!(seen.iter().all(|&s| s == 1), "{:?}", seen.iter().filter(|&&s| s != 1).count());
    }

    #[test]
    fn identical_boxes_give_a_shallow_tree_that_finds_them_all() {
        // 3000 copies of one box: PLOC alone chains them.
        let prims: Vec<Box3> = (0..3000).map(|_| Box3(Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)))).collect();
        let bvh = build_cwbvh(&prims, BvhBuildParams::fast_build());
        bvh.validate(&prims, false);
        all_found(&bvh, prims.len());
    }

    #[test]
    fn geometric_sizes_give_a_shallow_tree() {
        // Slabs halving in width around x = 0, nested: the other chain.
        let prims: Vec<Box3> = (0..120)
            .map(|k| {
                let s = 0.5f32.powi(k);
                Box3(Aabb::new(Vec3A::new(-s, -1.0, -1.0), Vec3A::new(s, 1.0, 1.0)))
            })
            .collect();
        let bvh = build_cwbvh(&prims, BvhBuildParams::medium_build());
        bvh.validate(&prims, false);
        all_found(&bvh, prims.len());
    }

    #[test]
    fn median_split_is_balanced() {
        let prims: Vec<Box3> = (0..1000)
            .map(|i| {
                let c = Vec3A::new(i as f32, (i * 7 % 13) as f32, 0.0);
                Box3(Aabb::new(c - 0.1, c + 0.1))
            })
            .collect();
        let bvh2 = median_split(&prims);
        assert_eq!(depth(&bvh2), 11);
        let mut leaves: Vec<u32> = bvh2.primitive_indices.clone();
        leaves.sort();
        assert!(leaves.iter().copied().eq(0..1000));
    }
}
