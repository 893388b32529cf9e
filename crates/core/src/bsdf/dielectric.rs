//! Glass: a dielectric boundary that reflects and transmits, smooth or
//! rough, with coloured transmission.
//!
//! # The model
//!
//! glTF's `KHR_materials_transmission` (and Cycles' Principled BSDF at
//! transmission 1): Fresnel reflection, white, and transmission tinted at
//! each crossing by the square root of the base colour, so that a solid
//! piece seen through shows the base colour (Cycles' Principled BSDF
//! tints so; glTF's thin-walled reading, one crossing by the base colour,
//! gives the same colour through a closed object). Below [`SMOOTH_ROUGHNESS`] both are
//! deltas (the mirror direction and Snell's refraction). Rougher glass is
//! Walter et al. 2007 ("Microfacet Models for Refraction through Rough
//! Surfaces") with the GGX distribution of α = roughness² and the
//! height-correlated G2, sampled through the normals visible from `wo`
//! (Heitz 2018), as pbrt-v4's `DielectricBxDF`:
//!
//! ```text
//! reflection    f_r = F(wo·h) D(h) G2 / (4 |cos θo| |cos θi|)              h ∝ wo + wi
//! transmission  f_t = tint (1 − F(wo·h)) D(h) G2 |wi·h| |wo·h|
//!                     / (|cos θo| |cos θi| (wi·h + wo·h/η')²)             h ∝ η' wi + wo
//! ```
//!
//! with η' = η(wi's side)/η(wo's side). Both lobes are chosen with the
//! probability of their Fresnel term at the sampled microfacet, so a
//! sample's weight is G2/G1(wo) (times the tint through the boundary).
//!
//! # Radiance and importance
//!
//! Radiance divided by η² is what a ray keeps across a boundary, so an eye
//! path that crosses into glass (η' = ior) carries 1/η'² of what it would
//! ([`Transport::Radiance`]); photons carry power, which crosses unchanged
//! ([`Transport::Importance`], the adjoint). The factor cancels on a path
//! that enters and leaves a closed object (a glass ball seen and lit from
//! outside); it matters where an eye path gathers or meets light inside
//! glass: a stone under water, a lamp inside a glass bulb.
//!
//! # Frames
//!
//! The local frame's +z is the boundary's **outward** normal (not turned
//! toward the viewer): `wo.z > 0` means `wo` is outside (index 1), below it
//! is inside (index `ior`). `wo` and `wi` point away from the surface.

use super::ShadingFrame;
use super::ggx;
use super::{ALPHA_MIN, SMOOTH_ROUGHNESS};
use crate::material::{Rgb, dielectric_split, fresnel_dielectric};
use glam::{Vec2, Vec3};

/// Which quantity a path carries through a boundary (pbrt's `TransportMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// Eye paths: radiance, which scales by 1/η'² across the boundary.
    Radiance,
    /// Photon (light) paths: power, which does not.
    Importance,
}

/// A glass surface: index of refraction, perceptual roughness (GGX α =
/// roughness²), the colour seen through a solid piece of it (each
/// crossing tints by its square root) and what its inside absorbs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    pub ior: f32,
    pub roughness: f32,
    pub tint: Rgb,
    /// Absorption coefficient of the glass's inside, per scene unit
    /// (`KHR_materials_volume`: −ln(attenuationColor) / attenuationDistance;
    /// zero: clear): light crossing a length d of it keeps e^(−σ·d)
    /// ([`Dielectric::interior_transmittance`]), coloured glass as thick
    /// parts look darker.
    pub absorption: Rgb,
}

/// A direction drawn by [`Dielectric::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlassSample {
    /// The continuation direction (local frame).
    pub wi: Vec3,
    /// f·|cos θi|/pdf: what the path's throughput is multiplied by.
    pub weight: Rgb,
    /// Density per steradian of `wi` (equal to `Dielectric::pdf`); for a
    /// smooth boundary the probability of the lobe chosen.
    pub pdf: f32,
    /// The smooth boundary's mirror or refraction: no density, no MIS.
    pub is_delta: bool,
    /// `wi` crossed the boundary.
    pub transmitted: bool,
    /// η' of the crossing, η(wi's side)/η(wo's side); 1 for a reflection.
    /// Radiance carried across is 1/η'² of what it was (pbrt's `etaScale`).
    pub eta: f32,
}

impl Dielectric {
    /// Clear smooth glass of index `ior`.
    pub fn clear(ior: f32) -> Self {
        Dielectric { ior, roughness: 0.0, tint: Rgb::ONE, absorption: Rgb::ZERO }
    }

