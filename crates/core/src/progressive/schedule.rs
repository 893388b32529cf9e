//! The radius schedule of progressive photon mapping (Knaus & Zwicker 2011,
//! "Progressive photon mapping: a probabilistic approach"; docs/progressive.md).
//!
//! Pass i = 1, 2, … traces an independent photon set and estimates with
//! radius r_i; the image is the mean of the passes. A kernel of dimension d
//! (its support's measure grows as r^d) has per-pass variance ∝ 1/r_i^d and
//! bias ∝ r_i². Shrinking
//!
//!   r_{i+1}^d = r_i^d · (i + α) / (i + 1),   α ∈ (0, 1),
//!
//! makes the mean's variance and its bias both vanish:
//! r_i^d = r_1^d · ∏_{k=1}^{i−1} (k + α)/(k + 1) = r_1^d · Γ(i + α) / (Γ(1 + α) Γ(i + 1)),
//! which falls as i^{α−1}. The surface maps (global, caustic) gather over a
//! disc (d = 2). The volume estimate gathers the photons whose radius-r
//! sphere a view ray crosses, weighted by the chord: integrated along the
//! ray, that is a 2-D kernel across it (∫ 2√(r²−ρ²) / (4/3 π r³) dA = 1), so
//! it too has d = 2 and shrinks like the surface maps. A 3-D point query (a
//! density at a point) would have d = 3: r³ shrinks by (i + α)/(i + 1).

/// Knaus & Zwicker's α: the fraction of the photons that stay in the shrunk
/// disc; smaller α shrinks faster (less bias, more noise).
pub const DEFAULT_ALPHA: f32 = 2.0 / 3.0;

/// The radii of one map over the passes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiusSchedule {
    /// r_1: the first pass's radius (the single-pass method's).
    pub initial: f32,
    pub alpha: f32,
    /// d: the kernel's dimension (2 for every photon map of hikari; see above).
    pub dimension: u32,
}

impl RadiusSchedule {
    /// The schedule of a disc kernel (surfaces, and the volume's chord estimate).
    pub fn disc(initial: f32, alpha: f32) -> Self {
        RadiusSchedule { initial, alpha, dimension: 2 }
    }

    /// The schedule of a ball kernel: a density at a point in a medium
    /// (vertex merging's volume vertices).
    pub fn ball(initial: f32, alpha: f32) -> Self {
        RadiusSchedule { initial, alpha, dimension: 3 }
    }

    /// r_i / r_1 for pass `pass` (from 1): the product, in f64 (a million
    /// passes lose no precision), to the power 1/d.
    pub fn shrink(&self, pass: u32) -> f64 {
        let alpha = self.alpha as f64;
        let ratio: f64 = (1..pass.max(1)).map(|k| (k as f64 + alpha) / (k as f64 + 1.0)).product();
        ratio.powf(1.0 / self.dimension as f64)
    }

    /// r_i, pass from 1.
    pub fn radius(&self, pass: u32) -> f32 {
        (self.initial as f64 * self.shrink(pass)) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; about 1e-15 relative).
    fn ln_gamma(x: f64) -> f64 {
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let x = x - 1.0;
        let t = x + 7.5;
        let sum: f64 = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
        0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
    }

    #[test]
    fn the_recurrence_and_the_closed_form_agree() {
        for alpha in [0.1f32, 0.5, DEFAULT_ALPHA, 0.9] {
            let s = RadiusSchedule::disc(0.1, alpha);
            assert_eq!(s.radius(1), 0.1);
            let mut r2 = 0.01f64;
            for i in 1..2000u32 {
                let closed =
                    (ln_gamma(i as f64 + alpha as f64) - ln_gamma(1.0 + alpha as f64) - ln_gamma(i as f64 + 1.0)).exp()
                        * 0.01;
                let got = (s.radius(i) as f64).powi(2);
                assert!((got / r2 - 1.0).abs() < 1e-5, "α {alpha} pass {i}: {got} vs recurrence {r2}");
                assert!((got / closed - 1.0).abs() < 1e-5, "α {alpha} pass {i}: {got} vs closed form {closed}");
                r2 *= (i as f64 + alpha as f64) / (i as f64 + 1.0);
            }
        }
    }

    #[test]
    fn radii_fall_as_a_power_of_the_pass() {
        // r_i^2 ~ r_1^2 · i^(α−1) / Γ(1 + α) for large i.
        let s = RadiusSchedule::disc(1.0, 0.5);
        let i = 100_000u32;
        let want = (i as f64).powf(-0.5) / ln_gamma(1.5).exp();
        let got = (s.radius(i) as f64).powi(2);
        assert!((got / want - 1.0).abs() < 1e-4, "{got} vs {want}");
        // A 3-D kernel shrinks r³ by the same factors.
        let cube = RadiusSchedule { dimension: 3, ..s };
        assert!(((cube.radius(7) as f64).powi(3) - (s.radius(7) as f64).powi(2)).abs() < 1e-6);
    }
}
