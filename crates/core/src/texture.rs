//! Textures on triangle meshes: images decoded once to linear RGBA, the
//! per-triangle texture coordinates of the primitives that have them, and
//! what each material takes from its textures.
//!
//! Lookups happen once per surface interaction ([`Texturing::apply`],
//! called by `Scene::material_at`, pbrt's `MaterialEvalContext`), and in
//! the BVH's alpha test of `alphaMode` MASK cut-outs
//! ([`Texturing::is_there_at`]).
//!
//! # Memory
//!
//! A texel is four f32 (16 bytes; an 8-bit RGBA file is 4). Texture
//! coordinates cost 24 bytes per triangle of a textured primitive and
//! nothing elsewhere: [`TexCoords`] holds runs of consecutive primitive
//! indices, found by a binary search over the runs.
//!
//! # Filtering
//!
//! Bilinear between texel centres, without mipmaps: the CPU renderers take
//! many samples per pixel, which average a minified texture instead of a
//! mip level.

use crate::material::{Material, Rgb};
use crate::sampling::hash_u32;
use glam::{Affine2, Vec2, Vec4, Vec4Swizzles};
use std::borrow::Cow;

/// How texture coordinates outside [0, 1] wrap (glTF's `wrapS`, `wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    #[default]
    Repeat,
    ClampToEdge,
    MirroredRepeat,
}

impl Wrap {
    /// A texture coordinate brought into a bounded range that wraps the
    /// same (a period of 2 serves repeat and mirrored repeat; clamping
    /// needs only [−1, 2]), so that huge coordinates cannot overflow the
    /// texel arithmetic.
    fn bounded(self, u: f32) -> f32 {
        match self {
            Wrap::ClampToEdge => u.clamp(-1.0, 2.0),
            Wrap::Repeat | Wrap::MirroredRepeat => u.rem_euclid(2.0),
        }
    }

    /// Texel index `i` of a row or column of `n` texels, wrapped.
    fn texel(self, i: i64, n: i64) -> usize {
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        }) as usize
    }
}

/// Wrapping in u (s) and v (t).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
}

/// How an 8- or 16-bit file's values are turned into linear values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// sRGB-encoded colour (base colour, emissive); alpha stays linear.
    Srgb,
    /// Data (metallic–roughness, normals, occlusion).
    Linear,
}

/// The sRGB transfer function's inverse: an encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// An image in linear RGBA, row 0 at the top (glTF's texture coordinate
/// (0, 0) is the top-left corner of the image, (1, 1) the bottom-right).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    texels: Vec<Vec4>,
}

impl Image {
    /// `texels` row by row from the top; None if the count does not match
    /// or the image is empty.
    pub fn new(width: u32, height: u32, texels: Vec<Vec4>) -> Option<Image> {
        (width > 0 && height > 0 && texels.len() == width as usize * height as usize).then_some(Image {
            width,
            height,
            texels,
        })
    }

    /// Decodes `channels` (1: grey, 2: grey + alpha, 3: RGB, 4: RGBA)
    /// values per texel, each `max`-scaled (255 or 65535), from `space`.
    pub fn from_integers(
        width: u32,
        height: u32,
        channels: usize,
        values: impl Iterator<Item = u32>,
        max: u32,
        space: ColorSpace,
    ) -> Option<Image> {
        let scale = 1.0 / max as f32;
        let colour = |v: u32| match space {
            ColorSpace::Srgb => srgb_to_linear(v as f32 * scale),
            ColorSpace::Linear => v as f32 * scale,
        };
        let values: Vec<u32> = values.collect();
        let texels = values
            .chunks_exact(channels)
            .map(|t| match *t {
                [g] => Vec4::new(colour(g), colour(g), colour(g), 1.0),
                [g, a] => Vec4::new(colour(g), colour(g), colour(g), a as f32 * scale),
                [r, g, b] => Vec4::new(colour(r), colour(g), colour(b), 1.0),
                [r, g, b, a, ..] => Vec4::new(colour(r), colour(g), colour(b), a as f32 * scale),
                [] => Vec4::ZERO,
            })
            .collect();
        Image::new(width, height, texels)
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn texel(&self, x: usize, y: usize) -> Vec4 {
        self.texels[y * self.width as usize + x]
    }

    /// The value at texture coordinate `uv`: bilinear between the four
    /// nearest texel centres (texel (i, j) has its centre at
    /// ((i + ½)/width, (j + ½)/height)), wrapped by `sampler`.
    pub fn sample(&self, uv: Vec2, sampler: Sampler) -> Vec4 {
        let (w, h) = (self.width as i64, self.height as i64);
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        let uv = Vec2::new(sampler.wrap_s.bounded(uv.x), sampler.wrap_t.bounded(uv.y));
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let xs = [sampler.wrap_s.texel(x0, w), sampler.wrap_s.texel(x0 + 1, w)];
        let ys = [sampler.wrap_t.texel(y0, h), sampler.wrap_t.texel(y0 + 1, h)];
        let row = |y: usize| self.texel(xs[0], y).lerp(self.texel(xs[1], y), fx);
        row(ys[0]).lerp(row(ys[1]), fy)
    }

    /// The mean over all texels.
    pub fn mean(&self) -> Vec4 {
        let sum: glam::DVec4 = self.texels.iter().map(|t| t.as_dvec4()).sum();
        (sum / self.texels.len() as f64).as_vec4()
    }
}

/// A texture: an image of [`Texturing::images`] read through a sampler,
/// at texture coordinates moved by `transform` first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    pub image: u32,
    pub sampler: Sampler,
    /// `KHR_texture_transform` (identity without it): the coordinates the
    /// image is read at are `transform` of the surface's.
    pub transform: Affine2,
}

impl TextureRef {
    /// Image `image` through `sampler`, coordinates untransformed.
    pub fn new(image: u32, sampler: Sampler) -> TextureRef {
        TextureRef { image, sampler, transform: Affine2::IDENTITY }
    }

    /// The coordinates the image is read at, for surface coordinates `uv`.
    pub fn image_uv(&self, uv: Vec2) -> Vec2 {
        self.transform.transform_point2(uv)
    }
}

