// The G-buffer's geometric normal (gbuffer/geometric_normal.rs, its twin),
// in position.w, which is 0 where no surface is seen: 1 where the shading
// normal is the geometric one (estimate::is_bent false), else −(1 + the
// geometric normal's octahedral code of 12 + 12 bits), an integer down to
// −2^24 (exact in f32).

// estimate::BENT_COS.
const BENT_COS: f32 = 0.99999;

// estimate::is_bent.
fn is_bent(ns: vec3<f32>, ng: vec3<f32>) -> bool {
    return dot(ns, ng) < BENT_COS;
}

// What position.w stores where a surface shading with `ns` across `ng`
// (unit, on the same side) is seen.
fn pack_geometric_normal(ns: vec3<f32>, ng: vec3<f32>) -> f32 {
    if (!is_bent(ns, ng)) {
        return 1.0;
    }
    return -f32(1u + encode_octahedral(ng, 12u));
}

// The geometric normal from a seen pixel's position.w and its shading
// normal `ns`.
fn unpack_geometric_normal(packed: f32, ns: vec3<f32>) -> vec3<f32> {
    if (packed > 0.0) {
        return ns;
    }
    return decode_octahedral(u32(-packed) - 1u, 12u);
}

// The G-buffer's albedo.a (geometric_normal.rs, its twin): the material
// kind, and at a point a normal texture bends, the smooth (interpolated)
// normal it was bent from, whose bump shadowing the diffuse lobes take:
// kind + KIND_CODES · (1 + its octahedral code of 10 + 10 bits), an
// integer below 2^24 (exact in f32); the kind alone elsewhere.
const KIND_CODES: u32 = 8u;

// What albedo.a stores for `kind` at a point of smooth normal `unbent`
// (unit) that a normal texture bent where `bumped`.
fn pack_kind(kind: u32, unbent: vec3<f32>, bumped: bool) -> f32 {
    if (!bumped) {
        return f32(kind);
    }
    return f32(kind + KIND_CODES * (1u + encode_octahedral(unbent, 10u)));
}

// The kind from albedo.a.
fn pixel_kind(packed: f32) -> u32 {
    return u32(packed) % KIND_CODES;
}

// The smooth normal from albedo.a; zero where no normal texture bent it.
fn pixel_smooth_normal(packed: f32) -> vec3<f32> {
    let code = u32(packed) / KIND_CODES;
    if (code == 0u) {
        return vec3<f32>(0.0);
    }
    return decode_octahedral(code - 1u, 10u);
}
