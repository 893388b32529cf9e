//! The Trowbridge–Reitz (GGX) microfacet distribution, isotropic, in the
//! local shading frame (normal +z).
//!
//! * `d`: the distribution of normals D(h) = α² / (π ((n·h)²(α² − 1) + 1)²).
//! * `lambda`: Smith's Λ(w) = (√(1 + α² tan²θ) − 1) / 2, from which
//!   G1 = 1/(1 + Λ) and the height-correlated G2 = 1/(1 + Λ(wo) + Λ(wi))
//!   (Heitz 2014, "Understanding the Masking-Shadowing Function in
//!   Microfacet-Based BRDFs").
//! * `visibility`: V = G2 / (4 |n·wo| |n·wi|), written without the division
//!   so it stays finite at grazing angles.
//! * `sample_visible_normal`: Heitz 2018, "Sampling the GGX Distribution of
//!   Visible Normals" (JCGT 7(4)), whose density is the visible-normal
//!   distribution D_wo(h) = G1(wo) max(0, wo·h) D(h) / (n·wo); reflecting wo
//!   about h gives wi with density D_wo(h) / (4 |wo·h|) (`reflection_pdf`).
//!
//! `1 − z²` is computed as `x² + y²` throughout: for the small α of nearly
//! smooth surfaces the peak of D is decided by sin²θ ≈ α², below what
//! `1 − z²` can resolve in f32.

use crate::sampling::unit_circle;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// sin²θ of a unit vector, without the cancellation of 1 − cos²θ.
fn sin2(w: Vec3) -> f32 {
    w.x * w.x + w.y * w.y
}

/// D(h): density of microfacet normals per unit projected area and steradian
/// (∫ D(h) (n·h) dω_h = 1); zero below the surface.
pub fn d(h: Vec3, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    // (n·h)²(α² − 1) + 1 = α² cos²θ + sin²θ for unit h.
    let t = a2 * h.z * h.z + sin2(h);
    a2 / (PI * t * t)
}

/// Smith's Λ(w); infinite for directions in the tangent plane.
pub fn lambda(w: Vec3, alpha: f32) -> f32 {
    let z2 = w.z * w.z;
    if z2 == 0.0 {
        return f32::INFINITY;
    }
    let tan2 = sin2(w) / z2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Smith's masking G1(w) = 1/(1 + Λ(w)).
pub fn g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + lambda(w, alpha))
}

/// Height-correlated masking–shadowing G2(wo, wi) = 1/(1 + Λ(wo) + Λ(wi)).
pub fn g2(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + lambda(wo, alpha) + lambda(wi, alpha))
}

/// V = G2 / (4 |n·wo| |n·wi|), both directions above the surface (zero
/// otherwise). With √(z² + α² sin²θ) = z √(1 + α² tan²θ) the division by the
/// cosines cancels: V = 1 / (2 (z_i √(z_o² + α² sin²θ_o) + z_o √(z_i² + α² sin²θ_i))),
/// the form of the Khronos sample renderer's `V_GGX`.
pub fn visibility(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let lo = (wo.z * wo.z + a2 * sin2(wo)).sqrt();
    let li = (wi.z * wi.z + a2 * sin2(wi)).sqrt();
    0.5 / (wi.z * lo + wo.z * li)
}