/// `KHR_texture_transform`'s matrix, translation × rotation × scale: a
/// coordinate is scaled, rotated by `rotation` radians and then offset.
/// The rotation turns (u, v) to (u cos r + v sin r, −u sin r + v cos r):
/// with v pointing down the image, that turns the image clockwise, as the
/// extension says (its example, offset (0, 1), rotation π/2, scale ½,
/// shows the image's lower-left quadrant; a test checks it).
pub fn uv_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
    let (sin, cos) = rotation.sin_cos();
    Affine2::from_cols(Vec2::new(cos, -sin) * scale.x, Vec2::new(sin, cos) * scale.y, offset)
}

/// How a surface's alpha (`alpha_factor` × the base-colour texture's alpha)
/// decides where it is there: glTF's `alphaMode`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Everywhere, whatever its alpha.
    #[default]
    Opaque,
    /// Where its alpha is at least the cutoff (`alphaCutoff`; cut-outs).
    Mask(f32),
    /// With probability alpha, decided afresh by each ray
    /// ([`blend_threshold`]): stochastic transparency, whose mean over
    /// samples and passes is what Cycles draws for a Principled BSDF's
    /// alpha (a mix with a transparent BSDF), for eye rays, photons and
    /// shadow rays alike.
    Blend,
}

impl AlphaMode {
    /// Whether a surface of alpha `alpha` is there for a ray whose
    /// threshold is `u` (uniform in [0, 1); only BLEND reads it).
    pub fn is_there(self, alpha: f32, u: f32) -> bool {
        match self {
            AlphaMode::Opaque => true,
            AlphaMode::Mask(cutoff) => alpha >= cutoff,
            AlphaMode::Blend => alpha > u,
        }
    }
}

/// The uniform threshold in [0, 1) a BLEND surface's alpha is compared with
/// for the ray from `origin` along `dir` at primitive `prim`: a hash of the
/// ray's bits, so each ray decides afresh (and any traversal of the same ray
/// the same way), with no random stream to thread through the BVH.
/// The WGSL twin is `blend_threshold` in hikari-gpu's surface_point.wgsl.
pub fn blend_threshold(origin: glam::Vec3, dir: glam::Vec3, prim: u32) -> f32 {
    let mut h = hash_u32(prim ^ 0x2545_f491);
    for bits in [origin.x, origin.y, origin.z, dir.x, dir.y, dir.z].map(f32::to_bits) {
        h = hash_u32(h ^ bits);
    }
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The uniform number in [0, 1) that draws one of a mixed material's two
/// materials ([`Transmission`]) at a hit on primitive `prim` at `point`: a
/// hash of their bits, so each hit draws afresh without a random stream to
/// thread through every renderer, and the same hit draws the same.
pub fn mix_threshold(prim: u32, point: glam::Vec3) -> f32 {
    let mut h = hash_u32(prim ^ 0x6a09_e667);
    for bits in [point.x, point.y, point.z].map(f32::to_bits) {
        h = hash_u32(h ^ bits);
    }
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// `KHR_materials_transmission` below 1, or with a `transmissionTexture`
/// (Cycles' Transmission Weight), on a `Material::Pbr` base: the
/// dielectric base lets a share T (factor × the texture's R) of what it
/// does not reflect through, as glass of its IOR and of the base's colour
/// and roughness (textures included). Drawn per hit ([`Texturing::apply`]):
/// the glass with probability p = T·(1 − m), else the base with its
/// metallic m raised to m / (1 − p). The mean over draws,
/// p·glass + (1 − p)·base, is then the extension's
/// mix(fresnel_mix(mix(diffuse, BTDF, T), specular), metal, m) exactly,
/// since the glass reflects as the base's specular lobe does (same IOR and
/// roughness). Coat and sheen lie on the base's share only; the glass's
/// inside absorbs nothing (a ray inside may leave through the base's share).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transmission {
    pub factor: f32,
    /// Linear: R × the factor.
    pub texture: Option<TextureRef>,
    /// The glass's index of refraction (`KHR_materials_ior`).
    pub ior: f32,
}

impl Transmission {
    /// The glass of the (textured) base `bsdf`'s colour and roughness.
    fn glass(&self, bsdf: &crate::bsdf::Bsdf) -> Material {
        Material::Glass(crate::bsdf::dielectric::Dielectric {
            ior: self.ior,
            roughness: bsdf.roughness,
            tint: bsdf.base_color,
            absorption: Rgb::ZERO,
        })
    }
}

/// The material at a point ([`Texturing::apply`]): where the file mixes
/// two ([`Transmission`]) the one this hit drew, the probability it had and
/// the other; else the one material, drawn with probability 1.
/// Borrowed where nothing was looked up (`Scene::material_at` says why).
#[derive(Clone, Debug, PartialEq)]
pub struct Drawn<'a> {
    pub material: Cow<'a, Material>,
    pub probability: f32,
    pub other: Option<Material>,
}

impl<'a> Drawn<'a> {
    pub fn only(material: Cow<'a, Material>) -> Drawn<'a> {
        Drawn { material, probability: 1.0, other: None }
    }

    /// What a photon stored at this hit (which stores only where `stores`
    /// says the drawn material does) is weighted by: 1 / the probability
    /// that a hit here stores, so that the stored power is the incident
    /// power whichever material was drawn.
    pub fn store_weight(&self, stores: impl Fn(&Material) -> bool) -> f32 {
        let other = self.other.as_ref().is_some_and(&stores) as u32 as f32;
        let p_store = self.probability * stores(&self.material) as u32 as f32 + (1.0 - self.probability) * other;
        if p_store > 0.0 { 1.0 / p_store } else { 0.0 }
    }
}

/// What a material takes from textures (glTF's metallic–roughness model);
/// each texture multiplies its factor, which the material already holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// sRGB RGB × base colour, alpha × `alpha_factor`.
    pub base_color: Option<TextureRef>,
    /// Linear: B × metallic, G × roughness.
    pub metallic_roughness: Option<TextureRef>,
    /// sRGB RGB × the emitted radiance.
    pub emissive: Option<TextureRef>,
    /// The mean of the emissive texture's RGB, by which the emitter's
    /// radiance (`EmissiveMesh`: uniform over the mesh) was already scaled.
    pub emissive_mean: Rgb,
    /// `baseColorFactor`'s alpha.
    pub alpha_factor: f32,
    /// Where the surface is there, from its alpha (glTF's `alphaMode`).
    pub alpha_mode: AlphaMode,
    /// Linear tangent-space normals (RGB = 2n − 1 … ), read by the path
    /// tracer (`Texturing::shading_normal`), with the file's `scale` of
    /// their x and y.
    pub normal: Option<TextureRef>,
    pub normal_scale: f32,
    /// `KHR_materials_clearcoat`'s `clearcoatNormalTexture`, as `normal`
    /// but bending the coat alone (`Texturing::coat_normal`), with its scale.
    pub coat_normal: Option<TextureRef>,
    pub coat_normal_scale: f32,
    /// A coat over a normal texture without one of its own: the coat lies
    /// on the unbent normal (the extension: "no normal mapping is applied
    /// to the clear coat layer, even if normal mapping is applied to the
    /// base material"; Cycles' Coat Normal likewise defaults to the
    /// surface's), not on the base's bent one.
    pub coat_unbent: bool,
    /// The clear-coat, sheen and specular extensions' textures.
    pub layers: LayerTextures,
    /// A share let through as glass, drawn per hit.
    pub transmission: Option<Transmission>,
}

