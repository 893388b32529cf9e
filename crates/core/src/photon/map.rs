//! A photon map: photons plus a kd-tree (kiddo) over their positions,
//! answering the seed's fixed-radius query (all photons within r) and the
//! classic k-nearest query.

use super::Photon;
use glam::Vec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZeroUsize;

pub struct PhotonMap {
    photons: Vec<Photon>,
    /// `photons[i].power_in_units()`, decoded once: the estimate reads it for
    /// every photon in range, and decoding is exact, so nothing changes.
    power: Vec<Vec3>,
    tree: Option<ImmutableKdTree<f32, 3>>,
    /// Watts per unit of `Photon::power_in_units`.
    pub power_unit: f32,
}

impl PhotonMap {
    pub fn new(photons: Vec<Photon>, power_unit: f32) -> Self {
        let points: Vec<[f32; 3]> = photons.iter().map(|p| p.position).collect();
        // kiddo refuses empty input; an empty map simply answers nothing.
        let tree = (!points.is_empty())
            .then(|| ImmutableKdTree::new_from_slice(&points).expect("photon positions are finite by construction"));
        let power = photons.iter().map(Photon::power_in_units).collect();
        PhotonMap { photons, power, tree, power_unit }
    }

    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// Calls `visit` for every photon with |x − x_p| ≤ `radius` (eq. 4.1's w(d)).
    #[inline]
    pub fn for_each_within(&self, x: Vec3, radius: f32, mut visit: impl FnMut(&Photon)) {
        self.for_each_index_within(x, radius, |i, _| visit(&self.photons[i]));
    }

    /// Like `for_each_within`, giving the photon's index and squared distance.
    #[inline]
    pub fn for_each_index_within(&self, x: Vec3, radius: f32, mut visit: impl FnMut(usize, f32)) {
        if let Some(tree) = &self.tree {
            tree.query(&x.to_array())
                .within::<SquaredEuclidean<f32>>(radius * radius)
                .unsorted()
                .visit(|r| visit(r.item as usize, r.distance));
        }
    }

    /// Decoded power of photon `i`, in power units.
    #[inline]
    pub fn power_in_units(&self, i: usize) -> Vec3 {
        self.power[i]
    }

    /// The `k` photons nearest to `x` (at most `max_radius` away), and the
    /// distance to the farthest of them.
    pub fn nearest(&self, x: Vec3, k: usize, max_radius: f32) -> (Vec<&Photon>, f32) {
        let (Some(tree), Some(k)) = (&self.tree, NonZeroUsize::new(k)) else {
            return (Vec::new(), 0.0);
        };
        let found =
            tree.query(&x.to_array()).nearest_n::<SquaredEuclidean<f32>>(k).within(max_radius * max_radius).execute();
        let radius = found.iter().map(|r| r.distance).fold(0.0f32, f32::max).sqrt();
        (found.iter().map(|r| &self.photons[r.item as usize]).collect(), radius)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::PathClass;
    use crate::sampling::Rng;

    fn random_map(n: usize) -> PhotonMap {
        let mut rng = Rng::for_item(31, 0);
        let photons = (0..n)
            .map(|_| {
                let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
                Photon::new(p, Vec3::ONE, Vec3::NEG_Y, PathClass::Indirect)
            })
            .collect();
        PhotonMap::new(photons, 1.0)
    }

    /// The kd-tree's fixed-radius query returns exactly the brute-force set.
    #[test]
    fn fixed_radius_query_equals_brute_force() {
        let map = random_map(20_000);
        let mut rng = Rng::for_item(32, 0);
        for _ in 0..300 {
            let x = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.4 - 1.2;
            let r = 0.02 + rng.next_f32() * 0.2;
            let mut got: Vec<[u32; 3]> = Vec::new();
            map.for_each_within(x, r, |p| got.push(p.position.map(f32::to_bits)));
            let mut want: Vec<[u32; 3]> = map
                .photons()
                .iter()
                .filter(|p| (p.position() - x).length_squared() <= r * r)
                .map(|p| p.position.map(f32::to_bits))
                .collect();
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want);
        }
    }

    #[test]
    fn nearest_returns_the_k_closest() {
        let map = random_map(5_000);
        let x = Vec3::new(0.1, -0.2, 0.3);
        let (found, radius) = map.nearest(x, 50, 10.0);
        assert_eq!(found.len(), 50);
        let mut d: Vec<f32> = map.photons().iter().map(|p| (p.position() - x).length()).collect();
        d.sort_by(f32::total_cmp);
        assert!((radius - d[49]).abs() < 1e-5);
    }

    #[test]
    fn empty_map_answers_nothing() {
        let map = PhotonMap::new(Vec::new(), 1.0);
        let mut n = 0;
        map.for_each_within(Vec3::ZERO, 1.0, |_| n += 1);
        assert_eq!(n, 0);
        assert!(map.nearest(Vec3::ZERO, 5, 1.0).0.is_empty());
    }
}
