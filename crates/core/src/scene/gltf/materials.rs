//! glTF materials as hikari materials.
//!
//! Until the metallic–roughness BRDF of the glTF specification (Appendix B)
//! is hikari's material model, each glTF material is approximated by the
//! closest of hikari's: a transmissive one is glass, a smooth metal a
//! mirror tinted by its base colour, everything else Lambertian with its
//! base colour (rough metal included), and textures are not sampled (their
//! factors are). Each approximation made is reported in one note.

use crate::material::{Material, Rgb};
use glam::Vec3;

/// Light a surface emits: `emissiveFactor` × `KHR_materials_emissive_strength`,
/// a radiance in W/(m² sr) (Blender writes its emission strength there
/// unchanged, so no 683 applies).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    pub radiance: Rgb,
    /// Emits from both faces (`doubleSided`), else from the front only.
    pub two_sided: bool,
}

/// Roughness below which a metal is followed as a mirror.
pub const MIRROR_ROUGHNESS: f32 = 0.2;

/// The document's materials, then the specification's default material
/// (white, metallic 1, roughness 1) for primitives without one, each with
/// its emission.
pub fn convert(doc: &gltf::Document, notes: &mut Vec<String>) -> (Vec<Material>, Vec<Option<Emission>>) {
    let mut textured = 0;
    let mut approximated = 0;
    let mut masked = 0;
    let mut out: (Vec<Material>, Vec<Option<Emission>>) = doc
        .materials()
        .map(|m| {
            let pbr = m.pbr_metallic_roughness();
            textured += [
                pbr.base_color_texture().is_some(),
                pbr.metallic_roughness_texture().is_some(),
                m.emissive_texture().is_some(),
                m.normal_texture().is_some(),
            ]
            .iter()
            .any(|&t| t) as usize;
            masked += (m.alpha_mode() != gltf::material::AlphaMode::Opaque) as usize;
            let [r, g, b, _] = pbr.base_color_factor();
            let base = sane(Vec3::new(r, g, b), 1.0);
            let metallic = sane(Vec3::splat(pbr.metallic_factor()), 1.0).x;
            let roughness = sane(Vec3::splat(pbr.roughness_factor()), 1.0).x;
            let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
            let material = if transmission >= 0.5 {
                approximated += (roughness > 0.0 || transmission < 1.0) as usize;
                Material::Glass { ior: m.ior().unwrap_or(1.5).clamp(1.0, 3.0) }
            } else {
                approximated += (metallic > 0.0 && metallic < 1.0 || (metallic > 0.0 && roughness > 0.0)) as usize;
                if metallic > 0.0 && roughness < MIRROR_ROUGHNESS {
                    Material::Diffuse { albedo: base * (1.0 - metallic), specular: base * metallic }
                } else {
                    Material::Diffuse { albedo: base, specular: Rgb::ZERO }
                }
            };
            let strength = m.emissive_strength().unwrap_or(1.0);
            let radiance = sane(Vec3::from(m.emissive_factor()), 1.0) * sane(Vec3::splat(strength), 1e6).x;
            let emission = (radiance.max_element() > 0.0).then_some(Emission { radiance, two_sided: m.double_sided() });
            (material, emission)
        })
        .unzip();
    // The specification's default material: metallic 1, roughness 1, white.
    out.0.push(Material::Diffuse { albedo: Rgb::ONE, specular: Rgb::ZERO });
    out.1.push(None);
    if textured > 0 {
        notes.push(format!("{textured} material(s) have textures, which are not sampled yet: their factors are used"));
    }
    if approximated > 0 {
        notes.push(format!(
            "{approximated} material(s) approximated: rough metal as diffuse, smooth metal (roughness < {MIRROR_ROUGHNESS}) \
             as a tinted mirror, transmission as smooth glass"
        ));
    }
    if masked > 0 {
        notes.push(format!("{masked} material(s) with alphaMode MASK or BLEND are rendered opaque"));
    }
    out
}

/// Each component made finite and clamped to [0, max] (the specification's
/// ranges; validation has already rejected most values outside them).
fn sane(v: Vec3, max: f32) -> Vec3 {
    Vec3::from(v.to_array().map(|x| if x.is_finite() { x.clamp(0.0, max) } else { 0.0 }))
}
