//! The scene: camera, materials, surfaces, lights and the BVH over them,
//! loaded from a TOML file (docs/scene-format.md), a glTF 2.0 file
//! (`gltf`) or a built-in scene. Loaders are front ends: nothing past them
//! knows which format a scene came from.

mod animation;
pub mod builtin;
pub mod deformation;
mod desc;
mod error;
pub mod files;
pub mod gltf;
pub mod keyframes;
pub mod limits;
mod load;

pub use animation::{Animation, Motion, Names, Pose, Target};
pub use error::SceneError;
pub use gltf::LoadOptions;

use crate::camera::Camera;
use crate::geometry::{Accel, Hit};
use crate::light::Light;
use crate::material::{Material, mean};
use std::borrow::Cow;
use std::path::Path;

/// One object of the scene: its material and, for area lights, which light.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub material: u32,
    pub emitter: Option<u32>,
}

#[derive(Clone)]
pub struct Scene {
    /// Where the scene came from (file path or `builtin:NAME`).
    pub source: String,
    pub camera: Camera,
    pub materials: Vec<Material>,
    pub surfaces: Vec<Surface>,
    pub lights: Vec<Light>,
    pub accel: Accel,
    /// Participating media (none: clear air).
    pub media: crate::medium::Media,
    /// Names of objects and lights (for animations and the viewer).
    pub names: Names,
    /// How lights and objects move (`posed`); empty for a still scene.
    pub animations: Vec<Animation>,
    /// One-line notes from the loader on what it ignored, approximated or
    /// added (a glTF file's unused extensions, a default light or camera).
    pub notes: Vec<String>,
    /// Images, texture coordinates and what materials take from them;
    /// None for an untextured scene. Read through [`Scene::material_at`]
    /// and [`Scene::emitted_radiance`]; the BVH holds it too for cut-outs
    /// (`Accel::set_alpha_mask`).
    pub texturing: Option<std::sync::Arc<crate::texture::Texturing>>,
}

impl Scene {
    /// Loads a built-in scene by name, or else a `.toml`, `.gltf` or `.glb`
    /// file at that path.
    pub fn load(spec: &str) -> Result<Scene, SceneError> {
        Self::load_with(spec, &LoadOptions::default())
    }

    /// [`Scene::load`] with options (the camera of a glTF file).
    pub fn load_with(spec: &str, options: &LoadOptions) -> Result<Scene, SceneError> {
        Self::load_with_progress(spec, options, &crate::progress::Silent)
    }

    /// [`Scene::load_with`], reporting the stages of loading a large file
    /// (reading a glTF file's meshes, building the BVH) to `progress`.
    pub fn load_with_progress(
        spec: &str,
        options: &LoadOptions,
        progress: &dyn crate::progress::Progress,
    ) -> Result<Scene, SceneError> {
        let mut scene = match builtin::source(spec) {
            Some(text) => load::parse(text, &format!("builtin:{spec}"), files::SceneFiles::None),
            None if gltf::is_gltf(Path::new(spec)) => gltf::load_scene(Path::new(spec), options, progress),
            None => Self::from_file(Path::new(spec)),
        }?;
        if let Some(path) = &options.environment {
            let map = crate::envmap::EnvironmentMap::load(path).map_err(|message| SceneError {
                file: path.display().to_string(),
                position: None,
                context: String::new(),
                message: message.trim_start_matches(&format!("{}: ", path.display())).to_string(),
            })?;
            scene.set_environment_map(std::sync::Arc::new(map), &path.display().to_string());
        }
        Ok(scene)
    }

    /// Lights the scene by `map` (named `name` in the note) in place of its
    /// environment: its sky (a scene has one at most: a glTF file's default
    /// one, or TOML's `[environment]`) is replaced, radiance factor 1, in
    /// place (light indices stay); a scene without one gains it. Distant
    /// lights' discs are refitted.
    pub fn set_environment_map(&mut self, map: std::sync::Arc<crate::envmap::EnvironmentMap>, name: &str) {
        let sky = Light::Environment { radiance: glam::Vec3::ONE, disc: crate::light::Disc::UNIT, map: Some(map) };
        match self.lights.iter().position(|l| matches!(l, Light::Environment { .. })) {
            Some(i) => self.lights[i] = sky,
            None => {
                self.lights.push(sky);
                self.names.lights.push(None);
            }
        }
        crate::light::fit_distant_lights(&mut self.lights, self.accel.bounds());
        self.notes.retain(|n| !n.contains("uniform white environment"));
        self.notes.push(format!("lit by the environment map {name}"));
    }

