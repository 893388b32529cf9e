//! Light sources: a closed set (point, spot, sphere, quad).
//!
//! Each light knows its total emitted power (to split photons among lights),
//! how to emit a photon (origin and direction, distributed as its emission),
//! and how to sample incident light at a point (for direct lighting).

use crate::material::Rgb;
use crate::sampling::{self, Rng, local_to_world};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light; `intensity` in W/sr.
    Point { position: Vec3, intensity: Rgb },
    /// Spot light with Mitsuba's falloff: full `intensity` (W/sr) within
    /// `falloff_start` of the axis, zero beyond `cutoff`, linear in the angle between.
    Spot { position: Vec3, axis: Vec3, intensity: Rgb, cutoff: f32, falloff_start: f32 },
    /// Sphere emitting `radiance` (W/(m² sr)) from its outer surface.
    Sphere { center: Vec3, radius: f32, radiance: Rgb },
    /// Parallelogram `corner + s·edge_u + t·edge_v`, emitting `radiance` on the
    /// side of `edge_u × edge_v` only.
    Quad { corner: Vec3, edge_u: Vec3, edge_v: Vec3, radiance: Rgb },
}

/// Light arriving at a point from one sampled direction.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the point toward the light.
    pub wi: Vec3,
    /// Distance to the sampled light point (for the shadow ray).
    pub distance: f32,
    /// Incident radiance for area lights; I·falloff/d² for delta lights.
    pub radiance: Rgb,
    /// Solid-angle density of `wi`; 1 for delta lights.
    pub pdf: f32,
    pub is_delta: bool,
}

