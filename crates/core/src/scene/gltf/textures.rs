//! glTF images and samplers as [`crate::texture`] images: each image a
//! material reads is decoded once per colour space it is read in (sRGB for
//! base colour and emission, linear for metallic–roughness), from the
//! `.glb`'s buffer views, data URIs or files beside the `.gltf`.

use super::error;
use crate::scene::SceneError;
use crate::scene::files::SceneFiles;
use crate::texture::{ColorSpace, Image, Sampler, TextureRef, Wrap};
use std::collections::HashMap;

/// The decoded images, by (glTF image index, colour space).
#[derive(Default)]
pub struct Images {
    pub images: Vec<Image>,
    index: HashMap<(usize, ColorSpace), u32>,
}

impl Images {
    /// The texture `info` reads in `space`; None if it reads a texture
    /// coordinate set other than 0 (the caller notes it) or has no image.
    pub fn texture(&self, info: &gltf::texture::Info, space: ColorSpace) -> Option<TextureRef> {
        let transform = info.texture_transform().map(|t| Transform {
            offset: t.offset(),
            rotation: t.rotation(),
            scale: t.scale(),
            tex_coord: t.tex_coord(),
        });
        self.reference(&info.texture(), info.tex_coord(), transform, space)
    }

    /// A material's normal texture (linear data), with its `scale`.
    pub fn normal(
        &self,
        info: &gltf::material::NormalTexture,
        json: &gltf::json::material::NormalTexture,
    ) -> Option<(TextureRef, f32)> {
        let transform = json.extensions.as_ref().and_then(|e| e.others.get(TRANSFORM)).and_then(Transform::from_json);
        Some((self.reference(&info.texture(), info.tex_coord(), transform, ColorSpace::Linear)?, info.scale()))
    }

    /// A texture named by a texture info in raw JSON (`KHR_materials_clearcoat`'s and
    /// `KHR_materials_sheen`'s, which the `gltf` crate does not parse);
    /// None where it names no texture or reads a set other than 0.
    pub fn from_json(&self, doc: &gltf::Document, info: &gltf::json::Value, space: ColorSpace) -> Option<TextureRef> {
        let (texture, tex_coord, transform) = json_info(doc, info)?;
        self.reference(&texture, tex_coord, transform, space)
    }

    fn reference(
        &self,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<Transform>,
        space: ColorSpace,
    ) -> Option<TextureRef> {
        // The extension's texCoord, where it has one, replaces the texture's.
        if transform.as_ref().and_then(|t| t.tex_coord).unwrap_or(tex_coord) != 0 {
            return None;
        }
        let image = *self.index.get(&(image_index(texture), space))?;
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        };
        let sampler = texture.sampler();
        let mut reference =
            TextureRef::new(image, Sampler { wrap_s: wrap(sampler.wrap_s()), wrap_t: wrap(sampler.wrap_t()) });
        if let Some(t) = transform {
            reference.transform = t.matrix();
        }
        Some(reference)
    }
}

/// The texture coordinate set a normal texture reads (the transform's
/// texCoord where it has one).
pub fn normal_tex_coord(info: &gltf::material::NormalTexture, json: &gltf::json::material::NormalTexture) -> u32 {
    let transform = json.extensions.as_ref().and_then(|e| e.others.get(TRANSFORM)).and_then(Transform::from_json);
    transform.and_then(|t| t.tex_coord).unwrap_or(info.tex_coord())
}

/// A texture info given as raw JSON: its texture, `texCoord` and
/// `KHR_texture_transform`; None where `index` names no texture.
fn json_info<'a>(
    doc: &'a gltf::Document,
    info: &gltf::json::Value,
) -> Option<(gltf::Texture<'a>, u32, Option<Transform>)> {
    let texture = doc.textures().nth(usize::try_from(info.get("index")?.as_u64()?).ok()?)?;
    let tex_coord = info.get("texCoord").and_then(|c| c.as_u64()).map_or(0, |c| c.min(u32::MAX as u64) as u32);
    let transform = info.get("extensions").and_then(|e| e.get(TRANSFORM)).and_then(Transform::from_json);
    Some((texture, tex_coord, transform))
}

/// The texture infos of a material extension's JSON (`extension`), by key
/// and the colour space each is read in.
pub fn extension_textures<'v>(
    m: &'v gltf::Material,
    extension: &str,
    keys: &[(&'static str, ColorSpace)],
) -> Vec<(&'static str, &'v gltf::json::Value, ColorSpace)> {
    let Some(v) = m.extension_value(extension) else { return Vec::new() };
    keys.iter().filter_map(|&(key, space)| Some((key, v.get(key)?, space))).collect()
}

/// The clear coat's and the sheen's textures hikari reads, with their
/// colour spaces.
pub const LAYER_JSON_TEXTURES: [(&str, &[(&str, ColorSpace)]); 2] = [
    (
        super::materials::CLEARCOAT,
        &[
            ("clearcoatTexture", ColorSpace::Linear),
            ("clearcoatRoughnessTexture", ColorSpace::Linear),
            ("clearcoatNormalTexture", ColorSpace::Linear),
        ],
    ),
    (
        super::materials::SHEEN,
        &[("sheenColorTexture", ColorSpace::Srgb), ("sheenRoughnessTexture", ColorSpace::Linear)],
    ),
];

/// The extension's name, as it appears in a texture info's `extensions`.
pub const TRANSFORM: &str = "KHR_texture_transform";

/// A texture info's `KHR_texture_transform`.
struct Transform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
    tex_coord: Option<u32>,
}

