//! Direct light at a surface point with shadow rays (the L D paths, and
//! L G paths through glossy lobes).

use crate::geometry::Ray;
use crate::material::Rgb;
use crate::sampling::Rng;
use crate::scene::Scene;
use glam::Vec3;
use std::f32::consts::PI;

/// Reflected radiance albedo/π · ∫ L_i cos θ dω from all lights, each delta
/// light (point, spot, sun) by one shadow ray, each area light and the sky
/// by `area_samples` samples. `normal` faces the viewer.
pub fn direct_diffuse(scene: &Scene, x: Vec3, normal: Vec3, albedo: Rgb, area_samples: u32, rng: &mut Rng) -> Rgb {
    direct_reflected(scene, x, normal, |_| albedo / PI, area_samples, rng)
}

/// Reflected radiance ∫ f_r(ω_i) L_i cos θ dω from all lights, sampled as
/// [`direct_diffuse`] does; `brdf` is f_r for the world direction ω_i
/// toward the light (the viewer's direction fixed by the caller).
pub fn direct_reflected(
    scene: &Scene,
    x: Vec3,
    normal: Vec3,
    brdf: impl Fn(Vec3) -> Rgb,
    area_samples: u32,
    rng: &mut Rng,
) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        let samples = if light.is_delta() { 1 } else { area_samples.max(1) };
        let mut light_sum = Rgb::ZERO;
        for _ in 0..samples {
            let Some(s) = light.sample_incident(x, rng.next_2d()) else {
                continue;
            };
            let cos = s.wi.dot(normal);
            if cos <= 0.0 || s.pdf <= 0.0 {
                continue;
            }
            let mut shadow = Ray::new(x, s.wi);
            shadow.t_max = s.distance * (1.0 - 1e-4);
            if !scene.accel.occluded(&shadow) {
                let transmittance = scene.media.transmittance(x, s.wi, s.distance);
                light_sum += brdf(s.wi) * s.radiance * transmittance * (cos / s.pdf);
            }
        }
        sum += light_sum / samples as f32;
    }
    sum
}
