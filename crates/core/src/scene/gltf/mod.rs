//! The glTF 2.0 front end: a `.gltf` (with its buffers) or `.glb` file
//! turned into the parts a [`Scene`](super::Scene) is made of: world-space
//! triangles per node and primitive, materials, lights and a camera.
//! What is read, approximated and refused is listed in
//! docs/scene-format.md ("glTF files").
//!
//! Every problem is a [`SceneError`] naming the file and the glTF path of
//! the culprit (`meshes[3].primitives[0].attributes.POSITION`).

mod accessors;
mod animations;
mod compressed;
mod deform;
pub mod export;
mod materials;
mod tangents;
mod textures;

use super::SceneError;
use super::files::SceneFiles;
use super::limits::MAX_COORD;
use crate::geometry::{Triangle, TriangleNormals};
use crate::light::Light;
use crate::material::{Material, Rgb};
use crate::progress::Progress;
use crate::texture::{Image, MaterialTextures};
use glam::{Affine3A, Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::DataType;
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

pub use materials::Emission;

/// glTF's photometric units to radiometric ones: 683 lm/W, the luminous
/// efficacy at 555 nm that defines the candela (docs/scene-format.md).
pub const LUMENS_PER_WATT: f32 = 683.0;

/// Extensions whose meaning hikari reads; a file that requires any other is
/// refused, one that merely uses another is loaded with a note.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_specular",
    "KHR_materials_volume",
    materials::CLEARCOAT,
    materials::SHEEN,
    "KHR_texture_transform",
    "KHR_mesh_quantization",
    compressed::MESHOPT,
    compressed::DRACO,
    "EXT_texture_webp",
];

/// A glTF file in world space.
pub struct Asset {
    /// One per glTF material, then the specification's default material
    /// (for primitives without one) last.
    pub materials: Vec<Material>,
    /// Parallel to `materials`: each one's name in the file.
    pub material_names: Vec<Option<String>>,
    /// Parallel to `materials`: what each takes from textures.
    pub material_textures: Vec<Option<MaterialTextures>>,
    /// The decoded images `material_textures` refer to.
    pub images: Vec<Image>,
    pub primitives: Vec<Primitive>,
    /// Each light with its node's name.
    pub lights: Vec<(Option<String>, Light)>,
    /// The chosen camera, if the file has one.
    pub camera: Option<CameraPose>,
    /// One-line notes on what was ignored or approximated.
    pub notes: Vec<String>,
    /// Parallel to `lights`: the node path (root first) of each.
    pub light_paths: Vec<Vec<usize>>,
    /// The file's first animation, by node.
    pub channels: animations::NodeChannels,
    /// Where the file was placed (identity for a file loaded on its own).
    pub world_from_file: Affine3A,
}

impl Asset {
    /// The keyframed motion of what sits at the end of `path`, if it moves.
    pub fn motion(&self, path: &[usize]) -> Option<crate::scene::Motion> {
        let keys = self.channels.keyframes(self.world_from_file, path)?;
        Some(crate::scene::Motion::Keyframed(std::sync::Arc::new(keys)))
    }
}

/// The triangles of one primitive under one node (a mesh under several
/// nodes gives one `Primitive` per node: instancing).
pub struct Primitive {
    /// The node's name (for the viewer and animations), if it has one.
    pub name: Option<String>,
    pub triangles: Vec<Triangle>,
    /// Texture coordinates of each triangle's vertices, when its material
    /// reads textures and the primitive has `TEXCOORD_0`.
    pub uvs: Option<Vec<[Vec2; 3]>>,
    /// Tangents of each triangle's vertices, when its material has a
    /// normal texture (and the primitive coordinates).
    pub tangents: Option<Vec<[crate::texture::PackedTangent; 3]>>,
    /// Index into [`Asset::materials`].
    pub material: u32,
    /// Light the surface emits, from its material.
    pub emission: Option<Emission>,
    /// The node indices from the scene's root down to the primitive's node.
    pub node_path: Vec<usize>,
    /// A mesh whose skin's joints or morph weights the file's animations
    /// move: how to reshape it at any time (its triangles are `triangles`,
    /// in this order).
    pub deformed: Option<std::sync::Arc<crate::scene::deformation::DeformedMesh>>,
}

impl Primitive {
    /// The light an emissive primitive is (its triangles emitting its
    /// material's radiance); None for others and for ones without area.
    pub fn emitted_light(&self) -> Option<Light> {
        let e = self.emission?;
        let mesh =
            crate::light::EmissiveMesh::new(self.triangles.iter().map(|t| t.v).collect(), e.radiance, e.two_sided)?;
        Some(Light::Mesh(std::sync::Arc::new(mesh)))
    }
}

/// A perspective camera placed by its node.
#[derive(Clone, Copy, Debug)]
pub struct CameraPose {
    pub position: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub fov_y: f32,
    /// Width / height, when the file gives it.
    pub aspect: Option<f32>,
}

/// Is `path` a glTF file (by its extension)?
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

fn error(file: &str, context: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError { file: file.to_string(), position: None, context: context.into(), message: message.into() }
}

/// Reads `path` and places its default scene by `world_from_file`.
/// `camera` picks a camera by name (else the first perspective one).
/// Reading the meshes is reported to `progress` (a stage of one step per
/// placed primitive).
pub fn load_asset(
    path: &Path,
    world_from_file: Affine3A,
    camera: Option<&str>,
    progress: &dyn Progress,
) -> Result<Asset, SceneError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| error(&file, "", format!("cannot read glTF file: {e}")))?;
    asset_from_bytes(&bytes, &file, SceneFiles::beside(path.parent()), world_from_file, camera, progress)
}

