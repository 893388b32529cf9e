// The glTF 2.0 metallic–roughness BRDF (hikari_core::bsdf and bsdf::ggx),
// operation for operation in the local shading frame (normal +z): wo toward
// the viewer, wi toward the light. A test (tests/bsdf.rs) pins every
// function here to its Rust twin on random inputs. `unit` is optics.wgsl's
// glam-exact normalize, so the GPU tracer keeps the CPU's bits.
//
// The sheen's albedo table (bsdf::sheen::SHEEN_ALBEDO) is read from the
// `surfaces` buffer (surface.wgsl's `Surfaces`), which every includer binds.

const SMOOTH_ROUGHNESS: f32 = 0.05;
const GATHER_ROUGHNESS: f32 = 0.35;
const ALPHA_MIN: f32 = 1.0e-4;
const DIELECTRIC_F0: f32 = 0.04;
const MIN_LOBE_WEIGHT: f32 = 1.0e-4;

struct Bsdf {
    base_color: vec3<f32>,
    metallic: f32,
    roughness: f32,
    specular: f32,
    clearcoat: f32,
    clearcoat_roughness: f32,
    // The dielectric's reflectance at normal incidence (KHR_materials_ior).
    f0: f32,
    // The Charlie sheen over the base (KHR_materials_sheen; black: none).
    sheen_color: vec3<f32>,
    sheen_roughness: f32,
    // KHR_materials_specular's colour: scales F0 per channel.
    specular_color: vec3<f32>,
    // The coat's own normal in the shading frame (+z: the base's; a
    // clearcoatNormalTexture tilts it, `with_coat_normal`).
    coat_normal: vec3<f32>,
    // The coat's mean reflectance's (1 − cos)^5 term (Bsdf::coat_schlick_mean).
    coat_schlick_mean: f32,
}

// The largest f32 below 1 (clearcoat.rs's ONE_BELOW).
const ONE_BELOW: f32 = 0.99999994;

// ---- ggx ----

fn ggx_sin2(w: vec3<f32>) -> f32 {
    return w.x * w.x + w.y * w.y;
}

fn ggx_d(h: vec3<f32>, alpha: f32) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = a2 * h.z * h.z + ggx_sin2(h);
    return a2 / (PI * t * t);
}

// Smith's G1 = 1/(1 + Λ): zero in the tangent plane, where Λ is infinite.
fn ggx_g1(w: vec3<f32>, alpha: f32) -> f32 {
    let z2 = w.z * w.z;
    if (z2 == 0.0) {
        return 0.0;
    }
    let lambda = 0.5 * (sqrt(1.0 + alpha * alpha * (ggx_sin2(w) / z2)) - 1.0);
    return 1.0 / (1.0 + lambda);
}

fn ggx_visibility(wo: vec3<f32>, wi: vec3<f32>, alpha: f32) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let lo = sqrt(wo.z * wo.z + a2 * ggx_sin2(wo));
    let li = sqrt(wi.z * wi.z + a2 * ggx_sin2(wi));
    return 0.5 / (wi.z * lo + wo.z * li);
}

// Heitz 2018, listing 1 (ggx::sample_visible_normal).
fn ggx_sample_visible_normal(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = unit(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if (len2 > 0.0) {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) / sqrt(len2);
    }
    let t2 = cross(vh, t1);
    let disk = unit_circle(u.y) * sqrt(u.x);
    let s = 0.5 * (1.0 + vh.z);
    let p1 = disk.x;
    let p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * disk.y;
    let nh = p1 * t1 + p2 * t2 + sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0)) * vh;
    return unit(vec3<f32>(alpha * nh.x, alpha * nh.y, max(nh.z, 0.0)));
}

fn ggx_reflect(wo: vec3<f32>, h: vec3<f32>) -> vec3<f32> {
    return 2.0 * dot(wo, h) * h - wo;
}

fn ggx_reflection_pdf(wo: vec3<f32>, h: vec3<f32>, alpha: f32) -> f32 {
    if (wo.z <= 0.0 || dot(wo, h) <= 0.0) {
        return 0.0;
    }
    return ggx_g1(wo, alpha) * ggx_d(h, alpha) / (4.0 * wo.z);
}

// ---- the BRDF ----

