//! Structured fuzzing of glTF files: mutants of valid `.glb` files (numbers
//! in the JSON pushed to extremes, array entries dropped or duplicated,
//! keys removed; words of the binary chunk overwritten with extreme floats
//! and integers; the file cut short), loaded and rendered like the TOML
//! mutants. The loader must answer with a `Scene` or a `SceneError` that
//! says what is wrong; nothing may panic, and every pixel must be finite.

use super::{EXTREMES, INT_EXTREMES, Outcome, Renderer, guarded, pick, render_all};
use crate::sampling::Rng;
use crate::scene::Scene;
use gltf::json::Value;
use std::path::Path;
use std::time::Duration;

/// Seeds for the mutator: cornell-box written as glTF, and a small file
/// with a node hierarchy, indices, normals, a camera, punctual lights of
/// every kind and an emissive surface.
pub fn seed_files() -> Vec<Vec<u8>> {
    use crate::scene::gltf::export::{GltfBuilder, PbrMaterial, looking, scene_to_glb};
    use glam::{Quat, Vec3};
    use gltf::json;
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    let cornell = Scene::load("cornell-box").expect("built-in scene");
    let mut b = GltfBuilder::new();
    let glow = b.material(&PbrMaterial { emission: Vec3::new(5.0, 4.0, 3.0), ..Default::default() });
    let metal = b.material(&PbrMaterial { metallic: 1.0, roughness: 0.05, ..Default::default() });
    let quad =
        [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, 1.0)];
    let normals = [Vec3::Y; 4];
    let floor = b.mesh(&quad, Some(&normals), Some(&[0, 2, 1, 0, 3, 2]), Some(metal));
    let panel = b.mesh(&quad, None, Some(&[0, 1, 2, 0, 2, 3]), Some(glow));
    let child = b.node(json::Node {
        mesh: Some(panel),
        translation: Some([0.0, 2.0, 0.0]),
        scale: Some([0.3, -1.0, 0.3]),
        ..Default::default()
    });
    let root = b.node(json::Node { mesh: Some(floor), children: Some(vec![child]), ..Default::default() });
    let point = b.light(Type::Point, Vec3::ONE, 500.0, None);
    let spot = b.light(Type::Spot, Vec3::new(1.0, 0.8, 0.6), 900.0, Some((0.3, 0.6)));
    let sun = b.light(Type::Directional, Vec3::ONE, 300.0, None);
    let point = b.node(GltfBuilder::light_node(point, Vec3::new(0.5, 1.5, 0.0), Quat::IDENTITY));
    let spot = b.node(GltfBuilder::light_node(spot, Vec3::new(0.0, 1.8, 0.5), looking(-Vec3::Y, Vec3::Z)));
    let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, looking(Vec3::new(0.3, -1.0, 0.2), Vec3::Y)));
    let camera = b.camera(0.8, Some(1.0));
    let camera = b.node(json::Node { camera: Some(camera), translation: Some([0.0, 1.0, 4.0]), ..Default::default() });
    // The panel swings and the spot steps (animations' samplers and tracks).
    use gltf::json::animation::{Interpolation, Property};
    let swing: Vec<f32> = [Quat::IDENTITY, Quat::from_rotation_z(0.5)].iter().flat_map(|q| q.to_array()).collect();
    b.animate(child, Property::Rotation, Interpolation::Linear, &[0.0, 1.5], &swing);
    b.animate(spot, Property::Translation, Interpolation::Step, &[0.0, 1.0], &[0.0, 1.8, 0.5, 0.3, 1.8, 0.5]);
    let lit = b.to_glb(vec![root, point, spot, sun, camera]);
    vec![scene_to_glb(&cornell).expect("cornell-box is triangles"), lit, textured()]
}

/// A quad with a base-colour texture cut out by its alpha (MASK), over a
/// floor with a metallic-roughness texture, under the default sky: the
/// image decoder, the texture lookups and the masked traversal.
fn textured() -> Vec<u8> {
    use crate::scene::gltf::export::{GltfBuilder, PbrMaterial, png};
    use glam::{Vec2, Vec3};
    use gltf::json;
    use gltf::json::texture::WrappingMode::{ClampToEdge, Repeat};
    let mut b = GltfBuilder::new();
    let rgba: Vec<u8> =
        (0..16).flat_map(|i| [(i * 16) as u8, 255 - (i * 16) as u8, 90, if i % 3 == 0 { 0 } else { 255 }]).collect();
    let image = b.image(&png(4, 4, &rgba), "image/png");
    let repeat = b.texture(image, Repeat, Repeat);
    let clamp = b.texture(image, ClampToEdge, Repeat);
    let cutout = b.material(&PbrMaterial {
        base_color_texture: Some(repeat),
        alpha_mode: crate::texture::AlphaMode::Mask(0.5),
        ..Default::default()
    });
    let floor =
        b.material(&PbrMaterial { metallic: 1.0, metallic_roughness_texture: Some(clamp), ..Default::default() });
    let uvs = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y].map(|uv| uv * 3.0);
    let screen =
        [Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)];
    let ground = [
        Vec3::new(-1.0, -0.5, 1.0),
        Vec3::new(1.0, -0.5, 1.0),
        Vec3::new(1.0, -0.5, -1.0),
        Vec3::new(-1.0, -0.5, -1.0),
    ];
    let screen = b.textured_mesh(&screen, None, Some(&uvs), Some(&[0, 1, 2, 0, 2, 3]), Some(cutout));
    let ground = b.textured_mesh(&ground, None, Some(&uvs), Some(&[0, 1, 2, 0, 2, 3]), Some(floor));
    let nodes = vec![
        b.node(json::Node { mesh: Some(screen), ..Default::default() }),
        b.node(json::Node { mesh: Some(ground), ..Default::default() }),
    ];
    b.to_glb(nodes)
}

