//! Environment maps: a sky image (equirectangular, `.hdr` or `.exr`) whose
//! texels are the radiance arriving from every direction, importance-sampled
//! for light sampling and photon emission.
//!
//! # Mapping
//!
//! Blender's (so a map lights a scene as in Blender, with glTF's +Y up and
//! −Z forward): a direction d toward the sky has
//!
//! ```text
//! u = 0.5 + atan2(d.z, d.x) / 2π     v = acos(d.y) / π
//! ```
//!
//! with (u, v) = (0, 0) the image's top-left corner: the top row is the
//! zenith, the middle of the image looks along +X, its quarter to the left
//! along −Z (Blender's +Y), to the right along +Z (Cycles'
//! `direction_to_equirectangular`: u = ½ − atan2(y, x)/2π in Blender's
//! Z-up frame, whose (x, y) are glTF's (x, −z)). Until 2026-12-07 hikari
//! turned maps by 180° about the vertical (u = ½ + atan2(−z, −x)/2π): the
//! Blender add-on's HDRI test found it, a sun in the map lighting the scene
//! from behind. Each texel holds a constant radiance (nearest texel, no
//! filtering), so the sampling density below is exactly proportional to
//! what the lookup returns.
//!
//! # Sampling
//!
//! A piecewise-constant 2D distribution over the texels with weights
//! luminance × the texel's solid angle: a row by the marginal CDF,
//! a texel in it by the row's CDF, a point uniformly inside the texel. The
//! density per steradian is p(u, v) / (2π² sin θ), p the density over the
//! unit square.

use crate::material::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::path::Path;

/// An equirectangular environment map, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    width: u32,
    height: u32,
    texels: Vec<Rgb>,
    /// Marginal CDF over rows (height + 1 entries, from 0 to 1).
    row_cdf: Vec<f32>,
    /// Per row, the CDF over its texels (width + 1 entries each).
    column_cdf: Vec<f32>,
    /// Sum of the texels' weights (luminance × solid angle); 0 for a black map.
    total_weight: f64,
    /// ∫ L(ω) dω over the sphere, per channel.
    integral: Rgb,
}

/// A direction drawn from the map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSample {
    /// Toward the sky (where the light comes from).
    pub dir: Vec3,
    pub radiance: Rgb,
    /// Density per steradian.
    pub pdf: f32,
}

fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The solid angle of a texel of row `row` of a `w × h` map: its band of
/// the sphere, (2π/w)(cos θ₀ − cos θ₁), exactly.
fn texel_solid_angle(row: usize, w: usize, h: usize) -> f64 {
    let theta = |r: usize| std::f64::consts::PI * r as f64 / h as f64;
    2.0 * std::f64::consts::PI / w as f64 * (theta(row).cos() - theta(row + 1).cos())
}

/// The CDF of `weights` (one more entry than weights, from 0 to 1; uniform
/// when they sum to zero) and their sum.
fn cdf(weights: impl Iterator<Item = f64>) -> (Vec<f32>, f64) {
    let mut running = vec![0.0f64];
    for w in weights {
        running.push(running.last().unwrap() + w);
    }
    let total = *running.last().unwrap();
    let n = running.len() - 1;
    let cdf = running
        .iter()
        .enumerate()
        .map(|(i, &c)| if total > 0.0 { (c / total) as f32 } else { i as f32 / n as f32 })
        .collect();
    (cdf, total)
}

/// The entry i of a CDF `cdf` with cdf[i] ≤ x < cdf[i + 1], and where x lies
/// in it (0 to 1); entries of zero width are never chosen.
fn sample_cdf(cdf: &[f32], x: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let i = cdf.partition_point(|&c| c <= x).clamp(1, n) - 1;
    let width = cdf[i + 1] - cdf[i];
    let t = if width > 0.0 { ((x - cdf[i]) / width).clamp(0.0, 1.0) } else { 0.5 };
    (i, t)
}