/// A photon leaving a light: start point and unit direction.
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Light {
    /// Total emitted power Φ in watts per channel.
    pub fn power(&self) -> Rgb {
        match *self {
            Light::Point { intensity, .. } => 4.0 * PI * intensity,
            Light::Spot { intensity, cutoff, falloff_start, .. } => intensity * spot_solid_angle(cutoff, falloff_start),
            Light::Sphere { radius, radiance, .. } => radiance * PI * (4.0 * PI * radius * radius),
            Light::Quad { edge_u, edge_v, radiance, .. } => radiance * PI * edge_u.cross(edge_v).length(),
        }
    }

    /// The point that places the light: position (point, spot), centre
    /// (sphere) or corner (quad). Moving a light moves this point.
    pub fn anchor(&self) -> Vec3 {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => position,
            Light::Sphere { center, .. } => center,
            Light::Quad { corner, .. } => corner,
        }
    }

    /// Where a point or spot light sits; None for area lights.
    pub fn delta_position(&self) -> Option<Vec3> {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(position),
            Light::Sphere { .. } | Light::Quad { .. } => None,
        }
    }

    /// The part [ta, tb] of the ray `origin + t·dir` (unit `dir`), t in
    /// [t0, t1], that the light can reach: a spot's cone (convex while its
    /// cutoff is under 90°) cut out of the interval, the whole interval for
    /// other lights. None if the ray misses the cone there.
    pub fn lit_interval(&self, origin: Vec3, dir: Vec3, t0: f32, t1: f32) -> Option<(f32, f32)> {
        let Light::Spot { position, axis, cutoff, .. } = *self else { return Some((t0, t1)) };
        if cutoff >= CLIPPED_CONE_LIMIT {
            return Some((t0, t1));
        }
        let cos_cutoff = cutoff.cos();
        let inside = |t: f32| {
            let to_point = origin + dir * t - position;
            to_point.dot(axis) >= cos_cutoff * to_point.length()
        };
        // Along the ray the cone's boundary, (p − apex)·axis = cos·|p − apex|,
        // squared: a t² + b t + c = 0. Between consecutive roots (and the
        // apex plane) whether a point is inside does not change, so a test
        // at one point of each piece decides it.
        let v = origin - position;
        let cos2 = cos_cutoff * cos_cutoff;
        let (dk, vk) = (dir.dot(axis), v.dot(axis));
        let (a, b, c) = (dk * dk - cos2, 2.0 * (vk * dk - cos2 * v.dot(dir)), vk * vk - cos2 * v.length_squared());
        let mut cuts = [t0, t1, f32::NAN, f32::NAN, f32::NAN];
        let discriminant = b * b - 4.0 * a * c;
        if discriminant >= 0.0 && a != 0.0 {
            let q = -0.5 * (b + discriminant.sqrt().copysign(b));
            (cuts[2], cuts[3]) = (q / a, if q != 0.0 { c / q } else { f32::NAN });
        } else if a == 0.0 && b != 0.0 {
            cuts[2] = -c / b;
        }
        if dk != 0.0 {
            cuts[4] = -vk / dk;
        }
        let mut cuts: Vec<f32> = cuts.into_iter().filter(|t| *t >= t0 && *t <= t1).collect();
        cuts.sort_by(f32::total_cmp);
        let mut lit: Option<(f32, f32)> = None;
        for piece in cuts.windows(2) {
            let (start, end) = (piece[0], piece[1]);
            let probe = if end.is_finite() { 0.5 * (start + end) } else { start + 1.0 + start.abs() };
            if end > start && inside(probe) {
                lit = Some(lit.map_or((start, end), |(s, _)| (s, end)));
            }
        }
        // Roots are rounded: widen by a hair (the falloff is zero at the
        // cutoff, so what is gained or lost at the boundary carries nothing).
        lit.map(|(s, e)| ((s - 1e-4 * (1.0 + s.abs())).max(t0), (e + 1e-4 * (1.0 + e.abs())).min(t1)))
    }

    /// The same light with its anchor at `anchor`.
    pub fn with_anchor(&self, anchor: Vec3) -> Light {
        let mut light = self.clone();
        match &mut light {
            Light::Point { position, .. } | Light::Spot { position, .. } => *position = anchor,
            Light::Sphere { center, .. } => *center = anchor,
            Light::Quad { corner, .. } => *corner = anchor,
        }
        light
    }

    /// Intensity (point, spot; W/sr) or radiance (area lights; W/(m² sr)).
    pub fn emission(&self) -> Rgb {
        match *self {
            Light::Point { intensity, .. } | Light::Spot { intensity, .. } => intensity,
            Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } => radiance,
        }
    }

    /// The same light emitting `emission` (see `emission`).
    pub fn with_emission(&self, emission: Rgb) -> Light {
        let mut light = self.clone();
        match &mut light {
            Light::Point { intensity, .. } | Light::Spot { intensity, .. } => *intensity = emission,
            Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } => *radiance = emission,
        }
        light
    }

    /// The light carried by the rigid motion `motion` (rotation and
    /// translation): its anchor moved, its axis or edges turned.
    pub fn moved(&self, motion: &glam::Affine3A) -> Light {
        let point = |p: Vec3| motion.transform_point3(p);
        let vector = |v: Vec3| motion.transform_vector3(v);
        match self.clone() {
            Light::Point { position, intensity } => Light::Point { position: point(position), intensity },
            Light::Spot { position, axis, intensity, cutoff, falloff_start } => Light::Spot {
                position: point(position),
                axis: vector(axis).normalize(),
                intensity,
                cutoff,
                falloff_start,
            },
            Light::Sphere { center, radius, radiance } => Light::Sphere { center: point(center), radius, radiance },
            Light::Quad { corner, edge_u, edge_v, radiance } => {
                Light::Quad { corner: point(corner), edge_u: vector(edge_u), edge_v: vector(edge_v), radiance }
            }
        }
    }

    /// Area lights have geometry in the scene; point and spot lights do not.
    pub fn is_area(&self) -> bool {
        matches!(self, Light::Sphere { .. } | Light::Quad { .. })
    }

    /// Samples a photon's start, distributed as the light's emission
    /// (METHOD.md §2), so every photon of a light carries the same power.
    pub fn emit(&self, rng: &mut Rng) -> EmittedRay {
        match *self {
            Light::Point { position, .. } => {
                EmittedRay { origin: position, dir: sampling::uniform_sphere(rng.next_2d()) }
            }
            Light::Spot { position, axis, cutoff, falloff_start, .. } => {
                let local = sample_spot_direction(cutoff, falloff_start, rng);
                EmittedRay { origin: position, dir: local_to_world(local, axis) }
            }
            Light::Sphere { center, radius, .. } => {
                let n = sampling::uniform_sphere(rng.next_2d());
                let dir = local_to_world(sampling::cosine_hemisphere(rng.next_2d()), n);
                EmittedRay { origin: center + n * radius, dir }
            }
            Light::Quad { corner, edge_u, edge_v, .. } => {
                let u = rng.next_2d();
                let n = edge_u.cross(edge_v).normalize();
                let dir = local_to_world(sampling::cosine_hemisphere(rng.next_2d()), n);
                EmittedRay { origin: corner + edge_u * u.x + edge_v * u.y, dir }
            }
        }
    }

    /// Samples light arriving at `point`. None if this sample carries nothing.
    pub fn sample_incident(&self, point: Vec3, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Point { position, intensity } => delta_sample(point, position, intensity),
            Light::Spot { position, axis, intensity, cutoff, falloff_start } => {
                let to_point = (point - position).normalize_or_zero();
                let f = spot_falloff(to_point.dot(axis).clamp(-1.0, 1.0).acos(), cutoff, falloff_start);
                if f <= 0.0 {
                    return None;
                }
                delta_sample(point, position, intensity * f)
            }
            Light::Sphere { center, radius, radiance } => {
                let to_center = center - point;
                let d2 = to_center.length_squared();
                if d2 <= radius * radius {
                    return None;
                }
                let d = d2.sqrt();
                let sin2_max = radius * radius / d2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                let axis = to_center / d;
                let wi = local_to_world(sampling::uniform_cone(u, cos_max), axis);
                let distance = sphere_entry_distance(point, wi, center, radius).unwrap_or(d - radius);
                Some(LightSample { wi, distance, radiance, pdf: cone_pdf(sin2_max, cos_max), is_delta: false })
            }
            Light::Quad { corner, edge_u, edge_v, radiance } => {
                let p = corner + edge_u * u.x + edge_v * u.y;
                let normal_area = edge_u.cross(edge_v);
                let area = normal_area.length();
                let to_light = p - point;
                let d2 = to_light.length_squared();
                let distance = d2.sqrt();
                let wi = to_light / distance;
                let cos_l = -wi.dot(normal_area / area);
                if cos_l <= 0.0 || !distance.is_finite() || distance == 0.0 {
                    return None;
                }
                Some(LightSample { wi, distance, radiance, pdf: d2 / (area * cos_l), is_delta: false })
            }
        }
    }

    /// Solid-angle density with which `sample_incident` at `point` would pick
    /// direction `wi` that hits this (area) light at `hit_point` with normal
    /// `hit_normal`. Used for MIS when a BSDF-sampled ray hits the light.
    pub fn incident_pdf(&self, point: Vec3, hit_point: Vec3, hit_normal: Vec3) -> f32 {
        match *self {
            Light::Sphere { center, radius, .. } => {
                let d2 = (center - point).length_squared();
                if d2 <= radius * radius {
                    return 0.0;
                }
                let sin2_max = radius * radius / d2;
                cone_pdf(sin2_max, (1.0 - sin2_max).max(0.0).sqrt())
            }
            Light::Quad { edge_u, edge_v, .. } => {
                let to_light = hit_point - point;
                let d2 = to_light.length_squared();
                let cos_l = (to_light / d2.sqrt()).dot(hit_normal).abs();
                let area = edge_u.cross(edge_v).length();
                if cos_l <= 0.0 { 0.0 } else { d2 / (area * cos_l) }
            }
            _ => 0.0,
        }
    }

    /// Radiance leaving an area light's surface at a point with geometric
    /// normal `normal`, seen along `dir` (propagation direction of the eye ray).
    pub fn emitted_radiance(&self, dir: Vec3, normal: Vec3) -> Rgb {
        match *self {
            Light::Sphere { radiance, .. } if dir.dot(normal) < 0.0 => radiance,
            Light::Quad { edge_u, edge_v, radiance, .. } if dir.dot(edge_u.cross(edge_v)) < 0.0 => radiance,
            _ => Rgb::ZERO,
        }
    }
}

