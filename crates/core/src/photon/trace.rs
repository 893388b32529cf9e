//! Photon tracing from the lights (METHOD.md §2), parallel and deterministic:
//! photon path `i` draws only from its own random stream `(seed, i)`, and
//! chunks are concatenated in index order, so the maps do not depend on the
//! number of threads.

use super::{PathClass, Photon};
use crate::bsdf::ShadingFrame;
use crate::bsdf::bump::BumpShadow;
use crate::bsdf::dielectric::Transport;
use crate::geometry::Ray;
use crate::material::{Event, Material, Rgb, mean, reflect};
use crate::medium::Flight;
use crate::progress::Progress;
use crate::sampling::{Rng, cosine_hemisphere, local_to_world};
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;

#[derive(Clone, Debug)]
pub struct TraceSettings {
    /// Photon paths emitted from all lights together (n_e).
    pub photons: u64,
    pub seed: u64,
    /// Longest path followed; glass can trap photons by total internal
    /// reflection, so some bound is needed (what it cuts off is counted).
    pub max_bounces: u32,
}

impl Default for TraceSettings {
    fn default() -> Self {
        TraceSettings { photons: 200_000, seed: 0, max_bounces: 64 }
    }
}

/// Counters for the summary and the tests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TraceStats {
    pub emitted: u64,
    /// Total power stored at the k-th diffuse hit of each path (watts), k = 0, 1, ….
    pub stored_flux_per_bounce: Vec<Rgb>,
    /// Paths stopped by `max_bounces` rather than by absorption or escape.
    pub truncated: u64,
}

pub struct TracedPhotons {
    /// Every diffuse hit, flagged with its `PathClass`.
    pub global: Vec<Photon>,
    /// L S+ D photons only.
    pub caustic: Vec<Photon>,
    /// Scattering events in the scene's medium (METHOD.md §5.2), with the
    /// power they scatter.
    pub volume: Vec<Photon>,
    /// Watts per unit of stored photon power (`Photon::power_in_units`).
    pub power_unit: f32,
    pub stats: TraceStats,
}

impl TracedPhotons {
    /// The global map's `Indirect` photons: what the global-map estimate
    /// shows, since direct light and caustics are rendered separately.
    pub fn indirect(&self) -> Vec<Photon> {
        self.global.iter().filter(|p| p.class() == PathClass::Indirect).copied().collect()
    }
}

/// Photons per parallel work item: large enough to amortise scheduling.
const CHUNK: u64 = 4096;

pub fn trace_photons(scene: &Scene, settings: &TraceSettings, progress: &dyn Progress) -> TracedPhotons {
    let n = settings.photons.max(1);
    let probabilities = scene.light_selection_probabilities();
    let total_power: f32 = scene.lights.iter().map(|l| mean(l.power())).sum();
    // Every emitted photon carries Φ_l / (p_l n) = Φ_total / n in the mean channel.
    let power_unit = total_power / n as f32;
    let mixes = scene.texturing.as_ref().is_some_and(|t| t.has_mixes());
    let bumps = scene.texturing.as_ref().is_some_and(|t| t.has_normal_textures());
    let chunks = n.div_ceil(CHUNK);
    progress.begin("tracing photons", n);
    let results: Vec<ChunkResult> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let range = c * CHUNK..((c + 1) * CHUNK).min(n);
            // Room for two stored photons per path (1.7 in cornell-box), so
            // most chunks never grow their buffer.
            let mut out = ChunkResult { global: Vec::with_capacity(2 * CHUNK as usize), ..Default::default() };
            let mut tracer =
                PathTracer { scene, probabilities: &probabilities, n, power_unit, settings, mixes, out: &mut out };
            for i in range.clone() {
                if bumps { tracer.trace_one::<true>(i) } else { tracer.trace_one::<false>(i) }
            }
            progress.advance(range.end - range.start);
            out
        })
        .collect();
    progress.end();

    let mut traced = TracedPhotons {
        global: Vec::with_capacity(results.iter().map(|r| r.global.len()).sum()),
        caustic: Vec::with_capacity(results.iter().map(|r| r.caustic.len()).sum()),
        volume: Vec::with_capacity(results.iter().map(|r| r.volume.len()).sum()),
        power_unit,
        stats: TraceStats { emitted: n, ..Default::default() },
    };
    for r in results {
        traced.global.extend(r.global);
        traced.caustic.extend(r.caustic);
        traced.volume.extend(r.volume);
        let per_bounce = &mut traced.stats.stored_flux_per_bounce;
        if per_bounce.len() < r.flux_per_bounce.len() {
            per_bounce.resize(r.flux_per_bounce.len(), Rgb::ZERO);
        }
        for (acc, f) in per_bounce.iter_mut().zip(&r.flux_per_bounce) {
            *acc += *f * power_unit;
        }
        traced.stats.truncated += r.truncated;
    }
    traced
}

