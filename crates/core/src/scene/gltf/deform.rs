//! Meshes bent by skins and reshaped by morph targets, applied when the
//! scene is built, in the pose the file's node transforms give (glTF 2.0,
//! 3.7.3 and 3.7.2.2): a morph target adds its weighted POSITION and NORMAL
//! deltas; a skin places each vertex by the weighted sum of its joints'
//! matrices (the joint node's world transform times its inverse bind
//! matrix), up to 8 joints a vertex (`JOINTS_0`/`WEIGHTS_0` and
//! `JOINTS_1`/`WEIGHTS_1`), in world space: the skinned mesh's own node
//! transform does not apply, as the specification says.

use super::{LocalPrimitive, accessors};
use crate::scene::deformation::{Influences, MorphTarget, morph_vertices, skin_vertices};
use glam::{Mat4, Vec3};
use gltf::accessor::DataType;

/// Each node's world transform in `scene` under `root` (None for nodes
/// outside it).
pub fn node_worlds(doc: &gltf::Document, scene: &gltf::Scene, root: Mat4) -> Vec<Option<Mat4>> {
    let mut worlds = vec![None; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, root)).collect();
    while let Some((node, parent)) = stack.pop() {
        if worlds[node.index()].is_some() {
            continue; // reached twice: the walk refuses the file
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        worlds[node.index()] = Some(world);
        stack.extend(node.children().map(|c| (c, world)));
    }
    worlds
}

/// Each node's path from the scene's root (node indices, root first;
/// None for nodes outside it): what animates a joint.
pub fn node_paths(doc: &gltf::Document, scene: &gltf::Scene) -> Vec<Option<Vec<usize>>> {
    let mut paths = vec![None; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Vec<usize>)> = scene.nodes().map(|n| (n, Vec::new())).collect();
    while let Some((node, mut path)) = stack.pop() {
        if paths[node.index()].is_some() {
            continue;
        }
        path.push(node.index());
        stack.extend(node.children().map(|c| (c, path.clone())));
        paths[node.index()] = Some(path);
    }
    paths
}

/// `primitive`'s morph targets: per target, its POSITION deltas (zeros
/// where it has none) and its NORMAL deltas, checked.
pub fn morph_targets(
    primitive: &gltf::Primitive,
    count: usize,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<MorphTarget>, String> {
    let mut targets = Vec::new();
    for (k, target) in primitive.morph_targets().enumerate() {
        let deltas = |a: Option<gltf::Accessor>, what: &str| -> Result<Option<Vec<Vec3>>, String> {
            let Some(a) = a else { return Ok(None) };
            let d = accessors::read::<3>(&a, buffers, &[DataType::F32, DataType::I8, DataType::I16])
                .map_err(|m| format!("targets[{k}].{what}: accessor {} {m}", a.index()))?;
            if d.len() != count {
                return Err(format!("targets[{k}].{what} has {} deltas for {count} vertices", d.len()));
            }
            if let Some((i, d)) = d.iter().enumerate().find(|(_, d)| !d.iter().all(|x| x.is_finite())) {
                return Err(format!("targets[{k}].{what}: delta {i} is not finite: {d:?}"));
            }
            Ok(Some(d.into_iter().map(Vec3::from).collect()))
        };
        let positions = deltas(target.positions(), "POSITION")?.unwrap_or_else(|| vec![Vec3::ZERO; count]);
        targets.push((positions, deltas(target.normals(), "NORMAL")?));
    }
    Ok(targets)
}

/// `local` with `targets` added by `weights`.
pub fn morph(local: &LocalPrimitive, targets: &[MorphTarget], weights: &[f32]) -> Result<LocalPrimitive, String> {
    if let Some((k, w)) = weights.iter().enumerate().find(|(_, w)| !w.is_finite()) {
        return Err(format!("morph target {k}'s weight {w} is not finite"));
    }
    let (positions, normals) = morph_vertices(&local.positions, local.normals.as_deref(), targets, weights);
    if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(format!("morphed vertex {i} is not finite: {p}"));
    }
    Ok(LocalPrimitive { positions, normals, ..local.clone() })
}

