//! The TOML scene file as written by users (docs/scene-format.md).
//!
//! These structs mirror the file one to one and reject unknown fields; which
//! fields apply to which `type`/`shape` is checked in `load`, where errors can
//! name the entry.

use serde::Deserialize;
use toml::Spanned;

pub type V3 = [f32; 3];

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    pub camera: Spanned<CameraDesc>,
    #[serde(default)]
    pub material: Vec<Spanned<MaterialDesc>>,
    #[serde(default)]
    pub object: Vec<Spanned<ObjectDesc>>,
    #[serde(default)]
    pub light: Vec<Spanned<LightDesc>>,
    #[serde(default)]
    pub medium: Vec<Spanned<MediumDesc>>,
    #[serde(default)]
    pub animation: Vec<Spanned<AnimationDesc>>,
    pub environment: Option<Spanned<EnvironmentDesc>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub position: V3,
    pub look_at: V3,
    #[serde(default = "default_up")]
    pub up: V3,
    #[serde(default = "default_fov")]
    pub fov_y: f32,
    #[serde(default = "default_resolution")]
    pub resolution: [u32; 2],
}

fn default_up() -> V3 {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    40.0
}
fn default_resolution() -> [u32; 2] {
    [512, 512]
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub albedo: Option<V3>,
    pub specular_reflectance: Option<V3>,
    pub reflectance: Option<V3>,
    pub ior: Option<f32>,
    /// The glTF metallic–roughness model (`type = "pbr"`).
    pub base_color: Option<V3>,
    pub metallic: Option<f32>,
    pub roughness: Option<f32>,
    pub specular: Option<f32>,
    /// KHR_materials_specular's colour (scales F0 per channel).
    pub specular_color: Option<V3>,
    /// A clear coat over a pbr material (KHR_materials_clearcoat).
    pub clearcoat: Option<f32>,
    pub clearcoat_roughness: Option<f32>,
    /// A sheen over a pbr material (KHR_materials_sheen).
    pub sheen_color: Option<V3>,
    pub sheen_roughness: Option<f32>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// Lets animations and the viewer's panel refer to the object.
    pub name: Option<String>,
    /// Spanned so that an unknown name is reported where it is written.
    /// Required, except for glTF objects, whose materials are the file's.
    pub material: Option<Spanned<String>>,
    pub mesh: Option<String>,
    /// A `.gltf` or `.glb` file placed as one object (its meshes,
    /// materials, lights and emissive surfaces; its cameras are ignored).
    pub gltf: Option<String>,
    pub shape: Option<String>,
    pub center: Option<V3>,
    pub radius: Option<f32>,
    pub corner: Option<V3>,
    pub edge_u: Option<V3>,
    pub edge_v: Option<V3>,
    pub size: Option<V3>,
    /// Rotation about +y in degrees (box and mesh).
    pub rotate_y: Option<f32>,
    /// Uniform scale (mesh).
    pub scale: Option<f32>,
    /// Translation (mesh).
    pub translate: Option<V3>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    pub name: Option<String>,
    #[serde(rename = "type")]
    pub kind: String,
    pub position: Option<V3>,
    pub intensity: Option<V3>,
    pub direction: Option<V3>,
    pub cutoff_angle: Option<f32>,
    pub falloff_start_angle: Option<f32>,
    pub center: Option<V3>,
    pub radius: Option<f32>,
    pub radiance: Option<V3>,
    pub corner: Option<V3>,
    pub edge_u: Option<V3>,
    pub edge_v: Option<V3>,
    /// W/m² on a surface facing a directional light.
    pub irradiance: Option<V3>,
}

/// A sky: uniform, or an equirectangular map.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// W/(m² sr), the same from every direction; with a `map`, the factor
    /// its texels are multiplied by (1 by default).
    pub radiance: Option<V3>,
    /// An `.hdr` or `.exr` equirectangular image, relative to the scene file.
    pub map: Option<String>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    #[serde(default)]
    pub sigma_a: V3,
    #[serde(default)]
    pub sigma_s: V3,
    /// "schlick" (with `k`) or "hg" (with `g`).
    pub phase: Option<String>,
    pub k: Option<f32>,
    pub g: Option<f32>,
    /// A closed mesh bounding the medium; none: the whole scene.
    pub region: Option<String>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct AnimationDesc {
    /// The `name` of an object or a light; spanned to locate an unknown one.
    pub target: Spanned<String>,
    /// "rotate" (with `center`, `axis`) or "move" (with `offset`).
    #[serde(rename = "type")]
    pub kind: String,
    pub center: Option<V3>,
    pub axis: Option<V3>,
    pub offset: Option<V3>,
    /// Seconds.
    pub period: f32,
}
