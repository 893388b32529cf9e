//! The scene's textures on the GPU: every image of `Scene::texturing` with
//! its mip chain, packed into one storage buffer of 32-bit texels (8 bits a
//! channel, sRGB-encoded where the image holds colour), then the texture
//! coordinates of every BVH primitive. `textures.wgsl` samples them with
//! the CPU's bilinear filter and wrap modes (`hikari_core::texture::Image::sample`,
//! pinned by a test); the G-buffer pass picks a mip level from the pixel's
//! footprint, the passes that trace rays read level 0 as the CPU does.
//!
//! One buffer, not texture arrays: it works in every stage on every
//! adapter the project supports (no bindless on GL), costs one binding,
//! holds images of any size without size classes, and the filter is
//! written once, twin of the CPU's.
//!
//! # Layout (u32 words)
//!
//! * `[0]` image count, `[1]` word offset of the texture coordinates (0:
//!   none), `[2]` word offset of the sky image's sampling block (0: none;
//!   `sky_block`, in the photon tracer's buffer only), `[3]` word offset of
//!   the tangents (0: none).
//! * per texture view (`TextureViews`: each image, then each image with a
//!   `KHR_texture_transform` a material reads it through), `VIEW_WORDS`
//!   words from `HEADER_WORDS`: width, height, level count, flags (bit 0:
//!   sRGB-encoded, bit 1: transformed), the transform's six f32 (its columns: x axis, y axis,
//!   translation), then the word offset of each level (a view shares its
//!   image's levels).
//! * per material with clear-coat, sheen or specular textures
//!   (`LayerTextures`) or a coat apart from its base's normal
//!   (`MaterialTextures::coat_apart`), in material order,
//!   eight words: those textures' view references (`texture_ref`;
//!   `NO_TEXTURE` for none) in `LayerTextures::all`'s order, then the coat
//!   normal texture's reference and its scale's f32 bits;
//!   `GpuSurface::layer_textures` holds where its eight start
//!   (`TextureViews::layer_table`).
//! * the levels' texels, row by row from the top, `pack4x8unorm` order
//!   (r in the low byte).
//! * per BVH primitive (`FlatBvh::prims` order), its three vertices' (u, v)
//!   as f32 bits; six `NO_TEXTURE` words for primitives without coordinates.
//! * where some triangle has stored tangents (`Texturing::tangents`), per
//!   BVH primitive its three vertices' `PackedTangent`s, two words each
//!   (x | y << 16, z | w << 16, as `unpack2x16snorm` reads them); zeros for
//!   primitives without.

use hikari_core::geometry::FlatBvh;
use hikari_core::scene::Scene;
use hikari_core::texture::{ColorSpace, Image, Sampler, TextureRef, Texturing, Wrap};

/// The texture lookups; the includer declares `texture_data`.
pub static TEXTURES: crate::wgsl::Module =
    crate::wgsl::Module { name: "textures.wgsl", source: include_str!("textures.wgsl"), requires: &[] };

/// A surface at a point with its textures (`surface_point`), and the
/// G-buffer's packing of textured metallic and roughness.
pub static SURFACE_POINT: crate::wgsl::Module = crate::wgsl::Module {
    name: "surface_point.wgsl",
    source: include_str!("surface_point.wgsl"),
    requires: &[
        &TEXTURES,
        &crate::wgsl::SURFACE,
        &crate::wgsl::BSDF,
        &crate::wgsl::RANDOM,
        &crate::gbuffer::layer_texels::LAYER_TEXELS,
    ],
};

/// A surface without this texture (`GpuSurface`'s texture fields).
pub const NO_TEXTURE: u32 = u32::MAX;
const HEADER_WORDS: usize = 4;
/// Width, height, levels, sRGB, the transform, then up to `MAX_LEVELS`
/// level offsets.
const VIEW_WORDS: usize = 4 + TRANSFORM_WORDS + MAX_LEVELS;
const TRANSFORM_WORDS: usize = 6;
/// Levels of a 32768-texel side: more than any adapter draws.
const MAX_LEVELS: usize = 16;

