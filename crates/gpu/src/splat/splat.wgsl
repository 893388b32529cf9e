// Photon splat (METHOD.md §4): one instanced quad per photon covering the
// screen footprint of its radius-r sphere; each fragment adds the photon's
// contribution (eq. 4.3) at the surface point the G-buffer holds for it.
// Prepended with estimate.wgsl and footprint.wgsl.

struct SplatParams {
    clip_from_world: mat4x4<f32>,
    radius: f32,
    // Watts per unit of stored photon power.
    power_unit: f32,
    normal_test: u32,
    _pad: u32,
    // The eye, for glossy surfaces' BRDF.
    camera_position: vec3<f32>,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: SplatParams;
@group(0) @binding(1) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(5) var gbuffer_emission: texture_2d<f32>;

@fragment
fn fs_main(in: SplatVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.clip.xy);
    let position = textureLoad(gbuffer_position, pixel, 0);
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    // Only visible diffuse surfaces (kind 0) take photon light.
    if (position.w == 0.0 || albedo.a != 0.0) {
        discard;
    }
    let g = textureLoad(gbuffer_normal, pixel, 0);
    let normal = g.xyz;
    let d = position.xyz - in.photon_position;
    let direction = in.direction;
    if (!photon_accepted(dot(d, d), direction, normal, params.radius, params.normal_test != 0u)) {
        discard;
    }
    // ρ/(π² r²) on a Lambertian surface; on a glossy one (the only ones
    // that pay for the eye, the BRDF and the G-buffer's metal-roughness)
    // the BRDF for the photon's own direction over π r².
    var weight = radiance_per_power(albedo.rgb, params.radius);
    let surface = surfaces[u32(g.w)];
    if (GLOSSY && surface.glossy != 0u) {
        let b = pixel_bsdf(surface, albedo.rgb, textureLoad(gbuffer_emission, pixel, 0).w);
        let eye = unit(params.camera_position - position.xyz);
        weight = photon_brdf(b, eye, normal, direction) * radiance_per_weighted_power(params.radius);
    }
    let radiance = weight * in.power * (params.power_unit * in.scale);
    // Alpha counts the photons that reached the pixel.
    return vec4<f32>(radiance, 1.0);
}
