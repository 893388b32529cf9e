//! A hashed uniform grid over a photon map for GPU gathers (the specular
//! pass shades points seen through glass and mirrors, which a screen-space
//! splat cannot reach). Cells are `radius` wide, so the 27 cells around a
//! point hold every photon within `radius` of it. `PhotonGrid::for_each_within`
//! is the CPU mirror of the WGSL query.

use glam::{IVec3, Vec3};
use hikari_core::photon::Photon;

pub struct PhotonGrid {
    pub cell_size: f32,
    /// Number of hash buckets (a power of two).
    pub buckets: u32,
    /// `starts[b] .. starts[b + 1]` index `photons` for bucket b.
    pub starts: Vec<u32>,
    /// The photons, sorted by bucket.
    pub photons: Vec<Photon>,
}

/// Bucket of a cell: the classic spatial hash (Teschner et al. 2003). The
/// WGSL `bucket_of` is the same expression in wrapping u32 arithmetic.
pub fn bucket_of(cell: IVec3, buckets: u32) -> u32 {
    let h = (cell.x as u32).wrapping_mul(73_856_093)
        ^ (cell.y as u32).wrapping_mul(19_349_663)
        ^ (cell.z as u32).wrapping_mul(83_492_791);
    h & (buckets - 1)
}

pub fn cell_of(p: Vec3, cell_size: f32) -> IVec3 {
    (p / cell_size).floor().as_ivec3()
}

impl PhotonGrid {
    pub fn new(photons: &[Photon], radius: f32) -> Self {
        let buckets = (2 * photons.len().max(1)).next_power_of_two() as u32;
        let bucket = |p: &Photon| bucket_of(cell_of(p.position(), radius), buckets);
        // Counting sort by bucket.
        let mut starts = vec![0u32; buckets as usize + 1];
        for p in photons {
            starts[bucket(p) as usize + 1] += 1;
        }
        for b in 0..buckets as usize {
            starts[b + 1] += starts[b];
        }
        let mut fill = starts.clone();
        let mut sorted =
            vec![Photon::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y, hikari_core::photon::PathClass::Direct); photons.len()];
        for p in photons {
            let b = bucket(p) as usize;
            sorted[fill[b] as usize] = *p;
            fill[b] += 1;
        }
        PhotonGrid { cell_size: radius, buckets, starts, photons: sorted }
    }

    /// Every photon within `radius` (≤ the cell size) of `x`, each once:
    /// buckets shared by two of the 27 cells are visited once.
    pub fn for_each_within(&self, x: Vec3, radius: f32, mut visit: impl FnMut(&Photon)) {
        let centre = cell_of(x, self.cell_size);
        let mut seen = [u32::MAX; 27];
        let mut n = 0;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let b = bucket_of(centre + IVec3::new(dx, dy, dz), self.buckets);
                    if seen[..n].contains(&b) {
                        continue;
                    }
                    seen[n] = b;
                    n += 1;
                    for p in &self.photons[self.starts[b as usize] as usize..self.starts[b as usize + 1] as usize] {
                        let d = p.position() - x;
                        if d.dot(d) <= radius * radius {
                            visit(p);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::photon::PathClass;
    use hikari_core::sampling::Rng;

    #[test]
    fn grid_query_equals_brute_force() {
        let mut rng = Rng::for_item(5, 0);
        let photons: Vec<Photon> = (0..20_000)
            .map(|_| {
                let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
                Photon::new(p, Vec3::ONE, Vec3::Y, PathClass::Indirect)
            })
            .collect();
        let radius = 0.13;
        let grid = PhotonGrid::new(&photons, radius);
        for _ in 0..300 {
            let x = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.4 - 2.2;
            let mut got: Vec<[u32; 3]> = Vec::new();
            grid.for_each_within(x, radius, |p| got.push(p.position.map(f32::to_bits)));
            let mut want: Vec<[u32; 3]> = photons
                .iter()
                .filter(|p| (p.position() - x).dot(p.position() - x) <= radius * radius)
                .map(|p| p.position.map(f32::to_bits))
                .collect();
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want);
        }
    }
}
