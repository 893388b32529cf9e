//! `KHR_draco_mesh_compression`: primitives whose indices and attributes
//! are one Draco stream (Blender's "Compression" export option, gltf-transform
//! `draco`), decoded with `draco-core`, a pure-Rust Draco decoder (so the web
//! page reads them too). Each decoded attribute is written in its accessor's
//! own component type, so what follows reads it as an uncompressed one.

use super::{point_view_at, push_buffer};
use gltf::json::accessor::{ComponentType, GenericComponentType};
use gltf::json::validation::{Checked, USize64};
use gltf::json::{Index, Root, Value};

/// The extension's name.
pub const DRACO: &str = "KHR_draco_mesh_compression";

/// Decodes every Draco-compressed primitive of `root`; errors are (glTF
/// path, message).
pub fn decode(root: &mut Root, buffers: &mut Vec<gltf::buffer::Data>) -> Result<(), (String, String)> {
    for m in 0..root.meshes.len() {
        for p in 0..root.meshes[m].primitives.len() {
            let primitive = &root.meshes[m].primitives[p];
            let Some(ext) = primitive.extensions.as_ref().and_then(|e| e.others.get(DRACO)).cloned() else {
                continue;
            };
            let at = format!("meshes[{m}].primitives[{p}].extensions.{DRACO}");
            decode_primitive(root, buffers, m, p, &ext).map_err(|message| (at, message))?;
            if let Some(e) = root.meshes[m].primitives[p].extensions.as_mut() {
                e.others.remove(DRACO);
            }
        }
    }
    Ok(())
}

fn decode_primitive(
    root: &mut Root,
    buffers: &mut Vec<gltf::buffer::Data>,
    m: usize,
    p: usize,
    ext: &Value,
) -> Result<(), String> {
    let view_index = ext.get("bufferView").and_then(Value::as_u64).ok_or("has no valid `bufferView`")? as usize;
    let view = root.buffer_views.get(view_index).ok_or_else(|| format!("bufferView {view_index} does not exist"))?;
    let (offset, length) = (view.byte_offset.map_or(0, |o| o.0 as usize), view.byte_length.0 as usize);
    let stream = buffers
        .get(view.buffer.value())
        .and_then(|b| b.get(offset..offset.checked_add(length)?))
        .ok_or_else(|| format!("bufferViews[{view_index}] lies beyond its buffer"))?;
    let mut mesh = draco_core::Mesh::new();
    draco_core::MeshDecoder::new()
        .decode(&mut draco_core::DecoderBuffer::new(stream), &mut mesh)
        .map_err(|e| format!("cannot decode the Draco stream in bufferViews[{view_index}]: {e}"))?;
    let points = mesh.num_points();

    let indices: Vec<u8> = mesh.faces().iter().flatten().flat_map(|i| i.0.to_le_bytes()).collect();
    let face_count = mesh.num_faces();
    let indices_accessor = root.meshes[m].primitives[p].indices.ok_or("the primitive has no `indices` accessor")?;
    let buffer = push_buffer(root, buffers, indices);
    let view = new_view(root, view_index, buffer, face_count * 12);
    let accessor = accessor_mut(root, indices_accessor.value())?;
    accessor.buffer_view = Some(view);
    accessor.byte_offset = None;
    accessor.count = USize64::from(face_count * 3);
    accessor.component_type = Checked::Valid(GenericComponentType(ComponentType::U32));
    accessor.normalized = false;

    let attributes = ext.get("attributes").and_then(Value::as_object).ok_or("has no `attributes` object")?;
    for (name, id) in attributes {
        let id = id.as_u64().ok_or_else(|| format!("attributes.{name} is not an attribute id"))? as u32;
        let Some(semantic) = semantic(name) else {
            // An application-specific attribute (`_NAME`) hikari does not read.
            continue;
        };
        let Some(&accessor_index) = root.meshes[m].primitives[p].attributes.get(&Checked::Valid(semantic)) else {
            return Err(format!("attributes.{name} names an attribute the primitive does not have"));
        };
        let attribute = mesh
            .attribute_by_unique_id(id)
            .ok_or_else(|| format!("attributes.{name}: the Draco stream has no attribute with id {id}"))?;
        let accessor = accessor_mut(root, accessor_index.value())?;
        let (Checked::Valid(kind), Checked::Valid(GenericComponentType(component))) =
            (accessor.type_, accessor.component_type)
        else {
            return Err(format!("attributes.{name}: its accessor has an invalid type"));
        };
        let components = kind.multiplicity();
        let raw_integers =
            !matches!(attribute.data_type(), draco_core::DataType::Float32 | draco_core::DataType::Float64);
        let values = attribute.read_f32s(points, components);
        let normalized = accessor.normalized;
        let bytes: Vec<u8> = values.iter().flat_map(|&v| encode(v, component, normalized && !raw_integers)).collect();
        let length = bytes.len();
        let buffer = push_buffer(root, buffers, bytes);
        let view = new_view(root, view_index, buffer, length);
        let accessor = accessor_mut(root, accessor_index.value())?;
        accessor.buffer_view = Some(view);
        accessor.byte_offset = None;
        accessor.count = USize64::from(points);
    }
    Ok(())
}

fn accessor_mut(root: &mut Root, index: usize) -> Result<&mut gltf::json::Accessor, String> {
    let count = root.accessors.len();
    root.accessors.get_mut(index).ok_or_else(|| format!("accessor {index} does not exist ({count} accessors)"))
}

/// A new buffer view (a copy of `template`, re-pointed) over all of `buffer`.
fn new_view(root: &mut Root, template: usize, buffer: u32, length: usize) -> Index<gltf::json::buffer::View> {
    let mut view = root.buffer_views[template].clone();
    point_view_at(&mut view, buffer, length);
    view.byte_stride = None;
    view.target = None;
    root.buffer_views.push(view);
    Index::new(root.buffer_views.len() as u32 - 1)
}

/// A glTF attribute name as the JSON's semantic.
fn semantic(name: &str) -> Option<gltf::json::mesh::Semantic> {
    let value = Value::String(name.to_string());
    match gltf::json::deserialize::from_value::<Checked<gltf::json::mesh::Semantic>>(value) {
        Ok(Checked::Valid(s)) => Some(s),
        _ => None,
    }
}

/// One component in `component`'s little-endian bytes: a float's value
/// scaled to a normalized integer's range where `normalize`, else rounded.
fn encode(value: f32, component: ComponentType, normalize: bool) -> Vec<u8> {
    let scaled = |max: f32| if normalize { (value * max).round() } else { value.round() };
    match component {
        ComponentType::F32 => value.to_le_bytes().to_vec(),
        ComponentType::I8 => (scaled(127.0) as i8).to_le_bytes().to_vec(),
        ComponentType::U8 => (scaled(255.0) as u8).to_le_bytes().to_vec(),
        ComponentType::I16 => (scaled(32767.0) as i16).to_le_bytes().to_vec(),
        ComponentType::U16 => (scaled(65535.0) as u16).to_le_bytes().to_vec(),
        ComponentType::U32 => (scaled(u32::MAX as f32) as u32).to_le_bytes().to_vec(),
    }
}