impl Transform {
    /// The extension as raw JSON (the `gltf` crate parses it on
    /// `textureInfo`s only, not on a normal texture's); None where it is
    /// not an object of the extension's fields.
    fn from_json(value: &gltf::json::Value) -> Option<Transform> {
        let parsed: gltf::json::extensions::texture::TextureTransform =
            gltf::json::deserialize::from_value(value.clone()).ok()?;
        Some(Transform {
            offset: parsed.offset.0,
            rotation: parsed.rotation.0,
            scale: parsed.scale.0,
            tex_coord: parsed.tex_coord,
        })
    }

    /// The matrix; non-finite values (a broken file) as the extension's
    /// defaults, so that no coordinate becomes NaN.
    fn matrix(&self) -> glam::Affine2 {
        let finite = |v: [f32; 2], default: f32| glam::Vec2::from(v.map(|x| if x.is_finite() { x } else { default }));
        let rotation = if self.rotation.is_finite() { self.rotation } else { 0.0 };
        crate::texture::uv_transform(finite(self.offset, 0.0), rotation, finite(self.scale, 1.0))
    }
}

/// The extension that gives a texture a WebP image.
pub const WEBP: &str = "EXT_texture_webp";

/// The image a texture shows: its `EXT_texture_webp` source where it has
/// one (hikari decodes WebP), else its `source` (which validation made sure
/// it has where it has no WebP one).
fn image_index(texture: &gltf::Texture) -> usize {
    let webp = texture.extensions().and_then(|e| e.get(WEBP)).and_then(|w| w.get("source")).and_then(|s| s.as_u64());
    webp.map_or_else(|| texture.source().index(), |s| s as usize)
}

/// The textures each material reads, with the glTF path that reads them.
fn used_textures<'a>(doc: &'a gltf::Document) -> Vec<(String, gltf::Texture<'a>, ColorSpace)> {
    let mut used = Vec::new();
    for m in doc.materials() {
        let at = format!("materials[{}]", m.index().unwrap_or(0));
        let pbr = m.pbr_metallic_roughness();
        let mut push = |name: &str, texture: Option<(gltf::Texture<'a>, u32)>, space| {
            if let Some((texture, 0)) = texture {
                used.push((format!("{at}.{name}"), texture, space));
            }
        };
        let info = |i: Option<gltf::texture::Info<'a>>| {
            i.map(|i| (i.texture(), i.texture_transform().and_then(|t| t.tex_coord()).unwrap_or(i.tex_coord())))
        };
        push("pbrMetallicRoughness.baseColorTexture", info(pbr.base_color_texture()), ColorSpace::Srgb);
        let mr = info(pbr.metallic_roughness_texture());
        push("pbrMetallicRoughness.metallicRoughnessTexture", mr, ColorSpace::Linear);
        push("emissiveTexture", info(m.emissive_texture()), ColorSpace::Srgb);
        let json = m.index().and_then(|i| doc.as_json().materials.get(i)).and_then(|m| m.normal_texture.as_ref());
        let normal = m.normal_texture().zip(json).map(|(n, json)| (n.texture(), normal_tex_coord(&n, json)));
        push("normalTexture", normal, ColorSpace::Linear);
        if let Some(s) = m.specular() {
            push("extensions.KHR_materials_specular.specularTexture", info(s.specular_texture()), ColorSpace::Linear);
            let color = info(s.specular_color_texture());
            push("extensions.KHR_materials_specular.specularColorTexture", color, ColorSpace::Srgb);
        }
        if let Some(t) = m.transmission() {
            let texture = info(t.transmission_texture());
            push("extensions.KHR_materials_transmission.transmissionTexture", texture, ColorSpace::Linear);
        }
        for (extension, keys) in LAYER_JSON_TEXTURES {
            for (key, value, space) in extension_textures(&m, extension, keys) {
                let read = json_info(doc, value).map(|(texture, tex_coord, transform)| {
                    (texture, transform.and_then(|t| t.tex_coord).unwrap_or(tex_coord))
                });
                push(&format!("extensions.{extension}.{key}"), read, space);
            }
        }
    }
    used
}

