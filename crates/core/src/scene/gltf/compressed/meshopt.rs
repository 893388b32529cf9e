//! `EXT_meshopt_compression`: buffer views stored as meshoptimizer's vertex
//! or index codec (what gltfpack `-c` writes), decoded with the pure-Rust
//! port of meshoptimizer (so the web page reads them too), including the
//! octahedral, quaternion and exponential filters.

use super::{point_view_at, push_buffer};
use gltf::json::{Root, Value};
use meshoptimizer_rs::codec::{BufferView, Filter, Mode};

/// The extension's name.
pub const MESHOPT: &str = "EXT_meshopt_compression";

/// The extension object of a view, as the specification lays it out.
struct Compressed {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
}

impl Compressed {
    fn from_json(value: &Value) -> Result<Compressed, String> {
        let number = |key: &str, default: Option<u64>| {
            value
                .get(key)
                .map_or(default, Value::as_u64)
                .map(|n| n as usize)
                .ok_or_else(|| format!("has no valid `{key}` (a non-negative integer is required)"))
        };
        let text = |key: &str, default: Option<&str>| {
            value
                .get(key)
                .map_or(default, Value::as_str)
                .map(str::to_string)
                .ok_or_else(|| format!("has no valid `{key}`"))
        };
        Ok(Compressed {
            buffer: number("buffer", None)?,
            offset: number("byteOffset", Some(0))?,
            length: number("byteLength", None)?,
            stride: number("byteStride", None)?,
            count: number("count", None)?,
            mode: text("mode", None)?,
            filter: text("filter", Some("NONE"))?,
        })
    }
}

/// Decodes every compressed buffer view of `root` into a buffer of its
/// own; errors are (glTF path, message).
pub fn decode(root: &mut Root, buffers: &mut Vec<gltf::buffer::Data>) -> Result<(), (String, String)> {
    let mut workspace = meshoptimizer_rs::Workspace::new(meshoptimizer_rs::Limits {
        // The default (1 GiB of output) would refuse a large but valid scene.
        max_bytes: usize::MAX,
        max_work: u64::MAX,
    });
    for v in 0..root.buffer_views.len() {
        let Some(ext) = root.buffer_views[v].extensions.as_ref().and_then(|e| e.others.get(MESHOPT)) else {
            continue;
        };
        let at = format!("bufferViews[{v}].extensions.{MESHOPT}");
        let c = Compressed::from_json(ext).map_err(|m| (at.clone(), m))?;
        let source =
            buffers.get(c.buffer).and_then(|b| b.get(c.offset..c.offset.checked_add(c.length)?)).ok_or_else(|| {
                let size = buffers.get(c.buffer).map_or("no such buffer".into(), |b| format!("{} bytes", b.len()));
                (at.clone(), format!("reads bytes {}..+{} of buffers[{}] ({size})", c.offset, c.length, c.buffer))
            })?;
        let mode = Mode::parse(&c.mode).map_err(|_| (at.clone(), format!("has unknown mode \"{}\"", c.mode)))?;
        let filter =
            Filter::parse(&c.filter).map_err(|_| (at.clone(), format!("has unknown filter \"{}\"", c.filter)))?;
        let layout = BufferView::new(mode, filter, c.count, c.stride).map_err(|e| {
            (
                at.clone(),
                format!(
                    "has an invalid layout ({e}): mode {}, filter {}, count {}, byteStride {}",
                    c.mode, c.filter, c.count, c.stride
                ),
            )
        })?;
        let view_length = root.buffer_views[v].byte_length.0 as usize;
        if layout.byte_length() > view_length {
            return Err((
                at,
                format!("decodes to {} bytes, more than its view's byteLength {view_length}", layout.byte_length()),
            ));
        }
        let decoded =
            layout.decode(source, &mut workspace).map_err(|e| (at.clone(), format!("cannot be decoded: {e}")))?;
        let length = decoded.len();
        let buffer = push_buffer(root, buffers, decoded);
        point_view_at(&mut root.buffer_views[v], buffer, length);
    }
    Ok(())
}
