//! A hashed uniform grid over one iteration's light vertices, for the
//! fixed-radius queries of vertex merging (SmallVCM's `HashGrid`): cells of
//! twice the radius, so a query ball touches at most 2×2×2 of them;
//! vertices sorted by cell hash (counting sort) so each cell is a range,
//! their positions copied in that order so a query reads them in sequence
//! (the scattered reads cost a fifth of a VCM pass on the Cornell box).

use glam::{IVec3, Vec3};
use rayon::prelude::*;

#[derive(Default)]
pub struct HashGrid {
    radius: f32,
    inverse_cell: f32,
    /// The vertices' bounds.
    min: Vec3,
    max: Vec3,
    /// Entry h: the start of hash bucket h in `order`; one more at the end.
    starts: Vec<u32>,
    /// Vertex indices, bucket by bucket.
    order: Vec<u32>,
    /// Their positions, in the same order.
    points: Vec<Vec3>,
    /// Scratch, kept to reuse its allocation: each vertex's bucket, each
    /// bucket's next free slot.
    hashes: Vec<u32>,
    next_slot: Vec<u32>,
}

impl HashGrid {
    #[cfg(test)]
    pub fn new(positions: &[Vec3], radius: f32) -> Self {
        let mut grid = HashGrid::default();
        grid.rebuild(positions, radius);
        grid
    }

    /// Grids `positions` at `radius`, reusing the buffers of the last
    /// grid (a VCM pass grids ~10⁵ vertices; fresh pages each pass cost
    /// more than the sort).
    pub fn rebuild(&mut self, positions: &[Vec3], radius: f32) {
        self.min = positions.iter().fold(Vec3::splat(f32::INFINITY), |m, &p| m.min(p));
        self.max = positions.iter().fold(Vec3::splat(f32::NEG_INFINITY), |m, &p| m.max(p));
        self.radius = radius;
        self.inverse_cell = 1.0 / (2.0 * radius);
        let buckets = positions.len().next_power_of_two().max(1);
        self.starts.clear();
        self.starts.resize(buckets + 1, 0);
        let mut hashes = std::mem::take(&mut self.hashes);
        hashes.clear();
        hashes.par_extend(positions.par_iter().map(|&p| self.hash(self.cell(p)) as u32));
        for &h in &hashes {
            self.starts[h as usize + 1] += 1;
        }
        for h in 0..buckets {
            self.starts[h + 1] += self.starts[h];
        }
        self.order.clear();
        self.order.resize(positions.len(), 0);
        self.next_slot.clear();
        self.next_slot.extend_from_slice(&self.starts[..buckets]);
        for (i, &h) in hashes.iter().enumerate() {
            let slot = &mut self.next_slot[h as usize];
            self.order[*slot as usize] = i as u32;
            *slot += 1;
        }
        self.points.clear();
        self.points.par_extend(self.order.par_iter().map(|&i| positions[i as usize]));
        self.hashes = hashes;
    }

    /// The vertex index of each slot, slot by slot: what [`HashGrid::query`]
    /// reports are slots, so per-vertex data laid out in this order is read
    /// in sequence.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The cell of `p`. No vertex lies below `min`, so cells below 0 are
    /// empty and a query may look in cell 0 instead; truncation is then
    /// the floor, without a call to libm's `floorf` (x86-64 has no SSE4.1
    /// rounding by default): 8% of the queries' time in a profile of the
    /// Cornell box.
    fn cell(&self, p: Vec3) -> IVec3 {
        ((p - self.min) * self.inverse_cell).max(Vec3::ZERO).as_ivec3()
    }

    fn hash(&self, c: IVec3) -> usize {
        let h = (c.x as u32).wrapping_mul(73_856_093)
            ^ (c.y as u32).wrapping_mul(19_349_663)
            ^ (c.z as u32).wrapping_mul(83_492_791);
        h as usize & (self.starts.len() - 2)
    }

    /// Calls `visit` with the slot (see [`HashGrid::order`]) of every vertex
    /// within the radius of `p`.
    pub fn query(&self, p: Vec3, mut visit: impl FnMut(usize)) {
        let reach = Vec3::splat(self.radius);
        // A point farther than the radius beyond the vertices' bounds finds none.
        if self.order.is_empty() || p.cmplt(self.min - reach).any() || p.cmpgt(self.max + reach).any() {
            return;
        }
        let (lo, hi) = (self.cell(p - Vec3::splat(self.radius)), self.cell(p + Vec3::splat(self.radius)));
        let r2 = self.radius * self.radius;
        let mut seen = [usize::MAX; 8];
        let mut count = 0;
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let h = self.hash(IVec3::new(x, y, z));
                    // Two cells may share a bucket: visit it once.
                    if seen[..count].contains(&h) {
                        continue;
                    }
                    if count < seen.len() {
                        seen[count] = h;
                        count += 1;
                    }
                    let range = self.starts[h] as usize..self.starts[h + 1] as usize;
                    for slot in range {
                        if (self.points[slot] - p).length_squared() <= r2 {
                            visit(slot);
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
    use crate::sampling::Rng;

    /// The grid finds exactly the points a brute-force search finds.
    #[test]
    fn finds_what_brute_force_finds() {
        let mut rng = Rng::for_item(5, 0);
        let points: Vec<Vec3> =
            (0..3000).map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.3)).collect();
        for radius in [0.01, 0.05, 0.2] {
            let grid = HashGrid::new(&points, radius);
            for _ in 0..200 {
                let q = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.3);
                let mut found = Vec::new();
                grid.query(q, |slot| found.push(grid.order()[slot] as usize));
                found.sort();
                let expected: Vec<usize> =
                    (0..points.len()).filter(|&i| (points[i] - q).length_squared() <= radius * radius).collect();
                assert_eq!(found, expected, "radius {radius} at {q}");
            }
        }
    }
}
