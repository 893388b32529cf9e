//! Writing glTF 2.0 (`.glb`) with the `gltf-json` crate: a small builder
//! for tests and for the scripts that make the example scenes, and
//! [`scene_to_glb`], which writes a hikari scene of triangles as glTF (so a
//! test can load the same scene from both formats and compare the images).

use super::LUMENS_PER_WATT;
use super::materials::{CLEARCOAT, SHEEN};
use crate::light::Light;
use crate::material::{Material, Rgb};
use crate::scene::Scene;
use crate::texture::AlphaMode;
use glam::{Mat3, Quat, Vec2, Vec3};
/// The wrap modes `GltfBuilder::texture` takes, for writers outside this crate.
pub use gltf::json::texture::WrappingMode;
use gltf::json::{self, Index, validation::Checked::Valid, validation::USize64};

/// A glTF material in the metallic–roughness model.
#[derive(Clone, Debug)]
pub struct PbrMaterial {
    pub name: String,
    pub base_color: Rgb,
    pub metallic: f32,
    pub roughness: f32,
    /// Radiance, W/(m² sr): written as `emissiveFactor` (at most 1 per
    /// channel) × `KHR_materials_emissive_strength`.
    pub emission: Rgb,
    /// Smooth glass with this index of refraction (`KHR_materials_transmission`).
    pub glass_ior: Option<f32>,
    /// The share of the glass's light let through (the extension's
    /// `transmissionFactor`; 1: glass throughout, else a mix with the base).
    pub transmission: f32,
    /// The glass's inside absorption per unit length (`KHR_materials_volume`,
    /// written as the colour e^−σ at distance 1; zero: none written).
    pub glass_absorption: Rgb,
    /// `KHR_materials_specular`'s factor: 1 is glTF's default dielectric
    /// (F0 = 0.04), 0 a pure Lambertian.
    pub specular: f32,
    /// `KHR_materials_specular`'s colour (white: glTF's default).
    pub specular_color: Rgb,
    /// `KHR_materials_ior` of an opaque material (1.5, glTF's default: not
    /// written).
    pub ior: f32,
    /// `KHR_materials_clearcoat`'s factor and roughness (factor 0: none).
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    /// `KHR_materials_sheen`'s colour and roughness (black: none).
    pub sheen_color: Rgb,
    pub sheen_roughness: f32,
    pub double_sided: bool,
    /// `baseColorFactor`'s alpha.
    pub alpha: f32,
    /// `alphaMode` (MASK with its `alphaCutoff`).
    pub alpha_mode: AlphaMode,
    /// Textures (from [`GltfBuilder::texture`]), read through TEXCOORD_0.
    pub base_color_texture: Option<Index<json::Texture>>,
    pub metallic_roughness_texture: Option<Index<json::Texture>>,
    pub emissive_texture: Option<Index<json::Texture>>,
    /// A normal texture and its `scale`.
    pub normal_texture: Option<(Index<json::Texture>, f32)>,
    /// `KHR_materials_transmission`'s texture (R × the factor; with
    /// `glass_ior` only).
    pub transmission_texture: Option<Index<json::Texture>>,
}

impl Default for PbrMaterial {
    fn default() -> Self {
        PbrMaterial {
            name: String::new(),
            base_color: Rgb::ONE,
            metallic: 0.0,
            roughness: 1.0,
            emission: Rgb::ZERO,
            glass_ior: None,
            transmission: 1.0,
            glass_absorption: Rgb::ZERO,
            specular: 1.0,
            specular_color: Rgb::ONE,
            ior: 1.5,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_color: Rgb::ZERO,
            sheen_roughness: 0.0,
            double_sided: true,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            base_color_texture: None,
            metallic_roughness_texture: None,
            transmission_texture: None,
            emissive_texture: None,
            normal_texture: None,
        }
    }
}

/// Builds a glTF document whose binary data lives in one buffer (the `.glb`'s).
#[derive(Default)]
pub struct GltfBuilder {
    pub root: json::Root,
    bin: Vec<u8>,
    lights: Vec<json::extensions::scene::khr_lights_punctual::Light>,
}

