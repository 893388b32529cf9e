//! The radiance estimates, defined once (METHOD.md §3). Every CPU renderer
//! calls these; the GPU splat mirrors `photon_contribution` in WGSL and a
//! twin test pins the two together.
//!
//! Conventions: `x` the shaded point, `normal` its unit shading normal turned
//! toward the viewer, `albedo` its diffuse reflectance (Lambertian,
//! f_r = albedo/π), photon power in watts.

use crate::material::Rgb;
use crate::photon::{PathClass, Photon, PhotonMap, VolumePhotonMap};
use glam::Vec3;
use std::f32::consts::PI;

/// Parameters of the fixed-radius estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedRadius {
    /// r: photons farther than this from x do not count (constant kernel).
    pub radius: f32,
    /// Count only photons that arrived from the side `normal` faces. This
    /// keeps light from leaking through thin two-sided walls; it does not
    /// change the estimate on a closed surface seen from inside.
    pub normal_test: bool,
}

/// The kernel w(d_p) of eq. 4.1 with the optional normal test: 1 if photon
/// `p` counts at `x`, else 0. `d2` is |x − x_p|².
#[inline]
pub fn photon_accepted(d2: f32, photon_dir: Vec3, normal: Vec3, params: &FixedRadius) -> bool {
    d2 <= params.radius * params.radius && !(params.normal_test && photon_dir.dot(normal) >= 0.0)
}

/// The factor turning accepted photon power into reflected radiance for a
/// Lambertian surface: f_r / (π r²) = albedo / (π² r²).
#[inline]
pub fn radiance_per_power(albedo: Rgb, params: &FixedRadius) -> Rgb {
    albedo * (1.0 / (PI * PI * params.radius * params.radius))
}

/// One photon's contribution L_rp (eq. 4.3), in units of the photon's stored
/// power: albedo/π · ΔΦ_p / (π r²) · w(d_p). This is what the GPU splat adds
/// per fragment.
#[inline]
pub fn photon_contribution(x: Vec3, normal: Vec3, albedo: Rgb, photon: &Photon, params: &FixedRadius) -> Rgb {
    let d2 = (photon.position() - x).length_squared();
    if photon_accepted(d2, photon.direction(), normal, params) {
        radiance_per_power(albedo, params) * photon.power_in_units()
    } else {
        Rgb::ZERO
    }
}

/// The seed's estimate (eq. 4.1): the sum of `photon_contribution` over every
/// photon of `map` in `class` (all classes if None) within r of x, computed
/// as (Σ accepted power) × `radiance_per_power` — the same sum, factored.
pub fn fixed_radius_radiance(
    map: &PhotonMap,
    class: Option<PathClass>,
    x: Vec3,
    normal: Vec3,
    albedo: Rgb,
    params: &FixedRadius,
) -> Rgb {
    let photons = map.photons();
    let mut power = Rgb::ZERO;
    map.for_each_index_within(x, params.radius, |i, d2| {
        let p = &photons[i];
        let dir_needed = params.normal_test;
        let accepted = if dir_needed {
            photon_accepted(d2, p.direction(), normal, params)
        } else {
            d2 <= params.radius * params.radius
        };
        if accepted && class.is_none_or(|c| p.class() == c) {
            power += map.power_in_units(i);
        }
    });
    radiance_per_power(albedo, params) * power * map.power_unit
}

/// Most a photon's weight may grow by `shading_normal_factor`: the ratio
/// is unbounded for photons grazing the true surface, and without a cap
/// the rare large ones made photon-cpu's noise estimate 1.1% → 10% on a
/// normal-mapped scene (with 8: 1.15%). Under a uniform sky the cap loses
/// 0.1%, 0.9% and 2.4% of the light a normal bent 10°, 30° and 50°
/// reflects (a test integrates it); 4 lost 2.1% at 30°.
pub const MAX_SHADING_NORMAL_FACTOR: f32 = 8.0;

/// Below this cosine between the shading and the geometric normal a surface
/// point counts as bent (`is_bent`): 0.26°, well above the rounding of an
/// interpolated normal that equals the face's, well below any shading
/// that shows.
pub const BENT_COS: f32 = 0.99999;

/// Whether a point shading with unit normal `ns` across unit `ng` weighs
/// its photons by `shading_normal_factor` (smooth-shaded and normal-mapped
/// meshes); elsewhere the factor is 1 up to rounding and is skipped.
#[inline]
pub fn is_bent(ns: Vec3, ng: Vec3) -> bool {
    ns.dot(ng) < BENT_COS
}

