//! Light sources: a closed set. Local lights: point, spot, sphere, quad and
//! emissive triangle meshes (glTF's glowing surfaces). Distant lights: a
//! directional sun and a uniform environment (sky).
//!
//! Each light knows its total emitted power (to split photons among lights),
//! how to emit a photon (origin and direction, distributed as its emission),
//! and how to sample incident light at a point (for direct lighting).
//!
//! Distant lights shine from infinitely far away, so their photons start on
//! a [`Disc`] fitted to the scene's bounding sphere ([`fit_distant_lights`]):
//! of that disc's radius, perpendicular to the light's direction and set
//! back by the radius, so that it covers the whole scene. Their power is
//! what crosses the disc. Shadow rays toward them end at the same disc, so
//! in a medium the path tracer attenuates them over the photons' path.

use crate::envmap::EnvironmentMap;
use crate::material::Rgb;
use crate::sampling::{self, Rng, local_to_world, orthonormal_basis};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

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
    /// A sun: parallel light travelling along the unit `direction`, giving
    /// `irradiance` (W/m²) on a surface facing it. Power E·πr² across `disc`.
    Directional { direction: Vec3, irradiance: Rgb, disc: Disc },
    /// A sky: `radiance` (W/(m² sr)) arriving from every direction, times
    /// the texel of `map` toward it where there is one (an `.hdr`/`.exr`
    /// equirectangular image, [`EnvironmentMap`]). Power L·4π·πr² across
    /// `disc`, or L·∫map dω·πr² (see [`Light::power`]).
    Environment { radiance: Rgb, disc: Disc, map: Option<Arc<EnvironmentMap>> },
    /// Emissive triangles, which are also scene geometry with an ordinary
    /// (reflecting) material.
    Mesh(Arc<EmissiveMesh>),
}

/// Where a distant light's photons start: the disc of `radius` through the
/// scene's bounding sphere (centre `center`), turned perpendicular to each
/// photon's direction and set back by the radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    pub center: Vec3,
    pub radius: f32,
}

impl Disc {
    /// A unit disc at the origin, until [`fit_distant_lights`] fits it.
    pub const UNIT: Disc = Disc { center: Vec3::ZERO, radius: 1.0 };

    /// Distance from `point` along `wi` to the plane that light arriving
    /// along −`wi` starts from (the set-back disc): where shadow rays toward
    /// a distant light end. Between 0 and 2r inside the sphere; 0 upstream
    /// of the plane, where no photon goes either.
    pub fn reach(&self, point: Vec3, wi: Vec3) -> f32 {
        (self.radius - (point - self.center).dot(wi)).max(0.0)
    }

    /// Whether light arriving at `point` along −`wi` (unit) comes from the
    /// disc, as photons do: `point` lies downstream of the disc and within
    /// its radius of the axis. Always so inside the sphere, where every
    /// surface is; in fog outside it, where no photon of that direction
    /// goes, the renderers' direct light must not go either.
    pub fn covers(&self, point: Vec3, wi: Vec3) -> bool {
        let v = point - self.center;
        let along = v.dot(wi);
        along.abs() <= self.radius && (v - wi * along).length_squared() <= self.radius * self.radius
    }

    /// A uniform point on the disc perpendicular to `dir` (unit), set back
    /// by the radius against `dir`.
    fn emission_origin(&self, dir: Vec3, u: Vec2) -> Vec3 {
        let (t, b) = orthonormal_basis(dir);
        let p = sampling::unit_circle(u.y) * u.x.sqrt() * self.radius;
        self.center - dir * self.radius + t * p.x + b * p.y
    }

    pub fn area(&self) -> f32 {
        PI * self.radius * self.radius
    }
}

