// Smooth dielectric boundaries, mirrored from hikari_core::material.

// v / |v| as glam's `normalize` computes it (v · (1 / √(v·v))), which can
// round differently from WGSL's normalize.
fn unit(v: vec3<f32>) -> vec3<f32> {
    return v * (1.0 / sqrt(dot(v, v)));
}

// fresnel_dielectric: (reflectance, cos_t) for cos_i ≥ 0 on the incident
// side and eta = n_incident / n_transmitted; reflectance 1 is total
// internal reflection.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> vec2<f32> {
    let sin2_t = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
    if (sin2_t >= 1.0) {
        return vec2<f32>(1.0, 0.0);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_par = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return vec2<f32>(0.5 * (r_par * r_par + r_perp * r_perp), cos_t);
}

// The refracted direction of `dir` through a boundary with normal `n` on
// the incident side (dielectric_split), given fresnel_dielectric's cos_t.
fn refract_direction(dir: vec3<f32>, n: vec3<f32>, eta: f32, cos_i: f32, cos_t: f32) -> vec3<f32> {
    return unit(eta * dir + (eta * cos_i - cos_t) * n);
}
