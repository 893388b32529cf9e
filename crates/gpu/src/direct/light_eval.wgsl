// Light evaluation shared by the direct-light pass and the specular pass:
// each light's exact unshadowed light times the fraction of its
// shadow-mapped samples that see the point (point, spot, sphere, quad,
// sun), or, where no closed form fits, a sum over the samples each
// evaluated on its own (sky, emissive mesh: `sampled_radiance`). The
// counterpart of hikari_core::render::direct_diffuse and direct_reflected,
// which integrate the same by shadow rays.
//
// A Lambertian point takes the closed-form irradiance. A glossy point
// (the glTF BRDF, `Reflector`) takes f at the light's direction for point,
// spot and sun (exact); for sphere and quad lights the unshadowed integral
// of f·L·cos over the light is estimated with `AREA_SAMPLES` light samples
// and as many BRDF samples, weighted by multiple importance sampling, from
// the caller's random stream (a new one each progressive pass, so passes
// converge), and the sky's from BRDF samples alone (`sky_glossy`); an
// emissive mesh's likewise from area-uniform points on its triangles and,
// for small meshes, BRDF samples (`mesh_glossy`). The shadow-mapped samples
// give the fraction seen, as for Lambertian points. The includer declares
// `direct_params` and `shadow_maps` and defines `light_record(i)`,
// `light_sample(i)`, `shadow_view(i)` (its lights, samples and views, from
// arrays as `LIGHT_ARRAYS` reads them or from packed tables), and `light_transmittance(x, end)` (the
// media's transmittance from x to a point toward the light; 1 where media
// are not drawn).

struct DirectParams {
    light_count: u32,
    shadow_size: u32,
    // Depth bias, as a fraction of the distance to the light sample.
    bias: f32,
    // The progressive pass (from 1), seeding the direct pass's random
    // streams (the specular pass seeds its own).
    pass_index: u32,
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
    // Sky: 1 when it is an image (its samples' `weight`s hold it).
    mapped: u32,
    // Emissive mesh: its triangles in the samples array (`mesh_triangle`).
    first_triangle: u32,
    triangle_count: u32,
}

