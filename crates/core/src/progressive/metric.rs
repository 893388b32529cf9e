//! How far an image is from a reference: the figures `hikari render
//! --reference` prints and the error-against-time curves use.

use crate::render::Image;

/// The error of an image against a reference of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// √(Σ‖a − b‖² / Σ‖b‖²) over every pixel and channel: the RMS error
    /// relative to the reference's RMS value (0: equal; 1: as far as black).
    pub relative_rmse: f64,
    /// mean(a) / mean(b) over every pixel and channel: 1 when the image
    /// carries the reference's energy.
    pub mean_ratio: f64,
}

/// `image` against `reference`. Errors if the sizes differ or the reference
/// is black; non-finite pixels of either are an error too (they would make
/// every figure meaningless).
pub fn compare(image: &Image, reference: &Image) -> Result<ImageError, String> {
    if (image.width, image.height) != (reference.width, reference.height) {
        return Err(format!(
            "the image is {}x{} and the reference {}x{}",
            image.width, image.height, reference.width, reference.height
        ));
    }
    let (mut diff2, mut ref2, mut sum, mut ref_sum) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (a, b) in image.pixels.iter().zip(&reference.pixels) {
        if !a.is_finite() || !b.is_finite() {
            return Err("a pixel is not finite".into());
        }
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
    Ok(ImageError { relative_rmse: (diff2 / ref2).sqrt(), mean_ratio: sum / ref_sum })
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
        // Black: as far as black can be.
        let e = compare(&image(&[[0.0; 3], [0.0; 3]]), &reference).unwrap();
        assert!((e.relative_rmse - 1.0).abs() < 1e-12 && e.mean_ratio == 0.0);
    }

    #[test]
    fn mismatches_are_errors() {
        let reference = image(&[[1.0; 3], [1.0; 3]]);
        assert!(compare(&image(&[[1.0; 3]]), &reference).unwrap_err().contains("1x1"));
        assert!(compare(&reference, &image(&[[0.0; 3], [0.0; 3]])).unwrap_err().contains("black"));
        assert!(compare(&image(&[[f32::NAN; 3], [1.0; 3]]), &reference).is_err());
    }
}
