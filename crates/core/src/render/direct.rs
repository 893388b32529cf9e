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
/// by `area_samples` samples. `normal` (shading) and `geometric` face the
/// viewer.
pub fn direct_diffuse(
    scene: &Scene,
    x: Vec3,
    normal: Vec3,
    geometric: Vec3,
    albedo: Rgb,
    area_samples: u32,
    rng: &mut Rng,
) -> Rgb {
    direct_reflected(scene, x, normal, geometric, |_| albedo / PI, area_samples, rng)
}

/// Which lights a surface point's light sampling reaches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LitSides {
    /// Those above the normal: the surface only reflects.
    Front,
    /// Those on both sides: a rough glass boundary also transmits (the
    /// cosine is |ω_i · n|; a light beyond is seen through the boundary).
    Both,
    /// All lights above the normal, and below it only point, spot and sun
    /// lights: for a renderer whose sampled transmitted directions count
    /// the area lights and skies they meet (photon-cpu), and so would miss
    /// only the lights no direction meets.
    FrontAndDeltaBehind,
}

impl LitSides {
    /// |cos θ| of `wi` about `normal` where a light (`delta` or not) on
    /// that side is sampled here, else ≤ 0.
    pub fn cos(self, wi: Vec3, normal: Vec3, delta: bool) -> f32 {
        let cos = wi.dot(normal);
        match self {
            LitSides::Front => cos,
            LitSides::Both => cos.abs(),
            LitSides::FrontAndDeltaBehind if delta => cos.abs(),
            LitSides::FrontAndDeltaBehind => cos,
        }
    }
}

/// Reflected radiance ∫ f_r(ω_i) L_i cos θ dω from all lights, sampled as
/// [`direct_diffuse`] does; `brdf` is f_r for the world direction ω_i
/// toward the light (the viewer's direction fixed by the caller), from
/// above the geometric normal `geometric` (facing the viewer) only.
pub fn direct_reflected(
    scene: &Scene,
    x: Vec3,
    normal: Vec3,
    geometric: Vec3,
    brdf: impl Fn(Vec3) -> Rgb,
    area_samples: u32,
    rng: &mut Rng,
) -> Rgb {
    // No light from below the geometric surface, whatever the shading
    // normal (a bent or smooth one): it would come through the surface
    // (the path tracer's `next_event` and vcm's `Scatter::evaluate` agree).
    let above = |wi: Vec3| if wi.dot(geometric) > 0.0 { brdf(wi) } else { Rgb::ZERO };
    direct_scattered(scene, x, normal, LitSides::Front, above, area_samples, rng)
}

/// [`direct_reflected`] from the lights on `sides` of `normal`: with
/// `LitSides::Both`, `bsdf` is f for reflected and transmitted ω_i alike.
pub fn direct_scattered(
    scene: &Scene,
    x: Vec3,
    normal: Vec3,
    sides: LitSides,
    bsdf: impl Fn(Vec3) -> Rgb,
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
            let cos = sides.cos(s.wi, normal, s.is_delta);
            if cos <= 0.0 || s.pdf <= 0.0 {
                continue;
            }
            let mut shadow = Ray::new(x, s.wi);
            shadow.t_max = s.distance * (1.0 - 1e-4);
            if !scene.accel.occluded(&shadow) {
                let transmittance = scene.media.transmittance(x, s.wi, s.distance);
                light_sum += bsdf(s.wi) * s.radiance * transmittance * (cos / s.pdf);
            }
        }
        sum += light_sum / samples as f32;
    }
    sum
}