struct LightSample {
    // The sample point; for distant lights, where the view starts.
    position: vec3<f32>,
    first_view: u32,
    // Toward a distant light (sun, sky); a mesh sample's front normal.
    direction: vec3<f32>,
    view_count: u32,
    // A sky image's direction: L(ω)/(K·p(ω)) (light_samples.rs).
    weight: vec3<f32>,
    _pad: u32,
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

// The geometric normal of the point being shaded where its shading normal
// is bent off it (the G-buffer's, the specular pass's hit), else zero: set
// by the pass before `direct_radiance`. Light from below the geometric
// surface is none, whatever the shading normal sees, as in `path` and
// `photon-cpu` (a shadow ray there would start into the surface).
var<private> shaded_geometric_normal: vec3<f32>;

// Whether light arriving along `wi` (toward the light) at the point being
// shaded comes from above its geometric surface.
fn above_surface(wi: vec3<f32>) -> bool {
    return !BENT || all(shaded_geometric_normal == vec3<f32>(0.0)) || dot(shaded_geometric_normal, wi) > 0.0;
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
    let view = shadow_view(layer);
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

// How the shaded point reflects toward the viewer: Lambertian `albedo`, or
// (glossy) the glTF BRDF `bsdf` seen from `wo` (shading frame of the normal);
// at a point a normal texture bends, its diffuse lobes shadowed by `bump`
// (world frame; none elsewhere), as Cycles' bump map correction.
struct Reflector {
    albedo: vec3<f32>,
    glossy: bool,
    bsdf: Bsdf,
    wo: vec3<f32>,
    bump: BumpShadow,
}

// Surface `s` at a point where its BRDF is `b` (textures applied), of
// shading normal `n`, seen from `eye` (world, toward the viewer); the
// caller sets `bump` where a normal texture bent `n`.
fn surface_reflector(s: Surface, b: Bsdf, eye: vec3<f32>, n: vec3<f32>) -> Reflector {
    return Reflector(b.base_color, GLOSSY && s.glossy != 0u, b, to_shading(eye, n), no_bump());
}

// The diffuse lobes' bump shadowing for light from the world direction `wi`.
fn reflector_bump(r: Reflector, wi: vec3<f32>) -> f32 {
    if (!bump_mapped()) {
        return 1.0;
    }
    return bump_term(r.bump, wi);
}

// f toward the world direction `wi` (every non-delta lobe).
fn reflector_f(r: Reflector, n: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    let k = reflector_bump(r, wi);
    if (!r.glossy) {
        return r.albedo / PI * k;
    }
    return bsdf_f_bumped(r.bsdf, r.wo, to_shading(wi, n), k);
}

// f toward `wi` (world), given as `local` in the shading frame, at a glossy point.
fn glossy_f(r: Reflector, wi: vec3<f32>, local: vec3<f32>) -> vec3<f32> {
    return bsdf_f_bumped(r.bsdf, r.wo, local, reflector_bump(r, wi));
}

// Light and BRDF samples per sphere or quad light and glossy point.
const AREA_SAMPLES: u32 = 4u;

// Veach's power heuristic for a sample of density a against b, written so
// that neither square overflows.
fn power_heuristic(a: f32, b: f32) -> f32 {
    if (a <= 0.0) {
        return 0.0;
    }
    let ratio = b / a;
    return 1.0 / (1.0 + ratio * ratio);
}

// A BRDF sample for the area-light and sky estimates at a glossy point of
// normal `n`: a non-delta direction (the mirror of smooth lobes is the
// specular pass's), or `valid` false; weighed by the bump shadowing.
fn glossy_sample(r: Reflector, n: vec3<f32>, rng: ptr<function, u32>) -> BsdfSample {
    let u_lobe = stream_next_f32(rng);
    let s = bsdf_sample(r.bsdf, r.wo, u_lobe, stream_next_2d(rng));
    if (s.is_delta) {
        return no_bsdf_sample();
    }
    if (bump_mapped() && r.bump.alpha >= 0.0 && s.valid) {
        return bsdf_reweigh(r.bsdf, r.wo, s, bump_term(r.bump, local_to_world(s.wi, n)));
    }
    return s;
}

// ∫ f L cos dω over sphere or quad light l, unshadowed, at a glossy point:
// light samples (uniform on the quad, uniform in the sphere's cone) and
// BRDF samples combined by the power heuristic.
fn area_glossy(l: Light, x: vec3<f32>, n: vec3<f32>, r: Reflector, rng: ptr<function, u32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    if (l.kind == 2u) {
        let to_centre = l.position - x;
        let dc2 = dot(to_centre, to_centre);
        let r2 = l.cutoff * l.cutoff;
        if (dc2 <= r2) {
            return vec3<f32>(0.0);
        }
        let axis = to_centre / sqrt(dc2);
        let sin2_max = r2 / dc2;
        let cos_max = sqrt(max(1.0 - sin2_max, 0.0));
        // 1 − cos θmax without cancellation for small or distant spheres.
        let pdf_cone = 1.0 / (2.0 * PI * (sin2_max / (1.0 + cos_max)));
        for (var k = 0u; k < AREA_SAMPLES; k++) {
            if (!loop_iteration()) {
                break;
            }
            let wi = local_to_world(uniform_cone(stream_next_2d(rng), cos_max), axis);
            let local = to_shading(wi, n);
            if (local.z > 0.0) {
                let f = glossy_f(r, wi, local);
                sum += f * (local.z / pdf_cone * power_heuristic(pdf_cone, bsdf_pdf(r.bsdf, r.wo, local)));
            }
            let s = glossy_sample(r, n, rng);
            if (s.valid && dot(local_to_world(s.wi, n), axis) >= cos_max) {
                sum += s.weight * power_heuristic(s.pdf, pdf_cone);
            }
        }
    } else {
        let normal = cross(l.axis, l.edge_v);
        let area = length(normal);
        let nl = normal / area;
        // Its two edges' Gram matrix, to find where a ray crosses it.
        let uu = dot(l.axis, l.axis);
        let uv = dot(l.axis, l.edge_v);
        let vv = dot(l.edge_v, l.edge_v);
        let det = uu * vv - uv * uv;
        for (var k = 0u; k < AREA_SAMPLES; k++) {
            if (!loop_iteration()) {
                break;
            }
            let u = stream_next_2d(rng);
            let to_light = l.position + l.axis * u.x + l.edge_v * u.y - x;
            let d2 = dot(to_light, to_light);
            let wi = to_light / sqrt(d2);
            let cos_l = -dot(wi, nl);
            let local = to_shading(wi, n);
            if (cos_l > 0.0 && local.z > 0.0) {
                let pdf_light = d2 / (area * cos_l);
                let f = glossy_f(r, wi, local);
                sum += f * (local.z / pdf_light * power_heuristic(pdf_light, bsdf_pdf(r.bsdf, r.wo, local)));
            }
            let s = glossy_sample(r, n, rng);
            if (!s.valid) {
                continue;
            }
            let dir = local_to_world(s.wi, n);
            let facing = -dot(dir, nl);
            if (facing <= 0.0) {
                continue;
            }
            let t = dot(x - l.position, nl) / facing;
            let q = x + dir * t - l.position;
            let qu = dot(q, l.axis);
            let qv = dot(q, l.edge_v);
            let a = (qu * vv - qv * uv) / det;
            let b = (qv * uu - qu * uv) / det;
            if (t > 0.0 && a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0) {
                let pdf_light = t * t / (area * facing);
                sum += s.weight * power_heuristic(s.pdf, pdf_light);
            }
        }
    }
    return l.emission * sum / f32(AREA_SAMPLES);
}

// The sky's light reflected at a glossy point x: L·∫f cos·V dω by BRDF
// samples, the visibility V of each sampled direction taken from the
// nearest of the sky's K shadow-mapped directions (each stands for its
// cell of the sphere, as an area light's N points stand for theirs), with
// the media's transmittance toward it. Exact where the whole sky or none of
// it is seen; a narrow lobe pointing at a wall is shadowed by that wall,
// which weighting the K directions by f could not see.
fn sky_glossy(l: Light, x: vec3<f32>, n: vec3<f32>, r: Reflector, rng: ptr<function, u32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var m = 0u; m < AREA_SAMPLES; m++) {
        if (!loop_iteration()) {
            break;
        }
        let b = glossy_sample(r, n, rng);
        if (!b.valid) {
            continue;
        }
        let wi = local_to_world(b.wi, n);
        var nearest = 0u;
        var best = -2.0;
        for (var k = 0u; k < l.sample_count; k++) {
            if (!loop_iteration()) {
                break;
            }
            let c = dot(wi, light_sample(l.first_sample + k).direction);
            if (c > best) {
                best = c;
                nearest = k;
            }
        }
        let s = light_sample(l.first_sample + nearest);
        if (above_surface(wi) && visible(s, x, n)) {
            sum += b.weight * light_transmittance(x, distant_start(l, x, s.direction));
        }
    }
    return l.emission * sum / f32(AREA_SAMPLES);
}

// A sky image's light reflected at x: its K directions were drawn from the
// image in proportion to radiance × solid angle, each weighted L/(K·p), so
// Σ_k f·L_k/(K·p_k)·cos·V_k estimates ∫ f L cos V dω: a sun in the image
// gets many of them and its hard shadow; Lambertian and glossy points alike
// (a glossy lobe narrower than the directions' spacing is a quadrature).
fn sky_image(l: Light, x: vec3<f32>, n: vec3<f32>, r: Reflector) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < l.sample_count; k++) {
        if (!loop_iteration()) {
            break;
        }
        let s = light_sample(l.first_sample + k);
        let cos = dot(n, s.direction);
        if (cos > 0.0 && above_surface(s.direction) && visible(s, x, n)) {
            let t = light_transmittance(x, distant_start(l, x, s.direction));
            sum += reflector_f(r, n, s.direction) * s.weight * cos * t;
        }
    }
    return l.emission * sum;
}

