//! `path`: a unidirectional path tracer with next-event estimation and, for
//! area lights and the sky, multiple importance sampling (power heuristic).
//! Ground truth for the photon renderers. Emissive surfaces add their light
//! where a path meets them and, unless they are the black bodies of sphere
//! and quad lights (`Material::Emitter`), scatter it on by their material;
//! a path that leaves the scene sees the sky. In media (homogeneous or
//! regions) it samples free flights (the photon tracer's, with the same RGB
//! weights) and attenuates shadow rays by the transmittance. Light from area
//! lights, the sky and the sun scattered in the media is sampled at the
//! free-flight points through the phase function; light from point and spot
//! lights is sampled along every ray segment by equiangular sampling
//! (`sampling::Equiangular`), whose density follows the light's 1/d²
//! falloff: at free-flight points, in thin fog, most samples land far from
//! the light and the rare ones close to it are fireflies.

mod lanes;

use super::{Image, LitSides, finite_mean, render_row_batches};
use crate::bsdf::ShadingFrame;
use crate::bsdf::bump::BumpShadow;
use crate::bsdf::dielectric::Transport;
use crate::geometry::Ray;
use crate::geometry::packet::LANES;
use crate::material::{Material, Rgb, mean, reflect};
use crate::medium::{Flight, Phase};
use crate::progress::Progress;
use crate::sampling::{Equiangular, Sampler, SobolSampler, cosine_hemisphere, local_to_world, power_heuristic};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct PathSettings {
    pub spp: u32,
    pub seed: u64,
    /// Bounces before a path is cut (material roulette ends most much sooner).
    pub max_depth: u32,
    /// Which pass of a progressive render this is (from 1; 1 for a single
    /// render). Pass p draws samples ⌊(p−1)/2⌋·spp … of one of two Sobol
    /// streams per pixel, the odd passes' or the even ones': each half is
    /// one well-stratified sequence, and the two halves are independent,
    /// which is what the noise estimate of two half-images assumes.
    pub pass: u32,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings { spp: 64, seed: 0, max_depth: 64, pass: 1 }
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

/// A path between two vertices: the light it has gathered, its
/// throughput, how its last vertex chose the ray it now follows, and which
/// vertex comes next.
struct PathState {
    ray: Ray,
    l: Rgb,
    beta: Rgb,
    previous: Previous,
    bounce: u32,
    /// Product of η'² over the boundaries crossed (1 outside glass).
    eta_scale: f32,
}

impl PathState {
    fn new(ray: Ray) -> Self {
        PathState { ray, l: Rgb::ZERO, beta: Rgb::ONE, previous: Previous::Specular, bounce: 0, eta_scale: 1.0 }
    }

    /// Moves on to the next vertex: false where the path is cut.
    fn next_vertex(&mut self, settings: &PathSettings) -> bool {
        self.bounce += 1;
        self.bounce < settings.max_depth
    }
}

/// The radiance arriving along `ray`: one path.
pub fn radiance(scene: &Scene, ray: Ray, settings: &PathSettings, sampler: &mut impl Sampler) -> Rgb {
    let mut path = PathState::new(ray);
    if settings.max_depth > 0 {
        loop {
            let hit = scene.accel.intersect(&path.ray);
            if !advance(scene, settings, &mut path, hit.as_ref(), sampler) {
                break;
            }
        }
    }
    path.l
}

/// Continues `path` at `hit`, the closest hit of its ray (None where it
/// leaves the scene): adds the light found on the way and there, and sets
/// the next ray. False where the path ends. Paths traced one at a time
/// ([`radiance`]) and eight at a time ([`trace_in_packets`]) are this
/// same step, so they give the same numbers.
fn advance(
    scene: &Scene,
    settings: &PathSettings,
    path: &mut PathState,
    hit: Option<&crate::geometry::Hit>,
    sampler: &mut impl Sampler,
) -> bool {
    let media = &scene.media;
    if !media.is_empty() {
        // A ray leaving the scene ends where a shadow ray toward the sky
        // would, so sky sampling and phase sampling see the same fog.
        let t_max = hit.map_or_else(|| scene.escape_distance(path.ray.origin, path.ray.dir), |h| h.t);
        path.l += path.beta * in_scattered_from_delta_lights(scene, &path.ray, t_max, sampler);
        match media.sample_flight(path.ray.origin, path.ray.dir, t_max, sampler.next_f32()) {
            Flight::Passed { weight, .. } => path.beta *= weight,
            Flight::Interaction { distance, weight, mask, .. } => {
                let (lambda, albedo) = media.scattering(mask);
                if sampler.next_f32() >= lambda {
                    return false; // absorbed
                }
                path.beta *= weight * albedo;
                let x = path.ray.at(distance);
                // One medium scatters, chosen ∝ σ_s: its phase function
                // serves both light sampling and the next direction.
                let phase = media.choose_scatterer(mask, sampler.next_f32()).medium.phase;
                path.l += path.beta * medium_next_event(scene, &phase, x, path.ray.dir, sampler);
                // Light reaching x along −wi continues along ray.dir
                // backwards: μ = wi · ray.dir, sampled from the phase function.
                let wi = phase.sample(path.ray.dir, sampler.next_2d());
                path.previous = Previous::Diffuse { point: x, pdf: phase.eval(wi.dot(path.ray.dir)) };
                path.ray = Ray::new(x, wi);
                return path.next_vertex(settings);
            }
        }
    }
    let Some(hit) = hit else {
        path.l += path.beta * sky(scene, &path.ray, path.previous);
        return false;
    };
    let material = &*scene.material_at(hit);
    // Emitted light, MIS-weighted against the light sampling of the last
    // vertex. An emissive mesh's surface then reflects like any other.
    if let Some(light) = scene.emitter(hit) {
        let le = scene.emitted_radiance(hit, path.ray.dir).unwrap_or_default();
        let weight = match path.previous {
            Previous::Specular => 1.0,
            Previous::Diffuse { point, pdf } => {
                power_heuristic(pdf, light.incident_pdf(point, hit.point, hit.geometric_normal))
            }
        };
        path.l += path.beta * le * weight;
        if matches!(material, Material::Emitter) {
            return false;
        }
    }
    let facing = if path.ray.dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
    // Normal textures bend the shading normal here (only the path tracer reads them).
    let (ng, ns) = (hit.geometric_normal * facing, scene.shading_normal_at(hit, path.ray.dir) * facing);
    let next_dir = match material {
        Material::Emitter => return false,
        Material::Glass(glass) => {
            // Arriving from inside: what the glass absorbed on the way.
            path.beta *= glass.interior_transmittance(path.ray.dir, hit.geometric_normal, hit.t);
            if !glass.is_smooth() {
                // The boundary's own frame: +z its outward (geometric) normal.
                let frame = ShadingFrame::new(hit.geometric_normal);
                let wo = frame.to_local(-path.ray.dir);
                // Lights on both sides, through the rough reflection and
                // transmission (a point light behind frosted glass glows
                // through it; shadow rays stop at glass, so a light beyond
                // the glass's far side is the transmitted samples' alone,
                // as MIS expects).
                let f = |wi: Vec3| glass.f(wo, frame.to_local(wi), Transport::Radiance);
                let pdf = |wi: Vec3| glass.pdf(wo, frame.to_local(wi));
                path.l += path.beta * next_event(scene, hit.point, ng, ng, LitSides::Both, f, pdf, sampler);
            }
            let u_lobe = sampler.next_f32();
            let u = if glass.is_smooth() { Vec2::ZERO } else { sampler.next_2d() };
            let Some(s) = glass.sample_world(path.ray.dir, hit.geometric_normal, u_lobe, u, Transport::Radiance) else {
                return false;
            };
            path.beta *= s.weight;
            // Radiance crossing scales by 1/η'²; roulette looks past it.
            path.eta_scale *= s.eta * s.eta;
            path.previous =
                if s.is_delta { Previous::Specular } else { Previous::Diffuse { point: hit.point, pdf: s.pdf } };
            s.wi
        }
        Material::Pbr(bsdf) => {
            let frame = ShadingFrame::new(ns);
            let tilted = scene.coat_tilted(bsdf, hit, hit.shading_normal, path.ray.dir, &frame);
            let bsdf = tilted.as_ref().unwrap_or(bsdf);
            let wo = frame.to_local(-path.ray.dir);
            // A normal-mapped point's diffuse lobes: Cycles' bump shadowing
            // of the light's direction (none where nothing bends).
            let bump = BumpShadow::new(hit.shading_normal * facing, ns);
            let k = |wi: Vec3| bump.map_or(1.0, |b| b.term(wi));
            // Light sampling finds nothing through a mirror alone.
            if bsdf.has_non_delta_lobe() {
                let brdf = |wi: Vec3| bsdf.f_bumped(wo, frame.to_local(wi), k(wi));
                let pdf = |wi: Vec3| bsdf.pdf(wo, frame.to_local(wi));
                path.l += path.beta * next_event(scene, hit.point, ns, ng, LitSides::Front, brdf, pdf, sampler);
            }
            let Some(s) = bsdf.sample(wo, sampler.next_f32(), sampler.next_2d()) else { return false };
            let s = bsdf.reweigh(wo, s, k(frame.to_world(s.wi)));
            path.beta *= s.weight;
            path.previous =
                if s.is_delta { Previous::Specular } else { Previous::Diffuse { point: hit.point, pdf: s.pdf } };
            frame.to_world(s.wi)
        }
        Material::Diffuse { .. } | Material::Mirror { .. } => {
            let (albedo, specular) = (material.diffuse_albedo(), material.mirror_reflectance());
            let (p_d, p_s) = (mean(albedo), mean(specular));
            if p_d + p_s <= 0.0 {
                return false; // black
            }
            // Diffuse or mirror, chosen ∝ their reflectances but never
            // absorbed here (the photon tracer's roulette at the albedo
            // ends 30–75% of paths at their first bounce); the
            // throughput's roulette below ends paths instead.
            let p_diffuse = p_d / (p_d + p_s);
            // A normal-mapped exactly Lambertian glTF material: the bump
            // shadowing of the light's direction, as the Pbr arm's.
            let bump = BumpShadow::new(hit.shading_normal * facing, ns);
            let k = |wi: Vec3| bump.map_or(1.0, |b| b.term(wi));
            if p_d > 0.0 {
                let pdf = |wi: Vec3| p_diffuse * wi.dot(ns).max(0.0) / PI;
                let f = |wi: Vec3| albedo / PI * k(wi);
                path.l += path.beta * next_event(scene, hit.point, ns, ng, LitSides::Front, f, pdf, sampler);
            }
            if p_s == 0.0 || sampler.next_f32() < p_diffuse {
                let dir = local_to_world(cosine_hemisphere(sampler.next_2d()), ns);
                path.beta *= albedo / p_diffuse * k(dir);
                path.previous = Previous::Diffuse { point: hit.point, pdf: p_diffuse * dir.dot(ns).max(0.0) / PI };
                dir
            } else {
                path.beta *= specular / (1.0 - p_diffuse);
                path.previous = Previous::Specular;
                reflect(path.ray.dir, ns)
            }
        }
    };
    // Russian roulette on the throughput from the fifth vertex on
    // (Mitsuba's `rr_depth = 5`): a path survives with probability
    // max(β), at most 0.95, and carries 1/that if it does. Starting at
    // the third (pbrt's rule) made paths 1.25× cheaper but 1.32× as
    // noisy in variance on the Cornell box: 7% less efficient.
    if path.bounce >= 4 {
        // Inside glass β is 1/η² of what it carries out again (pbrt's
        // `etaScale`): judged without that, paths inside are not cut more.
        let survive = (path.beta.max_element() * path.eta_scale).min(0.95);
        if sampler.next_f32() >= survive {
            return false;
        }
        path.beta /= survive;
    }
    let transmits = matches!(material, Material::Glass { .. }) && next_dir.dot(ng) < 0.0;
    if next_dir.dot(ng) <= 0.0 && !transmits {
        return false;
    }
    path.ray = Ray::new(hit.point, next_dir);
    path.next_vertex(settings)
}

/// Runs paths `0..out.len()` eight at a time, their closest hits found in
/// packets (`Accel::intersect_packet`; the lane step casts its shadow rays
/// in packets too, the scalar step one at a time). `start(k)` makes path
/// k's camera ray and sampler;
/// `out[k]` receives its radiance. A lane whose path ends takes the next.
fn trace_in_packets<S: Sampler>(
    scene: &Scene,
    settings: &PathSettings,
    out: &mut [Rgb],
    start: impl Fn(usize) -> (Ray, S),
) {
    if settings.max_depth == 0 {
        out.fill(Rgb::ZERO);
        return;
    }
    let lane_step = lanes::LaneStep::for_scene(scene);
    let mut lanes: [Option<(usize, PathState, S)>; LANES] = std::array::from_fn(|_| None);
    let mut hits = [None; LANES];
    // Kept from one round to the next: zeroing its 1.3 kB each round was
    // 0.6% of the Cornell box's samples (a lane not taken is never read).
    let mut diffuse = lanes::DiffuseLanes::default();
    let mut next = 0;
    loop {
        for lane in &mut lanes {
            if lane.is_none() && next < out.len() {
                let (camera_ray, sampler) = start(next);
                *lane = Some((next, PathState::new(camera_ray), sampler));
                next += 1;
            }
        }
        if lanes.iter().all(Option::is_none) {
            return;
        }
        // The rays where the step wrote them, borrowed, not copied (a copy
        // read back at once stalled on its stores: 10% of the step, perf).
        let rays: [Option<&Ray>; LANES] = std::array::from_fn(|l| lanes[l].as_ref().map(|(_, path, _)| &path.ray));
        scene.accel.intersect_packet(&rays, &mut hits);
        // Vertices the lane step serves go through it together; the rest
        // one at a time.
        diffuse.clear();
        for (l, (lane, hit)) in lanes.iter_mut().zip(&hits).enumerate() {
            let Some((k, path, sampler)) = lane else { continue };
            if let (Some(step), Some(hit)) = (&lane_step, hit)
                && let Some(albedo) = step.albedo_at(hit)
            {
                diffuse.take(l, path, hit, albedo, sampler);
            } else if !advance(scene, settings, path, hit.as_ref(), sampler) {
                out[*k] = path.l;
                *lane = None;
            }
        }
        if let Some(step) = &lane_step
            && diffuse.any()
        {
            diffuse.step(scene, step, settings.max_depth);
            for (l, lane) in lanes.iter_mut().enumerate() {
                let Some((k, path, _)) = lane else { continue };
                if diffuse.taken(l) && !diffuse.finish(l, path) {
                    out[*k] = path.l;
                    *lane = None;
                }
            }
        }
    }
}

/// The sky seen by a ray that leaves the scene, each environment
/// MIS-weighted against its light sampling at the last vertex (which finds
/// nothing where the sky's photons do not go: `Disc::covers`).
fn sky(scene: &Scene, ray: &Ray, previous: Previous) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        let le = light.escaped_radiance(ray.dir);
        if le == Rgb::ZERO {
            continue;
        }
        let weight = match previous {
            Previous::Specular => 1.0,
            Previous::Diffuse { point, .. } if light.distant_disc().is_some_and(|d| !d.covers(point, ray.dir)) => {
                continue;
            }
            Previous::Diffuse { point, pdf } => {
                power_heuristic(pdf, light.incident_pdf(point, point + ray.dir, ray.dir))
            }
        };
        sum += le * weight;
    }
    sum
}

