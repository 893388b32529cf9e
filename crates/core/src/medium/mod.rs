//! Participating media (METHOD.md §5): coefficients, transmittance,
//! free-flight sampling and phase functions. Groundwork for issue #4; the
//! scene format, photon tracing and renderers use it as they gain media.
//!
//! Coefficients are RGB per scene unit. Free flights are sampled against the
//! mean extinction σ̄ = mean(σ_t), with per-channel weights that make the
//! RGB result unbiased (equal to the single-channel rule when the medium is
//! grey).

pub mod phase;

pub use phase::Phase;

use crate::material::{Rgb, mean};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    pub phase: Phase,
}

/// Where a sampled free flight ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flight {
    /// An interaction at `distance`; the photon's power is multiplied by
    /// `weight` (all ones in a grey medium).
    Interaction { distance: f32, weight: Rgb },
    /// No interaction before `max_distance` (a surface); power × `weight`.
    Passed { weight: Rgb },
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

    /// Samples a free flight from uniform `xi` (eq. 5.10: d = −ln(1−ξ)/σ̄),
    /// up to `max_distance`.
    pub fn sample_flight(&self, xi: f32, max_distance: f32) -> Flight {
        let sigma_t = self.sigma_t();
        let sigma_bar = mean(sigma_t);
        if sigma_bar <= 0.0 {
            return Flight::Passed { weight: Rgb::ONE };
        }
        let distance = -(1.0 - xi).ln() / sigma_bar;
        if distance >= max_distance {
            // P(pass) = e^(−σ̄ D): weight T(D) / P per channel.
            let weight = (-(sigma_t - sigma_bar) * max_distance).exp();
            Flight::Passed { weight }
        } else {
            // p(d) = σ̄ e^(−σ̄ d): weight σ_t(c) e^(−σ_t(c) d) / p(d) per
            // channel. The scatter/absorb roulette (probability Λ) then
            // multiplies a scattered photon by (σ_s(c)/σ_t(c)) / Λ.
            let weight = (-(sigma_t - sigma_bar) * distance).exp() * sigma_t / sigma_bar;
            Flight::Interaction { distance, weight }
        }
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

    #[test]
    fn free_flights_have_mean_one_over_sigma_t() {
        let m = grey(0.3, 0.9);
        let mut rng = Rng::for_item(51, 0);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            match m.sample_flight(rng.next_f32(), f32::INFINITY) {
                Flight::Interaction { distance, weight } => {
                    assert_eq!(weight, Vec3::ONE);
                    sum += distance as f64;
                }
                Flight::Passed { .. } => panic!("an infinite medium always interacts"),
            }
        }
        let mean = sum / n as f64;
        assert!((mean - 1.0 / 1.2).abs() < 0.01, "mean free path {mean}");
    }

    /// A slab of thickness d lets e^(−σ_t d) of the photons through untouched.
    #[test]
    fn slab_transmission_matches_beer_lambert() {
        let m = grey(0.5, 1.5);
        let d = 0.7;
        let mut rng = Rng::for_item(52, 0);
        let n = 200_000;
        let passed = (0..n).filter(|_| matches!(m.sample_flight(rng.next_f32(), d), Flight::Passed { .. })).count();
        let expected = m.transmittance(d).x as f64;
        assert!((passed as f64 / n as f64 - expected).abs() < 0.004, "{passed} of {n} vs {expected}");
        assert!((expected - (-2.0f64 * 0.7).exp()).abs() < 1e-6);
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

    /// With RGB coefficients the weighted flights stay unbiased: the expected
    /// weight of photons passing a slab is the per-channel transmittance.
    #[test]
    fn rgb_flight_weights_are_unbiased() {
        let m = Medium {
            sigma_a: Vec3::new(0.1, 0.4, 0.9),
            sigma_s: Vec3::new(0.5, 0.5, 0.2),
            phase: Phase::Schlick { k: 0.0 },
        };
        let d = 0.8;
        let mut rng = Rng::for_item(54, 0);
        let n = 400_000;
        let mut passed = Vec3::ZERO;
        for _ in 0..n {
            if let Flight::Passed { weight } = m.sample_flight(rng.next_f32(), d) {
                passed += weight;
            }
        }
        let got = passed / n as f32;
        let want = m.transmittance(d);
        assert!(((got - want) / want).abs().max_element() < 0.01, "{got} vs {want}");
    }
}