/// [`load_asset`] of a file's bytes, named `file` in errors; buffers and
/// images given by relative URI are read from `files`.
pub fn asset_from_bytes(
    bytes: &[u8],
    file: &str,
    files: SceneFiles,
    world_from_file: Affine3A,
    camera: Option<&str>,
    progress: &dyn Progress,
) -> Result<Asset, SceneError> {
    let file = file.to_string();
    if file.to_ascii_lowercase().ends_with(".glb") && !bytes.starts_with(b"glTF") {
        return Err(error(&file, "", "not a binary glTF file: it does not start with the `glTF` magic bytes"));
    }
    let (gltf, skipped_channels) = parse(bytes, &file)?;
    let mut buffers = load_buffers(&gltf, files, &file)?;
    let mut notes = Vec::new();
    if skipped_channels > 0 {
        notes.push(format!(
            "{skipped_channels} animation channel(s) target no node (an extension such as KHR_animation_pointer \
             names what they animate, which hikari does not read): ignored"
        ));
    }
    check_extensions(&gltf.document, &file, &mut notes)?;
    let gltf = compressed::decode(gltf, &mut buffers, &file)?;
    let images = textures::load(&gltf.document, &buffers, files, &file)?;
    let materials::Converted { materials, emissions, textures, names: material_names } =
        materials::convert(&gltf.document, &images, &mut notes);
    let textured: Vec<bool> = textures.iter().map(|t| t.is_some_and(|t| t.is_textured())).collect();
    let normal_mapped: Vec<bool> =
        textures.iter().map(|t| t.is_some_and(|t| t.normal.is_some() || t.coat_apart())).collect();
    let mut walk = Walk {
        file: &file,
        buffers: &buffers,
        emissions: &emissions,
        textured: &textured,
        normal_mapped: &normal_mapped,
        camera_name: camera,
        cache: HashMap::new(),
        asset: Asset {
            materials,
            material_names,
            material_textures: textures,
            images: images.images,
            primitives: Vec::new(),
            lights: Vec::new(),
            camera: None,
            notes,
            light_paths: Vec::new(),
            channels: animations::NodeChannels::default(),
            world_from_file,
        },
        visited: vec![false; gltf.document.nodes().len()],
        ignored_range: false,
        quantized: gltf.document.extensions_used().any(|e| e == "KHR_mesh_quantization"),
        without_uvs: 0,
        node_worlds: Vec::new(),
        node_paths: Vec::new(),
        skinned_lights: 0,
        unweighted: 0,
        skinned_normal_mapped: 0,
        progress,
    };
    let scene = gltf
        .document
        .default_scene()
        .or_else(|| gltf.document.scenes().next())
        .ok_or_else(|| error(&file, "scenes", "the file has no scene to render"))?;
    let world = Mat4::from(world_from_file);
    walk.node_worlds = deform::node_worlds(&gltf.document, &scene, world);
    walk.node_paths = deform::node_paths(&gltf.document, &scene);
    // Read before the meshes: a skin's joints may move with them.
    walk.asset.channels = animations::read(&gltf.document, &buffers, &file, &mut walk.asset.notes)?;
    progress.begin("reading meshes", placed_primitives(&scene));
    let walked = scene.nodes().try_for_each(|node| walk.node(&node, world, &mut Vec::new()));
    progress.end();
    walked?;
    if let Some(name) = camera
        && walk.asset.camera.is_none()
    {
        let names: Vec<&str> = gltf
            .document
            .nodes()
            .filter(|n| n.camera().is_some())
            .flat_map(|n| [n.name(), n.camera().and_then(|c| c.name())])
            .flatten()
            .collect();
        return Err(error(
            &file,
            "cameras",
            format!("no perspective camera named \"{name}\" is placed in the scene (cameras: {})", names.join(", ")),
        ));
    }
    if walk.ignored_range {
        walk.asset.notes.push("light `range` is ignored: lights fall off physically, as 1/d²".into());
    }
    if walk.without_uvs > 0 {
        walk.asset.notes.push(format!(
            "{} primitive(s) with textured materials have no TEXCOORD_0: their factors are used",
            walk.without_uvs
        ));
    }
    if walk.skinned_normal_mapped > 0 {
        walk.asset.notes.push(format!(
            "{} skinned primitive(s) have normal textures: they are read in each triangle's own tangent frame \
             (from its texture coordinates; the skin does not bend TANGENT or MikkTSpace tangents)",
            walk.skinned_normal_mapped
        ));
    }
    if walk.skinned_lights > 0 {
        walk.asset.notes.push(format!(
            "{} emissive skinned or morphed mesh(es) keep their loaded pose: animations do not reshape them",
            walk.skinned_lights
        ));
    }
    if walk.unweighted > 0 {
        walk.asset
            .notes
            .push(format!("{} skinned vertices have no joint weights: placed by their mesh's node", walk.unweighted));
    }
    Ok(walk.asset)
}

/// Parses and validates the JSON (of a `.gltf`, or of a `.glb`'s first
/// chunk); also returns how many animation channels without a target node
/// were left out.
fn parse(bytes: &[u8], file: &str) -> Result<(gltf::Gltf, usize), SceneError> {
    let parsed = gltf::Gltf::from_slice_without_validation(bytes);
    // The `gltf-json` crate requires a channel's target node, which glTF
    // 2.0 makes optional (extensions name other targets): such channels
    // are taken out of the JSON, and the file parsed again.
    let (parsed, skipped) = match parsed {
        Err(gltf::Error::Deserialize(_)) => match without_nodeless_channels(bytes) {
            Some((gltf, skipped)) => (Ok(gltf), skipped),
            None => (parsed, 0),
        },
        other => (other, 0),
    };
    let gltf::Gltf { document, blob } = parsed.map_err(|e| match e {
        gltf::Error::Deserialize(json) => SceneError {
            file: file.to_string(),
            position: (json.line() > 0).then(|| (json.line(), json.column())),
            context: String::new(),
            message: format!("invalid glTF JSON: {json}"),
        },
        gltf::Error::Binary(b) => error(file, "", format!("not a valid binary glTF (.glb): {b}")),
        other => error(file, "", other.to_string()),
    })?;
    let root = document.into_json();
    check_indices(&root, file)?;
    let problems = validation_problems(&root);
    if let Some((path, problem)) = problems.first() {
        let more =
            if problems.len() > 1 { format!(" (and {} more problems)", problems.len() - 1) } else { String::new() };
        return Err(error(file, path.to_string(), format!("{problem}{more}")));
    }
    let document = gltf::Document::from_json_without_validation(root);
    Ok((gltf::Gltf { document, blob }, skipped))
}

