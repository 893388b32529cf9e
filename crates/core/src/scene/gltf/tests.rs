//! The glTF front end on files written here with `gltf-json`.

use super::export::{GltfBuilder, PbrMaterial, glb, looking};
use super::*;
use gltf::json;
use std::path::PathBuf;

/// A fresh folder for one test's files.
fn folder(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hikari-gltf-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// One triangle: (0,0,0), (1,0,0), (0,1,0), facing +z.
const TRIANGLE: [Vec3; 3] = [Vec3::ZERO, Vec3::X, Vec3::Y];

fn one_triangle(b: &mut GltfBuilder) -> json::Index<json::Mesh> {
    let m = b.material(&PbrMaterial { base_color: Vec3::new(0.5, 0.25, 1.0), ..Default::default() });
    b.mesh(&TRIANGLE, None, None, Some(m))
}

fn sorted_vertices(t: &Triangle) -> [Vec3; 3] {
    t.v
}

/// A hierarchy: a parent rotated 90° about +z and scaled (2, 1, 1), a child
/// translated by (0, 0, 5) under it with a negative x scale given as a
/// matrix, and the same mesh instanced under both.
#[test]
fn node_hierarchy_places_and_instances_triangles() {
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    // Column-major matrix: scale x by −1, translate (0, 0, 5).
    let mut matrix = [0.0f32; 16];
    matrix[0] = -1.0;
    matrix[5] = 1.0;
    matrix[10] = 1.0;
    matrix[14] = 5.0;
    matrix[15] = 1.0;
    let child = b.node(json::Node { mesh: Some(mesh), matrix: Some(matrix), ..Default::default() });
    let q = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let parent = b.node(json::Node {
        mesh: Some(mesh),
        rotation: Some(json::scene::UnitQuaternion(q.to_array())),
        scale: Some([2.0, 1.0, 1.0]),
        translation: Some([10.0, 0.0, 0.0]),
        children: Some(vec![child]),
        ..Default::default()
    });
    let dir = folder("hierarchy");
    let path = write(&dir, "h.glb", &b.to_glb(vec![parent]));
    let asset = load_asset(&path, Affine3A::IDENTITY, None, &crate::progress::Silent).unwrap();
    assert_eq!(asset.primitives.len(), 2, "one mesh under two nodes: two instances");
    // Parent: p ↦ T + R(S p) with S = diag(2,1,1), R = 90° about z: (x, y) ↦ (−y, x).
    let parent_of = |p: Vec3| Vec3::new(10.0 - p.y, 2.0 * p.x, p.z);
    let expected_parent = TRIANGLE.map(parent_of);
    // Child: p ↦ parent((−x, y, z + 5)); mirrored, so its winding is reversed.
    let child_of = |p: Vec3| parent_of(Vec3::new(-p.x, p.y, p.z + 5.0));
    let c = TRIANGLE.map(child_of);
    let expected_child = [c[0], c[2], c[1]];
    let close = |a: [Vec3; 3], b: [Vec3; 3]| a.iter().zip(b).all(|(x, y)| (*x - y).length() < 1e-5);
    let got: Vec<[Vec3; 3]> = asset.primitives.iter().map(|p| sorted_vertices(&p.triangles[0])).collect();
    assert!(close(got[0], expected_parent), "{:?} vs {expected_parent:?}", got[0]);
    assert!(close(got[1], expected_child), "{:?} vs {expected_child:?}", got[1]);
    // Front faces: the parent keeps +z (a rotation about z); the mirrored
    // child's reversed winding keeps its normal +z too (x ↦ −x alone would flip it).
    for p in &asset.primitives {
        let n = p.triangles[0].geometric_normal().normalize();
        assert!((n - Vec3::Z).length() < 1e-5, "normal {n}");
    }
    // glTF's default dielectric: the metallic–roughness BRDF with its 4% specular lobe.
    let expected = crate::bsdf::Bsdf::new(Vec3::new(0.5, 0.25, 1.0), 0.0, 1.0, 1.0);
    assert_eq!(asset.materials[asset.primitives[0].material as usize], Material::Pbr(expected));
}

#[test]
fn smooth_normals_follow_the_inverse_transpose() {
    let mut b = GltfBuilder::new();
    // A 45° slope in x–y: normal (−1, 1, 0)/√2; scaling x by 2 tilts it to (−1, 2, 0)/√5.
    let positions = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 0.0, -1.0)];
    let n = Vec3::new(-1.0, 1.0, 0.0).normalize();
    let mesh = b.mesh(&positions, Some(&[n, n, n]), Some(&[0, 1, 2]), None);
    let node = b.node(json::Node { mesh: Some(mesh), scale: Some([2.0, 1.0, 1.0]), ..Default::default() });
    let dir = folder("normals");
    let path = write(&dir, "n.glb", &b.to_glb(vec![node]));
    let asset = load_asset(&path, Affine3A::IDENTITY, None, &crate::progress::Silent).unwrap();
    let TriangleNormals(normals) = asset.primitives[0].triangles[0].normals.unwrap();
    assert!((normals[0] - Vec3::new(-1.0, 2.0, 0.0).normalize()).length() < 1e-5, "{}", normals[0]);
    // Without a material the specification's default (white) applies.
    assert_eq!(asset.primitives[0].material as usize, asset.materials.len() - 1);
}

#[test]
fn cameras_and_punctual_lights_in_radiometric_units() {
    use json::extensions::scene::khr_lights_punctual::Type;
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    let geometry = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    // A Blender export of a 100 W spot: 100·683/(4π) cd, 60° outer and 45° inner half-angles.
    let candela = 100.0 * 683.0 / (4.0 * std::f32::consts::PI);
    let spot = b.light(Type::Spot, Vec3::ONE, candela, Some((45f32.to_radians(), 60f32.to_radians())));
    let down = looking(-Vec3::Y, Vec3::Z);
    let spot = b.node(GltfBuilder::light_node(spot, Vec3::new(0.0, 3.0, 0.0), down));
    // A 2 W/m² sun: 1366 lux, shining down.
    let sun = b.light(Type::Directional, Vec3::new(1.0, 0.5, 0.25), 2.0 * 683.0, None);
    let sun = b.node(GltfBuilder::light_node(sun, Vec3::ZERO, down));
    let camera = b.camera(0.5, Some(2.0));
    let camera = b.node(json::Node { camera: Some(camera), translation: Some([0.0, 0.0, 4.0]), ..Default::default() });
    let dir = folder("lights");
    let path = write(&dir, "l.glb", &b.to_glb(vec![geometry, spot, sun, camera]));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    match &scene.lights[0] {
        Light::Spot { position, axis, intensity, cutoff, falloff_start } => {
            assert!((*position - Vec3::new(0.0, 3.0, 0.0)).length() < 1e-6);
            assert!((*axis + Vec3::Y).length() < 1e-6, "axis {axis}");
            // 100 W of a point light: 100/(4π) W/sr.
            let expected = 100.0 / (4.0 * std::f32::consts::PI);
            assert!((intensity.x / expected - 1.0).abs() < 1e-6, "{intensity} vs {expected}");
            assert!((cutoff.to_degrees() - 60.0).abs() < 1e-4 && (falloff_start.to_degrees() - 45.0).abs() < 1e-4);
        }
        other => panic!("expected a spot, got {other:?}"),
    }
    assert!(matches!(scene.lights[1], Light::Directional { .. }), "{:?}", scene.lights[1]);
    assert!((scene.lights[1].emission() - Vec3::new(2.0, 1.0, 0.5)).length() < 1e-6);
    // yfov 0.5 rad, aspect 2: 1024×512 looking down −z from (0, 0, 4).
    let c = &scene.camera;
    assert_eq!((c.width, c.height), (1024, 512));
    assert!((c.fov_y - 0.5f32.to_degrees()).abs() < 1e-4);
    assert!((c.position - Vec3::new(0.0, 0.0, 4.0)).length() < 1e-6);
    assert!((c.forward() + Vec3::Z).length() < 1e-6);
    assert!(scene.notes.is_empty(), "{:?}", scene.notes);
}

