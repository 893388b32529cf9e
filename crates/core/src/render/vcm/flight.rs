//! One step of a subpath: the next vertex along a ray, on the surface the
//! ray hits or, where media lie on the way, at the end of a sampled free
//! flight (the sampler the photon tracer and the path tracer use), with
//! what vertex connection and merging needs of it: the throughput's
//! factor and e^−τ̄, on which the flight's densities depend (σ̄ e^−τ̄ per
//! unit length to stop at a point, e^−τ̄ to pass; τ̄ the optical depth in
//! the mean channel, which the sampler spends).

use crate::geometry::{Hit, Ray};
use crate::material::{Rgb, mean};
use crate::medium::{Flight, Media};
use crate::sampling::Rng;
use crate::scene::Scene;
use glam::Vec3;

pub enum Event {
    /// A surface hit, its shading normal bent by any normal texture, and
    /// the smooth (interpolated) normal before it (the bump shadowing's).
    Surface {
        hit: Hit,
        unbent: Vec3,
    },
    /// A scattering event at `point` in the media of `mask`.
    Medium {
        point: Vec3,
        mask: u32,
    },
    Escaped,
}

pub struct Step {
    pub event: Event,
    pub distance: f32,
    /// Multiplies the throughput: the flight's RGB weight and, at a medium
    /// vertex, σ_s/σ_t (so T σ_s / (σ̄ e^−τ̄) in all there).
    pub weight: Rgb,
    /// e^−τ̄ along the step (1 without media).
    pub passes: f32,
}

pub fn step(scene: &Scene, ray: &Ray, rng: &mut Rng) -> Step {
    // Surfaces shade with their normal textures' normals.
    let unbent_hit = scene.accel.intersect(ray);
    let unbent = unbent_hit.map_or(Vec3::ZERO, |h| h.shading_normal);
    let hit = unbent_hit.map(|hit| scene.bent(hit, ray.dir));
    // Arriving at glass from inside: what it absorbed on the way (a
    // deterministic factor: no density changes).
    let absorbed = hit.as_ref().map_or(Rgb::ONE, |h| match scene.material(h) {
        crate::material::Material::Glass(glass) => glass.interior_transmittance(ray.dir, h.geometric_normal, h.t),
        _ => Rgb::ONE,
    });
    let media = &scene.media;
    if media.is_empty() {
        return match hit {
            Some(hit) => Step { distance: hit.t, event: Event::Surface { hit, unbent }, weight: absorbed, passes: 1.0 },
            None => Step { event: Event::Escaped, distance: f32::INFINITY, weight: Rgb::ONE, passes: 1.0 },
        };
    }
    // A ray leaving the scene crosses the fog a shadow ray toward the sky would.
    let t_max = hit.map_or_else(|| scene.escape_distance(ray.origin, ray.dir), |h| h.t);
    match media.sample_flight(ray.origin, ray.dir, t_max, rng.next_f32()) {
        // The sampler's own τ̄: no second walk over the region crossings.
        Flight::Interaction { distance, weight, mask, tau_bar } => {
            let (sigma_t, sigma_s) = (media.sigma_t(mask), media.sigma_s(mask));
            let albedo = Rgb::select(sigma_t.cmpgt(Rgb::ZERO), sigma_s / sigma_t, Rgb::ZERO);
            Step {
                event: Event::Medium { point: ray.at(distance), mask },
                distance,
                weight: weight * albedo,
                passes: (-tau_bar).exp(),
            }
        }
        Flight::Passed { weight, tau_bar } => Step {
            event: hit.map_or(Event::Escaped, |hit| Event::Surface { hit, unbent }),
            distance: t_max,
            weight: weight * absorbed,
            passes: (-tau_bar).exp(),
        },
    }
}

/// The transmittance (RGB) and e^−τ̄ from `x` along `dir` over `distance`.
pub fn between(media: &Media, x: Vec3, dir: Vec3, distance: f32) -> (Rgb, f32) {
    if media.is_empty() {
        return (Rgb::ONE, 1.0);
    }
    let tau = media.optical_depth(x, dir, distance);
    ((-tau).exp(), (-mean(tau)).exp())
}
