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

/// The most elements an accessor without a buffer view may have (its
/// zeros are allocated; a fuzzed count asked for 64 GiB).
const MAX_ZERO_ELEMENTS: usize = 1 << 24;

/// An accessor's elements, checked to lie inside their buffer.
struct Layout<'a> {
    bytes: &'a [u8],
    offset: usize,
    stride: usize,
    count: usize,
    data_type: DataType,
    /// False: no buffer view, every element zero before the sparse
    /// substitutions (the specification's rule).
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
    let count = accessor.count();
    let element = data_type.size() * components;
    let Some(view) = accessor.view() else {
        // Zeros cost memory the file does not: a count no buffer backs is bounded.
        if count > MAX_ZERO_ELEMENTS {
            return Err(format!(
                "has no buffer view and {count} elements, more than the {MAX_ZERO_ELEMENTS} hikari reads as zeros"
            ));
        }
        return Ok(Layout { bytes: &[], offset: 0, stride: 0, count, data_type, present: false });
    };
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!("has a byte stride of {stride}, less than its element size {element}"));
    }
    let bytes = view_bytes(&view, buffers)?;
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

/// The bytes of `view`, checked to lie in its buffer.
fn view_bytes<'a>(view: &gltf::buffer::View, buffers: &'a [gltf::buffer::Data]) -> Result<&'a [u8], String> {
    let data = buffers.get(view.buffer().index()).ok_or("refers to a buffer that was not loaded")?;
    let end = view.offset().checked_add(view.length()).filter(|&e| e <= data.len()).ok_or_else(|| {
        format!(
            "reads bufferViews[{}] (bytes {}..{}), beyond its buffer's {} bytes",
            view.index(),
            view.offset(),
            view.offset() as u64 + view.length() as u64,
            data.len()
        )
    })?;
    Ok(&data[view.offset()..end])
}

/// `count` elements of `size` bytes, tightly packed from `offset` in
/// `view` (a sparse accessor's indices or values), checked to fit.
fn packed<'a>(
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    size: usize,
    what: &str,
    buffers: &'a [gltf::buffer::Data],
) -> Result<&'a [u8], String> {
    let bytes = view_bytes(view, buffers)?;
    let end = count.checked_mul(size).and_then(|n| n.checked_add(offset));
    match end {
        Some(end) if end <= bytes.len() => Ok(&bytes[offset..end]),
        _ => Err(format!(
            "has sparse {what} out of range: {count} of {size} bytes at offset {offset} do not fit in bufferViews[{}] ({} bytes)",
            view.index(),
            bytes.len()
        )),
    }
}

/// A sparse accessor's substitutions: (element index, that element's
/// bytes), the indices checked to be below the accessor's count and
/// increasing (the specification's rule). Empty where it is not sparse.
fn sparse<'a>(
    accessor: &gltf::Accessor,
    buffers: &'a [gltf::buffer::Data],
    element: usize,
) -> Result<Vec<(usize, &'a [u8])>, String> {
    let Some(sparse) = accessor.sparse() else { return Ok(Vec::new()) };
    let n = sparse.count();
    let indices = sparse.indices();
    let index_size = match indices.index_type() {
        gltf::accessor::sparse::IndexType::U8 => 1,
        gltf::accessor::sparse::IndexType::U16 => 2,
        gltf::accessor::sparse::IndexType::U32 => 4,
    };
    let index_bytes = packed(&indices.view(), indices.offset(), n, index_size, "indices", buffers)?;
    let values = sparse.values();
    let value_bytes = packed(&values.view(), values.offset(), n, element, "values", buffers)?;
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let b = &index_bytes[k * index_size..];
        let index = match index_size {
            1 => b[0] as usize,
            2 => u16::from_le_bytes([b[0], b[1]]) as usize,
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
        };
        if index >= accessor.count() {
            return Err(format!("has sparse index {index} (entry {k}) beyond its {} elements", accessor.count()));
        }
        if out.last().is_some_and(|&(last, _)| last >= index) {
            return Err(format!("has sparse indices that do not increase (entry {k}: {index})"));
        }
        out.push((index, &value_bytes[k * element..(k + 1) * element]));
    }
    Ok(out)
}

/// Reads an accessor of `N` components per element, converted to f32.
/// `allowed` lists the component types the attribute may use.
pub fn read<const N: usize>(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    allowed: &[DataType],
) -> Result<Vec<[f32; N]>, String> {
    let l = layout(accessor, buffers, N, allowed)?;
    let (size, normalized) = (l.data_type.size(), accessor.normalized());
    let decode = |e: &[u8]| std::array::from_fn(|c| component(&e[c * size..], l.data_type, normalized));
    let mut out: Vec<[f32; N]> =
        if l.present { (0..l.count).map(|i| decode(l.element(i))).collect() } else { vec![[0.0; N]; l.count] };
    for (i, e) in sparse(accessor, buffers, size * N)? {
        out[i] = decode(e);
    }
    Ok(out)
}

/// Reads an index accessor (unsigned scalars) as u32, exactly.
pub fn read_indices(accessor: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> Result<Vec<u32>, String> {
    if accessor.normalized() {
        return Err("indices are marked normalized".into());
    }
    let l = layout(accessor, buffers, 1, &[DataType::U8, DataType::U16, DataType::U32])?;
    let decode = |e: &[u8]| match l.data_type {
        DataType::U8 => e[0] as u32,
        DataType::U16 => u16::from_le_bytes([e[0], e[1]]) as u32,
        _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
    };
    let mut out: Vec<u32> =
        if l.present { (0..l.count).map(|i| decode(l.element(i))).collect() } else { vec![0; l.count] };
    for (i, e) in sparse(accessor, buffers, l.data_type.size())? {
        out[i] = decode(e);
    }
    Ok(out)
}