// Meshes of at most this many triangles take BRDF samples too (each tested
// against every triangle); larger ones light samples alone (unbiased, but
// noisy on narrow lobes).
const MESH_MIS_TRIANGLES: u32 = 64u;

// One triangle of an emissive mesh: a vertex, its two edges from it (front
// normal e1 × e2) and the mesh's area up to and including it
// (light_samples.rs, `add_triangles`).
struct MeshTriangle {
    v0: vec3<f32>,
    e1: vec3<f32>,
    e2: vec3<f32>,
    cumulative_area: f32,
}

fn mesh_triangle(l: Light, i: u32) -> MeshTriangle {
    let s = light_sample(l.first_triangle + i);
    return MeshTriangle(s.position, s.direction, s.weight, bitcast<f32>(s.first_view));
}

// The cosine at the light of a ray leaving mesh triangle normal `nl`
// toward −wi, zero where that face does not emit.
fn mesh_emitting_cos(l: Light, nl: vec3<f32>, wi: vec3<f32>) -> f32 {
    let c = -dot(wi, nl);
    if (l.two_sided != 0u) {
        return abs(c);
    }
    return max(c, 0.0);
}

// A point of mesh l, uniform in area (its triangle by cumulative area, u.x
// reused inside it, then the square-root map), and its triangle's unit normal.
struct MeshPoint {
    position: vec3<f32>,
    normal: vec3<f32>,
}

