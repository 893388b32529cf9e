// One volume photon's in-scattering along a ray (METHOD.md §5, eq.
// 5.21–5.24), hikari_core::estimate::volume_radiance_along's term, written
// once for the volume splat, the tiled estimator and the specular pass.
// Needs media.wgsl (phase_eval) and photon_encoding.wgsl.

// The chord of the ray o + t·d, t in [0, len], through the radius-r sphere
// (r2 = r²) around p: (t0, t1, s_p), s_p the chord's point nearest p;
// t1 <= t0 when the ray misses the sphere within [0, len].
fn volume_chord(o: vec3<f32>, d: vec3<f32>, len: f32, p: vec3<f32>, r2: f32) -> vec3<f32> {
    let to_photon = p - o;
    let t_closest = dot(to_photon, d);
    let h2 = dot(to_photon, to_photon) - t_closest * t_closest;
    if (h2 > r2) {
        return vec3<f32>(0.0);
    }
    let half_chord = sqrt(max(r2 - h2, 0.0));
    let t0 = max(t_closest - half_chord, 0.0);
    let t1 = min(t_closest + half_chord, len);
    return vec3<f32>(t0, t1, clamp(t_closest, t0, t1));
}

// The photon's power (RGB9E5 bits) times its phase function toward the eye
// (propagation `d`) times the chord length: what the photon scatters along
// the chord, before the transmittance to s_p and the 1/((4/3)πr³) kernel.
fn chord_scattering(power_rgb9e5: u32, direction_and_class: u32, d: vec3<f32>, chord: vec3<f32>) -> vec3<f32> {
    let direction = decode_octahedral_15(direction_and_class & 0x3fffffffu);
    return decoded_chord_scattering(decode_rgb9e5(power_rgb9e5), direction, direction_and_class >> 30u, d, chord);
}

// The same from the photon already decoded: its power, travel direction and
// phase slot (the volume splat decodes them per vertex, not per fragment).
fn decoded_chord_scattering(power: vec3<f32>, direction: vec3<f32>, phase_slot: u32, d: vec3<f32>, chord: vec3<f32>) -> vec3<f32> {
    let phase = phase_eval(phase_slot, dot(direction, -d));
    return power * (phase * (chord.y - chord.x));
}

// The kernel 1/((4/3)πr³) of the volume estimate.
fn volume_kernel(r: f32) -> f32 {
    return 1.0 / (4.0 / 3.0 * PI * r * r * r);
}