#[test]
fn a_bare_model_gets_a_white_environment_and_a_framing_camera() {
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let dir = folder("bare");
    let path = write(&dir, "bare.glb", &b.to_glb(vec![node]));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.lights.len(), 1);
    assert!(matches!(scene.lights[0], Light::Environment { .. }));
    assert_eq!(scene.notes.len(), 2, "{:?}", scene.notes);
    assert!(scene.notes[0].contains("no lights") && scene.notes[1].contains("no camera"), "{:?}", scene.notes);
    // The triangle's centre projects inside the image.
    let c = &scene.camera;
    let to_centre = (Vec3::new(0.33, 0.33, 0.0) - c.position).normalize();
    assert!(to_centre.dot(c.forward()) > (c.fov_y.to_radians() * 0.5).cos());
}

#[test]
fn an_emissive_primitive_is_a_mesh_light() {
    let mut b = GltfBuilder::new();
    let m = b.material(&PbrMaterial {
        base_color: Vec3::splat(0.5),
        emission: Vec3::new(4.0, 2.0, 1.0),
        double_sided: false,
        ..Default::default()
    });
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let dir = folder("emissive");
    let path = write(&dir, "e.glb", &b.to_glb(vec![node]));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.lights.len(), 1, "the emissive triangle lights the scene: no default environment");
    assert!(matches!(scene.lights[0], Light::Mesh(_)));
    assert_eq!(scene.surfaces[0].emitter, Some(0));
    assert_eq!(scene.lights[0].emission(), Vec3::new(4.0, 2.0, 1.0));
    // It reflects as well as it glows.
    assert!(scene.materials[scene.surfaces[0].material as usize].is_diffuse());
}

/// Loads `bytes` written as `name` and returns the error's text.
fn error_of(tag: &str, files: &[(&str, &[u8])]) -> String {
    let dir = folder(tag);
    for (name, bytes) in files {
        write(&dir, name, bytes);
    }
    let path = dir.join(files[0].0);
    match crate::scene::Scene::load(path.to_str().unwrap()) {
        Ok(_) => panic!("{tag}: loaded"),
        Err(e) => {
            assert!(e.to_string().starts_with(&path.display().to_string()), "{e}");
            e.to_string()
        }
    }
}

fn assert_says(text: &str, words: &[&str]) {
    for w in words {
        assert!(text.contains(w), "`{text}` does not say `{w}`");
    }
}

/// A valid one-triangle document to break.
fn valid() -> (json::Root, Vec<u8>) {
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    b.finish(vec![node])
}

