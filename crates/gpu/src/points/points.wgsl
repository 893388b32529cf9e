// Photons as points (the seed's figures 6.1 and 6.2): every photon the last
// frame drew (the LOD pass's survivors), one pixel each, hidden behind the
// G-buffer's surfaces. Coloured by map and power, or by LOD detail level.
// Prepended with estimate.wgsl (decode_rgb9e5).

struct PointsParams {
    clip_from_world: mat4x4<f32>,
    eye: vec3<f32>,
    // 0: the photon's power colour, tinted by `tint`; 1: its LOD detail
    // level q = 1 − 1/scale (the power scale of a fully kept photon),
    // blue (full detail) → red (coarsest).
    mode: u32,
    tint: vec3<f32>,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: PointsParams;

struct PointOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec3<f32>,
}

// The detail level's false colour: a blue → cyan → yellow → red ramp.
fn level_color(q: f32) -> vec3<f32> {
    let t = clamp(q, 0.0, 1.0);
    return clamp(vec3<f32>(2.0 * t - 0.5, 1.5 - abs(2.0 * t - 1.0) * 1.5, 1.5 - 2.0 * t), vec3<f32>(0.0), vec3<f32>(1.0));
}

@vertex
fn vs_main(
    @location(0) position: vec3<f32>,
    @location(1) power_rgb9e5: u32,
    @location(2) direction_and_class: u32,
    @location(3) scale: f32,
) -> PointOut {
    var out: PointOut;
    // A photon lies on its surface: pulled 1% toward the eye, it passes
    // the depth test there and stays hidden behind nearer surfaces.
    let p = params.eye + (position - params.eye) * 0.99;
    out.clip = params.clip_from_world * vec4<f32>(p, 1.0);
    if (params.mode == 1u) {
        out.color = level_color(1.0 - 1.0 / max(scale, 1.0));
    } else {
        let power = decode_rgb9e5(power_rgb9e5);
        out.color = params.tint * power / max(max(power.r, max(power.g, power.b)), 1e-30);
    }
    return out;
}

@fragment
fn fs_main(in: PointOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color, 1.0);
}
