//! A closed mesh bounding a medium (heterogeneous media, METHOD.md §5,
//! eq. 5.25–5.30). Its faces' normals (counter-clockwise winding) point out
//! of the medium, so a ray crossing a face against its normal enters it. A
//! mesh may hold several shells: a box of fog with a fog-free hole in it is
//! the box plus an inward-facing inner shell.
//!
//! Everything here rests on one identity. Call a crossing at distance t_c
//! along a ray *leaving* (s_c = +1, along the normal) or *entering*
//! (s_c = −1). For a closed, consistently oriented mesh whose shells do not
//! overlap, the length of [0, L] inside the medium is Σ_c s_c · min(t_c, L)
//! over the crossings ahead of the origin, whether or not the origin is
//! inside. It needs no sorting, and it is exactly what the GPU optical-depth
//! pass accumulates with additive blending (leaving faces add their clamped
//! depth, entering faces subtract it), so both sides compute the same sum.

use glam::Vec3;
use std::collections::HashMap;

#[derive(Clone, Debug)]
pub struct RegionMesh {
    triangles: Vec<[Vec3; 3]>,
    min: Vec3,
    max: Vec3,
}

/// Where a ray crosses a region's boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub t: f32,
    /// +1 leaving the medium, −1 entering it.
    pub sign: i32,
}

impl RegionMesh {
    /// Checks that the mesh is closed and consistently oriented: every
    /// directed edge a→b has exactly one partner b→a (by vertex position).
    pub fn new(triangles: Vec<[Vec3; 3]>) -> Result<RegionMesh, String> {
        if triangles.is_empty() {
            return Err("the region mesh has no triangles".into());
        }
        let key = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut balance: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
        for t in &triangles {
            for i in 0..3 {
                let (a, b) = (key(t[i]), key(t[(i + 1) % 3]));
                // Count a→b as +1 and b→a as −1 under one unordered key.
                let (k, s) = if a < b { ((a, b), 1) } else { ((b, a), -1) };
                *balance.entry(k).or_insert(0) += s;
            }
        }
        let open: Vec<_> = balance.iter().filter(|(_, b)| **b != 0).collect();
        if let Some(((a, b), _)) = open.first() {
            let v = |k: &[u32; 3]| k.map(f32::from_bits);
            return Err(format!(
                "the region mesh is not closed and consistently wound: {} edge(s) lack a partner edge running the \
                 other way, e.g. the edge from {:?} to {:?} (a region must enclose its medium, normals outward)",
                open.len(),
                v(a),
                v(b)
            ));
        }
        let mut min = Vec3::INFINITY;
        let mut max = Vec3::NEG_INFINITY;
        for v in triangles.iter().flatten() {
            min = min.min(*v);
            max = max.max(*v);
        }
        Ok(RegionMesh { triangles, min, max })
    }

    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// Appends the boundary crossings at t > 0 along `origin + t·dir`.
    pub fn crossings(&self, origin: Vec3, dir: Vec3, out: &mut Vec<Crossing>) {
        if !self.ray_meets_bounds(origin, dir) {
            return;
        }
        for [a, b, c] in &self.triangles {
            if let Some(t) = intersect_triangle(origin, dir, *a, *b, *c) {
                let normal = (*b - *a).cross(*c - *a);
                out.push(Crossing { t, sign: if normal.dot(dir) > 0.0 { 1 } else { -1 } });
            }
        }
    }

    /// Length of `origin + t·dir`, t in [0, `length`], inside the medium.
    pub fn inside_length(&self, origin: Vec3, dir: Vec3, length: f32) -> f32 {
        let mut crossings = Vec::new();
        self.crossings(origin, dir, &mut crossings);
        crossings.iter().map(|c| c.sign as f32 * c.t.min(length)).sum::<f32>().max(0.0)
    }

    /// Whether `point` is inside: the net number of times a ray from it
    /// leaves the medium. The direction is skewed so it rarely grazes edges.
    pub fn contains(&self, point: Vec3) -> bool {
        let dir = Vec3::new(0.5773, 0.5774, 0.5775).normalize();
        let mut crossings = Vec::new();
        self.crossings(point, dir, &mut crossings);
        crossings.iter().map(|c| c.sign).sum::<i32>() > 0
    }

    fn ray_meets_bounds(&self, origin: Vec3, dir: Vec3) -> bool {
        let inv = dir.recip();
        let t0 = (self.min - origin) * inv;
        let t1 = (self.max - origin) * inv;
        // NaN (0·∞ on a face plane) counts as a hit: min/max ignore it.
        let near = t0.min(t1).max_element();
        let far = t0.max(t1).min_element();
        far >= near.max(0.0) || far.is_nan() || near.is_nan()
    }
}

