//! Reading glTF accessors: every accessor's range is checked against its
//! buffer view and the view's against its buffer before a byte is read,
//! so a file that lies about its sizes is an error naming the accessor,
//! never a read out of bounds.

use gltf::accessor::{DataType, Dimensions};

/// The accessor's elements as `N` floats each (normalized integers scaled
/// to [0, 1] or [-1, 1] as glTF says).
pub fn read_floats<const N: usize>(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<[f32; N]>, String> {
    let dims = acc.dimensions().multiplicity();
    if dims != N {
        return Err(format!("accessor {} has {dims} components per element, expected {N}", acc.index()));
    }
    let ty = acc.data_type();
    let normalized = acc.normalized();
    let mut out = Vec::with_capacity(room(acc, buffers));
    for_each_element(acc, buffers, |bytes| {
        let mut e = [0.0f32; N];
        for (k, v) in e.iter_mut().enumerate() {
            let c = component(bytes, k, ty);
            *v = match (normalized, ty) {
                (true, DataType::I8) => (c / 127.0).max(-1.0),
                (true, DataType::U8) => c / 255.0,
                (true, DataType::I16) => (c / 32767.0).max(-1.0),
                (true, DataType::U16) => c / 65535.0,
                _ => c,
            } as f32;
        }
        out.push(e);
    })?;
    Ok(out)
}

/// An index accessor's values (unsigned byte, short or int scalars).
pub fn read_indices(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    let ty = acc.data_type();
    if acc.dimensions() != Dimensions::Scalar || !matches!(ty, DataType::U8 | DataType::U16 | DataType::U32) {
        return Err(format!("accessor {} holds indices but is not unsigned integer scalars", acc.index()));
    }
    let mut out = Vec::with_capacity(room(acc, buffers));
    for_each_element(acc, buffers, |bytes| out.push(component(bytes, 0, ty) as u32))?;
    Ok(out)
}

/// Elements to reserve room for: the accessor's count, but never more
/// than the buffers' bytes can hold (the count is checked while reading).
fn room(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> usize {
    let size = acc.data_type().size() * acc.dimensions().multiplicity();
    acc.count().min(buffers.iter().map(Vec::len).sum::<usize>() / size.max(1))
}

/// Component `k` of one element's bytes, as a number.
fn component(bytes: &[u8], k: usize, ty: DataType) -> f64 {
    let s = ty.size();
    let b = &bytes[k * s..k * s + s];
    match ty {
        DataType::I8 => b[0] as i8 as f64,
        DataType::U8 => b[0] as f64,
        DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
        DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
    }
}

/// Hands each element's bytes to `f`, after checking that every one lies
/// inside the accessor's buffer view and the view inside its buffer.
fn for_each_element(acc: &gltf::Accessor, buffers: &[Vec<u8>], mut f: impl FnMut(&[u8])) -> Result<(), String> {
    let i = acc.index();
    if acc.sparse().is_some() {
        return Err(format!("accessor {i} is sparse, which pinhole does not read"));
    }
    let view = acc.view().ok_or(format!("accessor {i} has no buffer view (zero-filled accessors are not read)"))?;
    let buffer = &buffers[view.buffer().index()];
    let view_end = view.offset().checked_add(view.length()).filter(|&e| e <= buffer.len()).ok_or(format!(
        "buffer view {} (bytes {} to {}) runs past the end of buffer {} ({} bytes)",
        view.index(),
        view.offset(),
        view.offset().saturating_add(view.length()),
        view.buffer().index(),
        buffer.len()
    ))?;
    let size = acc.data_type().size() * acc.dimensions().multiplicity();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!("buffer view {} has a stride of {stride} bytes, less than accessor {i}'s {size}-byte elements", view.index()));
    }
    let start = view.offset().saturating_add(acc.offset());
    let count = acc.count();
    if count == 0 {
        return Ok(());
    }
    let end = (count - 1).checked_mul(stride).and_then(|s| s.checked_add(start)).and_then(|s| s.checked_add(size));
    if end.is_none_or(|e| e > view_end) {
        return Err(format!("accessor {i} ({count} elements from byte {}) reads past the end of buffer view {}", acc.offset(), view.index()));
    }
    for k in 0..count {
        let at = start + k * stride;
        f(&buffer[at..at + size]);
    }
    Ok(())
}