    pub fn from_file(path: &Path) -> Result<Scene, SceneError> {
        if gltf::is_gltf(path) {
            return gltf::load_scene(path, &LoadOptions::default(), &crate::progress::Silent);
        }
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            file: name.clone(),
            position: None,
            context: String::new(),
            message: if builtin::NAMES.contains(&name.as_str()) {
                e.to_string()
            } else {
                format!("cannot read scene file: {e} (built-in scenes: {})", builtin::NAMES.join(", "))
            },
        })?;
        load::parse(&text, &name, files::SceneFiles::beside(path.parent()))
    }

    /// Parses scene text; relative mesh paths resolve against `base_dir`.
    pub fn from_toml(text: &str, name: &str, base_dir: Option<&Path>) -> Result<Scene, SceneError> {
        load::parse(text, name, files::SceneFiles::beside(base_dir))
    }

    /// Parses scene text whose meshes, glTF files and sky image are read
    /// from `files` (e.g. files dropped onto the web page with it).
    pub fn from_toml_with_files(text: &str, name: &str, files: files::SceneFiles) -> Result<Scene, SceneError> {
        load::parse(text, name, files)
    }

    /// The material of the surface hit, as the file gives it (its
    /// factors, no texture): what the GPU renderer uploads per surface.
    pub fn material(&self, hit: &Hit) -> &Material {
        &self.materials[self.surfaces[hit.surface as usize].material as usize]
    }

    /// The material at the point hit, its textures looked up there (pbrt's
    /// `MaterialEvalContext`): what the CPU renderers shade with. Borrowed
    /// where nothing is textured: a copy just made and read back at once
    /// stalls the load on its store (the path tracer's step spent 5% of its
    /// time on one such load, perf).
    ///
    /// Where the file mixes two materials (`texture::Transmission`) this
    /// is the one the hit drew ([`Scene::drawn_material_at`]): any estimate
    /// that uses it once is the mix's on average.
    pub fn material_at(&self, hit: &Hit) -> Cow<'_, Material> {
        let index = self.surfaces[hit.surface as usize].material;
        let material = &self.materials[index as usize];
        match &self.texturing {
            Some(t) => t.apply(*material, index, hit.prim, hit.barycentrics, || mix_draw(hit)).material,
            None => Cow::Borrowed(material),
        }
    }

    /// [`Scene::material_at`] with the probability it was drawn with and the
    /// material not drawn.
    pub fn drawn_material_at(&self, hit: &Hit) -> crate::texture::Drawn<'_> {
        let index = self.surfaces[hit.surface as usize].material;
        let material = &self.materials[index as usize];
        match &self.texturing {
            Some(t) => t.apply(*material, index, hit.prim, hit.barycentrics, || mix_draw(hit)),
            None => crate::texture::Drawn::only(Cow::Borrowed(material)),
        }
    }

    /// Is the surface at `hit` partly transmissive (`texture::Transmission`)?
    pub fn mixes_at(&self, hit: &Hit) -> bool {
        self.texturing.as_ref().is_some_and(|t| t.mixes(self.surfaces[hit.surface as usize].material))
    }

    /// What a photon stored at `hit`, where [`Scene::material_at`]'s
    /// material stores, is weighted by (`texture::Drawn::store_weight`; 1
    /// but on partly transmissive materials). `stores` says which
    /// materials store.
    #[inline(never)]
    pub fn store_weight(&self, hit: &Hit, stores: impl Fn(&Material) -> bool) -> f32 {
        if self.mixes_at(hit) { self.drawn_material_at(hit).store_weight(stores) } else { 1.0 }
    }

    /// The shading normal at `hit` (reached travelling along `dir`), bent
    /// by its material's normal texture (`Texturing::shading_normal`) and
    /// then, as Cycles does, lifted where the eye would see it reflect
    /// below the surface (`texture::valid_reflection_normal`).
    pub fn shading_normal_at(&self, hit: &Hit, dir: glam::Vec3) -> glam::Vec3 {
        let (Some(t), Some(triangle)) = (&self.texturing, self.accel.triangle(hit.prim)) else {
            return hit.shading_normal;
        };
        let material = self.surfaces[hit.surface as usize].material;
        let bent = t.shading_normal(material, hit.prim, hit.barycentrics, triangle.v, hit.shading_normal);
        if bent == hit.shading_normal {
            return bent;
        }
        let facing = if dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
        crate::texture::valid_reflection_normal(hit.geometric_normal * facing, -dir, bent * facing) * facing
    }

    /// `bsdf` at `hit` (reached along `dir`) with its clear coat on the
    /// coat's own normal, where the material has a `clearcoatNormalTexture`
    /// (`Texturing::coat_normal`, bent from `smooth`, the unbent shading
    /// normal, and lifted as [`Scene::shading_normal_at`] lifts): in
    /// `frame`, the shading frame the renderer shades `bsdf` in (+z the
    /// bent shading normal on the side `dir` arrives from). None where
    /// nothing changes (no coat, no such texture).
    pub fn coat_tilted(
        &self,
        bsdf: &crate::bsdf::Bsdf,
        hit: &Hit,
        smooth: glam::Vec3,
        dir: glam::Vec3,
        frame: &crate::bsdf::ShadingFrame,
    ) -> Option<crate::bsdf::Bsdf> {
        if !bsdf.has_coat() {
            return None;
        }
        let (t, triangle) = (self.texturing.as_ref()?, self.accel.triangle(hit.prim)?);
        let material = self.surfaces[hit.surface as usize].material;
        let (coat, own) = t.coat_normal(material, hit.prim, hit.barycentrics, triangle.v, smooth)?;
        let facing = if dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
        let lifted = if coat == smooth {
            coat * facing
        } else {
            crate::texture::valid_reflection_normal(hit.geometric_normal * facing, -dir, coat * facing)
        };
        let local = frame.to_local(lifted);
        Some(if own { bsdf.with_coat_normal(local) } else { bsdf.with_unbent_coat(local) })
    }

    /// `hit` (reached along `dir`) with its shading normal bent by its
    /// material's normal texture (`shading_normal_at`): what every renderer
    /// and the photon tracer shade with, so a normal-mapped surface looks
    /// the same in each.
    pub fn bent(&self, hit: Hit, dir: glam::Vec3) -> Hit {
        Hit { shading_normal: self.shading_normal_at(&hit, dir), ..hit }
    }

    pub fn emitter(&self, hit: &Hit) -> Option<&Light> {
        self.surfaces[hit.surface as usize].emitter.map(|l| &self.lights[l as usize])
    }

    /// Radiance the emissive surface at `hit` sends along `dir`
    /// (propagation direction), or None if the surface is not a light. An
    /// emissive texture is read here, at the point: its light
    /// (`Light::Mesh`) emits the texture's mean uniformly, so photons,
    /// shadow rays and light sampling see that mean (docs/scene-format.md).
    pub fn emitted_radiance(&self, hit: &Hit, dir: glam::Vec3) -> Option<crate::material::Rgb> {
        let light = self.emitter(hit)?;
        let le = light.emitted_radiance(dir, hit.geometric_normal);
        Some(match &self.texturing {
            Some(t) => le * t.emission_scale(self.surfaces[hit.surface as usize].material, hit.prim, hit.barycentrics),
            None => le,
        })
    }

    /// Scene size used to derive default radii and offsets.
    pub fn diagonal(&self) -> f32 {
        self.accel.diagonal()
    }

    /// How far a ray (eye ray or photon) from `origin` along `dir` that hits
    /// nothing still travels through the media: to the plane of the disc
    /// that the distant lights' photons of the opposite direction start
    /// from (`Disc::reach`, also where shadow rays toward them end), so that
    /// both renderers and the photons see the same fog; forever in a scene
    /// without distant lights.
    pub fn escape_distance(&self, origin: glam::Vec3, dir: glam::Vec3) -> f32 {
        self.lights.iter().find_map(Light::distant_disc).map_or(f32::INFINITY, |disc| disc.reach(origin, dir))
    }

    /// Radiance reaching the origin of a ray that hits nothing: the sky's.
    pub fn escaped_radiance(&self, dir: glam::Vec3) -> crate::material::Rgb {
        self.lights.iter().map(|l| l.escaped_radiance(dir)).sum()
    }

    /// Probability of emitting each photon from each light: proportional to
    /// its power (channel mean), as METHOD.md §2 asks.
    pub fn light_selection_probabilities(&self) -> Vec<f32> {
        let powers: Vec<f32> = self.lights.iter().map(|l| mean(l.power())).collect();
        let total: f32 = powers.iter().sum();
        powers.iter().map(|p| p / total).collect()
    }
}

/// The uniform number that draws a mixed material at `hit`.
fn mix_draw(hit: &Hit) -> f32 {
    crate::texture::mix_threshold(hit.prim, hit.point)
}
