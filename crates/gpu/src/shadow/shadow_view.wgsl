// A shadow view: one layer of the shadow-map array. A perspective view
// stores the distance from its light sample to the nearest surface; an
// orthographic one (a distant light's) the distance along the light's
// direction from the plane its photons start from. Either is divided by
// the view's range so it fits in [0, 1].

struct ShadowView {
    clip_from_world: mat4x4<f32>,
    // xyz: the light sample, or a point of an orthographic view's start
    // plane; w: the range the stored depths are fractions of.
    light_position: vec4<f32>,
    // Orthographic views: xyz the unit direction light travels, w the
    // view's width (> 0). Perspective views: w = 0.
    direction: vec4<f32>,
    // x: the seed of this drawing's BLEND fragments (ShadowViewParams).
    blend_seed: vec4<u32>,
}

// What view `v` stores for a surface at p, before dividing by its range.
fn shadow_depth(v: ShadowView, p: vec3<f32>) -> f32 {
    if (v.direction.w > 0.0) {
        return dot(p - v.light_position.xyz, v.direction.xyz);
    }
    return distance(p, v.light_position.xyz);
}
