//! `path`: a unidirectional path tracer with next-event estimation and, for
//! area lights, multiple importance sampling (power heuristic). Ground truth
//! for the photon renderers. In media (homogeneous or regions) it samples
//! free flights (the photon tracer's, with the same RGB weights), does
//! next-event estimation at scattering points through the phase function,
//! and attenuates shadow rays by the transmittance.

use super::{Image, render_pixels};
use crate::geometry::Ray;
use crate::material::{Material, Rgb, dielectric_split, mean, reflect};
use crate::medium::{Flight, Phase};
use crate::progress::Progress;
use crate::sampling::{Rng, cosine_hemisphere, local_to_world, power_heuristic};
use crate::scene::Scene;
use glam::Vec3;
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct PathSettings {
    pub spp: u32,
    pub seed: u64,
    /// Bounces before a path is cut (material roulette ends most much sooner).
    pub max_depth: u32,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings { spp: 64, seed: 0, max_depth: 64 }
    }
}

/// How the previous vertex chose the current ray, for MIS on emitter hits.
#[derive(Clone, Copy)]
enum Previous {
    /// Camera or a specular bounce: emitters hit count fully.
    Specular,
    /// A diffuse bounce from `point`, sampled with solid-angle density `pdf`.
    Diffuse { point: Vec3, pdf: f32 },
}

pub fn radiance(scene: &Scene, mut ray: Ray, settings: &PathSettings, rng: &mut Rng) -> Rgb {
    let mut l = Rgb::ZERO;
    let mut beta = Rgb::ONE;
    let mut previous = Previous::Specular;
    for bounce in 0..settings.max_depth {
        let hit = scene.accel.intersect(&ray);
        let media = &scene.media;
        if !media.is_empty() {
            match media.sample_flight(ray.origin, ray.dir, hit.map_or(f32::INFINITY, |h| h.t), rng.next_f32()) {
                Flight::Passed { weight } => beta *= weight,
                Flight::Interaction { distance, weight, mask } => {
                    let (lambda, albedo) = media.scattering(mask);
                    if rng.next_f32() >= lambda {
                        break; // absorbed
                    }
                    beta *= weight * albedo;
                    let x = ray.at(distance);
                    // One medium scatters, chosen ∝ σ_s: its phase function
                    // serves both light sampling and the next direction.
                    let phase = media.choose_scatterer(mask, rng.next_f32()).medium.phase;
                    l += beta * medium_next_event(scene, &phase, x, ray.dir, rng);
                    // Light reaching x along −wi continues along ray.dir
                    // backwards: μ = wi · ray.dir, sampled from the phase function.
                    let wi = phase.sample(ray.dir, rng.next_2d());
                    previous = Previous::Diffuse { point: x, pdf: phase.eval(wi.dot(ray.dir)) };
                    ray = Ray::new(x, wi);
                    continue;
                }
            }
        }
        let Some(hit) = hit else { break };
        // Emitted light, MIS-weighted against the light sampling of the last vertex.
        if let Some(light) = scene.emitter(&hit) {
            let le = light.emitted_radiance(ray.dir, hit.geometric_normal);
            let weight = match previous {
                Previous::Specular => 1.0,
                Previous::Diffuse { point, pdf } => {
                    power_heuristic(pdf, light.incident_pdf(point, hit.point, hit.geometric_normal))
                }
            };
            l += beta * le * weight;
            break;
        }
        let material = scene.material(&hit);
        let facing = if ray.dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
        let (ng, ns) = (hit.geometric_normal * facing, hit.shading_normal * facing);
        let next_dir = match material {
            Material::Emitter => break,
            Material::Glass { ior } => {
                let split = dielectric_split(ray.dir, hit.geometric_normal, *ior);
                previous = Previous::Specular;
                match split.refracted {
                    Some(t) if rng.next_f32() >= split.reflectance => t,
                    _ => split.reflected,
                }
            }
            Material::Diffuse { .. } | Material::Mirror { .. } => {
                let (albedo, specular) = (material.diffuse_albedo(), material.mirror_reflectance());
                let (p_d, p_s) = (mean(albedo), mean(specular));
                if p_d + p_s <= 0.0 {
                    break; // black
                }
                // Diffuse or mirror, chosen ∝ their reflectances but never
                // absorbed here (the photon tracer's roulette at the albedo
                // ends 30–75% of paths at their first bounce); the
                // throughput's roulette below ends paths instead.
                let p_diffuse = p_d / (p_d + p_s);
                if p_d > 0.0 {
                    l += beta * next_event(scene, hit.point, ns, albedo, p_diffuse, rng);
                }
                if rng.next_f32() < p_diffuse {
                    beta *= albedo / p_diffuse;
                    let dir = local_to_world(cosine_hemisphere(rng.next_2d()), ns);
                    previous = Previous::Diffuse { point: hit.point, pdf: p_diffuse * dir.dot(ns).max(0.0) / PI };
                    dir
                } else {
                    beta *= specular / (1.0 - p_diffuse);
                    previous = Previous::Specular;
                    reflect(ray.dir, ns)
                }
            }
        };
        // Russian roulette on the throughput from the third vertex on
        // (pbrt's and Mitsuba's rule): a path survives with probability
        // max(β), at most 0.95, and carries 1/that if it does.
        if bounce >= 2 {
            let survive = beta.max_element().min(0.95);
            if rng.next_f32() >= survive {
                break;
            }
            beta /= survive;
        }
        let transmits = matches!(material, Material::Glass { .. }) && next_dir.dot(ng) < 0.0;
        if next_dir.dot(ng) <= 0.0 && !transmits {
            break;
        }
        ray = Ray::new(hit.point, next_dir);
    }
    l
}

