//! hikari's lights as vertex connection and merging needs them: emission
//! with the densities of its start, next-event estimation with the density
//! a light subpath would have had to start at the sampled point, and both
//! densities at a point a camera subpath hits (SmallVCM's `Emit`,
//! `Illuminate` and `GetRadiance`). Positions and directions come from
//! [`Light::emit`] and [`Light::sample_incident`], which the photon tracer
//! and the path tracer use; this module adds the densities.
//!
//! Conventions (SmallVCM's): densities per steradian at the light's side;
//! next-event estimation of point and spot lights has density d² (a delta
//! position's "area density" 1 turned into solid angle), of the sun 1;
//! distant lights' densities of position are per unit area of their disc.

use crate::geometry::Hit;
use crate::light::{Light, cone_pdf, spot_falloff, spot_solid_angle};
use crate::material::Rgb;
use crate::sampling::{Rng, UNIFORM_SPHERE_PDF};
use crate::scene::Scene;
use glam::Vec3;
use std::f32::consts::PI;

/// The scene's lights with their choice probabilities (∝ power, as photons).
pub struct Emitters<'a> {
    scene: &'a Scene,
    probabilities: Vec<f32>,
    cumulative: Vec<f32>,
}

/// A light subpath's start.
pub struct Emission {
    pub light: usize,
    pub origin: Vec3,
    /// The emitting face's normal (area lights; zero for the others).
    pub normal: Vec3,
    pub dir: Vec3,
    /// Le·cos / (choice × emission density).
    pub throughput: Rgb,
    /// Of the start, light choice included.
    pub emission_pdf_w: f32,
    /// Of next-event estimation picking the start (light choice included);
    /// 1 for a sphere, whose density depends on the receiver
    /// ([`Emitters::sphere_direct_pdf_a`] at the first hit).
    pub direct_pdf: f32,
    pub cos_light: f32,
    pub delta: bool,
    /// Distant lights: the first segment's densities are per solid angle.
    pub finite: bool,
}

/// A next-event sample toward a light.
pub struct Illumination {
    pub wi: Vec3,
    pub distance: f32,
    /// What `cos·f·radiance / direct_pdf_w` turns into reflected radiance.
    pub radiance: Rgb,
    /// Light choice × density per steradian (d² for point and spot lights).
    pub direct_pdf_w: f32,
    pub emission_pdf_w: f32,
    pub cos_at_light: f32,
    pub delta: bool,
}

/// Emitted light a camera subpath finds, with the densities of the other
/// strategies that reach the same point (light choice included).
pub struct Found {
    pub radiance: Rgb,
    pub direct_pdf: f32,
    pub emission_pdf_w: f32,
}

