//! Reading glTF accessors with every offset checked against its buffer.
//!
//! The `gltf` crate's readers trust the file (a zero count underflows, a
//! stride smaller than the element trips a debug assertion, a view past its
//! buffer yields nothing silently), so hikari reads accessors itself: each
//! read either returns every element or an error that names what is wrong.

use gltf::accessor::{DataType, Dimensions};

/// Converts one component to f32 as the glTF specification says: floats as
/// they are, normalized integers to [0, 1] or [−1, 1], others by value.
fn component(bytes: &[u8], data_type: DataType, normalized: bool) -> f32 {
    let le2 = |b: &[u8]| [b[0], b[1]];
    match data_type {
        DataType::F32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
        DataType::U32 => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
        DataType::U8 if normalized => bytes[0] as f32 / 255.0,
        DataType::U8 => bytes[0] as f32,
        DataType::I8 if normalized => (bytes[0] as i8 as f32 / 127.0).max(-1.0),
        DataType::I8 => bytes[0] as i8 as f32,
        DataType::U16 if normalized => u16::from_le_bytes(le2(bytes)) as f32 / 65535.0,
        DataType::U16 => u16::from_le_bytes(le2(bytes)) as f32,
        DataType::I16 if normalized => (i16::from_le_bytes(le2(bytes)) as f32 / 32767.0).max(-1.0),
        DataType::I16 => i16::from_le_bytes(le2(bytes)) as f32,
    }
}

fn dimension_count(d: Dimensions) -> usize {
    match d {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// An accessor's elements, checked to lie inside their buffer.
struct Layout<'a> {
    bytes: &'a [u8],
    offset: usize,
    stride: usize,
    count: usize,
    data_type: DataType,
    /// None: no buffer view, every element zero (the specification's rule).
    present: bool,
}

impl Layout<'_> {
    fn element(&self, i: usize) -> &[u8] {
        &self.bytes[self.offset + i * self.stride..]
    }
}

fn layout<'a>(
    accessor: &gltf::Accessor,
    buffers: &'a [gltf::buffer::Data],
    components: usize,
    allowed: &[DataType],
) -> Result<Layout<'a>, String> {
    let (data_type, dims) = (accessor.data_type(), accessor.dimensions());
    if dimension_count(dims) != components {
        return Err(format!("has {dims:?} elements where {components} components are needed"));
    }
    if !allowed.contains(&data_type) {
        return Err(format!("has components of type {data_type:?} (allowed here: {allowed:?})"));
    }
    if accessor.sparse().is_some() {
        return Err("is sparse, which hikari does not read".into());
    }
    let count = accessor.count();
    let element = data_type.size() * components;
    let Some(view) = accessor.view() else {
        return Ok(Layout { bytes: &[], offset: 0, stride: 0, count, data_type, present: false });
    };
    let data = buffers.get(view.buffer().index()).ok_or("refers to a buffer that was not loaded")?;
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!("has a byte stride of {stride}, less than its element size {element}"));
    }
    let view_end = view.offset().checked_add(view.length()).filter(|&e| e <= data.len()).ok_or_else(|| {
        format!(
            "reads bufferViews[{}] (bytes {}..{}), beyond its buffer's {} bytes",
            view.index(),
            view.offset(),
            view.offset() as u64 + view.length() as u64,
            data.len()
        )
    })?;
    let bytes = &data[view.offset()..view_end];
    if count > 0 {
        let end = (count - 1).checked_mul(stride).and_then(|x| x.checked_add(accessor.offset() + element));
        if end.is_none_or(|end| end > bytes.len()) {
            return Err(format!(
                "is out of range: {count} elements of {element} bytes at offset {} with stride {stride} \
                 do not fit in bufferViews[{}] ({} bytes)",
                accessor.offset(),
                view.index(),
                bytes.len()
            ));
        }
    }
    Ok(Layout { bytes, offset: accessor.offset(), stride, count, data_type, present: true })
}

/// Reads an accessor of `N` components per element, converted to f32.
/// `allowed` lists the component types the attribute may use.
pub fn read<const N: usize>(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    allowed: &[DataType],
) -> Result<Vec<[f32; N]>, String> {
    let l = layout(accessor, buffers, N, allowed)?;
    if !l.present {
        return Ok(vec![[0.0; N]; l.count]);
    }
    let (size, normalized) = (l.data_type.size(), accessor.normalized());
    Ok((0..l.count)
        .map(|i| {
            let e = l.element(i);
            std::array::from_fn(|c| component(&e[c * size..], l.data_type, normalized))
        })
        .collect())
}

/// Reads an index accessor (unsigned scalars) as u32, exactly.
pub fn read_indices(accessor: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> Result<Vec<u32>, String> {
    if accessor.normalized() {
        return Err("indices are marked normalized".into());
    }
    let l = layout(accessor, buffers, 1, &[DataType::U8, DataType::U16, DataType::U32])?;
    if !l.present {
        return Ok(vec![0; l.count]);
    }
    Ok((0..l.count)
        .map(|i| {
            let e = l.element(i);
            match l.data_type {
                DataType::U8 => e[0] as u32,
                DataType::U16 => u16::from_le_bytes([e[0], e[1]]) as u32,
                _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
            }
        })
        .collect())
}
