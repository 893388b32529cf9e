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

// The octahedral map (photon_encoding.wgsl) quantised to 12 + 12 bits.
fn encode_octahedral_12(direction: vec3<f32>) -> u32 {
    let q = vec2<u32>((octahedral_square(direction) * 0.5 + 0.5) * 4095.0 + 0.5) & vec2<u32>(0xfffu);
    return q.x | (q.y << 12u);
}

fn decode_octahedral_12(bits: u32) -> vec3<f32> {
    return octahedral_direction(vec2<f32>(f32(bits & 0xfffu), f32((bits >> 12u) & 0xfffu)) / 4095.0 * 2.0 - 1.0);
}

// What position.w stores where a surface shading with `ns` across `ng`
// (unit, on the same side) is seen.
fn pack_geometric_normal(ns: vec3<f32>, ng: vec3<f32>) -> f32 {
    if (!is_bent(ns, ng)) {
        return 1.0;
    }
    return -f32(1u + encode_octahedral_12(ng));
}

// The geometric normal from a seen pixel's position.w and its shading
// normal `ns`.
fn unpack_geometric_normal(packed: f32, ns: vec3<f32>) -> vec3<f32> {
    if (packed > 0.0) {
        return ns;
    }
    return decode_octahedral_12(u32(-packed) - 1u);
}
