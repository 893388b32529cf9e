//! Writing images: `.png` (tone-mapped 8-bit sRGB) or `.exr` (linear float
//! RGB); reading `.exr` back (references to compare with). Files are written under a temporary name in the same folder and
//! renamed into place, so a failed write never leaves a half file.

use crate::render::Image;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{path}: unsupported image type (use .png or .exr)")]
    UnsupportedExtension { path: String },
    #[error("{path}: cannot write image: {source}")]
    Write { path: String, source: Box<dyn std::error::Error + Send + Sync> },
}

/// sRGB transfer function (IEC 61966-2-1) of a linear value in [0,1].
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

/// Exposure in stops (value × 2^exposure), clamp to [0,1], sRGB encode.
pub fn tone_map(image: &Image, exposure: f32) -> Vec<u8> {
    let scale = 2f32.powf(exposure);
    image
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|c| {
            let v = if c.is_finite() { (c * scale).clamp(0.0, 1.0) } else { 0.0 };
            (linear_to_srgb(v) * 255.0 + 0.5) as u8
        })
        .collect()
}

pub fn write_image(path: &Path, image: &Image, exposure: f32) -> Result<(), OutputError> {
    let shown = path.display().to_string();
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("png") => ::image::ImageFormat::Png,
        Some("exr") => ::image::ImageFormat::OpenExr,
        _ => return Err(OutputError::UnsupportedExtension { path: shown }),
    };
    save_atomically(path, |tmp| match format {
        ::image::ImageFormat::Png => ::image::RgbImage::from_raw(image.width, image.height, tone_map(image, exposure))
            .expect("buffer size matches the image")
            .save_with_format(tmp, format),
        _ => {
            let data: Vec<f32> =
                image.pixels.iter().flat_map(|p| p.to_array()).map(|c| if c.is_finite() { c } else { 0.0 }).collect();
            ::image::Rgb32FImage::from_raw(image.width, image.height, data)
                .expect("buffer size matches the image")
                .save_with_format(tmp, format)
        }
    })
}

/// An auxiliary image written beside the colour (`--aov`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aov {
    Albedo,
    Normal,
    Depth,
}

impl Aov {
    /// Blender's pass names, so its compositor (the Denoise node) and OIDN
    /// front ends find them: "Denoising Albedo" (R, G, B), "Denoising
    /// Normal" (X, Y, Z), "Depth" (Z).
    fn channels(self) -> (&'static str, &'static [&'static str]) {
        match self {
            Aov::Albedo => ("Denoising Albedo", &["R", "G", "B"]),
            Aov::Normal => ("Denoising Normal", &["X", "Y", "Z"]),
            Aov::Depth => ("Depth", &["Z"]),
        }
    }
}

/// Writes `image` as an EXR's R, G, B channels (what any reader takes as
/// the picture) with the AOVs `which` from `aovs` as further channels named
/// as Blender names its passes ("Denoising Albedo.R", …, "Depth.Z"),
/// atomically. Depth keeps infinity where the camera ray hits nothing.
pub fn write_exr_with_aovs(
    path: &Path,
    image: &Image,
    aovs: &crate::render::aov::Aovs,
    which: &[Aov],
) -> Result<(), OutputError> {
    use exr::prelude::*;
    let shown = path.display().to_string();
    if path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("exr") {
        return Err(OutputError::UnsupportedExtension { path: shown });
    }
    let finite = |c: f32| if c.is_finite() { c } else { 0.0 };
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        channels.push(AnyChannel::new(*name, FlatSamples::F32(image.pixels.iter().map(|p| finite(p[c])).collect())));
    }
    for aov in which {
        let (pass, names) = aov.channels();
        for (c, name) in names.iter().enumerate() {
            let samples: Vec<f32> = match aov {
                Aov::Albedo => aovs.albedo.pixels.iter().map(|p| p[c]).collect(),
                Aov::Normal => aovs.normal.pixels.iter().map(|p| p[c]).collect(),
                Aov::Depth => aovs.depth.clone(),
            };
            channels.push(AnyChannel::new(format!("{pass}.{name}").as_str(), FlatSamples::F32(samples)));
        }
    }
    let size = (image.width as usize, image.height as usize);
    let layer = Layer::new(size, LayerAttributes::default(), Encoding::FAST_LOSSLESS, AnyChannels::sort(channels));
    let exr_image = exr::image::Image::from_layer(layer);
    atomically(path, |tmp| exr_image.write().to_file(tmp).map_err(|e| e.to_string()))
        .map_err(|e| OutputError::Write { path: shown, source: e.into() })
}

/// Writes an 8-bit sRGB image (`data`: RGB rows, `width` × `height`) as
/// PNG, atomically, as [`write_image`] does (a chart, a screenshot).
pub fn write_rgb8_png(path: &Path, width: u32, height: u32, data: Vec<u8>) -> Result<(), OutputError> {
    let image = ::image::RgbImage::from_raw(width, height, data).expect("buffer size matches the image");
    save_atomically(path, |tmp| image.save_with_format(tmp, ::image::ImageFormat::Png))
}

/// Writes by `write` to a temporary name beside `path`, then renames it,
/// so no half-written file ever has the name asked for. Errors name `path`.
pub fn atomically(path: &Path, write: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), String> {
    let tmp = temporary_name(path);
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("{}: {e}", path.display()));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}

