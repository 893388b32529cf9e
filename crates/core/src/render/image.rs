//! A linear-RGB image in scene radiance units.

use crate::material::Rgb;

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Row-major, row 0 at the top.
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Image { width, height, pixels: vec![Rgb::ZERO; (width * height) as usize] }
    }

    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Mean over all pixels and channels.
    pub fn mean(&self) -> f32 {
        let sum: f64 = self.pixels.iter().map(|p| (p.x + p.y + p.z) as f64).sum();
        (sum / (3 * self.pixels.len()).max(1) as f64) as f32
    }
}