#[test]
fn broken_files_are_located_errors() {
    let (root, bin) = valid();
    let whole = glb(&root, bin.clone());

    let e = error_of("truncated", &[("t.glb", &whole[..whole.len() - 20])]);
    assert_says(&e, &["binary glTF"]);

    let e = error_of("garbage", &[("g.gltf", b"{ \"asset\": ")]);
    assert_says(&e, &["invalid glTF JSON"]);
    let e = error_of("not-binary", &[("g.glb", b"{ \"asset\": {} }")]);
    assert_says(&e, &["not a binary glTF file", "magic"]);

    // A .gltf whose buffer file is missing.
    let mut r = root.clone();
    r.buffers[0].uri = Some("missing.bin".into());
    let e = error_of("missing-buffer", &[("m.gltf", &r.to_vec().unwrap())]);
    assert_says(&e, &["buffers[0]", "missing.bin"]);

    // A buffer shorter than its byteLength.
    let mut r = root.clone();
    r.buffers[0].uri = Some("short.bin".into());
    let e = error_of("short-buffer", &[("s.gltf", &r.to_vec().unwrap()), ("short.bin", &bin[..8])]);
    assert_says(&e, &["buffers[0]", "truncated"]);

    // An accessor reading past its view.
    let mut r = root.clone();
    r.accessors[0].count = json::validation::USize64(1000);
    let e = error_of("accessor", &[("a.glb", &glb(&r, bin.clone()))]);
    assert_says(&e, &["meshes[0].primitives[0].attributes.POSITION", "out of range"]);

    // A NaN position.
    let mut nan_bin = bin.clone();
    nan_bin[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = error_of("nan", &[("n.glb", &glb(&root, nan_bin))]);
    assert_says(&e, &["meshes[0].primitives[0].attributes.POSITION", "vertex 1", "not finite"]);

    // An extension hikari does not read, required.
    let mut r = root.clone();
    r.extensions_used.push("KHR_materials_pbrSpecularGlossiness".into());
    r.extensions_required.push("KHR_materials_pbrSpecularGlossiness".into());
    let e = error_of("extension", &[("x.glb", &glb(&r, bin.clone()))]);
    assert_says(&e, &["extensionsRequired[0]", "KHR_materials_pbrSpecularGlossiness"]);

    // Lines are not surfaces.
    let mut r = root.clone();
    r.meshes[0].primitives[0].mode = json::validation::Checked::Valid(json::mesh::Mode::Lines);
    let e = error_of("lines", &[("l.glb", &glb(&r, bin.clone()))]);
    assert_says(&e, &["meshes[0].primitives[0].mode", "Lines"]);

    // A reference to a node that does not exist (the crate's validation).
    let mut r = root.clone();
    r.scenes[0].nodes.push(json::Index::new(7));
    let e = error_of("index", &[("i.glb", &glb(&r, bin.clone()))]);
    assert_says(&e, &["scenes[0].nodes[1]"]);

    // An unknown camera name (missing and corrupt images:
    // `texture_tests::missing_and_corrupt_images_are_located_errors`).
    let dir = folder("camera-name");
    let path = write(&dir, "c.glb", &whole);
    let options = LoadOptions { camera: Some("Front".into()), ..Default::default() };
    let e = crate::scene::Scene::load_with(path.to_str().unwrap(), &options).err().unwrap().to_string();
    assert_says(&e, &["cameras", "\"Front\""]);
}

#[test]
fn indices_beyond_the_vertices_are_refused() {
    let mut b = GltfBuilder::new();
    let mesh = b.mesh(&TRIANGLE, None, Some(&[0, 1, 3]), None);
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let e = error_of("indices", &[("i.glb", &b.to_glb(vec![node]))]);
    assert_says(&e, &["meshes[0].primitives[0].indices", "index 2 is 3"]);
}

#[test]
fn unused_optional_extensions_are_one_note() {
    let (mut root, bin) = valid();
    root.extensions_used.push("KHR_materials_iridescence".into());
    root.extensions_used.push("KHR_materials_anisotropy".into());
    let dir = folder("optional");
    let path = write(&dir, "o.glb", &glb(&root, bin));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    let ext_notes: Vec<&String> = scene.notes.iter().filter(|n| n.contains("extensions ignored")).collect();
    assert_eq!(ext_notes.len(), 1);
    assert_says(ext_notes[0], &["KHR_materials_iridescence", "KHR_materials_anisotropy"]);
}

/// A TOML scene whose one `[[object]]` is `object` (its fields), with a
/// camera on +z and a point light.
fn placing(object: &str) -> String {
    format!(
        "[camera]\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\n\n[[object]]\n{object}\n\n\
         [[light]]\ntype = \"point\"\nposition = [0.0, 2.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n"
    )
}

#[test]
fn a_toml_scene_places_a_gltf_object() {
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let dir = folder("toml");
    write(&dir, "tri.glb", &b.to_glb(vec![node]));
    let toml = placing("gltf = \"tri.glb\"\nscale = 2.0\nrotate_y = 90.0\ntranslate = [1.0, 0.0, 0.0]");
    let scene = crate::scene::Scene::from_toml(&toml, "t.toml", Some(&dir)).unwrap();
    let (t, _) = scene.accel.triangles().next().unwrap();
    // (1, 0, 0) scaled by 2 and turned 90° about +y is (0, 0, −2), then moved by (1, 0, 0).
    assert!(t.v.iter().any(|v| (*v - Vec3::new(1.0, 0.0, -2.0)).length() < 1e-5), "{:?}", t.v);
    assert_eq!(scene.materials.len(), 2, "the file's material and the default");
    assert!(matches!(scene.materials[0], Material::Pbr(_)));

    let bad = toml.replace("scale = 2.0", "scale = 2.0\nmaterial = \"white\"");
    let e = crate::scene::Scene::from_toml(&bad, "t.toml", Some(&dir)).err().unwrap().to_string();
    assert_says(&e, &["t.toml:", "[[object]] #1", "`material` does not apply to a glTF object"]);
    let missing = toml.replace("tri.glb", "nothing.glb");
    let e = crate::scene::Scene::from_toml(&missing, "t.toml", Some(&dir)).err().unwrap().to_string();
    assert_says(&e, &["t.toml:", "nothing.glb", "cannot read glTF file"]);
}

/// Loading reports its stages: one step per placed primitive (instances
/// counted each time), then the BVH.
#[test]
fn loading_reports_progress_per_placed_primitive() {
    use std::sync::Mutex;
    #[derive(Default)]
    struct Recorder(Mutex<Vec<(String, u64, u64)>>);
    impl crate::progress::Progress for Recorder {
        fn begin(&self, stage: &str, total: u64) {
            self.0.lock().unwrap().push((stage.to_string(), total, 0));
        }
        fn advance(&self, amount: u64) {
            self.0.lock().unwrap().last_mut().unwrap().2 += amount;
        }
    }
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    let child = b.node(json::Node { mesh: Some(mesh), translation: Some([0.0, 0.0, 1.0]), ..Default::default() });
    let parent = b.node(json::Node { mesh: Some(mesh), children: Some(vec![child]), ..Default::default() });
    let dir = folder("progress");
    let path = write(&dir, "p.glb", &b.to_glb(vec![parent]));
    let recorder = Recorder::default();
    let options = LoadOptions::default();
    crate::scene::Scene::load_with_progress(path.to_str().unwrap(), &options, &recorder).unwrap();
    let stages = recorder.0.into_inner().unwrap();
    assert_eq!(stages, vec![("reading meshes".to_string(), 2, 2), ("building the BVH".to_string(), 1, 1)]);
}

/// `KHR_materials_clearcoat`'s factors are read (not noted as ignored);
/// its textures, not yet read, are noted; a coat over a Lambertian base
/// keeps the material glossy.
#[test]
fn the_clearcoat_extension_is_read() {
    let mut b = GltfBuilder::new();
    let coat = PbrMaterial {
        base_color: Vec3::splat(0.5),
        specular: 0.0,
        clearcoat: 0.8,
        clearcoat_roughness: 0.25,
        ..Default::default()
    };
    let m = b.material(&coat);
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let (mut root, bin) = b.finish(vec![node]);
    let dir = folder("clearcoat");
    let path = write(&dir, "c.glb", &glb(&root, bin.clone()));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("clearcoat") || n.contains("ignored")), "{:?}", scene.notes);
    assert_eq!(
        scene.materials[0],
        Material::Pbr(crate::bsdf::Bsdf::new(Vec3::splat(0.5), 0.0, 1.0, 0.0).with_clearcoat(0.8, 0.25))
    );
    // A coat texture that the file does not have: the factors still
    // apply, with a note (texture_tests reads real ones).
    let ext = root.materials[0].extensions.as_mut().unwrap();
    let value = ext.others.get_mut(materials::CLEARCOAT).unwrap().as_object_mut().unwrap();
    value.insert("clearcoatTexture".into(), json::Value::from_iter([("index", json::Value::from(0))]));
    let path = write(&dir, "t.glb", &glb(&root, bin));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(scene.notes.iter().any(|n| n.contains("names no texture of the file")), "{:?}", scene.notes);
    assert!(matches!(scene.materials[0], Material::Pbr(b) if b.clearcoat == 0.8));
}

