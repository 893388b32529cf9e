//! The schedule on a field whose answer is known: photons sampled on a
//! plane from an irradiance that is a linear gradient plus a step, gathered
//! with the library's fixed-radius estimate. Near the step a disc reaches
//! across it, so each pass is biased by the part of its disc on the other
//! side; as the radius shrinks that part vanishes and the mean of the
//! passes converges, as the schedule says.

use super::*;
use crate::estimate::{FixedRadius, fixed_radius_radiance};
use crate::photon::{PathClass, Photon, PhotonMap};
use crate::sampling::Rng;
use std::f64::consts::PI;

/// E(x, z) = A + B·x + S·[x > 0] on the square [−1, 1]² of the plane y = 0.
const A: f64 = 1.0;
const B: f64 = 0.5;
const S: f64 = 1.0;

fn irradiance(x: f64) -> f64 {
    A + B * x + if x > 0.0 { S } else { 0.0 }
}

/// Photons drawn from E by rejection, each carrying ∫E / n, so the
/// estimate's expected value at a point is E averaged over its disc.
fn photons(n: usize, seed: u64) -> PhotonMap {
    let total = 4.0 * (A + S / 2.0); // ∫E over the square (the gradient integrates to 0)
    let max = A + B + S;
    let mut rng = Rng::for_item(seed, 0);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let [u, v, w] = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
        let (x, z) = (2.0 * u as f64 - 1.0, 2.0 * v as f64 - 1.0);
        if (w as f64) * max < irradiance(x) {
            let power = Vec3::splat((total / n as f64) as f32);
            out.push(Photon::new(Vec3::new(x as f32, 0.0, z as f32), power, Vec3::Y, PathClass::Indirect));
        }
    }
    PhotonMap::new(out, 1.0)
}

/// E averaged over a disc of radius r centred at x0: the gradient averages
/// to its centre value; the step to S times the disc's share beyond x = 0.
fn expected(x0: f64, r: f64) -> f64 {
    let d = x0.abs().min(r);
    let segment = r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
    let beyond = if x0 < 0.0 { segment } else { PI * r * r - segment };
    A + B * x0 + S * beyond / (PI * r * r)
}

#[test]
fn the_mean_of_passes_converges_on_a_step_as_the_schedule_says() {
    let schedule = RadiusSchedule::disc(0.2, DEFAULT_ALPHA);
    let x0 = -0.08; // inside the first disc's reach of the step
    let truth = irradiance(x0);
    let point = Vec3::new(x0 as f32, 0.0, 0.0);
    let passes = 48u32;
    let seeds = 4u64;
    // E · albedo/π with albedo 1 is the radiance: scale back by π.
    let estimate = |map: &PhotonMap, r: f32| {
        let params = FixedRadius { radius: r, normal_test: false };
        fixed_radius_radiance(map, None, point, Vec3::Y, Vec3::ONE, &params).x as f64 * std::f64::consts::PI
    };
    // Bias of the mean of the first n passes, by the schedule's radii.
    let theory = |n: u32| (1..=n).map(|i| expected(x0, schedule.radius(i) as f64)).sum::<f64>() / n as f64 - truth;
    for n in [1u32, 8, 48] {
        let means: Vec<f64> = (0..seeds)
            .map(|s| {
                (1..=n).map(|i| estimate(&photons(20_000, 1000 * s + i as u64), schedule.radius(i))).sum::<f64>()
                    / n as f64
            })
            .collect();
        let mean = means.iter().sum::<f64>() / seeds as f64;
        let spread = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64).sqrt();
        let standard_error = spread / (seeds as f64).sqrt();
        let bias = mean - truth;
        eprintln!("{n} passes: bias {bias:+.4} (theory {:+.4}), standard error {standard_error:.4}", theory(n));
        assert!(
            (bias - theory(n)).abs() < 4.0 * standard_error + 0.01,
            "{n} passes: measured bias {bias} against {}",
            theory(n)
        );
    }
    // The theory itself: once r_i < |x0| (from pass 332 here) no disc reaches
    // the step, and the mean's bias falls as 1/N from there.
    assert!(theory(1) > 0.25, "the first disc reaches well across the step: {}", theory(1));
    assert!(theory(passes) < 0.55 * theory(1), "{} vs {}", theory(passes), theory(1));
    assert!(theory(10 * passes) < 0.11 * theory(1));
    assert!((theory(100 * passes) * 10.0 - theory(10 * passes)).abs() < 1e-6);
}

