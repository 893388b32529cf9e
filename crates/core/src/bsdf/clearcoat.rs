//! `KHR_materials_clearcoat`: a clear dielectric layer (index 1.5, F0 =
//! 0.04) of its own roughness over the glTF BRDF, as [`Bsdf`]'s
//! `clearcoat` and `clearcoat_roughness`:
//!
//! ```text
//! f = T(θo)·T(θi)/(1 − E)·f_diffuse + √(T(θo)·T(θi))·f_specular + c·F_c(|v·h|)·D_c(h)·V_c
//! T(θ) = 1 − c·F_c(cos θ)      F_c(x) = 0.04 + 0.96 (1 − x)^5
//! E = c·(0.04 + 0.96/21)       (the coat's cosine-weighted mean reflectance)
//! ```
//!
//! with c the clearcoat factor, f_diffuse and f_specular the base's lobes,
//! and D_c, V_c the GGX terms of α_c = clearcoatRoughness².
//!
//! # How the base is dimmed
//!
//! The specification dims the base by 1 − c·F_c(|v·h|) per pair of
//! directions, which creates light at grazing views (a white rough metal
//! under a rough coat reflects 1.22 of what arrives at 80°); Cycles and the
//! Khronos sample viewer dim it by 1 − (the coat's albedo at the view)
//! alone, which conserves energy but is not reciprocal (photons and eye
//! paths would disagree). hikari keeps the BSDF reciprocal and matches
//! Cycles where it counts:
//!
//! * the diffuse lobe is dimmed by T(θo)·T(θi)/(1 − E) (Kelemen and
//!   Szirmay-Kalos' coupling): integrated over the light's directions this
//!   is exactly T(θo) times the Lambertian albedo, as in Cycles, and a white
//!   Lambertian base under a smooth coat reflects exactly 1 at every angle;
//! * the specular lobe is dimmed by √(T(θo)·T(θi)): exactly T(θo) at the
//!   mirror direction, so a white mirror under a smooth coat also reflects
//!   exactly 1 (what light bouncing between coat and mirror adds up to).
//!
//! Dimming by T(θo)·T(θi) alone (light crossing the coat in and out, no
//! bounces between coat and base) drew coated balls 5–8% darker than
//! Cycles (`scripts/cycles/clearcoat.py`). Below `SMOOTH_ROUGHNESS` the coat
//! is a perfect mirror of reflectance c·F_c(cos θo) (a delta, sampled but
//! not in `f`).
//!
//! # Sampling, and which lobes the photon maps stand for
//!
//! `sample` picks the coat with probability ∝ c·F_c(cos θo) against the
//! base's albedo estimate and returns the mixture density of both. A coat
//! smoother than `GATHER_ROUGHNESS` is followed by the eye like a smooth
//! base lobe (`sample_followed` chooses between the two by their Fresnel
//! weights at `wo`); a rougher one is estimated from the photon maps
//! (`f_gathered`).
//!
//! # The coat's own normal
//!
//! `clearcoatNormalTexture` bends the coat apart from the base: the coat's
//! lobe, its Fresnel and what it lets through to the diffuse lobe are then
//! functions of the directions in the coat's frame (+z
//! [`Bsdf::coat_normal`], given in the shading frame), the base's lobes of
//! those in the shading frame, as in Cycles' Principled BSDF (its coat
//! closure takes the coat normal, the base's dimming the view's angle to
//! it). Neither side is lit from below: a direction under either surface
//! gets nothing from that surface's lobes.
//!
//! * The diffuse lobe's coupling keeps its normalisation where the coat's
//!   own texture tilts it (`with_coat_normal`): E becomes the coat's
//!   cosine-weighted mean reflectance over the base's hemisphere
//!   ([`tilted_schlick_mean`]), so what the coat leaves of a Lambertian
//!   base is still T(θo) times its albedo, as in Cycles. Without it a coat
//!   tilted 40° took 16% of the base's light (`scripts/cycles/coat_normal.py`'s
//!   orange-peel ball 13% darker than Cycles).
//! * Where the coat lies on the unbent normal over a normal-mapped base
//!   (`with_unbent_coat`), E stays the untilted one: the directions below
//!   the coat's horizon are below the surface, lit by nothing anyway
//!   (normalising over them drew that ball 18% brighter than Cycles).
//! * The base's specular and sheen lobes are dimmed as under an untilted
//!   coat, by the cosines to the shading normal: with the coat's,
//!   √(T(θo)·T(θi)) darkened every mirror direction the tilt put near the
//!   coat's horizon (the metal ball under a bumpy coat 15% darker than
//!   Cycles; 7% with the shading normal's).
//!
//! With the coat normal +z every function is the untilted one to the bit.
//!
//! The WGSL twin is in `crates/gpu/src/wgsl/bsdf.wgsl`, pinned by
//! `crates/gpu/tests/bsdf.rs`; keep the arithmetic the same on both sides.

