//! glTF materials as hikari materials: `pbrMetallicRoughness` is
//! [`Material::Pbr`] (the specification's BRDF, `crate::bsdf`); a
//! transmissive material (`KHR_materials_transmission` 1, metallic 0) is
//! glass ([`Dielectric`]) of the base colour's tint, the roughness and
//! `KHR_materials_ior` (which also sets an opaque dielectric's
//! reflectance); a partly transmissive one (factor below 1, a
//! `transmissionTexture`, metallic) is the base with a share of that glass
//! drawn per hit (`texture::Transmission`); `KHR_materials_specular`'s factor scales the
//! dielectric's Fresnel and its colour F0's; `KHR_materials_clearcoat`
//! and `KHR_materials_sheen` add their layers; the three extensions'
//! textures multiply their factors (`texture::LayerTextures`; the coat's
//! normal texture is noted as not read); `KHR_materials_volume` gives glass
//! an absorbing inside. Base-colour,
//! metallic–roughness, emissive and normal textures are read
//! (`crate::texture`; normal maps bend the CPU renderers' shading normals);
//! occlusion textures are not. `alphaMode` MASK makes cut-outs,
//! BLEND stochastic transparency (`crate::texture::AlphaMode`). Each
//! approximation made is reported in one note.

use super::textures::Images;
use crate::bsdf::Bsdf;
use crate::bsdf::dielectric::Dielectric;
use crate::material::{Material, Rgb};
use crate::texture::{AlphaMode, ColorSpace, LayerTextures, MaterialTextures, TextureRef, Transmission};
use glam::{Vec3, Vec4Swizzles};

/// Light a surface emits: `emissiveFactor` × `KHR_materials_emissive_strength`,
/// a radiance in W/(m² sr) (Blender writes its emission strength there
/// unchanged, so no 683 applies).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    pub radiance: Rgb,
    /// Emits from both faces (`doubleSided`), else from the front only.
    pub two_sided: bool,
}

/// The document's materials, then the specification's default material
/// (white, metallic 1, roughness 1) for primitives without one.
pub struct Converted {
    pub materials: Vec<Material>,
    pub emissions: Vec<Option<Emission>>,
    /// What each material takes from textures (None: nothing, and opaque).
    pub textures: Vec<Option<MaterialTextures>>,
    /// Each material's name in the file (None for the default material).
    pub names: Vec<Option<String>>,
}

