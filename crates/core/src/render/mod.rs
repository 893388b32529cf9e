//! CPU renderers: `photon-cpu` (the seed's pipeline, CPU twin of the GPU
//! renderer) and `path` (a path tracer for ground truth).

mod direct;
mod image;
pub mod path;
pub mod photon_cpu;
pub mod vcm;

pub use self::image::Image;
pub use direct::{direct_diffuse, direct_reflected};

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
    let (w, h) = (camera.width as usize, camera.height as usize);
    let spp = spp.max(1);
    let strata = (spp as f32).sqrt().floor() as u32;
    let nonfinite = AtomicU64::new(0);
    let mut pixels = vec![Rgb::ZERO; w * h];
    progress.begin("rendering", h as u64);
    pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let index = (y * w + x) as u64;
            let mut rng = Rng::for_item(seed ^ 0x5eed_0f_91c5, index);
            let mut sum = Rgb::ZERO;
            let mut bad = 0u64;
            for s in 0..spp {
                let offset = if spp == 1 {
                    Vec2::splat(0.5)
                } else if s < strata * strata {
                    (Vec2::new((s % strata) as f32, (s / strata) as f32) + rng.next_2d()) / strata as f32
                } else {
                    rng.next_2d()
                };
                let value = sample(camera.ray(Vec2::new(x as f32, y as f32) + offset), &mut rng);
                if value.is_finite() {
                    sum += value;
                } else {
                    bad += 1;
                }
            }
            *out = sum / spp as f32;
            if bad > 0 {
                nonfinite.fetch_add(bad, Ordering::Relaxed);
            }
        }
        progress.advance(1);
    });
    progress.end();
    (Image { width: w as u32, height: h as u32, pixels }, nonfinite.into_inner())
}
