//! How far an image is from a reference: the figures `hikari render
//! --reference` prints and the error-against-time curves use.
//!
//! The figure to report is [`ImageError::relative_to_mean`], the project's
//! metric (`shared/relerr.py`): the per-pixel RMS error divided by the
//! reference's mean. [`ImageError::relative_rmse`] divides by the
//! reference's RMS instead, and reads 1.5–4× lower on images with a hot
//! spot; the older tests keep it.

use crate::render::Image;

/// Side of the pixel blocks of [`ImageError::block_relative_to_mean`] (relerr.py's default).
pub const BLOCK: u32 = 16;

/// The error of an image against a reference of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// √(Σ‖a − b‖² / Σ‖b‖²) over every pixel and channel: the RMS error
    /// relative to the reference's RMS value (0: equal; 1: as far as black).
    pub relative_rmse: f64,
    /// √(mean (a − b)²) / mean(b) over every pixel and channel: relerr.py's
    /// `relRMSE`, the metric the project reports.
    pub relative_to_mean: f64,
    /// The same on the means of [`BLOCK`]² pixel blocks (whole blocks only;
    /// None for images smaller than one): the error that survives local
    /// averaging, bias and blur rather than noise (relerr.py's `block16`).
    pub block_relative_to_mean: Option<f64>,
    /// mean(a) / mean(b) over every pixel and channel: 1 when the image
    /// carries the reference's energy.
    pub mean_ratio: f64,
}

impl std::fmt::Display for ImageError {
    /// relerr.py's line, then the RMS-relative figure.
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "relRMSE {:.4} meanratio {:.4}", self.relative_to_mean, self.mean_ratio)?;
        if let Some(block) = self.block_relative_to_mean {
            write!(f, " block{BLOCK} {block:.4}")?;
        }
        write!(f, " (relative to the reference's RMS: {:.4})", self.relative_rmse)
    }
}

/// `image` against `reference`. Errors if the sizes differ or the reference
/// is black; non-finite pixels of either are an error too (they would make
/// every figure meaningless).
pub fn compare(image: &Image, reference: &Image) -> Result<ImageError, String> {
    compare_where(image, reference, &vec![true; reference.pixels.len()])
}

/// The pixels that are not a light's own (relerr.py's `--exclude-brightest`):
/// false where either image's brightest channel is at least 50 times the
/// median of the reference's values, grown by one pixel. A directly seen
/// light's edge pixels carry sub-pixel noise hundreds of times the scene's,
/// which would drown every other error.
pub fn without_lights(image: &Image, reference: &Image) -> Vec<bool> {
    let brightest = |p: &glam::Vec3| p.max_element();
    let mut values: Vec<f32> = reference.pixels.iter().flat_map(|p| p.to_array()).collect();
    values.sort_by(f32::total_cmp);
    let median = values.get(values.len() / 2).copied().unwrap_or(0.0);
    let (w, h) = (reference.width as i64, reference.height as i64);
    let lit: Vec<bool> = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| brightest(a) >= 50.0 * median || brightest(b) >= 50.0 * median)
        .collect();
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            !(-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    // np.roll wraps around the edges; so does this.
                    let (nx, ny) = ((x + dx).rem_euclid(w), (y + dy).rem_euclid(h));
                    lit[(ny * w + nx) as usize]
                })
            })
        })
        .collect()
}

/// [`compare`] over the pixels where `mask` is true (blocks count when 90%
/// of their pixels do, as relerr.py's).
pub fn compare_where(image: &Image, reference: &Image, mask: &[bool]) -> Result<ImageError, String> {
    if (image.width, image.height) != (reference.width, reference.height) {
        return Err(format!(
            "the image is {}x{} and the reference {}x{}",
            image.width, image.height, reference.width, reference.height
        ));
    }
    let (mut diff2, mut ref2, mut sum, mut ref_sum) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut values = 0.0;
    for ((a, b), &kept) in image.pixels.iter().zip(&reference.pixels).zip(mask) {
        if !a.is_finite() || !b.is_finite() {
            return Err("a pixel is not finite".into());
        }
        if !kept {
            continue;
        }
        values += 3.0;
        for c in 0..3 {
            let (a, b) = (a[c] as f64, b[c] as f64);
            diff2 += (a - b) * (a - b);
            ref2 += b * b;
            sum += a;
            ref_sum += b;
        }
    }
    if ref2 == 0.0 || ref_sum == 0.0 {
        return Err("the reference is black".into());
    }
    let (block_image, kept) = block_means(image, mask);
    let (block_reference, _) = block_means(reference, mask);
    let whole: Vec<usize> = (0..kept.len()).filter(|&b| kept[b]).collect();
    let block_relative_to_mean = (!whole.is_empty()).then(|| {
        let channels = || whole.iter().flat_map(|&b| 3 * b..3 * b + 3);
        let diff2: f64 = channels().map(|i| (block_image[i] - block_reference[i]).powi(2)).sum();
        let mean = channels().map(|i| block_reference[i]).sum::<f64>() / (3 * whole.len()) as f64;
        (diff2 / (3 * whole.len()) as f64).sqrt() / mean
    });
    Ok(ImageError {
        relative_rmse: (diff2 / ref2).sqrt(),
        relative_to_mean: (diff2 / values).sqrt() / (ref_sum / values),
        block_relative_to_mean,
        mean_ratio: sum / ref_sum,
    })
}

