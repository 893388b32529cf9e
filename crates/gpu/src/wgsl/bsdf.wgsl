// The glTF 2.0 metallic–roughness BRDF (hikari_core::bsdf and bsdf::ggx),
// operation for operation in the local shading frame (normal +z): wo toward
// the viewer, wi toward the light. A test (tests/bsdf.rs) pins every
// function here to its Rust twin on random inputs. `unit` is optics.wgsl's
// glam-exact normalize, so the GPU tracer keeps the CPU's bits.

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
}

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

// The photon maps stand for the whole BRDF (Bsdf::gathers_specular).
fn bsdf_gathers_specular(b: Bsdf) -> bool {
    return b.roughness >= GATHER_ROUGHNESS;
}

fn bsdf_specular_fresnel(b: Bsdf, cos: f32) -> vec3<f32> {
    let w = schlick_weight(cos);
    let f_dielectric = b.specular * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * w);
    let f_metal = b.base_color + (vec3<f32>(1.0) - b.base_color) * w;
    return vec3<f32>((1.0 - b.metallic) * f_dielectric) + b.metallic * f_metal;
}

fn bsdf_diffuse_reflectance(b: Bsdf, cos: f32) -> vec3<f32> {
    let f_dielectric = DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * schlick_weight(cos);
    return b.base_color * ((1.0 - b.metallic) * (1.0 - b.specular * f_dielectric));
}

fn rgb_mean(c: vec3<f32>) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

// Probability of sampling the specular lobe at wo; negative when neither
// lobe reflects anything (Bsdf::specular_probability's None).
fn bsdf_specular_probability(b: Bsdf, cos_o: f32) -> f32 {
    var diffuse = 0.0;
    if (bsdf_has_diffuse(b)) {
        diffuse = max(rgb_mean(bsdf_diffuse_reflectance(b, cos_o)), MIN_LOBE_WEIGHT);
    }
    var specular = 0.0;
    if (bsdf_has_specular(b)) {
        specular = max(rgb_mean(bsdf_specular_fresnel(b, cos_o)), MIN_LOBE_WEIGHT);
    }
    let total = diffuse + specular;
    if (total > 0.0) {
        return specular / total;
    }
    return -1.0;
}

// The diffuse and microfacet parts of f (Bsdf::f_lobes).
struct Lobes {
    diffuse: vec3<f32>,
    specular: vec3<f32>,
}

fn bsdf_f_lobes(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> Lobes {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return Lobes(vec3<f32>(0.0), vec3<f32>(0.0));
    }
    let h = unit(wo + wi);
    let cos = 0.5 * (dot(wo, h) + dot(wi, h));
    let diffuse = bsdf_diffuse_reflectance(b, cos) / PI;
    if (bsdf_is_smooth(b) || !bsdf_has_specular(b)) {
        return Lobes(diffuse, vec3<f32>(0.0));
    }
    let alpha = bsdf_alpha(b);
    return Lobes(diffuse, bsdf_specular_fresnel(b, cos) * (ggx_d(h, alpha) * ggx_visibility(wo, wi, alpha)));
}

fn bsdf_f(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    let lobes = bsdf_f_lobes(b, wo, wi);
    return lobes.diffuse + lobes.specular;
}

// What the photon maps stand for at this surface (photon-cpu's `part`): all
// of f where they gather the specular lobe, else the diffuse lobe.
fn bsdf_f_gathered(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    let lobes = bsdf_f_lobes(b, wo, wi);
    if (bsdf_gathers_specular(b)) {
        return lobes.diffuse + lobes.specular;
    }
    return lobes.diffuse;
}

fn bsdf_pdf(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let p_specular = bsdf_specular_probability(b, wo.z);
    if (p_specular < 0.0) {
        return 0.0;
    }
    var pdf = (1.0 - p_specular) * max(wi.z, 0.0) / PI;
    if (p_specular > 0.0 && !bsdf_is_smooth(b)) {
        pdf += p_specular * ggx_reflection_pdf(wo, unit(wo + wi), bsdf_alpha(b));
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
    specular: bool,
    valid: bool,
}

fn no_bsdf_sample() -> BsdfSample {
    return BsdfSample(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), false, vec3<f32>(0.0), false, false);
}

fn bsdf_sample(b: Bsdf, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> BsdfSample {
    if (wo.z <= 0.0) {
        return no_bsdf_sample();
    }
    let p_specular = bsdf_specular_probability(b, wo.z);
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
    } else {
        wi = cosine_hemisphere(u);
    }
    if (wi.z <= 0.0) {
        return no_bsdf_sample();
    }
    let pdf = bsdf_pdf(b, wo, wi);
    if (pdf <= 0.0) {
        return no_bsdf_sample();
    }
    let f = bsdf_f(b, wo, wi);
    return BsdfSample(wi, pdf, f, false, f * (wi.z / pdf), specular, true);
}

// A direction from the specular lobe alone (Bsdf::sample_specular).
fn bsdf_sample_specular(b: Bsdf, wo: vec3<f32>, u: vec2<f32>) -> BsdfSample {
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
    let f = bsdf_f_lobes(b, wo, wi).specular;
    return BsdfSample(wi, pdf, f, false, f * (wi.z / pdf), true, true);
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
    return Bsdf(base, s.metallic, s.roughness, s.specular_factor);
}

// The BRDF at a G-buffer pixel of glossy surface `s`: base colour from the
// G-buffer's albedo, metallic and roughness from `packed` (its emission.w,
// surface_point.wgsl's `pack_metal_rough`) where a texture varies them.
fn pixel_bsdf(s: Surface, base: vec3<f32>, packed: f32) -> Bsdf {
    var b = surface_bsdf(s, base);
    if (s.metallic_roughness_texture != 0xffffffffu) {
        let bits = u32(packed);
        b.metallic = f32(bits / 4096u) / 4095.0;
        b.roughness = f32(bits % 4096u) / 4095.0;
    }
    return b;
}
