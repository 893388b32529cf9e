// Volume splat (METHOD.md §5, eq. 5.21–5.24): one instanced quad per volume
// photon over the screen footprint of its radius-r sphere; each fragment adds
// the light the photon scatters toward the eye along the pixel's view ray:
// p(μ) · ΔΦ / ((4/3)π r³) · chord · T(eye → chord point nearest the photon),
// the chord clipped to the visible surface's depth. The CPU twin is
// hikari_core::estimate::volume_radiance_along. Composed with
// footprint.wgsl, view_depth.wgsl and volume_chord.wgsl.

struct VolumeParams {
    clip_from_world: mat4x4<f32>,
    radius: f32,
    // Watts per unit of stored photon power.
    power_unit: f32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: VolumeParams;
@group(0) @binding(1) var<uniform> media: MediaParams;
@group(0) @binding(2) var<storage, read> regions: array<RegionTriangle>;
@group(0) @binding(3) var slices_tex: texture_2d_array<f32>;
@group(0) @binding(4) var gbuffer_position: texture_2d<f32>;

// Every pixel of the sphere's footprint: the view ray can cross the sphere
// in front of any surface.
fn splat_footprint(position: vec3<f32>) -> vec4<f32> {
    return photon_footprint(position);
}

@fragment
fn fs_main(in: SplatVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.clip.xy);
    let ray = view_ray(textureLoad(gbuffer_position, pixel, 0), in.clip.xy);
    let dir = ray.xyz;
    let chord = volume_chord(media.camera_position, dir, ray.w, in.photon_position, params.radius * params.radius);
    if (chord.y <= chord.x) {
        discard;
    }
    let transmittance = exp(-view_optical_depth(pixel, chord.z, ray.w));
    let radiance = transmittance * decoded_chord_scattering(in.power, in.direction, in.direction_and_class >> 30u, dir, chord)
        * (volume_kernel(params.radius) * params.power_unit * in.scale);
    return vec4<f32>(radiance, 1.0);
}