/// Each channel's mean over the kept pixels of each whole [`BLOCK`]²
/// block, block by block, and whether 90% of a block's pixels are kept.
fn block_means(image: &Image, mask: &[bool]) -> (Vec<f64>, Vec<bool>) {
    let (columns, rows) = (image.width / BLOCK, image.height / BLOCK);
    let blocks = (columns * rows) as usize;
    let (mut sums, mut counts) = (vec![0.0f64; 3 * blocks], vec![0u32; blocks]);
    for y in 0..rows * BLOCK {
        for x in 0..columns * BLOCK {
            let i = (y * image.width + x) as usize;
            if !mask[i] {
                continue;
            }
            let block = ((y / BLOCK) * columns + x / BLOCK) as usize;
            counts[block] += 1;
            for c in 0..3 {
                sums[3 * block + c] += image.pixels[i][c] as f64;
            }
        }
    }
    for (b, &n) in counts.iter().enumerate() {
        for c in 0..3 {
            sums[3 * b + c] /= n.max(1) as f64;
        }
    }
    (sums, counts.iter().map(|&n| n as f64 >= 0.9 * (BLOCK * BLOCK) as f64).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn image(pixels: &[[f32; 3]]) -> Image {
        let mut i = Image::new(pixels.len() as u32, 1);
        i.pixels = pixels.iter().map(|&p| Vec3::from(p)).collect();
        i
    }

    #[test]
    fn hand_computed_values() {
        let reference = image(&[[1.0, 1.0, 1.0], [3.0, 3.0, 3.0]]);
        // Equal: no error.
        let e = compare(&reference, &reference).unwrap();
        assert_eq!((e.relative_rmse, e.mean_ratio), (0.0, 1.0));
        // Twice the reference: RMS error equals the reference's RMS; mean doubled.
        let e = compare(&image(&[[2.0, 2.0, 2.0], [6.0, 6.0, 6.0]]), &reference).unwrap();
        assert!((e.relative_rmse - 1.0).abs() < 1e-12 && (e.mean_ratio - 2.0).abs() < 1e-12);
        // One channel of one pixel off by 1: √(1 / (3·1 + 3·9)) = √(1/30).
        let e = compare(&image(&[[1.0, 2.0, 1.0], [3.0, 3.0, 3.0]]), &reference).unwrap();
        assert!((e.relative_rmse - (1.0f64 / 30.0).sqrt()).abs() < 1e-12, "{e:?}");
        assert!((e.mean_ratio - 13.0 / 12.0).abs() < 1e-12, "{e:?}");
        // Relative to the mean (relerr.py): √(1/6) / 2.
        assert!((e.relative_to_mean - (1.0f64 / 6.0).sqrt() / 2.0).abs() < 1e-12, "{e:?}");
        assert_eq!(e.block_relative_to_mean, None, "no whole block");
        // Black: as far as black can be.
        let e = compare(&image(&[[0.0; 3], [0.0; 3]]), &reference).unwrap();
        assert!((e.relative_rmse - 1.0).abs() < 1e-12 && e.mean_ratio == 0.0);
    }

    /// A hot spot: one bright pixel in a dim image, each pixel off by ±10%
    /// in a checker. Relative to the mean the figures are relerr.py's (from
    /// numpy on the same arrays: 0.3796783 and block16 0.0229144); relative
    /// to the RMS the error reads 0.1, 3.8× lower.
    #[test]
    fn relative_to_the_mean_as_relerr() {
        let mut reference = Image::new(32, 16);
        for (i, p) in reference.pixels.iter_mut().enumerate() {
            *p = Vec3::splat(if i == 0 { 100.0 } else { 1.0 });
        }
        let mut test = reference.clone();
        for (i, p) in test.pixels.iter_mut().enumerate() {
            *p *= if (i + i / 32) % 2 == 0 { 1.1 } else { 0.9 };
        }
        let e = compare(&test, &reference).unwrap();
        assert!((e.relative_to_mean - 0.3796783).abs() < 1e-6, "{e:?}");
        assert!((e.block_relative_to_mean.unwrap() - 0.0229144).abs() < 1e-6, "{e:?}");
        assert!((e.relative_rmse - 0.1).abs() < 1e-6, "{e:?}");
        assert!(e.to_string().starts_with("relRMSE 0."), "{e}");
    }

    /// One light pixel masks itself and its 8 neighbours (wrapping at the
    /// edges, as relerr.py's np.roll); the rest compares as before.
    #[test]
    fn lights_are_left_out() {
        let mut reference = Image::new(16, 16);
        reference.pixels.fill(Vec3::ONE);
        reference.pixels[5 * 16 + 7] = Vec3::splat(1000.0);
        let mut test = reference.clone();
        test.pixels[5 * 16 + 7] = Vec3::splat(10.0);
        test.pixels[15 * 16 + 15] = Vec3::splat(60.0);
        let mask = without_lights(&test, &reference);
        assert_eq!(mask.iter().filter(|&&k| !k).count(), 18);
        assert!(!mask[4 * 16 + 6] && !mask[6 * 16 + 8] && mask[7 * 16 + 7]);
        assert!(!mask[0] && !mask[15], "the corner's neighbours wrap around");
        let e = compare_where(&test, &reference, &mask).unwrap();
        assert_eq!((e.relative_to_mean, e.mean_ratio), (0.0, 1.0));
        assert_eq!(e.block_relative_to_mean, Some(0.0), "238 of 256 kept: the block counts");
    }

    #[test]
    fn mismatches_are_errors() {
        let reference = image(&[[1.0; 3], [1.0; 3]]);
        assert!(compare(&image(&[[1.0; 3]]), &reference).unwrap_err().contains("1x1"));
        assert!(compare(&reference, &image(&[[0.0; 3], [0.0; 3]])).unwrap_err().contains("black"));
        assert!(compare(&image(&[[f32::NAN; 3], [1.0; 3]]), &reference).is_err());
    }
}
