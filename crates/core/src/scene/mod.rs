//! The scene: camera, materials, surfaces, lights and the BVH over them,
//! loaded from a TOML file (docs/scene-format.md) or a built-in scene.

mod animation;
pub mod builtin;
mod desc;
mod error;
pub mod limits;
mod load;

pub use animation::{Animation, Motion, Names, Pose, Target};
pub use error::SceneError;

use crate::camera::Camera;
use crate::geometry::{Accel, Hit};
use crate::light::Light;
use crate::material::{Material, mean};
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
}

impl Scene {
    /// Loads a built-in scene by name, or else a `.toml` file at that path.
    pub fn load(spec: &str) -> Result<Scene, SceneError> {
        match builtin::source(spec) {
            Some(text) => load::parse(text, &format!("builtin:{spec}"), None),
            None => Self::from_file(Path::new(spec)),
        }
    }

    pub fn from_file(path: &Path) -> Result<Scene, SceneError> {
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
        load::parse(&text, &name, path.parent())
    }

    /// Parses scene text; relative mesh paths resolve against `base_dir`.
    pub fn from_toml(text: &str, name: &str, base_dir: Option<&Path>) -> Result<Scene, SceneError> {
        load::parse(text, name, base_dir)
    }

    pub fn material(&self, hit: &Hit) -> &Material {
        &self.materials[self.surfaces[hit.surface as usize].material as usize]
    }

    pub fn emitter(&self, hit: &Hit) -> Option<&Light> {
        self.surfaces[hit.surface as usize].emitter.map(|l| &self.lights[l as usize])
    }

    /// Scene size used to derive default radii and offsets.
    pub fn diagonal(&self) -> f32 {
        self.accel.diagonal()
    }

    /// Probability of emitting each photon from each light: proportional to
    /// its power (channel mean), as METHOD.md §2 asks.
    pub fn light_selection_probabilities(&self) -> Vec<f32> {
        let powers: Vec<f32> = self.lights.iter().map(|l| mean(l.power())).collect();
        let total: f32 = powers.iter().sum();
        powers.iter().map(|p| p / total).collect()
    }
}
