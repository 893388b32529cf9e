// Light evaluation shared by the direct-light pass and the specular pass:
// each light's exact unshadowed irradiance times the fraction of its
// shadow-mapped sample points that see the point. The counterpart of
// hikari_core::render::direct_diffuse, which integrates the same by shadow rays.
// The includer declares `direct_params`, `lights`, `samples`, `views`,
// `shadow_maps`, and `light_transmittance(x, sample_position)` (the media's
// transmittance between them; 1 where media are not drawn).

struct DirectParams {
    light_count: u32,
    shadow_size: u32,
    // Depth bias, as a fraction of the distance to the light sample.
    bias: f32,
    _pad: u32,
}

struct Light {
    position: vec3<f32>,
    kind: u32,
    emission: vec3<f32>,
    first_sample: u32,
    axis: vec3<f32>,
    sample_count: u32,
    edge_v: vec3<f32>,
    cutoff: f32,
    falloff_start: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct LightSample {
    position: vec3<f32>,
    first_view: u32,
    view_count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct ShadowView {
    clip_from_world: mat4x4<f32>,
    // w: the range the stored depths are fractions of.
    light_position: vec4<f32>,
}

// Irradiance ∫ L cos θ dω at x (normal n) from light l, ignoring occlusion.
fn unshadowed_irradiance(l: Light, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let to_light = l.position - x;
    let d2 = dot(to_light, to_light);
    let wi = to_light / sqrt(d2);
    let cos_x = max(dot(n, wi), 0.0);
    switch l.kind {
        case 0u: {
            return l.emission * cos_x / d2;
        }
        case 1u: {
            return l.emission * spot_falloff(acos(clamp(dot(-wi, l.axis), -1.0, 1.0)), l.cutoff, l.falloff_start) * cos_x / d2;
        }
        case 2u: {
            // A sphere of radius R subtends a cap with sin²α = R²/d²: E = π L sin²α cos θ
            // (exact while the whole cap is above the horizon).
            let r2 = l.cutoff * l.cutoff;
            if (d2 <= r2) {
                return vec3<f32>(0.0);
            }
            return l.emission * PI * (r2 / d2) * cos_x;
        }
        default: {
            // Lambert's polygon formula: E = L/2 Σ θ_i (γ_i · n) over the edges
            // (exact while the whole quad is above the horizon). One-sided.
            if (dot(x - l.position, cross(l.axis, l.edge_v)) <= 0.0) {
                return vec3<f32>(0.0);
            }
            var corners = array<vec3<f32>, 4>(l.position, l.position + l.axis, l.position + l.axis + l.edge_v, l.position + l.edge_v);
            var total = 0.0;
            for (var i = 0u; i < 4u; i++) {
                if (!loop_iteration()) {
                    break;
                }
                let a = normalize(corners[i] - x);
                let b = normalize(corners[(i + 1u) % 4u] - x);
                let theta = acos(clamp(dot(a, b), -1.0, 1.0));
                let g = cross(a, b);
                let len = length(g);
                if (len > 0.0) {
                    total += theta * dot(g / len, n);
                }
            }
            return l.emission * 0.5 * abs(total);
        }
    }
}

// Is `x` (with normal `n`) seen from sample point `s`?
fn visible(s: LightSample, x: vec3<f32>, n: vec3<f32>) -> bool {
    let d = x - s.position;
    var face = 0u;
    if (s.view_count == 6u) {
        let a = abs(d);
        if (a.x >= a.y && a.x >= a.z) {
            face = select(1u, 0u, d.x >= 0.0);
        } else if (a.y >= a.z) {
            face = select(3u, 2u, d.y >= 0.0);
        } else {
            face = select(5u, 4u, d.z >= 0.0);
        }
    }
    let layer = s.first_view + face;
    // Offset along the normal by about a texel's footprint against acne.
    let texel = 2.0 * length(d) / f32(direct_params.shadow_size);
    let xs = x + n * (1.5 * texel);
    let clip = views[layer].clip_from_world * vec4<f32>(xs, 1.0);
    if (clip.w <= 0.0) {
        return true;
    }
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let size = i32(direct_params.shadow_size);
    let texel_index = clamp(vec2<i32>(uv * f32(size)), vec2<i32>(0), vec2<i32>(size - 1));
    let stored = textureLoad(shadow_maps, texel_index, i32(layer), 0).r * views[layer].light_position.w;
    return distance(xs, s.position) <= stored * (1.0 + direct_params.bias);
}


// Direct radiance leaving a diffuse point x (normal n toward the viewer).
fn direct_radiance(x: vec3<f32>, n: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < direct_params.light_count; i++) {
        if (!loop_iteration()) {
            break;
        }
        let l = lights[i];
        let e = unshadowed_irradiance(l, x, n);
        if (all(e == vec3<f32>(0.0))) {
            continue;
        }
        var seen = vec3<f32>(0.0);
        for (var k = 0u; k < l.sample_count; k++) {
            if (!loop_iteration()) {
                break;
            }
            let s = samples[l.first_sample + k];
            if (visible(s, x, n)) {
                seen += light_transmittance(x, s.position);
            }
        }
        sum += e * (seen / f32(l.sample_count));
    }
    return albedo / PI * sum;
}