/// `KHR_materials_sheen`'s factors are read (not noted as ignored), come
/// back from the exporter, and its textures are noted as not read; a
/// malformed colour is noted.
#[test]
fn the_sheen_extension_is_read() {
    let mut b = GltfBuilder::new();
    let velvet = PbrMaterial {
        base_color: Vec3::new(0.3, 0.05, 0.1),
        sheen_color: Vec3::new(0.9, 0.6, 0.7),
        sheen_roughness: 0.4,
        ..Default::default()
    };
    let m = b.material(&velvet);
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let (mut root, bin) = b.finish(vec![node]);
    let dir = folder("sheen");
    let path = write(&dir, "s.glb", &glb(&root, bin.clone()));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("sheen") || n.contains("ignored")), "{:?}", scene.notes);
    let want =
        crate::bsdf::Bsdf::new(Vec3::new(0.3, 0.05, 0.1), 0.0, 1.0, 1.0).with_sheen(Vec3::new(0.9, 0.6, 0.7), 0.4);
    assert_eq!(scene.materials[0], Material::Pbr(want));
    let placed = crate::scene::Scene::from_toml(&placing("gltf = \"s.glb\""), "t.toml", Some(&dir)).unwrap();
    let again = super::export::scene_to_glb(&placed).unwrap();
    let reloaded = crate::scene::Scene::load(write(&dir, "again.glb", &again).to_str().unwrap()).unwrap();
    assert_eq!(reloaded.materials[0], Material::Pbr(want));
    // A sheen texture that the file does not have: the factors still
    // apply, with a note.
    let ext = root.materials[0].extensions.as_mut().unwrap();
    let value = ext.others.get_mut(materials::SHEEN).unwrap().as_object_mut().unwrap();
    value.insert("sheenRoughnessTexture".into(), json::Value::from_iter([("index", json::Value::from(0))]));
    let scene = crate::scene::Scene::load(write(&dir, "t.glb", &glb(&root, bin.clone())).to_str().unwrap()).unwrap();
    assert!(scene.notes.iter().any(|n| n.contains("names no texture of the file")), "{:?}", scene.notes);
    assert_eq!(scene.materials[0], Material::Pbr(want));
    // A colour of two numbers is noted and read as no sheen.
    let ext = root.materials[0].extensions.as_mut().unwrap();
    let value = ext.others.get_mut(materials::SHEEN).unwrap().as_object_mut().unwrap();
    value.insert("sheenColorFactor".into(), json::Value::from(vec![0.5, 0.5]));
    let scene = crate::scene::Scene::load(write(&dir, "m.glb", &glb(&root, bin)).to_str().unwrap()).unwrap();
    assert!(
        scene.notes.iter().any(|n| n.contains("KHR_materials_sheen factor that is not a number")),
        "{:?}",
        scene.notes
    );
    assert!(matches!(scene.materials[0], Material::Pbr(b) if !b.has_sheen()));
}

/// `KHR_materials_ior` sets an opaque dielectric's reflectance at normal
/// incidence (it was read for glass alone): index 2 reflects 1/9, and the
/// exporter writes it back.
#[test]
fn the_ior_extension_is_read_for_opaque_materials() {
    let mut b = GltfBuilder::new();
    let m = b.material(&PbrMaterial { base_color: Vec3::splat(0.5), roughness: 0.3, ior: 2.0, ..Default::default() });
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let dir = folder("ior");
    write(&dir, "i.glb", &b.to_glb(vec![node]));
    let scene = crate::scene::Scene::from_toml(&placing("gltf = \"i.glb\""), "t.toml", Some(&dir)).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("ior")), "{:?}", scene.notes);
    let Material::Pbr(bsdf) = scene.materials[0] else { panic!("{:?}", scene.materials[0]) };
    assert!((bsdf.f0 - 1.0 / 9.0).abs() < 1e-6, "{}", bsdf.f0);
    let again = super::export::scene_to_glb(&scene).unwrap();
    let path = write(&dir, "again.glb", &again);
    let reloaded = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    let Material::Pbr(back) = reloaded.materials[0] else { panic!("{:?}", reloaded.materials[0]) };
    assert!((back.f0 - bsdf.f0).abs() < 1e-5, "{} against {}", back.f0, bsdf.f0);
}

/// `KHR_materials_specular` is read, not listed as ignored: its factor 0
/// makes an exact Lambertian (as hikari's own diffuse material).
#[test]
fn the_specular_extension_is_read() {
    let mut b = GltfBuilder::new();
    let m = b.material(&PbrMaterial { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() });
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let dir = folder("specular");
    let path = write(&dir, "s.glb", &b.to_glb(vec![node]));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("KHR_materials_specular")), "{:?}", scene.notes);
    assert_eq!(scene.materials[0], Material::Diffuse { albedo: Vec3::splat(0.5), specular: Vec3::ZERO });
}

/// `KHR_materials_specular`'s colour tints F0 (no longer noted as
/// ignored), comes back from the exporter, and its textures are noted as
/// not read.
#[test]
fn the_specular_colour_is_read() {
    let mut b = GltfBuilder::new();
    let tint = Vec3::new(1.0, 2.5, 0.5);
    let image = b.image(&super::export::png(1, 1, &[255; 4]), "image/png");
    let texture = b.texture(image, json::texture::WrappingMode::Repeat, json::texture::WrappingMode::Repeat);
    let m = b.material(&PbrMaterial { base_color: Vec3::splat(0.5), specular_color: tint, ..Default::default() });
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let (mut root, bin) = b.finish(vec![node]);
    let dir = folder("specular-colour");
    write(&dir, "s.glb", &glb(&root, bin.clone()));
    let scene = crate::scene::Scene::from_toml(&placing("gltf = \"s.glb\""), "t.toml", Some(&dir)).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("specular")), "{:?}", scene.notes);
    let Material::Pbr(bsdf) = scene.materials[0] else { panic!("{:?}", scene.materials[0]) };
    assert_eq!(bsdf.specular_color, tint);
    assert!((bsdf.dielectric_f0 - Vec3::new(0.04, 0.1, 0.02)).abs().max_element() < 1e-7);
    let again = super::export::scene_to_glb(&scene).unwrap();
    let reloaded = crate::scene::Scene::load(write(&dir, "again.glb", &again).to_str().unwrap()).unwrap();
    assert!(matches!(reloaded.materials[0], Material::Pbr(b) if b.specular_color == tint));
    // A specular texture is read (white: the factors alone), by every
    // renderer: no note.
    let ext = root.materials[0].extensions.as_mut().unwrap();
    ext.specular.as_mut().unwrap().specular_texture =
        Some(json::texture::Info { index: texture, tex_coord: 0, extensions: None, extras: Default::default() });
    let scene = crate::scene::Scene::load(write(&dir, "t.glb", &glb(&root, bin)).to_str().unwrap()).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("specular")), "{:?}", scene.notes);
    let textures = scene.texturing.as_ref().unwrap().materials[0].unwrap();
    assert!(textures.layers.specular.is_some() && textures.layers.specular_color.is_none());
}

/// `KHR_materials_transmission` is glass of the material's roughness,
/// tinted by its base colour, with `KHR_materials_ior`: no longer noted
/// as approximated (Blender writes rough and coloured glass this way).
#[test]
fn transmission_is_rough_tinted_glass() {
    let mut b = GltfBuilder::new();
    let tint = Vec3::new(0.9, 0.6, 0.3);
    let m = b.material(&PbrMaterial { base_color: tint, roughness: 0.4, glass_ior: Some(1.33), ..Default::default() });
    let mesh = b.mesh(&TRIANGLE, None, None, Some(m));
    let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let dir = folder("transmission");
    let path = write(&dir, "t.glb", &b.to_glb(vec![node]));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(!scene.notes.iter().any(|n| n.contains("approximated")), "{:?}", scene.notes);
    let want = crate::bsdf::dielectric::Dielectric { ior: 1.33, roughness: 0.4, tint, absorption: Rgb::ZERO };
    assert_eq!(scene.materials[0], Material::Glass(want));
}

