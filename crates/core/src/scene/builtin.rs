//! Built-in scenes: scene files stored in the repository's `scenes/` folder
//! and embedded in the binary, so users can copy and edit them.

pub const NAMES: &[&str] = &["cornell-box", "cornell-caustic", "fog-stage", "fog-stage-layered", "cornell-orbit"];

pub const DEFAULT: &str = "cornell-box";

pub fn source(name: &str) -> Option<&'static str> {
    match name {
        "cornell-box" => Some(include_str!("../../../../scenes/cornell-box.toml")),
        "cornell-caustic" => Some(include_str!("../../../../scenes/cornell-caustic.toml")),
        "fog-stage" => Some(include_str!("../../../../scenes/fog-stage.toml")),
        "fog-stage-layered" => Some(include_str!("../../../../scenes/fog-stage-layered.toml")),
        "cornell-orbit" => Some(include_str!("../../../../scenes/cornell-orbit.toml")),
        _ => None,
    }
}

/// Meshes the built-in scenes use, by the path their scene files give.
pub fn mesh(path: &str) -> Option<&'static str> {
    match path {
        "meshes/fog-layer.obj" => Some(include_str!("../../../../scenes/meshes/fog-layer.obj")),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_builtin_loads() {
        for name in super::NAMES {
            let scene = crate::scene::Scene::load(name).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.lights.is_empty());
        }
    }
}
