//! `photon-cpu`: the seed's pipeline on the CPU and the CPU twin of the GPU
//! renderer. Primary rays; mirror and glass followed recursively (Whitted) to
//! the first diffuse hit; there, direct light by shadow rays, indirect light
//! from the global map and caustics from the caustic map, both with the
//! fixed-radius estimate of `crate::estimate`. Rays that leave the scene
//! (from the eye or a mirror or glass) see the sky; emissive surfaces seen
//! add their light to what their material reflects.

use super::{Image, LitSides, direct_diffuse, direct_reflected, direct_scattered, render_pixels};
use crate::bsdf::ShadingFrame;
use crate::bsdf::bump::BumpShadow;
use crate::bsdf::dielectric::Transport;
use crate::estimate::{FixedRadius, fixed_radius_radiance, fixed_radius_radiance_brdf, is_bent, shading_normal_factor};
use crate::geometry::Ray;
use crate::material::{Material, Rgb, reflect};
use crate::medium::MediaAlong;
use crate::photon::{PhotonMap, TracedPhotons, VolumePhotonMap};
use crate::progress::Progress;
use crate::sampling::Rng;
use crate::scene::Scene;

/// Which parts of the light at diffuse points to include (all by default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Components {
    pub direct: bool,
    pub indirect: bool,
    pub caustic: bool,
    /// In-scattered light from the volume map (scenes with a medium).
    pub volume: bool,
}

impl Components {
    pub const ALL: Components = Components { direct: true, indirect: true, caustic: true, volume: true };
}

#[derive(Clone, Debug)]
pub struct PhotonCpuSettings {
    /// Global-map radius r; None: `default_radius`.
    pub radius: Option<f32>,
    /// Caustic-map radius; None: `default_caustic_radius`.
    pub caustic_radius: Option<f32>,
    /// Volume-map radius; None: `default_radius`.
    pub volume_radius: Option<f32>,
    pub spp: u32,
    pub seed: u64,
    /// Shadow-ray samples per area light and sky at each shaded point.
    pub area_light_samples: u32,
    /// Mirror/glass bounces followed from the eye before giving up.
    pub max_specular_depth: u32,
    /// See `FixedRadius::normal_test`.
    pub normal_test: bool,
    pub components: Components,
}

impl Default for PhotonCpuSettings {
    fn default() -> Self {
        PhotonCpuSettings {
            radius: None,
            caustic_radius: None,
            volume_radius: None,
            spp: 4,
            seed: 0,
            area_light_samples: 4,
            max_specular_depth: 8,
            // Off, as in the seed. Measured on cornell-box (64×64, 1M photons,
            // against a 1024-spp path tracer): with the test the image is
            // 1.1–1.2% dark at every radius from 0.025 to 0.104, because near
            // edges it drops the neighbouring wall's photons that otherwise
            // make up for the part of the disc beyond the surface; without
            // it the difference is −0.5%, 0.0%, +1.1% and shrinks with r.
            normal_test: false,
            components: Components::ALL,
        }
    }
}

impl PhotonCpuSettings {
    /// The global-map and caustic-map estimates these settings ask for in
    /// `scene` (defaults filled in): what the GPU renderer uses too.
    pub fn estimate_params(&self, scene: &Scene) -> (FixedRadius, FixedRadius) {
        let global =
            FixedRadius { radius: self.radius.unwrap_or_else(|| default_radius(scene)), normal_test: self.normal_test };
        let caustic = FixedRadius {
            radius: self.caustic_radius.unwrap_or_else(|| default_caustic_radius(scene)),
            normal_test: self.normal_test,
        };
        (global, caustic)
    }
}

/// Default global radius: 3% of the scene's bounding-box diagonal.
pub fn default_radius(scene: &Scene) -> f32 {
    0.03 * scene.diagonal()
}

/// Default caustic radius: 1% of the diagonal (caustic photons are dense).
pub fn default_caustic_radius(scene: &Scene) -> f32 {
    0.01 * scene.diagonal()
}