fn schlick_weight(cos: f32) -> f32 {
    let m = clamp(1.0 - cos, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

fn bsdf_alpha(b: Bsdf) -> f32 {
    return max(b.roughness * b.roughness, ALPHA_MIN);
}

fn bsdf_is_smooth(b: Bsdf) -> bool {
    return b.roughness < SMOOTH_ROUGHNESS;
}

fn bsdf_has_specular(b: Bsdf) -> bool {
    return b.metallic > 0.0 || b.specular > 0.0;
}

fn bsdf_has_diffuse(b: Bsdf) -> bool {
    return b.metallic < 1.0 && max(b.base_color.x, max(b.base_color.y, b.base_color.z)) > 0.0;
}

// The photon maps stand for the base's specular lobe (Bsdf::gathers_specular).
fn bsdf_gathers_specular(b: Bsdf) -> bool {
    return b.roughness >= GATHER_ROUGHNESS;
}

// min(f0·specular_color, 1) per channel (Bsdf::dielectric_f0).
fn bsdf_dielectric_f0(b: Bsdf) -> vec3<f32> {
    return min(b.specular_color * b.f0, vec3<f32>(1.0));
}

fn bsdf_specular_fresnel(b: Bsdf, cos: f32) -> vec3<f32> {
    let w = schlick_weight(cos);
    let f0 = bsdf_dielectric_f0(b);
    let f_dielectric = (f0 + (vec3<f32>(1.0) - f0) * w) * b.specular;
    let f_metal = b.base_color + (vec3<f32>(1.0) - b.base_color) * w;
    return f_dielectric * (1.0 - b.metallic) + b.metallic * f_metal;
}

fn bsdf_diffuse_reflectance(b: Bsdf, cos: f32) -> vec3<f32> {
    let f0 = bsdf_dielectric_f0(b);
    let f = f0 + (vec3<f32>(1.0) - f0) * schlick_weight(cos);
    let f_dielectric = max(f.x, max(f.y, f.z));
    return b.base_color * ((1.0 - b.metallic) * (1.0 - b.specular * f_dielectric));
}

fn rgb_mean(c: vec3<f32>) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

// ---- the sheen (bsdf::sheen) ----

const MIN_SHEEN_ROUGHNESS: f32 = 0.07;
const SHEEN_TABLE_SIZE: u32 = 32u;

// SHEENED (features.wgsl) folds the sheen's code away in scenes without one.
fn bsdf_has_sheen(b: Bsdf) -> bool {
    return SHEENED && max(b.sheen_color.x, max(b.sheen_color.y, b.sheen_color.z)) > 0.0;
}

fn sheen_effective_roughness(roughness: f32) -> f32 {
    return clamp(roughness, MIN_SHEEN_ROUGHNESS, 1.0);
}

fn charlie_d(cos_h: f32, alpha: f32) -> f32 {
    let inv = 1.0 / alpha;
    let sin2 = max(1.0 - cos_h * cos_h, 0.0);
    return (2.0 + inv) * pow(sin2, 0.5 * inv) / (2.0 * PI);
}

fn charlie_lambda_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let a = 21.5473 + (25.3245 - 21.5473) * t;
    let b = 3.82987 + (3.32435 - 3.82987) * t;
    let c = 0.19823 + (0.16801 - 0.19823) * t;
    let d = -1.97760 + (-1.27393 - -1.97760) * t;
    let e = -4.32054 + (-4.85967 - -4.32054) * t;
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

fn charlie_lambda(cos: f32, alpha: f32) -> f32 {
    let c = abs(cos);
    if (c < 0.5) {
        return exp(charlie_lambda_fit(c, alpha));
    }
    return exp(2.0 * charlie_lambda_fit(0.5, alpha) - charlie_lambda_fit(1.0 - c, alpha));
}

fn charlie_visibility(cos_o: f32, cos_i: f32, alpha: f32) -> f32 {
    let g = 1.0 + charlie_lambda(cos_o, alpha) + charlie_lambda(cos_i, alpha);
    return min(1.0 / (g * 4.0 * cos_o * cos_i), 1.0);
}

fn white_sheen(wo: vec3<f32>, wi: vec3<f32>, roughness: f32) -> f32 {
    let alpha = roughness * roughness;
    let h = unit(wo + wi);
    return charlie_d(h.z, alpha) * charlie_visibility(wo.z, wi.z, alpha);
}

// E(cos θ, r), bilinear in (√cos θ, r) (sheen::sheen_albedo).
fn sheen_albedo(cos: f32, roughness: f32) -> f32 {
    let last = f32(SHEEN_TABLE_SIZE - 1u);
    let x = sqrt(clamp(cos, 0.0, 1.0)) * last;
    let y = sheen_effective_roughness(roughness) * last;
    let i = min(u32(x), SHEEN_TABLE_SIZE - 2u);
    let j = min(u32(y), SHEEN_TABLE_SIZE - 2u);
    let fx = x - f32(i);
    let fy = y - f32(j);
    let k = j * SHEEN_TABLE_SIZE + i;
    let a = surfaces.sheen_albedo[k];
    let b = surfaces.sheen_albedo[k + 1u];
    let c = surfaces.sheen_albedo[k + SHEEN_TABLE_SIZE];
    let d = surfaces.sheen_albedo[k + SHEEN_TABLE_SIZE + 1u];
    let row0 = a + (b - a) * fx;
    let row1 = c + (d - c) * fx;
    return row0 + (row1 - row0) * fy;
}

fn sheen_albedo_at(b: Bsdf, cos: f32) -> f32 {
    return min(sheen_albedo(cos, b.sheen_roughness), 1.0);
}

// S and f_sheen between wo and wi (Bsdf::sheen_parts): x the scaling, yzw the lobe.
fn sheen_parts(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let r = sheen_effective_roughness(b.sheen_roughness);
    let e = max(sheen_albedo(wo.z, r), sheen_albedo(wi.z, r));
    let m = min(max(b.sheen_color.x, max(b.sheen_color.y, b.sheen_color.z)), 1.0);
    return vec4<f32>(1.0 - m * min(e, 1.0), b.sheen_color * (white_sheen(wo, wi, r) / max(e, 1.0)));
}

fn sheen_weight(b: Bsdf, cos_o: f32) -> f32 {
    if (!bsdf_has_sheen(b)) {
        return 0.0;
    }
    return rgb_mean(b.sheen_color) * sheen_albedo_at(b, cos_o);
}

// ---- the base's lobes ----

// Probabilities of sampling the specular (x) and the sheen (y) lobe at wo;
// x negative when no lobe reflects anything (Bsdf::lobe_probabilities's None).
fn bsdf_lobe_probabilities(b: Bsdf, cos_o: f32) -> vec2<f32> {
    var diffuse = 0.0;
    if (bsdf_has_diffuse(b)) {
        diffuse = max(rgb_mean(bsdf_diffuse_reflectance(b, cos_o)), MIN_LOBE_WEIGHT);
    }
    var specular = 0.0;
    if (bsdf_has_specular(b)) {
        specular = max(rgb_mean(bsdf_specular_fresnel(b, cos_o)), MIN_LOBE_WEIGHT);
    }
    var sheen = 0.0;
    if (bsdf_has_sheen(b)) {
        sheen = max(sheen_weight(b, cos_o), MIN_LOBE_WEIGHT);
    }
    let total = diffuse + specular + sheen;
    if (total > 0.0) {
        return vec2<f32>(specular / total, sheen / total);
    }
    return vec2<f32>(-1.0, 0.0);
}

// The parts of f (Bsdf::f_lobes): diffuse and microfacet as the sheen
// leaves them, and the sheen.
struct Lobes {
    diffuse: vec3<f32>,
    specular: vec3<f32>,
    sheen: vec3<f32>,
}

// `k` weighs the diffuse and sheen lobes: a normal-mapped point's bump
// shadowing of the light's direction (`bump_term`), 1 elsewhere.
fn bsdf_f_lobes(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, k: f32) -> Lobes {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return Lobes(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    }
    let h = unit(wo + wi);
    let cos = 0.5 * (dot(wo, h) + dot(wi, h));
    var lobes = Lobes(bsdf_diffuse_reflectance(b, cos) / PI, vec3<f32>(0.0), vec3<f32>(0.0));
    if (!bsdf_is_smooth(b) && bsdf_has_specular(b)) {
        let alpha = bsdf_alpha(b);
        lobes.specular = bsdf_specular_fresnel(b, cos) * (ggx_d(h, alpha) * ggx_visibility(wo, wi, alpha));
    }
    if (bsdf_has_sheen(b)) {
        let parts = sheen_parts(b, wo, wi);
        lobes.diffuse *= parts.x;
        lobes.specular *= parts.x;
        lobes.sheen = parts.yzw * k;
    }
    lobes.diffuse *= k;
    return lobes;
}

fn bsdf_base_f(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, k: f32) -> vec3<f32> {
    let lobes = bsdf_f_lobes(b, wo, wi, k);
    return lobes.diffuse + lobes.specular + lobes.sheen;
}

fn bsdf_base_pdf(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let p = bsdf_lobe_probabilities(b, wo.z);
    if (p.x < 0.0) {
        return 0.0;
    }
    var pdf = (1.0 - p.x - p.y) * max(wi.z, 0.0) / PI;
    if (p.x > 0.0 && !bsdf_is_smooth(b)) {
        pdf += p.x * ggx_reflection_pdf(wo, unit(wo + wi), bsdf_alpha(b));
    }
    if (p.y > 0.0) {
        pdf += p.y * (1.0 / (2.0 * PI));
    }
    return pdf;
}

// Bsdf::sample's result; `valid` false for its None.
struct BsdfSample {
    wi: vec3<f32>,
    pdf: f32,
    f: vec3<f32>,
    is_delta: bool,
    weight: vec3<f32>,
    followed: bool,
    valid: bool,
}

fn no_bsdf_sample() -> BsdfSample {
    return BsdfSample(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), false, vec3<f32>(0.0), false, false);
}

fn bsdf_base_sample(b: Bsdf, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> BsdfSample {
    if (wo.z <= 0.0) {
        return no_bsdf_sample();
    }
    let p = bsdf_lobe_probabilities(b, wo.z);
    let p_specular = p.x;
    if (p_specular < 0.0) {
        return no_bsdf_sample();
    }
    let specular = u_lobe < p_specular;
    var wi: vec3<f32>;
    if (specular) {
        if (bsdf_is_smooth(b)) {
            let fresnel = bsdf_specular_fresnel(b, wo.z);
            return BsdfSample(vec3<f32>(-wo.x, -wo.y, wo.z), p_specular, fresnel / wo.z, true, fresnel / p_specular, true, true);
        }
        wi = ggx_reflect(wo, ggx_sample_visible_normal(wo, bsdf_alpha(b), u));
    } else if (u_lobe < p_specular + p.y) {
        wi = uniform_cone(u, 0.0);
    } else {
        wi = cosine_hemisphere(u);
    }
    if (wi.z <= 0.0) {
        return no_bsdf_sample();
    }
    let pdf = bsdf_base_pdf(b, wo, wi);
    if (pdf <= 0.0) {
        return no_bsdf_sample();
    }
    let f = bsdf_base_f(b, wo, wi, 1.0);
    return BsdfSample(wi, pdf, f, false, f * (wi.z / pdf), specular && !bsdf_gathers_specular(b), true);
}

// A direction from the base's specular lobe alone (Bsdf::sample_specular_lobe).
fn bsdf_sample_specular_lobe(b: Bsdf, wo: vec3<f32>, u: vec2<f32>) -> BsdfSample {
    if (wo.z <= 0.0 || !bsdf_has_specular(b)) {
        return no_bsdf_sample();
    }
    if (bsdf_is_smooth(b)) {
        let fresnel = bsdf_specular_fresnel(b, wo.z);
        return BsdfSample(vec3<f32>(-wo.x, -wo.y, wo.z), 1.0, fresnel / wo.z, true, fresnel, true, true);
    }
    let alpha = bsdf_alpha(b);
    let h = ggx_sample_visible_normal(wo, alpha, u);
    let wi = ggx_reflect(wo, h);
    let pdf = ggx_reflection_pdf(wo, h, alpha);
    if (wi.z <= 0.0 || pdf <= 0.0) {
        return no_bsdf_sample();
    }
    let f = bsdf_f_lobes(b, wo, wi, 1.0).specular;
    return BsdfSample(wi, pdf, f, false, f * (wi.z / pdf), !bsdf_gathers_specular(b), true);
}

// Bsdf::base_albedo_estimate.
fn bsdf_base_albedo_estimate(b: Bsdf) -> vec3<f32> {
    let f0 = bsdf_dielectric_f0(b);
    let f_dielectric = (f0 + (vec3<f32>(1.0) - f0) / 21.0) * b.specular;
    let diffuse = b.base_color * ((1.0 - b.metallic) * (1.0 - max(f_dielectric.x, max(f_dielectric.y, f_dielectric.z))));
    let average = b.base_color + (vec3<f32>(1.0) - b.base_color) / 21.0;
    let specular = f_dielectric * (1.0 - b.metallic) + b.metallic * average;
    if (bsdf_has_sheen(b)) {
        let e = sheen_albedo_at(b, 0.5);
        let m = min(max(b.sheen_color.x, max(b.sheen_color.y, b.sheen_color.z)), 1.0);
        return (diffuse + specular) * (1.0 - m * e) + b.sheen_color * e;
    }
    return diffuse + specular;
}

// ---- the clear coat (bsdf::clearcoat) ----

// COATED (features.wgsl) folds the coat's code away in scenes without one.
fn bsdf_has_coat(b: Bsdf) -> bool {
    return COATED && b.clearcoat > 0.0;
}

fn coat_is_smooth(b: Bsdf) -> bool {
    return b.clearcoat_roughness < SMOOTH_ROUGHNESS;
}

fn coat_is_gathered(b: Bsdf) -> bool {
    return b.clearcoat_roughness >= GATHER_ROUGHNESS;
}

// Bsdf::with_coat_normal: the coat on its own normal `n` (shading frame),
// tilted by its texture.
fn with_coat_normal(b: Bsdf, n: vec3<f32>) -> Bsdf {
    var out = with_unbent_coat(b, n);
    out.coat_schlick_mean = tilted_schlick_mean(out.coat_normal.z);
    return out;
}

// Bsdf::with_unbent_coat: `n` (shading frame) normalised; +z where it is
// at or below the base's horizon or not a direction.
fn with_unbent_coat(b: Bsdf, n: vec3<f32>) -> Bsdf {
    var out = b;
    out.coat_schlick_mean = 1.0 / 21.0;
    let len2 = dot(n, n);
    let recip = 1.0 / sqrt(len2);
    out.coat_normal = vec3<f32>(0.0, 0.0, 1.0);
    if (recip > 0.0 && recip <= 3.0e38) {
        let unit_n = n * recip;
        if (unit_n.z > 0.0) {
            out.coat_normal = unit_n;
        }
    }
    return out;
}

// The coat lies apart from the base. Only LAYERED scenes (clear-coat
// normal textures among the layer textures) tilt a coat.
fn coat_is_tilted(b: Bsdf) -> bool {
    return LAYERED && any(b.coat_normal != vec3<f32>(0.0, 0.0, 1.0));
}

// `w` (shading frame) in the coat's frame (Bsdf::to_coat).
fn to_coat(b: Bsdf, w: vec3<f32>) -> vec3<f32> {
    if (!coat_is_tilted(b)) {
        return w;
    }
    return to_shading(w, b.coat_normal);
}

// `w` (coat's frame) in the shading frame (Bsdf::from_coat).
fn from_coat(b: Bsdf, w: vec3<f32>) -> vec3<f32> {
    if (!coat_is_tilted(b)) {
        return w;
    }
    let basis = orthonormal_basis(b.coat_normal);
    return basis.t * w.x + basis.b * w.y + b.coat_normal * w.z;
}

fn coat_alpha(b: Bsdf) -> f32 {
    return max(b.clearcoat_roughness * b.clearcoat_roughness, ALPHA_MIN);
}

fn coat_fresnel(b: Bsdf, cos: f32) -> f32 {
    return b.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * schlick_weight(cos));
}

fn coat_transmission(b: Bsdf, cos: f32) -> f32 {
    return 1.0 - coat_fresnel(b, cos);
}

// clearcoat::tilted_schlick_mean: the cosine-weighted mean of (1 − cos)^5
// to a coat normal tilted acos(z) from the base's, its fit in the angle.
fn tilted_schlick_mean(z: f32) -> f32 {
    let theta = acos(clamp(z, -1.0, 1.0));
    var sum = -0.015920898;
    sum = sum * theta + 0.072868034;
    sum = sum * theta - 0.20406739;
    sum = sum * theta + 0.42324913;
    sum = sum * theta + 0.007523404;
    return sum * theta + 0.047376793;
}

fn coat_diffuse_through(b: Bsdf, cos_o: f32, cos_i: f32) -> f32 {
    var mean_reflectance = b.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) / 21.0);
    if (coat_is_tilted(b)) {
        mean_reflectance = b.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * b.coat_schlick_mean);
    }
    return coat_transmission(b, cos_o) * coat_transmission(b, cos_i) / (1.0 - mean_reflectance);
}

