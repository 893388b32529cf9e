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

/// A 4×4 diffuse floor of albedo `albedo` at y = 0 (facing +y) under a sun
/// of irradiance `irradiance` tilted `theta_degrees` from the zenith toward
/// +x, seen from straight above by a 16×16 camera that sees only the floor.
/// With `blocker`, a black box floats off camera at (1.5, 0.5, 1.5), its
/// shadow off camera too (it reflects nothing, so the camera's view stays
/// lit by the sun alone): radiance albedo/π · E cos θ everywhere in view.
pub fn sunlit_floor(theta_degrees: f32, irradiance: f32, albedo: f32, blocker: bool) -> Scene {
    let (s, c) = theta_degrees.to_radians().sin_cos();
    let blocker = if blocker {
        "[[object]]\nshape = \"box\"\ncenter = [1.5, 0.5, 1.5]\nsize = [0.4, 0.4, 0.4]\nmaterial = \"black\"\n"
    } else {
        ""
    };
    let light = format!(
        "[[light]]\ntype = \"directional\"\ndirection = [{s}, {}, 0.0]\nirradiance = [{irradiance}, {irradiance}, {irradiance}]\n",
        -c
    );
    Scene::from_toml(&floor_scene(albedo, &format!("{blocker}{light}")), "sunlit-floor", None)
        .expect("the sunlit floor is valid")
}

/// The floor of [`sunlit_floor`] (no blocker) under a uniform sky of
/// radiance `radiance` and nothing else, made of `material` (a TOML
/// material table body named "floor"): a diffuse floor of albedo ρ shows ρ·L
/// (it sees the upper hemisphere, irradiance π·L), a mirror R·L.
pub fn sky_floor(radiance: f32, material: &str) -> Scene {
    let text = floor_scene(0.5, &format!("[environment]\nradiance = [{radiance}, {radiance}, {radiance}]\n"))
        .replace("name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]", material);
    Scene::from_toml(&text, "sky-floor", None).expect("the sky floor is valid")
}

fn floor_scene(albedo: f32, extra: &str) -> String {
    format!(
        r#"
[camera]
position = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov_y = 20.0
resolution = [16, 16]

[[material]]
name = "floor"
type = "diffuse"
albedo = [{albedo}, {albedo}, {albedo}]

[[material]]
name = "black"
type = "diffuse"
albedo = [0.0, 0.0, 0.0]

[[object]]
shape = "quad"
corner = [-2.0, 0.0, -2.0]
edge_u = [0.0, 0.0, 4.0]
edge_v = [4.0, 0.0, 0.0]
material = "floor"

{extra}"#
    )
}

/// The Cornell box at `size`×`size` pixels, its point light replaced by a
/// 0.5×0.5 quad light of radiance 12 facing down just under the ceiling.
pub fn cornell_quad_light(size: u32) -> Scene {
    let text = crate::scene::builtin::source("cornell-box").expect("cornell-box is built in");
    let start = text.find("[[light]]").expect("cornell-box has a light");
    let quad = "[[light]]\ntype = \"quad\"\ncorner = [-0.25, 0.999, -0.25]\nedge_u = [0.5, 0.0, 0.0]\nedge_v = [0.0, 0.0, 0.5]\nradiance = [12.0, 12.0, 12.0]\n";
    let mut scene = Scene::from_toml(&format!("{}{quad}", &text[..start]), "cornell-quad", None).unwrap();
    scene.camera = scene.camera.with_resolution(size, size).unwrap();
    scene
}

/// `scene` with every quad light turned into the same two triangles as an
/// emissive mesh ([`crate::light::Light::Mesh`]) whose surface is a black
/// diffuse material instead of `Material::Emitter`: the same light, carried
/// by the code paths of emissive meshes.
pub fn quad_lights_as_meshes(scene: &Scene) -> Scene {
    quad_lights_as_split_meshes(scene, 1)
}

/// [`quad_lights_as_meshes`] with each quad cut into `cuts`×`cuts` cells of
/// two triangles each.
pub fn quad_lights_as_split_meshes(scene: &Scene, cuts: u32) -> Scene {
    use crate::light::{EmissiveMesh, Light};
    use crate::material::Material;
    let mut scene = scene.clone();
    let black = scene.materials.len() as u32;
    scene.materials.push(Material::Diffuse { albedo: Vec3::ZERO, specular: Vec3::ZERO });
    for (i, light) in scene.lights.iter_mut().enumerate() {
        let Light::Quad { corner, edge_u, edge_v, radiance } = *light else { continue };
        // The loader's winding (`add_quad`): normal edge_u × edge_v.
        let (du, dv) = (edge_u / cuts as f32, edge_v / cuts as f32);
        let triangles = (0..cuts * cuts)
            .flat_map(|k| {
                let c = corner + du * (k % cuts) as f32 + dv * (k / cuts) as f32;
                [[c, c + du, c + du + dv], [c, c + du + dv, c + dv]]
            })
            .collect();
        *light = Light::Mesh(std::sync::Arc::new(EmissiveMesh::new(triangles, radiance, false).unwrap()));
        for surface in scene.surfaces.iter_mut().filter(|s| s.emitter == Some(i as u32)) {
            surface.material = black;
        }
    }
    scene
}