pub struct PhotonCpuRenderer<'a> {
    scene: &'a Scene,
    /// Indirect-class photons only: what the global-map estimate shows.
    global: PhotonMap,
    caustic: PhotonMap,
    volume: VolumePhotonMap,
    pub volume_radius: f32,
    pub global_params: FixedRadius,
    pub caustic_params: FixedRadius,
    settings: PhotonCpuSettings,
}

impl<'a> PhotonCpuRenderer<'a> {
    pub fn new(scene: &'a Scene, traced: &TracedPhotons, settings: &PhotonCpuSettings) -> Self {
        let (global_params, caustic_params) = settings.estimate_params(scene);
        let volume_radius = settings.volume_radius.unwrap_or_else(|| default_radius(scene));
        PhotonCpuRenderer {
            scene,
            global: PhotonMap::new(traced.indirect(), traced.power_unit),
            caustic: PhotonMap::new(traced.caustic.clone(), traced.power_unit),
            volume: VolumePhotonMap::new(traced.volume.clone(), traced.power_unit, volume_radius),
            volume_radius,
            global_params,
            caustic_params,
            settings: settings.clone(),
        }
    }

    pub fn global_map(&self) -> &PhotonMap {
        &self.global
    }

    pub fn caustic_map(&self) -> &PhotonMap {
        &self.caustic
    }

    pub fn volume_map(&self) -> &VolumePhotonMap {
        &self.volume
    }

    /// The photon-map part of the light leaving a diffuse point: indirect
    /// (global map) plus caustics (caustic map), per the enabled components.
    /// The photon-map part of the light a Lambertian surface of `albedo`
    /// reflects, shading with `normal` where its geometric normal is `ng`
    /// (where the two differ, smooth-shaded and normal-mapped meshes, each
    /// photon weighs `estimate::shading_normal_factor`).
    pub fn photon_radiance(&self, x: glam::Vec3, normal: glam::Vec3, ng: glam::Vec3, albedo: Rgb) -> Rgb {
        if is_bent(normal, ng) {
            let frame = ShadingFrame::new(normal);
            let lambert = albedo / std::f32::consts::PI;
            return self.photon_radiance_brdf(x, &frame, ng, |wi| if wi.z > 0.0 { lambert } else { Rgb::ZERO });
        }
        let c = self.settings.components;
        let mut l = Rgb::ZERO;
        if c.indirect {
            l += fixed_radius_radiance(&self.global, None, x, normal, albedo, &self.global_params);
        }
        if c.caustic {
            l += fixed_radius_radiance(&self.caustic, None, x, normal, albedo, &self.caustic_params);
        }
        l
    }

    /// The photon-map part of the light a `Pbr` surface reflects toward
    /// `wo` (local frame `frame`, on a surface of geometric normal `ng`):
    /// each photon weighted by `brdf` for its own direction (the whole BRDF
    /// where the photon maps stand for it, else the diffuse lobe), and by
    /// `estimate::shading_normal_factor` where the normals differ.
    fn photon_radiance_brdf(
        &self,
        x: glam::Vec3,
        frame: &ShadingFrame,
        ng: glam::Vec3,
        brdf: impl Fn(glam::Vec3) -> Rgb,
    ) -> Rgb {
        let c = self.settings.components;
        let bent = is_bent(frame.normal, ng);
        let f = |wi: glam::Vec3| {
            let f = brdf(frame.to_local(wi));
            if bent { f * shading_normal_factor(wi, frame.normal, ng) } else { f }
        };
        let mut l = Rgb::ZERO;
        if c.indirect {
            l += fixed_radius_radiance_brdf(&self.global, x, frame.normal, &self.global_params, f);
        }
        if c.caustic {
            l += fixed_radius_radiance_brdf(&self.caustic, x, frame.normal, &self.caustic_params, f);
        }
        l
    }

    /// Radiance arriving along `ray`, with `depth` specular bounces so far:
    /// the surface's, attenuated by the medium, plus in-scattered light.
    pub fn radiance(&self, ray: &Ray, depth: u32, rng: &mut Rng) -> Rgb {
        self.radiance_seen(ray, depth, true, rng)
    }

