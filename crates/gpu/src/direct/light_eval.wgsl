// Light evaluation shared by the direct-light pass and the specular pass:
// each light's exact unshadowed irradiance times the fraction of its
// shadow-mapped samples that see the point (point, spot, sphere, quad,
// sun), or, where no closed form fits, a sum over the samples each
// evaluated on its own (sky, emissive mesh: `sampled_irradiance`). The
// counterpart of hikari_core::render::direct_diffuse, which integrates the
// same by shadow rays. The includer declares `direct_params`, `lights`,
// `samples`, `views`, `shadow_maps`, and `light_transmittance(x, end)` (the
// media's transmittance from x to a point toward the light; 1 where media
// are not drawn).

struct DirectParams {
    light_count: u32,
    shadow_size: u32,
    // Depth bias, as a fraction of the distance to the light sample.
    bias: f32,
    _pad: u32,
}

// Kinds (light_samples::kind): 0 point, 1 spot, 2 sphere, 3 quad, 4 sun,
// 5 sky, 6 emissive mesh.
struct Light {
    // Point/spot position, sphere centre, quad corner, a distant light's disc centre.
    position: vec3<f32>,
    kind: u32,
    // Intensity (point, spot), irradiance (sun) or radiance (the others).
    emission: vec3<f32>,
    first_sample: u32,
    // Spot axis, quad edge_u, the unit direction toward the sun.
    axis: vec3<f32>,
    sample_count: u32,
    edge_v: vec3<f32>,
    // Spot cutoff, sphere radius, a distant light's disc radius.
    cutoff: f32,
    falloff_start: f32,
    // Emissive mesh: each sample's share of its area (A / N), and whether
    // it emits from both faces.
    sample_area: f32,
    two_sided: u32,
    _pad: u32,
}

struct LightSample {
    // The sample point; for distant lights, where the view starts.
    position: vec3<f32>,
    first_view: u32,
    // Toward a distant light (sun, sky); a mesh sample's front normal.
    direction: vec3<f32>,
    view_count: u32,
}

const KIND_SUN: u32 = 4u;
const KIND_SKY: u32 = 5u;
const KIND_MESH: u32 = 6u;

// Where light arriving at x along −wi from a distant light starts: the
// plane of its disc (hikari_core::light::Disc::reach), the end of the
// segment whose media attenuate it.
fn distant_start(l: Light, x: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    return x + wi * max(l.cutoff - dot(x - l.position, wi), 0.0);
}

// Irradiance ∫ L cos θ dω at x (normal n) from light l, ignoring occlusion.
fn unshadowed_irradiance(l: Light, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if (l.kind == KIND_SUN) {
        // E cos θ (every point of the scene lies within its disc's reach).
        return l.emission * max(dot(n, l.axis), 0.0);
    }
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

// Is `x` (with normal `n`) seen from sample `s`?
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
    let view = views[layer];
    // Offset along the normal by about a texel's footprint against acne: a
    // 90° view's texel spans 2·distance / size there, an orthographic
    // view's its width / size everywhere.
    var footprint = 2.0 * length(d);
    if (view.direction.w > 0.0) {
        footprint = view.direction.w;
    }
    let texel = footprint / f32(direct_params.shadow_size);
    let xs = x + n * (1.5 * texel);
    let clip = view.clip_from_world * vec4<f32>(xs, 1.0);
    if (clip.w <= 0.0) {
        return true;
    }
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let size = i32(direct_params.shadow_size);
    let texel_index = clamp(vec2<i32>(uv * f32(size)), vec2<i32>(0), vec2<i32>(size - 1));
    let stored = textureLoad(shadow_maps, texel_index, i32(layer), 0).r * view.light_position.w;
    return shadow_depth(view, xs) <= stored * (1.0 + direct_params.bias);
}

// Irradiance at x (normal n) from a light whose samples are each evaluated
// on their own, shadowed:
// * the sky (radiance L from every direction): πL, what the upper
//   hemisphere gives, times the cosine-weighted fraction of its K fixed
//   directions that see x. Exact where all or none see it; in between a
//   sky seen through K hard shadows, as an area light is N hard shadows.
// * an emissive mesh: Σ_k L·a·cos_l·cos_x/(d² + a/π) over its N points,
//   each standing for its share a = A/N of the area (the small-disc form of
//   a/d²), one-sided unless two-sided.
fn sampled_irradiance(l: Light, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    var seen = vec3<f32>(0.0);
    var total_weight = 0.0;
    for (var k = 0u; k < l.sample_count; k++) {
        if (!loop_iteration()) {
            break;
        }
        let s = samples[l.first_sample + k];
        var weight = 0.0;
        var end = s.position;
        if (l.kind == KIND_SKY) {
            weight = max(dot(n, s.direction), 0.0);
            total_weight += weight;
            end = distant_start(l, x, s.direction);
        } else {
            let to_light = s.position - x;
            let d2 = dot(to_light, to_light);
            if (d2 <= 0.0) {
                continue;
            }
            let wi = to_light / sqrt(d2);
            var cos_l = -dot(s.direction, wi);
            if (l.two_sided != 0u) {
                cos_l = abs(cos_l);
            }
            // Each point stands for a disc of its share of the area: on its
            // axis that gives L·a/(d² + a/π) exactly, which stays finite
            // (at most πL) where a point's a/d² would not.
            weight = max(dot(n, wi), 0.0) * max(cos_l, 0.0) / (d2 + l.sample_area / PI);
        }
        if (weight > 0.0 && visible(s, x, n)) {
            seen += weight * light_transmittance(x, end);
        }
    }
    if (l.kind == KIND_SKY) {
        if (total_weight <= 0.0) {
            return vec3<f32>(0.0);
        }
        return l.emission * PI * seen / total_weight;
    }
    return l.emission * l.sample_area * seen;
}


// Direct radiance leaving a diffuse point x (normal n toward the viewer).
fn direct_radiance(x: vec3<f32>, n: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < direct_params.light_count; i++) {
        if (!loop_iteration()) {
            break;
        }
        let l = lights[i];
        if (l.kind == KIND_SKY || l.kind == KIND_MESH) {
            sum += sampled_irradiance(l, x, n);
            continue;
        }
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
                var end = s.position;
                if (l.kind == KIND_SUN) {
                    end = distant_start(l, x, l.axis);
                }
                seen += light_transmittance(x, end);
            }
        }
        sum += e * (seen / f32(l.sample_count));
    }
    return albedo / PI * sum;
}