use super::{
    Bsdf, BsdfSample, DIELECTRIC_F0, GATHER_ROUGHNESS, Lobes, MIN_LOBE_WEIGHT, SMOOTH_ROUGHNESS, ggx, schlick_weight,
};
use crate::material::{Rgb, mean};
use crate::sampling::orthonormal_basis;
use glam::{Vec2, Vec3};

/// The largest f32 below 1: where a reused random number must stay.
const ONE_BELOW: f32 = 0.99999994;

impl Bsdf {
    /// A coat is present (clearcoatFactor > 0).
    pub fn has_coat(&self) -> bool {
        self.clearcoat > 0.0
    }

    /// This material with its coat's normal `normal` (in the local shading
    /// frame; normalised here): the coat's own, bent by
    /// `clearcoatNormalTexture`. One at or below the base's horizon, or
    /// not a direction, leaves the coat on the base's normal.
    pub fn with_coat_normal(self, normal: Vec3) -> Self {
        let b = self.with_unbent_coat(normal);
        Bsdf { coat_schlick_mean: tilted_schlick_mean(b.coat_normal.z), ..b }
    }

    /// This material with its coat on the surface's unbent normal
    /// `normal` (shading frame) over a base a normal texture bent: tilted
    /// as `with_coat_normal`, its mean reflectance the untilted coat's.
    pub fn with_unbent_coat(self, normal: Vec3) -> Self {
        let n = normal.normalize_or_zero();
        let coat_normal = if n.z > 0.0 && n.is_finite() { n } else { Vec3::Z };
        Bsdf { coat_normal, coat_schlick_mean: 1.0 / 21.0, ..self }
    }

    /// The coat lies apart from the base (its normal is not +z).
    fn coat_is_tilted(&self) -> bool {
        self.coat_normal != Vec3::Z
    }

    /// `w` (shading frame) in the coat's frame, whose +z is the coat's normal.
    pub(super) fn to_coat(&self, w: Vec3) -> Vec3 {
        if !self.coat_is_tilted() {
            return w;
        }
        let (t, b) = orthonormal_basis(self.coat_normal);
        Vec3::new(w.dot(t), w.dot(b), w.dot(self.coat_normal))
    }

    /// `w` (coat's frame) in the shading frame.
    fn from_coat(&self, w: Vec3) -> Vec3 {
        if !self.coat_is_tilted() {
            return w;
        }
        let (t, b) = orthonormal_basis(self.coat_normal);
        t * w.x + b * w.y + self.coat_normal * w.z
    }

    /// The coat is a perfect mirror.
    pub(super) fn coat_is_smooth(&self) -> bool {
        self.clearcoat_roughness < SMOOTH_ROUGHNESS
    }

    /// The photon maps stand for the coat's lobe.
    pub(super) fn coat_is_gathered(&self) -> bool {
        self.clearcoat_roughness >= GATHER_ROUGHNESS
    }

    fn coat_alpha(&self) -> f32 {
        (self.clearcoat_roughness * self.clearcoat_roughness).max(super::ALPHA_MIN)
    }