/// Sets every directional and environment light's disc to the bounding
/// sphere of the box `bounds` (min, max), a hair larger so that no surface
/// touches the plane photons start from. An empty scene (infinite bounds)
/// gets the unit sphere.
pub fn fit_distant_lights(lights: &mut [Light], (lo, hi): (Vec3, Vec3)) {
    let fitted = if lo.is_finite() && hi.is_finite() && hi.cmpge(lo).all() {
        let radius = 0.5 * (hi - lo).length();
        Disc { center: 0.5 * (lo + hi), radius: (radius * 1.001).max(MIN_DISC_RADIUS) }
    } else {
        Disc::UNIT
    };
    for light in lights {
        if let Light::Directional { disc, .. } | Light::Environment { disc, .. } = light {
            *disc = fitted;
        }
    }
}

/// Smallest disc radius: a scene of one point still gets photons.
const MIN_DISC_RADIUS: f32 = 1e-3;

/// Emissive triangles with uniform `radiance` (W/(m² sr)), emitted on the
/// side of each triangle's winding normal (v1 − v0) × (v2 − v0), or on both
/// sides if `two_sided`.
#[derive(Clone, Debug, PartialEq)]
pub struct EmissiveMesh {
    triangles: Vec<[Vec3; 3]>,
    pub radiance: Rgb,
    pub two_sided: bool,
    /// `cumulative_area[i]`: total area of triangles 0..=i (for picking a
    /// triangle ∝ its area by binary search).
    cumulative_area: Vec<f32>,
}

impl EmissiveMesh {
    /// None if the triangles have no area between them. Zero-area
    /// triangles are kept (they are never picked).
    pub fn new(triangles: Vec<[Vec3; 3]>, radiance: Rgb, two_sided: bool) -> Option<EmissiveMesh> {
        let mut total = 0.0f32;
        let cumulative_area: Vec<f32> = triangles
            .iter()
            .map(|t| {
                total += triangle_area(t);
                total
            })
            .collect();
        (total > 0.0 && total.is_finite()).then_some(EmissiveMesh { triangles, radiance, two_sided, cumulative_area })
    }

    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    pub fn area(&self) -> f32 {
        *self.cumulative_area.last().expect("an emissive mesh has triangles")
    }

    /// Entry i: the total area of triangles 0..=i, as `emit` and
    /// `sample_incident` search it (the GPU's photon tracer searches the
    /// same numbers, so it picks the same triangles).
    pub fn cumulative_areas(&self) -> &[f32] {
        &self.cumulative_area
    }

    /// The same mesh with every vertex mapped by `f`, which must keep areas
    /// (a rigid motion), so the area table stays valid.
    fn map_vertices(&self, f: impl Fn(Vec3) -> Vec3) -> EmissiveMesh {
        EmissiveMesh { triangles: self.triangles.iter().map(|t| t.map(&f)).collect(), ..self.clone() }
    }

    /// A point uniform on the mesh (triangle ∝ area, then uniform on it)
    /// and its unit winding normal. `u.x` picks the triangle and is reused,
    /// rescaled, inside it.
    pub fn sample_point(&self, u: Vec2) -> (Vec3, Vec3) {
        let target = u.x * self.area();
        let i = self.cumulative_area.partition_point(|&c| c <= target).min(self.triangles.len() - 1);
        let start = if i == 0 { 0.0 } else { self.cumulative_area[i - 1] };
        let width = self.cumulative_area[i] - start;
        let ux = if width > 0.0 { ((target - start) / width).clamp(0.0, 1.0) } else { 0.5 };
        let [v0, v1, v2] = self.triangles[i];
        // Uniform on the triangle (pbrt's square-root mapping).
        let s = ux.sqrt();
        let (b1, b2) = (s * (1.0 - u.y), s * u.y);
        let point = v0 * (1.0 - b1 - b2) + v1 * b1 + v2 * b2;
        (point, (v1 - v0).cross(v2 - v0).normalize_or_zero())
    }

    /// Area density of `sample_point` converted to solid angle at `point`
    /// for a light point `to_light` away with unit normal `normal`; 0 where
    /// the light emits nothing (its back, unless two-sided).
    pub fn solid_angle_pdf(&self, to_light: Vec3, normal: Vec3) -> f32 {
        let d2 = to_light.length_squared();
        let cos_l = -to_light.dot(normal) / d2.sqrt();
        let cos_l = if self.two_sided { cos_l.abs() } else { cos_l };
        if cos_l > 0.0 && d2 > 0.0 { d2 / (self.area() * cos_l) } else { 0.0 }
    }