#[test]
fn pass_one_is_the_single_pass_method() {
    assert_eq!(pass_seed(42, 1), 42);
    assert_eq!(pass_seed(42, 3), 44);
    let s = Schedules::new([0.1, 0.03, 0.2], 0.5);
    assert_eq!(s.radii(1), [0.1, 0.03, 0.2]);
    let r = s.radii(2);
    assert!((r[0] / 0.1 - 0.75f32.sqrt()).abs() < 1e-6 && (r[1] / 0.03 - 0.75f32.sqrt()).abs() < 1e-6);
}

#[test]
fn the_running_mean_is_the_mean() {
    let mut mean = ImageMean::new(2, 1);
    for v in [1.0f32, 2.0, 6.0] {
        let mut image = Image::new(2, 1);
        image.pixels = vec![Vec3::splat(v), Vec3::new(v, 0.0, -v)];
        mean.add(&image);
    }
    assert_eq!(mean.passes(), 3);
    assert_eq!(mean.mean().pixels, vec![Vec3::splat(3.0), Vec3::new(3.0, 0.0, -3.0)]);
}

#[test]
fn pass_jitters_cover_the_pixel_evenly() {
    assert_eq!(pass_jitter(1), Vec2::ZERO);
    let jitters: Vec<Vec2> = (1..=256).map(pass_jitter).collect();
    assert!(jitters.iter().all(|j| j.abs().max_element() <= 0.5));
    // Every eighth of the square in x and in y gets 32 ± 3 of 256.
    for axis in 0..2 {
        for bin in 0..8 {
            let lo = -0.5 + bin as f32 / 8.0;
            let n = jitters.iter().filter(|j| j[axis] >= lo && j[axis] < lo + 0.125).count();
            assert!((29..=35).contains(&n), "axis {axis} bin {bin}: {n}");
        }
    }
}

/// Passes of known noise around a known image: the half-image estimate
/// matches the mean's true relative error within 15%, for even and odd
/// pass counts; a single pass gives none.
#[test]
fn the_noise_estimate_matches_the_true_error() {
    let (w, h) = (64, 64);
    let truth: Vec<f32> = (0..w * h).map(|i| 0.5 + (i % 7) as f32 * 0.3).collect();
    let mut rng = Rng::for_item(21, 0);
    let mut mean = ImageMean::new(w, h);
    assert_eq!(mean.noise_estimate(), None);
    for pass in 1..=33u32 {
        let mut image = crate::render::Image::new(w, h);
        for (p, &t) in image.pixels.iter_mut().zip(&truth) {
            // Uniform noise of the value's size: an unbiased pass.
            *p = glam::Vec3::new(t, 2.0 * t, 0.5 * t) * (0.5 + rng.next_f32());
        }
        mean.add(&image);
        if [2, 8, 9, 33].contains(&pass) {
            let m = mean.mean();
            let (mut squares, mut total) = (0.0f64, 0.0f64);
            for (p, &t) in m.pixels.iter().zip(&truth) {
                let t = glam::Vec3::new(t, 2.0 * t, 0.5 * t);
                squares += (*p - t).length_squared() as f64;
                total += t.element_sum() as f64;
            }
            let values = 3.0 * truth.len() as f64;
            let actual = (squares / values).sqrt() / (total / values);
            let estimate = mean.noise_estimate().unwrap();
            assert!((estimate / actual - 1.0).abs() < 0.15, "pass {pass}: estimate {estimate}, actual {actual}");
        }
    }
}