    /// [`Self::radiance`], counting the light that emitters (and the sky)
    /// send straight along `ray` only if `with_emission`: a ray following a
    /// glossy lobe leaves it out, since the shadow rays at its start already
    /// counted direct light through that lobe.
    fn radiance_seen(&self, ray: &Ray, depth: u32, with_emission: bool, rng: &mut Rng) -> Rgb {
        let hit = self.scene.accel.intersect(ray);
        // Direct light at diffuse points comes from shadow rays, so only
        // these specular or eye rays see the sky itself.
        let surface = match hit {
            None if with_emission => self.scene.escaped_radiance(ray.dir),
            None => Rgb::ZERO,
            Some(h) => self.surface_radiance(ray, &h, depth, with_emission, rng),
        };
        let media = &self.scene.media;
        if media.is_empty() {
            return surface;
        }
        let escape = self.scene.escape_distance(ray.origin, ray.dir);
        let length = hit.map_or_else(|| if escape.is_finite() { escape } else { self.scene.diagonal() * 2.0 }, |h| h.t);
        let along = MediaAlong::new(media, ray.origin, ray.dir, length);
        let volume = if self.settings.components.volume {
            crate::estimate::volume_radiance_along(&self.volume, media.phases(), ray.origin, ray.dir, length, |s| {
                along.transmittance(s)
            })
        } else {
            Rgb::ZERO
        };
        along.transmittance(length) * surface + volume
    }

    /// Radiance leaving the surface at `hit` toward the ray's origin:
    /// emitted, plus reflected unless the surface is a light's black body.
    fn surface_radiance(
        &self,
        ray: &Ray,
        hit: &crate::geometry::Hit,
        depth: u32,
        with_emission: bool,
        rng: &mut Rng,
    ) -> Rgb {
        let emitted = match self.scene.emitted_radiance(hit, ray.dir) {
            Some(le) if with_emission => le,
            _ => Rgb::ZERO,
        };
        // The material with its textures, looked up once for this point.
        let material = &*self.scene.material_at(hit);
        if matches!(material, Material::Emitter) {
            return emitted;
        }
        emitted + self.reflected_radiance(ray, hit, &material, depth, rng)
    }