impl MaterialTextures {
    /// The coat lies apart from the base's shading normal: on its own
    /// normal texture, or on the unbent normal over a normal texture
    /// (`coat_unbent`).
    pub fn coat_apart(&self) -> bool {
        self.coat_normal.is_some() || self.coat_unbent
    }

    pub fn is_textured(&self) -> bool {
        self.base_color.is_some()
            || self.metallic_roughness.is_some()
            || self.emissive.is_some()
            || self.normal.is_some()
            || self.coat_normal.is_some()
            || self.layers.any()
            || self.transmission.is_some_and(|t| t.texture.is_some())
    }
}

/// The textures of the layers over glTF's base BRDF, each multiplying its
/// factor as its extension says: `KHR_materials_clearcoat` (R × the coat,
/// G × its roughness), `KHR_materials_sheen` (sRGB RGB × the sheen's
/// colour, A × its roughness), `KHR_materials_specular` (A × the specular
/// factor, sRGB RGB × the specular colour).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LayerTextures {
    pub clearcoat: Option<TextureRef>,
    pub clearcoat_roughness: Option<TextureRef>,
    pub sheen_color: Option<TextureRef>,
    pub sheen_roughness: Option<TextureRef>,
    pub specular: Option<TextureRef>,
    pub specular_color: Option<TextureRef>,
}

impl LayerTextures {
    pub fn any(&self) -> bool {
        self.all().iter().any(Option::is_some)
    }

    /// Every texture, in the order of the fields.
    pub fn all(&self) -> [Option<TextureRef>; 6] {
        [
            self.clearcoat,
            self.clearcoat_roughness,
            self.sheen_color,
            self.sheen_roughness,
            self.specular,
            self.specular_color,
        ]
    }

    /// `bsdf` with the layers' texels applied: `texel(t)` is texture `t`'s
    /// linear RGBA at the point (None where the point has no coordinates:
    /// the factors alone).
    fn apply(
        &self,
        mut bsdf: crate::bsdf::Bsdf,
        texel: impl Fn(Option<TextureRef>) -> Option<Vec4>,
    ) -> crate::bsdf::Bsdf {
        if let Some(c) = texel(self.clearcoat) {
            bsdf.clearcoat = (bsdf.clearcoat * c.x).clamp(0.0, 1.0);
        }
        if let Some(c) = texel(self.clearcoat_roughness) {
            bsdf.clearcoat_roughness = (bsdf.clearcoat_roughness * c.y).clamp(0.0, 1.0);
        }
        if let Some(c) = texel(self.sheen_color) {
            bsdf.sheen_color *= c.xyz();
        }
        if let Some(c) = texel(self.sheen_roughness) {
            bsdf.sheen_roughness = (bsdf.sheen_roughness * c.w).clamp(0.0, 1.0);
        }
        if let Some(c) = texel(self.specular) {
            bsdf.specular = (bsdf.specular * c.w).clamp(0.0, 1.0);
        }
        match texel(self.specular_color) {
            Some(c) => bsdf.with_specular_color(bsdf.specular_color * c.xyz()),
            None => bsdf,
        }
    }
}

/// A run of consecutive primitive indices with per-triangle values.
#[derive(Clone, Copy, Debug)]
struct Run {
    first_prim: u32,
    end_prim: u32,
    first_value: u32,
}

/// Per-triangle values (one per vertex 0, 1, 2, say), indexed by the BVH's
/// primitive index, for the triangles that have them: kept in runs of
/// consecutive primitives, so a scene pays only for the meshes that have
/// them.
#[derive(Clone, Debug)]
pub struct PerTriangle<T> {
    runs: Vec<Run>,
    values: Vec<T>,
}

impl<T> Default for PerTriangle<T> {
    fn default() -> Self {
        PerTriangle { runs: Vec::new(), values: Vec::new() }
    }
}

impl<T: Clone> PerTriangle<T> {
    /// Adds the values of primitives `first_prim..first_prim + values.len()`;
    /// runs must be added in increasing primitive order.
    pub fn push_run(&mut self, first_prim: u32, values: &[T]) {
        if values.is_empty() {
            return;
        }
        assert!(self.runs.last().is_none_or(|r| r.end_prim <= first_prim), "runs in increasing order");
        let end_prim = first_prim + values.len() as u32;
        let first_value = self.values.len() as u32;
        match self.runs.last_mut() {
            Some(r) if r.end_prim == first_prim => r.end_prim = end_prim,
            _ => self.runs.push(Run { first_prim, end_prim, first_value }),
        }
        self.values.extend_from_slice(values);
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    pub fn triangle(&self, prim: u32) -> Option<&T> {
        let i = self.runs.partition_point(|r| r.end_prim <= prim);
        let run = self.runs.get(i).filter(|r| r.first_prim <= prim)?;
        self.values.get((run.first_value + prim - run.first_prim) as usize)
    }
}

/// Per-triangle texture coordinates (of vertices 0, 1, 2).
pub type TexCoords = PerTriangle<[Vec2; 3]>;

impl TexCoords {
    /// The coordinates at barycentrics `b` (weights of vertices 1 and 2).
    pub fn at(&self, prim: u32, b: Vec2) -> Option<Vec2> {
        let [a, c1, c2] = *self.triangle(prim)?;
        Some(a * (1.0 - b.x - b.y) + c1 * b.x + c2 * b.y)
    }
}

/// A vertex's tangent, glTF's `TANGENT`: xyz the unit direction in which
/// the normal texture's u grows, w (±1) the side of the bitangent, the
/// image's up, which is w·(normal × tangent). Stored as four signed
/// normalized 16-bit integers, as the GPU's vertex buffer holds them
/// (`Snorm16x4`, `unpack2x16snorm`), so every renderer reads the same
/// numbers: 8 bytes a vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PackedTangent(pub [i16; 4]);

impl PackedTangent {
    pub fn encode(t: Vec4) -> PackedTangent {
        PackedTangent(t.to_array().map(|x| (x.clamp(-1.0, 1.0) * 32767.0).round() as i16))
    }