#[derive(Default)]
struct ChunkResult {
    global: Vec<Photon>,
    caustic: Vec<Photon>,
    volume: Vec<Photon>,
    flux_per_bounce: Vec<Rgb>,
    truncated: u64,
}

struct PathTracer<'a> {
    scene: &'a Scene,
    probabilities: &'a [f32],
    n: u64,
    power_unit: f32,
    settings: &'a TraceSettings,
    /// Some material lets a share through as glass (`texture::Transmission`).
    mixes: bool,
    out: &'a mut ChunkResult,
}

/// The bump shadowing at a point of smooth normal `smooth` bent to `bent`
/// for light from `wi` (`bsdf::bump`); out of line, off the tracer's loop.
#[inline(never)]
fn bump_weight(smooth: Vec3, bent: Vec3, wi: Vec3) -> f32 {
    BumpShadow::new(smooth, bent).map_or(1.0, |b| b.term(wi))
}

impl PathTracer<'_> {
    /// Picks a light with probability ∝ power; returns it and its photons' power.
    fn choose_light(&self, xi: f32) -> (usize, Rgb) {
        let mut acc = 0.0;
        let mut index = self.probabilities.len() - 1;
        for (i, p) in self.probabilities.iter().enumerate() {
            acc += p;
            if xi < acc {
                index = i;
                break;
            }
        }
        let light = &self.scene.lights[index];
        (index, light.power() / (self.probabilities[index] * self.n as f32))
    }

    /// Traces photon path `index`. `BUMPS`: some material has a normal
    /// texture, whose bump shadowing the diffuse bounces take; the loop is
    /// made twice so that scenes without one run none of it (it cost the
    /// CPU tracer 3–6% on cornell-box when tested at run time).
    fn trace_one<const BUMPS: bool>(&mut self, index: u64) {
        let mut rng = Rng::for_item(self.settings.seed, index);
        let (light, power) = self.choose_light(rng.next_f32());
        let emitted = self.scene.lights[light].emit(&mut rng);
        // Power is tracked in units of `power_unit` from here on.
        let mut power = power * emitted.weight / self.power_unit;
        let mut ray = Ray::new(emitted.origin, emitted.dir);
        let (mut diffuse_bounces, mut specular_bounces) = (0u32, 0u32);

        for _ in 0..self.settings.max_bounces {
            let hit = self.scene.accel.intersect(&ray);
            // Free flight through the media, if any (eq. 5.10–5.12).
            let media = &self.scene.media;
            if !media.is_empty() {
                // A photon leaving the scene flies through fog as far as an
                // eye ray would (`Scene::escape_distance`).
                let t_max = hit.map_or_else(|| self.scene.escape_distance(ray.origin, ray.dir), |h| h.t);
                match media.sample_flight(ray.origin, ray.dir, t_max, rng.next_f32()) {
                    Flight::Passed { weight, .. } => power *= weight,
                    Flight::Interaction { distance, weight, mask, .. } => {
                        let (lambda, albedo) = media.scattering(mask);
                        if rng.next_f32() >= lambda {
                            return; // absorbed
                        }
                        // Scattered: stored with the power it leaves with.
                        power *= weight * albedo;
                        let x = ray.at(distance);
                        let scatterer = media.choose_scatterer(mask, rng.next_f32());
                        self.out.volume.push(Photon::volume(x, power, ray.dir, scatterer.phase_slot));
                        diffuse_bounces += 1;
                        ray = Ray::new(x, scatterer.medium.phase.sample(ray.dir, rng.next_2d()));
                        continue;
                    }
                }
            }
            let Some(hit) = hit else { return };
            let smooth = hit.shading_normal;
            let hit = self.scene.bent(hit, ray.dir);
            let material = &*self.scene.material_at(&hit);
            // Normals on the side the photon arrives from.
            let facing = if ray.dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
            let (ng, ns) = (hit.geometric_normal * facing, hit.shading_normal * facing);
            // A normal-mapped point's diffuse lobes: the bump shadowing of
            // the side the photon comes from (taken here, so only a number
            // stays live through the bounce below).
            let bump =
                if BUMPS && smooth != hit.shading_normal { bump_weight(smooth * facing, ns, -ray.dir) } else { 1.0 };

            let next_dir = match material {
                Material::Emitter => return,
                Material::Glass(glass) => {
                    // Arriving from inside: what the glass absorbed on the way.
                    power *= glass.interior_transmittance(ray.dir, hit.geometric_normal, hit.t);
                    // Power crosses unchanged (importance); a rough or
                    // tinted boundary's weight is below 1, and Russian
                    // roulette on it keeps photons near constant power.
                    let u_lobe = rng.next_f32();
                    let u = if glass.is_smooth() { glam::Vec2::ZERO } else { rng.next_2d() };
                    let Some(s) = glass.sample_world(ray.dir, hit.geometric_normal, u_lobe, u, Transport::Importance)
                    else {
                        return;
                    };
                    let survive = mean(s.weight).min(1.0);
                    if survive < 1.0 && !(rng.next_f32() < survive) {
                        return;
                    }
                    power *= s.weight / survive;
                    specular_bounces += 1;
                    s.wi
                }
                Material::Pbr(bsdf) => {
                    if bsdf.stores_photons() {
                        if self.mixes {
                            self.store_where_mixed(&hit, facing, power, ray.dir, diffuse_bounces, specular_bounces);
                        } else {
                            self.store(hit.point, power, ray.dir, diffuse_bounces, specular_bounces);
                        }
                    }
                    // The bounce samples the whole BRDF; Russian roulette on
                    // the sample's weight keeps photons near constant power.
                    let frame = ShadingFrame::new(ns);
                    let tilted = self.scene.coat_tilted(bsdf, &hit, smooth, ray.dir, &frame);
                    let bsdf = tilted.as_ref().unwrap_or(bsdf);
                    let wo = frame.to_local(-ray.dir);
                    let Some(mut s) = bsdf.sample(wo, rng.next_f32(), rng.next_2d()) else { return };
                    if bump != 1.0 {
                        s = bsdf.reweigh(wo, s, bump);
                    }
                    let survive = mean(s.weight).min(1.0);
                    if !(rng.next_f32() < survive) {
                        return;
                    }
                    power *= s.weight / survive;
                    // A bounce off a lobe the eye follows (smoother than the
                    // gather threshold) makes caustics, as a mirror does.
                    if s.followed {
                        specular_bounces += 1;
                    } else {
                        diffuse_bounces += 1;
                    }
                    frame.to_world(s.wi)
                }
                Material::Diffuse { .. } | Material::Mirror { .. } => {
                    if material.is_diffuse() {
                        if self.mixes {
                            self.store_where_mixed(&hit, facing, power, ray.dir, diffuse_bounces, specular_bounces);
                        } else {
                            self.store(hit.point, power, ray.dir, diffuse_bounces, specular_bounces);
                        }
                    }
                    let (event, factor) = material.roulette(rng.next_f32());
                    power *= factor;
                    match event {
                        Event::Absorbed => return,
                        Event::Diffuse => {
                            diffuse_bounces += 1;
                            power *= bump;
                            local_to_world(cosine_hemisphere(rng.next_2d()), ns)
                        }
                        Event::Specular => {
                            specular_bounces += 1;
                            reflect(ray.dir, ns)
                        }
                    }
                }
            };
            // A shading normal can send the path below the true surface: end it there.
            let leaves_front = next_dir.dot(ng) > 0.0;
            let is_transmission = matches!(material, Material::Glass { .. }) && next_dir.dot(ng) < 0.0;
            if !leaves_front && !is_transmission {
                return;
            }
            ray = Ray::new(hit.point, next_dir);
        }
        self.out.truncated += 1;
    }

    /// [`Self::store`] in a scene where some material lets a share through
    /// as glass (`texture::Transmission`): photons stored on the base's
    /// draws stand for the ones drawn through (`Scene::store_weight`), and
    /// none is stored behind such a surface (arriving from `facing` −1),
    /// inside its body, where the light trapped by the glass share would
    /// leak through the gather radius onto whatever the body touches (a
    /// floor under a ball glowed 1.2–2× too bright); photon-cpu shades those
    /// points by a sampled bounce instead. Out of line, behind a flag set
    /// once: the checks inlined in the loop cost other scenes' tracing up
    /// to 11% (criterion, cornell-box).
    #[inline(never)]
    fn store_where_mixed(
        &mut self,
        hit: &crate::geometry::Hit,
        facing: f32,
        power: Rgb,
        dir: Vec3,
        diffuse_bounces: u32,
        specular_bounces: u32,
    ) {
        if facing < 0.0 && self.scene.mixes_at(hit) {
            return;
        }
        let power = power * self.scene.store_weight(hit, Material::is_diffuse);
        self.store(hit.point, power, dir, diffuse_bounces, specular_bounces);
    }

    // Inlined: called out of line from its three arms, its power (a Vec3
    // passed through memory) was read by an 8-byte load over the caller's
    // 4-byte stores and waited for them (16% of its samples, perf
    // cpu-clock): the CPU tracer was 13-17% slower than at 662e119.
    #[inline(always)]
    fn store(&mut self, point: Vec3, power: Rgb, dir: Vec3, diffuse_bounces: u32, specular_bounces: u32) {
        let class = match (diffuse_bounces, specular_bounces) {
            (0, 0) => PathClass::Direct,
            (0, _) => PathClass::Caustic,
            _ => PathClass::Indirect,
        };
        let photon = Photon::new(point, power, dir, class);
        self.out.global.push(photon);
        if class == PathClass::Caustic {
            self.out.caustic.push(photon);
        }
        let k = diffuse_bounces as usize;
        if self.out.flux_per_bounce.len() <= k {
            self.out.flux_per_bounce.resize(k + 1, Rgb::ZERO);
        }
        self.out.flux_per_bounce[k] += power;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::{Media, Medium, Phase};
    use crate::progress::Silent;
    use crate::test_scenes;
    use glam::Vec3;

    #[test]
    fn identical_maps_with_one_and_two_threads() {
        let scene = Scene::load("cornell-caustic").unwrap();
        let settings = TraceSettings { photons: 30_000, seed: 42, ..Default::default() };
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| trace_photons(&scene, &settings, &Silent))
        };
        let (a, b) = (run(1), run(2));
        assert!(!a.global.is_empty() && !a.caustic.is_empty());
        assert_eq!(a.global, b.global);
        assert_eq!(a.caustic, b.caustic);
        assert_eq!(a.stats, b.stats);
        // A different seed gives different photons.
        let c = trace_photons(&scene, &TraceSettings { seed: 43, ..settings.clone() }, &Silent);
        assert_ne!(a.global, c.global);
    }

    /// In a closed sphere of RGB albedo ρ around a point light of power Φ, the
    /// power stored at the k-th diffuse hit is Φ ρ^k in expectation, channel by
    /// channel, whatever the roulette does to individual photons.
    #[test]
    fn russian_roulette_keeps_stored_flux_per_bounce() {
        let albedo = Vec3::new(0.8, 0.5, 0.2);
        let scene = test_scenes::furnace(albedo, 1.0);
        let phi = scene.lights[0].power();
        let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 5, ..Default::default() }, &Silent);
        for k in 0..4 {
            let expected = phi * albedo.powf(k as f32);
            let got = traced.stats.stored_flux_per_bounce[k];
            // The roulette is driven by the mean albedo 0.5, so by bounce 3 about
            // 25,000 photons remain: a 3% band is about 5 standard deviations.
            let rel = ((got - expected) / expected).abs().max_element();
            assert!(rel < 0.03, "bounce {k}: stored {got}, expected {expected}");
        }
        assert_eq!(traced.stats.truncated, 0);
    }

    /// A purely absorbing medium inside the furnace sphere: the first-bounce
    /// flux is Φ e^(−σ_a R), and nothing scatters.
    #[test]
    fn absorbing_medium_attenuates_stored_flux() {
        let mut scene = test_scenes::furnace(Vec3::splat(0.5), 1.0);
        let sigma_a = Vec3::new(0.3, 0.6, 1.2);
        scene.media = Media::homogeneous(Medium { sigma_a, sigma_s: Vec3::ZERO, phase: Phase::Schlick { k: 0.0 } });
        let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 8, ..Default::default() }, &Silent);
        assert!(traced.volume.is_empty());
        let expected = scene.lights[0].power() * (-sigma_a).exp();
        let got = traced.stats.stored_flux_per_bounce[0];
        assert!(((got - expected) / expected).abs().max_element() < 0.02, "{got} vs {expected}");
    }

    /// A scattering medium fills the volume map, identically for any thread count.
    #[test]
    fn scattering_medium_fills_the_volume_map_deterministically() {
        let mut scene = Scene::load("cornell-box").unwrap();
        scene.media = Media::homogeneous(Medium {
            sigma_a: Vec3::splat(0.05),
            sigma_s: Vec3::new(0.2, 0.3, 0.4),
            phase: Phase::HenyeyGreenstein { g: 0.3 },
        });
        let settings = TraceSettings { photons: 20_000, seed: 9, ..Default::default() };
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| trace_photons(&scene, &settings, &Silent))
        };
        let (a, b) = (run(1), run(2));
        assert!(a.volume.len() > 1000);
        assert!(a.volume.iter().all(|p| p.phase_slot() == 0));
        assert_eq!(a.volume, b.volume);
        assert_eq!(a.global, b.global);
    }

    /// Two media filling the same space, with different phase functions:
    /// each stores its share σ_s,i / Σσ_s of the scattering events, under its
    /// own phase slot.
    #[test]
    fn overlapping_media_scatter_in_proportion_to_sigma_s() {
        let mut scene = Scene::load("cornell-box").unwrap();
        let medium = |sigma_s: f32, g: f32| {
            (
                Medium {
                    sigma_a: Vec3::splat(0.02),
                    sigma_s: Vec3::splat(sigma_s),
                    phase: Phase::HenyeyGreenstein { g },
                },
                None,
            )
        };
        scene.media = Media::new(vec![medium(0.1, 0.5), medium(0.3, -0.3)]).unwrap();
        let traced = trace_photons(&scene, &TraceSettings { photons: 40_000, seed: 10, ..Default::default() }, &Silent);
        let second = traced.volume.iter().filter(|p| p.phase_slot() == 1).count() as f64;
        let share = second / traced.volume.len() as f64;
        assert!(traced.volume.len() > 5000 && (share - 0.75).abs() < 0.015, "{share} of {}", traced.volume.len());
    }

    #[test]
    fn path_classes_partition_hits() {
        let scene = Scene::load("cornell-caustic").unwrap();
        let traced = trace_photons(&scene, &TraceSettings { photons: 20_000, seed: 1, ..Default::default() }, &Silent);
        let count = |c| traced.global.iter().filter(|p| p.class() == c).count();
        assert!(count(PathClass::Direct) > 0 && count(PathClass::Indirect) > 0);
        assert_eq!(count(PathClass::Caustic), traced.caustic.len());
        assert!(traced.caustic.iter().all(|p| p.class() == PathClass::Caustic));
    }

    /// A sun's photons carry its irradiance: a floor of area A tilted θ from
    /// it receives E·cos θ·A at their first hits.
    #[test]
    fn sun_photons_carry_e_cos_theta_per_area() {
        let scene = test_scenes::sunlit_floor(30.0, 3.0, 0.5, false);
        let traced =
            trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 11, ..Default::default() }, &Silent);
        let expected = 3.0 * 30f32.to_radians().cos() * 16.0;
        let got = traced.stats.stored_flux_per_bounce[0];
        eprintln!("sun: {got} vs {expected}");
        // Each photon hits with probability 0.55: ±0.2%.
        assert!(((got - Vec3::splat(expected)) / expected).abs().max_element() < 0.01, "{got} vs {expected}");
    }

    /// A sky's photons carry its radiance: a floor of area A open to a sky
    /// of radiance L receives π·L·A on each face, 2π·L·A in all.
    #[test]
    fn sky_photons_carry_pi_l_per_area_and_face() {
        let scene = test_scenes::sky_floor(2.0, "name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]");
        let traced =
            trace_photons(&scene, &TraceSettings { photons: 200_000, seed: 12, ..Default::default() }, &Silent);
        let expected = 2.0 * std::f32::consts::PI * 2.0 * 16.0;
        let got = traced.stats.stored_flux_per_bounce[0];
        eprintln!("sky: {got} vs {expected}");
        // Each photon hits with probability 0.32: ±0.3%.
        assert!(((got - Vec3::splat(expected)) / expected).abs().max_element() < 0.015, "{got} vs {expected}");
    }
}