/// Converts every material, reading its textures from `images`.
pub fn convert(doc: &gltf::Document, images: &Images, notes: &mut Vec<String>) -> Converted {
    let mut unread_maps = 0;
    let mut other_sets = 0;
    let mut mixed_volumes = 0;
    let mut missing_layer_textures = 0;
    let mut malformed_coats = 0;
    let mut coated_glass = 0;
    let mut malformed_sheens = 0;
    let mut sheened_glass = 0;
    let mut opaque_volumes = 0;
    let mut malformed_volumes = 0;
    let mut blender_volumes = 0;
    let absorbs = if written_by_blender(doc) { Absorbs::AsBlender } else { Absorbs::AsSpecified };
    let mut textures = Vec::new();
    let (mut materials, mut emissions): (Vec<Material>, Vec<Option<Emission>>) = doc
        .materials()
        .map(|m| {
            let pbr = m.pbr_metallic_roughness();
            unread_maps += m.occlusion_texture().is_some() as usize;
            let normal_json =
                m.index().and_then(|i| doc.as_json().materials.get(i)).and_then(|m| m.normal_texture.as_ref());
            let normal = m.normal_texture().zip(normal_json).and_then(|(n, json)| images.normal(&n, json));
            let read = [
                pbr.base_color_texture().map(|i| (tex_coord(&i), images.texture(&i, ColorSpace::Srgb))),
                pbr.metallic_roughness_texture().map(|i| (tex_coord(&i), images.texture(&i, ColorSpace::Linear))),
                m.emissive_texture().map(|i| (tex_coord(&i), images.texture(&i, ColorSpace::Srgb))),
            ];
            let normal_set =
                m.normal_texture().zip(normal_json).map_or(0, |(n, json)| super::textures::normal_tex_coord(&n, json));
            other_sets += (read.iter().flatten().any(|(set, _)| *set != 0) || normal_set != 0) as usize;
            let [base_color, metallic_roughness, emissive] = read.map(|r| r.and_then(|(_, t)| t));
            let alpha_mode = match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            };
            let [r, g, b, alpha] = pbr.base_color_factor();
            let base = sane(Vec3::new(r, g, b), 1.0);
            let metallic = sane(Vec3::splat(pbr.metallic_factor()), 1.0).x;
            let roughness = sane(Vec3::splat(pbr.roughness_factor()), 1.0).x;
            let transmission = sane(Vec3::splat(m.transmission().map_or(0.0, |t| t.transmission_factor())), 1.0).x;
            let transmission_info = m.transmission().and_then(|t| t.transmission_texture());
            let transmission_texture =
                transmission_info.as_ref().and_then(|info| images.texture(info, ColorSpace::Linear));
            other_sets += (transmission_info.is_some() && transmission_texture.is_none()) as usize;
            let coat = Clearcoat::of(&m);
            let (coat_normal, unread_coat_normal, missing_coat_normal) = coat_normal_of(doc, &m, images);
            other_sets += unread_coat_normal as usize;
            malformed_coats += coat.malformed as usize;
            let sheen = Sheen::of(&m);
            malformed_sheens += sheen.malformed as usize;
            let (layers, unread_layers, missing) = layer_textures_of(doc, &m, images);
            other_sets += unread_layers as usize;
            missing_layer_textures += (missing || missing_coat_normal) as usize;
            let transmits = transmission > 0.0;
            // Glass throughout: all of it transmits, nothing metallic
            // (`texture::Transmission` draws any other share per hit).
            let all_glass = transmission >= 1.0 && metallic == 0.0 && transmission_texture.is_none();
            let absorption = if transmits {
                match volume_absorption(&m, absorbs) {
                    Ok(a) => {
                        blender_volumes += (absorbs == Absorbs::AsBlender && a != Vec3::ZERO) as usize;
                        a
                    }
                    Err(()) => {
                        malformed_volumes += 1;
                        Vec3::ZERO
                    }
                }
            } else {
                opaque_volumes += volume_absorption(&m, absorbs).is_ok_and(|a| a != Vec3::ZERO) as usize;
                Vec3::ZERO
            };
            // The base colour tints what crosses (glTF's BTDF, and Cycles').
            let glass = Dielectric { ior: m.ior().unwrap_or(1.5).clamp(1.0, 3.0), roughness, tint: base, absorption };
            let mix = (transmits && !all_glass).then_some(Transmission {
                factor: transmission,
                texture: transmission_texture,
                ior: glass.ior,
            });
            mixed_volumes += mix.is_some_and(|_| absorption != Vec3::ZERO) as usize;
            coated_glass += (transmits && coat.factor > 0.0) as usize;
            sheened_glass += (transmits && sheen.color.max_element() > 0.0) as usize;
            let material = if all_glass {
                Material::Glass(glass)
            } else {
                // KHR_materials_specular's factor scales the dielectric's
                // Fresnel (0: a pure Lambertian, as hikari's "diffuse").
                let specular = m.specular().map_or(1.0, |s| s.specular_factor());
                // Its colour scales F0 per channel.
                let specular_color = m.specular().map_or(Vec3::ONE, |s| Vec3::from(s.specular_color_factor()));
                // KHR_materials_ior sets the dielectric's reflectance.
                let bsdf = Bsdf::new(base, metallic, roughness, sane(Vec3::splat(specular), 1.0).x)
                    .with_clearcoat(coat.factor, coat.roughness)
                    .with_sheen(sheen.color, sheen.roughness)
                    .with_specular_color(specular_color)
                    .with_ior(m.ior().unwrap_or(1.5).clamp(1.0, 3.0));
                // A mix's glass takes the base's roughness: kept as a BRDF.
                if mix.is_some() { Material::Pbr(bsdf) } else { Material::from_bsdf(bsdf) }
            };
            // An emissive texture varies the radiance over the surface; the
            // light (uniform over its mesh) emits the texture's mean.
            let emissive_mean = emissive.map_or(Rgb::ONE, |t| images.images[t.image as usize].mean().xyz());
            let strength = m.emissive_strength().unwrap_or(1.0);
            let radiance =
                sane(Vec3::from(m.emissive_factor()), 1.0) * sane(Vec3::splat(strength), 1e6).x * emissive_mean;
            let emission = (radiance.max_element() > 0.0).then_some(Emission { radiance, two_sided: m.double_sided() });
            let t = MaterialTextures {
                base_color,
                metallic_roughness,
                emissive,
                emissive_mean,
                alpha_factor: sane(Vec3::splat(alpha), 1.0).x,
                alpha_mode,
                normal: normal.map(|(t, _)| t),
                normal_scale: normal.map_or(1.0, |(_, scale)| if scale.is_finite() { scale } else { 1.0 }),
                // A coat normal matters only under a coat.
                coat_normal: coat_normal.filter(|_| coat.factor > 0.0).map(|(t, _)| t),
                coat_normal_scale: coat_normal.map_or(1.0, |(_, scale)| scale),
                coat_unbent: coat.factor > 0.0 && coat_normal.is_none() && normal.is_some(),
                layers,
                transmission: mix,
            };
            textures.push((t.is_textured() || alpha_mode != AlphaMode::Opaque || mix.is_some()).then_some(t));
            (material, emission)
        })
        .unzip();
    let mut names: Vec<Option<String>> = doc.materials().map(|m| m.name().map(str::to_string)).collect();
    names.push(None);
    // The specification's default material: metallic 1, roughness 1, white.
    materials.push(Material::Pbr(Bsdf::new(Rgb::ONE, 1.0, 1.0, 1.0)));
    emissions.push(None);
    textures.push(None);
    if unread_maps > 0 {
        notes.push(format!("{unread_maps} material(s) have occlusion textures, which are ignored"));
    }
    if other_sets > 0 {
        notes.push(format!(
            "{other_sets} material(s) read textures through texCoord other than 0 (TEXCOORD_0): those textures are ignored"
        ));
    }
    if mixed_volumes > 0 {
        notes.push(format!(
            "{mixed_volumes} partly transmissive material(s) have KHR_materials_volume attenuation, which only \
             materials that are glass throughout (transmission 1, metallic 0, no transmissionTexture) absorb by: ignored"
        ));
    }
    if missing_layer_textures > 0 {
        notes.push(format!(
            "{missing_layer_textures} material(s) have a clear-coat or sheen texture whose index names no texture of \
             the file: ignored (the factor applies alone)"
        ));
    }
    if malformed_coats > 0 {
        notes.push(format!(
            "{malformed_coats} material(s) have a KHR_materials_clearcoat factor that is not a number: read as 0"
        ));
    }
    if coated_glass > 0 {
        notes.push(format!(
            "{coated_glass} transmissive material(s) have a clear coat, which is ignored on their glass (the share \
             that transmits)"
        ));
    }
    if malformed_sheens > 0 {
        notes.push(format!(
            "{malformed_sheens} material(s) have a KHR_materials_sheen factor that is not a number (or a colour not \
             of 3 numbers): read as 0"
        ));
    }
    if sheened_glass > 0 {
        notes.push(format!(
            "{sheened_glass} transmissive material(s) have a sheen, which is ignored on their glass (the share that \
             transmits)"
        ));
    }
    if opaque_volumes > 0 {
        notes.push(format!(
            "{opaque_volumes} material(s) without transmission have KHR_materials_volume attenuation, which only \
             transmissive (glass) materials have: ignored"
        ));
    }
    if blender_volumes > 0 {
        notes.push(format!(
            "{blender_volumes} material(s) of this Blender export have KHR_materials_volume: read as Blender's \
             Volume Absorption, which it was written from (absorption (1 − attenuationColor) / attenuationDistance, \
             as Cycles draws it; the extension's own reading, −ln(colour) / distance, absorbs more)"
        ));
    }
    if malformed_volumes > 0 {
        notes.push(format!(
            "{malformed_volumes} material(s) have a KHR_materials_volume attenuationDistance that is not a positive \
             number, or an attenuationColor not of 3 numbers in [0, 1]: their glass absorbs nothing"
        ));
    }
    Converted { materials, emissions, textures, names }
}