    /// WebGPU's snorm16 conversion: max(−1, c / 32767).
    pub fn decode(self) -> Vec4 {
        Vec4::from_array(self.0.map(|c| (c as f32 / 32767.0).max(-1.0)))
    }
}

/// Per-triangle tangents of the meshes that have normal textures (the
/// file's `TANGENT`, or MikkTSpace's where it has none).
pub type Tangents = PerTriangle<[PackedTangent; 3]>;

/// Everything a scene's textures need: the images, the texture
/// coordinates, and per material what it takes from them.
#[derive(Clone, Debug, Default)]
pub struct Texturing {
    pub images: Vec<Image>,
    /// Parallel to `Scene::materials`: None for untextured opaque ones.
    pub materials: Vec<Option<MaterialTextures>>,
    pub uvs: TexCoords,
    /// Where tangents were given or made (normal-textured meshes); the
    /// others' tangent frames come from their corners' coordinates.
    pub tangents: Tangents,
    /// Each surface's material (the BVH's alpha test knows surfaces only).
    pub surface_materials: Vec<u32>,
}

impl Texturing {
    fn textures(&self, material: u32) -> Option<&MaterialTextures> {
        self.materials.get(material as usize)?.as_ref()
    }

    fn lookup(&self, texture: Option<TextureRef>, uv: Option<Vec2>) -> Option<Vec4> {
        let (texture, uv) = (texture?, uv?);
        Some(self.images[texture.image as usize].sample(texture.image_uv(uv), texture.sampler))
    }

    /// Does any material have a normal texture (whose bend the diffuse
    /// lobes' bump shadowing follows, `bsdf::bump`)?
    pub fn has_normal_textures(&self) -> bool {
        self.materials.iter().flatten().any(|m| m.normal.is_some())
    }

    /// Does any material's coat lie apart from its base's normal (a
    /// clear-coat normal texture, or a coat over a normal texture)?
    pub fn has_coats_apart(&self) -> bool {
        self.materials.iter().flatten().any(MaterialTextures::coat_apart)
    }

    /// Does any material let a share through as glass ([`Transmission`])?
    pub fn has_mixes(&self) -> bool {
        self.materials.iter().flatten().any(|m| m.transmission.is_some())
    }

    /// Does `material` let a share through as glass ([`Transmission`])?
    pub fn mixes(&self, material: u32) -> bool {
        self.textures(material).is_some_and(|t| t.transmission.is_some())
    }

    /// Is any material a MASK cut-out or BLEND (so the BVH must test alpha)?
    pub fn has_masks(&self) -> bool {
        self.materials.iter().flatten().any(|m| m.alpha_mode != AlphaMode::Opaque)
    }

    /// Is any material BLEND (stochastic transparency)?
    pub fn has_blend(&self) -> bool {
        self.materials.iter().flatten().any(|m| m.alpha_mode == AlphaMode::Blend)
    }

    /// Is `surface` a MASK cut-out or BLEND?
    pub fn is_masked(&self, surface: u32) -> bool {
        let m = self.surface_materials.get(surface as usize);
        m.and_then(|&m| self.textures(m)).is_some_and(|t| t.alpha_mode != AlphaMode::Opaque)
    }

    /// Is the surface there at primitive `prim`, barycentrics `b`, for a
    /// ray of BLEND threshold `u()` ([`blend_threshold`], asked only of
    /// BLEND surfaces): its alpha (factor × base-colour texture) decides as
    /// its [`AlphaMode`] says.
    pub fn is_there_at(&self, surface: u32, prim: u32, b: Vec2, u: impl FnOnce() -> f32) -> bool {
        let Some(t) = self.surface_materials.get(surface as usize).and_then(|&m| self.textures(m)) else {
            return true;
        };
        if t.alpha_mode == AlphaMode::Opaque {
            return true;
        }
        let alpha = t.alpha_factor * self.lookup(t.base_color, self.uvs.at(prim, b)).map_or(1.0, |c| c.w);
        match t.alpha_mode {
            AlphaMode::Blend => t.alpha_mode.is_there(alpha, u()),
            mode => mode.is_there(alpha, 0.0),
        }
    }

    /// `material` (of index `index`) at primitive `prim`, barycentrics `b`,
    /// with its textures applied, and where it mixes in glass
    /// ([`Transmission`]) one of the two drawn by `u()` (uniform in [0, 1),
    /// [`mix_threshold`]; asked only of mixes). Textures without
    /// coordinates (a primitive without `TEXCOORD_0`) leave the factors
    /// alone.
    pub fn apply(&self, material: Material, index: u32, prim: u32, b: Vec2, u: impl FnOnce() -> f32) -> Drawn<'static> {
        let Some(t) = self.textures(index) else { return Drawn::only(Cow::Owned(material)) };
        let uv = self.uvs.at(prim, b);
        let base = self.lookup(t.base_color, uv).map_or(Rgb::ONE, |c| c.xyz());
        let mr = self.lookup(t.metallic_roughness, uv);
        let textured = match material {
            Material::Pbr(mut bsdf) => {
                bsdf.base_color *= base;
                if let Some(mr) = mr {
                    bsdf.metallic = (bsdf.metallic * mr.z).clamp(0.0, 1.0);
                    bsdf.roughness = (bsdf.roughness * mr.y).clamp(0.0, 1.0);
                }
                Material::Pbr(t.layers.apply(bsdf, |texture| self.lookup(texture, uv)))
            }
            // An exactly Lambertian glTF material (metallic 0, no specular
            // lobe: `Material::from_bsdf`); a metallic texture cannot change
            // a zero metallic factor.
            Material::Diffuse { albedo, specular } => Material::Diffuse { albedo: albedo * base, specular },
            // Glass: the base colour tints its transmission, G its roughness.
            Material::Glass(mut glass) => {
                glass.tint *= base;
                if let Some(mr) = mr {
                    glass.roughness = (glass.roughness * mr.y).clamp(0.0, 1.0);
                }
                Material::Glass(glass)
            }
            other => other,
        };
        let (Some(transmission), Material::Pbr(mut bsdf)) = (t.transmission, textured) else {
            return Drawn::only(Cow::Owned(textured));
        };
        let share = transmission.factor * self.lookup(transmission.texture, uv).map_or(1.0, |c| c.x);
        let p_glass = (share * (1.0 - bsdf.metallic)).clamp(0.0, 1.0);
        if p_glass <= 0.0 {
            return Drawn::only(Cow::Owned(textured));
        }
        let glass = transmission.glass(&bsdf);
        // The metal keeps its share m of the whole: m / (1 − p) of the rest.
        if p_glass < 1.0 {
            bsdf.metallic = (bsdf.metallic / (1.0 - p_glass)).min(1.0);
        }
        let rest = Material::Pbr(bsdf);
        if u() < p_glass {
            Drawn { material: Cow::Owned(glass), probability: p_glass, other: Some(rest) }
        } else {
            Drawn { material: Cow::Owned(rest), probability: 1.0 - p_glass, other: Some(glass) }
        }
    }