/// What one photon arriving from `wi` (toward where it came from) counts for
/// where the surface shades with normal `ns` but lies across `ng` (both on
/// the side the eye sees): max(ns·ωi, 0) / |ng·ωi|, at most
/// `MAX_SHADING_NORMAL_FACTOR`. A photon map's density is flux over the
/// true surface, ∫ L cos θg dω; light reflected through a shading normal
/// weighs cos θs (as `path`'s shadow rays and bounces weigh it), so each
/// photon carries the ratio (Veach 1997, §5.3). Photons from below the
/// shading hemisphere reflect nothing, as light from there does in
/// `path`. Without it, photon-cpu drew normal-mapped tiles 4–6% brighter
/// than `path` (BENCHMARKS.md).
#[inline]
pub fn shading_normal_factor(wi: Vec3, ns: Vec3, ng: Vec3) -> f32 {
    let cos_g = wi.dot(ng).abs();
    if cos_g <= 0.0 {
        return 0.0;
    }
    (wi.dot(ns).max(0.0) / cos_g).min(MAX_SHADING_NORMAL_FACTOR)
}

/// The same estimate for any BRDF: Σ f_r(ω_p) ΔΦ_p / (π r²) over the
/// accepted photons of `map`, each weighted by `brdf` at its own incoming
/// direction (−`photon.direction()`, toward where it came from). With
/// f_r = albedo/π it equals [`fixed_radius_radiance`].
pub fn fixed_radius_radiance_brdf(
    map: &PhotonMap,
    x: Vec3,
    normal: Vec3,
    params: &FixedRadius,
    brdf: impl Fn(Vec3) -> Rgb,
) -> Rgb {
    let photons = map.photons();
    let mut sum = Rgb::ZERO;
    map.for_each_index_within(x, params.radius, |i, d2| {
        let p = &photons[i];
        if photon_accepted(d2, p.direction(), normal, params) {
            sum += brdf(-p.direction()) * map.power_in_units(i);
        }
    });
    sum * (map.power_unit / (PI * params.radius * params.radius))
}

/// In-scattered radiance reaching the eye along the segment `origin +
/// t·dir`, t in [0, length], from a volume photon map (eq. 5.21–5.24 with an
/// exact chord): for each photon p whose radius-r sphere the segment crosses,
/// p(μ_p) · ΔΦ_p / ((4/3)π r³) · t_p · T(s_p), where t_p is the length of the
/// segment inside the sphere, s_p the point of that chord nearest the photon,
/// μ_p the cosine between the photon's direction and the direction toward
/// the eye, p the phase function of the photon's slot in `phases`, and
/// `transmittance(s)` that of the media from the eye to distance s (exact in
/// photon-cpu; interpolated between depth slices in the GPU's twin).
pub fn volume_radiance_along(
    map: &VolumePhotonMap,
    phases: &[crate::medium::Phase],
    origin: Vec3,
    dir: Vec3,
    length: f32,
    transmittance: impl Fn(f32) -> Rgb,
) -> Rgb {
    if map.is_empty() || !(length > 0.0) {
        return Rgb::ZERO;
    }
    let radius = map.radius();
    let r2 = radius * radius;
    let norm = 1.0 / (4.0 / 3.0 * PI * r2 * radius);
    let mut sum = Rgb::ZERO;
    map.for_each_near_segment(origin, dir, length, |photon| {
        let to_photon = photon.position - origin;
        let t_closest = to_photon.dot(dir);
        let h2 = to_photon.length_squared() - t_closest * t_closest;
        if h2 > r2 {
            return;
        }
        let half = (r2 - h2).max(0.0).sqrt();
        let (t0, t1) = ((t_closest - half).max(0.0), (t_closest + half).min(length));
        if t1 <= t0 {
            return;
        }
        let s_p = t_closest.clamp(t0, t1);
        let mu = photon.direction.dot(-dir);
        let phase = phases[photon.phase_slot].eval(mu);
        sum += transmittance(s_p) * photon.power * (phase * (t1 - t0));
    });
    sum * norm * map.power_unit
}

