//! The G-buffer's fifth target: at each pixel of a surface with clear-coat,
//! sheen or specular textures (`hikari_core::texture::LayerTextures`), those
//! textures' texels at the pixel's footprint, each channel as
//! `LayerTextures::apply` reads it (1 where the surface lacks that texture
//! or the point has no coordinates), and where it has a
//! `clearcoatNormalTexture` the coat's own normal in the shading frame
//! (`Scene::coat_tilted`). The raster passes multiply the surface's factors
//! by the texels (layer_texels.wgsl's `pixel_surface`) and turn its coat
//! (`pixel_coat`), as the CPU renderers do at each hit. Packed in four
//! words: the coat's, its roughness', the sheen's roughness and the
//! specular factor's texels at 8 bits each (the images' own precision:
//! glTF's PNG and JPEG images hold 8 bits a channel); the coat normal's x
//! and y at 16 bits (snorm; z ≥ 0 from them); the sheen's and the
//! specular's colour at 10 bits a channel, the sheen's word's bit 30 set
//! where the coat lies on the unbent normal over a normal texture
//! (`Bsdf::with_unbent_coat`) rather than on its own texture's. layer_texels.wgsl is the GPU's
//! half; this Rust one reads a G-buffer back (the tests).

use glam::Vec3;

/// The WGSL half (`LayerTexels`, `pack_layer_texels`, `unpack_layer_texels`,
/// `with_layer_texels`, `pixel_surface`, `pixel_coat`).
pub static LAYER_TEXELS: crate::wgsl::Module = crate::wgsl::Module {
    name: "layer_texels.wgsl",
    source: include_str!("layer_texels.wgsl"),
    requires: &[&crate::wgsl::SURFACE, &crate::wgsl::BSDF],
};

/// The target's format.
pub const LAYERS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// The layer textures' texels at a point (layer_texels.wgsl's `LayerTexels`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerTexels {
    /// `clearcoatTexture`'s R.
    pub clearcoat: f32,
    /// `clearcoatRoughnessTexture`'s G.
    pub clearcoat_roughness: f32,
    /// `sheenRoughnessTexture`'s A.
    pub sheen_roughness: f32,
    /// `specularTexture`'s A.
    pub specular: f32,
    /// `sheenColorTexture`'s RGB (linear).
    pub sheen_color: Vec3,
    /// `specularColorTexture`'s RGB (linear).
    pub specular_color: Vec3,
    /// The coat's own normal in the shading frame (+z: the base's).
    pub coat_normal: Vec3,
    /// The coat lies on the unbent normal over a normal texture (no
    /// texture of its own tilts it).
    pub coat_unbent: bool,
}

/// The sheen colour word's bit marking `LayerTexels::coat_unbent`.
const COAT_UNBENT_BIT: u32 = 1 << 30;

/// WGSL's `pack4x8unorm`: floor(0.5 + 255·clamp(v, 0, 1)), x in the low byte.
fn unorm8x4(v: [f32; 4]) -> u32 {
    v.iter().enumerate().map(|(k, &v)| ((0.5 + 255.0 * v.clamp(0.0, 1.0)).floor() as u32) << (8 * k)).sum()
}

/// WGSL's `pack2x16snorm` of (a, b): floor(0.5 + 32767·clamp(v, −1, 1)).
fn snorm16x2(a: f32, b: f32) -> u32 {
    let q = |v: f32| ((0.5 + 32767.0 * v.clamp(-1.0, 1.0)).floor() as i32 as i16) as u16 as u32;
    q(a) | q(b) << 16
}

/// layer_texels.wgsl's `unpack_coat_normal`: `unpack2x16snorm`'s x and y,
/// z = √(1 − x² − y²).
fn coat_normal_of(w: u32) -> Vec3 {
    let s = |h: u32| (h as u16 as i16 as f32 / 32767.0).max(-1.0);
    let (x, y) = (s(w & 0xffff), s(w >> 16));
    Vec3::new(x, y, (1.0 - (x * x + y * y)).max(0.0).sqrt())
}

fn unorm10x3(c: Vec3) -> u32 {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 1023.0).round() as u32;
    q(c.x) | q(c.y) << 10 | q(c.z) << 20
}

impl LayerTexels {
    /// Where a surface has none of the textures: every texel 1.
    pub const NONE: LayerTexels = LayerTexels {
        clearcoat: 1.0,
        clearcoat_roughness: 1.0,
        sheen_roughness: 1.0,
        specular: 1.0,
        sheen_color: Vec3::ONE,
        specular_color: Vec3::ONE,
        coat_normal: Vec3::Z,
        coat_unbent: false,
    };

    /// The texels in the order of the fields, colours' channels in turn,
    /// then the coat normal's x and y and `coat_unbent` (1 or 0).
    pub fn to_array(&self) -> [f32; 13] {
        let [sr, sg, sb] = self.sheen_color.to_array();
        let [cr, cg, cb] = self.specular_color.to_array();
        let (n, unbent) = (self.coat_normal, self.coat_unbent as u32 as f32);
        let factors = [self.clearcoat, self.clearcoat_roughness, self.sheen_roughness, self.specular];
        let rest = [sr, sg, sb, cr, cg, cb, n.x, n.y, unbent];
        std::array::from_fn(|k| if k < 4 { factors[k] } else { rest[k - 4] })
    }