    /// c·F_c at `cos` = |v·h|: what the coat reflects.
    fn coat_fresnel(&self, cos: f32) -> f32 {
        self.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * schlick_weight(cos))
    }

    /// T = 1 − c·F_c(cos): what crosses the coat at `cos` to or from the base.
    fn coat_transmission(&self, cos: f32) -> f32 {
        1.0 - self.coat_fresnel(cos)
    }

    /// What the coat leaves of the base's diffuse lobe between `cos_o` and
    /// `cos_i`: T(θo)·T(θi)/(1 − E), E the coat's cosine-weighted mean
    /// reflectance over the base's hemisphere.
    fn coat_diffuse_through(&self, cos_o: f32, cos_i: f32) -> f32 {
        let mean_reflectance = if self.coat_is_tilted() {
            self.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * self.coat_schlick_mean)
        } else {
            self.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) / 21.0)
        };
        self.coat_transmission(cos_o) * self.coat_transmission(cos_i) / (1.0 - mean_reflectance)
    }

    /// What the coat leaves of the base's specular lobe: √(T(θo)·T(θi)).
    fn coat_specular_through(&self, cos_o: f32, cos_i: f32) -> f32 {
        (self.coat_transmission(cos_o) * self.coat_transmission(cos_i)).sqrt()
    }

    /// The coat's microfacet lobe c·F_c·D·V between `wo` and `wi` in the
    /// coat's frame (zero when smooth: its mirror is a delta; zero for a
    /// direction below the coat).
    fn coat_lobe(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.coat_is_smooth() || wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        let cos = 0.5 * (wo.dot(h) + wi.dot(h));
        let alpha = self.coat_alpha();
        self.coat_fresnel(cos) * ggx::d(h, alpha) * ggx::visibility(wo, wi, alpha)
    }

    /// Probability that `sample` picks the coat at `cos_o` (to the coat's
    /// normal; none from below it).
    fn coat_probability(&self, cos_o: f32) -> f32 {
        if cos_o <= 0.0 {
            return 0.0;
        }
        let coat = self.coat_fresnel(cos_o);
        let base = (1.0 - coat) * self.base_albedo_estimate().max_element();
        if coat + base <= 0.0 { 0.0 } else { coat / (coat + base) }
    }

    pub(super) fn coated_f(&self, wo: Vec3, wi: Vec3, k: f32) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (co, ci) = (self.to_coat(wo), self.to_coat(wi));
        self.under_coat(wo, wi, co, ci, self.f_lobes(wo, wi, k)) + Rgb::splat(self.coat_lobe(co, ci))
    }

    /// The base's lobes between `wo` and `wi` (shading frame; `co`, `ci`
    /// in the coat's) as the coat leaves them: the diffuse lobe by the
    /// cosines to the coat's normal, the specular and the sheen (dimmed
    /// like it) by those to the shading normal.
    fn under_coat(&self, wo: Vec3, wi: Vec3, co: Vec3, ci: Vec3, lobes: Lobes) -> Rgb {
        lobes.diffuse * self.coat_diffuse_through(co.z, ci.z)
            + (lobes.specular + lobes.sheen) * self.coat_specular_through(wo.z, wi.z)
    }

    /// `f_gathered` under the coat: `lobes` are the base's gathered lobes.
    pub(super) fn coated_gathered(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (co, ci) = (self.to_coat(wo), self.to_coat(wi));
        let coat = if self.coat_is_gathered() { self.coat_lobe(co, ci) } else { 0.0 };
        self.under_coat(wo, wi, co, ci, lobes) + Rgb::splat(coat)
    }

    pub(super) fn coated_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let co = self.to_coat(wo);
        let p = self.coat_probability(co.z);
        let mut pdf = (1.0 - p) * self.base_pdf(wo, wi);
        let ci = self.to_coat(wi);
        if !self.coat_is_smooth() && ci.z > 0.0 && p > 0.0 {
            pdf += p * ggx::reflection_pdf(co, (co + ci).normalize(), self.coat_alpha());
        }
        pdf
    }

    pub(super) fn coated_sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let co = self.to_coat(wo);
        let p = self.coat_probability(co.z);
        if u_lobe < p {
            if self.coat_is_smooth() {
                return self.coat_mirror(co, p);
            }
            let ci = ggx::reflect(co, ggx::sample_visible_normal(co, self.coat_alpha(), u));
            return self.coated_finish(wo, self.from_coat(ci), !self.coat_is_gathered());
        }
        let s = self.base_sample(wo, ((u_lobe - p) / (1.0 - p)).min(ONE_BELOW), u)?;
        if s.is_delta {
            // The base's mirror under the coat: √(T·T) at the mirror
            // direction is T(θo).
            let through = self.coat_transmission(wo.z);
            let pdf = (1.0 - p) * s.pdf;
            return Some(BsdfSample { f: s.f * through, pdf, weight: s.f * (through * wo.z / pdf), ..s });
        }
        self.coated_finish(wo, s.wi, s.followed)
    }

    /// The smooth coat's mirror at `co` (the view in the coat's frame),
    /// chosen with probability `p`; None where it leaves below the base.
    fn coat_mirror(&self, co: Vec3, p: f32) -> Option<BsdfSample> {
        let wi = self.from_coat(Vec3::new(-co.x, -co.y, co.z));
        if wi.z <= 0.0 {
            return None;
        }
        let fc = self.coat_fresnel(co.z);
        Some(BsdfSample {
            wi,
            f: Rgb::splat(fc / wi.z),
            pdf: p,
            weight: Rgb::splat(fc / p),
            is_delta: true,
            followed: true,
        })
    }

    fn coated_finish(&self, wo: Vec3, wi: Vec3, followed: bool) -> Option<BsdfSample> {
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.coated_pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let f = self.coated_f(wo, wi, 1.0);
        Some(BsdfSample { wi, f, pdf, weight: f * (wi.z / pdf), is_delta: false, followed })
    }

    /// `sample_followed` with a coat: the coat (if followed) or the base's
    /// specular lobe (if followed, seen through the coat), chosen by their
    /// Fresnel weights at `wo`.
    pub(super) fn coated_sample_followed(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let co = self.to_coat(wo);
        let coat = if self.coat_is_gathered() || co.z <= 0.0 { 0.0 } else { self.coat_fresnel(co.z) };
        let base = if self.has_specular() && !self.gathers_specular() {
            self.coat_transmission(wo.z) * mean(self.specular_fresnel(wo.z)).max(MIN_LOBE_WEIGHT)
        } else {
            0.0
        };
        if coat + base <= 0.0 {
            return None;
        }
        let p = coat / (coat + base);
        if u.x < p {
            let u = Vec2::new((u.x / p).min(ONE_BELOW), u.y);
            if self.coat_is_smooth() {
                return self.coat_mirror(co, p);
            }
            let alpha = self.coat_alpha();
            let h = ggx::sample_visible_normal(co, alpha, u);
            let ci = ggx::reflect(co, h);
            let wi = self.from_coat(ci);
            let pdf = p * ggx::reflection_pdf(co, h, alpha);
            if wi.z <= 0.0 || ci.z <= 0.0 || pdf <= 0.0 {
                return None;
            }
            let f = Rgb::splat(self.coat_lobe(co, ci));
            return Some(BsdfSample { wi, f, pdf, weight: f * (wi.z / pdf), is_delta: false, followed: true });
        }
        let u = Vec2::new(((u.x - p) / (1.0 - p)).min(ONE_BELOW), u.y);
        let s = self.sample_specular_lobe(wo, u)?;
        let through = self.coat_specular_through(wo.z, s.wi.z);
        Some(BsdfSample { f: s.f * through, pdf: (1.0 - p) * s.pdf, weight: s.weight * (through / (1.0 - p)), ..s })
    }

    /// `albedo_estimate` with a coat: the coat's cosine-averaged Fresnel,
    /// and the base's estimate under what is left.
    pub(super) fn coated_albedo_estimate(&self) -> Rgb {
        let coat = self.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) / 21.0);
        Rgb::splat(coat) + self.base_albedo_estimate() * (1.0 - coat)
    }
}