/// Decodes every image a material reads (PNG or JPEG); a missing or
/// undecodable one is an error at `images[i]`.
pub fn load(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    files: SceneFiles,
    file: &str,
) -> Result<Images, SceneError> {
    let mut out = Images::default();
    for (used_at, texture, space) in used_textures(doc) {
        let index = image_index(&texture);
        let key = (index, space);
        if out.index.contains_key(&key) {
            continue;
        }
        let at = format!("images[{index}] (read by {used_at})");
        let image = doc.images().nth(index).ok_or_else(|| {
            error(file, format!("textures[{}]", texture.index()), format!("image {index} does not exist"))
        })?;
        let decoded = decode(doc, &image, buffers, files).map_err(|m| error(file, &at, m))?;
        let texels =
            to_image(&decoded, space).ok_or_else(|| error(file, &at, "has a pixel format hikari cannot read"))?;
        out.index.insert(key, out.images.len() as u32);
        out.images.push(texels);
    }
    Ok(out)
}

/// A decoded image as the `gltf` crate gives one (its `Data::new`, which
/// it keeps private).
fn image_data(image: image::DynamicImage) -> Option<gltf::image::Data> {
    use gltf::image::Format;
    use image::DynamicImage as D;
    let format = match image {
        D::ImageLuma8(_) => Format::R8,
        D::ImageLumaA8(_) => Format::R8G8,
        D::ImageRgb8(_) => Format::R8G8B8,
        D::ImageRgba8(_) => Format::R8G8B8A8,
        D::ImageLuma16(_) => Format::R16,
        D::ImageLumaA16(_) => Format::R16G16,
        D::ImageRgb16(_) => Format::R16G16B16,
        D::ImageRgba16(_) => Format::R16G16B16A16,
        D::ImageRgb32F(_) => Format::R32G32B32FLOAT,
        D::ImageRgba32F(_) => Format::R32G32B32A32FLOAT,
        _ => return None,
    };
    let (width, height) = (image.width(), image.height());
    Some(gltf::image::Data { pixels: image.into_bytes(), format, width, height })
}

/// One image's pixels (PNG, JPEG or WebP, told apart by their bytes).
fn decode(
    doc: &gltf::Document,
    image: &gltf::image::Image,
    buffers: &[gltf::buffer::Data],
    files: SceneFiles,
) -> Result<gltf::image::Data, String> {
    let json = &doc.as_json().images[image.index()];
    let (what, bytes) = match (&json.buffer_view, &json.uri) {
        (Some(view), _) => {
            if json.mime_type.is_none() {
                return Err("is stored in a buffer view but has no mimeType".into());
            }
            let view = doc.views().nth(view.value()).ok_or("refers to a buffer view that does not exist")?;
            let buffer = buffers.get(view.buffer().index()).map_or(&[][..], |b| &b[..]);
            let end = view.offset().checked_add(view.length()).filter(|&end| end <= buffer.len());
            let Some(end) = end else {
                return Err(format!("reads bufferViews[{}], beyond its buffer's {} bytes", view.index(), buffer.len()));
            };
            (format!("the image in bufferViews[{}]", view.index()), buffer[view.offset()..end].to_vec())
        }
        (None, Some(uri)) if uri.starts_with("data:") => {
            let source = gltf::buffer::Source::Uri(uri);
            let data = gltf::buffer::Data::from_source_and_blob(source, None, &mut None)
                .map_err(|e| format!("cannot read its data URI: {e}"))?;
            ("its data URI".to_string(), data.0)
        }
        (None, Some(uri)) => (format!("\"{uri}\""), files.read(uri, true)?),
        (None, None) => return Err("has neither a uri nor a bufferView".into()),
    };
    let decoded = image::load_from_memory(&bytes).map_err(|e| format!("cannot read {what}: {e}"))?;
    image_data(decoded).ok_or_else(|| format!("{what} has a pixel format hikari cannot read"))
}

/// The `gltf` crate's pixels as a linear image.
fn to_image(data: &gltf::image::Data, space: ColorSpace) -> Option<Image> {
    use gltf::image::Format;
    let (w, h, p) = (data.width, data.height, &data.pixels);
    let eight = |channels| Image::from_integers(w, h, channels, p.iter().map(|&b| b as u32), 255, space);
    let sixteen = |channels| {
        let values = p.chunks_exact(2).map(|b| u16::from_ne_bytes([b[0], b[1]]) as u32);
        Image::from_integers(w, h, channels, values, 65535, space)
    };
    match data.format {
        Format::R8 => eight(1),
        Format::R8G8 => eight(2),
        Format::R8G8B8 => eight(3),
        Format::R8G8B8A8 => eight(4),
        Format::R16 => sixteen(1),
        Format::R16G16 => sixteen(2),
        Format::R16G16B16 => sixteen(3),
        Format::R16G16B16A16 => sixteen(4),
        Format::R32G32B32FLOAT | Format::R32G32B32A32FLOAT => None,
    }
}
