//! Which material and light features a scene uses, as pipeline-overridable
//! constants (features.wgsl): the passes test them before the per-surface
//! fields, so a scene pays only for what it uses. Measured on llvmpipe,
//! which runs both sides of every branch: the G-buffer of `cornell-box`
//! (no texture, no cut-out, nothing glossy) took 9x its time before the
//! glTF materials with the texture and cut-out code in it (BENCHMARKS.md).

use crate::scene_upload::{GpuSurface, kind};
use crate::textures::NO_TEXTURE;
use hikari_core::light::Light;

/// features.wgsl, required by `wgsl::SURFACE` (every pass that reads surfaces).
pub static FEATURES: crate::wgsl::Module =
    crate::wgsl::Module { name: "features.wgsl", source: include_str!("features.wgsl"), requires: &[] };

/// What the surfaces and lights of a scene use (features.wgsl says what
/// each stands for). `ALL` is correct for any scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneFeatures {
    pub textured: bool,
    pub cut_outs: bool,
    pub glossy: bool,
    pub coated: bool,
    pub sheened: bool,
    pub sampled_lights: bool,
    pub sky_image: bool,
    pub media: bool,
    pub bent: bool,
    pub mixed: bool,
    /// Some surface reads clear-coat, sheen, specular or clear-coat normal
    /// textures per point (`GpuSurface::layer_textures`), which the
    /// G-buffer keeps in a fifth target (`GBuffer::layers`).
    pub layered: bool,
}

impl SceneFeatures {
    /// What a Lambertian scene lit by point, spot, area and sun lights uses.
    pub const NONE: SceneFeatures = SceneFeatures {
        textured: false,
        cut_outs: false,
        glossy: false,
        coated: false,
        sheened: false,
        sampled_lights: false,
        sky_image: false,
        media: false,
        bent: false,
        mixed: false,
        layered: false,
    };
    pub const ALL: SceneFeatures = SceneFeatures {
        textured: true,
        cut_outs: true,
        glossy: true,
        coated: true,
        sheened: true,
        sampled_lights: true,
        sky_image: true,
        media: true,
        bent: true,
        mixed: true,
        layered: true,
    };

    /// What `surfaces` (scene_upload::scene_surfaces) and `lights` use, in
    /// a scene with media where `media` and whose diffuse surfaces' meshes
    /// shade with normals off their facets' where `bent_geometry`.
    pub fn of(surfaces: &[GpuSurface], lights: &[Light], media: bool, bent_geometry: bool) -> Self {
        SceneFeatures {
            textured: surfaces.iter().any(|s| {
                [
                    s.base_color_texture,
                    s.metallic_roughness_texture,
                    s.emissive_texture,
                    s.normal_texture,
                    s.transmission_texture,
                ]
                .iter()
                .any(|&t| t != NO_TEXTURE)
                    || s.layer_textures != NO_TEXTURE
            }),
            cut_outs: surfaces.iter().any(|s| s.alpha_cutoff >= 0.0),
            glossy: surfaces.iter().any(|s| s.glossy != 0),
            coated: surfaces.iter().any(|s| s.glossy != 0 && s.clearcoat > 0.0),
            sheened: surfaces.iter().any(|s| s.glossy != 0 && s.sheen_color.iter().any(|&c| c > 0.0)),
            sampled_lights: lights.iter().any(|l| matches!(l, Light::Environment { .. } | Light::Mesh(_))),
            sky_image: lights.iter().any(|l| matches!(l, Light::Environment { map: Some(_), .. })),
            media,
            bent: bent_geometry || surfaces.iter().any(|s| s.kind == kind::DIFFUSE && s.normal_texture != NO_TEXTURE),
            mixed: surfaces.iter().any(|s| s.transmission > 0.0),
            layered: surfaces.iter().any(|s| s.layer_textures != NO_TEXTURE),
        }
    }

    /// Everything either uses.
    pub fn union(self, other: SceneFeatures) -> SceneFeatures {
        SceneFeatures {
            textured: self.textured || other.textured,
            cut_outs: self.cut_outs || other.cut_outs,
            glossy: self.glossy || other.glossy,
            coated: self.coated || other.coated,
            sheened: self.sheened || other.sheened,
            sampled_lights: self.sampled_lights || other.sampled_lights,
            sky_image: self.sky_image || other.sky_image,
            media: self.media || other.media,
            bent: self.bent || other.bent,
            mixed: self.mixed || other.mixed,
            layered: self.layered || other.layered,
        }
    }

    /// What `scene`'s surfaces and lights use, its layer textures read per
    /// point.
    pub fn of_scene(scene: &hikari_core::scene::Scene) -> Self {
        let surfaces = crate::scene_upload::scene_surfaces(scene, true);
        let bent = bent_geometry(scene, &surfaces);
        Self::of(&surfaces, &scene.lights, !scene.media.is_empty(), bent)
    }

