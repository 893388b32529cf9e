//! Meshes bent by skins and reshaped by morph targets, applied when the
//! scene is built, in the pose the file's node transforms give (glTF 2.0,
//! 3.7.3 and 3.7.2.2): a morph target adds its weighted POSITION and NORMAL
//! deltas; a skin places each vertex by the weighted sum of its joints'
//! matrices (the joint node's world transform times its inverse bind
//! matrix), up to 8 joints a vertex (`JOINTS_0`/`WEIGHTS_0` and
//! `JOINTS_1`/`WEIGHTS_1`), in world space: the skinned mesh's own node
//! transform does not apply, as the specification says.

use super::{LocalPrimitive, accessors};
use glam::{Mat3, Mat4, Vec3};
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

/// `local` with the morph targets of `primitive` added by `weights`.
pub fn morph(
    local: &LocalPrimitive,
    primitive: &gltf::Primitive,
    weights: &[f32],
    buffers: &[gltf::buffer::Data],
) -> Result<LocalPrimitive, String> {
    let mut positions = local.positions.clone();
    let mut normals = local.normals.clone();
    let count = positions.len();
    for (k, target) in primitive.morph_targets().enumerate() {
        let w = weights.get(k).copied().unwrap_or(0.0);
        if !w.is_finite() {
            return Err(format!("morph target {k}'s weight {w} is not finite"));
        }
        if w == 0.0 {
            continue;
        }
        let deltas = |a: Option<gltf::Accessor>, what: &str| -> Result<Option<Vec<Vec3>>, String> {
            let Some(a) = a else { return Ok(None) };
            let d = accessors::read::<3>(&a, buffers, &[DataType::F32, DataType::I8, DataType::I16])
                .map_err(|m| format!("targets[{k}].{what}: accessor {} {m}", a.index()))?;
            if d.len() != count {
                return Err(format!("targets[{k}].{what} has {} deltas for {count} vertices", d.len()));
            }
            Ok(Some(d.into_iter().map(Vec3::from).collect()))
        };
        if let Some(d) = deltas(target.positions(), "POSITION")? {
            positions.iter_mut().zip(d).for_each(|(p, d)| *p += w * d);
        }
        if let (Some(normals), Some(d)) = (normals.as_mut(), deltas(target.normals(), "NORMAL")?) {
            normals.iter_mut().zip(d).for_each(|(n, d)| *n += w * d);
        }
    }
    if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(format!("morphed vertex {i} is not finite: {p}"));
    }
    Ok(LocalPrimitive { positions, normals, ..local.clone() })
}

/// `local` bent by `skin`, in world space; also how many of its vertices
/// have no joint weight (placed by `node_world`, the mesh's node, instead).
pub fn skin(
    local: &LocalPrimitive,
    primitive: &gltf::Primitive,
    skin: &gltf::Skin,
    worlds: &[Option<Mat4>],
    node_world: Mat4,
    buffers: &[gltf::buffer::Data],
) -> Result<(LocalPrimitive, usize), String> {
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
    let matrices: Vec<Mat4> = joints
        .iter()
        .zip(&inverse_binds)
        .map(|(&j, ibm)| {
            let world = worlds[j].ok_or_else(|| format!("{at}: joint nodes[{j}] is not in the scene"))?;
            Ok(world * *ibm)
        })
        .collect::<Result<_, String>>()?;
    let count = local.positions.len();
    // Each vertex's summed joint matrix.
    let mut sums = vec![Mat4::ZERO; count];
    let mut weight_sums = vec![0.0f32; count];
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
                let m = matrices.get(joint as usize).ok_or_else(|| {
                    format!(
                        "attributes.JOINTS_{set}: vertex {v} names joint {joint}, beyond the skin's {}",
                        joints.len()
                    )
                })?;
                sums[v] += *m * weight;
                weight_sums[v] += weight;
            }
        }
    }
    let mut unweighted = 0;
    let mut positions = Vec::with_capacity(count);
    let mut normals = local.normals.as_ref().map(|_| Vec::with_capacity(count));
    for v in 0..count {
        // Weights are meant to sum to 1; exporters round them.
        let m = if weight_sums[v] > 0.0 {
            sums[v] * (1.0 / weight_sums[v])
        } else {
            unweighted += 1;
            node_world
        };
        positions.push(m.transform_point3(local.positions[v]));
        if let (Some(out), Some(n)) = (normals.as_mut(), local.normals.as_ref()) {
            out.push((Mat3::from_mat4(m).inverse().transpose() * n[v]).normalize_or_zero());
        }
    }
    if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(format!("skinned vertex {i} is not finite: {p}"));
    }
    Ok((LocalPrimitive { positions, normals, ..local.clone() }, unweighted))
}
