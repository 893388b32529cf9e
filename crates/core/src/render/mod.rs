//! CPU renderers: `photon-cpu` (the seed's pipeline, CPU twin of the GPU
//! renderer) and `path` (a path tracer for ground truth).

pub mod aov;
mod direct;
mod image;
pub mod path;
pub mod photon_cpu;
pub mod vcm;

pub use self::image::Image;
pub use direct::{LitSides, direct_diffuse, direct_reflected, direct_scattered};

use crate::camera::Camera;
use crate::material::Rgb;
use crate::progress::Progress;
use crate::sampling::Rng;
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Renders every pixel as the mean of `spp` samples over its square (box
/// filter). With one sample per pixel the sample is the pixel centre, which is
/// what a rasterizer sees; with more, samples are stratified and jittered.
/// Non-finite samples are dropped and counted, so NaN/Inf never reach the image.
pub(crate) fn render_pixels(
    camera: &Camera,
    spp: u32,
    seed: u64,
    progress: &dyn Progress,
    sample: impl Fn(crate::geometry::Ray, &mut Rng) -> Rgb + Sync,
) -> (Image, u64) {
    let spp = spp.max(1);
    let strata = (spp as f32).sqrt().floor() as u32;
    render_rows(camera, progress, |x, y| {
        let index = y as u64 * camera.width as u64 + x as u64;
        let mut rng = Rng::for_item(seed ^ 0x5eed_0f_91c5, index);
        finite_mean(spp, |s| {
            let offset = if spp == 1 {
                Vec2::splat(0.5)
            } else if s < strata * strata {
                (Vec2::new((s % strata) as f32, (s / strata) as f32) + rng.next_2d()) / strata as f32
            } else {
                rng.next_2d()
            };
            sample(camera.ray(Vec2::new(x as f32, y as f32) + offset), &mut rng)
        })
    })
}

/// Renders every pixel (x, y) as `pixel` gives it (its value and the
/// number of non-finite samples it dropped), rows in parallel.
pub(crate) fn render_rows(
    camera: &Camera,
    progress: &dyn Progress,
    pixel: impl Fn(u32, u32) -> (Rgb, u64) + Sync,
) -> (Image, u64) {
    render_row_batches(camera, progress, |y, row| {
        let mut bad = 0;
        for (x, out) in row.iter_mut().enumerate() {
            let (value, dropped) = pixel(x as u32, y);
            *out = value;
            bad += dropped;
        }
        bad
    })
}

/// [`render_rows`] for renderers that fill a whole row at once: `row(y,
/// pixels)` writes row y and returns the non-finite samples it dropped.
pub(crate) fn render_row_batches(
    camera: &Camera,
    progress: &dyn Progress,
    row: impl Fn(u32, &mut [Rgb]) -> u64 + Sync,
) -> (Image, u64) {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let nonfinite = AtomicU64::new(0);
    let mut pixels = vec![Rgb::ZERO; w * h];
    progress.begin("rendering", h as u64);
    pixels.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let bad = row(y as u32, out);
        if bad > 0 {
            nonfinite.fetch_add(bad, Ordering::Relaxed);
        }
        progress.advance(1);
    });
    progress.end();
    (Image { width: w as u32, height: h as u32, pixels }, nonfinite.into_inner())
}

/// The mean of samples 0..n (divided by n), non-finite ones dropped and
/// counted.
pub(crate) fn finite_mean(n: u32, mut sample: impl FnMut(u32) -> Rgb) -> (Rgb, u64) {
    let (mut sum, mut bad) = (Rgb::ZERO, 0);
    for s in 0..n {
        let value = sample(s);
        if value.is_finite() {
            sum += value;
        } else {
            bad += 1;
        }
    }
    (sum / n as f32, bad)
}
