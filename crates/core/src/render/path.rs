//! `path`: a unidirectional path tracer with next-event estimation and, for
//! area lights, multiple importance sampling (power heuristic). Ground truth
//! for the photon renderers. In media (homogeneous or regions) it samples
//! free flights (the photon tracer's, with the same RGB weights) and
//! attenuates shadow rays by the transmittance. Light from area lights
//! scattered in the media is sampled at the free-flight points through the
//! phase function; light from point and spot lights is sampled along every
//! ray segment by equiangular sampling (`sampling::Equiangular`), whose
//! density follows the light's 1/d² falloff: at free-flight points, in thin
//! fog, most samples land far from the light and the rare ones close to it
//! are fireflies.

use super::{Image, render_pixels};
use crate::geometry::Ray;
use crate::material::{Material, Rgb, dielectric_split, mean, reflect};
use crate::medium::{Flight, Phase};
use crate::progress::Progress;
use crate::sampling::{Equiangular, Rng, cosine_hemisphere, local_to_world, power_heuristic};
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
            let t_max = hit.map_or(f32::INFINITY, |h| h.t);
            l += beta * in_scattered_from_delta_lights(scene, &ray, t_max, rng);
            match media.sample_flight(ray.origin, ray.dir, t_max, rng.next_f32()) {
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

/// Light from area lights scattered at medium point `x` toward the eye
/// (travelling along −`dir` to reach it): one sample per light through the
/// phase function, MIS-weighted against phase sampling. Point and spot
/// lights are [`in_scattered_from_delta_lights`]'s.
fn medium_next_event(scene: &Scene, phase_function: &Phase, x: Vec3, dir: Vec3, rng: &mut Rng) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in scene.lights.iter().filter(|l| l.delta_position().is_none()) {
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

/// Light from point and spot lights scattered toward the eye anywhere along
/// `ray` up to `t_max` (single scattering of the segment,
/// ∫ [`delta_light_scattered_at`] dt): one equiangular sample per light.
/// Counted once per segment of the path, whether or not its free flight
/// scatters, so it replaces next-event estimation of these lights at
/// free-flight points.
fn in_scattered_from_delta_lights(scene: &Scene, ray: &Ray, t_max: f32, rng: &mut Rng) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        let Some(position) = light.delta_position() else { continue };
        let xi = rng.next_f32();
        // Only where a spot's cone reaches: outside it every sample is zero.
        let Some((t0, t1)) = light.lit_interval(ray.origin, ray.dir, 0.0, t_max) else { continue };
        let Some(sampler) = Equiangular::new(ray.origin, ray.dir, position, t0, t1) else { continue };
        let (t, pdf) = sampler.sample(xi);
        if pdf > 0.0 && pdf.is_finite() && t.is_finite() {
            sum += delta_light_scattered_at(scene, light, ray, t) / pdf;
        }
    }
    sum
}

/// T(0, t) Σᵢ σ_s,i(x) pᵢ(μ) L(x) at x = `ray.at(t)`: the point or spot
/// `light`'s radiance arriving at x (shadowed and attenuated), scattered by
/// the media there toward the ray's origin and attenuated on the way; μ as
/// in [`medium_next_event`].
fn delta_light_scattered_at(scene: &Scene, light: &crate::light::Light, ray: &Ray, t: f32) -> Rgb {
    let media = &scene.media;
    let x = ray.at(t);
    let mask = media.mask_at(x);
    if mask == 0 {
        return Rgb::ZERO;
    }
    let Some(s) = light.sample_incident(x, glam::Vec2::ZERO) else { return Rgb::ZERO };
    let mut shadow = Ray::new(x, s.wi);
    shadow.t_max = s.distance * (1.0 - 1e-4);
    if scene.accel.occluded(&shadow) {
        return Rgb::ZERO;
    }
    let mu = s.wi.dot(ray.dir);
    let mut scattering = Rgb::ZERO;
    let mut bits = mask;
    while bits != 0 {
        let entry = &media.entries()[bits.trailing_zeros() as usize];
        bits &= bits - 1;
        scattering += entry.medium.sigma_s * entry.medium.phase.eval(mu);
    }
    let transmittance = media.transmittance(ray.origin, ray.dir, t) * media.transmittance(x, s.wi, s.distance);
    scattering * s.radiance * transmittance / s.pdf
}

/// Renders the image; returns it and the number of non-finite samples dropped.
pub fn render(scene: &Scene, settings: &PathSettings, progress: &dyn Progress) -> (Image, u64) {
    render_pixels(&scene.camera, settings.spp, settings.seed, progress, |ray, rng| radiance(scene, ray, settings, rng))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The equiangular estimate of a segment's in-scattered light (clipped
    /// to the spot's cone) averages to the integral by the midpoint rule,
    /// on rays of the layered fog stage (a spot, thin fog and a denser
    /// region mesh, shadowing by the box) that cross the cone.
    #[test]
    fn equiangular_estimate_averages_to_the_integral() {
        let mut scene = Scene::load("fog-stage-layered").unwrap();
        scene.camera = scene.camera.with_resolution(16, 16).unwrap();
        let light = scene.lights[0].clone();
        let mut checked = 0;
        for pixel in [[8.5f32, 4.5], [8.5, 9.5], [6.5, 12.5], [11.5, 7.5], [2.5, 2.5]] {
            let ray = scene.camera.ray(glam::Vec2::from(pixel));
            let t_max = scene.accel.intersect(&ray).map_or(40.0, |h| h.t);
            let steps = 200_000;
            let h = t_max / steps as f32;
            let integral: glam::DVec3 = (0..steps)
                .map(|i| delta_light_scattered_at(&scene, &light, &ray, (i as f32 + 0.5) * h).as_dvec3() * h as f64)
                .sum();
            let mut rng = Rng::for_item(5, pixel[0] as u64 * 100 + pixel[1] as u64);
            let n = 100_000;
            let estimate: glam::DVec3 = (0..n)
                .map(|_| in_scattered_from_delta_lights(&scene, &ray, t_max, &mut rng).as_dvec3())
                .sum::<glam::DVec3>()
                / n as f64;
            eprintln!("pixel {pixel:?}: estimate {:.6}, integral {:.6}", estimate.x, integral.x);
            if integral.x == 0.0 {
                assert_eq!(estimate.x, 0.0, "light outside the cone");
                continue;
            }
            checked += 1;
            assert!((estimate.x / integral.x - 1.0).abs() < 0.01, "pixel {pixel:?}: {estimate} vs {integral}");
        }
        assert!(checked >= 3, "only {checked} rays cross the lit cone");
    }
}