/// A texture reference as `GpuSurface` holds it: the view index in bits
/// 0–23, wrap s in 24–25 and wrap t in 26–27 (0 repeat, 1 clamp to edge,
/// 2 mirrored repeat).
pub fn texture_ref(view: u32, sampler: Sampler) -> u32 {
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => 0,
        Wrap::ClampToEdge => 1,
        Wrap::MirroredRepeat => 2,
    };
    (view & 0x00ff_ffff) | wrap(sampler.wrap_s) << 24 | wrap(sampler.wrap_t) << 26
}

/// The images as the shaders read them: view `i` is image `i` with its
/// coordinates untransformed, then one view per other (image, transform)
/// pair the materials read (`KHR_texture_transform`), in the order the
/// materials name them. A transformed view costs a header, not texels.
#[derive(Clone, Debug, Default)]
pub struct TextureViews {
    images: u32,
    transformed: Vec<(u32, glam::Affine2)>,
    /// Per material, the index of its layer-texture table (`layer_table`)
    /// among the materials that have one.
    layer_tables: Vec<Option<u32>>,
}

/// Words of one material's layer-texture table: `LayerTextures::all`, the
/// clear coat's normal texture and its scale.
pub const LAYER_TABLE_WORDS: usize = 8;

impl TextureViews {
    pub fn of(texturing: &Texturing) -> TextureViews {
        let mut views =
            TextureViews { images: texturing.images.len() as u32, transformed: Vec::new(), layer_tables: Vec::new() };
        let mut tables = 0;
        for m in &texturing.materials {
            let table = m.is_some_and(|m| m.layers.any() || m.coat_apart()).then(|| {
                tables += 1;
                tables - 1
            });
            views.layer_tables.push(table);
        }
        for m in texturing.materials.iter().flatten() {
            let transmission = m.transmission.and_then(|t| t.texture);
            let own = [m.base_color, m.metallic_roughness, m.emissive, m.normal, transmission, m.coat_normal];
            for t in own.into_iter().chain(m.layers.all()).flatten() {
                if t.transform != glam::Affine2::IDENTITY && !views.transformed.contains(&(t.image, t.transform)) {
                    views.transformed.push((t.image, t.transform));
                }
            }
        }
        views
    }

    fn count(&self) -> usize {
        self.images as usize + self.transformed.len()
    }

    /// Words of the layer-texture tables after the views' headers.
    fn layer_words(&self) -> usize {
        LAYER_TABLE_WORDS * self.layer_tables.iter().flatten().count()
    }

    /// Where material `material`'s layer-texture table starts in the
    /// packed words (`GpuSurface::layer_textures`); `NO_TEXTURE` where it
    /// has no clear-coat, sheen, specular or coat normal texture.
    pub fn layer_table(&self, material: u32) -> u32 {
        match self.layer_tables.get(material as usize).copied().flatten() {
            Some(k) => (HEADER_WORDS + VIEW_WORDS * self.count() + LAYER_TABLE_WORDS * k as usize) as u32,
            None => NO_TEXTURE,
        }
    }

    /// Each view's image and transform.
    fn iter(&self) -> impl Iterator<Item = (u32, glam::Affine2)> + '_ {
        (0..self.images).map(|i| (i, glam::Affine2::IDENTITY)).chain(self.transformed.iter().copied())
    }

    /// `texture` as `GpuSurface` holds it (`texture_ref` of its view);
    /// `NO_TEXTURE` for None.
    pub fn reference(&self, texture: Option<TextureRef>) -> u32 {
        let Some(t) = texture else { return NO_TEXTURE };
        let view = if t.transform == glam::Affine2::IDENTITY {
            t.image
        } else {
            let at = self.transformed.iter().position(|&v| v == (t.image, t.transform));
            self.images + at.expect("TextureViews::of saw every material's textures") as u32
        };
        texture_ref(view, t.sampler)
    }
}

/// How each image is encoded: sRGB where some material reads it as colour
/// (base colour, emission, the sheen's and the specular's colour), linear
/// where it holds data (metallic–roughness, the layers' factors).
fn color_spaces(texturing: &Texturing) -> Vec<ColorSpace> {
    let mut spaces = vec![ColorSpace::Linear; texturing.images.len()];
    for m in texturing.materials.iter().flatten() {
        for t in [m.base_color, m.emissive, m.layers.sheen_color, m.layers.specular_color].into_iter().flatten() {
            spaces[t.image as usize] = ColorSpace::Srgb;
        }
    }
    spaces
}