/// The file with its animation channels that name no target node left
/// out, and how many there were; None where there are none, or the JSON
/// does not parse even so.
fn without_nodeless_channels(bytes: &[u8]) -> Option<(gltf::Gltf, usize)> {
    use gltf::json::Value;
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let glb = gltf::binary::Glb::from_slice(bytes).ok()?;
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    let mut value: Value = gltf::json::deserialize::from_slice(&json).ok()?;
    let mut skipped = 0;
    for animation in value.get_mut("animations")?.as_array_mut()? {
        if let Some(channels) = animation.get_mut("channels").and_then(Value::as_array_mut) {
            let before = channels.len();
            channels.retain(|c| c.get("target").is_some_and(|t| t.get("node").is_some()));
            skipped += before - channels.len();
        }
    }
    if skipped == 0 {
        return None;
    }
    let root: gltf::json::Root = gltf::json::deserialize::from_value(value).ok()?;
    Some((gltf::Gltf { document: gltf::Document::from_json_without_validation(root), blob }, skipped))
}

/// The `gltf-json` crate's validation problems, less one it gets wrong:
/// an accessor without a buffer view is valid, its elements zeros (glTF
/// 2.0, 3.6.2.1 and the validator's own test files), but the crate wants
/// one unless the accessor is sparse.
fn validation_problems(root: &gltf::json::Root) -> Vec<(gltf::json::Path, gltf::json::validation::Error)> {
    use gltf::json::validation::{Error, Validate};
    let mut problems = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| problems.push((path(), error)));
    // A texture may name its image through EXT_texture_webp alone.
    let webp_only = |text: &str| {
        let index = text.strip_prefix("textures[").and_then(|t| t.strip_suffix("].source"));
        let texture = index.and_then(|i| i.parse::<usize>().ok()).and_then(|i| root.textures.get(i));
        texture.and_then(|t| t.extensions.as_ref()).is_some_and(|e| e.others.contains_key(textures::WEBP))
    };
    problems.retain(|(path, error)| {
        let text = path.to_string();
        let missing = matches!(error, Error::Missing);
        // The crate knows only the extensions it parses; hikari reads more
        // (check_extensions refuses the rest, naming them).
        let required = text.starts_with("extensionsRequired[") && matches!(error, Error::Unsupported);
        !(missing && text.starts_with("accessors[") && text.ends_with("].bufferView")
            || missing && webp_only(&text)
            || required)
    });
    problems
}