/// Light through a slab of thickness 1 whose inside keeps c per unit, at
/// normal incidence, Fresnel F at each face and every inner reflection
/// summed: T = (1 − F)² c / (1 − F²c²) through, R = F + (1 − F)² F c² /
/// (1 − F²c²) back.
fn slab_transmission_and_reflection(c: Vec3) -> (Vec3, Vec3) {
    let f = 0.04; // ((1.5 − 1) / (1.5 + 1))²
    let bounce = Vec3::ONE - f * f * c * c;
    ((1.0 - f) * (1.0 - f) * c / bounce, f + (1.0 - f) * (1.0 - f) * f * c * c / bounce)
}

/// `KHR_materials_volume`: glass whose inside absorbs (Beer–Lambert). The
/// file's attenuation colour and distance become σ = −ln(c)/d; under the
/// white sky a ray straight down through the slab sees T + R of the hand
/// computation in path, photon-cpu (whose smooth glass branches exactly)
/// and vcm; from a sun straight down, the photons on the floor under the
/// slab carry T of the power of those beside it (within 3%: the floor's
/// light the slab's underside sends back down adds under 1%).
#[test]
fn an_absorbing_glass_slab_keeps_beer_lamberts_share() {
    use crate::photon::{TraceSettings, trace_photons};
    use crate::progress::Silent;
    use crate::render::path::{PathSettings, radiance};
    use crate::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
    use crate::test_scenes::gltf_textures::{absorbing_slab_glb, load};
    let c = Vec3::new(0.5, 0.8, 1.0);
    let scene = load("volume-slab", &absorbing_slab_glb(c, false));
    assert!(!scene.notes.iter().any(|n| n.contains("KHR_materials_volume")), "{:?}", scene.notes);
    let Material::Glass(glass) = scene.materials[0] else { panic!("{:?}", scene.materials[0]) };
    assert!((glass.absorption - (-c.ln())).abs().max_element() < 1e-5, "{}", glass.absorption);
    let (t, r) = slab_transmission_and_reflection(c);
    let want = t + r;
    let down = |x: f32, z: f32| crate::geometry::Ray::new(Vec3::new(x, 3.0, z), -Vec3::Y);
    let mut rng = crate::sampling::Rng::for_item(5, 0);
    let n = 20_000;
    let settings = PathSettings { spp: 1, ..Default::default() };
    let path =
        (0..n).map(|i| radiance(&scene, down(0.3 * (i % 7) as f32 / 7.0, 0.1), &settings, &mut rng)).sum::<Vec3>()
            / n as f32;
    let traced = trace_photons(&scene, &TraceSettings { photons: 1_000, ..Default::default() }, &Silent);
    let photon =
        PhotonCpuRenderer::new(&scene, &traced, &PhotonCpuSettings::default()).radiance(&down(0.2, 0.1), 0, &mut rng);
    let mut above = scene.clone();
    above.camera = crate::camera::Camera::new(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::Z, 20.0, 16, 16).unwrap();
    let vcm = (1..=8)
        .map(|pass| {
            let image = crate::render::vcm::render_pass(&above, &Default::default(), pass).unwrap().0;
            image.pixels.iter().sum::<Vec3>() / image.pixels.len() as f32
        })
        .sum::<Vec3>()
        / 8.0;
    eprintln!("through an absorbing slab: hand {want}, path {path}, photon-cpu {photon}, vcm {vcm}");
    for (name, l, tolerance) in [("path", path, 0.01), ("photon-cpu", photon, 2e-3), ("vcm", vcm, 0.02)] {
        assert!(((l - want) / want).abs().max_element() < tolerance, "{name}: {l} against {want}");
    }
    // Photons from a sun through the slab onto a floor.
    let scene = load("volume-slab-floor", &absorbing_slab_glb(c, true));
    let traced = trace_photons(&scene, &TraceSettings { photons: 200_000, ..Default::default() }, &Silent);
    let power_in = |inner: f32, outer: f32| {
        // The global map holds every photon stored (the caustic map
        // repeats the caustic ones).
        let on_floor = traced.global.iter().filter(|p| p.position[1].abs() < 1e-3);
        let r = |p: &&crate::photon::Photon| p.position[0].abs().max(p.position[2].abs());
        let inside = on_floor.filter(|p| (inner..outer).contains(&r(p)));
        inside.map(|p| p.power_in_units()).sum::<Vec3>() / (4.0 * (outer * outer - inner * inner))
    };
    let ratio = power_in(0.0, 0.75) / power_in(1.5, 3.0);
    eprintln!("photon power under the slab over beside it: {ratio} (T = {t})");
    assert!(((ratio - t) / t).abs().max_element() < 0.03, "{ratio} against {t}");
}

/// A file Blender wrote reads its attenuation as Blender's Volume
/// Absorption node, which it was written from: σ = (1 − c) / d, as Cycles
/// draws it (with a note); any other file as the extension says, −ln(c) / d.
#[test]
fn blenders_volume_absorption_reads_as_cycles_draws_it() {
    let c = Vec3::new(0.9, 0.5, 0.2);
    let absorption_of = |generator: &str, tag: &str| {
        let mut b = GltfBuilder::new();
        let glass = b.material(&PbrMaterial { glass_ior: Some(1.5), glass_absorption: -c.ln(), ..Default::default() });
        let mesh = b.mesh(&TRIANGLE, None, None, Some(glass));
        let node = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
        let (mut root, bin) = b.finish(vec![node]);
        root.asset.generator = Some(generator.into());
        let path = write(&folder(tag), "t.glb", &glb(&root, bin));
        let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
        let Material::Glass(glass) = scene.materials[0] else { panic!("{:?}", scene.materials[0]) };
        (glass.absorption, scene.notes)
    };
    let (blender, notes) = absorption_of("Khronos glTF Blender I/O v5.3.43", "volume-blender");
    assert!((blender - (Vec3::ONE - c)).abs().max_element() < 1e-5, "{blender}");
    assert!(notes.iter().any(|n| n.contains("Blender's Volume Absorption")), "{notes:?}");
    let (other, notes) = absorption_of("three.js", "volume-three");
    assert!((other - (-c.ln())).abs().max_element() < 1e-5, "{other}");
    assert!(!notes.iter().any(|n| n.contains("KHR_materials_volume")), "{notes:?}");
}