impl GltfBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends `data` to the binary buffer (4-byte aligned) as a buffer view.
    fn view(&mut self, data: &[u8]) -> Index<json::buffer::View> {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let view = self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(data.len()),
            byte_offset: Some(USize64::from(self.bin.len())),
            byte_stride: None,
            name: None,
            target: None,
            extensions: None,
            extras: Default::default(),
        });
        self.bin.extend_from_slice(data);
        view
    }

    /// Appends `data` to the binary buffer as a view and returns an accessor over it.
    fn accessor(
        &mut self,
        data: &[u8],
        count: usize,
        ty: json::accessor::Type,
        component: json::accessor::ComponentType,
        bounds: Option<(Vec3, Vec3)>,
    ) -> Index<json::Accessor> {
        let view = self.view(data);
        let (min, max) = match bounds {
            Some((lo, hi)) => (
                Some(json::serialize::to_value(lo.to_array()).unwrap()),
                Some(json::serialize::to_value(hi.to_array()).unwrap()),
            ),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(ty),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// Appends `bytes` (a PNG or JPEG file of MIME type `mime`) to the
    /// binary buffer as an image.
    pub fn image(&mut self, bytes: &[u8], mime: &str) -> Index<json::Image> {
        let view = self.view(bytes);
        self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType(mime.into())),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        })
    }

    /// A texture reading `image` with its own sampler wrapping as given (linear filtering).
    pub fn texture(
        &mut self,
        image: Index<json::Image>,
        wrap_s: json::texture::WrappingMode,
        wrap_t: json::texture::WrappingMode,
    ) -> Index<json::Texture> {
        let sampler = self.root.push(json::texture::Sampler {
            mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
            min_filter: Some(Valid(json::texture::MinFilter::Linear)),
            name: None,
            wrap_s: Valid(wrap_s),
            wrap_t: Valid(wrap_t),
            extensions: None,
            extras: Default::default(),
        });
        self.root.push(json::Texture {
            name: None,
            sampler: Some(sampler),
            source: image,
            extensions: None,
            extras: Default::default(),
        })
    }

    pub fn material(&mut self, m: &PbrMaterial) -> Index<json::Material> {
        let info = |t: Option<Index<json::Texture>>| {
            t.map(|index| json::texture::Info { index, tex_coord: 0, extensions: None, extras: Default::default() })
        };
        let strength = m.emission.max_element().max(1.0);
        let mut extensions = json::extensions::material::Material::default();
        if strength > 1.0 {
            extensions.emissive_strength = Some(json::extensions::material::EmissiveStrength {
                emissive_strength: json::extensions::material::EmissiveStrengthFactor(strength),
            });
        }
        if m.specular != 1.0 || m.specular_color != Rgb::ONE {
            extensions.specular = Some(json::extensions::material::Specular {
                specular_factor: json::extensions::material::SpecularFactor(m.specular),
                specular_texture: None,
                specular_color_factor: json::extensions::material::SpecularColorFactor(m.specular_color.to_array()),
                specular_color_texture: None,
                extras: Default::default(),
            });
        }
        if m.clearcoat > 0.0 {
            // gltf-json has no type for it: written as raw JSON.
            extensions.others.insert(
                CLEARCOAT.into(),
                json::Value::from_iter([
                    ("clearcoatFactor", json::Value::from(m.clearcoat)),
                    ("clearcoatRoughnessFactor", json::Value::from(m.clearcoat_roughness)),
                ]),
            );
        }
        if m.sheen_color.max_element() > 0.0 {
            extensions.others.insert(
                SHEEN.into(),
                json::Value::from_iter([
                    ("sheenColorFactor", json::Value::from(m.sheen_color.to_array().to_vec())),
                    ("sheenRoughnessFactor", json::Value::from(m.sheen_roughness)),
                ]),
            );
        }
        if m.glass_ior.is_none() && m.ior != 1.5 {
            extensions.ior = Some(json::extensions::material::Ior {
                ior: json::extensions::material::IndexOfRefraction(m.ior),
                extras: Default::default(),
            });
        }
        if let Some(ior) = m.glass_ior {
            extensions.transmission = Some(json::extensions::material::Transmission {
                transmission_factor: json::extensions::material::TransmissionFactor(m.transmission),
                transmission_texture: info(m.transmission_texture),
                extras: Default::default(),
            });
            extensions.ior = Some(json::extensions::material::Ior {
                ior: json::extensions::material::IndexOfRefraction(ior),
                extras: Default::default(),
            });
            if m.glass_absorption != Rgb::ZERO {
                extensions.volume = Some(json::extensions::material::Volume {
                    thickness_factor: json::extensions::material::ThicknessFactor(1.0),
                    thickness_texture: None,
                    attenuation_distance: json::extensions::material::AttenuationDistance(1.0),
                    attenuation_color: json::extensions::material::AttenuationColor(
                        (-m.glass_absorption).exp().to_array(),
                    ),
                    extras: Default::default(),
                });
            }
        }
        let [r, g, b] = m.base_color.to_array();
        self.root.push(json::Material {
            name: Some(m.name.clone()),
            double_sided: m.double_sided,
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor([r, g, b, m.alpha]),
                metallic_factor: json::material::StrengthFactor(m.metallic),
                roughness_factor: json::material::StrengthFactor(m.roughness),
                base_color_texture: info(m.base_color_texture),
                metallic_roughness_texture: info(m.metallic_roughness_texture),
                ..Default::default()
            },
            emissive_factor: json::material::EmissiveFactor((m.emission / strength).to_array()),
            emissive_texture: info(m.emissive_texture),
            normal_texture: m.normal_texture.map(|(index, scale)| json::material::NormalTexture {
                index,
                scale,
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            }),
            alpha_mode: Valid(match m.alpha_mode {
                AlphaMode::Opaque => json::material::AlphaMode::Opaque,
                AlphaMode::Mask(_) => json::material::AlphaMode::Mask,
                AlphaMode::Blend => json::material::AlphaMode::Blend,
            }),
            alpha_cutoff: match m.alpha_mode {
                AlphaMode::Mask(cutoff) => Some(json::material::AlphaCutoff(cutoff)),
                _ => None,
            },
            extensions: Some(extensions),
            ..Default::default()
        })
    }

    /// A mesh of one primitive: `positions`, optional `normals`, optional
    /// `indices` (else every three positions are a triangle).
    pub fn mesh(
        &mut self,
        positions: &[Vec3],
        normals: Option<&[Vec3]>,
        indices: Option<&[u32]>,
        material: Option<Index<json::Material>>,
    ) -> Index<json::Mesh> {
        self.textured_mesh(positions, normals, None, indices, material)
    }

    /// [`GltfBuilder::mesh`] with texture coordinates `uvs` (TEXCOORD_0, f32).
    pub fn textured_mesh(
        &mut self,
        positions: &[Vec3],
        normals: Option<&[Vec3]>,
        uvs: Option<&[Vec2]>,
        indices: Option<&[u32]>,
        material: Option<Index<json::Material>>,
    ) -> Index<json::Mesh> {
        self.tangent_mesh(positions, normals, uvs, None, indices, material)
    }

    /// [`GltfBuilder::textured_mesh`] with `tangents` (TANGENT, f32 xyzw).
    pub fn tangent_mesh(
        &mut self,
        positions: &[Vec3],
        normals: Option<&[Vec3]>,
        uvs: Option<&[Vec2]>,
        tangents: Option<&[glam::Vec4]>,
        indices: Option<&[u32]>,
        material: Option<Index<json::Material>>,
    ) -> Index<json::Mesh> {
        use json::accessor::{ComponentType, Type};
        let bounds = positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let pos = self.accessor(
            bytemuck::cast_slice(positions),
            positions.len(),
            Type::Vec3,
            ComponentType::F32,
            Some(bounds),
        );
        let mut attributes = std::collections::BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        if let Some(n) = normals {
            let acc = self.accessor(bytemuck::cast_slice(n), n.len(), Type::Vec3, ComponentType::F32, None);
            attributes.insert(Valid(json::mesh::Semantic::Normals), acc);
        }
        if let Some(uv) = uvs {
            let acc = self.accessor(bytemuck::cast_slice(uv), uv.len(), Type::Vec2, ComponentType::F32, None);
            attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), acc);
        }
        if let Some(t) = tangents {
            let acc = self.accessor(bytemuck::cast_slice(t), t.len(), Type::Vec4, ComponentType::F32, None);
            attributes.insert(Valid(json::mesh::Semantic::Tangents), acc);
        }
        let indices =
            indices.map(|i| self.accessor(bytemuck::cast_slice(i), i.len(), Type::Scalar, ComponentType::U32, None));
        self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: None,
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices,
                material,
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        })
    }

    /// A one-channel animation of `node`'s `property`: `values` holds 3
    /// (translation, scale) or 4 (rotation, x y z w) floats per key time
    /// (three times as many keys for CUBICSPLINE). The sampler's key times
    /// carry their min and max, as the specification asks.
    pub fn animate(
        &mut self,
        node: Index<json::Node>,
        property: json::animation::Property,
        interpolation: json::animation::Interpolation,
        times: &[f32],
        values: &[f32],
    ) {
        use json::accessor::{ComponentType, Type};
        let input = self.accessor(bytemuck::cast_slice(times), times.len(), Type::Scalar, ComponentType::F32, None);
        let lo = times.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = times.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let accessor = &mut self.root.accessors[input.value()];
        accessor.min = Some(json::serialize::to_value([lo]).unwrap());
        accessor.max = Some(json::serialize::to_value([hi]).unwrap());
        let (ty, n) = if property == json::animation::Property::Rotation { (Type::Vec4, 4) } else { (Type::Vec3, 3) };
        let output = self.accessor(bytemuck::cast_slice(values), values.len() / n, ty, ComponentType::F32, None);
        let sampler = json::animation::Sampler {
            extensions: None,
            extras: Default::default(),
            input,
            interpolation: Valid(interpolation),
            output,
        };
        let channel = json::animation::Channel {
            sampler: Index::new(0),
            target: json::animation::Target {
                extensions: None,
                extras: Default::default(),
                node,
                path: Valid(property),
            },
            extensions: None,
            extras: Default::default(),
        };
        self.root.push(json::Animation {
            extensions: None,
            extras: Default::default(),
            channels: vec![channel],
            name: None,
            samplers: vec![sampler],
        });
    }

    /// A `KHR_lights_punctual` light in the file's units (cd or lux).
    pub fn light(
        &mut self,
        kind: json::extensions::scene::khr_lights_punctual::Type,
        color: Rgb,
        intensity: f32,
        spot: Option<(f32, f32)>,
    ) -> u32 {
        use json::extensions::scene::khr_lights_punctual as k;
        self.lights.push(k::Light {
            color: color.to_array(),
            extensions: None,
            extras: Default::default(),
            intensity,
            name: None,
            range: None,
            spot: spot.map(|(inner, outer)| k::Spot { inner_cone_angle: inner, outer_cone_angle: outer }),
            type_: Valid(kind),
        });
        self.lights.len() as u32 - 1
    }

    /// A perspective camera (`yfov` in radians).
    pub fn camera(&mut self, yfov: f32, aspect: Option<f32>) -> Index<json::Camera> {
        self.root.push(json::Camera {
            name: None,
            orthographic: None,
            perspective: Some(json::camera::Perspective {
                aspect_ratio: aspect,
                yfov,
                zfar: None,
                znear: 0.01,
                extensions: None,
                extras: Default::default(),
            }),
            type_: Valid(json::camera::Type::Perspective),
            extensions: None,
            extras: Default::default(),
        })
    }

    pub fn node(&mut self, node: json::Node) -> Index<json::Node> {
        self.root.push(node)
    }

    /// A node carrying light `light` (from [`GltfBuilder::light`]).
    pub fn light_node(light: u32, translation: Vec3, rotation: Quat) -> json::Node {
        json::Node {
            translation: Some(translation.to_array()),
            rotation: Some(json::scene::UnitQuaternion(rotation.to_array())),
            extensions: Some(json::extensions::scene::Node {
                khr_lights_punctual: Some(json::extensions::scene::khr_lights_punctual::KhrLightsPunctual {
                    light: Index::new(light),
                }),
                ..Default::default()
            }),
            ..Default::default()
        }
    }

    /// Makes `roots` the default scene and serialises everything as `.glb`.
    pub fn to_glb(self, roots: Vec<Index<json::Node>>) -> Vec<u8> {
        let (root, bin) = self.finish(roots);
        glb(&root, bin)
    }

    /// Makes `roots` the default scene: the finished document, whose buffer 0
    /// is the returned bytes (without a `uri`: a `.glb`'s binary chunk).
    pub fn finish(mut self, roots: Vec<Index<json::Node>>) -> (json::Root, Vec<u8>) {
        let scene =
            self.root.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes: roots });
        self.root.scene = Some(scene);
        self.root.asset.generator = Some("hikari".into());
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.root.buffers.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        if !self.lights.is_empty() {
            self.root.extensions_used.push("KHR_lights_punctual".into());
            let mut ext = self.root.extensions.take().unwrap_or_default();
            ext.khr_lights_punctual =
                Some(json::extensions::root::KhrLightsPunctual { lights: std::mem::take(&mut self.lights) });
            self.root.extensions = Some(ext);
        }
        for m in &self.root.materials {
            let ext = m.extensions.as_ref();
            for (used, name) in [
                (ext.is_some_and(|e| e.transmission.is_some()), "KHR_materials_transmission"),
                (ext.is_some_and(|e| e.ior.is_some()), "KHR_materials_ior"),
                (ext.is_some_and(|e| e.emissive_strength.is_some()), "KHR_materials_emissive_strength"),
                (ext.is_some_and(|e| e.specular.is_some()), "KHR_materials_specular"),
                (ext.is_some_and(|e| e.volume.is_some()), "KHR_materials_volume"),
                (ext.is_some_and(|e| e.others.contains_key(CLEARCOAT)), CLEARCOAT),
                (ext.is_some_and(|e| e.others.contains_key(SHEEN)), SHEEN),
            ] {
                if used && !self.root.extensions_used.iter().any(|e| e == name) {
                    self.root.extensions_used.push(name.into());
                }
            }
        }
        (self.root, self.bin)
    }
}