/// Spots with a cutoff from here on are not clipped by [`Light::lit_interval`]
/// (the cone stops being convex at 90°).
const CLIPPED_CONE_LIMIT: f32 = 85.0 * PI / 180.0;

fn delta_sample(point: Vec3, position: Vec3, intensity: Rgb) -> Option<LightSample> {
    let to_light = position - point;
    let d2 = to_light.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let distance = d2.sqrt();
    Some(LightSample { wi: to_light / distance, distance, radiance: intensity / d2, pdf: 1.0, is_delta: true })
}

/// Uniform-cone density, with 1 − cos θ_max computed without cancellation.
fn cone_pdf(sin2_max: f32, cos_max: f32) -> f32 {
    let one_minus_cos = sin2_max / (1.0 + cos_max);
    1.0 / (2.0 * PI * one_minus_cos)
}

fn sphere_entry_distance(origin: Vec3, dir: Vec3, center: Vec3, radius: f32) -> Option<f32> {
    let s = crate::geometry::Sphere { center, radius };
    s.intersect(&crate::geometry::Ray::new(origin, dir), 0.0)
}

/// Mitsuba's spot falloff at angle θ from the axis (radians).
pub fn spot_falloff(theta: f32, cutoff: f32, falloff_start: f32) -> f32 {
    if theta >= cutoff {
        0.0
    } else if theta <= falloff_start {
        1.0
    } else {
        (cutoff - theta) / (cutoff - falloff_start)
    }
}

