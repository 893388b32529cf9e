//! Participating media (METHOD.md §5): coefficients, region meshes,
//! transmittance, free-flight sampling and phase functions.
//!
//! Coefficients are RGB per scene unit. A [`Medium`] is one set of
//! coefficients; [`Media`] holds all of a scene's, global or bounded by
//! [`RegionMesh`]es, and samples free flights across them.

mod media;
pub mod phase;
pub mod region;

pub use media::{Flight, MAX_MEDIA, MAX_PHASES, Media, MediaAlong, MediumEntry, Segment};
pub use phase::Phase;
pub use region::RegionMesh;

use crate::material::{Rgb, mean};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    pub phase: Phase,
}

impl Medium {
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }

    /// Scattering albedo Λ = σ_s / σ_t as used by the photon roulette
    /// (eq. 5.12): the ratio of the channel means.
    pub fn scattering_probability(&self) -> f32 {
        let t = mean(self.sigma_t());
        if t > 0.0 { mean(self.sigma_s) / t } else { 0.0 }
    }

    /// e^(−σ_t d) per channel (eq. 5.8 in a homogeneous medium).
    pub fn transmittance(&self, distance: f32) -> Rgb {
        (-self.sigma_t() * distance).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use glam::Vec3;

    fn grey(sigma_a: f32, sigma_s: f32) -> Medium {
        Medium { sigma_a: Vec3::splat(sigma_a), sigma_s: Vec3::splat(sigma_s), phase: Phase::Schlick { k: 0.0 } }
    }

    /// The albedo roulette absorbs a fraction 1 − Λ of the interactions.
    #[test]
    fn absorbed_fraction_is_one_minus_albedo() {
        let m = grey(0.25, 0.75);
        let mut rng = Rng::for_item(53, 0);
        let n = 100_000;
        let absorbed = (0..n).filter(|_| rng.next_f32() >= m.scattering_probability()).count();
        assert!((absorbed as f64 / n as f64 - 0.25).abs() < 0.005);
    }
}
