//! Sampling routines shared by photon tracing and the renderers.
//!
//! Every sampler maps uniform numbers in [0,1)² to a direction and states its
//! density with respect to solid angle; `chi2` tests check each one against
//! its stated density.

#[cfg(test)]
pub(crate) mod chi2;
pub mod cosine8;
mod equiangular;
mod rng;
mod sobol;

pub use equiangular::Equiangular;
pub use rng::Rng;
pub use sobol::SobolSampler;

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// PCG's output permutation as a hash (Jarzynski & Olano 2020, "Hash
/// Functions for GPU Rendering"); random.wgsl's `hash_u32`. What a ray
/// decides by without a random stream (`texture::blend_threshold`).
pub fn hash_u32(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A source of uniform numbers in [0, 1) for one path: independent ones
/// ([`Rng`]) or a quasi-random sample ([`SobolSampler`]).
pub trait Sampler {
    fn next_f32(&mut self) -> f32;

    fn next_2d(&mut self) -> Vec2 {
        let x = self.next_f32();
        Vec2::new(x, self.next_f32())
    }
}

impl Sampler for Rng {
    fn next_f32(&mut self) -> f32 {
        Rng::next_f32(self)
    }

    fn next_2d(&mut self) -> Vec2 {
        Rng::next_2d(self)
    }
}

/// An orthonormal basis whose third axis is `n` (Duff et al. 2017, branchless).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// Expresses a local direction (z = axis) in the frame around `axis`.
pub fn local_to_world(local: Vec3, axis: Vec3) -> Vec3 {
    let (t, b) = orthonormal_basis(axis);
    t * local.x + b * local.y + axis * local.z
}

/// (cos 2πu, sin 2πu) for u in [0, 1), within 2e-7 of the exact values.
///
/// Every bounce of every photon picks an azimuth, and libm's `sin_cos` was
/// 8% of photon-tracing time; this reduces to an octant (|angle| ≤ π/4) and
/// evaluates short Taylor polynomials there, which is exact enough for
/// sampling and several times cheaper.
pub fn unit_circle(u: f32) -> Vec2 {
    let x = u * 4.0;
    // Nearest quadrant by truncation (x ≥ 0): `round` is a libm call on
    // baseline x86-64.
    let quadrant = (x + 0.5) as i32;
    let a = (x - quadrant as f32) * (PI / 2.0);
    let a2 = a * a;
    let sin = a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362_880.0)))));
    let cos = 1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0))));
    // Rotate by the quadrant's multiple of π/2: (cos, sin), (−sin, cos),
    // (−cos, −sin), (sin, −cos). Written with bit masks, not a `match`:
    // the quadrant is random, and the jump table the `match` compiled to
    // was mispredicted three times in four (2.8 of the path tracer's 24
    // mispredicts a path on the Cornell box, scripts/count-path.sh).
    let odd = 0u32.wrapping_sub((quadrant & 1) as u32);
    let half_turn = ((quadrant & 2) as u32) << 30;
    let x = (cos.to_bits() & !odd) | ((-sin).to_bits() & odd);
    let y = (sin.to_bits() & !odd) | (cos.to_bits() & odd);
    Vec2::new(f32::from_bits(x ^ half_turn), f32::from_bits(y ^ half_turn))
}

/// Uniform direction on the unit sphere; density 1/(4π).
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    (unit_circle(u.y) * r).extend(z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Cosine-weighted direction about +z (METHOD.md §2, eq. 2.16):
/// θ = acos √ξ₁, φ = 2πξ₂; density cos θ / π.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let cos_theta = (1.0 - u.x).sqrt();
    let sin_theta = u.x.sqrt();
    (unit_circle(u.y) * sin_theta).extend(cos_theta)
}

pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) / PI
}

/// Uniform direction inside the cone of half-angle acos(`cos_max`) about +z;
/// density 1/(2π(1 − cos_max)).
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_theta = 1.0 - u.x * (1.0 - cos_max);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    (unit_circle(u.y) * sin_theta).extend(cos_theta)
}

pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// Power heuristic (β = 2) weight for a sample from strategy `f` against `g`.
pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    // As a ratio of the two, so that densities whose squares overflow (a
    // light of tiny area has a solid-angle density near 1e20) give a weight
    // instead of inf/inf.
    if pdf_f >= pdf_g {
        if pdf_f == 0.0 { 0.0 } else { 1.0 / (1.0 + (pdf_g / pdf_f).powi(2)) }
    } else {
        let r = pdf_f / pdf_g;
        r * r / (1.0 + r * r)
    }
}

#[cfg(test)]
mod tests {
    use super::chi2::{assert_direction_distribution, assert_unit_density};
    use super::*;

    #[test]
    fn power_heuristic_weights_sum_to_one_even_for_huge_densities() {
        for (a, b) in [(1.0f32, 1.0f32), (2.0, 1.0), (0.0, 3.0), (1e20, 3.0), (1e30, 1e29), (5.0, 0.0)] {
            let (wa, wb) = (power_heuristic(a, b), power_heuristic(b, a));
            assert!(wa.is_finite() && wb.is_finite() && (wa + wb - 1.0).abs() < 1e-6, "{a} {b}: {wa} {wb}");
        }
        assert!((power_heuristic(2.0, 1.0) - 0.8).abs() < 1e-6);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
    }

    #[test]
    fn unit_circle_matches_sin_cos() {
        let mut worst = 0.0f64;
        for i in 0..=100_000 {
            // The whole range, quadrant boundaries included, and a value just below 1.
            let u = if i == 100_000 { 1.0 - f32::EPSILON / 2.0 } else { i as f32 / 100_000.0 };
            let phi = 2.0 * std::f64::consts::PI * u as f64;
            let got = unit_circle(u);
            worst = worst.max((got.x as f64 - phi.cos()).abs()).max((got.y as f64 - phi.sin()).abs());
        }
        assert!(worst < 2e-7, "worst error {worst}");
    }

    #[test]
    fn basis_is_orthonormal() {
        let mut rng = Rng::for_item(5, 0);
        for _ in 0..1000 {
            let n = uniform_sphere(rng.next_2d());
            let (t, b) = orthonormal_basis(n);
            assert!(t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5 && t.dot(b).abs() < 1e-5);
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn uniform_sphere_matches_its_density() {
        assert_direction_distribution(uniform_sphere, |_| UNIFORM_SPHERE_PDF);
        assert_unit_density(|_| UNIFORM_SPHERE_PDF);
    }

    #[test]
    fn cosine_hemisphere_matches_its_density() {
        assert_direction_distribution(cosine_hemisphere, |w| cosine_hemisphere_pdf(w.z));
        assert_unit_density(|w| cosine_hemisphere_pdf(w.z));
    }

    #[test]
    fn uniform_cone_matches_its_density() {
        let cos_max = 0.8f32;
        let pdf = move |w: Vec3| {
            if w.z >= cos_max { uniform_cone_pdf(cos_max) } else { 0.0 }
        };
        assert_direction_distribution(move |u| uniform_cone(u, cos_max), pdf);
        assert_unit_density(pdf);
    }
}