/// The cosine-weighted mean over the base's hemisphere of Schlick's
/// (1 − cos)^5, cos taken to a coat normal tilted θ = acos(z) from the
/// base's (and 0 below the coat's horizon, where the coat reflects all):
/// 1/21 untilted, 0.60 at 90°. A degree-5 polynomial in θ fitted to the
/// quadrature, within 2.5·10⁻⁴ of it (`tilted_schlick_mean_fits_the_quadrature`).
pub(super) fn tilted_schlick_mean(z: f32) -> f32 {
    const FIT: [f32; 6] = [0.047376793, 0.007523404, 0.42324913, -0.20406739, 0.072868034, -0.015920898];
    let theta = z.clamp(-1.0, 1.0).acos();
    FIT.iter().rev().fold(0.0, |sum, &c| sum * theta + c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::ggx::tests::direction_at;
    use crate::bsdf::tests::{integrate_about, mean_weight};
    use crate::sampling::Rng;
    use crate::sampling::chi2::assert_direction_distribution;
    use std::cell::RefCell;

    fn coated(base: Bsdf, clearcoat: f32, roughness: f32) -> Bsdf {
        base.with_clearcoat(clearcoat, roughness)
    }

    fn mirror(wo: Vec3) -> Vec3 {
        Vec3::new(-wo.x, -wo.y, wo.z)
    }

    /// A coat normal 17° off the base's, as a clear-coat normal texture
    /// bends it.
    fn tilt() -> Vec3 {
        Vec3::new(0.25, -0.15, 0.95).normalize()
    }

    /// Where `c`'s coat mirrors `wo` (about its own normal).
    fn coat_mirror_of(c: &Bsdf, wo: Vec3) -> Vec3 {
        c.from_coat(mirror(c.to_coat(wo)))
    }

    /// `tilted_schlick_mean` against quadrature over the base's hemisphere
    /// at tilts from 0° to 90°.
    #[test]
    fn tilted_schlick_mean_fits_the_quadrature() {
        for deg in [0.0f32, 5.0, 17.0, 30.0, 45.0, 60.0, 75.0, 89.0] {
            let n = Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
            let quadrature = integrate_about(Vec3::Z, |w| {
                if w.z <= 0.0 {
                    return 0.0;
                }
                schlick_weight(n.dot(w).max(0.0)) as f64 * w.z as f64 / std::f64::consts::PI
            });
            let fit = tilted_schlick_mean(n.z) as f64;
            assert!((fit - quadrature).abs() < 3e-4, "{deg}°: fit {fit} against {quadrature}");
        }
    }

    /// A tilted coat over a black base is the untilted coat turned: its f
    /// between two directions is the untilted one's between them seen from
    /// the coat's frame, its pdf too, and a smooth one mirrors the view
    /// about the coat's normal with reflectance c·F_c(cos to that normal).
    #[test]
    fn a_tilted_coat_is_the_coat_turned() {
        let n = tilt();
        for roughness in [0.3, 0.6] {
            let flat = coated(Bsdf::diffuse(Rgb::ZERO), 1.0, roughness);
            let tilted = flat.with_coat_normal(n);
            let mut rng = Rng::for_item(0xC0AB, 0);
            for _ in 0..300 {
                let (wo, wi) = (direction_at(75.0 * rng.next_f32()), direction_at(75.0 * rng.next_f32()));
                let (wo, wi) = (Vec3::new(wo.x, wo.z * 0.3, wo.z).normalize(), wi);
                let (co, ci) = (tilted.to_coat(wo), tilted.to_coat(wi));
                let want = if co.z > 0.0 && ci.z > 0.0 { flat.f(co, ci).x } else { 0.0 };
                let got = tilted.f(wo, wi).x;
                assert!((got - want).abs() <= 1e-5 * want.max(1.0), "{wo} {wi}: {got} against {want}");
                let want_pdf = if co.z > 0.0 && ci.z > 0.0 { flat.pdf(co, ci) } else { 0.0 };
                assert!((tilted.pdf(wo, wi) - want_pdf).abs() <= 1e-4 * want_pdf.max(1.0));
            }
        }
        let smooth = coated(Bsdf::diffuse(Rgb::ZERO), 1.0, 0.0).with_coat_normal(n);
        let wo = direction_at(40.0);
        let s = smooth.sample(wo, 0.0, Vec2::ZERO).unwrap();
        let want = 2.0 * wo.dot(n) * n - wo;
        assert!(s.is_delta && s.wi.abs_diff_eq(want, 1e-5), "{} against {want}", s.wi);
        let fresnel = 0.04 + 0.96 * (1.0 - wo.dot(n)).powi(5);
        assert!((s.weight.x - fresnel).abs() < 1e-5, "{} against {fresnel}", s.weight.x);
        // Not a direction, or one below the base: the base's normal.
        assert_eq!(smooth.with_coat_normal(Vec3::ZERO).coat_normal, Vec3::Z);
        assert_eq!(smooth.with_coat_normal(Vec3::new(1.0, 0.0, -0.1)).coat_normal, Vec3::Z);
        assert_eq!(smooth.with_coat_normal(Vec3::new(0.0, 0.0, 2.0)).coat_normal, Vec3::Z);
    }

    /// A smooth coat over black reflects c·F_c: 4% at normal incidence, all
    /// of it at grazing (the extension's Fresnel), half as much at c = 0.5.
    #[test]
    fn smooth_coat_fresnel_at_normal_and_grazing_incidence() {
        let c = coated(Bsdf::diffuse(Rgb::ZERO), 1.0, 0.0);
        assert!((c.coat_fresnel(1.0) - 0.04).abs() < 1e-6);
        assert!((c.coat_fresnel(0.0) - 1.0).abs() < 1e-6);
        let s = c.sample(Vec3::Z, 0.0, Vec2::ZERO).unwrap();
        assert!(s.is_delta && (s.weight - Rgb::splat(0.04 / s.pdf)).abs().max_element() < 1e-5);
        // Over black the coat is all there is: always chosen, weight F_c.
        assert!((s.pdf - 1.0).abs() < 1e-6 && (s.weight.x - 0.04).abs() < 1e-6);
        let grazing = direction_at(89.9);
        let g = c.sample(grazing, 0.0, Vec2::ZERO).unwrap();
        assert!(g.weight.x > 0.99 && g.weight.x <= 1.0, "{}", g.weight.x);
        let half = coated(Bsdf::diffuse(Rgb::ZERO), 0.5, 0.0);
        assert!((half.coat_fresnel(1.0) - 0.02).abs() < 1e-6);
        // Under a coat of factor 1, a white Lambertian base seen and lit at
        // normal incidence keeps (1 − 0.04)²/(1 − E) of f, E = 0.04 + 0.96/21.
        let white = coated(Bsdf::diffuse(Rgb::ONE), 1.0, 0.5);
        let ratio = white.base_f(Vec3::Z, Vec3::Z, 1.0).x;
        let coated_diffuse = white.f(Vec3::Z, Vec3::Z).x - white.coat_lobe(Vec3::Z, Vec3::Z);
        let e = 0.04 + 0.96 / 21.0;
        assert!((coated_diffuse / ratio - 0.96 * 0.96 / (1.0 - e)).abs() < 1e-5);
    }

    /// What the coat leaves of a Lambertian base, integrated over the
    /// light's directions, is T(θo) times its albedo (Cycles' dimming by
    /// the view's coat reflectance); with a smooth coat a white Lambertian
    /// and a white mirror reflect exactly 1 at every angle.
    #[test]
    fn smooth_coats_over_white_bases_conserve_energy_exactly() {
        let lambert = coated(Bsdf::diffuse(Rgb::splat(0.5)), 1.0, 0.3);
        for deg in [0.0, 40.0, 75.0] {
            let wo = direction_at(deg);
            let under = integrate_about(Vec3::Z, |wi| {
                (mean(lambert.under_coat(wo, wi, wo, wi, lambert.f_lobes(wo, wi, 1.0))) * wi.z.max(0.0)) as f64
            });
            let want = 0.5 * lambert.coat_transmission(wo.z) as f64;
            assert!((under - want).abs() < 1e-3, "{deg}°: {under} against {want}");
        }
        // Under a coat tilted 17° (and one tilted 40°) still T(θo), θo
        // taken to the coat's normal.
        for n in [tilt(), Vec3::new(0.0, 40f32.to_radians().sin(), 40f32.to_radians().cos())] {
            let tilted = lambert.with_coat_normal(n);
            for deg in [0.0, 40.0, 75.0] {
                let wo = direction_at(deg);
                let under = integrate_about(Vec3::Z, |wi| {
                    let (co, ci) = (tilted.to_coat(wo), tilted.to_coat(wi));
                    (mean(tilted.under_coat(wo, wi, co, ci, tilted.f_lobes(wo, wi, 1.0))) * wi.z.max(0.0)) as f64
                });
                let want = 0.5 * tilted.coat_transmission(tilted.to_coat(wo).z) as f64;
                assert!((under - want).abs() < 1e-3, "tilt {n}, {deg}°: {under} against {want}");
            }
        }
        for base in [Bsdf::diffuse(Rgb::ONE), Bsdf::mirror(Rgb::ONE)] {
            let c = coated(base, 1.0, 0.0);
            for deg in [0.0, 30.0, 60.0, 80.0, 88.0] {
                let albedo = albedo_by_quadrature(&c, direction_at(deg));
                assert!((albedo - 1.0).abs() < 2e-3, "{base:?} at {deg}°: {albedo}");
            }
        }
    }

    /// A coat of factor 0 is no coat: f, pdf and samples are the base's to
    /// the bit (so uncoated scenes render as before).
    #[test]
    fn zero_coat_is_the_base() {
        let base = Bsdf::new(Rgb::new(0.7, 0.4, 0.2), 0.3, 0.2, 1.0);
        let zero = base.with_clearcoat(0.0, 0.3);
        let mut rng = Rng::for_item(0xC0A6, 0);
        for _ in 0..200 {
            let (wo, wi) = (direction_at(80.0 * rng.next_f32()), direction_at(80.0 * rng.next_f32()));
            assert_eq!(zero.f(wo, wi), base.f(wo, wi));
            assert_eq!(zero.pdf(wo, wi), base.pdf(wo, wi));
            let (u_lobe, u) = (rng.next_f32(), rng.next_2d());
            assert_eq!(zero.sample(wo, u_lobe, u), base.sample(wo, u_lobe, u));
            assert_eq!(zero.sample_followed(wo, u), base.sample_followed(wo, u));
        }
    }

    #[test]
    fn samples_match_their_density() {
        for (base, clearcoat, roughness, deg) in [
            (Bsdf::new(Rgb::new(0.8, 0.3, 0.1), 0.0, 0.8, 1.0), 1.0, 0.2, 30.0),
            (Bsdf::new(Rgb::new(0.9, 0.9, 0.9), 1.0, 0.5, 1.0), 0.7, 0.4, 70.0),
            (Bsdf::new(Rgb::new(0.8, 0.3, 0.1), 0.0, 0.8, 1.0), 1.0, 0.3, 31.0),
            (Bsdf::new(Rgb::new(0.2, 0.2, 0.2), 1.0, 0.6, 1.0), 1.0, 0.4, 65.0),
        ] {
            // Odd angles: under a coat tilted by a clear-coat normal texture.
            let tilted = deg as u32 % 2 == 1;
            let c = coated(base, clearcoat, roughness);
            let c = if tilted { c.with_coat_normal(tilt()) } else { c };
            let wo = direction_at(deg);
            let p_valid = integrate_about(mirror(wo), |wi| c.pdf(wo, wi) as f64) as f32;
            assert!(p_valid <= 1.0 + 1e-3 && p_valid > 0.9, "{p_valid}");
            let rng = RefCell::new(Rng::for_item(0xC0A7, deg as u64));
            let sample = |mut u: Vec2| loop {
                let u_lobe = rng.borrow_mut().next_f32();
                if let Some(s) = c.sample(wo, u_lobe, u) {
                    assert!(!s.is_delta);
                    return s.wi;
                }
                u = rng.borrow_mut().next_2d();
            };
            assert_direction_distribution(sample, |wi| c.pdf(wo, wi) / p_valid);
        }
    }

    /// Nothing is created: over a white rough metal and a white diffuse
    /// base the coated albedo stays at most 1, and f is reciprocal. Under
    /// a tilted coat the coat's lobe is weighed by the cosine to the
    /// shading normal, not to its own: seen at 80° it reflects up to 1.6%
    /// more than arrives (the gain of any bent normal kept reciprocal;
    /// Cycles weighs each closure by its own normal's cosine and gives up
    /// reciprocity instead), hence 2% there.
    #[test]
    fn white_furnace_and_reciprocity() {
        let bases = [Bsdf::new(Rgb::ONE, 1.0, 0.3, 1.0), Bsdf::diffuse(Rgb::ONE)];
        for c in
            bases.iter().flat_map(|&base| [coated(base, 1.0, 0.3), coated(base, 1.0, 0.3).with_coat_normal(tilt())])
        {
            for deg in [0.0, 45.0, 80.0] {
                let wo = direction_at(deg);
                let albedo = integrate_about(coat_mirror_of(&c, wo), |wi| (mean(c.f(wo, wi)) * wi.z.max(0.0)) as f64);
                let bound = if c.coat_normal != Vec3::Z && deg > 60.0 { 1.02 } else { 1.0 + 2e-3 };
                assert!(albedo <= bound, "{deg}°: {albedo}");
            }
            let mut rng = Rng::for_item(0xC0A8, 0);
            for _ in 0..500 {
                let (a, b) =
                    (crate::sampling::uniform_sphere(rng.next_2d()), crate::sampling::uniform_sphere(rng.next_2d()));
                let (a, b) = (Vec3::new(a.x, a.y, a.z.abs()), Vec3::new(b.x, b.y, b.z.abs()));
                let (x, y) = (c.f(a, b), c.f(b, a));
                assert!((x - y).abs().max_element() <= 1e-4 * x.max_element().max(1.0), "{x} {y}");
            }
        }
    }

    /// The mean sample weight is ∫ f cos dω by quadrature (plus the smooth
    /// coat's and base's mirrors): sampler, density and f agree.
    #[test]
    fn sampled_albedo_matches_quadrature() {
        for (c, deg) in [
            (coated(Bsdf::new(Rgb::new(0.8, 0.4, 0.2), 0.0, 0.6, 1.0), 1.0, 0.25), 40.0),
            (coated(Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.4, 1.0), 0.8, 0.0), 60.0),
            (coated(Bsdf::new(Rgb::new(0.5, 0.6, 0.7), 1.0, 0.0, 1.0), 1.0, 0.0), 50.0),
            (coated(Bsdf::new(Rgb::new(0.8, 0.4, 0.2), 0.0, 0.6, 1.0), 1.0, 0.25).with_coat_normal(tilt()), 41.0),
            (coated(Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.4, 1.0), 0.8, 0.0).with_coat_normal(tilt()), 61.0),
            (coated(Bsdf::new(Rgb::new(0.5, 0.6, 0.7), 1.0, 0.0, 1.0), 1.0, 0.0).with_coat_normal(tilt()), 51.0),
        ] {
            let wo = direction_at(deg);
            let quadrature = albedo_by_quadrature(&c, wo);
            let (m, error) = mean_weight(200_000, 0xC0A9 + deg as u64, |u_lobe, u| {
                c.sample(wo, u_lobe, u).map_or(0.0, |s| mean(s.weight) as f64)
            });
            assert!(
                (m - quadrature).abs() < 4.0 * error + 2e-3,
                "{deg}°: sampled {m} ± {error}, quadrature {quadrature}"
            );
        }
    }

    /// The directional albedo at `wo`: ∫ f cos dω by quadrature, plus what
    /// the delta lobes (a smooth coat, a smooth base mirror under the coat)
    /// reflect.
    fn albedo_by_quadrature(c: &Bsdf, wo: Vec3) -> f64 {
        let co = c.to_coat(wo);
        let coat_mirror = coat_mirror_of(c, wo);
        let coat = if c.coat_is_smooth() && coat_mirror.z > 0.0 { c.coat_fresnel(co.z) } else { 0.0 };
        let t = c.coat_transmission(wo.z);
        let base = if c.is_delta() { mean(c.specular_fresnel(wo.z)) * t } else { 0.0 };
        let lobes = integrate_about(mirror(wo), |wi| (mean(c.f(wo, wi)) * wi.z.max(0.0)) as f64);
        lobes + (coat + base) as f64
    }

    /// photon-cpu's split adds up: the gathered part's albedo plus the mean
    /// weight of the followed samples is the whole albedo, for a smooth,
    /// a followed-glossy and a gathered coat over bases of each kind.
    #[test]
    fn gathered_and_followed_parts_add_up_to_the_whole() {
        for (c, deg) in [
            (coated(Bsdf::new(Rgb::new(0.8, 0.4, 0.2), 0.0, 0.6, 1.0), 1.0, 0.0), 30.0),
            (coated(Bsdf::new(Rgb::new(0.8, 0.4, 0.2), 0.0, 0.6, 1.0), 0.7, 0.2), 60.0),
            (coated(Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.2, 1.0), 1.0, 0.1), 45.0),
            (coated(Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.0, 1.0), 1.0, 0.5), 45.0),
            (coated(Bsdf::new(Rgb::new(0.3, 0.5, 0.9), 0.0, 0.8, 1.0), 1.0, 0.6), 70.0),
            (coated(Bsdf::new(Rgb::new(0.8, 0.4, 0.2), 0.0, 0.6, 1.0), 0.7, 0.2).with_coat_normal(tilt()), 60.0),
            (coated(Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.0, 1.0), 1.0, 0.5).with_coat_normal(tilt()), 45.0),
            (coated(Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.2, 1.0), 1.0, 0.0).with_coat_normal(tilt()), 35.0),
        ] {
            let wo = direction_at(deg);
            let whole = albedo_by_quadrature(&c, wo);
            let gathered = integrate_about(mirror(wo), |wi| (mean(c.f_gathered(wo, wi)) * wi.z.max(0.0)) as f64);
            let (followed, error) = mean_weight(200_000, 0xC0AA + deg as u64, |_, u| {
                c.sample_followed(wo, u).map_or(0.0, |s| mean(s.weight) as f64)
            });
            assert_eq!(c.follows_any(), followed > 0.0, "{c:?}");
            assert!(
                (gathered + followed - whole).abs() < 4.0 * error + 2e-3,
                "{c:?} at {deg}°: gathered {gathered} + followed {followed} ± {error} against {whole}"
            );
        }
    }
}
