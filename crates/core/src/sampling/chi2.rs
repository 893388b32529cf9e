//! Chi-square goodness-of-fit for direction samplers (after pbrt-v4's tests).
//!
//! The sphere is binned in (cos θ, φ), equal-area bins; expected counts come
//! from integrating the claimed density over each bin numerically. Bins with
//! small expected counts are pooled, as the test requires.

use super::Rng;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

const COS_BINS: usize = 20;
const PHI_BINS: usize = 40;
const SAMPLES: usize = 400_000;

fn bin_of(w: Vec3) -> usize {
    let c = ((w.z.clamp(-1.0, 1.0) + 1.0) * 0.5 * COS_BINS as f32) as usize;
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let p = (phi / (2.0 * PI) * PHI_BINS as f32) as usize;
    c.min(COS_BINS - 1) * PHI_BINS + p.min(PHI_BINS - 1)
}

/// Expected probability of each bin: midpoint rule on a fine sub-grid.
fn expected_probabilities(pdf: &dyn Fn(Vec3) -> f32) -> Vec<f64> {
    const SUB: usize = 16;
    let bin_area = 4.0 * PI as f64 / (COS_BINS * PHI_BINS) as f64;
    let mut probs = vec![0.0f64; COS_BINS * PHI_BINS];
    for c in 0..COS_BINS {
        for p in 0..PHI_BINS {
            let mut sum = 0.0f64;
            for i in 0..SUB {
                for j in 0..SUB {
                    let z = -1.0 + 2.0 * (c as f64 + (i as f64 + 0.5) / SUB as f64) / COS_BINS as f64;
                    let phi = 2.0 * std::f64::consts::PI * (p as f64 + (j as f64 + 0.5) / SUB as f64) / PHI_BINS as f64;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                    sum += pdf(w) as f64;
                }
            }
            probs[c * PHI_BINS + p] = sum / (SUB * SUB) as f64 * bin_area;
        }
    }
    probs
}

/// Upper tail of the chi-square distribution (Wilson–Hilferty approximation),
/// good to a few percent for the degrees of freedom used here.
fn chi2_p_value(chi2: f64, dof: f64) -> f64 {
    let z = ((chi2 / dof).powf(1.0 / 3.0) - (1.0 - 2.0 / (9.0 * dof))) / (2.0 / (9.0 * dof)).sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

fn erfc(x: f64) -> f64 {
    // Numerical Recipes erfcc, relative error < 1.2e-7.
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Chi-square test of `sample` (from uniform [0,1)²) against `pdf` (solid angle).
pub fn assert_direction_distribution(sample: impl Fn(Vec2) -> Vec3, pdf: impl Fn(Vec3) -> f32) {
    let mut observed = vec![0u64; COS_BINS * PHI_BINS];
    let mut rng = Rng::for_item(0xC412, 0);
    for _ in 0..SAMPLES {
        let w = sample(rng.next_2d());
        assert!((w.length() - 1.0).abs() < 1e-3, "sampler returned non-unit {w}");
        observed[bin_of(w)] += 1;
    }
    let probs = expected_probabilities(&pdf);
    let (chi2, dof) = pooled_chi2(&observed, &probs, SAMPLES as f64);
    let p = chi2_p_value(chi2, dof);
    assert!(p > 1e-4, "chi-square rejects sampler: chi2 = {chi2:.1}, dof = {dof}, p = {p:e}");
}

/// Chi-square over histogram `observed` with cell probabilities `probs`.
/// Observations in cells of zero probability fail outright; cells expecting
/// fewer than 5 samples are pooled.
pub fn pooled_chi2(observed: &[u64], probs: &[f64], total: f64) -> (f64, f64) {
    let mut chi2 = 0.0;
    let mut cells = 0usize;
    let (mut pooled_obs, mut pooled_exp) = (0.0f64, 0.0f64);
    for (&o, &p) in observed.iter().zip(probs) {
        let e = p * total;
        if e <= 1e-9 {
            assert!(o == 0, "{o} samples in a cell of zero density");
            continue;
        }
        if e < 5.0 {
            pooled_obs += o as f64;
            pooled_exp += e;
            continue;
        }
        chi2 += (o as f64 - e).powi(2) / e;
        cells += 1;
    }
    if pooled_exp > 0.0 {
        chi2 += (pooled_obs - pooled_exp).powi(2) / pooled_exp.max(1.0);
        cells += 1;
    }
    (chi2, (cells.max(2) - 1) as f64)
}

/// The density integrates to one over the sphere.
pub fn assert_unit_density(pdf: impl Fn(Vec3) -> f32) {
    let total: f64 = expected_probabilities(&pdf).iter().sum();
    assert!((total - 1.0).abs() < 2e-3, "density integrates to {total}");
}