/// A glTF animation moves what it animates: a parent's rotation carries a
/// child mesh and a light, `--at` poses them (`Scene::at_time`), and the
/// loop restarts after the last key.
#[test]
fn node_animations_move_meshes_and_lights() {
    use json::animation::{Interpolation, Property};
    use json::extensions::scene::khr_lights_punctual::Type;
    let mut b = GltfBuilder::new();
    let mesh = one_triangle(&mut b);
    let child = b.node(json::Node { mesh: Some(mesh), translation: Some([2.0, 0.0, 0.0]), ..Default::default() });
    let light = b.light(Type::Point, Vec3::ONE, 683.0, None);
    let lamp = b.node(GltfBuilder::light_node(light, Vec3::new(0.0, 0.0, 3.0), glam::Quat::IDENTITY));
    let pivot = b.node(json::Node { children: Some(vec![child, lamp]), ..Default::default() });
    let quarter = glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let rotations: Vec<f32> = [glam::Quat::IDENTITY, quarter].iter().flat_map(|q| q.to_array()).collect();
    b.animate(pivot, Property::Rotation, Interpolation::Linear, &[0.0, 2.0], &rotations);
    // A second node moves by steps: 0, then 5 up from 1 s, then 10 from 2 s (a 2 s loop).
    let stepper = b.node(json::Node { mesh: Some(mesh), ..Default::default() });
    let ups = [0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 10.0, 0.0];
    b.animate(stepper, Property::Translation, Interpolation::Step, &[0.0, 1.0, 2.0], &ups);
    let dir = folder("animated");
    let path = write(&dir, "a.glb", &b.to_glb(vec![pivot, stepper]));
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(scene.is_animated());
    assert_eq!(scene.animations.len(), 3, "the child mesh, the lamp and the stepper");
    let at = |t: f32| scene.at_time(t);
    // The child's vertex (2, 0, 0) + (0, 0, 0) turns with the pivot: at 1.99 s almost a quarter turn.
    let first_vertex = |s: &crate::scene::Scene, surface: u32| {
        s.accel.triangles().find(|(_, id)| *id == surface).map(|(t, _)| t.v[0]).unwrap()
    };
    assert!((first_vertex(&at(0.0), 0) - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5);
    let turned = first_vertex(&at(1.0), 0);
    let s = 2.0 * std::f32::consts::FRAC_1_SQRT_2;
    assert!((turned - Vec3::new(s, 0.0, -s)).length() < 1e-4, "{turned}");
    // The lamp at (0, 0, 3) turns to (3 sin 45°, 0, 3 cos 45°).
    let lamp_at = at(1.0).lights[0].delta_position().unwrap();
    assert!((lamp_at - Vec3::new(3.0, 0.0, 3.0) * std::f32::consts::FRAC_1_SQRT_2).length() < 1e-4, "{lamp_at}");
    // Step interpolation holds each key (linear would give 2.5 and 7.5).
    assert_eq!(first_vertex(&at(0.5), 1), Vec3::ZERO);
    assert_eq!(first_vertex(&at(1.5), 1), Vec3::new(0.0, 5.0, 0.0));
    // The loop is 2 s long (its last key): 2.5 s is 0.5 s again.
    assert_eq!(first_vertex(&at(2.5), 1), Vec3::ZERO);
}

/// A `.gltf` whose buffer and image are files of their own loads from its
/// folder and from the same files given by name (a web page's drop), the
/// image's %-escaped URI decoded; a missing one is named.
#[test]
fn a_gltf_reads_its_buffer_and_image_from_its_folder_or_given_files() {
    use crate::scene::files::{GivenFile, SceneFiles};
    let files = crate::test_scenes::gltf_textures::checker_gltf_files();
    let dir = folder("external");
    for (name, bytes) in &files {
        write(&dir, name, bytes);
    }
    let from_folder = crate::scene::Scene::load(dir.join("checker.gltf").to_str().unwrap()).unwrap();
    let given: Vec<GivenFile> =
        files.iter().map(|(name, bytes)| GivenFile { name: name.clone(), bytes: bytes.clone() }).collect();
    let options = LoadOptions::default();
    let silent = &crate::progress::Silent;
    let from_given =
        scene_from_bytes(&files[0].1, "checker.gltf", SceneFiles::Given(&given), &options, silent).unwrap();
    for scene in [&from_folder, &from_given] {
        assert_eq!(scene.accel.triangles().count(), 4);
        let texturing = scene.texturing.as_ref().expect("the checker texture loaded");
        assert_eq!(texturing.images.len(), 1);
    }
    let without_image = &given[..2];
    let e = scene_from_bytes(&files[0].1, "checker.gltf", SceneFiles::Given(without_image), &options, silent)
        .err()
        .unwrap()
        .to_string();
    assert_says(&e, &["checker.gltf", "images[0]", "\"checker texture.png\"", "not among the files given"]);
    let e =
        scene_from_bytes(&files[0].1, "checker.gltf", SceneFiles::None, &options, silent).err().unwrap().to_string();
    assert_says(&e, &["checker.gltf", "buffers[0]", "not read from a folder"]);
}

/// Valid files the glTF-Validator's own tests hold, written here as a
/// `.gltf` by hand: an accessor without a buffer view (its elements zeros),
/// a sparse `POSITION` on top of one (two vertices replaced: the triangle
/// (0,0,0), (1,0,0), (0,1,0)), and an animation channel that names no node
/// (`KHR_animation_pointer`), left out with a note while its neighbour, on
/// node 0, still moves the triangle up 2 over 1 s.
#[test]
fn validator_edge_cases_load() {
    let mut bin: Vec<u8> = Vec::new();
    bin.extend([1u16, 2].iter().flat_map(|i| i.to_le_bytes())); // 0: sparse indices
    bin.extend([1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|v| v.to_le_bytes())); // 4: sparse values
    bin.extend([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes())); // 28: indices
    bin.extend([0.0f32, 1.0].iter().flat_map(|v| v.to_le_bytes())); // 40: key times
    bin.extend([0.0f32, 0.0, 0.0, 0.0, 0.0, 2.0].iter().flat_map(|v| v.to_le_bytes())); // 48: translations
    let json = r#"{
      "asset": {"version": "2.0"},
      "extensionsUsed": ["KHR_animation_pointer"],
      "buffers": [{"uri": "e.bin", "byteLength": 72}],
      "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 4},
        {"buffer": 0, "byteOffset": 4, "byteLength": 24},
        {"buffer": 0, "byteOffset": 28, "byteLength": 12},
        {"buffer": 0, "byteOffset": 40, "byteLength": 8},
        {"buffer": 0, "byteOffset": 48, "byteLength": 24}
      ],
      "accessors": [
        {"count": 3, "type": "VEC3", "componentType": 5126, "min": [0, 0, 0], "max": [1, 1, 0],
         "sparse": {"count": 2, "indices": {"bufferView": 0, "componentType": 5123}, "values": {"bufferView": 1}}},
        {"bufferView": 2, "count": 3, "type": "SCALAR", "componentType": 5125},
        {"bufferView": 3, "count": 2, "type": "SCALAR", "componentType": 5126, "min": [0], "max": [1]},
        {"bufferView": 4, "count": 2, "type": "VEC3", "componentType": 5126},
        {"count": 4, "type": "VEC3", "componentType": 5126}
      ],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "nodes": [{"mesh": 0}],
      "animations": [{
        "samplers": [{"input": 2, "output": 3}],
        "channels": [
          {"sampler": 0, "target": {"node": 0, "path": "translation"}},
          {"sampler": 0, "target": {"path": "translation",
            "extensions": {"KHR_animation_pointer": {"pointer": "/nodes/0/translation"}}}}
        ]
      }],
      "scenes": [{"nodes": [0]}],
      "scene": 0
    }"#;
    let dir = folder("validator-edge-cases");
    write(&dir, "e.bin", &bin);
    let path = write(&dir, "e.gltf", json.as_bytes());
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    let notes: Vec<&String> = scene.notes.iter().filter(|n| n.contains("animation channel")).collect();
    assert_eq!(notes.len(), 1, "{:?}", scene.notes);
    assert_says(notes[0], &["1 animation channel", "no node", "ignored"]);
    let vertices = |s: &crate::scene::Scene| s.accel.triangles().next().map(|(t, _)| t.v).unwrap();
    assert_eq!(vertices(&scene.at_time(0.0)), [Vec3::ZERO, Vec3::X, Vec3::Y]);
    let up = vertices(&scene.at_time(0.5));
    assert!((up[1] - Vec3::new(1.0, 0.0, 1.0)).length() < 1e-5, "{up:?}");
}