    /// Radiance the surface at `hit` reflects toward the ray's origin.
    fn reflected_radiance(
        &self,
        ray: &Ray,
        hit: &crate::geometry::Hit,
        material: &Material,
        depth: u32,
        rng: &mut Rng,
    ) -> Rgb {
        let smooth = hit.shading_normal;
        let hit = self.scene.bent(*hit, ray.dir);
        let can_recurse = depth < self.settings.max_specular_depth;
        let facing = if ray.dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
        let (ns, ng) = (hit.shading_normal * facing, hit.geometric_normal * facing);
        match material {
            Material::Glass(glass) => {
                // Arriving from inside: what the glass absorbed on the way.
                let absorbed = glass.interior_transmittance(ray.dir, hit.geometric_normal, hit.t);
                if glass.is_smooth() {
                    if !can_recurse {
                        return Rgb::ZERO;
                    }
                    let (reflected, refracted) =
                        glass.smooth_branches(ray.dir, hit.geometric_normal, Transport::Radiance);
                    let mut l = Rgb::ZERO;
                    for (wi, weight) in std::iter::once(reflected).chain(refracted) {
                        if weight.max_element() > 0.0 {
                            l += weight * self.radiance(&Ray::new(hit.point, wi), depth + 1, rng);
                        }
                    }
                    return absorbed * l;
                }
                // Rough glass: lights on this side by shadow rays through
                // the reflection, and point, spot and sun lights beyond by
                // shadow rays through the transmission (a shadow ray stops
                // at glass, so a light beyond the far side of a glass body is
                // counted where the path leaves it). Then one sampled
                // direction per eye ray: a transmitted one counts the area
                // lights and skies it meets, a reflected one leaves out
                // what its shadow rays counted.
                let frame = ShadingFrame::new(hit.geometric_normal);
                let wo = frame.to_local(-ray.dir);
                let mut l = Rgb::ZERO;
                if self.settings.components.direct {
                    let f = |wi: glam::Vec3| glass.f(wo, frame.to_local(wi), Transport::Radiance);
                    let samples = self.settings.area_light_samples;
                    l += direct_scattered(self.scene, hit.point, ng, LitSides::FrontAndDeltaBehind, f, samples, rng);
                }
                if can_recurse {
                    let u_lobe = rng.next_f32();
                    if let Some(s) = glass.sample(wo, u_lobe, rng.next_2d(), Transport::Radiance) {
                        let next = Ray::new(hit.point, frame.to_world(s.wi));
                        l += s.weight * self.radiance_seen(&next, depth + 1, s.transmitted, rng);
                    }
                }
                absorbed * l
            }
            Material::Emitter => Rgb::ZERO,
            Material::Pbr(bsdf) => {
                let frame = ShadingFrame::new(ns);
                let tilted = self.scene.coat_tilted(bsdf, &hit, smooth, ray.dir, &frame);
                let bsdf = tilted.as_ref().unwrap_or(bsdf);
                let wo = frame.to_local(-ray.dir);
                // A normal-mapped point's diffuse lobes: Cycles' bump
                // shadowing of the light's direction (`wi` local here).
                let bump = (smooth != hit.shading_normal)
                    .then(|| BumpShadow::new(frame.to_local(smooth * facing), glam::Vec3::Z))
                    .flatten();
                let k = |wi: glam::Vec3| bump.map_or(1.0, |b| b.term(wi));
                // The lobes the photon maps stand for: the diffuse one and
                // every lobe at least GATHER_ROUGHNESS rough.
                let part = |wi: glam::Vec3| bsdf.f_gathered_bumped(wo, wi, k(wi));
                let mut l = Rgb::ZERO;
                if self.settings.components.direct {
                    // Direct light through every non-delta lobe, by shadow rays.
                    let f = |wi: glam::Vec3| {
                        let wi = frame.to_local(wi);
                        bsdf.f_bumped(wo, wi, k(wi))
                    };
                    l += direct_reflected(self.scene, hit.point, ns, ng, f, self.settings.area_light_samples, rng);
                }
                // Behind a partly transmissive surface (inside its body) no
                // photons are stored (`photon::trace`): one sampled bounce of
                // the whole BRDF shows the light inside, what it sees
                // emitted left to the shadow rays but through a mirror lobe.
                if facing < 0.0 && self.scene.mixes_at(&hit) {
                    if can_recurse && let Some(s) = bsdf.sample(wo, rng.next_f32(), rng.next_2d()) {
                        let s = bsdf.reweigh(wo, s, k(s.wi));
                        let next = Ray::new(hit.point, frame.to_world(s.wi));
                        l += s.weight * self.radiance_seen(&next, depth + 1, s.is_delta, rng);
                    }
                    return l;
                }
                l += self.photon_radiance_brdf(hit.point, &frame, ng, part);
                // A lobe smoother than the gather threshold is followed, one
                // sampled direction per eye ray. A glossy (non-delta) one
                // leaves out what it sees emitted: its shadow rays counted that.
                if bsdf.follows_any()
                    && can_recurse
                    && let Some(s) = bsdf.sample_followed(wo, rng.next_2d())
                {
                    let next = Ray::new(hit.point, frame.to_world(s.wi));
                    l += s.weight * self.radiance_seen(&next, depth + 1, s.is_delta, rng);
                }
                l
            }
            Material::Diffuse { .. } | Material::Mirror { .. } => {
                let mut l = Rgb::ZERO;
                let albedo = material.diffuse_albedo();
                // A normal-mapped exactly Lambertian glTF material: the bump
                // shadowing of the light's direction, as the Pbr arm's.
                let bump = (smooth != hit.shading_normal).then(|| BumpShadow::new(smooth * facing, ns)).flatten();
                if let Some(bump) = bump.filter(|_| albedo.max_element() > 0.0) {
                    let samples = self.settings.area_light_samples;
                    if self.settings.components.direct {
                        let f = |wi: glam::Vec3| albedo / std::f32::consts::PI * bump.term(wi);
                        l += direct_reflected(self.scene, hit.point, ns, ng, f, samples, rng);
                    }
                    let frame = ShadingFrame::new(ns);
                    let f = |wi: glam::Vec3| albedo / std::f32::consts::PI * bump.term(frame.to_world(wi));
                    l += self.photon_radiance_brdf(hit.point, &frame, ng, f);
                } else if albedo.max_element() > 0.0 {
                    if self.settings.components.direct {
                        l += direct_diffuse(
                            self.scene,
                            hit.point,
                            ns,
                            ng,
                            albedo,
                            self.settings.area_light_samples,
                            rng,
                        );
                    }
                    l += self.photon_radiance(hit.point, ns, ng, albedo);
                }
                let rho_s = material.mirror_reflectance();
                if rho_s.max_element() > 0.0 && can_recurse {
                    l += rho_s * self.radiance(&Ray::new(hit.point, reflect(ray.dir, ns)), depth + 1, rng);
                }
                l
            }
        }
    }