    /// `to_array`'s inverse (the coat normal's z ≥ 0 from its x and y;
    /// `coat_unbent` from 0.5 up).
    pub fn from_array(v: [f32; 13]) -> LayerTexels {
        LayerTexels {
            clearcoat: v[0],
            clearcoat_roughness: v[1],
            sheen_roughness: v[2],
            specular: v[3],
            sheen_color: Vec3::new(v[4], v[5], v[6]),
            specular_color: Vec3::new(v[7], v[8], v[9]),
            coat_normal: Vec3::new(v[10], v[11], (1.0 - (v[10] * v[10] + v[11] * v[11])).max(0.0).sqrt()),
            coat_unbent: v[12] >= 0.5,
        }
    }

    /// `bsdf` with its layer factors times these texels, clamped as
    /// `LayerTextures::apply` clamps them, and its coat on `coat_normal`:
    /// layer_texels.wgsl's `with_layer_texels` and `pixel_coat` (the twin
    /// tests shade a pixel with it).
    pub fn apply(&self, bsdf: hikari_core::bsdf::Bsdf) -> hikari_core::bsdf::Bsdf {
        let mut b = bsdf;
        b.clearcoat = (b.clearcoat * self.clearcoat).clamp(0.0, 1.0);
        b.clearcoat_roughness = (b.clearcoat_roughness * self.clearcoat_roughness).clamp(0.0, 1.0);
        b.sheen_color *= self.sheen_color;
        b.sheen_roughness = (b.sheen_roughness * self.sheen_roughness).clamp(0.0, 1.0);
        b.specular = (b.specular * self.specular).clamp(0.0, 1.0);
        let b = b.with_specular_color(b.specular_color * self.specular_color);
        match (self.coat_normal == Vec3::Z, self.coat_unbent) {
            (true, _) => b,
            (false, false) => b.with_coat_normal(self.coat_normal),
            (false, true) => b.with_unbent_coat(self.coat_normal),
        }
    }

    /// The target's four words.
    pub fn pack(&self) -> [u32; 4] {
        [
            unorm8x4([self.clearcoat, self.clearcoat_roughness, self.sheen_roughness, self.specular]),
            snorm16x2(self.coat_normal.x, self.coat_normal.y),
            unorm10x3(self.sheen_color) | if self.coat_unbent { COAT_UNBENT_BIT } else { 0 },
            unorm10x3(self.specular_color),
        ]
    }

    /// The texels from the target's four words.
    pub fn unpack(words: [u32; 4]) -> LayerTexels {
        let byte = |k: u32| (words[0] >> (8 * k) & 255) as f32 / 255.0;
        let colour = |w: u32| Vec3::new((w & 1023) as f32, (w >> 10 & 1023) as f32, (w >> 20 & 1023) as f32) / 1023.0;
        LayerTexels {
            clearcoat: byte(0),
            clearcoat_roughness: byte(1),
            sheen_roughness: byte(2),
            specular: byte(3),
            sheen_color: colour(words[2]),
            specular_color: colour(words[3]),
            coat_normal: if words[1] == 0 { Vec3::Z } else { coat_normal_of(words[1]) },
            coat_unbent: words[2] & COAT_UNBENT_BIT != 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::sampling::Rng;

    /// Packed and unpacked, each texel within half a step of its own, the
    /// coat normal's x and y too (from −1 to 1: a normal below the base's
    /// horizon is `with_coat_normal`'s to refuse); none packs as none.
    #[test]
    fn texels_survive_packing_within_half_a_step() {
        let mut rng = Rng::for_item(5, 0);
        for _ in 0..1000 {
            let v: [f32; 13] = std::array::from_fn(|k| match k {
                0..10 => rng.next_f32(),
                10..12 => rng.next_f32() - 0.5,
                _ => (rng.next_f32() < 0.5) as u32 as f32,
            });
            let texels = LayerTexels::from_array(v);
            let back = LayerTexels::unpack(texels.pack());
            for (k, (got, want)) in back.to_array().into_iter().zip(texels.to_array()).enumerate() {
                let step = match k {
                    0..4 => 255.0,
                    10..12 => 32767.0,
                    12 => f32::INFINITY,
                    _ => 1023.0,
                };
                assert!((got - want).abs() <= 0.5 / step + 1e-7, "texel {k}: {got} vs {want}");
            }
            assert!((back.coat_normal.length() - 1.0).abs() < 1e-4, "{}", back.coat_normal);
        }
        assert_eq!(LayerTexels::unpack(LayerTexels::NONE.pack()), LayerTexels::NONE);
        assert_eq!(LayerTexels::NONE.pack()[1], 0, "an untilted coat packs as 0 (pixel_coat's test)");
    }
}