/// How a file's `KHR_materials_volume` attenuation reads as absorption.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Absorbs {
    /// The extension's Beer–Lambert law: light crossing the attenuation
    /// distance d keeps the attenuation colour c, σ = −ln(c) / d.
    AsSpecified,
    /// Blender's: its exporter writes a Volume Absorption node's colour as c
    /// and 1/density as d, and Cycles absorbs density × (1 − colour), so
    /// σ = (1 − c) / d is what Blender rendered (measured: hikari then
    /// matches Cycles within 2% on coloured glass, against 0.49 of its
    /// blue with the extension's σ; BENCHMARKS.md).
    AsBlender,
}

/// Whether Blender's glTF exporter wrote the file (`asset.generator`).
fn written_by_blender(doc: &gltf::Document) -> bool {
    doc.as_json().asset.generator.as_deref().is_some_and(|g| g.starts_with("Khronos glTF Blender I/O"))
}

/// The absorption coefficient inside a material's volume
/// (`KHR_materials_volume`, `Dielectric::absorption`), read as `absorbs`
/// says. Zero for a thin-walled material (thicknessFactor 0, the default:
/// no volume) or the default infinite distance; Err for malformed values.
/// The thickness itself (and its texture) is what rasterizers without the
/// geometry approximate the volume's depth by: hikari's renderers measure
/// it along each ray.
fn volume_absorption(m: &gltf::Material, absorbs: Absorbs) -> Result<Vec3, ()> {
    let Some(volume) = m.volume() else { return Ok(Vec3::ZERO) };
    if !(volume.thickness_factor() > 0.0) {
        return Ok(Vec3::ZERO);
    }
    let distance = volume.attenuation_distance();
    let color = Vec3::from(volume.attenuation_color());
    if !(distance > 0.0) || !color.is_finite() || color.min_element() < 0.0 || color.max_element() > 1.0 {
        return Err(());
    }
    if distance == f32::INFINITY {
        return Ok(Vec3::ZERO);
    }
    if absorbs == Absorbs::AsBlender {
        return Ok((Vec3::ONE - color) / distance);
    }
    // A colour of 0 absorbs everything: e^−20 per attenuation distance.
    Ok(-color.max(Vec3::splat((-20.0f32).exp())).ln() / distance)
}