fn coat_specular_through(b: Bsdf, cos_o: f32, cos_i: f32) -> f32 {
    return sqrt(coat_transmission(b, cos_o) * coat_transmission(b, cos_i));
}

// The base's lobes between `wo` and `wi` (`co`, `ci` in the coat's frame)
// as the coat leaves them: the diffuse lobe by the cosines to the coat's
// normal, the specular and the sheen (dimmed like it) by those to the
// shading normal.
fn under_coat(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, co: vec3<f32>, ci: vec3<f32>, lobes: Lobes) -> vec3<f32> {
    return lobes.diffuse * coat_diffuse_through(b, co.z, ci.z)
        + (lobes.specular + lobes.sheen) * coat_specular_through(b, wo.z, wi.z);
}

// The coat's lobe between `wo` and `wi` in the coat's frame.
fn coat_lobe(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (coat_is_smooth(b) || wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let h = unit(wo + wi);
    let cos = 0.5 * (dot(wo, h) + dot(wi, h));
    let alpha = coat_alpha(b);
    return coat_fresnel(b, cos) * ggx_d(h, alpha) * ggx_visibility(wo, wi, alpha);
}

fn coat_probability(b: Bsdf, cos_o: f32) -> f32 {
    if (cos_o <= 0.0) {
        return 0.0;
    }
    let coat = coat_fresnel(b, cos_o);
    let e = bsdf_base_albedo_estimate(b);
    let base = (1.0 - coat) * max(e.x, max(e.y, e.z));
    if (coat + base <= 0.0) {
        return 0.0;
    }
    return coat / (coat + base);
}

fn coated_f(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, k: f32) -> vec3<f32> {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let co = to_coat(b, wo);
    let ci = to_coat(b, wi);
    return under_coat(b, wo, wi, co, ci, bsdf_f_lobes(b, wo, wi, k)) + vec3<f32>(coat_lobe(b, co, ci));
}

fn coated_pdf(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let co = to_coat(b, wo);
    let p = coat_probability(b, co.z);
    var pdf = (1.0 - p) * bsdf_base_pdf(b, wo, wi);
    let ci = to_coat(b, wi);
    if (!coat_is_smooth(b) && ci.z > 0.0 && p > 0.0) {
        pdf += p * ggx_reflection_pdf(co, unit(co + ci), coat_alpha(b));
    }
    return pdf;
}

// The smooth coat's mirror at `co` (the view in the coat's frame), chosen
// with probability p; none where it leaves below the base.
fn coat_mirror(b: Bsdf, co: vec3<f32>, p: f32) -> BsdfSample {
    let wi = from_coat(b, vec3<f32>(-co.x, -co.y, co.z));
    if (wi.z <= 0.0) {
        return no_bsdf_sample();
    }
    let fc = coat_fresnel(b, co.z);
    return BsdfSample(wi, p, vec3<f32>(fc / wi.z), true, vec3<f32>(fc / p), true, true);
}

fn coated_finish(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, followed: bool) -> BsdfSample {
    if (wi.z <= 0.0) {
        return no_bsdf_sample();
    }
    let pdf = coated_pdf(b, wo, wi);
    if (pdf <= 0.0) {
        return no_bsdf_sample();
    }
    let f = coated_f(b, wo, wi, 1.0);
    return BsdfSample(wi, pdf, f, false, f * (wi.z / pdf), followed, true);
}

fn coated_sample(b: Bsdf, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> BsdfSample {
    if (wo.z <= 0.0) {
        return no_bsdf_sample();
    }
    let co = to_coat(b, wo);
    let p = coat_probability(b, co.z);
    if (u_lobe < p) {
        if (coat_is_smooth(b)) {
            return coat_mirror(b, co, p);
        }
        let ci = ggx_reflect(co, ggx_sample_visible_normal(co, coat_alpha(b), u));
        return coated_finish(b, wo, from_coat(b, ci), !coat_is_gathered(b));
    }
    let s = bsdf_base_sample(b, wo, min((u_lobe - p) / (1.0 - p), ONE_BELOW), u);
    if (!s.valid) {
        return s;
    }
    if (s.is_delta) {
        let through = coat_transmission(b, wo.z);
        let pdf = (1.0 - p) * s.pdf;
        return BsdfSample(s.wi, pdf, s.f * through, true, s.f * (through * wo.z / pdf), s.followed, true);
    }
    return coated_finish(b, wo, s.wi, s.followed);
}

fn coated_sample_followed(b: Bsdf, wo: vec3<f32>, u: vec2<f32>) -> BsdfSample {
    if (wo.z <= 0.0) {
        return no_bsdf_sample();
    }
    let co = to_coat(b, wo);
    var coat = 0.0;
    if (!coat_is_gathered(b) && co.z > 0.0) {
        coat = coat_fresnel(b, co.z);
    }
    var base = 0.0;
    if (bsdf_has_specular(b) && !bsdf_gathers_specular(b)) {
        base = coat_transmission(b, wo.z) * max(rgb_mean(bsdf_specular_fresnel(b, wo.z)), MIN_LOBE_WEIGHT);
    }
    if (coat + base <= 0.0) {
        return no_bsdf_sample();
    }
    let p = coat / (coat + base);
    if (u.x < p) {
        let uc = vec2<f32>(min(u.x / p, ONE_BELOW), u.y);
        if (coat_is_smooth(b)) {
            return coat_mirror(b, co, p);
        }
        let alpha = coat_alpha(b);
        let h = ggx_sample_visible_normal(co, alpha, uc);
        let ci = ggx_reflect(co, h);
        let wi = from_coat(b, ci);
        let pdf = p * ggx_reflection_pdf(co, h, alpha);
        if (wi.z <= 0.0 || ci.z <= 0.0 || pdf <= 0.0) {
            return no_bsdf_sample();
        }
        let f = vec3<f32>(coat_lobe(b, co, ci));
        return BsdfSample(wi, pdf, f, false, f * (wi.z / pdf), true, true);
    }
    let ub = vec2<f32>(min((u.x - p) / (1.0 - p), ONE_BELOW), u.y);
    let s = bsdf_sample_specular_lobe(b, wo, ub);
    if (!s.valid) {
        return s;
    }
    let through = coat_specular_through(b, wo.z, s.wi.z);
    return BsdfSample(s.wi, (1.0 - p) * s.pdf, s.f * through, s.is_delta, s.weight * (through / (1.0 - p)), s.followed, true);
}

// ---- the whole BSDF: the base, under the coat where there is one ----

fn bsdf_f(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    return bsdf_f_bumped(b, wo, wi, 1.0);
}

// `bsdf_f` with the diffuse and sheen lobes weighed by `k` (Bsdf::f_bumped).
fn bsdf_f_bumped(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, k: f32) -> vec3<f32> {
    if (bsdf_has_coat(b)) {
        return coated_f(b, wo, wi, k);
    }
    return bsdf_base_f(b, wo, wi, k);
}

// Sample `s` at `wo` with the diffuse and sheen lobes weighed by `k`: f and
// the weight change, the density not (Bsdf::reweigh).
fn bsdf_reweigh(b: Bsdf, wo: vec3<f32>, s: BsdfSample, k: f32) -> BsdfSample {
    if (k == 1.0 || s.is_delta || !s.valid) {
        return s;
    }
    var r = s;
    r.f = bsdf_f_bumped(b, wo, s.wi, k);
    r.weight = r.f * (s.wi.z / s.pdf);
    return r;
}

fn bsdf_pdf(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (bsdf_has_coat(b)) {
        return coated_pdf(b, wo, wi);
    }
    return bsdf_base_pdf(b, wo, wi);
}

fn bsdf_sample(b: Bsdf, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> BsdfSample {
    if (bsdf_has_coat(b)) {
        return coated_sample(b, wo, u_lobe, u);
    }
    return bsdf_base_sample(b, wo, u_lobe, u);
}

// What the photon maps stand for at this surface (Bsdf::f_gathered): the
// diffuse lobe and every lobe at least GATHER_ROUGHNESS rough.
fn bsdf_f_gathered(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    return bsdf_f_gathered_bumped(b, wo, wi, 1.0);
}

// `bsdf_f_gathered` with the diffuse and sheen lobes weighed by `k`.
fn bsdf_f_gathered_bumped(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>, k: f32) -> vec3<f32> {
    var lobes = bsdf_f_lobes(b, wo, wi, k);
    if (!bsdf_gathers_specular(b)) {
        lobes.specular = vec3<f32>(0.0);
    }
    if (!bsdf_has_coat(b)) {
        return lobes.diffuse + lobes.specular + lobes.sheen;
    }
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let co = to_coat(b, wo);
    let ci = to_coat(b, wi);
    var coat = 0.0;
    if (coat_is_gathered(b)) {
        coat = coat_lobe(b, co, ci);
    }
    return under_coat(b, wo, wi, co, ci, lobes) + vec3<f32>(coat);
}

// Photons are stored here (Bsdf::stores_photons).
fn bsdf_stores_photons(b: Bsdf) -> bool {
    return bsdf_has_diffuse(b) || (bsdf_has_specular(b) && bsdf_gathers_specular(b))
        || (bsdf_has_coat(b) && coat_is_gathered(b)) || bsdf_has_sheen(b);
}

// Some lobe is followed by the eye (Bsdf::follows_any).
fn bsdf_follows_any(b: Bsdf) -> bool {
    return (bsdf_has_specular(b) && !bsdf_gathers_specular(b)) || (bsdf_has_coat(b) && !coat_is_gathered(b));
}

// A direction from the lobes the eye follows (Bsdf::sample_followed).
fn bsdf_sample_followed(b: Bsdf, wo: vec3<f32>, u: vec2<f32>) -> BsdfSample {
    if (bsdf_has_coat(b)) {
        return coated_sample_followed(b, wo, u);
    }
    if (bsdf_gathers_specular(b)) {
        return no_bsdf_sample();
    }
    return bsdf_sample_specular_lobe(b, wo, u);
}

// ---- Cycles' bump map correction (hikari_core::bsdf::bump) ----

// A normal-mapped point's shadowing of its diffuse lobes: its smooth
// normal and the roughness α of its bend; α < 0 where nothing bends (the
// term is 1 there).
struct BumpShadow {
    unbent: vec3<f32>,
    alpha: f32,
}

fn no_bump() -> BumpShadow {
    return BumpShadow(vec3<f32>(0.0), -1.0);
}

// BumpShadow::new: smooth (interpolated) normal `unbent` bent to `bent`,
// both unit in one frame; α² = clamp(tan²θd / 8).
fn bump_shadow(unbent: vec3<f32>, bent: vec3<f32>) -> BumpShadow {
    let cos_d = abs(dot(unbent, bent));
    if (cos_d >= 1.0 || all(unbent == bent)) {
        return no_bump();
    }
    let alpha2 = clamp(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 0.0, 1.0);
    return BumpShadow(unbent, sqrt(alpha2));
}

// BumpShadow::term: Smith's GGX masking of |unbent·wi| (`wi` unit, in the
// normals' frame); 1 where nothing bends, 0 in the smooth surface's plane.
fn bump_term(b: BumpShadow, wi: vec3<f32>) -> f32 {
    if (b.alpha < 0.0) {
        return 1.0;
    }
    let cos_i = abs(dot(b.unbent, wi));
    if (cos_i >= 1.0) {
        return 1.0;
    }
    if (cos_i < 1.0e-6) {
        return 0.0;
    }
    return ggx_g1(vec3<f32>(sqrt(1.0 - cos_i * cos_i), 0.0, cos_i), b.alpha);
}

// World direction `w` in the shading frame around unit `n`
// (ShadingFrame::to_local; sampling.wgsl's basis).
fn to_shading(w: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let basis = orthonormal_basis(n);
    return vec3<f32>(dot(w, basis.t), dot(w, basis.b), dot(w, n));
}

// The BRDF of a glossy kind-0 surface whose base colour is `base` (the
// G-buffer's, textures applied; `s.albedo` where no texture is).
fn surface_bsdf(s: Surface, base: vec3<f32>) -> Bsdf {
    return Bsdf(base, s.metallic, s.roughness, s.specular_factor, s.clearcoat, s.clearcoat_roughness, s.dielectric_f0,
        s.sheen_color, s.sheen_roughness, s.specular_color, vec3<f32>(0.0, 0.0, 1.0), 1.0 / 21.0);
}

// The BRDF of glossy surface `s` at a point whose textures gave `base`,
// `metallic` and `roughness` (textures.wgsl's `surface_point`).
fn point_bsdf(s: Surface, base: vec3<f32>, metallic: f32, roughness: f32) -> Bsdf {
    return Bsdf(base, metallic, roughness, s.specular_factor, s.clearcoat, s.clearcoat_roughness, s.dielectric_f0,
        s.sheen_color, s.sheen_roughness, s.specular_color, vec3<f32>(0.0, 0.0, 1.0), 1.0 / 21.0);
}

// The BRDF at a G-buffer pixel of glossy surface `s`: base colour from the
// G-buffer's albedo, metallic and roughness from `packed` (its emission.w,
// surface_point.wgsl's `pack_metal_rough`) where a texture varies them.
fn pixel_bsdf(s: Surface, base: vec3<f32>, packed: f32) -> Bsdf {
    var b = surface_bsdf(s, base);
    // A texture, or a glass mix's draw (its base's metallic raised), varies them.
    if (s.metallic_roughness_texture != 0xffffffffu || (MIXED && s.transmission > 0.0)) {
        let metal_rough = unpack_metal_rough(packed);
        b.metallic = metal_rough.x;
        b.roughness = metal_rough.y;
    }
    return b;
}

// Metallic and roughness in one f32 of the G-buffer (emission.w), 12 bits
// each, exact as an integer-valued float. Read back (`pixel_bsdf`) only
// where a metallic–roughness texture or a glass mix's draw varies them:
// the others' come from `Surface` unrounded.
fn pack_metal_rough(metallic: f32, roughness: f32) -> f32 {
    return f32(u32(round(metallic * 4095.0)) * 4096u + u32(round(roughness * 4095.0)));
}

// `pack_metal_rough`'s (metallic, roughness).
fn unpack_metal_rough(packed: f32) -> vec2<f32> {
    let bits = u32(packed);
    return vec2<f32>(f32(bits / 4096u), f32(bits % 4096u)) / 4095.0;
}