fn mesh_sample_point(l: Light, area: f32, u: vec2<f32>) -> MeshPoint {
    let target_area = u.x * area;
    var lo = 0u;
    var hi = l.triangle_count - 1u;
    while (lo < hi) {
        if (!loop_iteration()) {
            break;
        }
        let mid = (lo + hi) / 2u;
        if (mesh_triangle(l, mid).cumulative_area <= target_area) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let t = mesh_triangle(l, lo);
    var start = 0.0;
    if (lo > 0u) {
        start = mesh_triangle(l, lo - 1u).cumulative_area;
    }
    let width = t.cumulative_area - start;
    var ux = 0.5;
    if (width > 0.0) {
        ux = clamp((target_area - start) / width, 0.0, 1.0);
    }
    let a = sqrt(ux);
    let p = t.v0 + t.e1 * (a * (1.0 - u.y)) + t.e2 * (a * u.y);
    return MeshPoint(p, unit(cross(t.e1, t.e2)));
}

// ∫ f L cos dω over emissive mesh l at a glossy point, unshadowed (its own
// faces do not hide each other, as its shadow views leave them out):
// `AREA_SAMPLES` area-uniform light samples a pass, and for small meshes as
// many BRDF samples counted at every emitting triangle they cross, combined
// by the power heuristic; then scaled by the fraction of the f-weighted
// light its N shadow-mapped points see (as a quad's fraction scales its
// closed form).
fn mesh_glossy(l: Light, x: vec3<f32>, n: vec3<f32>, r: Reflector, rng: ptr<function, u32>) -> vec3<f32> {
    let area = mesh_triangle(l, l.triangle_count - 1u).cumulative_area;
    if (area <= 0.0) {
        return vec3<f32>(0.0);
    }
    let brdf_samples = l.triangle_count <= MESH_MIS_TRIANGLES;
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < AREA_SAMPLES; k++) {
        if (!loop_iteration()) {
            break;
        }
        let m = mesh_sample_point(l, area, stream_next_2d(rng));
        let to_light = m.position - x;
        let d2 = dot(to_light, to_light);
        if (d2 > 0.0) {
            let wi = to_light / sqrt(d2);
            let cos_l = mesh_emitting_cos(l, m.normal, wi);
            let local = to_shading(wi, n);
            if (cos_l > 0.0 && local.z > 0.0) {
                let pdf_light = d2 / (area * cos_l);
                var weight = 1.0;
                if (brdf_samples) {
                    weight = power_heuristic(pdf_light, bsdf_pdf(r.bsdf, r.wo, local));
                }
                sum += glossy_f(r, wi, local) * (local.z / pdf_light * weight);
            }
        }
        if (!brdf_samples) {
            continue;
        }
        let s = glossy_sample(r, n, rng);
        if (!s.valid) {
            continue;
        }
        let dir = local_to_world(s.wi, n);
        for (var i = 0u; i < l.triangle_count; i++) {
            if (!loop_iteration()) {
                break;
            }
            let t = mesh_triangle(l, i);
            // Möller–Trumbore.
            let p = cross(dir, t.e2);
            let det = dot(t.e1, p);
            if (det == 0.0) {
                continue;
            }
            let to_x = x - t.v0;
            let b1 = dot(to_x, p) / det;
            let q = cross(to_x, t.e1);
            let b2 = dot(dir, q) / det;
            let dist = dot(t.e2, q) / det;
            if (b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || dist <= 0.0) {
                continue;
            }
            let cos_l = mesh_emitting_cos(l, unit(cross(t.e1, t.e2)), dir);
            if (cos_l > 0.0) {
                let pdf_light = dist * dist / (area * cos_l);
                sum += s.weight * power_heuristic(s.pdf, pdf_light);
            }
        }
    }
    let unshadowed = l.emission * sum / f32(AREA_SAMPLES);
    var seen = vec3<f32>(0.0);
    var total = vec3<f32>(0.0);
    for (var k = 0u; k < l.sample_count; k++) {
        if (!loop_iteration()) {
            break;
        }
        let s = light_sample(l.first_sample + k);
        let to_light = s.position - x;
        let d2 = dot(to_light, to_light);
        if (d2 <= 0.0) {
            continue;
        }
        let wi = to_light / sqrt(d2);
        let weight = reflector_f(r, n, wi) * (max(dot(n, wi), 0.0) * mesh_emitting_cos(l, s.direction, wi) / (d2 + l.sample_area / PI));
        total += weight;
        if (any(weight > vec3<f32>(0.0)) && above_surface(wi) && visible(s, x, n)) {
            seen += weight * light_transmittance(x, s.position);
        }
    }
    return unshadowed * select(vec3<f32>(0.0), seen / total, total > vec3<f32>(0.0));
}

