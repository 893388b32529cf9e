// The radiance estimate, mirrored from hikari_core::estimate; `twin` tests
// pin both sides together.

// w(d_p) of eq. 4.1 with the optional normal test (estimate::photon_accepted).
fn photon_accepted(d2: f32, photon_dir: vec3<f32>, normal: vec3<f32>, radius: f32, normal_test: bool) -> bool {
    return d2 <= radius * radius && !(normal_test && dot(photon_dir, normal) >= 0.0);
}

// f_r / (π r²) for a Lambertian surface (estimate::radiance_per_power).
fn radiance_per_power(albedo: vec3<f32>, radius: f32) -> vec3<f32> {
    return albedo * (1.0 / (PI * PI * radius * radius));
}

// estimate::MAX_SHADING_NORMAL_FACTOR.
const MAX_SHADING_NORMAL_FACTOR: f32 = 8.0;

// A photon arriving from `wi` at a surface shading with `ns` across `ng`
// (estimate::shading_normal_factor): max(ns·ωi, 0) / |ng·ωi|, capped.
fn shading_normal_factor(wi: vec3<f32>, ns: vec3<f32>, ng: vec3<f32>) -> f32 {
    let cos_g = abs(dot(wi, ng));
    if (cos_g <= 0.0) {
        return 0.0;
    }
    return min(max(dot(wi, ns), 0.0) / cos_g, MAX_SHADING_NORMAL_FACTOR);
}

// 1 / (π r²): the estimate's factor for photons already weighted by the
// BRDF at their own directions (estimate::fixed_radius_radiance_brdf).
fn radiance_per_weighted_power(radius: f32) -> f32 {
    return 1.0 / (PI * radius * radius);
}
