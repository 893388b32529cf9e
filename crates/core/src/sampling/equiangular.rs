//! Equiangular sampling of a distance along a ray (Kulla & Fajardo 2012,
//! "Importance sampling techniques for path tracing in participating media"):
//! light from a point source scattered along a ray falls off as 1/d², which
//! a free flight (density ∝ transmittance) ignores, so in thin fog most
//! free-flight points land far from the light and the few near it carry
//! huge weights. Sampling t with density ∝ 1/(D² + (t − Δ)²), Δ the ray
//! parameter closest to the light and D the distance there, cancels that
//! falloff: uniform in the angle subtended at the light.

use glam::Vec3;

/// The sampler for one ray, one light position and one interval [t0, t1]
/// (t1 may be infinite).
#[derive(Clone, Copy, Debug)]
pub struct Equiangular {
    /// Ray parameter of the point closest to the light.
    closest: f32,
    /// Distance from the light to the ray (kept above a floor so that a ray
    /// through the light stays finite).
    distance: f32,
    /// Angles at the light of the interval's ends, measured from the
    /// closest point: θ = atan((t − Δ) / D).
    theta0: f32,
    theta1: f32,
}

/// Below this distance from the light, a ray counts as passing at it: the
/// density stays finite (the integrand is still weighted exactly).
const MIN_DISTANCE: f32 = 1e-6;

impl Equiangular {
    /// None if the interval is empty.
    pub fn new(origin: Vec3, dir: Vec3, light: Vec3, t0: f32, t1: f32) -> Option<Equiangular> {
        if t1 <= t0 || !t0.is_finite() || t1.is_nan() {
            return None;
        }
        let closest = (light - origin).dot(dir);
        let distance = (origin + dir * closest - light).length().max(MIN_DISTANCE);
        let angle = |t: f32| ((t - closest) / distance).atan();
        let (theta0, theta1) = (angle(t0), angle(t1));
        (theta1 > theta0).then_some(Equiangular { closest, distance, theta0, theta1 })
    }

    /// A distance t in [t0, t1] from uniform `xi`, and its density.
    pub fn sample(&self, xi: f32) -> (f32, f32) {
        let theta = self.theta0 + xi * (self.theta1 - self.theta0);
        let t = self.closest + self.distance * theta.tan();
        (t, self.pdf(t))
    }

    /// Density of `t` (within the interval).
    pub fn pdf(&self, t: f32) -> f32 {
        let offset = t - self.closest;
        self.distance / ((self.theta1 - self.theta0) * (self.distance * self.distance + offset * offset))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampler(t1: f32) -> Equiangular {
        Equiangular::new(Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.5, 0.0), 0.25, t1).unwrap()
    }

    /// The density integrates to 1 over the interval (midpoint rule).
    #[test]
    fn density_integrates_to_one() {
        let s = sampler(6.0);
        let n = 200_000;
        let h = (6.0 - 0.25) / n as f64;
        let total: f64 = (0..n).map(|i| s.pdf(0.25 + ((i as f64 + 0.5) * h) as f32) as f64 * h).sum();
        assert!((total - 1.0).abs() < 1e-4, "∫ pdf = {total}");
    }

    /// Samples fall inside the interval with the stated cumulative
    /// distribution: the fraction below each of a few cut points matches ∫ pdf.
    #[test]
    fn samples_follow_the_density() {
        let s = sampler(6.0);
        let n = 100_000;
        let samples: Vec<f32> = (0..n).map(|i| s.sample((i as f32 + 0.5) / n as f32).0).collect();
        assert!(samples.iter().all(|&t| (0.25..=6.0 + 1e-4).contains(&t)));
        for cut in [0.5f32, 1.5, 2.0, 3.0, 5.0] {
            let below = samples.iter().filter(|&&t| t < cut).count() as f64 / n as f64;
            let steps = 20_000;
            let h = (cut - 0.25) as f64 / steps as f64;
            let cdf: f64 = (0..steps).map(|i| s.pdf(0.25 + ((i as f64 + 0.5) * h) as f32) as f64 * h).sum();
            assert!((below - cdf).abs() < 1e-3, "below {cut}: {below} vs {cdf}");
        }
        // Returned densities are the density at the returned distance.
        let (t, pdf) = s.sample(0.3);
        assert_eq!(pdf, s.pdf(t));
    }

    /// An unbounded interval (a ray leaving the scene) is a proper density,
    /// and a ray through the light stays finite.
    #[test]
    fn infinite_intervals_and_rays_through_the_light() {
        let s = sampler(f32::INFINITY);
        let (t, pdf) = s.sample(0.999);
        assert!(t.is_finite() && t > 6.0 && pdf > 0.0 && pdf.is_finite());
        let through = Equiangular::new(Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0), 0.0, 4.0).unwrap();
        let (t, pdf) = through.sample(0.7);
        assert!(t.is_finite() && pdf.is_finite() && pdf > 0.0);
        assert!(Equiangular::new(Vec3::ZERO, Vec3::X, Vec3::Y, 1.0, 1.0).is_none());
    }
}