/// Direct light at a diffuse vertex: one sample per light, MIS-weighted
/// against the diffuse sampling (chosen with probability `p_diffuse`).
fn next_event(scene: &Scene, x: Vec3, n: Vec3, albedo: Rgb, p_diffuse: f32, rng: &mut Rng) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        let Some(s) = light.sample_incident(x, rng.next_2d()) else {
            continue;
        };
        let cos = s.wi.dot(n);
        if cos <= 0.0 || s.pdf <= 0.0 {
            continue;
        }
        let mut shadow = Ray::new(x, s.wi);
        shadow.t_max = s.distance * (1.0 - 1e-4);
        if scene.accel.occluded(&shadow) {
            continue;
        }
        let weight = if s.is_delta { 1.0 } else { power_heuristic(s.pdf, p_diffuse * cos / PI) };
        let transmittance = scene.media.transmittance(x, s.wi, s.distance);
        sum += albedo / PI * s.radiance * transmittance * (cos * weight / s.pdf);
    }
    sum
}

/// Light scattered at medium point `x` toward the eye (travelling along −`dir`
/// to reach it): one sample per light through the phase function, MIS-weighted
/// against phase sampling for area lights.
fn medium_next_event(scene: &Scene, phase_function: &Phase, x: Vec3, dir: Vec3, rng: &mut Rng) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        let Some(s) = light.sample_incident(x, rng.next_2d()) else { continue };
        if s.pdf <= 0.0 {
            continue;
        }
        let mut shadow = Ray::new(x, s.wi);
        shadow.t_max = s.distance * (1.0 - 1e-4);
        if scene.accel.occluded(&shadow) {
            continue;
        }
        let phase = phase_function.eval(s.wi.dot(dir));
        let weight = if s.is_delta { 1.0 } else { power_heuristic(s.pdf, phase) };
        sum += s.radiance * scene.media.transmittance(x, s.wi, s.distance) * (phase * weight / s.pdf);
    }
    sum
}

/// Renders the image; returns it and the number of non-finite samples dropped.
pub fn render(scene: &Scene, settings: &PathSettings, progress: &dyn Progress) -> (Image, u64) {
    render_pixels(&scene.camera, settings.spp, settings.seed, progress, |ray, rng| radiance(scene, ray, settings, rng))
}
