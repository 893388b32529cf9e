// Rough glass (hikari_core::bsdf::dielectric), operation for operation in
// the boundary's frame: +z its outward normal, wo.z > 0 outside (index 1),
// wo toward where the path came from. GGX reflection and transmission
// (Walter et al. 2007) sampled through the normals visible from wo; √tint
// colours each crossing; radiance crossing scales by 1/η'² (eye paths),
// power does not (photons). Smooth glass (roughness below SMOOTH_ROUGHNESS)
// is split by optics.wgsl's fresnel_dielectric instead. A test
// (tests/bsdf.rs) pins these functions to their Rust twins.

struct Dielectric {
    ior: f32,
    roughness: f32,
    tint: vec3<f32>,
}

struct GlassSample {
    wi: vec3<f32>,
    weight: vec3<f32>,
    pdf: f32,
    valid: bool,
    transmitted: bool,
}

fn glass_is_smooth(g: Dielectric) -> bool {
    return g.roughness < SMOOTH_ROUGHNESS;
}

fn glass_alpha(g: Dielectric) -> f32 {
    return max(g.roughness * g.roughness, ALPHA_MIN);
}

// η' = η(the other side)/η(wo's side).
fn glass_eta_across(g: Dielectric, wo_z: f32) -> f32 {
    return select(1.0 / g.ior, g.ior, wo_z > 0.0);
}

// Dielectric::interior_transmittance: e^(−σ·t) for a ray along `dir`
// arriving at glass of outward geometric normal `ng` from inside, having
// crossed t of it (Beer–Lambert, KHR_materials_volume's absorption σ);
// 1 from outside.
fn glass_interior_transmittance(absorption: vec3<f32>, dir: vec3<f32>, ng: vec3<f32>, t: f32) -> vec3<f32> {
    if (dot(dir, ng) <= 0.0 || all(absorption == vec3<f32>(0.0))) {
        return vec3<f32>(1.0);
    }
    return exp(-absorption * t);
}

// √tint per crossing: a solid piece shows the tint.
fn glass_transmission_factor(g: Dielectric, eta: f32, radiance: bool) -> vec3<f32> {
    let tint = sqrt(g.tint);
    return select(tint, tint / (eta * eta), radiance);
}

// Smith's Λ, as ggx::lambda (infinite in the tangent plane).
fn ggx_lambda(w: vec3<f32>, alpha: f32) -> f32 {
    let z2 = w.z * w.z;
    if (z2 == 0.0) {
        return 1.0e30;
    }
    return 0.5 * (sqrt(1.0 + alpha * alpha * (ggx_sin2(w) / z2)) - 1.0);
}

