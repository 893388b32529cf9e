// Volume splat (METHOD.md §5, eq. 5.21–5.24): one instanced quad per volume
// photon over the screen footprint of its radius-r sphere; each fragment adds
// the light the photon scatters toward the eye along the pixel's view ray:
// p(μ) · ΔΦ / ((4/3)π r³) · chord · T(eye → chord point nearest the photon),
// the chord clipped to the visible surface's depth. The CPU twin is
// hikari_core::estimate::volume_radiance_along. Prepended with
// estimate.wgsl, footprint.wgsl, media.wgsl and view_depth.wgsl.

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

@fragment
fn fs_main(in: SplatVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.clip.xy);
    let ray = view_ray(textureLoad(gbuffer_position, pixel, 0), in.clip.xy);
    let dir = ray.xyz;
    let to_photon = in.photon_position - media.camera_position;
    let t_closest = dot(to_photon, dir);
    let h2 = dot(to_photon, to_photon) - t_closest * t_closest;
    let r2 = params.radius * params.radius;
    if (h2 > r2) {
        discard;
    }
    let half_chord = sqrt(max(r2 - h2, 0.0));
    let t0 = max(t_closest - half_chord, 0.0);
    let t1 = min(t_closest + half_chord, ray.w);
    if (t1 <= t0) {
        discard;
    }
    let s_p = clamp(t_closest, t0, t1);
    let mu = dot(decode_octahedral_15(in.direction_and_class & 0x3fffffffu), -dir);
    let phase = phase_eval(in.direction_and_class >> 30u, mu);
    let transmittance = exp(-view_optical_depth(pixel, s_p, ray.w));
    let norm = 1.0 / (4.0 / 3.0 * PI * r2 * params.radius);
    let radiance = transmittance * decode_rgb9e5(in.power_rgb9e5) * (phase * (t1 - t0))
        * (norm * params.power_unit * in.scale);
    return vec4<f32>(radiance, 1.0);
}