/// `local` bent by `skin`, in world space, and what it takes to bend it
/// again at another time: its influences, inverse bind matrices and joint
/// nodes (the caller adds the joints' motions); also how many of its
/// vertices have no joint weight (placed by `node_world`, the mesh's node,
/// instead).
pub fn skin(
    local: &LocalPrimitive,
    primitive: &gltf::Primitive,
    skin: &gltf::Skin,
    worlds: &[Option<Mat4>],
    node_world: Mat4,
    buffers: &[gltf::buffer::Data],
) -> Result<Skinned, String> {
    let at = format!("skins[{}]", skin.index());
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    let inverse_binds: Vec<Mat4> = match skin.inverse_bind_matrices() {
        Some(a) => accessors::read::<16>(&a, buffers, &[DataType::F32])
            .map_err(|m| format!("{at}.inverseBindMatrices: accessor {} {m}", a.index()))?
            .into_iter()
            .map(|m| Mat4::from_cols_array(&m))
            .collect(),
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    if inverse_binds.len() < joints.len() {
        return Err(format!("{at}: {} inverse bind matrices for {} joints", inverse_binds.len(), joints.len()));
    }
    let rest_worlds: Vec<Mat4> = joints
        .iter()
        .map(|&j| worlds[j].ok_or_else(|| format!("{at}: joint nodes[{j}] is not in the scene")))
        .collect::<Result<_, String>>()?;
    let matrices: Vec<Mat4> = rest_worlds.iter().zip(&inverse_binds).map(|(w, ibm)| *w * *ibm).collect();
    let count = local.positions.len();
    let mut per_vertex: Vec<Vec<(u32, f32)>> = vec![Vec::new(); count];
    for set in 0..2 {
        let (Some(j), Some(w)) =
            (primitive.get(&gltf::Semantic::Joints(set)), primitive.get(&gltf::Semantic::Weights(set)))
        else {
            continue;
        };
        let ji = accessors::read::<4>(&j, buffers, &[DataType::U8, DataType::U16])
            .map_err(|m| format!("attributes.JOINTS_{set}: accessor {} {m}", j.index()))?;
        let wi = accessors::read::<4>(&w, buffers, &[DataType::F32, DataType::U8, DataType::U16])
            .map_err(|m| format!("attributes.WEIGHTS_{set}: accessor {} {m}", w.index()))?;
        if ji.len() != count || wi.len() != count {
            return Err(format!("attributes.JOINTS_{set}/WEIGHTS_{set} do not have one entry per vertex ({count})"));
        }
        for (v, (js, ws)) in ji.iter().zip(&wi).enumerate() {
            for (&joint, &weight) in js.iter().zip(ws) {
                if weight == 0.0 {
                    continue;
                }
                if !(weight.is_finite() && weight >= 0.0) {
                    return Err(format!("attributes.WEIGHTS_{set}: vertex {v} has weight {weight}"));
                }
                if joint as usize >= joints.len() {
                    return Err(format!(
                        "attributes.JOINTS_{set}: vertex {v} names joint {joint}, beyond the skin's {}",
                        joints.len()
                    ));
                }
                per_vertex[v].push((joint as u32, weight));
            }
        }
    }
    // Weights are meant to sum to 1; exporters round them.
    let mut influences = Influences { starts: vec![0], entries: Vec::new() };
    let mut unweighted = 0;
    for entries in per_vertex {
        let total: f32 = entries.iter().map(|e| e.1).sum();
        unweighted += entries.is_empty() as usize;
        influences.entries.extend(entries.iter().map(|&(j, w)| (j, w / total)));
        influences.starts.push(influences.entries.len() as u32);
    }
    let (positions, normals) =
        skin_vertices(&local.positions, local.normals.as_deref(), &influences, &matrices, node_world);
    if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(format!("skinned vertex {i} is not finite: {p}"));
    }
    Ok(Skinned {
        // Tangents are not bent: a skinned mesh's normal texture is read in
        // each triangle's own frame (`Texturing::shading_normal`), which
        // follows the pose.
        placed: LocalPrimitive { positions, normals, tangents: None, ..local.clone() },
        unweighted,
        influences,
        inverse_binds,
        joints,
        rest_worlds,
    })
}

/// A primitive bent by its skin in the file's node transforms, and what
/// bending it at other times takes.
pub struct Skinned {
    pub placed: LocalPrimitive,
    pub unweighted: usize,
    pub influences: Influences,
    pub inverse_binds: Vec<Mat4>,
    /// Joint node indices, and their world transforms as loaded.
    pub joints: Vec<usize>,
    pub rest_worlds: Vec<Mat4>,
}