    /// The constants for a pipeline of the shader `source`: those of
    /// features.wgsl it declares (wgpu refuses values for overrides a
    /// module lacks).
    pub fn constants(&self, source: &str) -> Vec<(&'static str, f64)> {
        [
            ("TEXTURED", self.textured),
            ("CUT_OUTS", self.cut_outs),
            ("GLOSSY", self.glossy),
            ("COATED", self.coated),
            ("SHEENED", self.sheened),
            ("SAMPLED_LIGHTS", self.sampled_lights),
            ("SKY_IMAGE", self.sky_image),
            ("MEDIA", self.media),
            ("BENT", self.bent),
            ("MIXED", self.mixed),
            ("LAYERED", self.layered),
        ]
        .into_iter()
        .filter(|(name, _)| source.contains(&format!("override {name}: bool")))
        .map(|(name, on)| (name, on as u32 as f64))
        .collect()
    }
}

/// Whether a diffuse (kind 0) surface's geometry shades with normals off
/// its facets' (`estimate::is_bent`): tessellated spheres, and meshes with
/// smooth vertex normals. Stops at the first.
fn bent_geometry(scene: &hikari_core::scene::Scene, surfaces: &[GpuSurface]) -> bool {
    let diffuse = |s: u32| surfaces.get(s as usize).is_some_and(|s| s.kind == kind::DIFFUSE);
    scene.accel.spheres().any(|(_, s)| diffuse(s))
        || scene.accel.triangles().any(|(tri, s)| {
            diffuse(s)
                && tri.normals.is_some_and(|n| {
                    let ng = tri.geometric_normal().normalize();
                    n.0.iter().any(|&v| hikari_core::estimate::is_bent(v, ng) && hikari_core::estimate::is_bent(v, -ng))
                })
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_constants_are_the_overrides_features_wgsl_declares() {
        let features = SceneFeatures { textured: false, cut_outs: true, sampled_lights: false, ..SceneFeatures::ALL };
        let constants = features.constants(FEATURES.source);
        let expected = [
            ("TEXTURED", 0.0),
            ("CUT_OUTS", 1.0),
            ("GLOSSY", 1.0),
            ("COATED", 1.0),
            ("SHEENED", 1.0),
            ("SAMPLED_LIGHTS", 0.0),
            ("SKY_IMAGE", 1.0),
            ("MEDIA", 1.0),
            ("BENT", 1.0),
            ("MIXED", 1.0),
            ("LAYERED", 1.0),
        ];
        assert_eq!(constants, expected);
        assert!(features.constants("fn main() {}").is_empty());
    }

    #[test]
    fn built_in_scenes_use_what_their_materials_have() {
        use hikari_core::scene::Scene;
        let plain = SceneFeatures::of_scene(&Scene::load("cornell-box").unwrap());
        assert_eq!(plain, SceneFeatures::NONE);
        assert!(SceneFeatures::of_scene(&Scene::load("fog-stage").unwrap()).media);
        let showcase = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/showcase.glb");
        let showcase = SceneFeatures::of_scene(&Scene::load(showcase).unwrap());
        assert!(showcase.glossy && showcase.sampled_lights && !showcase.sky_image, "{showcase:?}");
        assert!(!showcase.coated && !showcase.sheened);
        let coated = hikari_core::test_scenes::coated_box(hikari_core::test_scenes::glossy_lights::QUAD, 8);
        assert!(SceneFeatures::of_scene(&coated).coated);
        let sheened = hikari_core::test_scenes::sheen_box(hikari_core::test_scenes::glossy_lights::QUAD, 8);
        assert!(SceneFeatures::of_scene(&sheened).sheened);
        // Bent normals: a diffuse ball, smooth-shaded meshes; not a glass ball.
        assert!(!SceneFeatures::of_scene(&Scene::load("cornell-caustic").unwrap()).bent);
        use hikari_core::test_scenes::{gltf_textures, smooth_wavy_grid_glb, wavy_grid_glb};
        assert!(SceneFeatures::of_scene(&gltf_textures::load("features-smooth", &smooth_wavy_grid_glb(200))).bent);
        assert!(!SceneFeatures::of_scene(&gltf_textures::load("features-flat", &wavy_grid_glb(200))).bent);
        // Layer textures make a scene layered and textured.
        let layered = SceneFeatures::of_scene(&gltf_textures::load("features-layered", &gltf_textures::layered_glb()));
        assert!(layered.layered && layered.textured && layered.coated && layered.sheened, "{layered:?}");
        assert!(!showcase.layered);
    }
}