/// The extension's name, as it appears in a material's `extensions`
/// (gltf 1.4 has no type for it: read from the JSON).
pub const CLEARCOAT: &str = "KHR_materials_clearcoat";

/// A material's `KHR_materials_clearcoat` (factor 0 without it).
struct Clearcoat {
    factor: f32,
    roughness: f32,
    /// A factor is not a number (read as the default, 0).
    malformed: bool,
}

impl Clearcoat {
    fn of(m: &gltf::Material) -> Clearcoat {
        let Some(v) = m.extension_value(CLEARCOAT) else {
            return Clearcoat { factor: 0.0, roughness: 0.0, malformed: false };
        };
        let malformed = ["clearcoatFactor", "clearcoatRoughnessFactor"]
            .iter()
            .any(|key| v.get(*key).is_some_and(|x| !x.is_number()));
        // The specification's defaults are 0.
        let number = |key: &str| sane(Vec3::splat(v.get(key).and_then(|x| x.as_f64()).unwrap_or(0.0) as f32), 1.0).x;
        Clearcoat { factor: number("clearcoatFactor"), roughness: number("clearcoatRoughnessFactor"), malformed }
    }
}

/// The extension's name (read from the JSON, as [`CLEARCOAT`]).
pub const SHEEN: &str = "KHR_materials_sheen";

/// A material's `KHR_materials_sheen` (black, no sheen, without it).
struct Sheen {
    color: Rgb,
    roughness: f32,
    /// A factor is not a number, or the colour not three of them (read as
    /// the default, 0).
    malformed: bool,
}

