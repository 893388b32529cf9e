//! Compressed geometry, decoded before anything reads an accessor:
//! `EXT_meshopt_compression` buffer views ([`meshopt`]) and
//! `KHR_draco_mesh_compression` primitives ([`draco`]). Each decoded stream
//! becomes a buffer of its own with a plain buffer view onto it, so the
//! accessors read it exactly as they read an uncompressed file.

mod draco;
mod meshopt;

use super::error;
use crate::scene::SceneError;
use gltf::json::Root;
use gltf::json::validation::USize64;

pub use draco::DRACO;
pub use meshopt::MESHOPT;

/// The document with its compressed views and primitives replaced by
/// decoded ones in new buffers (appended to `buffers`); the same document
/// where the file uses neither extension.
pub fn decode(gltf: gltf::Gltf, buffers: &mut Vec<gltf::buffer::Data>, file: &str) -> Result<gltf::Gltf, SceneError> {
    let used = |name: &str| gltf.document.extensions_used().any(|e| e == name);
    if !used(MESHOPT) && !used(DRACO) {
        return Ok(gltf);
    }
    let gltf::Gltf { document, blob } = gltf;
    let mut root = document.into_json();
    meshopt::decode(&mut root, buffers).map_err(|(at, m)| error(file, at, m))?;
    draco::decode(&mut root, buffers).map_err(|(at, m)| error(file, at, m))?;
    Ok(gltf::Gltf { document: gltf::Document::from_json_without_validation(root), blob })
}

/// Appends `bytes` as a new buffer and returns its index (in `root` and in
/// `buffers` alike).
fn push_buffer(root: &mut Root, buffers: &mut Vec<gltf::buffer::Data>, mut bytes: Vec<u8>) -> u32 {
    let length = bytes.len();
    bytes.resize(length.next_multiple_of(4), 0);
    let index = root.buffers.len() as u32;
    root.buffers.push(gltf::json::Buffer {
        byte_length: USize64::from(length),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    buffers.push(gltf::buffer::Data(bytes));
    index
}

/// `view` pointed at the whole of buffer `buffer`, its compression gone.
fn point_view_at(view: &mut gltf::json::buffer::View, buffer: u32, length: usize) {
    view.buffer = gltf::json::Index::new(buffer);
    view.byte_offset = None;
    view.byte_length = USize64::from(length);
    view.extensions = None;
}

#[cfg(test)]
mod tests;
