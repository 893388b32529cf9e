// Accel::intersect's normals at a BVH hit (the flat BVH's FlatShading per
// primitive: hikari_core::geometry::FlatShading). The includer defines
// `fn flat_shading(index: u32) -> FlatShading` over wherever it keeps them
// (the tracer: a buffer of its own; the specular pass: its tables).

struct FlatShading {
    geometric_normal: vec3<f32>,
    has_vertex_normals: u32,
    vertex_normals: array<vec4<f32>, 3>,
}

// Accel::intersect's normals at a hit on primitive `index` at x: the
// geometric one, and the shading one on its side.
struct HitNormals {
    geometric: vec3<f32>,
    shading: vec3<f32>,
}

fn hit_normals(index: u32, o: vec3<f32>, d: vec3<f32>, x: vec3<f32>) -> HitNormals {
    let p = prims[index];
    if (p.is_sphere != 0u) {
        let n = unit((x - p.a) / p.b.x);
        return HitNormals(n, n);
    }
    let s = flat_shading(index);
    let ng = s.geometric_normal;
    if (s.has_vertex_normals == 0u) {
        return HitNormals(ng, ng);
    }
    // The barycentrics of the hit, as Triangle::intersect computes them.
    let pv = cross(d, p.c);
    let inv = 1.0 / dot(p.b, pv);
    let sv = o - p.a;
    let b1 = dot(sv, pv) * inv;
    let b2 = dot(d, cross(sv, p.b)) * inv;
    let blend = s.vertex_normals[0].xyz * (1.0 - b1 - b2) + s.vertex_normals[1].xyz * b1 + s.vertex_normals[2].xyz * b2;
    let len = length(blend);
    var ns = ng;
    // Finite and non-zero (NaN fails both comparisons).
    if (len > 0.0 && len < 3.0e38) {
        ns = blend / len;
    }
    return HitNormals(ng, select(ns, -ns, dot(ns, ng) < 0.0));
}
