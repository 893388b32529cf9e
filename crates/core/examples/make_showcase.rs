//! Writes `scenes/showcase.glb`, the built-in example of what hikari reads
//! from glTF: a room whose left wall has a window the sun shines through
//! (`KHR_lights_punctual` directional), a glowing strip on the right wall
//! (an emissive material with `KHR_materials_emissive_strength`), a spot
//! light, a polished metal ball, a glass ball (`KHR_materials_transmission`
//! and `KHR_materials_ior`), three pillars that instance one mesh under
//! three nodes (one mirrored by a negative scale), and a camera.
//!
//!     cargo run -p hikari-core --example make_showcase [OUT.glb]
//!
//! The file is made here, from code, and licensed with the project.

use glam::{Quat, Vec3};
use gltf::json;
use gltf::json::extensions::scene::khr_lights_punctual::Type;
use hikari_core::scene::gltf::export::{GltfBuilder, PbrMaterial, looking};

/// A box of half-extents `h` centred on the origin: 24 vertices with flat
/// normals, 12 triangles facing outward.
fn cuboid(h: Vec3) -> (Vec<Vec3>, Vec<Vec3>, Vec<u32>) {
    let (mut p, mut n, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let normal = Vec3::from_array(std::array::from_fn(|i| if i == axis { sign } else { 0.0 }));
            let u = Vec3::from_array(std::array::from_fn(|i| if i == (axis + 1) % 3 { 1.0 } else { 0.0 }));
            let v = normal.cross(u);
            let base = p.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                p.push((normal + u * a + v * b) * h);
                n.push(normal);
            }
            idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    (p, n, idx)
}

/// A UV sphere of radius 1 with smooth normals.
fn sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<Vec3>, Vec<u32>) {
    let (mut p, mut idx) = (Vec::new(), Vec::new());
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            p.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            // Counter-clockwise seen from outside; the poles' slivers are dropped by the loader.
            idx.extend([a, b, b + 1, a, b + 1, a + 1]);
        }
    }
    (p.clone(), p, idx)
}

fn quad(corner: Vec3, u: Vec3, v: Vec3) -> (Vec<Vec3>, Vec<Vec3>, Vec<u32>) {
    let n = u.cross(v).normalize();
    (vec![corner, corner + u, corner + u + v, corner + v], vec![n; 4], vec![0, 1, 2, 0, 2, 3])
}