/// ∫ falloff(θ) dω over the sphere, in closed form.
pub fn spot_solid_angle(cutoff: f32, falloff_start: f32) -> f32 {
    let (b, c) = (falloff_start as f64, cutoff as f64);
    let inner = 1.0 - b.cos();
    // The ramp term is ((c − b)·cos b − sin c + sin b)/(c − b); written as a
    // sum of non-negative terms so that it does not cancel when c − b is tiny:
    // with d = c − b, m = b + d/2 and h = d/2 it is
    // 2·sin(b + d/4)·sin(d/4) + cos(m)·(1 − sin(h)/h).
    let d = c - b;
    let ramp = if d > 0.0 {
        let h = d / 2.0;
        let one_minus_sinc = if h < 1e-3 { h * h / 6.0 - h.powi(4) / 120.0 } else { 1.0 - h.sin() / h };
        2.0 * (b + d / 4.0).sin() * (d / 4.0).sin() + (b + h).cos() * one_minus_sinc
    } else {
        0.0
    };
    (2.0 * std::f64::consts::PI * (inner + ramp)) as f32
}

/// Direction about +z distributed ∝ falloff(θ): uniform in the cutoff cone,
/// accepted with probability falloff(θ) (exact rejection sampling).
pub fn sample_spot_direction(cutoff: f32, falloff_start: f32, rng: &mut Rng) -> Vec3 {
    let cos_max = cutoff.cos();
    loop {
        let w = sampling::uniform_cone(rng.next_2d(), cos_max);
        let f = spot_falloff(w.z.clamp(-1.0, 1.0).acos(), cutoff, falloff_start);
        if rng.next_f32() < f {
            return w;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{assert_direction_distribution, assert_unit_density};

    /// The lit interval of a spot holds every point of the ray inside the
    /// cone and starts and ends at the cone (dense sampling along rays from
    /// inside and outside, toward and away from the apex).
    #[test]
    fn lit_interval_is_the_part_of_the_ray_inside_the_cone() {
        let spot = Light::Spot {
            position: Vec3::new(0.0, 4.5, 0.0),
            axis: Vec3::NEG_Y,
            intensity: Vec3::ONE,
            cutoff: 22f32.to_radians(),
            falloff_start: 16f32.to_radians(),
        };
        let Light::Spot { position, axis, cutoff, .. } = spot else { unreachable!() };
        let inside = |p: Vec3| (p - position).normalize().dot(axis) >= cutoff.cos();
        let mut rng = Rng::for_item(17, 0);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..2000 {
            let origin = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 7.0 - 1.0, rng.next_f32() * 8.0 - 4.0);
            let dir = crate::sampling::uniform_sphere(rng.next_2d());
            let t1 = 12.0;
            let steps = 6000;
            let samples: Vec<f32> =
                (0..=steps).map(|i| t1 * i as f32 / steps as f32).filter(|&t| inside(origin + dir * t)).collect();
            match (spot.lit_interval(origin, dir, 0.0, t1), samples.first(), samples.last()) {
                (Some((a, b)), Some(&first), Some(&last)) => {
                    hits += 1;
                    assert!(a <= first && b >= last, "[{a}, {b}] misses [{first}, {last}]");
                    let step = t1 / steps as f32;
                    assert!(first - a < step + 3e-3 && b - last < step + 3e-3, "[{a}, {b}] vs [{first}, {last}]");
                }
                (None, None, None) => misses += 1,
                // A sliver thinner than the sampling step may be found by one side only.
                (Some((a, b)), None, None) => assert!(b - a < 0.01, "[{a}, {b}] with no sample inside"),
                (None, Some(&first), Some(&last)) => panic!("no interval, samples inside from {first} to {last}"),
                other => unreachable!("{other:?}"),
            }
        }
        assert!(hits > 100 && misses > 100, "{hits} rays through the cone, {misses} past it");
        // Other lights reach the whole interval.
        let point = Light::Point { position, intensity: Vec3::ONE };
        assert_eq!(point.lit_interval(Vec3::ZERO, Vec3::X, 0.5, 3.0), Some((0.5, 3.0)));
    }

    #[test]
    fn spot_solid_angle_is_the_closed_form_and_stable_for_thin_ramps() {
        let closed = |c: f64, b: f64| {
            2.0 * std::f64::consts::PI * (1.0 - b.cos() + ((c - b) * b.cos() - c.sin() + b.sin()) / (c - b))
        };
        for (c, b) in [(40.0f64, 20.0f64), (90.0, 0.0), (20.0, 15.0), (1.0, 0.5)] {
            let (c, b) = (c.to_radians(), b.to_radians());
            let ours = spot_solid_angle(c as f32, b as f32) as f64;
            assert!((ours / closed(c, b) - 1.0).abs() < 1e-5, "{c} {b}: {ours} vs {}", closed(c, b));
        }
        // A ramp far thinner than f32 can show: the hard-edged cone's solid angle.
        let c = 20f32.to_radians();
        let hard = spot_solid_angle(c, c);
        let thin = spot_solid_angle(c, c - 1e-7);
        assert!((thin / hard - 1.0).abs() < 1e-5, "{thin} vs {hard}");
        let tiny = spot_solid_angle(1e-4, 0.0);
        assert!(tiny > 0.0 && tiny.is_finite());
    }

    #[test]
    fn spot_emission_matches_falloff() {
        let (cutoff, start) = (40f32.to_radians(), 20f32.to_radians());
        let norm = spot_solid_angle(cutoff, start);
        let pdf = move |w: Vec3| spot_falloff(w.z.clamp(-1.0, 1.0).acos(), cutoff, start) / norm;
        assert_unit_density(pdf);
        let rng = std::cell::RefCell::new(Rng::for_item(3, 0));
        // The sampler needs more randomness than two uniforms: draw it from its own stream.
        assert_direction_distribution(|_| sample_spot_direction(cutoff, start, &mut rng.borrow_mut()), pdf);
    }

    #[test]
    fn spot_power_matches_numeric_integral() {
        let (cutoff, start) = (50f32.to_radians(), 10f32.to_radians());
        let n = 200_000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let theta = (i as f64 + 0.5) / n as f64 * std::f64::consts::PI;
            sum += spot_falloff(theta as f32, cutoff, start) as f64 * theta.sin();
        }
        let numeric = 2.0 * std::f64::consts::PI * sum * std::f64::consts::PI / n as f64;
        assert!((numeric as f32 - spot_solid_angle(cutoff, start)).abs() < 1e-4);
    }

    #[test]
    fn sphere_light_sampling_matches_cone_density() {
        // Light at distance 1 with radius 0.6: cos θ_max = 0.8.
        let light = Light::Sphere { center: Vec3::Z, radius: 0.6, radiance: Vec3::ONE };
        let pdf_val = 1.0 / (2.0 * PI * 0.2);
        let pdf = move |w: Vec3| if w.z >= 0.8 { pdf_val } else { 0.0 };
        assert_unit_density(pdf);
        assert_direction_distribution(|u| light.sample_incident(Vec3::ZERO, u).unwrap().wi, pdf);
        let s = light.sample_incident(Vec3::ZERO, Vec2::new(0.3, 0.7)).unwrap();
        assert!((s.pdf - pdf_val).abs() / pdf_val < 1e-4);
        // The sampled point lies on the sphere.
        assert!(((s.wi * s.distance - Vec3::Z).length() - 0.6).abs() < 1e-4);
    }

    #[test]
    fn quad_incident_pdf_agrees_with_sampling() {
        let light =
            Light::Quad { corner: Vec3::new(-0.5, 1.0, -0.5), edge_u: Vec3::Z, edge_v: Vec3::X, radiance: Vec3::ONE };
        // edge_u × edge_v = Z × X = +Y: emits upward, so a point below sees nothing.
        assert!(light.sample_incident(Vec3::ZERO, Vec2::splat(0.5)).is_none());
        let flipped =
            Light::Quad { corner: Vec3::new(-0.5, 1.0, -0.5), edge_u: Vec3::X, edge_v: Vec3::Z, radiance: Vec3::ONE };
        let s = flipped.sample_incident(Vec3::ZERO, Vec2::new(0.2, 0.9)).unwrap();
        let hit = s.wi * s.distance;
        let pdf = flipped.incident_pdf(Vec3::ZERO, hit, Vec3::NEG_Y);
        assert!((pdf - s.pdf).abs() / s.pdf < 1e-4);
        // Monte Carlo irradiance against the closed form: a unit-radiance square of
        // side 1 centred at height 1 is four 0.5×0.5 rectangles with a corner
        // above the point, each of form factor (1/2π)·2·X/√(1+X²)·atan(X/√(1+X²)).
        let mut rng = Rng::for_item(9, 0);
        let n = 200_000;
        let mut e = 0.0f64;
        for _ in 0..n {
            if let Some(s) = flipped.sample_incident(Vec3::ZERO, rng.next_2d()) {
                e += (s.radiance.x * s.wi.y / s.pdf) as f64;
            }
        }
        let x = 0.5f64;
        let k = (1.0 + x * x).sqrt();
        let expected = std::f64::consts::PI * 4.0 * (2.0 * x / k * (x / k).atan()) / (2.0 * std::f64::consts::PI);
        assert!((e / n as f64 - expected).abs() < 0.005, "irradiance {} vs {expected}", e / n as f64);
    }
}