    /// `material` (of index `index`) with its layer textures' means
    /// (`LayerTextures`; over the whole image) as factors: what the GPU
    /// renderer draws, which reads those textures nowhere per point. A
    /// [`Transmission`] mix stays its base: the GPU draws the glass per
    /// point as [`Texturing::apply`] does.
    pub fn with_layer_means(&self, material: Material, index: u32) -> Material {
        let Some(t) = self.textures(index) else { return material };
        let mean = |texture: Option<TextureRef>| texture.map(|t| self.images[t.image as usize].mean());
        match material {
            Material::Pbr(bsdf) if t.layers.any() => Material::Pbr(t.layers.apply(bsdf, mean)),
            other => other,
        }
    }

    /// The shading normal `ns` (unit, of triangle `corners` with hit
    /// barycentrics `b`) bent by the material's normal texture: the texel
    /// n_t = (2·rgb − 1)·(scale, scale, 1) in the tangent frame whose x
    /// follows the image's u and y the image's up (glTF: +Y up; its v
    /// points down), orthonormalised against `ns`. The frame is the
    /// triangle's stored tangents interpolated (`Texturing::tangents`),
    /// else the triangle's own from its corners' coordinates; either turned
    /// by the texture's transform. `ns` itself where there is no normal
    /// texture, no coordinates or a degenerate frame.
    pub fn shading_normal(
        &self,
        material: u32,
        prim: u32,
        b: Vec2,
        corners: [glam::Vec3; 3],
        ns: glam::Vec3,
    ) -> glam::Vec3 {
        let Some(t) = self.textures(material) else { return ns };
        self.bent_by(t.normal, t.normal_scale, prim, b, corners, ns)
    }

    /// The clear coat's normal at the point, as [`Texturing::shading_normal`]
    /// but bent by the material's `clearcoatNormalTexture` (from the same
    /// unbent `ns`: the specification's coat normal ignores the base's
    /// normal texture), `ns` itself for a coat over a normal texture
    /// without one of its own; with whether the coat has its own texture.
    /// None where the coat lies on the base's normal
    /// (`MaterialTextures::coat_apart`).
    pub fn coat_normal(
        &self,
        material: u32,
        prim: u32,
        b: Vec2,
        corners: [glam::Vec3; 3],
        ns: glam::Vec3,
    ) -> Option<(glam::Vec3, bool)> {
        let t = self.textures(material).filter(|t| t.coat_apart())?;
        Some((self.bent_by(t.coat_normal, t.coat_normal_scale, prim, b, corners, ns), t.coat_normal.is_some()))
    }

    /// `ns` bent by the tangent-space normal texture `normal` of x and y
    /// scale `scale` (`shading_normal`'s arithmetic).
    fn bent_by(
        &self,
        normal: Option<TextureRef>,
        scale: f32,
        prim: u32,
        b: Vec2,
        corners: [glam::Vec3; 3],
        ns: glam::Vec3,
    ) -> glam::Vec3 {
        let (Some(normal), Some(uvs)) = (normal, self.uvs.triangle(prim)) else { return ns };
        let uv = self.uvs.at(prim, b).unwrap_or_default();
        let texel = self.images[normal.image as usize].sample(normal.image_uv(uv), normal.sampler);
        let local = glam::Vec3::new((2.0 * texel.x - 1.0) * scale, (2.0 * texel.y - 1.0) * scale, 2.0 * texel.z - 1.0);
        let axes = match self.tangents.triangle(prim) {
            Some(corner_tangents) => stored_uv_axes(corner_tangents, b, ns),
            None => triangle_uv_axes(corners, uvs),
        };
        let Some(axes) = axes.and_then(|axes| image_axes(normal.transform, axes)) else { return ns };
        bend(local, axes, ns)
    }

    /// Per channel, the emissive texture at the point over its mean (1
    /// without an emissive texture): what scales the emitter's uniform
    /// radiance to the radiance emitted at this point.
    pub fn emission_scale(&self, material: u32, prim: u32, b: Vec2) -> Rgb {
        let Some(t) = self.textures(material) else { return Rgb::ONE };
        let Some(texel) = self.lookup(t.emissive, self.uvs.at(prim, b)) else { return Rgb::ONE };
        let mean = t.emissive_mean;
        Rgb::select(mean.cmpgt(Rgb::ZERO), texel.xyz() / mean.max(Rgb::splat(f32::MIN_POSITIVE)), Rgb::ZERO)
    }
}

/// A surface point's directions of growing u and of the image's up
/// (−v: glTF's v points down the image), in world space, unnormalised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvAxes {
    pub tangent: glam::Vec3,
    pub up: glam::Vec3,
}

/// The axes from a triangle's stored tangents at barycentrics `b`: the
/// tangent interpolated, the up w·(ns × tangent) with the first corner's w
/// (MikkTSpace gives a triangle one side). None for a zero tangent.
pub fn stored_uv_axes(corners: &[PackedTangent; 3], b: Vec2, ns: glam::Vec3) -> Option<UvAxes> {
    let [t0, t1, t2] = corners.map(PackedTangent::decode);
    let tangent = t0.truncate() * (1.0 - b.x - b.y) + t1.truncate() * b.x + t2.truncate() * b.y;
    let side = if t0.w < 0.0 { -1.0 } else { 1.0 };
    (tangent != glam::Vec3::ZERO).then(|| UvAxes { tangent, up: ns.cross(tangent) * side })
}