    fn emits_toward(&self, dir: Vec3, normal: Vec3) -> bool {
        self.two_sided || dir.dot(normal) < 0.0
    }
}

fn triangle_area([v0, v1, v2]: &[Vec3; 3]) -> f32 {
    0.5 * (*v1 - *v0).cross(*v2 - *v0).length()
}

/// Light arriving at a point from one sampled direction.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the point toward the light.
    pub wi: Vec3,
    /// Distance to the sampled light point (for the shadow ray); for
    /// distant lights, to the disc their photons start from (`Disc::reach`).
    pub distance: f32,
    /// Incident radiance for area lights and the sky; I·falloff/d² for
    /// point and spot lights; the irradiance E for a sun.
    pub radiance: Rgb,
    /// Solid-angle density of `wi`; 1 for delta lights.
    pub pdf: f32,
    pub is_delta: bool,
}

/// A photon leaving a light: start point, unit direction, and the factor
/// (mean 1 over emissions) its power is scaled by where the light's
/// direction sampling is not proportional to its radiance in every
/// channel (an environment map's colours); 1 elsewhere.
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    pub origin: Vec3,
    pub dir: Vec3,
    pub weight: Rgb,
    /// The unit normal of the emitting face at `origin` (area lights;
    /// `dir` lies on its side); zero for the others.
    pub normal: Vec3,
}

impl Light {
    /// Total emitted power Φ in watts per channel.
    pub fn power(&self) -> Rgb {
        match *self {
            Light::Point { intensity, .. } => 4.0 * PI * intensity,
            Light::Spot { intensity, cutoff, falloff_start, .. } => intensity * spot_solid_angle(cutoff, falloff_start),
            Light::Sphere { radius, radiance, .. } => radiance * PI * (4.0 * PI * radius * radius),
            Light::Quad { edge_u, edge_v, radiance, .. } => radiance * PI * edge_u.cross(edge_v).length(),
            // Every photon crosses the disc along `direction`: E per unit area.
            Light::Directional { irradiance, disc, .. } => irradiance * disc.area(),
            // Radiance L from all directions: through a disc of area A facing
            // ω, the solid angle dω carries L·A·dω, so Φ = L·A·4π. Photons
            // with ω uniform (density 1/4π) and origins uniform on the disc
            // then arrive at any point the discs cover with L per unit
            // perpendicular area and solid angle: the sky, seen from inside.
            Light::Environment { radiance, disc, ref map } => match map {
                Some(map) => radiance * map.integral() * disc.area(),
                None => radiance * 4.0 * PI * disc.area(),
            },
            // Lambertian: π·L per unit area, per emitting side.
            Light::Mesh(ref mesh) => mesh.radiance * PI * mesh.area() * if mesh.two_sided { 2.0 } else { 1.0 },
        }
    }

