// The radiance estimate and the photon decoding, mirrored from
// hikari_core::estimate and hikari_core::photon::encoding. Prepended to every
// shader that needs them; `twin` tests pin both sides together.

const PI: f32 = 3.14159265358979323846;

// 2^k for the normal-float range, exactly, from the exponent bits.
fn pow2(k: i32) -> f32 {
    return bitcast<f32>(u32(k + 127) << 23u);
}

// RGB9E5: 9-bit mantissas, shared 5-bit exponent with bias 15.
fn decode_rgb9e5(bits: u32) -> vec3<f32> {
    let scale = pow2(i32(bits >> 27u) - 15 - 9);
    return vec3<f32>(f32(bits & 511u), f32((bits >> 9u) & 511u), f32((bits >> 18u) & 511u)) * scale;
}

// Octahedral direction, 15 + 15 bits.
fn decode_octahedral_15(bits: u32) -> vec3<f32> {
    let p = vec2<f32>(f32(bits & 0x7fffu), f32((bits >> 15u) & 0x7fffu)) / 32767.0 * 2.0 - 1.0;
    let z = 1.0 - abs(p.x) - abs(p.y);
    let t = max(-z, 0.0);
    let x = p.x + select(t, -t, p.x >= 0.0);
    let y = p.y + select(t, -t, p.y >= 0.0);
    return normalize(vec3<f32>(x, y, z));
}

// w(d_p) of eq. 4.1 with the optional normal test (estimate::photon_accepted).
fn photon_accepted(d2: f32, photon_dir: vec3<f32>, normal: vec3<f32>, radius: f32, normal_test: bool) -> bool {
    return d2 <= radius * radius && !(normal_test && dot(photon_dir, normal) >= 0.0);
}

// f_r / (π r²) for a Lambertian surface (estimate::radiance_per_power).
fn radiance_per_power(albedo: vec3<f32>, radius: f32) -> vec3<f32> {
    return albedo * (1.0 / (PI * PI * radius * radius));
}
