// The optical depth along a pixel's view ray from the optical-depth slices
// (eq. 5.26 with the regions of eq. 5.25–5.30). Needs media.wgsl and the
// includer's `slices_tex`.

// ∫₀ˢ σ_t along the pixel's view ray of length `l`: exact for the media
// filling the scene, linear between slices for the regions (layer j holds
// the regions' optical depth to l·(j+1)/S).
fn view_optical_depth(pixel: vec2<i32>, s: f32, l: f32) -> vec3<f32> {
    if (!MEDIA) {
        return vec3<f32>(0.0);
    }
    var tau = media.global_sigma_t * s;
    if (media.slices > 0u) {
        let x = clamp(s / l, 0.0, 1.0) * f32(media.slices);
        let k = min(u32(x), media.slices - 1u);
        let f = x - f32(k);
        var lo = vec3<f32>(0.0);
        if (k > 0u) {
            lo = textureLoad(slices_tex, pixel, i32(k) - 1, 0).rgb;
        }
        let hi = textureLoad(slices_tex, pixel, i32(k), 0).rgb;
        tau += mix(lo, hi, f);
    }
    return tau;
}
