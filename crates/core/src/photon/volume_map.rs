//! The volume photon map as the CPU volume estimate reads it: a BVH (obvhs's
//! CWBVH) over each photon's sphere of radius r, so that a view ray visits
//! only the photons whose sphere's bounding box its segment crosses, each
//! once. A kd-tree answers point queries; here the query is a segment, and
//! walking point queries along it found most photons two or three times and
//! had to sort them out (photon-cpu spent over a minute on fog-stage).

use super::Photon;
use crate::material::Rgb;
use glam::{UVec2, Vec3, Vec3A};
use obvhs::{Boundable, BvhBuildParams, aabb::Aabb, cwbvh::CwBvh};

/// A volume photon decoded once, as the estimate reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumePhoton {
    pub position: Vec3,
    /// Power in units of the map's `power_unit`.
    pub power: Rgb,
    /// Unit propagation direction when it scattered.
    pub direction: Vec3,
    /// Phase slot of the medium that scattered it (`Photon::phase_slot`).
    pub phase_slot: usize,
}

impl VolumePhoton {
    fn decode(photon: &Photon) -> Self {
        VolumePhoton {
            position: photon.position(),
            power: photon.power_in_units(),
            direction: photon.direction(),
            phase_slot: photon.phase_slot(),
        }
    }
}

struct SphereBounds(Aabb);

impl Boundable for SphereBounds {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

pub struct VolumePhotonMap {
    photons: Vec<Photon>,
    radius: f32,
    bvh: Option<CwBvh>,
    /// `leaves[i]` is photon `bvh.primitive_indices[i]`, decoded, so the
    /// traversal reads them in order with no indirection.
    leaves: Vec<VolumePhoton>,
    /// Watts per unit of `VolumePhoton::power`.
    pub power_unit: f32,
}

impl VolumePhotonMap {
    /// Indexes `photons` as spheres of `radius`.
    pub fn new(photons: Vec<Photon>, power_unit: f32, radius: f32) -> Self {
        let r = Vec3A::splat(radius);
        let bounds: Vec<SphereBounds> = photons
            .iter()
            .map(|p| {
                let c = Vec3A::from(p.position());
                SphereBounds(Aabb::new(c - r, c + r))
            })
            .collect();
        let bvh = (!bounds.is_empty()).then(|| crate::geometry::build_cwbvh(&bounds, BvhBuildParams::fast_build()));
        let leaves = bvh
            .as_ref()
            .map(|b| b.primitive_indices.iter().map(|&i| VolumePhoton::decode(&photons[i as usize])).collect())
            .unwrap_or_default();
        VolumePhotonMap { photons, radius, bvh, leaves, power_unit }
    }

    /// The photons as traced (for uploads and LOD).
    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    pub fn radius(&self) -> f32 {
        self.radius
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// Calls `visit` for every photon whose sphere may meet the segment
    /// `origin + t·dir`, t in [0, `length`]: a superset (bounding boxes) that
    /// holds every photon whose sphere does, each exactly once.
    pub fn for_each_near_segment(&self, origin: Vec3, dir: Vec3, length: f32, mut visit: impl FnMut(&VolumePhoton)) {
        let Some(bvh) = &self.bvh else {
            return;
        };
        let ray = crate::geometry::obvhs_ray(origin, dir, length);
        let mut state = bvh.new_traversal(ray.direction);
        let mut node;
        obvhs::traverse!(bvh, node, state, node.intersect_ray(&ray, state.oct_inv4), {
            visit(&self.leaves[state.primitive_id as usize]);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::PathClass;
    use crate::sampling::{Rng, uniform_sphere};

    /// Every photon within r of the segment is visited exactly once, for
    /// segments inside, through and outside the cloud, axis-aligned ones
    /// included.
    #[test]
    fn visits_every_photon_near_the_segment_once() {
        let mut rng = Rng::for_item(51, 0);
        let point = |rng: &mut Rng| (rng.next_2d().extend(rng.next_f32()) - 0.5) * 4.0;
        let photons: Vec<Photon> =
            (0..5000).map(|_| Photon::new(point(&mut rng), Vec3::ONE, Vec3::Y, PathClass::Direct)).collect();
        let radius = 0.15;
        let map = VolumePhotonMap::new(photons.clone(), 1.0, radius);
        let mut segments: Vec<(Vec3, Vec3, f32)> =
            (0..300).map(|_| (point(&mut rng) * 1.5, uniform_sphere(rng.next_2d()), rng.next_f32() * 6.0)).collect();
        segments.push((Vec3::new(0.1, 0.2, -3.0), Vec3::Z, 6.0));
        segments.push((Vec3::new(-3.0, 0.0, 0.3), Vec3::X, 1e30));
        for (origin, dir, length) in segments {
            let mut seen: Vec<Vec3> = Vec::new();
            map.for_each_near_segment(origin, dir, length, |p| seen.push(p.position));
            let near = |p: Vec3| {
                let t = (p - origin).dot(dir).clamp(0.0, length);
                (origin + dir * t - p).length() <= radius * 0.999
            };
            let want = photons.iter().filter(|p| near(p.position())).count();
            let got = seen.iter().filter(|&&p| near(p)).count();
            assert_eq!(got, want, "segment {origin} {dir} {length}");
            let mut keys: Vec<[u32; 3]> = seen.iter().map(|p| p.to_array().map(f32::to_bits)).collect();
            keys.sort_unstable();
            keys.dedup();
            assert_eq!(keys.len(), seen.len(), "a photon visited twice");
        }
    }
}