/// The `gltf-json` crate's validation reads each primitive's `POSITION`
/// accessor before checking that it exists (and panics when it does not),
/// and its animation accessors unwrap their indices: those are checked
/// first.
fn check_indices(root: &gltf::json::Root, file: &str) -> Result<(), SceneError> {
    let positions = gltf::json::validation::Checked::Valid(gltf::json::mesh::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&positions)
                && index.value() >= root.accessors.len()
            {
                return Err(error(
                    file,
                    format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    format!("accessor {} does not exist ({} accessors)", index.value(), root.accessors.len()),
                ));
            }
        }
    }
    // The crate's animation accessors unwrap these indices too.
    for (a, animation) in root.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let checks = [
                ("sampler", channel.sampler.value(), animation.samplers.len(), "samplers"),
                ("target.node", channel.target.node.value(), root.nodes.len(), "nodes"),
            ];
            for (field, index, len, what) in checks {
                if index >= len {
                    return Err(error(
                        file,
                        format!("animations[{a}].channels[{c}].{field}"),
                        format!("{what} {index} does not exist ({len} {what})"),
                    ));
                }
            }
        }
        for (i, sampler) in animation.samplers.iter().enumerate() {
            for (field, index) in [("input", sampler.input.value()), ("output", sampler.output.value())] {
                if index >= root.accessors.len() {
                    return Err(error(
                        file,
                        format!("animations[{a}].samplers[{i}].{field}"),
                        format!("accessor {index} does not exist ({} accessors)", root.accessors.len()),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Every buffer's bytes, from the `.glb`'s binary chunk, a data URI or a
/// file beside the glTF file (in `files`).
fn load_buffers(gltf: &gltf::Gltf, files: SceneFiles, file: &str) -> Result<Vec<gltf::buffer::Data>, SceneError> {
    let mut blob = gltf.blob.clone();
    let mut out = Vec::new();
    for buffer in gltf.document.buffers() {
        let at = format!("buffers[{}]", buffer.index());
        let what = match buffer.source() {
            gltf::buffer::Source::Bin => "the .glb's binary chunk".to_string(),
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => "its data URI".to_string(),
            gltf::buffer::Source::Uri(uri) => format!("\"{uri}\""),
        };
        let data = match buffer.source() {
            // EXT_meshopt_compression's placeholder for data only its
            // compressed views hold: nothing to read.
            gltf::buffer::Source::Bin if is_meshopt_fallback(&buffer) => {
                out.push(gltf::buffer::Data(Vec::new()));
                continue;
            }
            gltf::buffer::Source::Uri(uri) if !uri.starts_with("data:") => {
                let mut bytes = files.read(uri, true).map_err(|e| error(file, &at, e))?;
                bytes.resize(bytes.len().next_multiple_of(4), 0);
                gltf::buffer::Data(bytes)
            }
            source => gltf::buffer::Data::from_source_and_blob(source, None, &mut blob)
                .map_err(|e| error(file, &at, format!("cannot read {what}: {e}")))?,
        };
        if data.len() < buffer.length() {
            return Err(error(
                file,
                &at,
                format!(
                    "{what} holds {} bytes, fewer than its byteLength {} (truncated?)",
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// Is `buffer` a placeholder (`EXT_meshopt_compression.fallback`) whose
/// bytes no uncompressed view reads?
fn is_meshopt_fallback(buffer: &gltf::Buffer) -> bool {
    let fallback = buffer.extensions().and_then(|e| e.get(compressed::MESHOPT)).and_then(|e| e.get("fallback"));
    fallback.and_then(|f| f.as_bool()) == Some(true)
}

fn check_extensions(doc: &gltf::Document, file: &str, notes: &mut Vec<String>) -> Result<(), SceneError> {
    for (i, ext) in doc.extensions_required().enumerate() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            return Err(error(
                file,
                format!("extensionsRequired[{i}]"),
                format!(
                    "the file requires extension {ext}, which hikari does not support (supported: {})",
                    SUPPORTED_EXTENSIONS.join(", ")
                ),
            ));
        }
    }
    let ignored: Vec<&str> = doc.extensions_used().filter(|e| !SUPPORTED_EXTENSIONS.contains(e)).collect();
    if !ignored.is_empty() {
        notes.push(format!("optional glTF extensions ignored: {}", ignored.join(", ")));
    }
    Ok(())
}

/// A primitive as `Walk::deformed` leaves it: its (morphed, skinned)
/// vertices, the transform that places them, the node path that moves it,
/// and, for a skin whose joints move, the mesh to bend again with the
/// vertices before skinning.
type Deformed =
    (std::rc::Rc<LocalPrimitive>, Mat4, Vec<usize>, Option<(crate::scene::deformation::DeformedMesh, LocalPrimitive)>);

/// A primitive's triangles in the file's own space, shared by every node
/// that instances its mesh.
#[derive(Clone)]
struct LocalPrimitive {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    /// `TEXCOORD_0`, read only where the material reads textures.
    uvs: Option<Vec<Vec2>>,
    /// Three vertex indices per triangle.
    triangles: Vec<[u32; 3]>,
    /// Each triangle's corners' tangents (`tangents`), where the material
    /// has a normal texture and the primitive coordinates.
    tangents: Option<Vec<[Vec4; 3]>>,
    material: u32,
}

/// The traversal of the node hierarchy.
struct Walk<'a> {
    file: &'a str,
    buffers: &'a [gltf::buffer::Data],
    emissions: &'a [Option<Emission>],
    /// Per material: does it read textures (so its primitives' UVs are kept)?
    textured: &'a [bool],
    /// Per material: has it a normal texture (so its primitives' tangents
    /// are read or made)?
    normal_mapped: &'a [bool],
    camera_name: Option<&'a str>,
    /// (mesh, primitive) → its triangles, read once.
    cache: HashMap<(usize, usize), std::rc::Rc<LocalPrimitive>>,
    asset: Asset,
    visited: Vec<bool>,
    ignored_range: bool,
    /// Does the file use KHR_mesh_quantization (integer attributes)?
    quantized: bool,
    /// Primitives of textured materials without `TEXCOORD_0`.
    without_uvs: usize,
    /// Every node's world transform (what skins read).
    node_worlds: Vec<Option<Mat4>>,
    /// Nodes whose mesh a skin bends.
    /// Every node's path from the root (what animates a joint).
    node_paths: Vec<Option<Vec<usize>>>,
    /// Emissive skinned meshes whose joints move (they do not bend).
    skinned_lights: usize,
    /// Skinned vertices without joint weights (placed by their node).
    unweighted: usize,
    /// Skinned primitives with normal textures (read without tangents).
    skinned_normal_mapped: usize,
    progress: &'a dyn Progress,
}

/// How many primitives the scene places (one per primitive of each node's
/// mesh, children included): the loader's progress total. Nodes reached
/// twice are counted once (the walk refuses them anyway).
fn placed_primitives(scene: &gltf::Scene) -> u64 {
    let mut seen = std::collections::HashSet::new();
    let mut stack: Vec<gltf::Node> = scene.nodes().collect();
    let mut count = 0;
    while let Some(node) = stack.pop() {
        if seen.insert(node.index()) {
            count += node.mesh().map_or(0, |m| m.primitives().len() as u64);
            stack.extend(node.children());
        }
    }
    count
}

impl Walk<'_> {
    /// Places `node` under `parent`; `path` holds the node indices above it.
    fn node(&mut self, node: &gltf::Node, parent: Mat4, path: &mut Vec<usize>) -> Result<(), SceneError> {
        let at = format!("nodes[{}]", node.index());
        if std::mem::replace(&mut self.visited[node.index()], true) {
            return Err(error(
                self.file,
                &at,
                "the node is reached twice in the scene's hierarchy (a cycle, or two parents)",
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(error(self.file, &at, "the node's transform is not finite"));
        }
        let name = node.name().map(str::to_string);
        path.push(node.index());
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                let local = self.local_primitive(&mesh, &primitive)?;
                let (local, placement, node_path, joints) =
                    self.deformed(node, &mesh, &primitive, local, world, path)?;
                let Placed { triangles, uvs, tangents, kept } = place_triangles(&local, &placement);
                if let Some(v) = triangles.iter().flat_map(|t| t.v).find(|v| v.abs().max_element() > MAX_COORD) {
                    return Err(error(
                        self.file,
                        format!("{at} (meshes[{}].primitives[{}])", mesh.index(), primitive.index()),
                        format!("a vertex placed at {v} lies beyond ±{MAX_COORD:e}"),
                    ));
                }
                let material = local.material;
                let emission = self.emissions[material as usize];
                let deformed = joints.filter(|_| {
                    self.skinned_lights += emission.is_some() as usize;
                    emission.is_none()
                });
                let deformed = deformed.map(|(mut mesh, base)| {
                    mesh.triangles = kept;
                    (mesh.positions, mesh.normals) = (base.positions, base.normals);
                    std::sync::Arc::new(mesh)
                });
                self.asset.primitives.push(Primitive {
                    name: name.clone(),
                    triangles,
                    uvs,
                    tangents,
                    material,
                    emission,
                    node_path,
                    deformed,
                });
                self.progress.advance(1);
            }
        }
        if let Some(camera) = node.camera() {
            self.camera(&camera, node.name(), &world);
        }
        if let Some(light) = node.light() {
            let light = self.light(&light, &world, &at)?;
            self.asset.lights.push((name, light));
            self.asset.light_paths.push(path.clone());
        }
        for child in node.children() {
            self.node(&child, world, path)?;
        }
        path.pop();
        Ok(())
    }

    /// `local` under `node` morphed by its weights (the node's, else the
    /// mesh's) and bent by its skin, with the transform that places it and
    /// the node path that moves it: a skinned primitive is in world space
    /// already and does not follow its node's motion.
    fn deformed(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        local: std::rc::Rc<LocalPrimitive>,
        world: Mat4,
        path: &[usize],
    ) -> Result<Deformed, SceneError> {
        use crate::scene::deformation::{DeformedMesh, Influences, Joint, Morph};
        let at = format!("nodes[{}] (meshes[{}].primitives[{}])", node.index(), mesh.index(), primitive.index());
        let fail = |m: String| error(self.file, &at, m);
        let weights = node.weights().or(mesh.weights()).unwrap_or(&[]);
        let has_targets = primitive.morph_targets().next().is_some();
        // Weights an animation keys make the mesh change shape as it plays.
        let keyed = self.asset.channels.weights(node.index()).filter(|_| has_targets).cloned();
        let targets = if has_targets && (keyed.is_some() || weights.iter().any(|&w| w != 0.0)) {
            deform::morph_targets(primitive, local.positions.len(), self.buffers).map_err(fail)?
        } else {
            Vec::new()
        };
        let unmorphed = local.clone();
        let mut local = local;
        if !targets.is_empty() && weights.iter().any(|&w| w != 0.0) {
            local = std::rc::Rc::new(deform::morph(&local, &targets, weights).map_err(fail)?);
        }
        let morph = keyed.map(|weights| Morph { targets, weights });
        // What a posed mesh starts from: unmorphed where the weights are keyed.
        let base = if morph.is_some() { unmorphed } else { local.clone() };
        let Some(skin) = node.skin() else {
            let count = local.positions.len();
            let again = morph.map(|morph| {
                let mesh = DeformedMesh {
                    positions: Vec::new(),
                    normals: None,
                    triangles: Vec::new(),
                    influences: Influences { starts: vec![0; count + 1], entries: Vec::new() },
                    joints: Vec::new(),
                    fallback: world,
                    morph: Some(morph),
                };
                (mesh, (*base).clone())
            });
            return Ok((local, world, path.to_vec(), again));
        };
        let skinned = deform::skin(&local, primitive, &skin, &self.node_worlds, world, self.buffers).map_err(fail)?;
        self.unweighted += skinned.unweighted;
        self.skinned_normal_mapped += local.tangents.is_some() as usize;
        // The joints' motions: a skin whose joints the animations move is
        // bent again at each time (`Motion::Deformed`).
        let above = self.asset.world_from_file;
        let joints: Vec<Joint> = skinned
            .joints
            .iter()
            .zip(&skinned.inverse_binds)
            .zip(&skinned.rest_worlds)
            .map(|((&j, &inverse_bind), &rest_world)| Joint {
                inverse_bind,
                rest_world,
                motion: self.node_paths[j].as_ref().and_then(|p| self.asset.channels.keyframes(above, p)),
            })
            .collect();
        let bendable = DeformedMesh {
            positions: Vec::new(),
            normals: None,
            triangles: Vec::new(),
            influences: skinned.influences,
            joints,
            fallback: world,
            morph,
        };
        let again = bendable.moves().then(|| (bendable, (*base).clone()));
        Ok((std::rc::Rc::new(skinned.placed), Mat4::IDENTITY, Vec::new(), again))
    }

    /// Keeps the camera if it is the one asked for by its own or its
    /// node's name (Blender names the node), or the first one.
    fn camera(&mut self, camera: &gltf::Camera, node_name: Option<&str>, world: &Mat4) {
        let gltf::camera::Projection::Perspective(p) = camera.projection() else { return };
        let wanted = match self.camera_name {
            Some(name) => camera.name() == Some(name) || node_name == Some(name),
            None => self.asset.camera.is_none(),
        };
        if !wanted {
            return;
        }
        // A glTF camera looks down its node's −z with +y up.
        self.asset.camera = Some(CameraPose {
            position: world.transform_point3(Vec3::ZERO),
            forward: world.transform_vector3(-Vec3::Z).normalize_or_zero(),
            up: world.transform_vector3(Vec3::Y).normalize_or_zero(),
            fov_y: p.yfov().to_degrees(),
            aspect: p.aspect_ratio(),
        });
    }

    /// A `KHR_lights_punctual` light in hikari's radiometric units: the
    /// file's candela (lm/sr) and lux (lm/m²) divided by 683 lm/W give W/sr
    /// and W/m². A Blender export of a P-watt point light says
    /// P·683/(4π) cd, so it arrives here as P/(4π) W/sr: P watts, as Blender
    /// renders it.
    fn light(&mut self, light: &gltf::khr_lights_punctual::Light, world: &Mat4, at: &str) -> Result<Light, SceneError> {
        use gltf::khr_lights_punctual::Kind;
        let at = format!("{at} (KHR_lights_punctual.lights[{}])", light.index());
        let color = Vec3::from(light.color());
        let intensity = light.intensity();
        if !(color.is_finite() && color.min_element() >= 0.0 && intensity.is_finite() && intensity >= 0.0) {
            return Err(error(self.file, &at, "the light's color and intensity must be finite and non-negative"));
        }
        let emission: Rgb = color * intensity / LUMENS_PER_WATT;
        if emission.max_element() > super::limits::MAX_EMISSION {
            return Err(error(self.file, &at, format!("intensity {intensity} is beyond hikari's limit")));
        }
        self.ignored_range |= light.range().is_some();
        let position = world.transform_point3(Vec3::ZERO);
        // Punctual lights shine down their node's −z.
        let axis = world.transform_vector3(-Vec3::Z).normalize_or_zero();
        if axis == Vec3::ZERO || position.abs().max_element() > MAX_COORD {
            return Err(error(self.file, &at, "the light's node transform is degenerate or places it too far away"));
        }
        Ok(match light.kind() {
            Kind::Point => Light::Point { position, intensity: emission },
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                let (min, max) = super::limits::CUTOFF_ANGLE;
                let outer = outer_cone_angle.to_degrees();
                if !(outer >= min && outer <= max) {
                    return Err(error(
                        self.file,
                        &at,
                        format!("outerConeAngle {outer}° must lie between {min}° and {max}°"),
                    ));
                }
                // glTF's smooth step in cos θ between the cone angles becomes
                // hikari's linear ramp in θ between the same angles.
                let inner = inner_cone_angle.clamp(0.0, outer_cone_angle);
                Light::Spot { position, axis, intensity: emission, cutoff: outer_cone_angle, falloff_start: inner }
            }
            Kind::Directional => {
                Light::Directional { direction: axis, irradiance: emission, disc: crate::light::Disc::UNIT }
            }
        })
    }

    /// Reads a primitive once (instancing shares it), checking every value.
    fn local_primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> Result<std::rc::Rc<LocalPrimitive>, SceneError> {
        let key = (mesh.index(), primitive.index());
        if let Some(p) = self.cache.get(&key) {
            return Ok(p.clone());
        }
        let at = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
        let fail = |field: &str, message: String| error(self.file, format!("{at}{field}"), message);
        let attribute = |semantic: gltf::Semantic, name: &str, allowed: &[DataType]| {
            primitive
                .get(&semantic)
                .map(|a| {
                    accessors::read::<3>(&a, self.buffers, allowed)
                        .map_err(|m| fail(&format!(".attributes.{name}"), format!("accessor {} {m}", a.index())))
                })
                .transpose()
        };
        // KHR_mesh_quantization lets positions, normals and texture
        // coordinates be (normalized) integers; the node's transform scales
        // them back.
        let (position_types, normal_types): (&[DataType], &[DataType]) = if self.quantized {
            (
                &[DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16],
                &[DataType::F32, DataType::I8, DataType::I16],
            )
        } else {
            (&[DataType::F32], &[DataType::F32])
        };
        let positions: Vec<Vec3> = attribute(gltf::Semantic::Positions, "POSITION", position_types)?
            .ok_or_else(|| fail(".attributes", "the primitive has no POSITION".into()))?
            .into_iter()
            .map(Vec3::from)
            .collect();
        if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(fail(".attributes.POSITION", format!("vertex {i} is not finite: {p}")));
        }
        let normals = attribute(gltf::Semantic::Normals, "NORMAL", normal_types)?
            .map(|n| n.into_iter().map(Vec3::from).collect::<Vec<_>>());
        if let Some((i, n)) = normals.iter().flatten().enumerate().find(|(_, n)| !n.is_finite()) {
            return Err(fail(".attributes.NORMAL", format!("normal {i} is not finite: {n}")));
        }
        if normals.as_ref().is_some_and(|n| n.len() != positions.len()) {
            return Err(fail(".attributes.NORMAL", "has a different count than POSITION".into()));
        }
        let indices = match primitive.indices() {
            Some(a) => accessors::read_indices(&a, self.buffers)
                .map_err(|m| fail(".indices", format!("accessor {} {m}", a.index())))?,
            None => (0..positions.len() as u32).collect(),
        };
        if let Some((i, v)) = indices.iter().enumerate().find(|&(_, &v)| v as usize >= positions.len()) {
            return Err(fail(".indices", format!("index {i} is {v}, beyond the {} vertices", positions.len())));
        }
        let triangles: Vec<[u32; 3]> = match primitive.mode() {
            Mode::Triangles => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            // Strips alternate winding so every triangle faces the same way.
            Mode::TriangleStrip => (2..indices.len())
                .map(|i| {
                    let [a, b, c] = [indices[i - 2], indices[i - 1], indices[i]];
                    if i % 2 == 0 { [a, b, c] } else { [b, a, c] }
                })
                .collect(),
            Mode::TriangleFan => (2..indices.len()).map(|i| [indices[0], indices[i - 1], indices[i]]).collect(),
            other => {
                return Err(fail(".mode", format!("mode {other:?} is not triangles (hikari renders surfaces only)")));
            }
        };
        let material = primitive.material().index().unwrap_or(self.asset.materials.len() - 1) as u32;
        let uvs = if self.textured[material as usize] {
            self.tex_coords(primitive, positions.len()).map_err(|m| fail(".attributes.TEXCOORD_0", m))?
        } else {
            None
        };
        self.without_uvs += (self.textured[material as usize] && uvs.is_none()) as usize;
        let tangents = match &uvs {
            Some(uvs) if self.normal_mapped[material as usize] => {
                let given = tangents::read(primitive, self.buffers, positions.len(), self.quantized)
                    .map_err(|m| fail(".attributes.TANGENT", m))?;
                Some(match given {
                    Some(given) => tangents::per_corner(&given, &triangles),
                    None => tangents::mikktspace(&positions, normals.as_deref(), uvs, &triangles),
                })
            }
            _ => None,
        };
        let local = std::rc::Rc::new(LocalPrimitive { positions, normals, uvs, triangles, tangents, material });
        self.cache.insert(key, local.clone());
        Ok(local)
    }
}

impl Walk<'_> {
    /// `TEXCOORD_0`: f32, or normalized u8 or u16 (the specification's choices).
    fn tex_coords(&self, primitive: &gltf::Primitive, count: usize) -> Result<Option<Vec<Vec2>>, String> {
        let Some(a) = primitive.get(&gltf::Semantic::TexCoords(0)) else { return Ok(None) };
        if a.data_type() != DataType::F32 && !a.normalized() && !self.quantized {
            return Err(format!(
                "accessor {}'s integer components must be normalized (or the file use KHR_mesh_quantization)",
                a.index()
            ));
        }
        let allowed: &[DataType] = if self.quantized {
            &[DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16]
        } else {
            &[DataType::F32, DataType::U8, DataType::U16]
        };
        let uvs = accessors::read::<2>(&a, self.buffers, allowed).map_err(|m| format!("accessor {} {m}", a.index()))?;
        if uvs.len() != count {
            return Err("has a different count than POSITION".into());
        }
        if let Some((i, uv)) = uvs.iter().enumerate().find(|(_, uv)| !uv.iter().all(|x| x.is_finite())) {
            return Err(format!("coordinate {i} is not finite: {uv:?}"));
        }
        Ok(Some(uvs.into_iter().map(Vec2::from).collect()))
    }
}

/// A primitive's triangles placed by `world`: normals by its inverse
/// transpose, tangents by `world` itself (their side turned where it
/// mirrors), and the winding reversed where it mirrors (negative
/// determinant), so the front face stays the front face, with their
/// texture coordinates and tangents in the same vertex order. Triangles
/// with no area in 32-bit floats are dropped.
fn place_triangles(local: &LocalPrimitive, world: &Mat4) -> Placed {
    let linear = Mat3::from_mat4(*world);
    let normal_matrix = linear.inverse().transpose();
    let mirrored = linear.determinant() < 0.0;
    let side = if mirrored { -1.0 } else { 1.0 };
    let positions: Vec<Vec3> = local.positions.iter().map(|&p| world.transform_point3(p)).collect();
    let normals: Option<Vec<Vec3>> =
        local.normals.as_ref().map(|n| n.iter().map(|&n| (normal_matrix * n).normalize_or_zero()).collect());
    let mut uvs = local.uvs.as_ref().map(|_| Vec::with_capacity(local.triangles.len()));
    let mut tangents = local.tangents.as_ref().map(|_| Vec::with_capacity(local.triangles.len()));
    let mut kept = Vec::with_capacity(local.triangles.len());
    let triangles = local
        .triangles
        .iter()
        .enumerate()
        .filter_map(|(t, &[a, b, c])| {
            let (order, corners) = if mirrored { ([a, c, b], [0, 2, 1]) } else { ([a, b, c], [0, 1, 2]) };
            let v = order.map(|i| positions[i as usize]);
            let normals = normals.as_ref().map(|n| TriangleNormals(order.map(|i| n[i as usize])));
            let tri = Triangle { v, normals };
            tri.geometric_normal().try_normalize()?;
            if let (Some(out), Some(uv)) = (uvs.as_mut(), local.uvs.as_ref()) {
                out.push(order.map(|i| uv[i as usize]));
            }
            if let (Some(out), Some(given)) = (tangents.as_mut(), local.tangents.as_ref()) {
                out.push(corners.map(|k| {
                    let t = given[t][k];
                    let direction = (linear * t.truncate()).normalize_or_zero();
                    crate::texture::PackedTangent::encode(direction.extend(if t.w < 0.0 { -side } else { side }))
                }));
            }
            kept.push(order);
            Some(tri)
        })
        .collect();
    Placed { triangles, uvs, tangents, kept }
}

/// What `place_triangles` gives: the triangles kept, their corners'
/// coordinates and tangents, and their vertex indices.
struct Placed {
    triangles: Vec<Triangle>,
    uvs: Option<Vec<[Vec2; 3]>>,
    tangents: Option<Vec<[crate::texture::PackedTangent; 3]>>,
    kept: Vec<[u32; 3]>,
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod texture_tests;

/// What a user may choose when loading a file on its own.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// The camera to render through, by name (glTF files).
    pub camera: Option<String>,
    /// An equirectangular `.hdr`/`.exr` sky that lights the scene in place
    /// of its environment (`Scene::set_environment_map`).
    pub environment: Option<std::path::PathBuf>,
}

/// Side of the longer image edge when the file gives only an aspect ratio.
const DEFAULT_HEIGHT: u32 = 512;

/// A glTF file as a whole scene: its camera (or one framing its bounds),
/// its lights and emissive surfaces (or a white environment if it has
/// none), with a note for each.
pub fn load_scene(path: &Path, options: &LoadOptions, progress: &dyn Progress) -> Result<super::Scene, SceneError> {
    let asset = load_asset(path, Affine3A::IDENTITY, options.camera.as_deref(), progress)?;
    scene_from_asset(asset, path.display().to_string(), progress)
}

/// [`load_scene`] of a file's bytes (see [`asset_from_bytes`]).
pub fn scene_from_bytes(
    bytes: &[u8],
    file: &str,
    files: SceneFiles,
    options: &LoadOptions,
    progress: &dyn Progress,
) -> Result<super::Scene, SceneError> {
    let asset = asset_from_bytes(bytes, file, files, Affine3A::IDENTITY, options.camera.as_deref(), progress)?;
    scene_from_asset(asset, file.to_string(), progress)
}

fn scene_from_asset(mut asset: Asset, file: String, progress: &dyn Progress) -> Result<super::Scene, SceneError> {
    use super::{Animation, Names, Scene, Surface, Target};
    let mut surfaces = Vec::new();
    let mut triangles = Vec::new();
    let mut names = Names::default();
    let mut lights: Vec<Light> = Vec::new();
    let mut light_names = Vec::new();
    // The file's animation, as motions of the lights and surfaces it moves.
    let mut animations = Vec::new();
    let light_motions: Vec<_> = asset.light_paths.iter().map(|path| asset.motion(path)).collect();
    let primitive_motions: Vec<_> = asset.primitives.iter().map(|p| asset.motion(&p.node_path)).collect();
    for ((name, light), motion) in asset.lights.drain(..).zip(light_motions) {
        if let Some(motion) = motion {
            animations.push(Animation { target: Target::Light(lights.len() as u32), motion });
        }
        light_names.push(name);
        lights.push(light);
    }
    let mut uvs = crate::texture::TexCoords::default();
    let mut tangents = crate::texture::Tangents::default();
    for (primitive, motion) in asset.primitives.drain(..).zip(primitive_motions) {
        if primitive.triangles.is_empty() {
            continue;
        }
        if let Some(tri_uvs) = &primitive.uvs {
            uvs.push_run(triangles.len() as u32, tri_uvs);
        }
        if let Some(tri_tangents) = &primitive.tangents {
            tangents.push_run(triangles.len() as u32, tri_tangents);
        }
        let surface = surfaces.len() as u32;
        let emitter = primitive.emitted_light().map(|light| {
            lights.push(light);
            light_names.push(None);
            lights.len() as u32 - 1
        });
        surfaces.push(Surface { material: primitive.material, emitter });
        if let Some(mesh) = primitive.deformed {
            animations.push(Animation { target: Target::Object(surface), motion: super::Motion::Deformed(mesh) });
        }
        if let Some(motion) = motion {
            // An emissive surface moves with its light (`Scene::posed`).
            let target = emitter.map_or(Target::Object(surface), Target::Light);
            animations.push(Animation { target, motion });
        }
        if let Some(name) = primitive.name
            && !names.objects.iter().any(|(n, _)| *n == name)
        {
            names.objects.push((name, surface));
        }
        triangles.extend(primitive.triangles.into_iter().map(|t| (t, surface)));
    }
    if triangles.is_empty() {
        return Err(error(&file, "", "the scene has no triangle to render"));
    }
    let (triangles, tri_surfaces): (Vec<_>, Vec<_>) = triangles.into_iter().unzip();
    progress.begin("building the BVH", 1);
    let mut accel = crate::geometry::Accel::build(triangles, tri_surfaces, Vec::new(), Vec::new());
    progress.advance(1);
    progress.end();
    let texturing = asset.material_textures.iter().any(Option::is_some).then(|| {
        std::sync::Arc::new(crate::texture::Texturing {
            images: std::mem::take(&mut asset.images),
            materials: std::mem::take(&mut asset.material_textures),
            uvs,
            tangents,
            surface_materials: surfaces.iter().map(|s| s.material).collect(),
        })
    });
    accel.set_alpha_mask(texturing.clone());
    if lights.is_empty() {
        asset.notes.push("the file has no lights: lit by a uniform white environment (radiance 1)".into());
        lights.push(Light::Environment { radiance: Rgb::ONE, disc: crate::light::Disc::UNIT, map: None });
        light_names.push(None);
    }
    crate::light::fit_distant_lights(&mut lights, accel.bounds());
    names.lights = light_names;
    names.materials = std::mem::take(&mut asset.material_names);
    let camera = match asset.camera {
        Some(pose) => camera_from_pose(&pose).map_err(|m| error(&file, "cameras", m))?,
        None => {
            asset.notes.push("the file has no camera: one frames the scene's bounds".into());
            framing_camera(accel.bounds())
        }
    };
    Ok(Scene {
        source: file,
        camera,
        materials: asset.materials,
        surfaces,
        lights,
        accel,
        media: crate::medium::Media::new(Vec::new()).expect("no media is valid"),
        names,
        animations,
        notes: asset.notes,
        texturing,
    })
}

/// The camera of a glTF camera node, at `DEFAULT_HEIGHT` pixels high and
/// its aspect ratio (square without one).
fn camera_from_pose(pose: &CameraPose) -> Result<crate::camera::Camera, String> {
    let aspect = pose.aspect.filter(|a| a.is_finite() && *a > 0.0).unwrap_or(1.0);
    let width = ((DEFAULT_HEIGHT as f32 * aspect).round() as u32).clamp(1, super::limits::MAX_SIDE);
    crate::camera::Camera::new(pose.position, pose.position + pose.forward, pose.up, pose.fov_y, width, DEFAULT_HEIGHT)
}

/// A camera looking at the bounds' centre from the front (+z) and a little
/// above, far enough that the bounding sphere fills the 40° field of view.
fn framing_camera((lo, hi): (Vec3, Vec3)) -> crate::camera::Camera {
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let fov_y: f32 = 40.0;
    let distance = radius / (fov_y.to_radians() * 0.5).sin();
    let position = center + Vec3::new(0.0, 0.3, 1.0).normalize() * distance;
    crate::camera::Camera::new(position, center, Vec3::Y, fov_y, DEFAULT_HEIGHT, DEFAULT_HEIGHT)
        .expect("a camera looking at the centre from outside, with +y up, is valid")
}