// Radiance reflected at x (normal n) from a light whose samples are each
// evaluated on their own, shadowed:
// * the sky (radiance L from every direction): a Lambertian point takes
//   πL·ρ/π, what the upper hemisphere gives, times the cosine-weighted
//   fraction of its K fixed directions that see x. Exact where all or none
//   see it; in between a sky seen through K hard shadows, as an area light
//   is N hard shadows (each weighed by the bump shadowing of its direction
//   at a normal-mapped point). A glossy point: `sky_glossy`.
// * an emissive mesh at a Lambertian point: Σ_k ρ/π·L·a·cos_l·cos_x/(d² + a/π)
//   over its N points, each standing for its share a = A/N of the area (the
//   small-disc form of a/d²), one-sided unless two-sided. A glossy point:
//   `mesh_glossy`.
fn sampled_radiance(l: Light, x: vec3<f32>, n: vec3<f32>, r: Reflector, rng: ptr<function, u32>) -> vec3<f32> {
    if (SKY_IMAGE && l.kind == KIND_SKY && l.mapped != 0u) {
        return sky_image(l, x, n, r);
    }
    if (l.kind == KIND_SKY && r.glossy) {
        return sky_glossy(l, x, n, r, rng);
    }
    if (l.kind == KIND_MESH && r.glossy) {
        return mesh_glossy(l, x, n, r, rng);
    }
    var seen = vec3<f32>(0.0);
    var total_weight = 0.0;
    for (var k = 0u; k < l.sample_count; k++) {
        if (!loop_iteration()) {
            break;
        }
        let s = light_sample(l.first_sample + k);
        var weight = 0.0;
        var end = s.position;
        var wi = s.direction;
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
            wi = to_light / sqrt(d2);
            let cos_l = mesh_emitting_cos(l, s.direction, wi);
            // Each point stands for a disc of its share of the area: on its
            // axis that gives L·a/(d² + a/π) exactly, which stays finite
            // (at most πL) where a point's a/d² would not.
            weight = max(dot(n, wi), 0.0) * cos_l / (d2 + l.sample_area / PI);
        }
        if (weight > 0.0 && above_surface(wi) && visible(s, x, n)) {
            seen += weight * reflector_bump(r, wi) * light_transmittance(x, end);
        }
    }
    if (l.kind == KIND_SKY) {
        if (total_weight <= 0.0) {
            return vec3<f32>(0.0);
        }
        return r.albedo * l.emission * seen / total_weight;
    }
    return r.albedo / PI * l.emission * l.sample_area * seen;
}