/// The Cornell box with glossy walls and blocks, open at the front, lit by `light`.
pub fn glossy_box(light: &str, size: u32) -> Scene {
    Scene::from_toml(
        &glossy_box_toml(light, size),
        &format!("glossy-box ({})", light.lines().nth(1).unwrap_or(light)),
        None,
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// `glossy_box` with clear coats (KHR_materials_clearcoat): a smooth coat
/// over the red wall's rough dielectric (car paint), a followed coat
/// (roughness 0.2) over the rough steel block, a gathered one (0.5) over
/// every satin white surface (floor, ceiling, back wall, tall block).
pub fn coated_box(light: &str, size: u32) -> Scene {
    let text = glossy_box_toml(light, size)
        .replace(
            "name = \"lacquered red\"\ntype = \"pbr\"\nbase_color = [0.63, 0.07, 0.05]\nroughness = 0.1",
            "name = \"lacquered red\"\ntype = \"pbr\"\nbase_color = [0.63, 0.07, 0.05]\nroughness = 0.6\nclearcoat = 1.0",
        )
        .replace("roughness = 0.7\n", "roughness = 0.7\nclearcoat = 0.8\nclearcoat_roughness = 0.2\n")
        .replace(
            "roughness = 0.5\n",
            "roughness = 0.5\nclearcoat = 1.0\nclearcoat_roughness = 0.5\n",
        );
    assert_eq!(text.matches("clearcoat =").count(), 3, "glossy_box's materials changed: update coated_box");
    Scene::from_toml(&text, &format!("coated-box ({})", light.lines().nth(1).unwrap_or(light)), None)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// `glossy_box` with sheens (KHR_materials_sheen): velvet on the green
/// wall (a white sheen of roughness 0.3 over a Lambertian green), a warm
/// sheen of roughness 0.8 over the rough steel block, and a smooth sheen
/// (the smallest roughness drawn) under a gathered clear coat over every
/// satin white surface.
pub fn sheen_box(light: &str, size: u32) -> Scene {
    let text = glossy_box_toml(light, size)
        .replace(
            "base_color = [0.14, 0.45, 0.09]\nroughness = 1.0\n",
            "base_color = [0.14, 0.45, 0.09]\nroughness = 1.0\nspecular = 0.0\nsheen_color = [1.0, 1.0, 1.0]\nsheen_roughness = 0.3\n",
        )
        .replace("roughness = 0.7\n", "roughness = 0.7\nsheen_color = [0.9, 0.6, 0.3]\nsheen_roughness = 0.8\n")
        .replace(
            "roughness = 0.5\n",
            "roughness = 0.5\nsheen_color = [0.5, 0.5, 0.6]\nsheen_roughness = 0.0\nclearcoat = 1.0\nclearcoat_roughness = 0.5\n",
        );
    assert_eq!(text.matches("sheen_color =").count(), 3, "glossy_box's materials changed: update sheen_box");
    Scene::from_toml(&text, &format!("sheen-box ({})", light.lines().nth(1).unwrap_or(light)), None)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn glossy_box_toml(light: &str, size: u32) -> String {
    format!(
        r#"
[camera]
position = [0.0, 0.0, 3.9]
look_at = [0.0, 0.0, 0.0]
fov_y = 39.3
resolution = [{size}, {size}]

[[material]]
name = "brushed gold"
type = "pbr"
base_color = [0.9, 0.75, 0.45]
metallic = 1.0
roughness = 0.2

[[material]]
name = "satin white"
type = "pbr"
base_color = [0.75, 0.74, 0.72]
roughness = 0.5

[[material]]
name = "lacquered red"
type = "pbr"
base_color = [0.63, 0.07, 0.05]
roughness = 0.1

[[material]]
name = "green"
type = "pbr"
base_color = [0.14, 0.45, 0.09]
roughness = 1.0

[[material]]
name = "rough steel"
type = "pbr"
base_color = [0.6, 0.6, 0.62]
metallic = 1.0
roughness = 0.7

[[object]]
shape = "quad"
corner = [-1.0, -1.0, -1.0]
edge_u = [0.0, 0.0, 2.0]
edge_v = [2.0, 0.0, 0.0]
material = "brushed gold"

[[object]]
shape = "quad"
corner = [-1.0, 1.0, -1.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 2.0]
material = "satin white"

[[object]]
shape = "quad"
corner = [-1.0, -1.0, -1.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 2.0, 0.0]
material = "satin white"

[[object]]
shape = "quad"
corner = [-1.0, -1.0, -1.0]
edge_u = [0.0, 2.0, 0.0]
edge_v = [0.0, 0.0, 2.0]
material = "lacquered red"

[[object]]
shape = "quad"
corner = [1.0, -1.0, -1.0]
edge_u = [0.0, 0.0, 2.0]
edge_v = [0.0, 2.0, 0.0]
material = "green"

[[object]]
shape = "box"
center = [0.33, -0.7, 0.3]
size = [0.6, 0.6, 0.6]
rotate_y = -17.0
material = "rough steel"

[[object]]
shape = "box"
center = [-0.33, -0.4, -0.3]
size = [0.6, 1.2, 0.6]
rotate_y = 17.0
material = "satin white"

{light}
"#
    )
}

/// The lights `glossy_box` is tested under, one of each kind, as TOML.
pub mod glossy_lights {
    pub const POINT: &str = "[[light]]\ntype = \"point\"\nposition = [0.0, 0.9, 0.0]\nintensity = [2.5, 2.5, 2.5]";
    pub const SPOT: &str = "[[light]]\ntype = \"spot\"\nposition = [0.0, 0.95, 0.3]\ndirection = [0.2, -1.0, -0.3]\n\
                        intensity = [6.0, 6.0, 6.0]\ncutoff_angle = 40.0\nfalloff_start_angle = 30.0";
    pub const QUAD: &str = "[[light]]\ntype = \"quad\"\ncorner = [-0.25, 0.999, -0.25]\nedge_u = [0.5, 0.0, 0.0]\n\
                        edge_v = [0.0, 0.0, 0.5]\nradiance = [12.0, 12.0, 12.0]";
    pub const SUN: &str =
        "[[light]]\ntype = \"directional\"\ndirection = [-0.3, -0.5, -1.0]\nirradiance = [3.0, 3.0, 3.0]";
    pub const SKY: &str = "[environment]\nradiance = [1.0, 1.0, 1.0]";
    /// A ball just under the ceiling, about the quad's power.
    pub const SPHERE: &str =
        "[[light]]\ntype = \"sphere\"\ncenter = [0.0, 0.8, 0.0]\nradius = 0.12\nradiance = [16.0, 16.0, 16.0]";
    /// Each with its name. (An emissive mesh: `quad_lights_as_meshes` of the quad's box.)
    pub const ALL: [(&str, &str); 6] =
        [("point", POINT), ("spot", SPOT), ("quad", QUAD), ("sun", SUN), ("sky", SKY), ("sphere", SPHERE)];
}

/// glTF files with textures, written by code: what the texture tests of
/// every renderer load.
pub mod gltf_textures {
    use crate::scene::Scene;
    use crate::scene::gltf::export::{GltfBuilder, PbrMaterial, looking, png};
    use glam::{Vec2, Vec3};
    use gltf::json;
    use gltf::json::texture::WrappingMode;

    /// A folder of the test's own (`tag`: tests run in parallel).
    pub fn folder(tag: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("hikari-gltf-tex-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Writes `bytes` to `t.glb` in `folder(tag)` and loads it.
    pub fn load(tag: &str, bytes: &[u8]) -> Scene {
        let path = folder(tag).join("t.glb");
        std::fs::write(&path, bytes).unwrap();
        Scene::load(path.to_str().unwrap()).unwrap()
    }

    /// A quad with corners `origin`, + `eu`, + `eu` + `ev`, + `ev`: the point
    /// `origin + s·eu + t·ev` has texture coordinates `scale · (s, t)`.
    pub fn quad(
        b: &mut GltfBuilder,
        origin: Vec3,
        eu: Vec3,
        ev: Vec3,
        scale: f32,
        m: json::Index<json::Material>,
    ) -> json::Index<json::Node> {
        let positions = [origin, origin + eu, origin + eu + ev, origin + ev];
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y].map(|uv| uv * scale);
        let mesh = b.textured_mesh(&positions, None, Some(&uvs), Some(&[0, 1, 2, 0, 2, 3]), Some(m));
        b.node(json::Node { mesh: Some(mesh), ..Default::default() })
    }

    /// A normal-mapped quad (one texel tilting its normal 45°; a skewed
    /// parallelogram, so the tangent frame is neither axis-aligned nor
    /// orthogonal) facing a smooth metal mirror in the plane z = 0, a point
    /// light between them, the camera at `size`² looking at the mirror from
    /// beside the quad.
    pub fn normal_map_before_a_mirror(tag: &str, size: u32) -> Scene {
        use crate::scene::gltf::export::GltfBuilder;
        use json::extensions::scene::khr_lights_punctual::Type;
        let mut b = GltfBuilder::new();
        let image = b.image(&png(1, 1, &[218, 128, 218, 255]), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let mapped = b.material(&PbrMaterial {
            base_color: Vec3::splat(0.7),
            specular: 0.0,
            normal_texture: Some((t, 1.0)),
            ..Default::default()
        });
        let mirror =
            b.material(&PbrMaterial { base_color: Vec3::ONE, metallic: 1.0, roughness: 0.0, ..Default::default() });
        // Facing −z, toward the mirror, centred on (−0.8, 0, 1).
        let (eu, ev) = (Vec3::new(1.0, 0.2, 0.1), Vec3::new(0.3, -1.0, 0.0));
        let quad_node = quad(&mut b, Vec3::new(-0.8, 0.0, 1.0) - 0.5 * (eu + ev), eu, ev, 1.0, mapped);
        let mirror_node =
            quad(&mut b, Vec3::new(-2.0, -1.5, 0.0), Vec3::new(3.5, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0), 1.0, mirror);
        let light = b.light(Type::Point, Vec3::ONE, 4.0 * 683.0, None);
        let light_node = b.node(GltfBuilder::light_node(light, Vec3::new(-0.5, 0.3, 0.45), glam::Quat::IDENTITY));
        let mut scene = load(tag, &b.to_glb(vec![quad_node, mirror_node, light_node]));
        scene.camera =
            crate::camera::Camera::new(Vec3::new(2.0, 0.0, 3.0), Vec3::new(-0.1, 0.0, 0.0), Vec3::Y, 40.0, size, size)
                .unwrap();
        scene
    }

    /// Two normal-mapped floors side by side in the plane z = 0 (a texel
    /// tilting the normal 45°), a Lambertian one (x < 0) and a glossy one,
    /// lit by a point light 0.25 above them at a grazing angle to much of
    /// them, and a white wall at y = 1 that the light and the floors light;
    /// the camera at `size`² looking down at the floors.
    pub fn normal_mapped_floors(tag: &str, size: u32) -> Scene {
        use json::extensions::scene::khr_lights_punctual::Type;
        let mut b = GltfBuilder::new();
        let image = b.image(&png(1, 1, &[218, 128, 218, 255]), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let lambert = b.material(&PbrMaterial {
            base_color: Vec3::splat(0.7),
            specular: 0.0,
            normal_texture: Some((t, 1.0)),
            ..Default::default()
        });
        let glossy = b.material(&PbrMaterial {
            base_color: Vec3::new(0.7, 0.6, 0.5),
            roughness: 0.6,
            normal_texture: Some((t, 1.0)),
            ..Default::default()
        });
        let white = b.material(&PbrMaterial { base_color: Vec3::splat(0.8), specular: 0.0, ..Default::default() });
        let (x, y) = (Vec3::X, 2.0 * Vec3::Y);
        let left = quad(&mut b, Vec3::new(-1.0, -1.0, 0.0), x, y, 1.0, lambert);
        let right = quad(&mut b, Vec3::new(0.0, -1.0, 0.0), x, y, 1.0, glossy);
        let wall = quad(&mut b, Vec3::new(-1.0, 1.0, 0.0), 2.0 * Vec3::X, 1.5 * Vec3::Z, 1.0, white);
        let light = b.light(Type::Point, Vec3::ONE, 4.0 * 683.0, None);
        let light = b.node(GltfBuilder::light_node(light, Vec3::new(0.0, -0.6, 0.25), glam::Quat::IDENTITY));
        let mut scene = load(tag, &b.to_glb(vec![left, right, wall, light]));
        scene.camera =
            crate::camera::Camera::new(Vec3::new(0.0, -0.6, 3.0), Vec3::new(0.0, 0.1, 0.0), Vec3::Y, 45.0, size, size)
                .unwrap();
        scene
    }

    /// 2×2 greys, sRGB-encoded, rows from the top: 255, 0 / 128, 64.
    pub const GREYS: [u8; 4] = [255, 0, 128, 64];

    pub fn grey_checker(alpha: [u8; 4]) -> Vec<u8> {
        let rgba: Vec<u8> = GREYS.iter().zip(alpha).flat_map(|(&g, a)| [g, g, g, a]).collect();
        png(2, 2, &rgba)
    }

    /// Two Lambertian quads (no specular lobe) under the white sky of a file
    /// without lights, both with the grey checker in base colour: x ∈ [0, 1]
    /// with texture coordinates [0, 1]² and REPEAT, x ∈ [2, 3] with [0, 2]²
    /// and CLAMP_TO_EDGE. They lie in z = 0, with v = 0 at the top (y = 1),
    /// as glTF's texture coordinates have the image's top-left at (0, 0).
    pub fn checker_glb() -> Vec<u8> {
        let (b, roots) = checker();
        b.to_glb(roots)
    }

    fn checker() -> (GltfBuilder, Vec<json::Index<json::Node>>) {
        let mut b = GltfBuilder::new();
        let image = b.image(&grey_checker([255; 4]), "image/png");
        let repeat = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let clamp = b.texture(image, WrappingMode::ClampToEdge, WrappingMode::ClampToEdge);
        let mut roots = Vec::new();
        for (x, t, scale) in [(0.0, repeat, 1.0), (2.0, clamp, 2.0)] {
            let m = b.material(&PbrMaterial { specular: 0.0, base_color_texture: Some(t), ..Default::default() });
            roots.push(quad(&mut b, Vec3::new(x, 1.0, 0.0), Vec3::X, -Vec3::Y, scale, m));
        }
        (b, roots)
    }

    /// `KHR_texture_transform`'s offset, rotation (radians) and scale of
    /// `transformed_checker_glb`.
    pub const TRANSFORM: ([f32; 2], f32, [f32; 2]) = ([0.5, 1.0], std::f32::consts::FRAC_PI_2, [2.0, 1.0]);

    /// One Lambertian quad, x and y in [0, 1] at z = 0 under the white sky,
    /// texture coordinates (x, 1 − y), with the grey checker in base colour
    /// (REPEAT) through `KHR_texture_transform` (`TRANSFORM`), which the
    /// file marks required, as Blender does: the image is read at
    /// (v + 0.5, 1 − 2u) = (1.5 − y, 1 − 2x).
    pub fn transformed_checker_glb() -> Vec<u8> {
        let mut b = GltfBuilder::new();
        let image = b.image(&grey_checker([255; 4]), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let m = b.material(&PbrMaterial { specular: 0.0, base_color_texture: Some(t), ..Default::default() });
        let root = quad(&mut b, Vec3::Y, Vec3::X, -Vec3::Y, 1.0, m);
        let (mut root, bin) = b.finish(vec![root]);
        let (offset, rotation, scale) = TRANSFORM;
        let info = root.materials[0].pbr_metallic_roughness.base_color_texture.as_mut().unwrap();
        info.extensions = Some(json::extensions::texture::Info {
            texture_transform: Some(json::extensions::texture::TextureTransform {
                offset: json::extensions::texture::TextureTransformOffset(offset),
                rotation: json::extensions::texture::TextureTransformRotation(rotation),
                scale: json::extensions::texture::TextureTransformScale(scale),
                tex_coord: None,
                extras: Default::default(),
            }),
            others: Default::default(),
        });
        for list in [&mut root.extensions_used, &mut root.extensions_required] {
            list.push("KHR_texture_transform".into());
        }
        crate::scene::gltf::export::glb(&root, bin)
    }

    /// The factors of `layered_glb`'s material, each of which a texture
    /// multiplies: clear coat, its roughness, the sheen's colour and
    /// roughness, the specular factor and colour.
    pub const LAYER_FACTORS: (f32, f32, [f32; 3], f32, f32, [f32; 3]) =
        (0.8, 0.5, [1.0, 0.5, 0.25], 0.6, 0.9, [1.0, 0.8, 0.6]);

    /// `layered_glb`'s checker alpha (its RGB is `GREYS`).
    pub const LAYER_ALPHA: [u8; 4] = [64, 128, 0, 255];

    /// `layered_glb`'s clear-coat normal texture: 2×2 texels tilting the
    /// coat 22.5° toward +u, −u, +up and −up (REPEAT), read at scale 0.8.
    pub const COAT_NORMAL_TEXELS: [[u8; 4]; 4] =
        [[176, 128, 245, 255], [80, 128, 245, 255], [128, 176, 245, 255], [128, 80, 245, 255]];

    /// The clear-coat normal texture's scale.
    pub const COAT_NORMAL_SCALE: f32 = 0.8;

    /// `COAT_NORMAL_TEXELS` as a texture of `b`.
    fn coat_normals(b: &mut GltfBuilder) -> json::Index<json::Texture> {
        let image = b.image(&png(2, 2, COAT_NORMAL_TEXELS.as_flattened()), "image/png");
        b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat)
    }

    /// One glossy quad as `transformed_checker_glb`'s (x, y in [0, 1], z =
    /// 0, texture coordinates (x, 1 − y)) with a clear coat, a sheen and
    /// `KHR_materials_specular` (`LAYER_FACTORS`), every one of their six
    /// textures the grey checker with alpha `LAYER_ALPHA` (REPEAT), the
    /// coat's normal texture `COAT_NORMAL_TEXELS`.
    pub fn layered_glb() -> Vec<u8> {
        let mut b = GltfBuilder::new();
        let image = b.image(&grey_checker(LAYER_ALPHA), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let normals = coat_normals(&mut b);
        let m = b.material(&PbrMaterial { roughness: 0.4, ..Default::default() });
        let root = quad(&mut b, Vec3::Y, Vec3::X, -Vec3::Y, 1.0, m);
        with_layers(b.finish(vec![root]), t.value(), normals.value())
    }

    /// `layered_glb`'s material (its base a darker orange) on a floor
    /// (x, y ∈ [−1, 1], z = 0, the checker four times over) before a white
    /// wall at y = 1, lit by a point light 0.4 above the floor: light
    /// bounces off the layers onto the wall and back; the camera at
    /// `size`² looking down at both.
    pub fn layered_floor(tag: &str, size: u32) -> Scene {
        use json::extensions::scene::khr_lights_punctual::Type;
        let mut b = GltfBuilder::new();
        let image = b.image(&grey_checker(LAYER_ALPHA), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let normals = coat_normals(&mut b);
        let m = b.material(&PbrMaterial { base_color: Vec3::new(0.5, 0.3, 0.1), roughness: 0.4, ..Default::default() });
        let white = b.material(&PbrMaterial { base_color: Vec3::splat(0.8), specular: 0.0, ..Default::default() });
        let floor = quad(&mut b, Vec3::new(-1.0, -1.0, 0.0), 2.0 * Vec3::X, 2.0 * Vec3::Y, 2.0, m);
        let wall = quad(&mut b, Vec3::new(-1.0, 1.0, 0.0), 2.0 * Vec3::X, 1.5 * Vec3::Z, 1.0, white);
        let light = b.light(Type::Point, Vec3::ONE, 4.0 * 683.0, None);
        let light = b.node(GltfBuilder::light_node(light, Vec3::new(0.0, -0.3, 0.4), glam::Quat::IDENTITY));
        let glb = with_layers(b.finish(vec![floor, wall, light]), t.value(), normals.value());
        let mut scene = load(tag, &glb);
        scene.camera =
            crate::camera::Camera::new(Vec3::new(0.0, -1.6, 2.2), Vec3::new(0.0, 0.2, 0.0), Vec3::Y, 50.0, size, size)
                .unwrap();
        scene
    }

    /// The document `(root, bin)` with its material 0 under a clear coat,
    /// a sheen and `KHR_materials_specular` (`LAYER_FACTORS`), all six
    /// textures texture `texture`, the coat's normal texture
    /// `coat_normal` (at `COAT_NORMAL_SCALE`).
    fn with_layers((root, bin): (json::Root, Vec<u8>), texture: usize, coat_normal: usize) -> Vec<u8> {
        let (coat, coat_roughness, sheen, sheen_roughness, specular, specular_color) = LAYER_FACTORS;
        let [sr, sg, sb] = sheen;
        let [cr, cg, cb] = specular_color;
        let info = format!(r#"{{"index": {texture}}}"#);
        let extensions = format!(
            r#"{{
                "KHR_materials_clearcoat": {{
                    "clearcoatFactor": {coat}, "clearcoatTexture": {info},
                    "clearcoatRoughnessFactor": {coat_roughness}, "clearcoatRoughnessTexture": {info},
                    "clearcoatNormalTexture": {{"index": {coat_normal}, "scale": {COAT_NORMAL_SCALE}}}
                }},
                "KHR_materials_sheen": {{
                    "sheenColorFactor": [{sr}, {sg}, {sb}], "sheenColorTexture": {info},
                    "sheenRoughnessFactor": {sheen_roughness}, "sheenRoughnessTexture": {info}
                }},
                "KHR_materials_specular": {{
                    "specularFactor": {specular}, "specularTexture": {info},
                    "specularColorFactor": [{cr}, {cg}, {cb}], "specularColorTexture": {info}
                }}
            }}"#
        );
        let mut value = json::serialize::to_value(&root).unwrap();
        value["materials"][0]["extensions"] = json::deserialize::from_str(&extensions).unwrap();
        let used = value["extensionsUsed"].as_array().cloned().unwrap_or_default();
        let mut used: Vec<String> = used.iter().filter_map(|v| v.as_str().map(String::from)).collect();
        used.extend(["KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_specular"].map(String::from));
        value["extensionsUsed"] = json::serialize::to_value(&used).unwrap();
        let root: json::Root = json::deserialize::from_value(value).unwrap();
        crate::scene::gltf::export::glb(&root, bin)
    }

    /// `checker_glb` as a `.gltf` with its buffer and image in files of
    /// their own, as exporters write them: (name, bytes) of
    /// `checker.gltf`, `checker.bin` and `checker texture.png` (its URI
    /// %-escaped).
    pub fn checker_gltf_files() -> Vec<(String, Vec<u8>)> {
        let (b, roots) = checker();
        let (mut root, bin) = b.finish(roots);
        root.buffers[0].uri = Some("checker.bin".into());
        let image = &mut root.images[0];
        image.buffer_view = None;
        image.mime_type = None;
        image.uri = Some("checker%20texture.png".into());
        let json = json::serialize::to_vec_pretty(&root).unwrap();
        vec![
            ("checker.gltf".into(), json),
            ("checker.bin".into(), bin),
            ("checker texture.png".into(), grey_checker([255; 4])),
        ]
    }

    /// A black cut-out quad at y = 1 over a white floor, lit by a sun straight
    /// down (E = 2 W/m²), alpha a 2×2 checker (REPEAT, cutoff 0.5): the floor
    /// is lit and seen from above exactly where alpha < 0.5, half of the quad.
    pub fn cutout_glb() -> Vec<u8> {
        let mut b = GltfBuilder::new();
        let floor = b.material(&PbrMaterial { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() });
        let floor = quad(&mut b, Vec3::new(-2.0, 0.0, -2.0), 4.0 * Vec3::X, 4.0 * Vec3::Z, 1.0, floor);
        let image = b.image(&grey_checker([255, 0, 0, 255]), "image/png");
        let t = b.texture(image, WrappingMode::Repeat, WrappingMode::Repeat);
        let cutout = b.material(&PbrMaterial {
            base_color: Vec3::ZERO,
            specular: 0.0,
            alpha_mode: crate::texture::AlphaMode::Mask(0.5),
            base_color_texture: Some(t),
            ..Default::default()
        });
        let cutout = quad(&mut b, Vec3::new(-0.5, 1.0, -0.5), Vec3::X, Vec3::Z, 1.0, cutout);
        use json::extensions::scene::khr_lights_punctual::Type;
        let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
        let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(-Vec3::Y, Vec3::Z)));
        b.to_glb(vec![floor, cutout, sun])
    }

    /// Of the photons on the floor (y = 0) of `cutout_glb` and `blend_glb`:
    /// how many lie under the quad (|x|, |z| < ½), how many beside it (out
    /// to 1½, 8 times the area), and the density under over the density
    /// beside: the fraction of the sun's light the quad lets through.
    pub fn density_under_the_quad(photons: &[crate::photon::Photon]) -> (usize, usize, f32) {
        let (mut under, mut beside) = (0usize, 0usize);
        for p in photons {
            let [x, y, z] = p.position;
            if y.abs() > 1e-3 {
                continue;
            }
            let r = x.abs().max(z.abs());
            if r < 0.5 {
                under += 1;
            } else if r < 1.5 {
                beside += 1;
            }
        }
        (under, beside, under as f32 * 8.0 / beside as f32)
    }

    /// A smooth glass slab (index 1.5) 2 wide and 1 thick, y from 0.5 to
    /// 1.5, whose inside keeps `color` of the light over its thickness
    /// (`KHR_materials_volume`: absorption −ln(color) per unit). With
    /// `floor_and_sun`, over a white floor (albedo 0.5, 8 wide) under a sun
    /// straight down (E = 2 W/m²); without, alone under the uniform white
    /// sky the loader gives a file without lights.
    pub fn absorbing_slab_glb(color: Vec3, floor_and_sun: bool) -> Vec<u8> {
        let mut b = GltfBuilder::new();
        let glass = b.material(&PbrMaterial {
            glass_ior: Some(1.5),
            roughness: 0.0,
            glass_absorption: -color.ln(),
            ..Default::default()
        });
        let slab = crate::medium::region::box_triangles(Vec3::new(-1.0, 0.5, -1.0), Vec3::new(1.0, 1.5, 1.0));
        let positions: Vec<Vec3> = slab.into_iter().flatten().collect();
        let mesh = b.mesh(&positions, None, None, Some(glass));
        let mut nodes = vec![b.node(json::Node { mesh: Some(mesh), ..Default::default() })];
        if floor_and_sun {
            let floor = b.material(&PbrMaterial { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() });
            nodes.push(quad(&mut b, Vec3::new(-4.0, 0.0, -4.0), 8.0 * Vec3::Z, 8.0 * Vec3::X, 1.0, floor));
            use json::extensions::scene::khr_lights_punctual::Type;
            let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
            nodes.push(b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(-Vec3::Y, Vec3::Z))));
        }
        b.to_glb(nodes)
    }

    /// A 2×2 pane at height 1 of white glass (IOR 1.5, smooth) of which a
    /// share `transmission` is let through (`KHR_materials_transmission`)
    /// and the rest a white Lambertian, over a Lambertian floor of albedo
    /// `floor`, under a sun straight down (irradiance 2 W/m²): from above
    /// the pane shows (1 − transmission) of a white Lambertian's 2/π and,
    /// over a black floor, nothing else (the glass shows the black sky and
    /// floor); the floor under it receives transmission × (1 − F(0)) =
    /// transmission × 0.96 of the sun straight through.
    pub fn mixed_pane_glb(transmission: f32, floor: f32) -> Vec<u8> {
        mixed_metal_pane_glb(transmission, 0.0, 0.0, floor)
    }

    /// `mixed_pane_glb` with the pane's base `metallic` and `roughness` (the
    /// glass as rough).
    pub fn mixed_metal_pane_glb(transmission: f32, metallic: f32, roughness: f32, floor: f32) -> Vec<u8> {
        let mut b = GltfBuilder::new();
        let floor = b.material(&PbrMaterial { base_color: Vec3::splat(floor), specular: 0.0, ..Default::default() });
        let floor = quad(&mut b, Vec3::new(-4.0, 0.0, -4.0), 8.0 * Vec3::Z, 8.0 * Vec3::X, 1.0, floor);
        let pane = b.material(&PbrMaterial {
            glass_ior: Some(1.5),
            transmission,
            metallic,
            roughness,
            specular: 0.0,
            ..Default::default()
        });
        let pane = quad(&mut b, Vec3::new(-1.0, 1.0, -1.0), 2.0 * Vec3::Z, 2.0 * Vec3::X, 1.0, pane);
        use json::extensions::scene::khr_lights_punctual::Type;
        let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
        let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(-Vec3::Y, Vec3::Z)));
        b.to_glb(vec![floor, pane, sun])
    }

    /// `cutout_glb`'s scene with the quad `alphaMode` BLEND of alpha
    /// `alpha` (the base colour factor's; no texture): it stops a fraction
    /// alpha of the sun's light and of the eye's rays, so from above the
    /// floor under it shows (1 − alpha)² of the lit floor's radiance.
    pub fn blend_glb(alpha: f32) -> Vec<u8> {
        let mut b = GltfBuilder::new();
        let floor = b.material(&PbrMaterial { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() });
        let floor = quad(&mut b, Vec3::new(-2.0, 0.0, -2.0), 4.0 * Vec3::X, 4.0 * Vec3::Z, 1.0, floor);
        let pane = b.material(&PbrMaterial {
            base_color: Vec3::ZERO,
            specular: 0.0,
            alpha,
            alpha_mode: crate::texture::AlphaMode::Blend,
            ..Default::default()
        });
        let pane = quad(&mut b, Vec3::new(-0.5, 1.0, -0.5), Vec3::X, Vec3::Z, 1.0, pane);
        use json::extensions::scene::khr_lights_punctual::Type;
        let sun = b.light(Type::Directional, Vec3::ONE, 2.0 * 683.0, None);
        let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(-Vec3::Y, Vec3::Z)));
        b.to_glb(vec![floor, pane, sun])
    }
}

