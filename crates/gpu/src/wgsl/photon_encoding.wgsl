// The stored photon's encodings (hikari_core::photon::encoding), both ways,
// with the same arithmetic, so a photon encoded on the GPU has the CPU's bits.

// 2^k for the normal-float range, exactly, from the exponent bits.
fn pow2(k: i32) -> f32 {
    return bitcast<f32>(u32(k + 127) << 23u);
}

// RGB9E5: 9-bit mantissas, shared 5-bit exponent with bias 15.
fn decode_rgb9e5(bits: u32) -> vec3<f32> {
    let scale = pow2(i32(bits >> 27u) - 15 - 9);
    return vec3<f32>(f32(bits & 511u), f32((bits >> 9u) & 511u), f32((bits >> 18u) & 511u)) * scale;
}

fn encode_rgb9e5(color: vec3<f32>) -> u32 {
    let c = clamp(color, vec3<f32>(0.0), vec3<f32>(511.0 / 512.0 * 65536.0));
    let max_c = max(max(c.x, c.y), c.z);
    // Below the smallest step (2^-24), or NaN: zero.
    if (!(max_c >= 5.9604645e-8)) {
        return 0u;
    }
    let floor_log2 = i32((bitcast<u32>(max_c) >> 23u) & 0xffu) - 127;
    var exponent = max(floor_log2, -16) + 1 + 15;
    var inv_scale = pow2(9 + 15 - exponent);
    if (u32(max_c * inv_scale + 0.5) == 512u) {
        exponent += 1;
        inv_scale *= 0.5;
    }
    let q = min(vec3<u32>(c * inv_scale + 0.5), vec3<u32>(511u));
    return q.x | (q.y << 9u) | (q.z << 18u) | (u32(exponent) << 27u);
}

// The octahedral map: a unit direction's point in the square [-1, 1]²,
// and back (each code below quantises the square its own way).
fn octahedral_square(direction: vec3<f32>) -> vec2<f32> {
    let d = direction / (abs(direction.x) + abs(direction.y) + abs(direction.z));
    var p = d.xy;
    if (d.z < 0.0) {
        // f32::signum: ±1 by the sign bit.
        let s = vec2<f32>(select(1.0, -1.0, (bitcast<u32>(p.x) & 0x80000000u) != 0u), select(1.0, -1.0, (bitcast<u32>(p.y) & 0x80000000u) != 0u));
        p = (vec2<f32>(1.0) - abs(p.yx)) * s;
    }
    return clamp(p, vec2<f32>(-1.0), vec2<f32>(1.0));
}

fn octahedral_direction(p: vec2<f32>) -> vec3<f32> {
    let z = 1.0 - abs(p.x) - abs(p.y);
    let t = max(-z, 0.0);
    let x = p.x + select(t, -t, p.x >= 0.0);
    let y = p.y + select(t, -t, p.y >= 0.0);
    return normalize(vec3<f32>(x, y, z));
}

// A unit direction's octahedral point quantised to `bits` per axis, x in
// the low `bits` and y above: photon::encode_octahedral / decode_octahedral.
fn encode_octahedral(direction: vec3<f32>, bits: u32) -> u32 {
    let mask = (1u << bits) - 1u;
    let q = vec2<u32>((octahedral_square(direction) * 0.5 + 0.5) * f32(mask) + 0.5) & vec2<u32>(mask);
    return q.x | (q.y << bits);
}

fn decode_octahedral(code: u32, bits: u32) -> vec3<f32> {
    let mask = (1u << bits) - 1u;
    return octahedral_direction(vec2<f32>(f32(code & mask), f32((code >> bits) & mask)) / f32(mask) * 2.0 - 1.0);
}

// The photon's direction code: 15 + 15 bits.
fn decode_octahedral_15(bits: u32) -> vec3<f32> {
    return decode_octahedral(bits, 15u);
}

fn encode_octahedral_15(direction: vec3<f32>) -> u32 {
    return encode_octahedral(direction, 15u);
}