/// Watertight ray–triangle test (Woop, Benthin and Wald 2013), two-sided,
/// t > 0 only. A ray through an edge or vertex shared by several triangles
/// must count exactly one crossing, or the winding (and every optical depth
/// after it) goes wrong; rays along axes through box diagonals do this
/// all the time. The edge functions of a shared edge are exact negatives of
/// each other, and a zero is given to one side only by the rasterizer's
/// top-left rule in the ray's projected plane, so the GPU's optical-depth
/// pass (which rasterizes with that rule) counts the same crossings.
fn intersect_triangle(origin: Vec3, dir: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<f32> {
    let kz = dir.abs().max_position();
    let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if dir[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
    // Vertices in ray space: the ray is the +z axis through the origin.
    let project = |v: Vec3| {
        let p = v - origin;
        (p[kx] - sx * p[kz], p[ky] - sy * p[kz], sz * p[kz])
    };
    let (pa, pb, pc) = (project(a), project(b), project(c));
    // f32 × f32 products are exact in f64, so edge(P,Q) = −edge(Q,P) exactly.
    let edge = |p: (f32, f32, f32), q: (f32, f32, f32)| q.0 as f64 * p.1 as f64 - q.1 as f64 * p.0 as f64;
    let (u, v, w) = (edge(pb, pc), edge(pc, pa), edge(pa, pb));
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let top_left = |p: (f32, f32, f32), q: (f32, f32, f32)| q.1 > p.1 || (q.1 == p.1 && q.0 < p.0);
    let inside = |e: f64, p, q| {
        if det > 0.0 { e > 0.0 || (e == 0.0 && top_left(p, q)) } else { e < 0.0 || (e == 0.0 && top_left(p, q)) }
    };
    if !(inside(u, pb, pc) && inside(v, pc, pa) && inside(w, pa, pb)) {
        return None;
    }
    let t = (u * pa.2 as f64 + v * pb.2 as f64 + w * pc.2 as f64) / det;
    (t > 0.0).then_some(t as f32)
}

/// The 12 outward-wound triangles of the axis-aligned box [min, max].
pub fn box_triangles(min: Vec3, max: Vec3) -> Vec<[Vec3; 3]> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 != 0 { max.x } else { min.x },
            if i & 2 != 0 { max.y } else { min.y },
            if i & 4 != 0 { max.z } else { min.z },
        )
    };
    // Each face as four corner indices, counter-clockwise seen from outside.
    let faces = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    faces
        .iter()
        .flat_map(|f| [[corner(f[0]), corner(f[1]), corner(f[2])], [corner(f[0]), corner(f[2]), corner(f[3])]])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> RegionMesh {
        RegionMesh::new(box_triangles(Vec3::ZERO, Vec3::ONE)).unwrap()
    }

    #[test]
    fn box_normals_point_outward() {
        let centre = Vec3::splat(0.5);
        for [a, b, c] in box_triangles(Vec3::ZERO, Vec3::ONE) {
            let n = (b - a).cross(c - a);
            assert!(n.dot((a + b + c) / 3.0 - centre) > 0.0);
        }
    }

    #[test]
    fn open_or_inconsistent_meshes_are_rejected() {
        let mut tris = box_triangles(Vec3::ZERO, Vec3::ONE);
        tris.pop();
        assert!(RegionMesh::new(tris.clone()).unwrap_err().contains("not closed"));
        let mut flipped = box_triangles(Vec3::ZERO, Vec3::ONE);
        flipped[0].swap(1, 2);
        assert!(RegionMesh::new(flipped).is_err());
    }

    #[test]
    fn inside_length_from_outside_inside_and_through() {
        let b = unit_box();
        let dir = Vec3::X;
        // From outside, through the whole box, and stopping halfway in.
        let o = Vec3::new(-1.0, 0.3, 0.6);
        assert!((b.inside_length(o, dir, 5.0) - 1.0).abs() < 1e-6);
        assert!((b.inside_length(o, dir, 1.5) - 0.5).abs() < 1e-6);
        assert_eq!(b.inside_length(o, dir, 0.5), 0.0);
        // From inside.
        let o = Vec3::new(0.25, 0.3, 0.6);
        assert!((b.inside_length(o, dir, 5.0) - 0.75).abs() < 1e-6);
        assert!((b.inside_length(o, dir, 0.5) - 0.5).abs() < 1e-6);
        assert!(b.contains(o) && !b.contains(Vec3::new(1.5, 0.5, 0.5)));
    }

    /// A box with an inward-facing inner shell: fog with a fog-free hole.
    #[test]
    fn a_second_shell_makes_a_hole() {
        let mut tris = box_triangles(Vec3::ZERO, Vec3::splat(3.0));
        let hole: Vec<[Vec3; 3]> =
            box_triangles(Vec3::ONE, Vec3::splat(2.0)).into_iter().map(|[a, b, c]| [a, c, b]).collect();
        tris.extend(hole);
        let region = RegionMesh::new(tris).unwrap();
        let o = Vec3::new(-1.0, 1.5, 1.5);
        assert!((region.inside_length(o, Vec3::X, 10.0) - 2.0).abs() < 1e-5);
        assert!(!region.contains(Vec3::splat(1.5)));
        assert!(region.contains(Vec3::splat(0.5)));
        // From inside the hole.
        assert!((region.inside_length(Vec3::splat(1.5), Vec3::X, 10.0) - 1.0).abs() < 1e-5);
    }
}