/// An accessor without a buffer view is read as zeros, which are
/// allocated: a count past 2^24 is a located error, not an allocation of
/// gigabytes (the CI fuzzer's seed 256 asked for 64 GiB through an
/// animation's key times and aborted).
#[test]
fn a_huge_accessor_without_a_buffer_view_is_a_located_error() {
    let json = r#"{
      "asset": {"version": "2.0"},
      "accessors": [{"count": 1073741824, "type": "VEC3", "componentType": 5126, "min": [0, 0, 0], "max": [0, 0, 0]}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "nodes": [{"mesh": 0}],
      "scenes": [{"nodes": [0]}]
    }"#;
    let dir = folder("huge-zeros");
    let path = write(&dir, "z.gltf", json.as_bytes());
    let e = crate::scene::Scene::load(path.to_str().unwrap()).err().expect("refused");
    assert_says(&e.to_string(), &["z.gltf", "POSITION", "no buffer view", "1073741824"]);
}

/// A sparse accessor's index beyond its elements, and indices that do not
/// increase, are located errors.
#[test]
fn bad_sparse_indices_are_located_errors() {
    for (indices, expected) in [([1u16, 3], "sparse index 3"), ([2u16, 1], "do not increase")] {
        let mut bin: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        bin.extend([1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|v| v.to_le_bytes()));
        let json = r#"{
          "asset": {"version": "2.0"},
          "buffers": [{"uri": "s.bin", "byteLength": 28}],
          "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 4}, {"buffer": 0, "byteOffset": 4, "byteLength": 24}],
          "accessors": [{"count": 3, "type": "VEC3", "componentType": 5126, "min": [0, 0, 0], "max": [1, 1, 0],
            "sparse": {"count": 2, "indices": {"bufferView": 0, "componentType": 5123}, "values": {"bufferView": 1}}}],
          "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
          "nodes": [{"mesh": 0}],
          "scenes": [{"nodes": [0]}]
        }"#;
        let dir = folder(&format!("sparse-{}", indices[1]));
        write(&dir, "s.bin", &bin);
        let path = write(&dir, "s.gltf", json.as_bytes());
        let e = crate::scene::Scene::load(path.to_str().unwrap()).err().expect("refused");
        assert_says(&e.to_string(), &["s.gltf", "POSITION", expected]);
    }
}