    /// Renders the image; returns it and the number of non-finite samples dropped.
    pub fn render(&self, progress: &dyn Progress) -> (Image, u64) {
        render_pixels(&self.scene.camera, self.settings.spp, self.settings.seed, progress, |ray, rng| {
            self.radiance(&ray, 0, rng)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::{TraceSettings, trace_photons};
    use crate::progress::Silent;
    use crate::render::path::tests::{compare, off_emitters};
    use crate::test_scenes::{cornell_quad_light, quad_lights_as_meshes, sky_floor, sunlit_floor};
    use glam::Vec3;
    use std::f32::consts::PI;

    fn render_with(scene: &Scene, photons: u64, seed: u64, settings: PhotonCpuSettings) -> (Image, PhotonCpuSettings) {
        let traced = trace_photons(scene, &TraceSettings { photons, seed, ..Default::default() }, &Silent);
        let settings = PhotonCpuSettings { seed, ..settings };
        let (image, nonfinite) = PhotonCpuRenderer::new(scene, &traced, &settings).render(&Silent);
        assert_eq!(nonfinite, 0);
        (image, settings)
    }

    /// The sun's light on the floor is direct light, by shadow rays:
    /// ρ/π · E cos θ in every pixel (its photons are all direct, or lost to
    /// the sky or the black box), nothing in the box's shadow.
    #[test]
    fn a_sun_lights_a_floor_by_e_cos_theta() {
        let scene = sunlit_floor(30.0, 3.0, 0.5, true);
        let expected = 0.5 / PI * 3.0 * 30f32.to_radians().cos();
        let (image, _) = render_with(&scene, 20_000, 1, PhotonCpuSettings::default());
        for p in &image.pixels {
            assert!((*p - Rgb::splat(expected)).abs().max_element() < 1e-4 * expected, "{p} vs {expected}");
        }
        let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, ..Default::default() }, &Silent);
        let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings::default());
        let shadowed = Vec3::new(1.5 + 0.5 * 30f32.to_radians().tan(), 0.1, 1.5);
        let l = renderer.radiance(&Ray::new(shadowed, Vec3::NEG_Y), 0, &mut Rng::for_item(1, 0));
        assert_eq!(l, Rgb::ZERO);
    }

    /// In absorbing fog the sun's light is attenuated from the disc its
    /// photons leave (one radius r upstream of the floor's centre) to the
    /// floor, and from there to the eye: e^(−σ(r + 1)) for an eye 1 above.
    #[test]
    fn a_sun_through_fog_is_attenuated_from_its_disc() {
        use crate::medium::{Media, Medium, Phase};
        let mut scene = sunlit_floor(30.0, 3.0, 0.5, false);
        let sigma = 0.2;
        let fog = Medium { sigma_a: Vec3::splat(sigma), sigma_s: Vec3::ZERO, phase: Phase::Schlick { k: 0.0 } };
        scene.media = Media::homogeneous(fog);
        let r = scene.lights[0].distant_disc().unwrap().radius;
        let expected = 0.5 / PI * 3.0 * 30f32.to_radians().cos() * (-sigma * (r + 1.0)).exp();
        let traced = trace_photons(&scene, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
        let renderer = PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings::default());
        let l = renderer.radiance(&Ray::new(Vec3::Y, Vec3::NEG_Y), 0, &mut Rng::for_item(1, 0));
        assert!((l - Rgb::splat(expected)).abs().max_element() < 1e-4 * expected, "{l} vs {expected}");
    }