/// The axes of a triangle of `corners` and coordinates `uvs` as they
/// change over it: dp/du and −dp/dv, solved from its edges. None where its
/// coordinates have no area.
pub fn triangle_uv_axes(corners: [glam::Vec3; 3], uvs: &[Vec2; 3]) -> Option<UvAxes> {
    let (e1, e2) = (corners[1] - corners[0], corners[2] - corners[0]);
    let (d1, d2) = (uvs[1] - uvs[0], uvs[2] - uvs[0]);
    let det = d1.x * d2.y - d2.x * d1.y;
    if det.abs() < 1e-20 {
        return None;
    }
    let tangent = (e1 * d2.y - e2 * d1.y) / det;
    let dp_dv = (e2 * d1.x - e1 * d2.x) / det;
    Some(UvAxes { tangent, up: -dp_dv })
}

/// The axes of the image the texture reads, whose coordinates are
/// `transform` of the surface's (`KHR_texture_transform`: the map's x and
/// up turn and flip with it): dp/du' = dp/du·∂u/∂u' + dp/dv·∂v/∂u'. None
/// for a transform that collapses the image.
pub fn image_axes(transform: glam::Affine2, axes: UvAxes) -> Option<UvAxes> {
    if transform.matrix2 == glam::Mat2::IDENTITY {
        return Some(axes);
    }
    let det = transform.matrix2.determinant();
    if det.abs() < 1e-20 || !det.is_finite() {
        return None;
    }
    let inverse = transform.matrix2.inverse();
    let dp_dv = -axes.up;
    let along = |column: Vec2| axes.tangent * column.x + dp_dv * column.y;
    Some(UvAxes { tangent: along(inverse.x_axis), up: -along(inverse.y_axis) })
}

/// `local` (a normal texture's texel as a direction) in the frame of `ns`
/// and `axes`: the tangent made orthogonal to `ns` (Gram–Schmidt), the
/// bitangent ns × tangent on the side of `axes.up` (mirrored textures).
/// `ns` where the frame or the result is degenerate.
pub fn bend(local: glam::Vec3, axes: UvAxes, ns: glam::Vec3) -> glam::Vec3 {
    let t_axis = (axes.tangent - ns * ns.dot(axes.tangent)).normalize_or_zero();
    let handed = if ns.cross(t_axis).dot(axes.up) < 0.0 { -1.0 } else { 1.0 };
    let b_axis = ns.cross(t_axis) * handed;
    let bent = (t_axis * local.x + b_axis * local.y + ns * local.z).normalize_or_zero();
    if t_axis == glam::Vec3::ZERO || bent == glam::Vec3::ZERO || !bent.is_finite() { ns } else { bent }
}

