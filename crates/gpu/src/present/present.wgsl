// Present: the resolved frame to the window, tone-mapped as
// hikari_core::output::tone_map does for PNG files: exposure (a scale of
// 2^stops), clamp to [0, 1], and the sRGB transfer function, unless the
// target is an *Srgb format, whose stores encode it themselves.

struct PresentParams {
    scale: f32,
    // 1: write sRGB-encoded values (a linear target); 0: linear (an sRGB target).
    encode_srgb: u32,
    // 0: radiance, tone-mapped; 1: a G-buffer normal (xyz · 0.5 + 0.5); 2: a
    // G-buffer albedo (rgb), 3 and 4: photon points — debug views, shown as stored.
    mode: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: PresentParams;
@group(0) @binding(1) var frame: texture_2d<f32>;

// hikari_core::output::linear_to_srgb
fn linear_to_srgb(x: f32) -> f32 {
    if (x <= 0.0031308) {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}


@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(frame));
    let pixel = min(vec2<i32>(position.xy), size - vec2<i32>(1));
    let texel = textureLoad(frame, pixel, 0).rgb;
    var c = texel * params.scale;
    if (params.mode == 1u) {
        c = texel * 0.5 + vec3<f32>(0.5) * f32(dot(texel, texel) > 0.0);
    } else if (params.mode >= 2u) {
        c = texel;
    }
    // Non-finite values show black, as in files.
    let finite = (c == c) & (abs(c) <= vec3<f32>(3.0e38));
    var v = select(vec3<f32>(0.0), clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), finite);
    if (params.encode_srgb != 0u) {
        v = vec3<f32>(linear_to_srgb(v.r), linear_to_srgb(v.g), linear_to_srgb(v.b));
    }
    return vec4<f32>(v, 1.0);
}