/// Direct light at a vertex from the lights on `sides` of `n`: one sample
/// per light, MIS-weighted against the vertex's own sampling. `brdf` and
/// `pdf` are f and the density with which the vertex samples the world
/// direction ω_i toward the light. A surface that only reflects takes no
/// light from below its geometric normal `ng` (on the side the path came
/// from), whatever its shading normal: it would come through the surface,
/// and the vertex's own sampling ends paths there too (as Cycles and pbrt
/// do).
fn next_event(
    scene: &Scene,
    x: Vec3,
    n: Vec3,
    ng: Vec3,
    sides: LitSides,
    brdf: impl Fn(Vec3) -> Rgb,
    pdf: impl Fn(Vec3) -> f32,
    sampler: &mut impl Sampler,
) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        // Point and spot lights need no numbers (and QMC sets are not free).
        let u = if light.delta_position().is_some() { glam::Vec2::ZERO } else { sampler.next_2d() };
        let Some(s) = light.sample_incident(x, u) else {
            continue;
        };
        let cos = sides.cos(s.wi, n, s.is_delta);
        if cos <= 0.0 || s.pdf <= 0.0 || (sides == LitSides::Front && s.wi.dot(ng) <= 0.0) {
            continue;
        }
        let mut shadow = Ray::new(x, s.wi);
        shadow.t_max = s.distance * (1.0 - 1e-4);
        if scene.accel.occluded(&shadow) {
            continue;
        }
        let weight = if s.is_delta { 1.0 } else { power_heuristic(s.pdf, pdf(s.wi)) };
        let transmittance = scene.media.transmittance(x, s.wi, s.distance);
        sum += brdf(s.wi) * s.radiance * transmittance * (cos * weight / s.pdf);
    }
    sum
}