impl<'a> Emitters<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        let probabilities = scene.light_selection_probabilities();
        let mut total = 0.0;
        let cumulative = probabilities
            .iter()
            .map(|p| {
                total += p;
                total
            })
            .collect();
        Emitters { scene, probabilities, cumulative }
    }

    fn choose(&self, u: f32) -> usize {
        let target = u * self.cumulative.last().copied().unwrap_or(0.0);
        self.cumulative.partition_point(|&c| c <= target).min(self.cumulative.len().saturating_sub(1))
    }

    /// A light subpath's start; None if the choice carries nothing.
    pub fn emit(&self, rng: &mut Rng) -> Option<Emission> {
        if self.probabilities.is_empty() {
            return None;
        }
        let index = self.choose(rng.next_f32());
        let pick = self.probabilities[index];
        let light = &self.scene.lights[index];
        let ray = light.emit(rng);
        let start = |le: Rgb, emission_pdf_w: f32, direct_pdf: f32, cos_light: f32, delta: bool, finite: bool| {
            let emission_pdf_w = emission_pdf_w * pick;
            (emission_pdf_w > 0.0 && le.max_element() > 0.0).then(|| Emission {
                light: index,
                origin: ray.origin,
                normal: ray.normal,
                dir: ray.dir,
                throughput: le * cos_light / emission_pdf_w,
                emission_pdf_w,
                direct_pdf: direct_pdf * pick,
                cos_light,
                delta,
                finite,
            })
        };
        match *light {
            Light::Point { intensity, .. } => start(intensity, UNIFORM_SPHERE_PDF, 1.0, 1.0, true, true),
            Light::Spot { axis, intensity, cutoff, falloff_start, .. } => {
                let falloff = spot_falloff(ray.dir.dot(axis).clamp(-1.0, 1.0).acos(), cutoff, falloff_start);
                let pdf = falloff / spot_solid_angle(cutoff, falloff_start);
                start(intensity * falloff, pdf, 1.0, 1.0, true, true)
            }
            Light::Sphere { radius, radiance, .. } => {
                let cos = ray.dir.dot(ray.normal);
                start(radiance, cos / (PI * 4.0 * PI * radius * radius), 1.0, cos, false, true)
            }
            Light::Quad { edge_u, edge_v, radiance, .. } => {
                let area = edge_u.cross(edge_v).length();
                let cos = ray.dir.dot(ray.normal);
                start(radiance, cos / (PI * area), 1.0 / area, cos, false, true)
            }
            Light::Mesh(ref mesh) => {
                let sides = if mesh.two_sided { 2.0 } else { 1.0 };
                let cos = ray.dir.dot(ray.normal);
                start(mesh.radiance, cos / (PI * mesh.area() * sides), 1.0 / mesh.area(), cos, false, true)
            }
            Light::Directional { irradiance, disc, .. } => start(irradiance, 1.0 / disc.area(), 1.0, 1.0, true, false),
            Light::Environment { disc, .. } => {
                let toward_sky = -ray.dir;
                let pdf = sky_pdf(light, toward_sky);
                start(light.escaped_radiance(toward_sky), pdf / disc.area(), pdf, 1.0, false, false)
            }
        }
    }

    /// Next-event density, per unit area, of a sphere light's cone choosing
    /// point `y` (normal `n`) as seen from `x` (light choice not included).
    pub fn sphere_direct_pdf_a(&self, light: usize, x: Vec3, y: Vec3, n: Vec3) -> f32 {
        let Light::Sphere { center, radius, .. } = self.scene.lights[light] else { return 1.0 };
        let d2 = (center - x).length_squared();
        if d2 <= radius * radius {
            return 0.0;
        }
        let sin2_max = radius * radius / d2;
        let to_y = y - x;
        let cos_y = to_y.normalize().dot(n).abs();
        cone_pdf(sin2_max, (1.0 - sin2_max).max(0.0).sqrt()) * cos_y / to_y.length_squared()
    }

    /// Next-event estimation at `x`: one light chosen ∝ power, one sample of it.
    pub fn illuminate(&self, x: Vec3, rng: &mut Rng) -> Option<Illumination> {
        if self.probabilities.is_empty() {
            return None;
        }
        let index = self.choose(rng.next_f32());
        let pick = self.probabilities[index];
        let light = &self.scene.lights[index];
        let s = light.sample_incident(x, rng.next_2d())?;
        if s.pdf <= 0.0 || !s.distance.is_finite() {
            return None;
        }
        let y = x + s.wi * s.distance;
        let d2 = s.distance * s.distance;
        let (radiance, direct_pdf_w, emission_pdf_w, cos_at_light) = match *light {
            Light::Point { .. } => (s.radiance * d2, d2, UNIFORM_SPHERE_PDF, 1.0),
            Light::Spot { axis, cutoff, falloff_start, .. } => {
                let falloff = spot_falloff((-s.wi).dot(axis).clamp(-1.0, 1.0).acos(), cutoff, falloff_start);
                (s.radiance * d2, d2, falloff / spot_solid_angle(cutoff, falloff_start), 1.0)
            }
            Light::Sphere { center, radius, .. } => {
                let cos = (-s.wi).dot((y - center) / radius).max(0.0);
                (s.radiance, s.pdf, cos / (PI * 4.0 * PI * radius * radius), cos)
            }
            Light::Quad { edge_u, edge_v, .. } => {
                let normal_area = edge_u.cross(edge_v);
                let area = normal_area.length();
                let cos = (-s.wi).dot(normal_area / area);
                (s.radiance, s.pdf, cos / (PI * area), cos)
            }
            Light::Mesh(ref mesh) => {
                // The sample's density d²/(A cos) gives its cosine back.
                let cos = d2 / (mesh.area() * s.pdf);
                let sides = if mesh.two_sided { 2.0 } else { 1.0 };
                (s.radiance, s.pdf, cos / (PI * mesh.area() * sides), cos)
            }
            Light::Directional { disc, .. } => (s.radiance, 1.0, 1.0 / disc.area(), 1.0),
            Light::Environment { disc, .. } => (s.radiance, s.pdf, s.pdf / disc.area(), 1.0),
        };
        (cos_at_light > 0.0 && emission_pdf_w > 0.0).then_some(Illumination {
            wi: s.wi,
            distance: s.distance,
            radiance,
            direct_pdf_w: direct_pdf_w * pick,
            emission_pdf_w: emission_pdf_w * pick,
            cos_at_light,
            delta: s.is_delta,
        })
    }

    /// The light a camera subpath from `from` finds at `hit` along `dir`:
    /// an area light's surface or an emissive mesh.
    pub fn at_surface(&self, hit: &Hit, from: Vec3, dir: Vec3) -> Option<Found> {
        let index = self.scene.surfaces[hit.surface as usize].emitter? as usize;
        let radiance = self.scene.emitted_radiance(hit, dir)?;
        if radiance.max_element() <= 0.0 {
            return None;
        }
        let pick = self.probabilities[index];
        let cos = dir.dot(hit.geometric_normal).abs();
        let (direct_pdf, emission_pdf_w) = match self.scene.lights[index] {
            Light::Sphere { radius, .. } => (
                self.sphere_direct_pdf_a(index, from, hit.point, hit.geometric_normal),
                cos / (PI * 4.0 * PI * radius * radius),
            ),
            Light::Quad { edge_u, edge_v, .. } => {
                let area = edge_u.cross(edge_v).length();
                (1.0 / area, cos / (PI * area))
            }
            Light::Mesh(ref mesh) => {
                let sides = if mesh.two_sided { 2.0 } else { 1.0 };
                (1.0 / mesh.area(), cos / (PI * mesh.area() * sides))
            }
            _ => return None,
        };
        Some(Found { radiance, direct_pdf: direct_pdf * pick, emission_pdf_w: emission_pdf_w * pick })
    }

    /// The skies a ray escaping along `dir` sees, each with its densities.
    pub fn escaped(&self, dir: Vec3) -> impl Iterator<Item = Found> + '_ {
        self.scene.lights.iter().enumerate().filter_map(move |(index, light)| {
            let Light::Environment { disc, .. } = *light else { return None };
            let radiance = light.escaped_radiance(dir);
            if radiance.max_element() <= 0.0 {
                return None;
            }
            let pick = self.probabilities[index];
            let pdf = sky_pdf(light, dir);
            Some(Found { radiance, direct_pdf: pdf * pick, emission_pdf_w: pdf / disc.area() * pick })
        })
    }
}

/// A sky's density per steradian of sampling the direction `toward_sky`.
fn sky_pdf(light: &Light, toward_sky: Vec3) -> f32 {
    match light {
        Light::Environment { map: Some(map), .. } => map.pdf(toward_sky),
        _ => UNIFORM_SPHERE_PDF,
    }
}