/// An 8-bit RGBA image (`rgba`: rows from the top) as a PNG file.
pub fn png(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
    let image = image::RgbaImage::from_raw(width, height, rgba.to_vec()).expect("width × height × 4 bytes");
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).expect("a PNG encodes");
    out.into_inner()
}

/// `root` and its binary chunk as a `.glb` file.
pub fn glb(root: &json::Root, bin: Vec<u8>) -> Vec<u8> {
    let json = root.to_vec().expect("a glTF document serialises");
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: json.into(),
        bin: Some(bin.into()),
    };
    glb.to_vec().expect("a .glb serialises")
}

/// The rotation that turns a glTF camera or light (looking down −z, +y up)
/// to look along `forward` with `up` as up.
pub fn looking(forward: Vec3, up: Vec3) -> Quat {
    let back = -forward.normalize();
    let right = up.cross(back).normalize();
    Quat::from_mat3(&Mat3::from_cols(right, back.cross(right), back))
}

/// Writes `scene` as a `.glb`: each surface's triangles as a mesh with its
/// material, point, spot and directional lights as `KHR_lights_punctual`
/// (× 683: cd, lux), quad lights as emissive quads, the camera. Fails on what glTF
/// cannot hold (analytic spheres, media, sphere lights, animations).
pub fn scene_to_glb(scene: &Scene) -> Result<Vec<u8>, String> {
    if scene.accel.sphere_count() > 0 {
        return Err("analytic spheres have no glTF form".into());
    }
    if !scene.media.is_empty() {
        return Err("participating media have no glTF form".into());
    }
    let mut b = GltfBuilder::new();
    let mut roots = Vec::new();
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let positions: Vec<Vec3> =
            scene.accel.triangles().filter(|(_, id)| *id == s as u32).flat_map(|(t, _)| t.v).collect();
        if positions.is_empty() {
            continue;
        }
        let material = match (&scene.materials[surface.material as usize], surface.emitter) {
            (Material::Emitter, Some(l)) => PbrMaterial {
                base_color: Rgb::ZERO,
                specular: 0.0,
                emission: scene.lights[l as usize].emission(),
                double_sided: false,
                ..Default::default()
            },
            (Material::Diffuse { albedo, specular }, _) if *specular == Rgb::ZERO => {
                PbrMaterial { base_color: *albedo, specular: 0.0, ..Default::default() }
            }
            (Material::Pbr(b), _) => PbrMaterial {
                base_color: b.base_color,
                metallic: b.metallic,
                roughness: b.roughness,
                specular: b.specular,
                specular_color: b.specular_color,
                clearcoat: b.clearcoat,
                clearcoat_roughness: b.clearcoat_roughness,
                sheen_color: b.sheen_color,
                sheen_roughness: b.sheen_roughness,
                // F0 = ((η − 1)/(η + 1))² back to η ≥ 1.
                ior: (1.0 + b.f0.sqrt()) / (1.0 - b.f0.sqrt()),
                ..Default::default()
            },
            (Material::Mirror { reflectance }, _) => {
                PbrMaterial { base_color: *reflectance, metallic: 1.0, roughness: 0.0, ..Default::default() }
            }
            (Material::Glass(glass), _) => PbrMaterial {
                base_color: glass.tint,
                roughness: glass.roughness,
                glass_ior: Some(glass.ior),
                glass_absorption: glass.absorption,
                ..Default::default()
            },
            (other, _) => return Err(format!("material {other:?} has no glTF form")),
        };
        let material = b.material(&PbrMaterial { name: format!("surface{s}"), ..material });
        let mesh = b.mesh(&positions, None, None, Some(material));
        roots.push(b.node(json::Node { mesh: Some(mesh), ..Default::default() }));
    }
    use json::extensions::scene::khr_lights_punctual::Type;
    for light in &scene.lights {
        let node = match *light {
            Light::Point { position, intensity } => {
                let l = b.light(Type::Point, Rgb::ONE, 0.0, None);
                set_intensity(&mut b, l, intensity);
                GltfBuilder::light_node(l, position, Quat::IDENTITY)
            }
            Light::Spot { position, axis, intensity, cutoff, falloff_start } => {
                let l = b.light(Type::Spot, Rgb::ONE, 0.0, Some((falloff_start, cutoff)));
                set_intensity(&mut b, l, intensity);
                let up = if axis.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
                GltfBuilder::light_node(l, position, looking(axis, up))
            }
            Light::Directional { direction, irradiance, .. } => {
                let l = b.light(Type::Directional, Rgb::ONE, 0.0, None);
                set_intensity(&mut b, l, irradiance);
                let up = if direction.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
                GltfBuilder::light_node(l, Vec3::ZERO, looking(direction, up))
            }
            Light::Quad { .. } => continue, // written above as an emissive surface
            _ => return Err("only point, spot, directional and quad lights are exported".into()),
        };
        roots.push(b.node(node));
    }
    let c = &scene.camera;
    let (forward, _, up, _) = c.basis();
    let camera = b.camera(c.fov_y.to_radians(), Some(c.aspect()));
    roots.push(b.node(json::Node {
        camera: Some(camera),
        translation: Some(c.position.to_array()),
        rotation: Some(json::scene::UnitQuaternion(looking(forward, up).to_array())),
        ..Default::default()
    }));
    Ok(b.to_glb(roots))
}

/// Writes a radiometric intensity (W/sr) or irradiance (W/m²) as glTF's
/// colour × candela or lux.
fn set_intensity(b: &mut GltfBuilder, light: u32, intensity: Rgb) {
    let peak = intensity.max_element();
    let l = &mut b.lights[light as usize];
    l.color = if peak > 0.0 { (intensity / peak).to_array() } else { [1.0; 3] };
    l.intensity = peak * LUMENS_PER_WATT;
}
