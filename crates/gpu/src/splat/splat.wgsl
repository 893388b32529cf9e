// Photon splat (METHOD.md §4): one instanced quad per photon covering the
// screen footprint of its radius-r sphere; each fragment adds the photon's
// contribution (eq. 4.3) at the surface point the G-buffer holds for it.
// Prepended with estimate.wgsl.

struct SplatParams {
    clip_from_world: mat4x4<f32>,
    radius: f32,
    // Watts per unit of stored photon power.
    power_unit: f32,
    normal_test: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: SplatParams;
@group(0) @binding(1) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;

// A surviving photon from the LOD pass: the stored photon and its power scale.
struct PhotonIn {
    @location(0) position: vec3<f32>,
    @location(1) power_rgb9e5: u32,
    @location(2) direction_and_class: u32,
    @location(3) scale: f32,
}

struct SplatVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) photon_position: vec3<f32>,
    @location(1) @interpolate(flat) power_rgb9e5: u32,
    @location(2) @interpolate(flat) direction_and_class: u32,
    @location(3) @interpolate(flat) scale: f32,
}

@vertex
fn vs_main(@builtin(vertex_index) corner: u32, photon: PhotonIn) -> SplatVertex {
    // Conservative screen rectangle: the projected corners of the sphere's
    // bounding cube. A corner behind the eye plane makes the projection
    // unbounded: cover the whole screen. All corners behind: nothing visible.
    var lo = vec2<f32>(1.0e30);
    var hi = vec2<f32>(-1.0e30);
    var behind = 0u;
    for (var i = 0u; i < 8u; i++) {
        let offset = vec3<f32>(
            select(-1.0, 1.0, (i & 1u) != 0u),
            select(-1.0, 1.0, (i & 2u) != 0u),
            select(-1.0, 1.0, (i & 4u) != 0u),
        );
        let c = params.clip_from_world * vec4<f32>(photon.position + params.radius * offset, 1.0);
        if (c.w <= 1.0e-6) {
            behind += 1u;
        } else {
            lo = min(lo, c.xy / c.w);
            hi = max(hi, c.xy / c.w);
        }
    }
    if (behind > 0u) {
        lo = vec2<f32>(-1.0);
        hi = vec2<f32>(1.0);
    }
    lo = clamp(lo, vec2<f32>(-1.0), vec2<f32>(1.0));
    hi = clamp(hi, vec2<f32>(-1.0), vec2<f32>(1.0));
    if (behind == 8u) {
        hi = lo; // degenerate: no fragments
    }
    var out: SplatVertex;
    let xy = vec2<f32>(select(lo.x, hi.x, (corner & 1u) != 0u), select(lo.y, hi.y, (corner & 2u) != 0u));
    out.clip = vec4<f32>(xy, 0.0, 1.0);
    out.photon_position = photon.position;
    out.power_rgb9e5 = photon.power_rgb9e5;
    out.direction_and_class = photon.direction_and_class;
    out.scale = photon.scale;
    return out;
}

@fragment
fn fs_main(in: SplatVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.clip.xy);
    let position = textureLoad(gbuffer_position, pixel, 0);
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    // Only visible diffuse surfaces (kind 0) take photon light.
    if (position.w == 0.0 || albedo.a != 0.0) {
        discard;
    }
    let normal = textureLoad(gbuffer_normal, pixel, 0).xyz;
    let d = position.xyz - in.photon_position;
    let direction = decode_octahedral_15(in.direction_and_class & 0x3fffffffu);
    if (!photon_accepted(dot(d, d), direction, normal, params.radius, params.normal_test != 0u)) {
        discard;
    }
    let radiance = radiance_per_power(albedo.rgb, params.radius) * decode_rgb9e5(in.power_rgb9e5) * (params.power_unit * in.scale);
    // Alpha counts the photons that reached the pixel.
    return vec4<f32>(radiance, 1.0);
}