fn main() {
    let out = std::env::args().nth(1).unwrap_or_else(|| "scenes/showcase.glb".into());
    let mut b = GltfBuilder::new();
    let material =
        |b: &mut GltfBuilder, name: &str, m: PbrMaterial| b.material(&PbrMaterial { name: name.into(), ..m });
    let plaster =
        material(&mut b, "plaster", PbrMaterial { base_color: Vec3::new(0.75, 0.73, 0.7), ..Default::default() });
    let clay =
        material(&mut b, "terracotta", PbrMaterial { base_color: Vec3::new(0.7, 0.32, 0.18), ..Default::default() });
    let teal = material(&mut b, "teal", PbrMaterial { base_color: Vec3::new(0.1, 0.45, 0.45), ..Default::default() });
    let chrome = material(
        &mut b,
        "polished metal",
        PbrMaterial { base_color: Vec3::new(0.95, 0.85, 0.6), metallic: 1.0, roughness: 0.05, ..Default::default() },
    );
    let glass = material(&mut b, "glass", PbrMaterial { roughness: 0.0, glass_ior: Some(1.5), ..Default::default() });
    let glow = material(
        &mut b,
        "glowing strip",
        PbrMaterial {
            base_color: Vec3::splat(0.1),
            emission: Vec3::new(6.0, 4.2, 2.4),
            double_sided: false,
            ..Default::default()
        },
    );

    let mut roots = Vec::new();
    let add = |b: &mut GltfBuilder, (p, n, i): (Vec<Vec3>, Vec<Vec3>, Vec<u32>), m, node: json::Node| {
        let mesh = b.mesh(&p, Some(&n), Some(&i), Some(m));
        b.node(json::Node { mesh: Some(mesh), ..node })
    };
    // The room: 6 wide (x), 3 high (y), 6 deep (z), open toward the camera (+z).
    let (w, h, d) = (3.0f32, 3.0f32, 3.0f32);
    let none = json::Node::default;
    // The floor runs out of the room under the camera.
    roots.push(add(
        &mut b,
        quad(Vec3::new(-w, 0.0, 3.0 * d), Vec3::new(2.0 * w, 0.0, 0.0), Vec3::new(0.0, 0.0, -4.0 * d)),
        plaster,
        none(),
    ));
    roots.push(add(
        &mut b,
        quad(Vec3::new(-w, h, -d), Vec3::new(2.0 * w, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0 * d)),
        plaster,
        none(),
    ));
    roots.push(add(
        &mut b,
        quad(Vec3::new(-w, 0.0, -d), Vec3::new(2.0 * w, 0.0, 0.0), Vec3::new(0.0, h, 0.0)),
        plaster,
        none(),
    ));
    roots.push(add(
        &mut b,
        quad(Vec3::new(w, 0.0, d), Vec3::new(0.0, 0.0, -2.0 * d), Vec3::new(0.0, h, 0.0)),
        teal,
        none(),
    ));
    // The left wall with a window (z from 0.3 to 1.9, y from 0.9 to 2.1): four pieces around it.
    let left = |z0: f32, z1: f32, y0: f32, y1: f32| {
        quad(Vec3::new(-w, y0, z0), Vec3::new(0.0, 0.0, z1 - z0), Vec3::new(0.0, y1 - y0, 0.0))
    };
    for piece in [left(-d, 0.3, 0.0, h), left(1.9, d, 0.0, h), left(0.3, 1.9, 0.0, 0.9), left(0.3, 1.9, 2.1, h)] {
        roots.push(add(&mut b, piece, clay, none()));
    }
    // A glowing strip along the right wall, facing into the room.
    roots.push(add(
        &mut b,
        quad(Vec3::new(w - 0.01, 2.4, 1.5), Vec3::new(0.0, 0.12, 0.0), Vec3::new(0.0, 0.0, -3.0)),
        glow,
        none(),
    ));
    // Three pillars: one mesh under three nodes (the last mirrored).
    let pillar = b.mesh(
        &cuboid(Vec3::new(0.2, 0.6, 0.2)).0,
        Some(&cuboid(Vec3::new(0.2, 0.6, 0.2)).1),
        Some(&cuboid(Vec3::new(0.2, 0.6, 0.2)).2),
        Some(clay),
    );
    for (x, z, s) in [(-1.8f32, -2.2f32, 1.0f32), (0.0, -2.4, 1.0), (1.8, -2.2, -1.0)] {
        roots.push(b.node(json::Node {
            mesh: Some(pillar),
            translation: Some([x, 0.6, z]),
            rotation: Some(json::scene::UnitQuaternion(Quat::from_rotation_y(0.4 * x).to_array())),
            scale: Some([s, 1.0, 1.0]),
            ..Default::default()
        }));
    }
    // Two balls on the floor, children of a "table" node placed by a matrix.
    let ball = sphere(24, 48);
    let metal = add(
        &mut b,
        ball.clone(),
        chrome,
        json::Node { translation: Some([-0.9, 0.55, 0.0]), scale: Some([0.55; 3]), ..Default::default() },
    );
    let clear = add(
        &mut b,
        ball,
        glass,
        json::Node { translation: Some([0.9, 0.5, 0.6]), scale: Some([0.5; 3]), ..Default::default() },
    );
    let mut matrix = glam::Mat4::from_translation(Vec3::new(0.0, 0.0, -0.5)).to_cols_array();
    matrix[15] = 1.0;
    roots.push(b.node(json::Node { matrix: Some(matrix), children: Some(vec![metal, clear]), ..Default::default() }));

    // A low sun in the west (5 W/m²: 3415 lux), through the window only
    // (it shines from behind the room, whose front is open).
    let sun = b.light(Type::Directional, Vec3::new(1.0, 0.9, 0.75), 5.0 * 683.0, None);
    let sun_dir = Vec3::new(1.0, -0.6, 0.15).normalize();
    roots.push(b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(sun_dir, Vec3::Y))));
    // A 40 W spot (Blender's units: 40·683/(4π) cd) on the pillars.
    let spot = b.light(Type::Spot, Vec3::ONE, 40.0 * 683.0 / (4.0 * std::f32::consts::PI), Some((0.35, 0.5)));
    let at = Vec3::new(0.5, 2.8, 1.0);
    roots.push(b.node(GltfBuilder::light_node(spot, at, looking(Vec3::new(0.0, 1.0, -2.3) - at, Vec3::Y))));
    let camera = b.camera(50f32.to_radians(), Some(1.5));
    let eye = Vec3::new(0.0, 1.5, 6.6);
    roots.push(b.node(json::Node {
        camera: Some(camera),
        translation: Some(eye.to_array()),
        rotation: Some(json::scene::UnitQuaternion(looking(Vec3::new(0.0, 1.0, 0.0) - eye, Vec3::Y).to_array())),
        name: Some("Camera".into()),
        ..Default::default()
    }));
    let glb = b.to_glb(roots);
    std::fs::write(&out, &glb).unwrap_or_else(|e| panic!("cannot write {out}: {e}"));
    println!("wrote {out} ({} bytes)", glb.len());
}