/// A skin bends a triangle and a morph target reshapes one, computed by
/// hand: joint A stays, joint B turns 90° about z around (0, 0, 2) (its
/// node at (0, 0, 2) turned, its inverse bind matrix back by 2); vertex 1
/// follows B alone, vertex 2 half A and half B; the skinned mesh's own
/// node (moved by 10 in x) does not place it. The morphed triangle's
/// vertex 1 rises by its target's delta (0, 0, 1) × the node's weight ½
/// (which replaces the mesh's 1), and its node moves it by 5 in y.
/// A skinned triangle (joints A at the origin and B at z = 2 turned a
/// quarter about z, bound with B's inverse bind shifted by −2 in z; one
/// vertex on each, one half on each) and a morphed one; with `animated`,
/// an animation moves B from z = 2 to z = 3 over a second and keys the
/// morph weight from 0 to 1.
fn deformation_file(animated: bool) -> (String, Vec<u8>) {
    let floats = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]); // 0: positions
    bin.extend([0u8, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]); // 36: joints
    bin.extend(floats(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0])); // 48: weights
    let mut shifted = Mat4::IDENTITY.to_cols_array();
    shifted[14] = -2.0;
    bin.extend(floats(&Mat4::IDENTITY.to_cols_array())); // 96: inverse bind matrices
    bin.extend(floats(&shifted));
    bin.extend(floats(&[0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])); // 224: morph deltas
    bin.extend(floats(&[0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 3.0])); // 260: key times, B's translations
    bin.extend(floats(&[0.0, 1.0])); // 292: the morph weight at each key
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let animation = if animated {
        r#"
      "animations": [{"samplers": [{"input": 5, "output": 6}, {"input": 5, "output": 7}], "channels": [
        {"sampler": 0, "target": {"node": 2, "path": "translation"}},
        {"sampler": 1, "target": {"node": 3, "path": "weights"}}]}],"#
    } else {
        ""
    };
    let json = format!(
        r#"{{
      "asset": {{"version": "2.0"}},
      "buffers": [{{"uri": "d.bin", "byteLength": 300}}],
      "bufferViews": [
        {{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
        {{"buffer": 0, "byteOffset": 36, "byteLength": 12}},
        {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
        {{"buffer": 0, "byteOffset": 96, "byteLength": 128}},
        {{"buffer": 0, "byteOffset": 224, "byteLength": 36}},
        {{"buffer": 0, "byteOffset": 260, "byteLength": 8}},
        {{"buffer": 0, "byteOffset": 268, "byteLength": 24}},
        {{"buffer": 0, "byteOffset": 292, "byteLength": 8}}
      ],
      "accessors": [
        {{"bufferView": 0, "count": 3, "type": "VEC3", "componentType": 5126, "min": [0, 0, 0], "max": [1, 1, 0]}},
        {{"bufferView": 1, "count": 3, "type": "VEC4", "componentType": 5121}},
        {{"bufferView": 2, "count": 3, "type": "VEC4", "componentType": 5126}},
        {{"bufferView": 3, "count": 2, "type": "MAT4", "componentType": 5126}},
        {{"bufferView": 4, "count": 3, "type": "VEC3", "componentType": 5126, "min": [0, 0, 0], "max": [0, 0, 1]}},
        {{"bufferView": 5, "count": 2, "type": "SCALAR", "componentType": 5126, "min": [0], "max": [1]}},
        {{"bufferView": 6, "count": 2, "type": "VEC3", "componentType": 5126}},
        {{"bufferView": 7, "count": 2, "type": "SCALAR", "componentType": 5126}}
      ],{animation}
      "meshes": [
        {{"primitives": [{{"attributes": {{"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}}}]}},
        {{"primitives": [{{"attributes": {{"POSITION": 0}}, "targets": [{{"POSITION": 4}}]}}], "weights": [1.0]}}
      ],
      "skins": [{{"joints": [1, 2], "inverseBindMatrices": 3}}],
      "nodes": [
        {{"mesh": 0, "skin": 0, "translation": [10, 0, 0]}},
        {{"name": "A"}},
        {{"name": "B", "translation": [0, 0, 2], "rotation": [0, 0, {s}, {s}]}},
        {{"mesh": 1, "weights": [0.5], "translation": [0, 5, 0]}}
      ],
      "scenes": [{{"nodes": [0, 1, 2, 3]}}]
    }}"#
    );
    (json, bin)
}

#[test]
fn skins_and_morph_targets_deform_meshes() {
    let (json, bin) = deformation_file(false);
    let dir = folder("deformations");
    write(&dir, "d.bin", &bin);
    let path = write(&dir, "d.gltf", json.as_bytes());
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    let triangle = |surface: u32| scene.accel.triangles().find(|(_, id)| *id == surface).map(|(t, _)| t.v).unwrap();
    let close = |got: [Vec3; 3], want: [Vec3; 3]| got.iter().zip(want).all(|(g, w)| (*g - w).length() < 1e-5);
    let skinned = triangle(0);
    let want = [Vec3::ZERO, Vec3::Y, Vec3::new(-0.5, 0.5, 0.0)];
    assert!(close(skinned, want), "skinned {skinned:?}, by hand {want:?}");
    let morphed = triangle(1);
    let want = [Vec3::new(0.0, 5.0, 0.0), Vec3::new(1.0, 5.0, 0.5), Vec3::new(0.0, 6.0, 0.0)];
    assert!(close(morphed, want), "morphed {morphed:?}, by hand {want:?}");
    assert!(scene.notes.iter().all(|n| !n.contains("skinned") && !n.contains("morph")), "{:?}", scene.notes);
}

/// The same skin with an animation moving joint B up by 1 over a second
/// (and keying the morphed mesh's weight from 0 to 1):
/// loaded, the triangle is as the node transforms place it; at t the vertex
/// on B has risen by t, the one half on B by t/2, the one on A not at all
/// (by hand, as above: B's world is then a translation by t in z after its
/// rest one).
#[test]
fn an_animated_skin_bends_over_time() {
    let (json, bin) = deformation_file(true);
    let dir = folder("animated-skin");
    write(&dir, "d.bin", &bin);
    let path = write(&dir, "d.gltf", json.as_bytes());
    let scene = crate::scene::Scene::load(path.to_str().unwrap()).unwrap();
    assert!(scene.is_animated());
    assert!(scene.notes.iter().all(|n| !n.contains("bend")), "{:?}", scene.notes);
    let triangle = |scene: &crate::scene::Scene| scene.accel.triangles().find(|(_, id)| *id == 0).unwrap().0.v;
    let close = |got: [Vec3; 3], want: [Vec3; 3]| got.iter().zip(want).all(|(g, w)| (*g - w).length() < 1e-5);
    let rest = [Vec3::ZERO, Vec3::Y, Vec3::new(-0.5, 0.5, 0.0)];
    assert!(close(triangle(&scene), rest));
    // (The animation loops over its one second: t = 1 is t = 0 again.)
    for (time, rise) in [(0.0, 0.0), (0.5, 0.5), (0.75, 0.75), (1.0, 0.0)] {
        let want = [rest[0], rest[1] + Vec3::Z * rise, rest[2] + Vec3::Z * rise / 2.0];
        let got = triangle(&scene.at_time(time));
        assert!(close(got, want), "t = {time}: {got:?}, by hand {want:?}");
    }
    // The morphed mesh's keyed weight w(t) = t lifts its second vertex
    // (delta (0, 0, 1)) to z = t; loaded, the node's weight ½ holds.
    let morphed = |scene: &crate::scene::Scene| scene.accel.triangles().find(|(_, id)| *id == 1).unwrap().0.v;
    assert!((morphed(&scene)[1] - Vec3::new(1.0, 5.0, 0.5)).length() < 1e-5);
    for time in [0.0, 0.25, 0.75] {
        let got = morphed(&scene.at_time(time))[1];
        assert!((got - Vec3::new(1.0, 5.0, time)).length() < 1e-5, "t = {time}: {got}");
    }
}

/// A glTF file placed by a TOML `[[object]]` plays its animations as when
/// loaded alone (here its skin's joint rising, moved 10 along x with the
/// object), and its notes reach the scene, each naming the file.
#[test]
fn a_placed_gltf_object_plays_its_animations_and_keeps_its_notes() {
    let (json, bin) = deformation_file(true);
    let dir = folder("placed-animated");
    write(&dir, "d.bin", &bin);
    write(&dir, "d.gltf", json.as_bytes());
    let toml = placing("gltf = \"d.gltf\"\ntranslate = [10.0, 0.0, 0.0]");
    let scene = crate::scene::Scene::from_toml(&toml, "t.toml", Some(&dir)).unwrap();
    assert!(scene.is_animated());
    let triangle = |scene: &crate::scene::Scene| scene.accel.triangles().find(|(_, id)| *id == 0).unwrap().0.v;
    let shift = Vec3::new(10.0, 0.0, 0.0);
    let rest = [Vec3::ZERO, Vec3::Y, Vec3::new(-0.5, 0.5, 0.0)].map(|v| v + shift);
    let close = |got: [Vec3; 3], want: [Vec3; 3]| got.iter().zip(want).all(|(g, w)| (*g - w).length() < 1e-5);
    assert!(close(triangle(&scene), rest), "{:?}", triangle(&scene));
    let want = [rest[0], rest[1] + Vec3::Z * 0.5, rest[2] + Vec3::Z * 0.25];
    assert!(close(triangle(&scene.at_time(0.5)), want), "{:?}", triangle(&scene.at_time(0.5)));

    // A note of the file (an extension it uses and hikari ignores) names it.
    let json = json.replacen("\"asset\"", "\"extensionsUsed\": [\"KHR_materials_iridescence\"],\n      \"asset\"", 1);
    write(&dir, "d.gltf", json.as_bytes());
    let scene = crate::scene::Scene::from_toml(&toml, "t.toml", Some(&dir)).unwrap();
    assert!(
        scene.notes.iter().any(|n| n.starts_with("d.gltf: ") && n.contains("KHR_materials_iridescence")),
        "{:?}",
        scene.notes
    );
}