    /// Point and spot lights and the sun: a single direction reaches each
    /// point, so BSDF sampling never finds them and direct light takes one
    /// sample of them.
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. })
    }

    /// The disc a distant light's photons start from; None for local lights.
    pub fn distant_disc(&self) -> Option<Disc> {
        match *self {
            Light::Directional { disc, .. } | Light::Environment { disc, .. } => Some(disc),
            _ => None,
        }
    }

    /// The point that places the light: position (point, spot), centre
    /// (sphere), corner (quad) or first vertex (mesh). Moving a light moves
    /// this point. Distant lights have no place: their disc's centre, which
    /// does not move (`with_anchor` leaves them as they are).
    pub fn anchor(&self) -> Vec3 {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => position,
            Light::Sphere { center, .. } => center,
            Light::Quad { corner, .. } => corner,
            Light::Directional { disc, .. } | Light::Environment { disc, .. } => disc.center,
            Light::Mesh(ref mesh) => mesh.triangles[0][0],
        }
    }

    /// Where a point or spot light sits; None for every other light (the
    /// sun is a delta light without a position).
    pub fn delta_position(&self) -> Option<Vec3> {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(position),
            _ => None,
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
            Light::Directional { .. } | Light::Environment { .. } => {}
            Light::Mesh(mesh) => {
                let shift = anchor - mesh.triangles[0][0];
                *mesh = Arc::new(mesh.map_vertices(|v| v + shift));
            }
        }
        light
    }

    /// Intensity (point, spot; W/sr), radiance (area lights, mesh, sky;
    /// W/(m² sr)) or irradiance (sun; W/m²).
    pub fn emission(&self) -> Rgb {
        match *self {
            Light::Point { intensity, .. } | Light::Spot { intensity, .. } => intensity,
            Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } | Light::Environment { radiance, .. } => {
                radiance
            }
            Light::Directional { irradiance, .. } => irradiance,
            Light::Mesh(ref mesh) => mesh.radiance,
        }
    }

    /// The same light emitting `emission` (see `emission`).
    pub fn with_emission(&self, emission: Rgb) -> Light {
        let mut light = self.clone();
        match &mut light {
            Light::Point { intensity, .. } | Light::Spot { intensity, .. } => *intensity = emission,
            Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } | Light::Environment { radiance, .. } => {
                *radiance = emission
            }
            Light::Directional { irradiance, .. } => *irradiance = emission,
            Light::Mesh(mesh) => *mesh = Arc::new(EmissiveMesh { radiance: emission, ..(**mesh).clone() }),
        }
        light
    }

    /// The light carried by the rigid motion `motion` (rotation and
    /// translation): its anchor moved, its axis, edges or triangles turned;
    /// a sun's direction turned; the sky unchanged (its disc is refitted
    /// with the posed scene's bounds).
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
            Light::Directional { direction, irradiance, disc } => {
                Light::Directional { direction: vector(direction).normalize(), irradiance, disc }
            }
            light @ Light::Environment { .. } => light,
            Light::Mesh(mesh) => Light::Mesh(Arc::new(mesh.map_vertices(point))),
        }
    }

    /// Area lights (sphere, quad, mesh) have geometry in the scene; point,
    /// spot and distant lights do not.
    pub fn is_area(&self) -> bool {
        matches!(self, Light::Sphere { .. } | Light::Quad { .. } | Light::Mesh(_))
    }

    /// Samples a photon's start, distributed as the light's emission
    /// (METHOD.md §2), so every photon of a light carries the same power.
    pub fn emit(&self, rng: &mut Rng) -> EmittedRay {
        match *self {
            Light::Point { position, .. } => EmittedRay {
                origin: position,
                dir: sampling::uniform_sphere(rng.next_2d()),
                weight: Rgb::ONE,
                normal: Vec3::ZERO,
            },
            Light::Spot { position, axis, cutoff, falloff_start, .. } => {
                let local = sample_spot_direction(cutoff, falloff_start, rng);
                EmittedRay { origin: position, dir: local_to_world(local, axis), weight: Rgb::ONE, normal: Vec3::ZERO }
            }
            Light::Sphere { center, radius, .. } => {
                let n = sampling::uniform_sphere(rng.next_2d());
                let dir = local_to_world(sampling::cosine_hemisphere(rng.next_2d()), n);
                EmittedRay { origin: center + n * radius, dir, weight: Rgb::ONE, normal: n }
            }
            Light::Quad { corner, edge_u, edge_v, .. } => {
                let u = rng.next_2d();
                let n = edge_u.cross(edge_v).normalize();
                let dir = local_to_world(sampling::cosine_hemisphere(rng.next_2d()), n);
                EmittedRay { origin: corner + edge_u * u.x + edge_v * u.y, dir, weight: Rgb::ONE, normal: n }
            }
            Light::Directional { direction, disc, .. } => EmittedRay {
                origin: disc.emission_origin(direction, rng.next_2d()),
                dir: direction,
                weight: Rgb::ONE,
                normal: Vec3::ZERO,
            },
            Light::Environment { disc, map: None, .. } => {
                let dir = sampling::uniform_sphere(rng.next_2d());
                EmittedRay {
                    origin: disc.emission_origin(dir, rng.next_2d()),
                    dir,
                    weight: Rgb::ONE,
                    normal: Vec3::ZERO,
                }
            }
            // From the map's sky direction ω, drawn ∝ luminance: the photon
            // travels along −ω, its power scaled by L(ω)/(p(ω)·∫L dω) per
            // channel (1 for a grey map).
            Light::Environment { disc, map: Some(ref map), .. } => {
                let Some(s) = map.sample(rng.next_2d()) else {
                    return EmittedRay { origin: disc.center, dir: Vec3::Y, weight: Rgb::ZERO, normal: Vec3::ZERO };
                };
                let dir = -s.dir;
                let integral = map.integral();
                let weight = Rgb::select(
                    integral.cmpgt(Rgb::ZERO),
                    s.radiance / (s.pdf * integral.max(Rgb::splat(f32::MIN_POSITIVE))),
                    Rgb::ZERO,
                );
                EmittedRay { origin: disc.emission_origin(dir, rng.next_2d()), dir, weight, normal: Vec3::ZERO }
            }
            Light::Mesh(ref mesh) => {
                let (origin, n) = mesh.sample_point(rng.next_2d());
                // Two-sided: either face, each with half the power.
                let n = if mesh.two_sided && rng.next_f32() < 0.5 { -n } else { n };
                EmittedRay {
                    origin,
                    dir: local_to_world(sampling::cosine_hemisphere(rng.next_2d()), n),
                    weight: Rgb::ONE,
                    normal: n,
                }
            }
        }
    }

    /// The fraction of its intensity a spot light sends toward `point`
    /// (Mitsuba's falloff; 0 outside its cone); 1 for any other light.
    pub fn falloff_toward(&self, point: Vec3) -> f32 {
        let Light::Spot { position, axis, cutoff, falloff_start, .. } = *self else { return 1.0 };
        let to_point = (point - position).normalize_or_zero();
        spot_falloff(to_point.dot(axis).clamp(-1.0, 1.0).acos(), cutoff, falloff_start)
    }

    /// Samples light arriving at `point`. None if this sample carries nothing.
    pub fn sample_incident(&self, point: Vec3, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Point { position, intensity } => delta_sample(point, position, intensity),
            Light::Spot { position, intensity, .. } => {
                let f = self.falloff_toward(point);
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
            Light::Directional { direction, irradiance, disc } => {
                let wi = -direction;
                if !disc.covers(point, wi) {
                    return None;
                }
                Some(LightSample {
                    wi,
                    distance: disc.reach(point, wi),
                    radiance: irradiance,
                    pdf: 1.0,
                    is_delta: true,
                })
            }
            // Uniform over the sphere: this does not know the surface's
            // normal, so the half of the samples below a surface's horizon
            // carry nothing there (the path tracer's MIS with cosine
            // sampling makes up for it).
            Light::Environment { radiance, disc, ref map } => {
                let (wi, radiance, pdf) = match map {
                    None => (sampling::uniform_sphere(u), radiance, sampling::UNIFORM_SPHERE_PDF),
                    Some(map) => {
                        let s = map.sample(u)?;
                        (s.dir, radiance * s.radiance, s.pdf)
                    }
                };
                if !disc.covers(point, wi) {
                    return None;
                }
                let distance = disc.reach(point, wi);
                Some(LightSample { wi, distance, radiance, pdf, is_delta: false })
            }
            Light::Mesh(ref mesh) => {
                let (p, normal) = mesh.sample_point(u);
                let to_light = p - point;
                let pdf = mesh.solid_angle_pdf(to_light, normal);
                let distance = to_light.length();
                if pdf <= 0.0 || !pdf.is_finite() {
                    return None;
                }
                Some(LightSample { wi: to_light / distance, distance, radiance: mesh.radiance, pdf, is_delta: false })
            }
        }
    }

    /// Solid-angle density with which `sample_incident` at `point` would pick
    /// direction `wi` that hits this (area) light at `hit_point` with normal
    /// `hit_normal`. Used for MIS when a BSDF-sampled ray hits the light.
    /// For the sky, a ray that escapes along `wi`: any `hit_point` along it.
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
            Light::Environment { map: None, .. } => sampling::UNIFORM_SPHERE_PDF,
            Light::Environment { map: Some(ref map), .. } => map.pdf((hit_point - point).normalize()),
            Light::Mesh(ref mesh) => mesh.solid_angle_pdf(hit_point - point, hit_normal),
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } => 0.0,
        }
    }

    /// Radiance leaving an area light's surface at a point with geometric
    /// normal `normal`, seen along `dir` (propagation direction of the eye ray).
    pub fn emitted_radiance(&self, dir: Vec3, normal: Vec3) -> Rgb {
        match *self {
            Light::Sphere { radiance, .. } if dir.dot(normal) < 0.0 => radiance,
            Light::Quad { edge_u, edge_v, radiance, .. } if dir.dot(edge_u.cross(edge_v)) < 0.0 => radiance,
            Light::Mesh(ref mesh) if mesh.emits_toward(dir, normal) => mesh.radiance,
            _ => Rgb::ZERO,
        }
    }

    /// Radiance reaching the origin of a ray that leaves the scene along
    /// `dir` (hits nothing): the sky's; zero for every other light.
    pub fn escaped_radiance(&self, dir: Vec3) -> Rgb {
        match *self {
            Light::Environment { radiance, map: None, .. } => radiance,
            Light::Environment { radiance, map: Some(ref map), .. } => radiance * map.radiance(dir),
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
pub fn cone_pdf(sin2_max: f32, cos_max: f32) -> f32 {
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

    /// The unit square at height 1 facing down (−y), as a quad light and as
    /// an emissive mesh of the two triangles the loader makes of a quad.
    fn square(two_sided: bool) -> (Light, Light) {
        let (corner, edge_u, edge_v) = (Vec3::new(-0.5, 1.0, -0.5), Vec3::X, Vec3::Z);
        let quad = Light::Quad { corner, edge_u, edge_v, radiance: Vec3::ONE };
        let triangles = vec![
            [corner, corner + edge_u, corner + edge_u + edge_v],
            [corner, corner + edge_u + edge_v, corner + edge_v],
        ];
        (quad, Light::Mesh(Arc::new(EmissiveMesh::new(triangles, Vec3::ONE, two_sided).unwrap())))
    }

    #[test]
    fn mesh_incident_pdf_agrees_with_sampling_and_the_quad() {
        let (quad, mesh) = square(false);
        assert_eq!(mesh.power(), quad.power());
        let mut rng = Rng::for_item(21, 0);
        let (mut e_quad, mut e_mesh) = (0.0f64, 0.0f64);
        let n = 200_000;
        for _ in 0..n {
            let s = mesh.sample_incident(Vec3::ZERO, rng.next_2d()).unwrap();
            let hit = s.wi * s.distance;
            assert!((hit.y - 1.0).abs() < 1e-5 && hit.x.abs() <= 0.5 + 1e-5 && hit.z.abs() <= 0.5 + 1e-5, "{hit}");
            // The geometric normal of the hit triangle is the winding normal, −y.
            let pdf = mesh.incident_pdf(Vec3::ZERO, hit, Vec3::NEG_Y);
            assert!((pdf - s.pdf).abs() <= 1e-4 * s.pdf, "{pdf} vs {}", s.pdf);
            e_mesh += (s.radiance.x * s.wi.y / s.pdf) as f64;
            let s = quad.sample_incident(Vec3::ZERO, rng.next_2d()).unwrap();
            e_quad += (s.radiance.x * s.wi.y / s.pdf) as f64;
        }
        // The same irradiance as the quad (≈ 1.36; both ±0.002).
        let (e_mesh, e_quad) = (e_mesh / n as f64, e_quad / n as f64);
        assert!((e_mesh - e_quad).abs() < 0.006, "mesh {e_mesh} vs quad {e_quad}");
        // From above, the back: nothing unless two-sided.
        let above = Vec3::new(0.1, 2.0, 0.2);
        assert!(mesh.sample_incident(above, Vec2::new(0.3, 0.6)).is_none());
        assert_eq!(mesh.incident_pdf(above, Vec3::new(0.0, 1.0, 0.0), Vec3::NEG_Y), 0.0);
        // An eye ray going up sees the front; one going down, the back.
        assert_eq!(mesh.emitted_radiance(Vec3::Y, Vec3::NEG_Y), Vec3::ONE);
        assert_eq!(mesh.emitted_radiance(Vec3::NEG_Y, Vec3::NEG_Y), Vec3::ZERO);
        let (_, both) = square(true);
        assert_eq!(both.power(), 2.0 * quad.power());
        let s = both.sample_incident(above, Vec2::new(0.3, 0.6)).unwrap();
        let pdf = both.incident_pdf(above, above + s.wi * s.distance, Vec3::NEG_Y);
        assert!(s.wi.y < 0.0 && (pdf - s.pdf).abs() <= 1e-4 * s.pdf);
        assert_eq!(both.emitted_radiance(Vec3::NEG_Y, Vec3::NEG_Y), Vec3::ONE);
    }

    /// Photons leave an emissive mesh uniformly over its area (triangles of
    /// very different sizes) and cosine-distributed about the front normal,
    /// or about either normal, half each, when it is two-sided.
    #[test]
    fn mesh_photons_are_uniform_in_area_and_cosine_in_direction() {
        // Areas 0.5 and 0.02, both facing +z.
        let triangles = vec![
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.2, 0.0, 0.0), Vec3::new(2.0, 0.2, 0.0)],
        ];
        for two_sided in [false, true] {
            let light = Light::Mesh(Arc::new(EmissiveMesh::new(triangles.clone(), Vec3::ONE, two_sided).unwrap()));
            let rng = std::cell::RefCell::new(Rng::for_item(4, two_sided as u64));
            let (n, mut small, mut inside) = (100_000, 0, 0);
            for _ in 0..n {
                let EmittedRay { origin: p, .. } = light.emit(&mut rng.borrow_mut());
                small += (p.x >= 2.0) as u32;
                // Uniform over the big triangle: its lower-left half (x + y ≤ ½) holds ¼ of its area.
                inside += (p.x < 2.0 && p.x + p.y <= 0.5) as u32;
            }
            let expected = 0.02 / 0.52 * n as f64;
            assert!((small as f64 - expected).abs() < 5.0 * expected.sqrt(), "{small} vs {expected}");
            let expected = 0.25 * 0.5 / 0.52 * n as f64;
            assert!((inside as f64 - expected).abs() < 5.0 * expected.sqrt(), "{inside} vs {expected}");
            let pdf = move |w: Vec3| if two_sided { w.z.abs() / (2.0 * PI) } else { w.z.max(0.0) / PI };
            assert_direction_distribution(|_| light.emit(&mut rng.borrow_mut()).dir, pdf);
        }
        assert!(EmissiveMesh::new(vec![[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]], Vec3::ONE, false).is_none());
    }

    #[test]
    fn moving_and_editing_a_mesh_light_moves_every_triangle() {
        let (_, mesh) = square(false);
        let moved = mesh.with_anchor(Vec3::new(1.0, 2.0, 3.0));
        let Light::Mesh(m) = &moved else { unreachable!() };
        assert_eq!(m.triangles()[0][0], Vec3::new(1.0, 2.0, 3.0));
        assert!((m.triangles()[1][2] - Vec3::new(1.0, 2.0, 4.0)).length() < 1e-6);
        let turned = mesh.moved(&glam::Affine3A::from_rotation_x(PI));
        // Turned upside down, it faces up: a point above now receives light.
        assert!(turned.sample_incident(Vec3::new(0.0, 0.0, 0.0), Vec2::splat(0.5)).is_some());
        assert_eq!(mesh.with_emission(Vec3::splat(2.0)).power(), 2.0 * mesh.power());
    }

    /// A fitted disc holds the whole box; its photons start on the plane
    /// one radius upstream of the centre, within the radius, uniformly
    /// (half of them within r/√2).
    #[test]
    fn distant_lights_emit_across_the_fitted_disc() {
        let direction = Vec3::new(1.0, -2.0, 0.5).normalize();
        let mut lights = [
            Light::Directional { direction, irradiance: Vec3::ONE, disc: Disc::UNIT },
            Light::Environment { radiance: Vec3::ONE, disc: Disc::UNIT, map: None },
        ];
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 2.5));
        fit_distant_lights(&mut lights, (lo, hi));
        let disc = lights[0].distant_disc().unwrap();
        assert_eq!(Some(disc), lights[1].distant_disc());
        for corner in [lo, hi, Vec3::new(lo.x, hi.y, lo.z), Vec3::new(hi.x, lo.y, hi.z)] {
            assert!((corner - disc.center).length() < disc.radius);
            // A shadow ray from there reaches past every surface to the disc.
            assert!(disc.reach(corner, -direction) > 0.0);
        }
        let mut rng = Rng::for_item(8, 0);
        let n = 20_000;
        let mut near = 0;
        for _ in 0..n {
            let ray = lights[0].emit(&mut rng);
            assert_eq!(ray.dir, direction);
            let from_centre = ray.origin - disc.center;
            assert!((from_centre.dot(direction) + disc.radius).abs() < 1e-4 * disc.radius);
            let off_axis = (from_centre - from_centre.dot(direction) * direction).length();
            assert!(off_axis <= disc.radius * (1.0 + 1e-5));
            near += (off_axis < disc.radius / 2f32.sqrt()) as u32;
        }
        assert!((near as f32 / n as f32 - 0.5).abs() < 0.02, "{near} of {n}");
        // The sky's photons start on the disc facing their own direction.
        for _ in 0..100 {
            let ray = lights[1].emit(&mut rng);
            assert!(((ray.origin - disc.center).dot(ray.dir) + disc.radius).abs() < 1e-4 * disc.radius);
        }
        // No geometry: the unit sphere.
        fit_distant_lights(&mut lights, (Vec3::INFINITY, Vec3::NEG_INFINITY));
        assert_eq!(lights[0].distant_disc(), Some(Disc::UNIT));
    }

    #[test]
    fn the_sky_is_sampled_uniformly_and_the_sun_along_its_direction() {
        let disc = Disc { center: Vec3::ZERO, radius: 10.0 };
        let sky = Light::Environment { radiance: Vec3::splat(2.0), disc, map: None };
        assert_direction_distribution(|u| sky.sample_incident(Vec3::ONE, u).unwrap().wi, |_| 1.0 / (4.0 * PI));
        let s = sky.sample_incident(Vec3::ONE, Vec2::new(0.2, 0.7)).unwrap();
        assert!(!s.is_delta && s.radiance == Vec3::splat(2.0));
        assert_eq!(s.pdf, sky.incident_pdf(Vec3::ONE, Vec3::ONE + s.wi * 3.0, s.wi));
        // The shadow ray ends on the disc's plane, upstream of the centre.
        assert!(((Vec3::ONE + s.wi * s.distance).dot(s.wi) - 10.0).abs() < 1e-4);
        assert_eq!(sky.escaped_radiance(Vec3::X), Vec3::splat(2.0));
        let sun = Light::Directional { direction: Vec3::NEG_Y, irradiance: Vec3::splat(3.0), disc };
        let s = sun.sample_incident(Vec3::ZERO, Vec2::ZERO).unwrap();
        assert!(s.is_delta && s.wi == Vec3::Y && s.distance == 10.0 && s.radiance == Vec3::splat(3.0));
        assert_eq!(sun.escaped_radiance(Vec3::Y), Vec3::ZERO);
        assert!(sun.delta_position().is_none() && sun.is_delta() && !sun.is_area());
        let turned = sun.moved(&glam::Affine3A::from_rotation_z(PI / 2.0));
        let Light::Directional { direction, .. } = turned else { unreachable!() };
        assert!((direction - Vec3::X).length() < 1e-6);
    }
}