impl EnvironmentMap {
    /// A map of `width × height` linear RGB texels, row 0 at the top.
    pub fn new(width: u32, height: u32, texels: Vec<Rgb>) -> Result<Self, String> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return Err(format!("an environment map of {width}x{height} needs that many texels"));
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite() || t.min_element() < 0.0) {
            return Err(format!(
                "texel ({}, {}) is {} (radiance must be finite and not negative)",
                i % width as usize,
                i / width as usize,
                texels[i]
            ));
        }
        let (w, h) = (width as usize, height as usize);
        let mut column_cdf = Vec::with_capacity(h * (w + 1));
        let mut row_weights = Vec::with_capacity(h);
        let mut integral = Rgb::ZERO;
        for row in 0..h {
            let solid_angle = texel_solid_angle(row, w, h);
            let texels = &texels[row * w..(row + 1) * w];
            let (c, total) = cdf(texels.iter().map(|&t| luminance(t) as f64 * solid_angle));
            column_cdf.extend(c);
            row_weights.push(total);
            integral += texels.iter().copied().sum::<Rgb>() * solid_angle as f32;
        }
        let (row_cdf, total_weight) = cdf(row_weights.into_iter());
        Ok(EnvironmentMap { width, height, texels, row_cdf, column_cdf, total_weight, integral })
    }

    /// Reads an `.hdr` (Radiance RGBE) or `.exr` file; errors name the file.
    pub fn load(path: &Path) -> Result<Self, String> {
        let name = path.display();
        let image = image::open(path).map_err(|e| format!("{name}: cannot read the environment map: {e}"))?;
        Self::from_image(image, &name.to_string())
    }

    /// An `.hdr` or `.exr` file's bytes (told apart by their magic bytes);
    /// errors name the file as `name`.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<Self, String> {
        let image =
            image::load_from_memory(bytes).map_err(|e| format!("{name}: cannot read the environment map: {e}"))?;
        Self::from_image(image, name)
    }

    fn from_image(image: image::DynamicImage, name: &str) -> Result<Self, String> {
        let rgb = image.to_rgb32f();
        let (width, height) = rgb.dimensions();
        let texels = rgb.pixels().map(|p| Vec3::from(p.0)).collect();
        EnvironmentMap::new(width, height, texels).map_err(|e| format!("{name}: {e}"))
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// The marginal CDF over rows (height + 1 entries) and, row after row,
    /// each row's CDF over its texels (width + 1 entries each): what the
    /// GPU tracer samples with (`sample`'s twin).
    pub fn cdfs(&self) -> (&[f32], &[f32]) {
        (&self.row_cdf, &self.column_cdf)
    }

    /// The texels, row by row from the top.
    pub fn texels(&self) -> &[Rgb] {
        &self.texels
    }

    /// ∫ L(ω) dω over the sphere, per channel.
    pub fn integral(&self) -> Rgb {
        self.integral
    }

    /// The texture coordinates of direction `dir` (unit, toward the sky).
    pub fn uv(dir: Vec3) -> Vec2 {
        let u = 0.5 + dir.z.atan2(dir.x) / (2.0 * PI);
        let v = dir.y.clamp(-1.0, 1.0).acos() / PI;
        Vec2::new(u.rem_euclid(1.0), v)
    }

    /// The direction of texture coordinates `uv`.
    pub fn direction(uv: Vec2) -> Vec3 {
        let phi = (uv.x - 0.5) * 2.0 * PI;
        let theta = uv.y * PI;
        let (sin_t, cos_t) = theta.sin_cos();
        // atan2(z, x) = φ: x = r cos φ, z = r sin φ.
        Vec3::new(sin_t * phi.cos(), cos_t, sin_t * phi.sin())
    }

    fn texel_index(&self, uv: Vec2) -> usize {
        let x = ((uv.x * self.width as f32) as usize).min(self.width as usize - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height as usize - 1);
        y * self.width as usize + x
    }

    /// Radiance arriving from direction `dir` (toward the sky).
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        self.texels[self.texel_index(Self::uv(dir))]
    }

    /// Density per steradian with which `sample` returns `dir`.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let uv = Self::uv(dir);
        self.texel_pdf(self.texel_index(uv), uv)
    }

    /// The density of `sample` at coordinates `uv` inside texel `i`: the
    /// texel's share of the weights over its area 1/(w·h) of the unit
    /// square, over the Jacobian 2π² sin θ.
    fn texel_pdf(&self, i: usize, uv: Vec2) -> f32 {
        if self.total_weight <= 0.0 {
            return 0.0;
        }
        let (w, h) = (self.width as usize, self.height as usize);
        let weight = luminance(self.texels[i]) as f64 * texel_solid_angle(i / w, w, h);
        let pdf_uv = (weight / self.total_weight) as f32 * (w * h) as f32;
        let sin_theta = (uv.y * PI).sin();
        if sin_theta <= 0.0 { 0.0 } else { pdf_uv / (2.0 * PI * PI * sin_theta) }
    }

    /// A direction toward the sky drawn ∝ radiance × solid angle; None for
    /// a black map. The point inside the chosen texel keeps 10⁻⁴ of a texel
    /// from its edges, so rounding never carries it into a neighbour (whose
    /// radiance and density would not be the ones drawn).
    pub fn sample(&self, u: Vec2) -> Option<MapSample> {
        if self.total_weight <= 0.0 {
            return None;
        }
        let w = self.width as usize;
        let (row, tv) = sample_cdf(&self.row_cdf, u.y);
        let (column, tu) = sample_cdf(&self.column_cdf[row * (w + 1)..(row + 1) * (w + 1)], u.x);
        let inside = |t: f32| t.clamp(1e-4, 1.0 - 1e-4);
        let uv = Vec2::new((column as f32 + inside(tu)) / w as f32, (row as f32 + inside(tv)) / self.height as f32);
        let i = row * w + column;
        let pdf = self.texel_pdf(i, uv);
        (pdf > 0.0).then(|| MapSample { dir: Self::direction(uv), radiance: self.texels[i], pdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{assert_direction_distribution, assert_unit_density};
    use crate::sampling::{Rng, uniform_sphere};

    /// A 16×8 map: dim blue everywhere, a bright warm patch (a sun) and a
    /// nearly black band, so the density is far from uniform (no texel is
    /// black: the chi-square test's bins straddle texels).
    fn patchy() -> EnvironmentMap {
        let (w, h) = (16, 8);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (5..7).contains(&x) && (2..4).contains(&y) {
                    Vec3::new(40.0, 30.0, 20.0)
                } else if y == 6 {
                    Vec3::splat(0.01)
                } else {
                    Vec3::new(0.2, 0.3, 0.5)
                }
            })
            .collect();
        EnvironmentMap::new(w as u32, h as u32, texels).unwrap()
    }

    #[test]
    fn directions_and_coordinates_invert_each_other() {
        let mut rng = Rng::for_item(3, 0);
        for _ in 0..1000 {
            let d = uniform_sphere(rng.next_2d());
            let back = EnvironmentMap::direction(EnvironmentMap::uv(d));
            assert!((back - d).length() < 1e-4, "{d} → {back}");
        }
        // Blender's layout, worked out from Cycles' u = ½ − atan2(y, x)/2π
        // in its Z-up frame: the zenith on the top row, +X in the middle,
        // −Z (Blender's +Y) a quarter to its left, +Z a quarter to its right,
        // −X at the seam.
        assert!(EnvironmentMap::uv(Vec3::Y).y < 1e-6);
        assert!((EnvironmentMap::uv(Vec3::X) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((EnvironmentMap::uv(-Vec3::Z) - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!((EnvironmentMap::uv(Vec3::Z) - Vec2::new(0.75, 0.5)).length() < 1e-6);
        let seam = EnvironmentMap::uv(-Vec3::X).x;
        assert!(seam < 1e-6 || seam > 1.0 - 1e-6, "{seam}");
    }

    #[test]
    fn sampling_follows_the_density_and_the_density_integrates_to_one() {
        let map = patchy();
        assert_unit_density(|d| map.pdf(d));
        assert_direction_distribution(|u| map.sample(u).map_or(Vec3::Y, |s| s.dir), |d| map.pdf(d));
    }

    /// The density is the radiance's share: L(ω)/p(ω) is the same for every
    /// texel of one colour, and its mean over samples is ∫L dω.
    #[test]
    fn samples_weigh_the_integral() {
        let map = patchy();
        let mut rng = Rng::for_item(5, 0);
        let n = 200_000;
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..n {
            let s = map.sample(rng.next_2d()).expect("a lit map");
            assert_eq!(s.radiance, map.radiance(s.dir));
            sum += (s.radiance / s.pdf).as_dvec3();
        }
        let estimate = (sum / n as f64).as_vec3();
        let rel = ((estimate - map.integral()) / map.integral()).abs().max_element();
        assert!(rel < 0.01, "{estimate} vs {}", map.integral());
    }

    /// A constant map of radiance L integrates to 4πL: the texels' bands
    /// tile the sphere exactly.
    #[test]
    fn a_constant_map_holds_four_pi_l() {
        let map = EnvironmentMap::new(64, 32, vec![Vec3::splat(2.0); 64 * 32]).unwrap();
        let rel = (map.integral() / (8.0 * PI) - Vec3::ONE).abs().max_element();
        assert!(rel < 1e-5, "{}", map.integral());
    }

    #[test]
    fn bad_maps_are_refused() {
        assert!(EnvironmentMap::new(2, 2, vec![Vec3::ONE; 3]).is_err());
        let err = EnvironmentMap::new(2, 1, vec![Vec3::ONE, Vec3::new(f32::NAN, 0.0, 0.0)]).unwrap_err();
        assert!(err.contains("texel (1, 0)"), "{err}");
        let err = EnvironmentMap::load(Path::new("no-such-sky.hdr")).unwrap_err();
        assert!(err.starts_with("no-such-sky.hdr: "), "{err}");
    }
}