/// A bent normal `n` turned toward the geometric normal `ng` just enough
/// that the mirror reflection of `wo` about it leaves the surface at least
/// as steeply as min(0.9·(wo·ng), 0.01): Cycles' correction of bump- and
/// normal-mapped normals (`ensure_valid_specular_reflection`), so that a
/// normal texture tilting away from the eye near a silhouette shades as in
/// Blender instead of black (lobes need wo above the shading normal). `ng`
/// on the side of `wo`; all unit. `n` itself where its reflection is high
/// enough. The new normal lies between `n` and `ng`.
pub fn valid_reflection_normal(ng: glam::Vec3, wo: glam::Vec3, n: glam::Vec3) -> glam::Vec3 {
    let reflected = 2.0 * n.dot(wo) * n - wo;
    let iz = wo.dot(ng);
    let threshold = (0.9 * iz).min(0.01);
    if reflected.dot(ng) >= threshold {
        return n;
    }
    // A frame with ng as z and n in the x–z plane: the normal sought,
    // (√(1 − z²), 0, z), reflects wo to height `threshold`:
    // 4a z⁴ − 2b z² + c = 0, of which the root below keeps the reflection
    // above the surface (the other gives −threshold).
    let x = (n - n.dot(ng) * ng).try_normalize().unwrap_or(n);
    let ix = wo.dot(x);
    let a = ix * ix + iz * iz;
    if !(a > 0.0) {
        return ng;
    }
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let z2 = if ix < 0.0 { 0.25 * (b + root) / a } else { 0.25 * (b - root) / a };
    let corrected = x * (1.0 - z2).max(0.0).sqrt() + ng * z2.max(0.0).sqrt();
    if corrected.is_finite() { corrected } else { ng }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// MASK keeps what reaches its cut-off; BLEND keeps alpha of the
    /// thresholds in [0, 1): none at 0, all at 1.
    #[test]
    fn alpha_modes_decide_as_gltf_says() {
        assert!(AlphaMode::Opaque.is_there(0.0, 0.5));
        assert!(AlphaMode::Mask(0.5).is_there(0.5, 0.99) && !AlphaMode::Mask(0.5).is_there(0.49, 0.0));
        assert!(!AlphaMode::Blend.is_there(0.0, 0.0) && AlphaMode::Blend.is_there(1.0, 0.999_999_94));
        assert!(AlphaMode::Blend.is_there(0.3, 0.29) && !AlphaMode::Blend.is_there(0.3, 0.3));
    }

    /// The thresholds of nearby rays (a pixel's jittered rays, one origin
    /// and many directions) and of one ray over neighbouring primitives
    /// are uniform: 16 bins each within 4% of an even share (a chi-square
    /// of 16 bins, 15 degrees of freedom, below its 0.1% point 37.7), and
    /// the two BLEND layers a ray meets decide independently.
    #[test]
    fn blend_thresholds_are_uniform_and_independent() {
        use glam::Vec3;
        let n = 64_000usize;
        let check = |name: &str, u: &dyn Fn(usize) -> f32| {
            let mut bins = [0usize; 16];
            for i in 0..n {
                let v = u(i);
                assert!((0.0..1.0).contains(&v), "{name}: {v}");
                bins[(v * 16.0) as usize] += 1;
            }
            let even = n as f64 / 16.0;
            let chi2: f64 = bins.iter().map(|&b| (b as f64 - even).powi(2) / even).sum();
            eprintln!("{name}: bins {bins:?}, chi-square {chi2:.1}");
            assert!(chi2 < 37.7, "{name}: chi-square {chi2}");
        };
        let origin = Vec3::new(0.25, 2.0, -0.5);
        let dir = |i: usize| {
            let (a, b) = ((i % 256) as f32 / 256.0 * 1e-3, (i / 256) as f32 / 256.0 * 1e-3);
            Vec3::new(a, -1.0, b).normalize()
        };
        check("one origin, nearby directions", &|i| blend_threshold(origin, dir(i), 7));
        check("one ray, neighbouring primitives", &|i| blend_threshold(origin, -Vec3::Y, i as u32));
        // Two layers (primitives 3 and 4): both there for 0.5 × 0.5 of the rays.
        let both =
            (0..n).filter(|&i| blend_threshold(origin, dir(i), 3) < 0.5 && blend_threshold(origin, dir(i), 4) < 0.5);
        let fraction = both.count() as f64 / n as f64;
        assert!((fraction - 0.25).abs() < 0.01, "{fraction}");
    }

    /// A triangle in the xy plane whose u grows along +x and v along −y
    /// (glTF's v points down the image): the image's up is +y.
    #[test]
    fn a_triangles_axes_are_u_and_the_images_up() {
        let corners = [glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y];
        let uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 0.0)];
        let axes = triangle_uv_axes(corners, &uvs).unwrap();
        assert_eq!(axes, UvAxes { tangent: glam::Vec3::X, up: glam::Vec3::Y });
        assert_eq!(triangle_uv_axes(corners, &[Vec2::ZERO; 3]), None);
    }

    /// A transform turning the image a quarter (the extension's rotation
    /// π/2) turns its axes; one scaling u by −2 flips and shortens its u;
    /// one that collapses the image has none.
    #[test]
    fn a_texture_transform_turns_the_images_axes() {
        let axes = UvAxes { tangent: glam::Vec3::X, up: glam::Vec3::Y };
        assert_eq!(image_axes(Affine2::IDENTITY, axes), Some(axes));
        let quarter =
            image_axes(uv_transform(Vec2::new(0.3, 0.1), std::f32::consts::FRAC_PI_2, Vec2::ONE), axes).unwrap();
        // (u, v) → (v, −u): u' grows with the surface's v, along −y; v'
        // grows with −u, along −x, so the image's up (−v') is +x.
        assert!((quarter.tangent + glam::Vec3::Y).length() < 1e-6, "{quarter:?}");
        assert!((quarter.up - glam::Vec3::X).length() < 1e-6, "{quarter:?}");
        let flipped = image_axes(uv_transform(Vec2::ZERO, 0.0, Vec2::new(-2.0, 1.0)), axes).unwrap();
        assert!((flipped.tangent + 0.5 * glam::Vec3::X).length() < 1e-6 && flipped.up == glam::Vec3::Y, "{flipped:?}");
        assert_eq!(image_axes(uv_transform(Vec2::ZERO, 0.0, Vec2::new(0.0, 1.0)), axes), None);
    }

    /// Stored tangents interpolate; the up is w·(n × t) with the first
    /// corner's w; a zero tangent is no frame.
    #[test]
    fn stored_tangents_give_the_frame() {
        let n = glam::Vec3::Z;
        let t = |x: f32, y: f32, w: f32| PackedTangent::encode(Vec4::new(x, y, 0.0, w));
        let corners = [t(1.0, 0.0, -1.0), t(0.0, 1.0, -1.0), t(1.0, 0.0, -1.0)];
        let axes = stored_uv_axes(&corners, Vec2::new(0.5, 0.0), n).unwrap();
        assert!((axes.tangent - glam::Vec3::new(0.5, 0.5, 0.0)).length() < 1e-4, "{axes:?}");
        assert!((axes.up - glam::Vec3::new(0.5, -0.5, 0.0)).length() < 1e-4, "{axes:?}");
        assert_eq!(stored_uv_axes(&[PackedTangent::default(); 3], Vec2::ZERO, n), None);
        // Encoding keeps ±1 and rounds to 1/32767.
        assert_eq!(
            PackedTangent::encode(Vec4::new(1.0, -1.0, 0.5, 2.0)).decode(),
            Vec4::new(1.0, -1.0, 16384.0 / 32767.0, 1.0)
        );
    }

    /// The frame bends the normal: +x of the texel toward the tangent, +y
    /// toward the up, whichever side of n × t it lies.
    #[test]
    fn bend_follows_the_tangent_and_the_up() {
        let n = glam::Vec3::Z;
        let local = glam::Vec3::new(0.6, 0.0, 0.8);
        let axes = UvAxes { tangent: glam::Vec3::new(2.0, 0.0, 1.0), up: glam::Vec3::Y };
        assert!((bend(local, axes, n) - glam::Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6);
        let up = glam::Vec3::new(0.0, 0.6, 0.8);
        assert!((bend(up, axes, n) - up).length() < 1e-6);
        let mirrored = UvAxes { up: -glam::Vec3::Y, ..axes };
        assert!((bend(up, mirrored, n) - glam::Vec3::new(0.0, -0.6, 0.8)).length() < 1e-6);
        assert_eq!(bend(local, UvAxes { tangent: n, up: glam::Vec3::Y }, n), n, "a tangent along n is no frame");
    }

    /// Normals whose mirror reflection of wo dips below the surface are
    /// lifted to reflect it at the threshold, staying between themselves
    /// and the geometric normal; the others are kept.
    #[test]
    fn valid_reflection_lifts_only_normals_that_reflect_below() {
        let mut rng = crate::sampling::Rng::for_item(5, 0);
        let mut unit = || {
            let u = glam::Vec2::new(rng.next_f32(), rng.next_f32());
            let z = 1.0 - 2.0 * u.x;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * std::f32::consts::PI * u.y;
            glam::Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let (mut lifted, mut kept) = (0, 0);
        for _ in 0..20_000 {
            let ng = unit();
            let wo = unit();
            let wo = if wo.dot(ng) < 0.0 { -wo } else { wo };
            let mut n = unit();
            if n.dot(ng) < 0.0 {
                n = -n;
            }
            let iz = wo.dot(ng);
            if iz < 1e-3 {
                continue;
            }
            let threshold = (0.9 * iz).min(0.01);
            let out = valid_reflection_normal(ng, wo, n);
            assert!((out.length() - 1.0).abs() < 1e-4, "{out}");
            let height = (2.0 * out.dot(wo) * out - wo).dot(ng);
            if out == n {
                kept += 1;
                assert!(height >= threshold);
            } else {
                lifted += 1;
                assert!(
                    (height - threshold).abs() < 2e-3,
                    "reflection at {height}, want {threshold} (ng {ng}, wo {wo}, n {n})"
                );
                assert!(out.dot(wo) > 0.0, "faces the eye");
                // Between n and ng: in their plane, nearer ng than n is.
                assert!(out.dot(n.cross(ng)).abs() < 1e-3 && out.dot(ng) >= n.dot(ng) - 1e-4, "{out} vs {n}");
            }
        }
        assert!(lifted > 1000 && kept > 1000, "{lifted} lifted, {kept} kept");
    }

    /// A 2×2 image: texel (x, y) = (x, y, 0, 1).
    fn ramp() -> Image {
        let t = (0..4).map(|i| Vec4::new((i % 2) as f32, (i / 2) as f32, 0.0, 1.0)).collect();
        Image::new(2, 2, t).unwrap()
    }

    #[test]
    fn bilinear_between_texel_centres() {
        let img = ramp();
        let s = Sampler::default();
        // Texel centres show the texels.
        assert_eq!(img.sample(Vec2::new(0.25, 0.25), s), Vec4::new(0.0, 0.0, 0.0, 1.0));
        assert_eq!(img.sample(Vec2::new(0.75, 0.25), s), Vec4::new(1.0, 0.0, 0.0, 1.0));
        assert_eq!(img.sample(Vec2::new(0.25, 0.75), s), Vec4::new(0.0, 1.0, 0.0, 1.0));
        // Halfway between centres: the mean.
        let mid = img.sample(Vec2::new(0.5, 0.375), s);
        assert!((mid - Vec4::new(0.5, 0.25, 0.0, 1.0)).abs().max_element() < 1e-6, "{mid}");
    }

    /// The extension's own example: offset (0, 1), rotation π/2, scale ½
    /// "utilizes only the lower left quadrant of the source image, rotated
    /// clockwise 90°": the surface's corners land on that quadrant's
    /// (u ∈ [0, ½], v ∈ [½, 1], v down the image), its top-left corner
    /// (0, 0) on the quadrant's bottom-left (0, 1).
    #[test]
    fn the_texture_transform_of_the_extensions_example() {
        let t = TextureRef {
            transform: uv_transform(Vec2::new(0.0, 1.0), std::f32::consts::FRAC_PI_2, Vec2::splat(0.5)),
            ..TextureRef::new(0, Sampler::default())
        };
        for (uv, want) in [
            (Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0)),
            (Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.5)),
            (Vec2::new(0.0, 1.0), Vec2::new(0.5, 1.0)),
            (Vec2::new(1.0, 1.0), Vec2::new(0.5, 0.5)),
        ] {
            let got = t.image_uv(uv);
            assert!((got - want).length() < 1e-6, "{uv} -> {got}, want {want}");
        }
        // Scale before rotation, offset last: (2u, v) turned, then moved.
        let t = uv_transform(Vec2::new(0.5, 1.0), std::f32::consts::FRAC_PI_2, Vec2::new(2.0, 1.0));
        let got = t.transform_point2(Vec2::new(0.25, 0.5));
        assert!((got - Vec2::new(1.0, 0.5)).length() < 1e-6, "{got}");
    }

    #[test]
    fn wrap_modes() {
        let img = ramp();
        let at = |u: f32, wrap: Wrap| img.sample(Vec2::new(u, 0.25), Sampler { wrap_s: wrap, wrap_t: wrap }).x;
        // u = 0: halfway between texel 0 and the one to its left.
        assert_eq!(at(0.0, Wrap::Repeat), 0.5); // texel 1 wraps around
        assert_eq!(at(0.0, Wrap::ClampToEdge), 0.0);
        assert_eq!(at(0.0, Wrap::MirroredRepeat), 0.0); // texel −1 mirrors to texel 0
        // u = 1.25: texel centre 0 of the next repeat, texel 1 clamped, texel 1 mirrored.
        assert_eq!(at(1.25, Wrap::Repeat), 0.0);
        assert_eq!(at(1.25, Wrap::ClampToEdge), 1.0);
        assert_eq!(at(1.25, Wrap::MirroredRepeat), 1.0);
        assert_eq!(at(-0.75, Wrap::MirroredRepeat), 1.0);
        assert_eq!(Wrap::MirroredRepeat.texel(-1, 3), 0);
        assert_eq!(Wrap::MirroredRepeat.texel(3, 3), 2);
        assert_eq!(Wrap::MirroredRepeat.texel(6, 3), 0);
    }

    #[test]
    fn srgb_decoding() {
        let img = Image::from_integers(1, 1, 4, [255, 188, 0, 128].into_iter(), 255, ColorSpace::Srgb).unwrap();
        let t = img.texel(0, 0);
        assert_eq!(t.x, 1.0);
        assert!((t.y - 0.5029).abs() < 1e-3, "{t}"); // sRGB 188 is linear 0.503
        assert_eq!(t.z, 0.0);
        assert!((t.w - 128.0 / 255.0).abs() < 1e-6, "alpha stays linear");
        let lin = Image::from_integers(1, 1, 1, [51].into_iter(), 255, ColorSpace::Linear).unwrap();
        assert!((lin.texel(0, 0) - Vec4::new(0.2, 0.2, 0.2, 1.0)).abs().max_element() < 1e-6, "data stays linear");
    }

    #[test]
    fn tex_coords_are_found_by_run() {
        let mut uvs = TexCoords::default();
        let tri = |x: f32| [Vec2::splat(x); 3];
        uvs.push_run(3, &[tri(3.0), tri(4.0)]);
        uvs.push_run(5, &[tri(5.0)]); // merges with the run before
        uvs.push_run(10, &[tri(10.0)]);
        assert_eq!(uvs.runs.len(), 2);
        for p in 0..12 {
            let expected = [3, 4, 5, 10].contains(&p).then(|| tri(p as f32));
            assert_eq!(uvs.triangle(p).copied(), expected, "prim {p}");
        }
        let mut one = TexCoords::default();
        one.push_run(0, &[[Vec2::ZERO, Vec2::X, Vec2::Y]]);
        assert_eq!(one.at(0, Vec2::new(0.25, 0.5)), Some(Vec2::new(0.25, 0.5)));
    }
}