    /// Under a sky of radiance L an open floor of albedo ρ shows ρ·L (direct
    /// light, sampled over the sphere); the eye sees L where it looks at the
    /// sky, and R·L in a mirror floor.
    #[test]
    fn a_sky_lights_an_open_floor_and_shows_in_mirrors() {
        let scene = sky_floor(2.0, "name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]");
        let settings = PhotonCpuSettings { spp: 16, area_light_samples: 16, ..Default::default() };
        let (image, _) = render_with(&scene, 20_000, 1, settings);
        // 65,536 sky samples of standard deviation 1.3·ρL: ±0.5%.
        let mean = image.mean();
        eprintln!("sky floor: {mean}");
        assert!((mean - 1.0).abs() < 0.02, "floor radiance {mean}, expected 1");
        let mirror = sky_floor(2.0, "name = \"floor\"\ntype = \"mirror\"\nreflectance = [0.8, 0.8, 0.8]");
        let traced = trace_photons(&mirror, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
        let renderer = PhotonCpuRenderer::new(&mirror, &traced, &PhotonCpuSettings::default());
        let mut rng = Rng::for_item(1, 0);
        let down = renderer.radiance(&Ray::new(Vec3::new(0.1, 1.0, 0.2), Vec3::NEG_Y), 0, &mut rng);
        assert!((down - Rgb::splat(1.6)).abs().max_element() < 1e-6, "{down}");
        assert_eq!(renderer.radiance(&Ray::new(Vec3::Y, Vec3::Y), 0, &mut rng), Rgb::splat(2.0));
    }

    /// A quad light and the same triangles as an emissive mesh give the same
    /// photon-cpu image of the Cornell box, direct light and photon maps
    /// alike, within the spread of two quad images with different seeds.
    #[test]
    fn an_emissive_mesh_lights_like_the_same_quad_light() {
        let quad = cornell_quad_light(16);
        let mesh = quad_lights_as_meshes(&quad);
        let settings = PhotonCpuSettings { spp: 16, ..Default::default() };
        let (a, _) = render_with(&quad, 300_000, 1, settings.clone());
        let (b, _) = render_with(&quad, 300_000, 2, settings.clone());
        let (m, _) = render_with(&mesh, 300_000, 3, settings);
        // Off the light (the pixels that see it have the noise of its
        // covered fraction, 16 samples each): the same image within noise.
        let mask = off_emitters(&quad);
        let ((noise, mean_a, mean_b), (difference, _, mean_m)) = (compare(&a, &b, &mask), compare(&a, &m, &mask));
        eprintln!(
            "off the light: means quad {mean_a} {mean_b}, mesh {mean_m}; rms quad–quad {noise}, quad–mesh {difference}"
        );
        assert!(difference < 1.5 * noise, "quad–mesh {difference} vs quad–quad {noise}");
        assert!((mean_m / mean_a - 1.0).abs() < 0.025, "mesh {mean_m} vs quad {mean_a}");
        // The light itself, seen from below, and nothing from its back.
        let mut rng = Rng::for_item(1, 0);
        for (scene, seen) in [(&quad, "quad"), (&mesh, "mesh")] {
            let traced = trace_photons(scene, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
            let renderer = PhotonCpuRenderer::new(scene, &traced, &PhotonCpuSettings::default());
            let up = renderer.radiance(&Ray::new(Vec3::new(0.05, 0.5, 0.02), Vec3::Y), 0, &mut rng);
            assert_eq!(up, Rgb::splat(12.0), "{seen}");
        }
    }
}