impl Sheen {
    fn of(m: &gltf::Material) -> Sheen {
        let Some(v) = m.extension_value(SHEEN) else {
            return Sheen { color: Rgb::ZERO, roughness: 0.0, malformed: false };
        };
        let color = v.get("sheenColorFactor").map(|c| {
            c.as_array()
                .filter(|a| a.len() == 3 && a.iter().all(|x| x.is_number()))
                .map(|a| Vec3::from_array([0, 1, 2].map(|i| a[i].as_f64().unwrap_or(0.0) as f32)))
        });
        let roughness = v.get("sheenRoughnessFactor");
        let malformed = color.is_some_and(|c| c.is_none()) || roughness.is_some_and(|x| !x.is_number());
        // The specification's defaults are 0.
        Sheen {
            color: sane(color.flatten().unwrap_or(Vec3::ZERO), 1.0),
            roughness: sane(Vec3::splat(roughness.and_then(|x| x.as_f64()).unwrap_or(0.0) as f32), 1.0).x,
            malformed,
        }
    }
}

/// A material's clear-coat, sheen and specular textures
/// (`LayerTextures`), whether it names one that is not read (through a
/// texture coordinate set other than 0), and whether its clear coat or
/// sheen names a texture the file does not have (the `gltf` crate checks
/// the specular's).
fn layer_textures_of(doc: &gltf::Document, m: &gltf::Material, images: &Images) -> (LayerTextures, bool, bool) {
    use super::textures::{LAYER_JSON_TEXTURES, extension_textures};
    let mut named = 0;
    let mut missing = false;
    let mut json = |extension: usize, key: &str| {
        let (name, keys) = LAYER_JSON_TEXTURES[extension];
        let (_, info, space) = extension_textures(m, name, keys).into_iter().find(|(k, ..)| *k == key)?;
        let index = info.get("index").and_then(|i| i.as_u64());
        if index.is_none_or(|i| i >= doc.textures().len() as u64) {
            missing = true;
            return None;
        }
        named += 1;
        images.from_json(doc, info, space)
    };
    let mut layers = LayerTextures {
        clearcoat: json(0, "clearcoatTexture"),
        clearcoat_roughness: json(0, "clearcoatRoughnessTexture"),
        sheen_color: json(1, "sheenColorTexture"),
        sheen_roughness: json(1, "sheenRoughnessTexture"),
        ..Default::default()
    };
    if let Some(s) = m.specular() {
        for (info, space, slot) in [
            (s.specular_texture(), ColorSpace::Linear, &mut layers.specular),
            (s.specular_color_texture(), ColorSpace::Srgb, &mut layers.specular_color),
        ] {
            if let Some(info) = info {
                named += 1;
                *slot = images.texture(&info, space);
            }
        }
    }
    let read = layers.all().iter().flatten().count();
    (layers, read < named, missing)
}

/// A material's `clearcoatNormalTexture` and its `scale` (1 if absent or
/// not a finite number), whether it is named but reads a texture coordinate
/// set other than 0 (unread), and whether its index names no texture.
fn coat_normal_of(
    doc: &gltf::Document,
    m: &gltf::Material,
    images: &Images,
) -> (Option<(TextureRef, f32)>, bool, bool) {
    let Some(info) = m.extension_value(CLEARCOAT).and_then(|v| v.get("clearcoatNormalTexture")) else {
        return (None, false, false);
    };
    let index = info.get("index").and_then(|i| i.as_u64());
    if index.is_none_or(|i| i >= doc.textures().len() as u64) {
        return (None, false, true);
    }
    let scale = info.get("scale").and_then(|s| s.as_f64()).map_or(1.0, |s| s as f32);
    let scale = if scale.is_finite() { scale } else { 1.0 };
    match images.from_json(doc, info, ColorSpace::Linear) {
        Some(texture) => (Some((texture, scale)), false, false),
        None => (None, true, false),
    }
}

/// Each component made finite and clamped to [0, max] (the specification's
/// ranges; validation has already rejected most values outside them).
fn sane(v: Vec3, max: f32) -> Vec3 {
    Vec3::from(v.to_array().map(|x| if x.is_finite() { x.clamp(0.0, max) } else { 0.0 }))
}

/// The texture coordinate set a texture reads: `KHR_texture_transform`'s
/// texCoord where it has one, else the texture info's.
fn tex_coord(info: &gltf::texture::Info) -> u32 {
    info.texture_transform().and_then(|t| t.tex_coord()).unwrap_or(info.tex_coord())
}