/// Saves by `save` to a temporary name beside `path`, then renames it, so
/// no half-written file ever has the name asked for.
fn save_atomically(path: &Path, save: impl FnOnce(&Path) -> ::image::ImageResult<()>) -> Result<(), OutputError> {
    let shown = path.display().to_string();
    let wrap = |e: Box<dyn std::error::Error + Send + Sync>| OutputError::Write { path: shown.clone(), source: e };
    let tmp = temporary_name(path);
    if let Err(e) = save(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(wrap(Box::new(e)));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        wrap(Box::new(e))
    })
}

/// Reads an `.exr` file as linear float RGB. Other types are refused: a
/// tone-mapped PNG cannot be turned back into radiance.
pub fn read_exr(path: &Path) -> Result<Image, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("exr") {
        return Err("not an .exr file (a tone-mapped PNG is not radiance)".into());
    }
    let decoded = ::image::open(path).map_err(|e| e.to_string())?.to_rgb32f();
    let mut image = Image::new(decoded.width(), decoded.height());
    for (p, q) in image.pixels.iter_mut().zip(decoded.pixels()) {
        *p = glam::Vec3::from(q.0);
    }
    if image.pixels.iter().any(|p| !p.is_finite()) {
        return Err("it has non-finite pixels".into());
    }
    Ok(image)
}

fn temporary_name(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The AOVs come back under Blender's pass names, depth's infinity
    /// kept, and the picture stays what `read_exr` reads.
    #[test]
    fn aovs_are_channels_named_as_blender_names_its_passes() {
        use exr::prelude::{ReadChannels, ReadLayers, Text, read};
        let dir = std::env::temp_dir().join(format!("hikari-aov-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("aov.exr");
        let mut color = Image::new(2, 1);
        color.pixels = vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(f32::NAN, 0.5, 0.25)];
        let mut albedo = Image::new(2, 1);
        albedo.pixels = vec![Vec3::new(0.1, 0.2, 0.3), Vec3::ZERO];
        let mut normal = Image::new(2, 1);
        normal.pixels = vec![Vec3::Z, Vec3::ZERO];
        let aovs = crate::render::aov::Aovs { albedo, normal, depth: vec![4.5, f32::INFINITY] };
        write_exr_with_aovs(&path, &color, &aovs, &[Aov::Albedo, Aov::Normal, Aov::Depth]).unwrap();
        let image =
            read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer().all_attributes();
        let image = image.from_file(&path).unwrap();
        let channel = |name: &str| -> Vec<f32> {
            let c = image.layer_data.channel_data.list.iter().find(|c| c.name == Text::from(name)).expect(name);
            c.sample_data.values_as_f32().collect()
        };
        assert_eq!(channel("Denoising Albedo.G"), vec![0.2, 0.0]);
        assert_eq!(channel("Denoising Normal.Z"), vec![1.0, 0.0]);
        assert_eq!(channel("Depth.Z"), vec![4.5, f32::INFINITY]);
        assert_eq!(channel("R"), vec![1.0, 0.0], "NaN never reaches the picture");
        let read_back = read_exr(&path).unwrap();
        assert_eq!(read_back.pixels[0], Vec3::new(1.0, 2.0, 3.0));
        assert!(write_exr_with_aovs(&dir.join("aov.png"), &color, &aovs, &[Aov::Depth]).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn png_and_exr_are_written_and_read_back() {
        let dir = std::env::temp_dir().join(format!("hikari-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut img = Image::new(4, 2);
        img.pixels[0] = Vec3::new(1.0, 0.5, 0.0);
        img.pixels[1] = Vec3::new(f32::NAN, f32::INFINITY, 2.0);
        write_image(&dir.join("a.png"), &img, 0.0).unwrap();
        let png = ::image::open(dir.join("a.png")).unwrap().to_rgb8();
        assert_eq!(png.get_pixel(0, 0).0, [255, 188, 0]);
        assert_eq!(png.get_pixel(1, 0).0, [0, 0, 255]);
        write_image(&dir.join("a.exr"), &img, 0.0).unwrap();
        let exr = ::image::open(dir.join("a.exr")).unwrap().to_rgb32f();
        assert_eq!(exr.get_pixel(0, 0).0, [1.0, 0.5, 0.0]);
        assert_eq!(exr.get_pixel(1, 0).0, [0.0, 0.0, 2.0]);
        let back = read_exr(&dir.join("a.exr")).unwrap();
        assert_eq!(&back.pixels[..2], &[img.pixels[0], Vec3::new(0.0, 0.0, 2.0)]);
        assert!(read_exr(&dir.join("a.png")).unwrap_err().contains("PNG"));
        assert!(read_exr(&dir.join("missing.exr")).is_err());
        assert!(matches!(write_image(&dir.join("a.jpg"), &img, 0.0), Err(OutputError::UnsupportedExtension { .. })));
        // A failed write leaves nothing behind.
        assert!(write_image(&dir.join("missing-dir/a.png"), &img, 0.0).is_err());
        let leftovers: Vec<_> =
            std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
        assert_eq!(leftovers.len(), 2, "{leftovers:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
