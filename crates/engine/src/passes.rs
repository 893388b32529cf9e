//! One renderer, pass by pass: what the session drives.

use anyhow::Result;
use hikari_core::render::Image;

pub trait PassRenderer {
    /// Renders pass `pass` (from 1) and adds it to the mean.
    fn render_pass(&mut self, pass: u32) -> Result<()>;
    /// The mean of the passes so far.
    fn mean(&mut self) -> Result<Image>;
    /// The global map's radius in pass `pass`, for progress (None: no radius).
    fn radius(&self, pass: u32) -> Option<f32>;
    /// The mean's relative error as its passes estimate it
    /// (`ImageMean::noise_estimate`); None before the second pass.
    fn noise(&mut self) -> Option<f64> {
        None
    }
    /// The per-pixel sums of the passes so far (row-major), what a shard
    /// of the render keeps for the merge.
    fn sums(&mut self) -> Result<Vec<[f64; 3]>>;
    /// Non-finite samples dropped so far (never in an image).
    fn nonfinite(&self) -> u64 {
        0
    }
}