/// A microfacet normal drawn from the normals visible from `wo` (wo.z > 0),
/// after Heitz 2018, listing 1. Density: `visible_normal_pdf`.
pub fn sample_visible_normal(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    // Stretch the view direction so that the distribution becomes the α = 1
    // one: a hemisphere of normals seen from `vh`.
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    // An orthonormal basis around vh (any tangent at normal incidence).
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    // A uniform point on the projected disk; its lower half is squeezed into
    // the part of the hemisphere's projection not hidden by its own rim.
    let disk = unit_circle(u.y) * u.x.sqrt();
    let s = 0.5 * (1.0 + vh.z);
    let p1 = disk.x;
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * disk.y;
    // Back onto the hemisphere, then un-stretch.
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// D_wo(h) = G1(wo) max(0, wo·h) D(h) / (n·wo): the density, per steradian
/// of h, of `sample_visible_normal`.
pub fn visible_normal_pdf(wo: Vec3, h: Vec3, alpha: f32) -> f32 {
    if wo.z <= 0.0 {
        return 0.0;
    }
    g1(wo, alpha) * wo.dot(h).max(0.0) * d(h, alpha) / wo.z
}

/// Mirror reflection of `wo` about the unit normal `h`: 2(wo·h)h − wo.
pub fn reflect(wo: Vec3, h: Vec3) -> Vec3 {
    2.0 * wo.dot(h) * h - wo
}

/// Density, per steradian of wi, of wi = reflect(wo, h) with h from
/// `sample_visible_normal`: D_wo(h) / (4 |wo·h|) (the Jacobian of the
/// reflection), which simplifies to G1(wo) D(h) / (4 n·wo).
pub fn reflection_pdf(wo: Vec3, h: Vec3, alpha: f32) -> f32 {
    if wo.z <= 0.0 || wo.dot(h) <= 0.0 {
        return 0.0;
    }
    g1(wo, alpha) * d(h, alpha) / (4.0 * wo.z)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sampling::chi2::{assert_direction_distribution, assert_unit_density};
    use std::f64::consts::PI as PI64;

    /// A unit direction at polar angle `deg` and a fixed, non-zero azimuth
    /// (so the sampler's basis is not aligned with the axes).
    pub(crate) fn direction_at(deg: f32) -> Vec3 {
        let (theta, phi) = (deg.to_radians(), 0.7f32);
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    const ALPHAS: [f32; 3] = [0.05, 0.3, 1.0];
    const ANGLES: [f32; 3] = [0.0, 45.0, 80.0];

    /// h ↦ h' = normalize(h.x/α, h.y/α, h.z): the stretch under which GGX of
    /// any α becomes GGX of α = 1, so narrow lobes fill the chi-square bins.
    fn stretch(h: Vec3, alpha: f32) -> Vec3 {
        Vec3::new(h.x / alpha, h.y / alpha, h.z).normalize()
    }

    /// The density of h' = stretch(h) given the density of h: with
    /// h = M h' / |M h'|, M = diag(α, α, 1), dω_h/dω_h' = det M / |M h'|³.
    fn stretched_pdf(pdf_h: impl Fn(Vec3) -> f32, alpha: f32) -> impl Fn(Vec3) -> f32 {
        move |hs: Vec3| {
            if hs.z <= 0.0 {
                return 0.0;
            }
            let m = Vec3::new(alpha * hs.x, alpha * hs.y, hs.z);
            let len = m.length();
            pdf_h(m / len) * alpha * alpha / (len * len * len)
        }
    }

    #[test]
    fn visible_normals_match_their_density() {
        // Chi-square in stretched space (see `stretch`): at α = 0.05 the
        // lobe is narrower than one (cos θ, φ) bin of the helper.
        for alpha in ALPHAS {
            for deg in ANGLES {
                println!("alpha {alpha}, theta_o {deg}°");
                let wo = direction_at(deg);
                let pdf = stretched_pdf(move |h| visible_normal_pdf(wo, h, alpha), alpha);
                assert_unit_density(&pdf);
                assert_direction_distribution(|u| stretch(sample_visible_normal(wo, alpha, u), alpha), &pdf);
            }
        }
    }

    #[test]
    fn reflected_directions_match_their_density() {
        // Unstretched, over the whole sphere (reflections may point below
        // the surface): checks the 1/(4 |wo·h|) Jacobian. α = 0.05 is too
        // narrow for the helper's bins and is covered by the test above.
        for alpha in [0.3, 1.0] {
            for deg in ANGLES {
                println!("alpha {alpha}, theta_o {deg}°");
                let wo = direction_at(deg);
                let pdf = move |wi: Vec3| {
                    let sum = wo + wi;
                    if sum.length_squared() < 1e-12 { 0.0 } else { reflection_pdf(wo, sum.normalize(), alpha) }
                };
                assert_unit_density(pdf);
                assert_direction_distribution(|u| reflect(wo, sample_visible_normal(wo, alpha, u)), pdf);
            }
        }
    }

    /// ∫ g(h) dω_h over the upper hemisphere by the midpoint rule in
    /// (ψ, φ) with tan θ = α tan ψ: the substitution spreads a lobe of width
    /// α over the whole ψ range, however small α is.
    pub(crate) fn integrate_half_vectors(alpha: f32, g: impl Fn(Vec3) -> f64) -> f64 {
        const N_PSI: usize = 600;
        const N_PHI: usize = 300;
        let alpha = alpha as f64;
        let mut sum = 0.0;
        for i in 0..N_PSI {
            let psi = (i as f64 + 0.5) / N_PSI as f64 * PI64 / 2.0;
            let theta = (alpha * psi.tan()).atan();
            // dθ/dψ = α sec²ψ / (1 + α² tan²ψ)
            let dtheta_dpsi = alpha / (psi.cos().powi(2) * (1.0 + (alpha * psi.tan()).powi(2)));
            let weight = theta.sin() * dtheta_dpsi * (PI64 / 2.0 / N_PSI as f64) * (2.0 * PI64 / N_PHI as f64);
            for j in 0..N_PHI {
                let phi = (j as f64 + 0.5) / N_PHI as f64 * 2.0 * PI64;
                let h =
                    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                sum += g(h) * weight;
            }
        }
        sum
    }

    #[test]
    fn distribution_and_visible_normals_integrate_to_one() {
        // ∫ D(h) cos θ_h dω_h = 1 (projected area), and the visible-normal
        // density integrates to one for every view: the latter only holds if
        // G1 is the Smith masking that belongs to D. α = 0.0025 is the
        // smooth threshold's (bsdf::SMOOTH_ROUGHNESS = 0.05).
        let mut worst = 0.0f64;
        for alpha in [0.0025, 0.05, 0.3, 1.0] {
            let projected = integrate_half_vectors(alpha, |h| (d(h, alpha) * h.z) as f64);
            worst = worst.max((projected - 1.0).abs());
            for deg in [0.0, 45.0, 80.0, 89.0] {
                let wo = direction_at(deg);
                let total = integrate_half_vectors(alpha, |h| visible_normal_pdf(wo, h, alpha) as f64);
                println!("alpha {alpha}, theta_o {deg}°: ∫ D_wo = {total:.6}, ∫ D cos = {projected:.6}");
                worst = worst.max((total - 1.0).abs());
            }
        }
        assert!(worst < 1e-3, "worst deviation from 1: {worst:e}");
    }

    #[test]
    fn visibility_is_g2_over_the_cosines() {
        let mut rng = crate::sampling::Rng::for_item(11, 0);
        for _ in 0..1000 {
            let alpha = 0.01 + rng.next_f32();
            let wo = crate::sampling::cosine_hemisphere(rng.next_2d());
            let wi = crate::sampling::cosine_hemisphere(rng.next_2d());
            let expected = g2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
            let v = visibility(wo, wi, alpha);
            assert!((v - expected).abs() <= 1e-4 * expected, "V {v} vs G2/(4 cos cos) {expected}");
            // Height correlation never shadows more than the two G1 alone.
            let g = g2(wo, wi, alpha);
            assert!(g <= g1(wo, alpha).min(g1(wi, alpha)) + 1e-6 && g >= g1(wo, alpha) * g1(wi, alpha) - 1e-6);
        }
        // At normal incidence nothing is masked.
        assert_eq!(g1(Vec3::Z, 0.7), 1.0);
    }
}