/// Applies 1 to 4 random mutations to a `.glb`. A file that is not a valid
/// `.glb` comes back unchanged.
pub fn mutate_glb(glb: &[u8], rng: &mut Rng) -> Vec<u8> {
    let Ok(parsed) = gltf::binary::Glb::from_slice(glb) else { return glb.to_vec() };
    let Ok(mut json) = gltf::json::deserialize::from_slice::<Value>(&parsed.json) else { return glb.to_vec() };
    let mut bin = parsed.bin.map(|b| b.into_owned()).unwrap_or_default();
    let mut cut = None;
    for _ in 0..1 + pick(rng, 4) {
        match pick(rng, 10) {
            0..=4 => mutate_json(&mut json, rng),
            5..=8 if bin.len() >= 4 => {
                let at = 4 * pick(rng, bin.len() / 4);
                let word = if rng.next_f32() < 0.5 {
                    (EXTREMES[pick(rng, EXTREMES.len())] as f32).to_le_bytes()
                } else {
                    (INT_EXTREMES[pick(rng, INT_EXTREMES.len())] as u32).to_le_bytes()
                };
                bin[at..at + 4].copy_from_slice(&word);
            }
            _ => cut = Some(pick(rng, glb.len())),
        }
    }
    let root = gltf::json::serialize::to_vec(&json).expect("a JSON value serialises");
    let out = gltf::binary::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: root.into(),
        bin: Some(bin.into()),
    }
    .to_vec()
    .unwrap_or_else(|_| glb.to_vec());
    match cut {
        Some(n) => out[..n.min(out.len())].to_vec(),
        None => out,
    }
}

/// One mutation of the JSON: a number replaced, an array entry dropped or
/// duplicated, or a key removed.
fn mutate_json(json: &mut Value, rng: &mut Rng) {
    let mut paths = Vec::new();
    collect(json, &mut Vec::new(), &mut paths);
    if paths.is_empty() {
        return;
    }
    let path = paths.swap_remove(pick(rng, paths.len()));
    let Some((last, parent_path)) = path.split_last() else { return };
    let Some(parent) = at(json, parent_path) else { return };
    let op = pick(rng, 6);
    match (parent, last) {
        (Value::Array(items), Step::Index(i)) if op == 0 && *i < items.len() => {
            items.remove(*i);
        }
        (Value::Array(items), Step::Index(i)) if op == 1 && *i < items.len() => {
            let copy = items[*i].clone();
            items.insert(*i, copy);
        }
        (Value::Object(map), Step::Key(k)) if op == 0 => {
            map.remove(k);
        }
        (parent, step) => {
            let Some(v) = child(parent, step) else { return };
            if v.is_number() {
                *v = if v.is_u64() && rng.next_f32() < 0.5 {
                    Value::from(INT_EXTREMES[pick(rng, INT_EXTREMES.len())])
                } else {
                    serde_number(EXTREMES[pick(rng, EXTREMES.len())])
                };
            }
        }
    }
}

/// JSON has no NaN or infinity: those become null, as a writer would emit.
fn serde_number(x: f64) -> Value {
    gltf::json::serialize::to_value(x).unwrap_or(Value::Null)
}

#[derive(Clone)]
enum Step {
    Key(String),
    Index(usize),
}

fn collect(v: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    if !prefix.is_empty() {
        out.push(prefix.clone());
    }
    match v {
        Value::Object(map) => {
            for (k, child) in map {
                prefix.push(Step::Key(k.clone()));
                collect(child, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                prefix.push(Step::Index(i));
                collect(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn child<'a>(v: &'a mut Value, step: &Step) -> Option<&'a mut Value> {
    match (v, step) {
        (Value::Object(map), Step::Key(k)) => map.get_mut(k),
        (Value::Array(items), Step::Index(i)) => items.get_mut(*i),
        _ => None,
    }
}

fn at<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, step| child(v, step))
}

/// Writes `glb` into `dir`, loads it and renders it at the fuzz size with
/// each renderer. `Err` describes a failure: a panic, an error that says
/// nothing, a non-finite pixel or dropped sample, or a slow render.
pub fn check_glb(glb: &[u8], dir: &Path, renderers: &[Renderer], slow: Duration) -> Result<Outcome, String> {
    let path = dir.join("mutant.glb");
    std::fs::write(&path, glb).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let loaded = guarded(|| Scene::load(path.to_str().expect("a UTF-8 temporary path")))
        .map_err(|p| format!("loader panicked: {p}"))?;
    match loaded {
        Err(e) if e.message.trim().is_empty() => Err(format!("loader error without a message: {e}")),
        Err(e) => Ok(Outcome::Rejected(e)),
        Ok(scene) => render_all(scene, renderers, slow),
    }
}
