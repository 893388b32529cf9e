//! Small analytic scenes for tests and benchmarks.

use crate::scene::Scene;
use glam::Vec3;

/// The furnace: a closed diffuse sphere of radius 1 and albedo `albedo`
/// around an isotropic point light of intensity `π · scale` at its centre;
/// with albedo 0.5 and scale 1 the radiance is exactly 1 everywhere inside
/// (direct 0.5 + indirect 0.5). The camera sits inside, off the light.
pub fn furnace(albedo: Vec3, scale: f32) -> Scene {
    let i = std::f32::consts::PI * scale;
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, 0.3]
look_at = [0.0, 0.0, -1.0]
fov_y = 60.0
resolution = [16, 16]

[[material]]
name = "wall"
type = "diffuse"
albedo = [{}, {}, {}]

[[object]]
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "wall"

[[light]]
type = "point"
position = [0.0, 0.0, 0.0]
intensity = [{i}, {i}, {i}]
"#,
        albedo.x, albedo.y, albedo.z
    );
    Scene::from_toml(&text, "furnace", None).expect("the furnace scene is valid")
}
