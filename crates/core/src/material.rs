//! Surface materials: a closed set, as in METHOD.md §2.
//!
//! `Pbr` is the glTF 2.0 metallic–roughness model ([`crate::bsdf::Bsdf`]:
//! Lambert plus a GGX lobe), which glTF files use. `Diffuse` is Lambertian
//! with an optional perfect-mirror part (ρ_d + ρ_s ≤ 1 per channel),
//! `Mirror` a perfect mirror (both the `Bsdf` settings `diffuse` and
//! `mirror` up to the mirror's Fresnel; they stay separate variants until the
//! GPU renderer evaluates `Bsdf`), `Glass` a dielectric boundary
//! ([`Dielectric`]: Fresnel reflection and tinted refraction, smooth or
//! GGX-rough).

use crate::bsdf::Bsdf;
use crate::bsdf::dielectric::Dielectric;
use glam::Vec3;

pub type Rgb = Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    Diffuse {
        albedo: Rgb,
        specular: Rgb,
    },
    Mirror {
        reflectance: Rgb,
    },
    /// Glass: reflects and refracts (`KHR_materials_transmission`).
    Glass(Dielectric),
    /// The glTF metallic–roughness BRDF.
    Pbr(Bsdf),
    /// Black, non-reflecting surface: the body of an area light.
    Emitter,
}

/// What a photon or path does at a surface, chosen by Russian roulette.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    Diffuse,
    Specular,
    Absorbed,
}

impl Material {
    /// Clear smooth glass of index `ior`.
    pub fn glass(ior: f32) -> Material {
        Material::Glass(Dielectric::clear(ior))
    }

    /// The glTF BRDF `bsdf` as a material: `Pbr`, or `Diffuse` when it is
    /// exactly Lambertian (a dielectric without specular lobe: f = base/π
    /// whatever the roughness), which every renderer, the GPU's included,
    /// draws exactly.
    pub fn from_bsdf(bsdf: Bsdf) -> Material {
        if bsdf.metallic == 0.0 && bsdf.specular == 0.0 && !bsdf.has_coat() {
            Material::Diffuse { albedo: bsdf.base_color, specular: Rgb::ZERO }
        } else {
            Material::Pbr(bsdf)
        }
    }

    /// Diffuse reflectance ρ_d (zero for purely specular materials).
    /// For `Pbr`, the diffuse lobe's reflectance at normal incidence.
    pub fn diffuse_albedo(&self) -> Rgb {
        match self {
            Material::Diffuse { albedo, .. } => *albedo,
            Material::Pbr(bsdf) => bsdf.lambert_albedo(),
            _ => Rgb::ZERO,
        }
    }

    /// Mirror reflectance ρ_s of diffuse/mirror materials; for a smooth
    /// `Pbr` lobe, its reflectance at normal incidence.
    pub fn mirror_reflectance(&self) -> Rgb {
        match self {
            Material::Diffuse { specular, .. } => *specular,
            Material::Mirror { reflectance } => *reflectance,
            Material::Pbr(bsdf) if bsdf.is_delta() => bsdf.normal_reflectance(),
            _ => Rgb::ZERO,
        }
    }

    /// Has a diffuse part, so photons are stored here and the estimate applies.
    pub fn is_diffuse(&self) -> bool {
        match self {
            Material::Pbr(bsdf) => bsdf.stores_photons(),
            _ => self.diffuse_albedo().max_element() > 0.0,
        }
    }

    /// Russian roulette over diffuse/specular/absorbed with the RGB rule of
    /// METHOD.md §2: scalar probabilities are channel means; the returned
    /// factor (ρ/P per channel) multiplies the photon power so the estimate
    /// stays unbiased. Glass is handled by Fresnel instead.
    pub fn roulette(&self, xi: f32) -> (Event, Rgb) {
        let rho_d = self.diffuse_albedo();
        let rho_s = self.mirror_reflectance();
        let p_d = mean(rho_d);
        let p_s = mean(rho_s);
        if xi < p_d {
            (Event::Diffuse, rho_d / p_d)
        } else if xi < p_d + p_s {
            (Event::Specular, rho_s / p_s)
        } else {
            (Event::Absorbed, Rgb::ZERO)
        }
    }
}

pub fn mean(c: Rgb) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// Perfect mirror reflection of `dir` (propagation direction) about `n`.
pub fn reflect(dir: Vec3, n: Vec3) -> Vec3 {
    dir - 2.0 * dir.dot(n) * n
}

/// Fresnel reflectance of an unpolarised wave at a smooth dielectric boundary.
/// `cos_i` ≥ 0 is the cosine on the incident side, `eta` = n_incident/n_transmitted.
/// Returns (reflectance, cos_t); reflectance 1 means total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> (f32, f32) {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_par = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (0.5 * (r_par * r_par + r_perp * r_perp), cos_t)
}

/// The two directions leaving a smooth dielectric hit by `dir`.
pub struct DielectricSplit {
    pub reflectance: f32,
    pub reflected: Vec3,
    /// None under total internal reflection.
    pub refracted: Option<Vec3>,
}

/// Splits `dir` at a glass surface with outward normal `n_out` and index `ior`.
pub fn dielectric_split(dir: Vec3, n_out: Vec3, ior: f32) -> DielectricSplit {
    let entering = dir.dot(n_out) < 0.0;
    let (n, eta) = if entering { (n_out, 1.0 / ior) } else { (-n_out, ior) };
    let cos_i = -dir.dot(n);
    let (reflectance, cos_t) = fresnel_dielectric(cos_i, eta);
    let reflected = reflect(dir, n);
    let refracted = (reflectance < 1.0).then(|| (eta * dir + (eta * cos_i - cos_t) * n).normalize());
    DielectricSplit { reflectance, reflected, refracted }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_normal_incidence_and_tir() {
        let (r, _) = fresnel_dielectric(1.0, 1.0 / 1.5);
        assert!((r - 0.04).abs() < 1e-4);
        // Inside glass beyond the critical angle (41.8°): total internal reflection.
        let cos_i = 50f32.to_radians().cos();
        assert_eq!(fresnel_dielectric(cos_i, 1.5).0, 1.0);
    }

    #[test]
    fn refraction_obeys_snell() {
        let theta_i = 30f32.to_radians();
        let dir = Vec3::new(theta_i.sin(), -theta_i.cos(), 0.0);
        let split = dielectric_split(dir, Vec3::Y, 1.5);
        let t = split.refracted.unwrap();
        let sin_t = t.x;
        assert!((theta_i.sin() - 1.5 * sin_t).abs() < 1e-5);
        assert!(t.y < 0.0);
        assert!((split.reflected - Vec3::new(dir.x, -dir.y, 0.0)).length() < 1e-6);
    }

    #[test]
    fn roulette_factor_keeps_expectation() {
        let m = Material::Diffuse { albedo: Vec3::new(0.8, 0.2, 0.5), specular: Vec3::new(0.1, 0.3, 0.0) };
        let n = 10_000;
        let mut total = Vec3::ZERO;
        for i in 0..n {
            let (e, f) = m.roulette((i as f32 + 0.5) / n as f32);
            if e != Event::Absorbed {
                total += f;
            }
        }
        let expected = m.diffuse_albedo() + m.mirror_reflectance();
        assert!((total / n as f32 - expected).abs().max_element() < 1e-3);
    }
}