// The fraction of light `l`'s shadow-mapped samples seen from x (normal
// `n`, the side they are seen from), each attenuated by the media between
// and weighed by the bump shadowing `bump` of its direction (a normal-mapped
// Lambertian point's closed form: exact for point, spot and sun, the
// samples' mean over a sphere or quad; `no_bump()` elsewhere).
fn shadowed_fraction(l: Light, x: vec3<f32>, n: vec3<f32>, bump: BumpShadow) -> vec3<f32> {
    var seen = vec3<f32>(0.0);
    for (var k = 0u; k < l.sample_count; k++) {
        if (!loop_iteration()) {
            break;
        }
        let s = light_sample(l.first_sample + k);
        var toward = s.position - x;
        if (l.kind == KIND_SUN) {
            toward = l.axis;
        }
        if (above_surface(toward) && visible(s, x, n)) {
            var end = s.position;
            if (l.kind == KIND_SUN) {
                end = distant_start(l, x, l.axis);
            }
            var shadowing = 1.0;
            if (bump_mapped() && bump.alpha >= 0.0) {
                shadowing = bump_term(bump, unit(toward));
            }
            seen += light_transmittance(x, end) * shadowing;
        }
    }
    return seen / f32(l.sample_count);
}

fn direct_radiance(x: vec3<f32>, n: vec3<f32>, r: Reflector, rng: ptr<function, u32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < direct_params.light_count; i++) {
        if (!loop_iteration()) {
            break;
        }
        let l = light_record(i);
        if (SAMPLED_LIGHTS && (l.kind == KIND_SKY || l.kind == KIND_MESH)) {
            sum += sampled_radiance(l, x, n, r, rng);
            continue;
        }
        let e = unshadowed_irradiance(l, x, n);
        if (all(e == vec3<f32>(0.0))) {
            continue;
        }
        if (!r.glossy) {
            sum += r.albedo / PI * e * shadowed_fraction(l, x, n, r.bump);
            continue;
        }
        let fraction = shadowed_fraction(l, x, n, no_bump());
        if (l.kind == 2u || l.kind == 3u) {
            sum += area_glossy(l, x, n, r, rng) * fraction;
        } else {
            // Point, spot, sun: one direction, f exact.
            var wi = l.axis;
            if (l.kind != KIND_SUN) {
                wi = unit(l.position - x);
            }
            sum += reflector_f(r, n, wi) * e * fraction;
        }
    }
    return sum;
}