    /// What reaches a hit on this glass of geometric normal `ng` at
    /// distance `t` along `dir` of what left the ray's origin: e^(−σ·t)
    /// where the ray arrives from inside (along `ng`, which points out),
    /// having crossed t of the glass (Beer–Lambert); 1 from outside. Every
    /// renderer applies it on arriving at glass (the WGSL twin is
    /// dielectric.wgsl's `glass_interior_transmittance`), so a closed glass
    /// mesh absorbs along each segment inside it.
    pub fn interior_transmittance(&self, dir: Vec3, ng: Vec3, t: f32) -> Rgb {
        if dir.dot(ng) <= 0.0 || self.absorption == Rgb::ZERO {
            return Rgb::ONE;
        }
        (-self.absorption * t).exp()
    }

    /// Both lobes are deltas.
    pub fn is_smooth(&self) -> bool {
        self.roughness < SMOOTH_ROUGHNESS
    }

    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(ALPHA_MIN)
    }

    /// η' for a transmission from `wo`'s side: η(other side)/η(wo's side).
    fn eta_across(&self, wo_z: f32) -> f32 {
        if wo_z > 0.0 { self.ior } else { 1.0 / self.ior }
    }

    /// What transmission multiplies a path's throughput by, besides 1 − F
    /// and the microfacet terms: √tint, and 1/η'² for radiance.
    fn transmission_factor(&self, eta: f32, mode: Transport) -> Rgb {
        let tint = Rgb::new(self.tint.x.sqrt(), self.tint.y.sqrt(), self.tint.z.sqrt());
        match mode {
            Transport::Radiance => tint / (eta * eta),
            Transport::Importance => tint,
        }
    }

    /// A continuation direction for a path arriving from `wo`: `u_lobe`
    /// chooses reflection or transmission, `u` the microfacet. None where
    /// the sampled direction falls on the wrong side (energy the
    /// single-scattering model loses) or `wo` is in the tangent plane.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2, mode: Transport) -> Option<GlassSample> {
        if wo.z == 0.0 {
            return None;
        }
        let eta = self.eta_across(wo.z);
        // Work with wo above the boundary: the distribution is symmetric
        // under z ↦ −z, so flipping back the result is exact.
        if self.is_smooth() {
            return Some(self.split(-wo, Vec3::Z, u_lobe, mode));
        }
        let flip = if wo.z > 0.0 { 1.0 } else { -1.0 };
        let up = |w: Vec3| Vec3::new(w.x, w.y, w.z * flip);
        let wo_up = up(wo);
        let alpha = self.alpha();
        let h = ggx::sample_visible_normal(wo_up, alpha, u);
        let cos_oh = wo_up.dot(h);
        if cos_oh <= 0.0 {
            return None;
        }
        let (reflectance, cos_t) = fresnel_dielectric(cos_oh, 1.0 / eta);
        let (wi_up, transmitted) = if u_lobe < reflectance {
            (ggx::reflect(wo_up, h), false)
        } else {
            (-wo_up / eta + (cos_oh / eta - cos_t) * h, true)
        };
        // Reflections must stay above, refractions go below.
        if (wi_up.z > 0.0) == transmitted || wi_up.z == 0.0 {
            return None;
        }
        let wi = up(wi_up);
        let (f, pdf) = self.f_and_pdf(wo, wi, mode);
        if !(pdf > 0.0) {
            return None;
        }
        let eta = if transmitted { eta } else { 1.0 };
        Some(GlassSample { wi, weight: f * (wi.z.abs() / pdf), pdf, is_delta: false, transmitted, eta })
    }

    /// [`Self::sample`] in world space, for a path travelling along `dir`
    /// that meets the boundary of outward normal `n_out`. A smooth boundary
    /// is split in world space ([`dielectric_split`]: the arithmetic the
    /// GPU's shaders mirror, so both trace the same photons to the bit).
    pub fn sample_world(&self, dir: Vec3, n_out: Vec3, u_lobe: f32, u: Vec2, mode: Transport) -> Option<GlassSample> {
        if self.is_smooth() {
            return Some(self.split(dir, n_out, u_lobe, mode));
        }
        let frame = ShadingFrame::new(n_out);
        let s = self.sample(frame.to_local(-dir), u_lobe, u, mode)?;
        Some(GlassSample { wi: frame.to_world(s.wi), ..s })
    }

    /// The smooth boundary's choice: refraction where `u_lobe` ≥ R, else
    /// (and under total internal reflection) the mirror.
    fn split(&self, dir: Vec3, n_out: Vec3, u_lobe: f32, mode: Transport) -> GlassSample {
        let split = dielectric_split(dir, n_out, self.ior);
        match split.refracted {
            Some(wi) if u_lobe >= split.reflectance => {
                let eta = self.eta_across(-dir.dot(n_out));
                GlassSample {
                    wi,
                    weight: self.transmission_factor(eta, mode),
                    pdf: 1.0 - split.reflectance,
                    is_delta: true,
                    transmitted: true,
                    eta,
                }
            }
            _ => GlassSample {
                wi: split.reflected,
                weight: Rgb::ONE,
                pdf: split.reflectance,
                is_delta: true,
                transmitted: false,
                eta: 1.0,
            },
        }
    }

    /// Both directions a smooth boundary sends a path travelling along
    /// `dir` (outward normal `n_out`), each with what it multiplies the
    /// path by: the reflection's R, and the refraction's tinted 1 − R (over
    /// η'² for radiance), None under total internal reflection. For
    /// renderers that follow both (the eye rays of the photon mappers);
    /// `sample` picks one with these probabilities.
    pub fn smooth_branches(&self, dir: Vec3, n_out: Vec3, mode: Transport) -> ((Vec3, Rgb), Option<(Vec3, Rgb)>) {
        let split = dielectric_split(dir, n_out, self.ior);
        let factor = self.transmission_factor(self.eta_across(-dir.dot(n_out)), mode);
        let refracted = split.refracted.map(|wi| (wi, factor * (1.0 - split.reflectance)));
        ((split.reflected, Rgb::splat(split.reflectance)), refracted)
    }

    /// The microfacet normal of the pair (wo, wi) in the frame where wo is
    /// above, with the pair's Fresnel reflectance; None for pairs no
    /// microfacet joins (backfacing, or a smooth boundary).
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<Half> {
        if self.is_smooth() || wo.z == 0.0 || wi.z == 0.0 {
            return None;
        }
        let eta = self.eta_across(wo.z);
        let flip = if wo.z > 0.0 { 1.0 } else { -1.0 };
        let (wo, wi) = (Vec3::new(wo.x, wo.y, wo.z * flip), Vec3::new(wi.x, wi.y, wi.z * flip));
        let transmitted = wi.z < 0.0;
        let h = if transmitted { eta * wi + wo } else { wi + wo };
        let h = h.normalize_or_zero();
        let h = if h.z < 0.0 { -h } else { h };
        // Both directions on the side of the microfacet their own side is.
        let (cos_oh, cos_ih) = (wo.dot(h), wi.dot(h));
        if h.z == 0.0 || cos_oh <= 0.0 || (cos_ih > 0.0) == transmitted || cos_ih == 0.0 {
            return None;
        }
        let reflectance = fresnel_dielectric(cos_oh, 1.0 / eta).0;
        Some(Half { wo, wi, h, eta, cos_oh, cos_ih, reflectance, transmitted })
    }

    /// f(wo, wi) per steradian of the rough boundary (zero on a smooth one,
    /// whose lobes are deltas).
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: Transport) -> Rgb {
        self.half_vector(wo, wi).map_or(Rgb::ZERO, |p| self.f_at(&p, mode))
    }

    /// Density per steradian with which `sample` returns the non-delta `wi`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.half_vector(wo, wi).map_or(0.0, |p| self.pdf_at(&p))
    }

    /// Both, from one microfacet normal (what `sample` needs).
    fn f_and_pdf(&self, wo: Vec3, wi: Vec3, mode: Transport) -> (Rgb, f32) {
        self.half_vector(wo, wi).map_or((Rgb::ZERO, 0.0), |p| (self.f_at(&p, mode), self.pdf_at(&p)))
    }

    fn f_at(&self, p: &Half, mode: Transport) -> Rgb {
        let alpha = self.alpha();
        let dg = ggx::d(p.h, alpha) * ggx::g2(p.wo, p.wi, alpha);
        let cosines = (p.wo.z * p.wi.z).abs();
        if !p.transmitted {
            return Rgb::splat(p.reflectance * dg / (4.0 * cosines));
        }
        let denom = p.cos_ih + p.cos_oh / p.eta;
        let scalar = (1.0 - p.reflectance) * dg * (p.cos_ih * p.cos_oh).abs() / (cosines * denom * denom);
        self.transmission_factor(p.eta, mode) * scalar
    }

    fn pdf_at(&self, p: &Half) -> f32 {
        let visible = ggx::visible_normal_pdf(p.wo, p.h, self.alpha());
        if !p.transmitted {
            return p.reflectance * visible / (4.0 * p.cos_oh);
        }
        let denom = p.cos_ih + p.cos_oh / p.eta;
        (1.0 - p.reflectance) * visible * p.cos_ih.abs() / (denom * denom)
    }
}

/// A direction pair as seen from above (wo.z > 0), with its microfacet.
struct Half {
    wo: Vec3,
    wi: Vec3,
    h: Vec3,
    eta: f32,
    cos_oh: f32,
    cos_ih: f32,
    reflectance: f32,
    transmitted: bool,
}

#[cfg(test)]
mod tests;
