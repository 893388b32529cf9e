//! A hashed uniform grid over one iteration's light vertices, for the
//! fixed-radius queries of vertex merging (SmallVCM's `HashGrid`): cells of
//! twice the radius, so a query ball touches at most 2×2×2 of them;
//! vertices sorted by cell hash (counting sort) so each cell is a range,
//! their positions copied in that order so a query reads them in sequence
//! (the scattered reads cost a fifth of a VCM pass on the Cornell box).

use glam::{IVec3, Vec3};

pub struct HashGrid {
    radius: f32,
    inverse_cell: f32,
    min: Vec3,
    /// Entry h: the start of hash bucket h in `order`; one more at the end.
    starts: Vec<u32>,
    /// Vertex indices, bucket by bucket.
    order: Vec<u32>,
    /// Their positions, in the same order.
    points: Vec<Vec3>,
}

impl HashGrid {
    pub fn new(positions: &[Vec3], radius: f32) -> Self {
        let min = positions.iter().fold(Vec3::splat(f32::INFINITY), |m, &p| m.min(p));
        let buckets = positions.len().next_power_of_two().max(1);
        let mut grid = HashGrid {
            radius,
            inverse_cell: 1.0 / (2.0 * radius),
            min,
            starts: vec![0; buckets + 1],
            order: vec![0; positions.len()],
            points: Vec::new(),
        };
        let hashes: Vec<usize> = positions.iter().map(|&p| grid.hash(grid.cell(p))).collect();
        for &h in &hashes {
            grid.starts[h + 1] += 1;
        }
        for h in 0..buckets {
            grid.starts[h + 1] += grid.starts[h];
        }
        let mut next = grid.starts.clone();
        for (i, &h) in hashes.iter().enumerate() {
            grid.order[next[h] as usize] = i as u32;
            next[h] += 1;
        }
        grid.points = grid.order.iter().map(|&i| positions[i as usize]).collect();
        grid
    }

    fn cell(&self, p: Vec3) -> IVec3 {
        ((p - self.min) * self.inverse_cell).floor().as_ivec3()
    }

    fn hash(&self, c: IVec3) -> usize {
        let h = (c.x as u32).wrapping_mul(73_856_093)
            ^ (c.y as u32).wrapping_mul(19_349_663)
            ^ (c.z as u32).wrapping_mul(83_492_791);
        h as usize & (self.starts.len() - 2)
    }

    /// Calls `visit` with the index of every vertex within the radius of `p`.
    pub fn query(&self, p: Vec3, mut visit: impl FnMut(usize)) {
        if self.order.is_empty() {
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
                    for (&i, q) in self.order[range.clone()].iter().zip(&self.points[range]) {
                        if (*q - p).length_squared() <= r2 {
                            visit(i as usize);
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
                grid.query(q, |i| found.push(i));
                found.sort();
                let expected: Vec<usize> =
                    (0..points.len()).filter(|&i| (points[i] - q).length_squared() <= radius * radius).collect();
                assert_eq!(found, expected, "radius {radius} at {q}");
            }
        }
    }
}
