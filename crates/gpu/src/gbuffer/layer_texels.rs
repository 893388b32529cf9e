//! The G-buffer's fifth target: at each pixel of a surface with clear-coat,
//! sheen or specular textures (`hikari_core::texture::LayerTextures`), those
//! textures' texels at the pixel's footprint, each channel as
//! `LayerTextures::apply` reads it (1 where the surface lacks that texture
//! or the point has no coordinates). The raster passes multiply the
//! surface's factors by them (layer_texels.wgsl's `pixel_surface`), as the
//! CPU renderers multiply them at each hit. Packed in four words: the
//! coat's, its roughness', the sheen's roughness and the specular factor's
//! texels at 16 bits each, the sheen's and the specular's colour at 10 bits
//! a channel. layer_texels.wgsl is the GPU's half; this Rust one reads a
//! G-buffer back (the tests).

use glam::Vec3;

/// The WGSL half (`LayerTexels`, `pack_layer_texels`, `unpack_layer_texels`,
/// `with_layer_texels`, `pixel_surface`).
pub static LAYER_TEXELS: crate::wgsl::Module = crate::wgsl::Module {
    name: "layer_texels.wgsl",
    source: include_str!("layer_texels.wgsl"),
    requires: &[&crate::wgsl::SURFACE],
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
}

/// WGSL's `pack2x16unorm` of (a, b).
fn unorm16x2(a: f32, b: f32) -> u32 {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u32;
    q(a) | q(b) << 16
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
    };

    /// The texels in the order of the fields, colours' channels in turn.
    pub fn to_array(&self) -> [f32; 10] {
        let [sr, sg, sb] = self.sheen_color.to_array();
        let [cr, cg, cb] = self.specular_color.to_array();
        [self.clearcoat, self.clearcoat_roughness, self.sheen_roughness, self.specular, sr, sg, sb, cr, cg, cb]
    }

    /// `to_array`'s inverse.
    pub fn from_array(v: [f32; 10]) -> LayerTexels {
        LayerTexels {
            clearcoat: v[0],
            clearcoat_roughness: v[1],
            sheen_roughness: v[2],
            specular: v[3],
            sheen_color: Vec3::new(v[4], v[5], v[6]),
            specular_color: Vec3::new(v[7], v[8], v[9]),
        }
    }

    /// `bsdf` with its layer factors times these texels, clamped as
    /// `LayerTextures::apply` clamps them: layer_texels.wgsl's
    /// `with_layer_texels` (the twin tests shade a pixel with it).
    pub fn apply(&self, bsdf: hikari_core::bsdf::Bsdf) -> hikari_core::bsdf::Bsdf {
        let mut b = bsdf;
        b.clearcoat = (b.clearcoat * self.clearcoat).clamp(0.0, 1.0);
        b.clearcoat_roughness = (b.clearcoat_roughness * self.clearcoat_roughness).clamp(0.0, 1.0);
        b.sheen_color *= self.sheen_color;
        b.sheen_roughness = (b.sheen_roughness * self.sheen_roughness).clamp(0.0, 1.0);
        b.specular = (b.specular * self.specular).clamp(0.0, 1.0);
        b.with_specular_color(b.specular_color * self.specular_color)
    }

    /// The target's four words.
    pub fn pack(&self) -> [u32; 4] {
        [
            unorm16x2(self.clearcoat, self.clearcoat_roughness),
            unorm16x2(self.sheen_roughness, self.specular),
            unorm10x3(self.sheen_color),
            unorm10x3(self.specular_color),
        ]
    }

    /// The texels from the target's four words.
    pub fn unpack(words: [u32; 4]) -> LayerTexels {
        let low = |w: u32| (w & 0xffff) as f32 / 65535.0;
        let high = |w: u32| (w >> 16) as f32 / 65535.0;
        let colour = |w: u32| Vec3::new((w & 1023) as f32, (w >> 10 & 1023) as f32, (w >> 20 & 1023) as f32) / 1023.0;
        LayerTexels {
            clearcoat: low(words[0]),
            clearcoat_roughness: high(words[0]),
            sheen_roughness: low(words[1]),
            specular: high(words[1]),
            sheen_color: colour(words[2]),
            specular_color: colour(words[3]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::sampling::Rng;

    /// Packed and unpacked, each texel within half a step of its own.
    #[test]
    fn texels_survive_packing_within_half_a_step() {
        let mut rng = Rng::for_item(5, 0);
        for _ in 0..1000 {
            let texels = LayerTexels::from_array(std::array::from_fn(|_| rng.next_f32()));
            let back = LayerTexels::unpack(texels.pack());
            for (k, (got, want)) in back.to_array().into_iter().zip(texels.to_array()).enumerate() {
                let step = if k < 4 { 65535.0 } else { 1023.0 };
                assert!((got - want).abs() <= 0.5 / step + 1e-7, "texel {k}: {got} vs {want}");
            }
        }
        assert_eq!(LayerTexels::unpack(LayerTexels::NONE.pack()), LayerTexels::NONE);
    }
}