/// The classic estimate (eq. 3.9): the k nearest photons within `max_radius`,
/// divided by the area π r_k² of the disc that holds them.
pub fn k_nearest_radiance(
    map: &PhotonMap,
    x: Vec3,
    normal: Vec3,
    albedo: Rgb,
    k: usize,
    max_radius: f32,
    normal_test: bool,
) -> Rgb {
    let (photons, r) = map.nearest(x, k, max_radius);
    if photons.is_empty() || r <= 0.0 {
        return Rgb::ZERO;
    }
    let mut flux = Rgb::ZERO;
    for p in photons {
        if !normal_test || p.direction().dot(normal) < 0.0 {
            flux += p.power_in_units();
        }
    }
    albedo / PI * flux * map.power_unit / (PI * r * r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A uniform photon density of flux E per unit area on a plane gives the
    /// radiance albedo·E/π with either estimate.
    #[test]
    fn the_shading_normal_factor_weighs_cosines_as_a_shadow_ray_would() {
        let ng = Vec3::Z;
        let tilt = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        // Normals that agree: 1 from the front.
        assert!((shading_normal_factor(tilt(50.0), ng, ng) - 1.0).abs() < 1e-6);
        // Bent 30° toward +x: a photon from 60° on that side (30° off the
        // shading normal) counts cos 30° / cos 60°; from the other side
        // cos 90° = 0.
        let ns = tilt(30.0);
        assert!((shading_normal_factor(tilt(60.0), ns, ng) - 0.866_025_4 / 0.5).abs() < 1e-5);
        assert!(shading_normal_factor(tilt(-60.0), ns, ng).abs() < 1e-6);
        // Below the shading hemisphere: nothing; grazing the true surface:
        // at most the cap.
        assert_eq!(shading_normal_factor(tilt(-80.0), ns, ng), 0.0);
        assert_eq!(shading_normal_factor(tilt(89.5), ns, ng), MAX_SHADING_NORMAL_FACTOR);
        assert_eq!(shading_normal_factor(Vec3::X, ns, ng), 0.0);
    }

    /// Photons of a uniform sky land with density ∝ cos θg; weighted by the
    /// factor, a Lambertian surface under a normal bent by δ reflects
    /// ∫ over both hemispheres of cos θs = π (1 + cos δ) / 2, what a path
    /// tracer's shading gives, less what the cap leaves out (quadrature:
    /// 0.11%, 0.94%, 2.42%).
    #[test]
    fn photons_of_a_uniform_sky_weigh_as_the_shading_normal_sees_them() {
        let mut rng = Rng::for_item(5, 0);
        for (deg, capped) in [(10.0f32, 0.0011), (30.0, 0.0094), (50.0, 0.0242)] {
            let ns = Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
            let n = 400_000;
            let sum: f64 = (0..n)
                .map(|_| shading_normal_factor(crate::sampling::cosine_hemisphere(rng.next_2d()), ns, Vec3::Z) as f64)
                .sum();
            // E[factor] under the cos θg / π density, times π.
            let got = sum / n as f64 * std::f64::consts::PI;
            let want = std::f64::consts::PI * (1.0 + (deg as f64).to_radians().cos()) / 2.0 * (1.0 - capped);
            eprintln!("bent {deg}°: {got:.5} vs {want:.5}");
            assert!((got / want - 1.0).abs() < 0.004, "bent {deg}°: {got} vs {want}");
        }
    }

    #[test]
    fn estimates_recover_uniform_irradiance() {
        let mut rng = Rng::for_item(41, 0);
        let n = 200_000;
        let irradiance = 2.0;
        // Photons on the square [-1,1]² of area 4, each of power E·4/n.
        let photons: Vec<Photon> = (0..n)
            .map(|_| {
                let u = rng.next_2d() * 2.0 - 1.0;
                Photon::new(Vec3::new(u.x, 0.0, u.y), Vec3::ONE, Vec3::NEG_Y, PathClass::Indirect)
            })
            .collect();
        let map = PhotonMap::new(photons, irradiance * 4.0 / n as f32);
        let albedo = Vec3::splat(0.5);
        let want = 0.5 * irradiance / PI;
        let params = FixedRadius { radius: 0.1, normal_test: true };
        let fixed = fixed_radius_radiance(&map, None, Vec3::ZERO, Vec3::Y, albedo, &params);
        assert!((fixed.x - want).abs() / want < 0.05, "fixed {fixed} vs {want}");
        let knn = k_nearest_radiance(&map, Vec3::ZERO, Vec3::Y, albedo, 500, 1.0, true);
        assert!((knn.x - want).abs() / want < 0.08, "knn {knn} vs {want}");
        // Seen from below, every photon arrived from the other side.
        let below = fixed_radius_radiance(&map, None, Vec3::ZERO, Vec3::NEG_Y, albedo, &params);
        assert_eq!(below, Vec3::ZERO);
    }
}