/// A `.glb` of about `triangles` triangles: an n×n grid of quads over
/// [-1, 1]² whose heights are a gentle wave, Lambertian grey, under a
/// point light 1 unit above its centre; no camera (loading frames it).
/// What `examples/gltf_load` and `hikari bench`'s large-mesh row load.
pub fn wavy_grid_glb(triangles: u64) -> Vec<u8> {
    wave_glb(triangles, false)
}

/// [`wavy_grid_glb`] with the wave's own normals at its vertices: shaded
/// smooth, so every point's shading normal is bent off its facet's (up to
/// about 25°), where the photon gathers weigh
/// `estimate::shading_normal_factor`.
pub fn smooth_wavy_grid_glb(triangles: u64) -> Vec<u8> {
    wave_glb(triangles, true)
}

fn wave_glb(triangles: u64, smooth: bool) -> Vec<u8> {
    use crate::scene::gltf::export::{GltfBuilder, PbrMaterial};
    use gltf::json;
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    let n = ((triangles as f64 / 2.0).sqrt().ceil() as u32).max(1);
    let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (2.0 * i as f32 / n as f32 - 1.0, 2.0 * j as f32 / n as f32 - 1.0);
            positions.push(Vec3::new(x, 0.05 * (9.0 * x).sin() * (7.0 * z).cos(), z));
        }
    }
    let mut indices = Vec::with_capacity((6 * n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
            indices.extend([a, c, b, b, c, d]);
        }
    }
    let mut builder = GltfBuilder::new();
    // Lambertian (no specular lobe), so the GPU renderer draws it exactly.
    let material = builder.material(&PbrMaterial { base_color: Vec3::splat(0.7), specular: 0.0, ..Default::default() });
    // The height 0.05·sin 9x·cos 7z has the normal (−∂h/∂x, 1, −∂h/∂z).
    let normals: Vec<Vec3> = positions
        .iter()
        .map(|p| {
            let (dx, dz) =
                (0.45 * (9.0 * p.x).cos() * (7.0 * p.z).cos(), -0.35 * (9.0 * p.x).sin() * (7.0 * p.z).sin());
            Vec3::new(-dx, 1.0, -dz).normalize()
        })
        .collect();
    let mesh = builder.mesh(&positions, smooth.then_some(&normals[..]), Some(&indices), Some(material));
    let grid = builder.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let light = builder.light(Type::Point, Vec3::ONE, 2000.0, None);
    let light = builder.node(GltfBuilder::light_node(light, Vec3::new(0.0, 1.0, 0.0), glam::Quat::IDENTITY));
    builder.to_glb(vec![grid, light])
}

/// A frosted pane (a closed slab of rough glass, roughness 0.6) before a
/// point light 0.55 behind it, over a grey floor, seen head-on at
/// `size`×`size`: everything the pane's pixels show is the light glowing
/// through its two rough boundaries.
pub fn frosted_pane(size: u32) -> Scene {
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
resolution = [{size}, {size}]

[[material]]
name = "frosted"
type = "glass"
roughness = 0.6

[[material]]
name = "grey"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[object]]
shape = "box"
center = [0.0, 0.0, 0.0]
size = [1.6, 1.6, 0.1]
material = "frosted"

[[object]]
shape = "quad"
corner = [-3.0, -1.0, -3.0]
edge_u = [0.0, 0.0, 6.0]
edge_v = [6.0, 0.0, 0.0]
material = "grey"

[[light]]
type = "point"
position = [0.0, 0.0, -0.6]
intensity = [3.0, 3.0, 3.0]
"#
    );
    Scene::from_toml(&text, "frosted-pane", None).unwrap_or_else(|e| panic!("{e}"))
}