fn ggx_g2(wo: vec3<f32>, wi: vec3<f32>, alpha: f32) -> f32 {
    return 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

// ggx::visible_normal_pdf.
fn ggx_visible_normal_pdf(wo: vec3<f32>, h: vec3<f32>, alpha: f32) -> f32 {
    if (wo.z <= 0.0) {
        return 0.0;
    }
    return ggx_g1(wo, alpha) * max(dot(wo, h), 0.0) * ggx_d(h, alpha) / wo.z;
}

// Dielectric::half_vector: the pair seen from above, with its microfacet.
struct GlassHalf {
    valid: bool,
    wo: vec3<f32>,
    wi: vec3<f32>,
    h: vec3<f32>,
    eta: f32,
    cos_oh: f32,
    cos_ih: f32,
    reflectance: f32,
    transmitted: bool,
}

fn glass_half(g: Dielectric, wo_in: vec3<f32>, wi_in: vec3<f32>) -> GlassHalf {
    var p: GlassHalf;
    p.valid = false;
    if (glass_is_smooth(g) || wo_in.z == 0.0 || wi_in.z == 0.0) {
        return p;
    }
    p.eta = glass_eta_across(g, wo_in.z);
    let flip = select(-1.0, 1.0, wo_in.z > 0.0);
    p.wo = vec3<f32>(wo_in.x, wo_in.y, wo_in.z * flip);
    p.wi = vec3<f32>(wi_in.x, wi_in.y, wi_in.z * flip);
    p.transmitted = p.wi.z < 0.0;
    var h = select(p.wi + p.wo, p.eta * p.wi + p.wo, p.transmitted);
    // glam's normalize_or_zero.
    let len2 = dot(h, h);
    if (len2 == 0.0) {
        return p;
    }
    h = unit(h);
    if (h.z < 0.0) {
        h = -h;
    }
    p.h = h;
    p.cos_oh = dot(p.wo, h);
    p.cos_ih = dot(p.wi, h);
    if (h.z == 0.0 || p.cos_oh <= 0.0 || (p.cos_ih > 0.0) == p.transmitted || p.cos_ih == 0.0) {
        return p;
    }
    p.reflectance = fresnel_dielectric(p.cos_oh, 1.0 / p.eta).x;
    p.valid = true;
    return p;
}

fn glass_f(g: Dielectric, wo: vec3<f32>, wi: vec3<f32>, radiance: bool) -> vec3<f32> {
    let p = glass_half(g, wo, wi);
    if (!p.valid) {
        return vec3<f32>(0.0);
    }
    return glass_f_at(g, p, radiance);
}

fn glass_pdf(g: Dielectric, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let p = glass_half(g, wo, wi);
    if (!p.valid) {
        return 0.0;
    }
    return glass_pdf_at(g, p);
}

// Dielectric::f_at: f of a valid pair.
fn glass_f_at(g: Dielectric, p: GlassHalf, radiance: bool) -> vec3<f32> {
    let alpha = glass_alpha(g);
    let dg = ggx_d(p.h, alpha) * ggx_g2(p.wo, p.wi, alpha);
    let cosines = abs(p.wo.z * p.wi.z);
    if (!p.transmitted) {
        return vec3<f32>(p.reflectance * dg / (4.0 * cosines));
    }
    let denom = p.cos_ih + p.cos_oh / p.eta;
    let scalar = (1.0 - p.reflectance) * dg * abs(p.cos_ih * p.cos_oh) / (cosines * denom * denom);
    return glass_transmission_factor(g, p.eta, radiance) * scalar;
}

// Dielectric::pdf_at: the density of a valid pair.
fn glass_pdf_at(g: Dielectric, p: GlassHalf) -> f32 {
    let visible = ggx_visible_normal_pdf(p.wo, p.h, glass_alpha(g));
    if (!p.transmitted) {
        return p.reflectance * visible / (4.0 * p.cos_oh);
    }
    let denom = p.cos_ih + p.cos_oh / p.eta;
    return (1.0 - p.reflectance) * visible * abs(p.cos_ih) / (denom * denom);
}

// Dielectric::sample for rough glass (smooth glass is split by the callers).
fn glass_sample_rough(g: Dielectric, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>, radiance: bool) -> GlassSample {
    var s: GlassSample;
    s.valid = false;
    if (wo.z == 0.0) {
        return s;
    }
    let eta = glass_eta_across(g, wo.z);
    let flip = select(-1.0, 1.0, wo.z > 0.0);
    let wo_up = vec3<f32>(wo.x, wo.y, wo.z * flip);
    let h = ggx_sample_visible_normal(wo_up, glass_alpha(g), u);
    let cos_oh = dot(wo_up, h);
    if (cos_oh <= 0.0) {
        return s;
    }
    let fresnel = fresnel_dielectric(cos_oh, 1.0 / eta);
    var wi_up: vec3<f32>;
    let transmitted = !(u_lobe < fresnel.x);
    if (transmitted) {
        wi_up = -wo_up / eta + (cos_oh / eta - fresnel.y) * h;
    } else {
        wi_up = ggx_reflect(wo_up, h);
    }
    if ((wi_up.z > 0.0) == transmitted || wi_up.z == 0.0) {
        return s;
    }
    let wi = vec3<f32>(wi_up.x, wi_up.y, wi_up.z * flip);
    // Dielectric::f_and_pdf: one microfacet normal for both.
    let p = glass_half(g, wo, wi);
    if (!p.valid) {
        return s;
    }
    let pdf = glass_pdf_at(g, p);
    if (!(pdf > 0.0)) {
        return s;
    }
    s.wi = wi;
    s.weight = glass_f_at(g, p, radiance) * (abs(wi.z) / pdf);
    s.pdf = pdf;
    s.transmitted = transmitted;
    s.valid = true;
    return s;
}
