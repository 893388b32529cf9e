// The screen rectangle a photon can light, shared by the raster splats
// (footprint.wgsl) and the tiled estimator. The includer declares `params`
// with `clip_from_world` and `radius`.

// The conservative screen rectangle of a photon's radius-r sphere, in NDC
// (lo.xy, hi.xy), clamped to the screen: the projected corners of the
// sphere's bounding cube. A corner behind the eye plane makes the
// projection unbounded: the whole screen. All corners behind: lo > hi.
fn photon_footprint(position: vec3<f32>) -> vec4<f32> {
    var lo = vec2<f32>(1.0e30);
    var hi = vec2<f32>(-1.0e30);
    var behind = 0u;
    for (var i = 0u; i < 8u; i++) {
        let offset = vec3<f32>(
            select(-1.0, 1.0, (i & 1u) != 0u),
            select(-1.0, 1.0, (i & 2u) != 0u),
            select(-1.0, 1.0, (i & 4u) != 0u),
        );
        let c = params.clip_from_world * vec4<f32>(position + params.radius * offset, 1.0);
        if (c.w <= 1.0e-6) {
            behind += 1u;
        } else {
            lo = min(lo, c.xy / c.w);
            hi = max(hi, c.xy / c.w);
        }
    }
    if (behind == 8u) {
        return vec4<f32>(1.0, 1.0, -1.0, -1.0);
    }
    if (behind > 0u) {
        lo = vec2<f32>(-1.0);
        hi = vec2<f32>(1.0);
    }
    return vec4<f32>(clamp(lo, vec2<f32>(-1.0), vec2<f32>(1.0)), clamp(hi, vec2<f32>(-1.0), vec2<f32>(1.0)));
}
