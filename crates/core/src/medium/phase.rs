//! Phase functions (METHOD.md §5): Schlick's (the seed's eq. 5.13–5.14) and
//! Henyey–Greenstein.
//!
//! Convention, for both: μ = cos θ is the cosine between the photon's
//! propagation direction before and after scattering, so μ = 1 is straight
//! on. Written this way Schlick's is p(μ) = (1 − k²) / (4π (1 − kμ)²): the
//! seed's eq. 5.13 measures θ from the direction the photon came *from*,
//! which flips the sign of μ, while its eq. 5.14 (the sampler, used as
//! printed) measures it from the propagation direction. With this convention
//! k > 0 and g > 0 scatter forward, as the seed states; the tests prove it.

use crate::sampling::{local_to_world, unit_circle};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// Schlick's approximation, k in (−1, 1); 0 is isotropic.
    Schlick { k: f32 },
    /// Henyey–Greenstein, g in (−1, 1) the mean cosine; 0 is isotropic.
    HenyeyGreenstein { g: f32 },
}

impl Phase {
    /// Density per steradian of scattering by angle acos(`mu`).
    pub fn eval(&self, mu: f32) -> f32 {
        match *self {
            Phase::Schlick { k } => {
                let d = 1.0 - k * mu;
                (1.0 - k * k) / (4.0 * PI * d * d)
            }
            Phase::HenyeyGreenstein { g } => {
                let d = 1.0 + g * g - 2.0 * g * mu;
                (1.0 - g * g) / (4.0 * PI * d * d.sqrt())
            }
        }
    }

    /// Samples μ from uniform `xi` in [0,1).
    pub fn sample_mu(&self, xi: f32) -> f32 {
        let mu = match *self {
            // The seed's eq. 5.14 as printed.
            Phase::Schlick { k } => (2.0 * xi + k - 1.0) / (2.0 * k * xi - k + 1.0),
            Phase::HenyeyGreenstein { g } if g.abs() < 1e-4 => 1.0 - 2.0 * xi,
            Phase::HenyeyGreenstein { g } => {
                let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
                (1.0 + g * g - s * s) / (2.0 * g)
            }
        };
        mu.clamp(-1.0, 1.0)
    }

    /// A new propagation direction for a photon travelling along `dir`.
    pub fn sample(&self, dir: Vec3, u: Vec2) -> Vec3 {
        let mu = self.sample_mu(u.x);
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        local_to_world((unit_circle(u.y) * sin).extend(mu), dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{assert_direction_distribution, assert_unit_density};

    const PHASES: [Phase; 6] = [
        Phase::Schlick { k: 0.0 },
        Phase::Schlick { k: 0.6 },
        Phase::Schlick { k: -0.4 },
        Phase::HenyeyGreenstein { g: 0.0 },
        Phase::HenyeyGreenstein { g: 0.5 },
        Phase::HenyeyGreenstein { g: -0.3 },
    ];

    #[test]
    fn sampling_matches_evaluation_and_integrates_to_one() {
        for phase in PHASES {
            // Photons travelling along +z: the sampled direction's z is μ.
            assert_unit_density(|w| phase.eval(w.z));
            assert_direction_distribution(|u| phase.sample(Vec3::Z, u), |w| phase.eval(w.z));
        }
    }

    #[test]
    fn positive_parameters_scatter_forward() {
        for phase in [Phase::Schlick { k: 0.5 }, Phase::HenyeyGreenstein { g: 0.5 }] {
            assert!(phase.eval(1.0) > phase.eval(-1.0));
            let n = 100_000;
            let mean_mu: f32 = (0..n).map(|i| phase.sample_mu((i as f32 + 0.5) / n as f32)).sum::<f32>() / n as f32;
            assert!(mean_mu > 0.3, "{phase:?}: mean cosine {mean_mu}");
        }
        for phase in [Phase::Schlick { k: -0.5 }, Phase::HenyeyGreenstein { g: -0.5 }] {
            assert!(phase.eval(1.0) < phase.eval(-1.0));
        }
        // Henyey–Greenstein's g is its mean cosine.
        let hg = Phase::HenyeyGreenstein { g: 0.7 };
        let n = 200_000;
        let mean: f32 = (0..n).map(|i| hg.sample_mu((i as f32 + 0.5) / n as f32)).sum::<f32>() / n as f32;
        assert!((mean - 0.7).abs() < 2e-3, "mean cosine {mean}");
    }
}