/// One texel's 8-bit channels from linear values.
fn encode(texel: glam::Vec4, space: ColorSpace) -> u32 {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    let colour = |v: f32| match space {
        ColorSpace::Srgb => byte(hikari_core::output::linear_to_srgb(v)),
        ColorSpace::Linear => byte(v),
    };
    colour(texel.x) | colour(texel.y) << 8 | colour(texel.z) << 16 | byte(texel.w) << 24
}

/// The mip chain of `image` below level 0: each level the 2×2 box mean of
/// the one above, in linear values (odd sides clamp their last texel).
pub fn mip_chain(image: &Image) -> Vec<Image> {
    let mut levels: Vec<Image> = Vec::new();
    loop {
        let above = levels.last().unwrap_or(image);
        let (w, h) = (above.width(), above.height());
        if (w, h) == (1, 1) || levels.len() + 1 >= MAX_LEVELS {
            return levels;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut texels = Vec::with_capacity((nw * nh) as usize);
        for y in 0..nh {
            for x in 0..nw {
                let at =
                    |dx: u32, dy: u32| above.texel((2 * x + dx).min(w - 1) as usize, (2 * y + dy).min(h - 1) as usize);
                texels.push((at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) * 0.25);
            }
        }
        levels.push(Image::new(nw, nh, texels).expect("a non-empty level"));
    }
}

/// The words of the texture buffer for `scene` with texture coordinates in
/// the primitive order of `bvh`; a header of zeros for a scene without
/// textures (wgpu refuses empty bindings).
pub fn pack_scene(scene: &Scene, bvh: Option<&FlatBvh>) -> Vec<u32> {
    match &scene.texturing {
        Some(texturing) => pack(texturing, bvh),
        None => vec![0; HEADER_WORDS],
    }
}

/// `pack_scene`'s words with the sky image's sampling block after them
/// (header word 2 its offset): the GPU photon tracer's buffer, the only
/// one that samples the image.
pub fn pack_scene_for_tracing(scene: &Scene, bvh: &FlatBvh) -> Vec<u32> {
    let mut words = pack_scene(scene, Some(bvh));
    if let Some(map) = sky_image(scene) {
        words[2] = words.len() as u32;
        words.extend(sky_block(map));
    }
    words
}

/// The scene's sky image, if its environment has one.
fn sky_image(scene: &Scene) -> Option<&hikari_core::envmap::EnvironmentMap> {
    use hikari_core::light::Light;
    scene.lights.iter().find_map(|l| match l {
        Light::Environment { map: Some(map), .. } => Some(&**map),
        _ => None,
    })
}

/// What the GPU tracer samples a sky image with (trace.wgsl's
/// `sample_sky_image`, `EnvironmentMap::sample`'s twin): width, height,
/// ∫L dω (3 f32), the row CDF (height + 1 f32), the rows' CDFs
/// (height × (width + 1) f32), the texels (3 f32 each).
fn sky_block(map: &hikari_core::envmap::EnvironmentMap) -> Vec<u32> {
    let (rows, columns) = map.cdfs();
    let mut words = vec![map.width(), map.height()];
    words.extend(map.integral().to_array().map(f32::to_bits));
    words.extend(rows.iter().chain(columns).map(|c| c.to_bits()));
    words.extend(map.texels().iter().flat_map(|t| t.to_array().map(f32::to_bits)));
    words
}

/// The words of the texture buffer for `texturing` (see `pack_scene`).
pub fn pack(texturing: &Texturing, bvh: Option<&FlatBvh>) -> Vec<u32> {
    if texturing.images.is_empty() {
        return vec![0; HEADER_WORDS];
    }
    let spaces = color_spaces(texturing);
    let images = &texturing.images;
    let views = TextureViews::of(texturing);
    let mut words = vec![0u32; HEADER_WORDS + VIEW_WORDS * views.count() + views.layer_words()];
    words[0] = views.count() as u32;
    for (material, m) in texturing.materials.iter().enumerate() {
        let (Some(m), table) = (m, views.layer_table(material as u32)) else { continue };
        if table != NO_TEXTURE {
            for (k, t) in m.layers.all().into_iter().enumerate() {
                words[table as usize + k] = views.reference(t);
            }
            words[table as usize + 6] = views.reference(m.coat_normal);
            words[table as usize + 7] = m.coat_normal_scale.to_bits();
        }
    }
    // The images' levels, and where each starts.
    let mut level_offsets = Vec::with_capacity(images.len());
    for (i, image) in images.iter().enumerate() {
        let chain = mip_chain(image);
        let mut offsets = Vec::with_capacity(1 + chain.len());
        for texels in std::iter::once(image).chain(chain.iter()) {
            offsets.push(words.len() as u32);
            for y in 0..texels.height() as usize {
                for x in 0..texels.width() as usize {
                    words.push(encode(texels.texel(x, y), spaces[i]));
                }
            }
        }
        level_offsets.push(offsets);
    }
    for (v, (image, transform)) in views.iter().enumerate() {
        let header = HEADER_WORDS + VIEW_WORDS * v;
        let i = image as usize;
        words[header] = images[i].width();
        words[header + 1] = images[i].height();
        words[header + 2] = level_offsets[i].len() as u32;
        let transformed = transform != glam::Affine2::IDENTITY;
        words[header + 3] = (spaces[i] == ColorSpace::Srgb) as u32 | (transformed as u32) << 1;
        let columns = [transform.matrix2.x_axis, transform.matrix2.y_axis, transform.translation];
        for (k, value) in columns.iter().flat_map(|c| c.to_array()).enumerate() {
            words[header + 4 + k] = value.to_bits();
        }
        let levels = header + 4 + TRANSFORM_WORDS;
        words[levels..levels + level_offsets[i].len()].copy_from_slice(&level_offsets[i]);
    }
    if let Some(bvh) = bvh.filter(|_| !texturing.uvs.is_empty()) {
        words[1] = words.len() as u32;
        for &source in &bvh.source {
            match texturing.uvs.triangle(source) {
                Some(uvs) => words.extend(uvs.iter().flat_map(|uv| [uv.x.to_bits(), uv.y.to_bits()])),
                None => words.extend([NO_TEXTURE; 6]),
            }
        }
    }
    if let Some(bvh) = bvh.filter(|_| !texturing.tangents.is_empty()) {
        words[3] = words.len() as u32;
        let pair = |a: i16, b: i16| a as u16 as u32 | (b as u16 as u32) << 16;
        for &source in &bvh.source {
            match texturing.tangents.triangle(source) {
                Some(corners) => {
                    words.extend(corners.iter().flat_map(|t| [pair(t.0[0], t.0[1]), pair(t.0[2], t.0[3])]))
                }
                None => words.extend([0; 6]),
            }
        }
    }
    words
}

/// The scene's sky image for `environment.wgsl`: width, height, then each
/// texel's linear RGB as f32 bits, row by row from the top; [0, 0] without
/// one.
pub fn environment_words(scene: &Scene) -> Vec<u32> {
    let Some(map) = sky_image(scene) else { return vec![0, 0] };
    let mut words = vec![map.width(), map.height()];
    words.extend(map.texels().iter().flat_map(|t| t.to_array().map(f32::to_bits)));
    words
}

/// The environment lookup (`environment_radiance`); the includer defines
/// `environment_word(i)`, the words of `environment_words`.
pub static ENVIRONMENT: crate::wgsl::Module = crate::wgsl::Module {
    name: "environment.wgsl",
    source: include_str!("environment.wgsl"),
    requires: &[&crate::wgsl::CONSTANTS, &crate::features::FEATURES],
};

/// Bytes of the renderer's sky image (`environment_words`).
fn sky_bytes(scene: &Scene) -> u64 {
    sky_image(scene).map_or(0, |m| 4 * (2 + 3 * m.width() as u64 * m.height() as u64))
}

/// Bytes of the renderer's texture buffers for `scene`, without building
/// them (the memory check before upload): the texels and their mip
/// chains, 24 bytes a primitive for texture coordinates and 24 for
/// tangents, and the sky image.
pub fn packed_bytes(scene: &Scene, primitives: usize) -> u64 {
    let Some(texturing) = &scene.texturing else { return 16 + sky_bytes(scene) };
    let texels: u64 = texturing
        .images
        .iter()
        .map(|image| {
            let (mut w, mut h, mut sum) = (image.width() as u64, image.height() as u64, 0);
            loop {
                sum += w * h;
                if w == 1 && h == 1 {
                    return sum;
                }
                (w, h) = ((w / 2).max(1), (h / 2).max(1));
            }
        })
        .sum();
    let uvs = if texturing.uvs.is_empty() { 0 } else { primitives as u64 * 24 };
    let tangents = if texturing.tangents.is_empty() { 0 } else { primitives as u64 * 24 };
    let views = TextureViews::of(texturing);
    4 * (HEADER_WORDS + VIEW_WORDS * views.count() + views.layer_words()) as u64
        + 4 * texels
        + uvs
        + tangents
        + sky_bytes(scene)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;
    use hikari_core::texture::srgb_to_linear;

    /// Every 8-bit sRGB value survives decoding (as the loader does) and
    /// re-encoding: the GPU holds the file's own bytes.
    #[test]
    fn srgb_bytes_round_trip() {
        for k in 0..=255u32 {
            let linear = srgb_to_linear(k as f32 / 255.0);
            let texel = Vec4::new(linear, linear, linear, k as f32 / 255.0);
            assert_eq!(encode(texel, ColorSpace::Srgb), k * 0x0101_0101, "byte {k}");
            assert_eq!(encode(Vec4::splat(k as f32 / 255.0), ColorSpace::Linear), k * 0x0101_0101, "byte {k}");
        }
    }

    /// A 5×3 image halves to 2×1, then 1×1, each texel the mean of the
    /// 2×2 texels above it.
    #[test]
    fn mip_levels_are_box_means() {
        let texels = (0..15).map(|i| Vec4::splat(i as f32)).collect();
        let image = Image::new(5, 3, texels).unwrap();
        let chain = mip_chain(&image);
        assert_eq!(chain.iter().map(|l| (l.width(), l.height())).collect::<Vec<_>>(), [(2, 1), (1, 1)]);
        // Texels (0,0), (1,0), (0,1), (1,1) of the top level: 0, 1, 5, 6.
        assert_eq!(chain[0].texel(0, 0), Vec4::splat(3.0));
        assert_eq!(chain[1].texel(0, 0), (chain[0].texel(0, 0) + chain[0].texel(1, 0)) * 0.5);
    }

    #[test]
    fn texture_references_pack_view_and_wraps() {
        use hikari_core::texture::{MaterialTextures, uv_transform};
        let sampler = Sampler { wrap_s: Wrap::MirroredRepeat, wrap_t: Wrap::ClampToEdge };
        let plain = TextureRef::new(7, sampler);
        let scaled = TextureRef { transform: uv_transform(glam::Vec2::ZERO, 0.0, glam::Vec2::splat(4.0)), ..plain };
        let other = TextureRef { transform: uv_transform(glam::Vec2::X, 0.0, glam::Vec2::ONE), ..plain };
        let texturing = Texturing {
            images: vec![Image::new(1, 1, vec![Vec4::ONE]).unwrap(); 8],
            materials: vec![
                Some(MaterialTextures { base_color: Some(scaled), emissive: Some(plain), ..Default::default() }),
                Some(MaterialTextures { normal: Some(other), metallic_roughness: Some(scaled), ..Default::default() }),
            ],
            ..Default::default()
        };
        let views = TextureViews::of(&texturing);
        // Untransformed: the image's own view; each transform once, after the images.
        assert_eq!(views.reference(Some(plain)), 7 | 2 << 24 | 1 << 26);
        assert_eq!(views.reference(Some(scaled)), 8 | 2 << 24 | 1 << 26);
        assert_eq!(views.reference(Some(other)), 9 | 2 << 24 | 1 << 26);
        assert_eq!(views.reference(None), NO_TEXTURE);
        let words = pack(&texturing, None);
        assert_eq!(words[0], 10, "views");
        let header = HEADER_WORDS + VIEW_WORDS * 8;
        assert_eq!(f32::from_bits(words[header + 4]), 4.0, "x axis scaled");
        assert_eq!(words[header + 4 + TRANSFORM_WORDS], words[HEADER_WORDS + VIEW_WORDS * 7 + 4 + TRANSFORM_WORDS]);
    }
}