/// Light from every light without a position (area lights, the sky, the
/// sun) scattered at medium point `x` toward the eye (travelling along
/// −`dir` to reach it): one sample per light through the phase function,
/// MIS-weighted against phase sampling except for the sun, which phase
/// sampling never finds. Point and spot lights are
/// [`in_scattered_from_delta_lights`]'s.
fn medium_next_event(scene: &Scene, phase_function: &Phase, x: Vec3, dir: Vec3, sampler: &mut impl Sampler) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in scene.lights.iter().filter(|l| l.delta_position().is_none()) {
        let Some(s) = light.sample_incident(x, sampler.next_2d()) else { continue };
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
fn in_scattered_from_delta_lights(scene: &Scene, ray: &Ray, t_max: f32, sampler: &mut impl Sampler) -> Rgb {
    let mut sum = Rgb::ZERO;
    for light in &scene.lights {
        let Some(position) = light.delta_position() else { continue };
        let xi = sampler.next_f32();
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

/// Renders the image (a box filter: each pixel the mean of `spp` paths
/// through points of its square, the first two numbers of each sample);
/// returns it and the number of non-finite samples dropped.
pub fn render(scene: &Scene, settings: &PathSettings, progress: &dyn Progress) -> (Image, u64) {
    let camera = &scene.camera;
    let spp = settings.spp.max(1);
    let passes_before = u64::from(settings.pass.max(1) - 1);
    let (half, first) = (passes_before % 2, passes_before / 2 * u64::from(spp));
    let streams = crate::sampling::Rng::seed_constants(settings.seed ^ 0x005e_ed0f_9a7e).0;
    // A row's paths (pixel by pixel, each pixel's samples in order) run
    // eight at a time; each pixel is then the mean of its samples in order,
    // the same numbers as one path after another.
    render_row_batches(camera, progress, |y, row| {
        let n = spp as usize;
        let mut samples = vec![Rgb::ZERO; row.len() * n];
        trace_in_packets(scene, settings, &mut samples, |k| {
            let x = (k / n) as u32;
            let stream = streams.wrapping_add((u64::from(y) * u64::from(camera.width) + u64::from(x)) * 2 + half);
            let mut sampler = SobolSampler::new(stream, first + (k % n) as u64);
            let offset = sampler.next_2d();
            (camera.ray(glam::Vec2::new(x as f32, y as f32) + offset), sampler)
        });
        let mut dropped = 0;
        for (x, pixel) in row.iter_mut().enumerate() {
            let (value, bad) = finite_mean(spp, |s| samples[x * n + s as usize]);
            *pixel = value;
            dropped += bad;
        }
        dropped
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sampling::Rng;

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

    /// Paths traced eight at a time with packets of closest-hit rays give
    /// each pixel the numbers that paths traced one at a time give it.
    #[test]
    fn paths_in_packets_match_paths_one_at_a_time() {
        for name in ["cornell-box", "cornell-caustic", "fog-stage"] {
            let mut scene = Scene::load(name).unwrap();
            scene.camera = scene.camera.with_resolution(16, 12).unwrap();
            let settings = PathSettings { spp: 3, seed: 5, pass: 4, ..Default::default() };
            let (image, _) = render(&scene, &settings, &crate::progress::Silent);
            // What `render` did before packets: pass 4 is the odd-numbered
            // stream's second set of 3 samples.
            let streams = crate::sampling::Rng::seed_constants(settings.seed ^ 0x005e_ed0f_9a7e).0;
            let mut differ = 0;
            for (i, pixel) in image.pixels.iter().enumerate() {
                let (x, y) = ((i % 16) as u32, (i / 16) as u32);
                let stream = streams.wrapping_add(u64::from(y * 16 + x) * 2 + 1);
                let (alone, _) = finite_mean(3, |s| {
                    let mut sampler = SobolSampler::new(stream, 3 + u64::from(s));
                    let offset = sampler.next_2d();
                    radiance(
                        &scene,
                        scene.camera.ray(glam::Vec2::new(x as f32, y as f32) + offset),
                        &settings,
                        &mut sampler,
                    )
                });
                if alone != *pixel {
                    differ += 1;
                    eprintln!("{name} ({x}, {y}): {alone} alone, {pixel} in packets");
                }
            }
            assert_eq!(differ, 0, "{name}");
        }
    }

    /// The lane step (`lanes`) serves Cornell boxes lit by point lights,
    /// and its images are the scalar step's to the bit: two point lights
    /// (one low, lighting some walls from behind) and a narrow spot whose
    /// cone's edge and falloff cross the back wall, paths cut after 3
    /// vertices and after 64 (the roulette's), against paths traced one
    /// at a time. Scenes with media (`fog-stage`) or other lights
    /// (`cornell-caustic`'s sphere light) are not served.
    #[test]
    fn the_lane_step_gives_the_scalar_steps_image() {
        let mut scene = Scene::load("cornell-box").unwrap();
        scene.camera = scene.camera.with_resolution(24, 20).unwrap();
        scene.lights.push(crate::light::Light::Point {
            position: Vec3::new(-0.7, -0.95, 0.4),
            intensity: Rgb::new(0.5, 1.5, 0.25),
        });
        scene.lights.push(crate::light::Light::Spot {
            position: Vec3::new(0.6, 0.9, 0.5),
            axis: Vec3::new(-0.5, -0.3, -1.0).normalize(),
            intensity: Rgb::new(3.0, 2.0, 1.0),
            cutoff: 0.35,
            falloff_start: 0.2,
        });
        assert!(lanes::LaneStep::for_scene(&scene).is_some());
        for name in ["fog-stage", "cornell-caustic"] {
            let other = Scene::load(name).unwrap();
            assert!(lanes::LaneStep::for_scene(&other).is_none(), "{name}");
        }
        for max_depth in [3, 64] {
            let settings = PathSettings { spp: 4, seed: 9, max_depth, ..Default::default() };
            let (image, _) = render(&scene, &settings, &crate::progress::Silent);
            let streams = crate::sampling::Rng::seed_constants(settings.seed ^ 0x005e_ed0f_9a7e).0;
            let mut lit = 0;
            for (i, pixel) in image.pixels.iter().enumerate() {
                let (x, y) = ((i % 24) as u32, (i / 24) as u32);
                let stream = streams.wrapping_add(u64::from(y * 24 + x) * 2);
                let (alone, _) = finite_mean(4, |s| {
                    let mut sampler = SobolSampler::new(stream, u64::from(s));
                    let offset = sampler.next_2d();
                    let ray = scene.camera.ray(glam::Vec2::new(x as f32, y as f32) + offset);
                    radiance(&scene, ray, &settings, &mut sampler)
                });
                assert_eq!(alone, *pixel, "max_depth {max_depth}, pixel ({x}, {y})");
                lit += usize::from(pixel.max_element() > 0.0);
            }
            assert!(lit > image.pixels.len() * 3 / 4, "{lit}");
        }
    }

    fn settings(spp: u32, seed: u64) -> PathSettings {
        PathSettings { spp, seed, ..Default::default() }
    }

    /// The odd passes draw one Sobol sequence per pixel: passes 1 and 3
    /// of 4 spp are the single render of 8 spp (to rounding), and pass 2,
    /// from the other, independent sequence, is another image.
    #[test]
    fn odd_passes_continue_one_sequence() {
        let mut scene = Scene::load("cornell-box").unwrap();
        scene.camera = scene.camera.with_resolution(12, 12).unwrap();
        let pass = |spp, pass| {
            render(&scene, &PathSettings { spp, seed: 3, pass, ..Default::default() }, &crate::progress::Silent).0
        };
        let (one, two, three, whole) = (pass(4, 1), pass(4, 2), pass(4, 3), pass(8, 1));
        let mut differs = 0;
        for i in 0..whole.pixels.len() {
            let mean = (one.pixels[i] + three.pixels[i]) / 2.0;
            assert!((mean - whole.pixels[i]).abs().max_element() <= 1e-5 * whole.pixels[i].max_element().max(1.0));
            differs += usize::from(two.pixels[i] != one.pixels[i] && two.pixels[i] != three.pixels[i]);
        }
        assert!(differs > whole.pixels.len() * 9 / 10, "{differs}");
    }

    /// A sun E tilted θ = 30° from a floor's normal: every pixel shows
    /// ρ/π · E cos θ (the floor's light leaves the scene or meets a black
    /// box), and a point in the box's shadow nothing.
    #[test]
    fn a_sun_lights_a_floor_by_e_cos_theta() {
        let scene = crate::test_scenes::sunlit_floor(30.0, 3.0, 0.5, true);
        let expected = 0.5 / PI * 3.0 * 30f32.to_radians().cos();
        let (image, _) = render(&scene, &settings(4, 1), &crate::progress::Silent);
        for p in &image.pixels {
            assert!((*p - Rgb::splat(expected)).abs().max_element() < 1e-4 * expected, "{p} vs {expected}");
        }
        // Under the box (centre (1.5, 0.5, 1.5)), where its shadow falls.
        let shadowed = Vec3::new(1.5 + 0.5 * 30f32.to_radians().tan(), 0.0, 1.5);
        let mut rng = Rng::for_item(2, 0);
        let l = radiance(&scene, Ray::new(shadowed + Vec3::Y * 0.1, Vec3::NEG_Y), &settings(1, 0), &mut rng);
        assert_eq!(l, Rgb::ZERO);
    }

    /// An open floor of albedo ρ under a sky of radiance L sees the upper
    /// hemisphere only: irradiance π·L, radiance ρ·L (sky sampling and
    /// cosine sampling, MIS-weighted). The sky itself and its mirror image
    /// show L and R·L.
    #[test]
    fn a_sky_lights_an_open_floor_by_albedo_times_radiance() {
        let scene =
            crate::test_scenes::sky_floor(2.0, "name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]");
        let (image, _) = render(&scene, &settings(64, 1), &crate::progress::Silent);
        // 16,384 samples of standard deviation about ρL: ±0.8%.
        let mean = image.mean();
        eprintln!("sky floor: {mean}");
        assert!((mean - 1.0).abs() < 0.03, "floor radiance {mean}, expected 1");
        let mut rng = Rng::for_item(2, 0);
        let up = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
        assert_eq!(radiance(&scene, up, &settings(1, 0), &mut rng), Rgb::splat(2.0));
        let mirror =
            crate::test_scenes::sky_floor(2.0, "name = \"floor\"\ntype = \"mirror\"\nreflectance = [0.8, 0.8, 0.8]");
        let down = Ray::new(Vec3::new(0.1, 1.0, 0.2), Vec3::NEG_Y);
        let l = radiance(&mirror, down, &settings(1, 0), &mut rng);
        assert!((l - Rgb::splat(1.6)).abs().max_element() < 1e-6, "{l}");
    }

    /// In grey absorbing fog a ray that leaves the scene sees the sky
    /// attenuated up to the disc its photons start from: L·e^(−σ·reach).
    #[test]
    fn the_sky_through_fog_is_attenuated_to_its_disc() {
        use crate::medium::{Media, Medium, Phase};
        let mut scene =
            crate::test_scenes::sky_floor(2.0, "name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]");
        let sigma = 0.3;
        let fog = Medium { sigma_a: Vec3::splat(sigma), sigma_s: Vec3::ZERO, phase: Phase::Schlick { k: 0.0 } };
        scene.media = Media::homogeneous(fog);
        let origin = Vec3::new(0.5, 1.0, 0.0);
        let reach = scene.lights[0].distant_disc().unwrap().reach(origin, Vec3::Y);
        let expected = 2.0 * (-sigma * reach).exp();
        let mut rng = Rng::for_item(4, 0);
        let n = 20_000;
        let sum: Rgb = (0..n).map(|_| radiance(&scene, Ray::new(origin, Vec3::Y), &settings(1, 0), &mut rng)).sum();
        // A path passes with probability e^(−σ·reach) ≈ 0.48: ±0.7%.
        let mean = sum.x / n as f32;
        assert!((mean / expected - 1.0).abs() < 0.03, "{mean} vs {expected}");
    }

    /// Pixels that see no emitter directly (8×8 rays each). A pixel that
    /// does is worth covered fraction × emitted radiance, and with a few
    /// samples its noise swamps every other pixel's.
    pub(crate) fn off_emitters(scene: &Scene) -> Vec<bool> {
        let cam = &scene.camera;
        (0..cam.height * cam.width)
            .map(|i| {
                let pixel = glam::Vec2::new((i % cam.width) as f32, (i / cam.width) as f32);
                !(0..64).any(|j| {
                    let offset = glam::Vec2::new((j % 8) as f32 + 0.5, (j / 8) as f32 + 0.5) / 8.0;
                    scene.accel.intersect(&cam.ray(pixel + offset)).is_some_and(|h| scene.emitter(&h).is_some())
                })
            })
            .collect()
    }

    /// Root-mean-square difference of two images' pixels (channel means)
    /// and the two images' means, over the pixels of `mask`.
    pub(crate) fn compare(a: &Image, b: &Image, mask: &[bool]) -> (f32, f32, f32) {
        let (mut sum2, mut sum_a, mut sum_b, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for ((p, q), _) in a.pixels.iter().zip(&b.pixels).zip(mask).filter(|(_, keep)| **keep) {
            let (p, q) = (crate::material::mean(*p) as f64, crate::material::mean(*q) as f64);
            (sum2, sum_a, sum_b, count) = (sum2 + (p - q).powi(2), sum_a + p, sum_b + q, count + 1);
        }
        let n = count.max(1) as f64;
        ((sum2 / n).sqrt() as f32, (sum_a / n) as f32, (sum_b / n) as f32)
    }

    /// A quad light and the same two triangles as an emissive mesh (black
    /// diffuse surface) light the Cornell box alike: the mesh's image is as
    /// far from the quad's as another quad image with another seed is.
    #[test]
    fn an_emissive_mesh_lights_like_the_same_quad_light() {
        let quad = crate::test_scenes::cornell_quad_light(16);
        let mesh = crate::test_scenes::quad_lights_as_meshes(&quad);
        let silent = &crate::progress::Silent;
        let (a, _) = render(&quad, &settings(512, 1), silent);
        let (b, _) = render(&quad, &settings(512, 2), silent);
        let (m, _) = render(&mesh, &settings(512, 3), silent);
        // Everywhere, light seen directly included.
        let all = vec![true; a.pixels.len()];
        let ((noise, mean_a, mean_b), (difference, _, mean_m)) = (compare(&a, &b, &all), compare(&a, &m, &all));
        eprintln!("all: means quad {mean_a} {mean_b}, mesh {mean_m}; rms quad–quad {noise}, quad–mesh {difference}");
        assert!(difference < 1.5 * noise, "quad–mesh {difference} vs quad–quad {noise}");
        // Off the light, where its light is reflected: means within 2.5%
        // (the two quad images' means differ by 0.2%).
        let mask = off_emitters(&quad);
        let ((noise, mean_a, mean_b), (difference, _, mean_m)) = (compare(&a, &b, &mask), compare(&a, &m, &mask));
        eprintln!(
            "off the light: means quad {mean_a} {mean_b}, mesh {mean_m}; rms quad–quad {noise}, quad–mesh {difference}"
        );
        assert!(difference < 1.5 * noise, "quad–mesh {difference} vs quad–quad {noise}");
        assert!((mean_m / mean_a - 1.0).abs() < 0.025, "mesh {mean_m} vs quad {mean_a}");
    }
}
