//! Stores that bypass the cache, for long runs of an image that nothing
//! reads again while the frame is drawn (the background around what a
//! rasterizer sees). An ordinary store first reads its 64-byte line from
//! memory, to own it, and writes it back later; a streaming store of whole
//! lines only writes. A frame's output is megabytes, far more than a core's
//! cache, so its empty rows cost about half the memory traffic this way.
//!
//! Streaming stores are ordered weakly: a thread that made them calls
//! `fence` before another thread may read what they wrote.

use crate::math::Vec3;

/// Runs shorter than this many values are stored the ordinary way: they
/// would fill few whole lines, and the part-lines at their ends would cost
/// more than streaming saves.
const SHORTEST_STREAMED: usize = 32;

/// Sets every value of `out` to `value`, streaming the whole 64-byte lines
/// of a long run past the cache; true when it did (the run's lines are then
/// not in cache). Call `fence` before the values are read by another
/// thread.
#[inline]
pub fn fill(out: &mut [Vec3], value: Vec3) -> bool {
    #[cfg(target_arch = "x86_64")]
    if out.len() >= SHORTEST_STREAMED {
        fill_streamed(out, value);
        return true;
    }
    out.fill(value);
    false
}

/// Makes the streaming stores of this thread visible before any store
/// after it (the release of the work to another thread).
#[inline]
pub fn fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64; the fence has no operands.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}

#[cfg(target_arch = "x86_64")]
fn fill_streamed(out: &mut [Vec3], value: Vec3) {
    use std::arch::x86_64::{_mm_loadu_ps, _mm_stream_ps};
    const FLOATS_PER_LINE: usize = 16;
    let components = [value.x, value.y, value.z];
    // The run as floats: float k holds component k % 3 of its value.
    let floats: &mut [f32] = bytemuck::cast_slice_mut(out);
    let n = floats.len();
    // Whole lines only: the floats before the first line boundary and
    // after the last one are stored the ordinary way.
    let misaligned = floats.as_ptr() as usize % 64 / 4;
    let start = ((FLOATS_PER_LINE - misaligned) % FLOATS_PER_LINE).min(n);
    let end = start + (n - start) / FLOATS_PER_LINE * FLOATS_PER_LINE;
    for (k, f) in floats[..start].iter_mut().enumerate() {
        *f = components[k % 3];
    }
    // Three vectors of four floats repeat the three components; the line
    // starts at component `start % 3`.
    let pattern: [f32; 12] = std::array::from_fn(|j| components[(start + j) % 3]);
    // SAFETY: SSE is part of x86-64; the loads read the 12 floats of
    // `pattern`.
    let (mut a, mut b, mut c) = unsafe { (_mm_loadu_ps(pattern.as_ptr()), _mm_loadu_ps(pattern.as_ptr().add(4)), _mm_loadu_ps(pattern.as_ptr().add(8))) };
    for chunk in floats[start..end].chunks_exact_mut(4) {
        // SAFETY: `chunk` is four floats starting on a 16-byte boundary
        // (`start` begins a line, and lines hold whole chunks).
        unsafe { _mm_stream_ps(chunk.as_mut_ptr(), a) };
        (a, b, c) = (b, c, a);
    }
    for (k, f) in floats[end..].iter_mut().enumerate() {
        *f = components[(end + k) % 3];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every run length and every start within a line (the slice begins at
    /// each float offset of a 64-byte line) is filled with the value, and
    /// the values around the run are left as they were.
    #[test]
    fn fills_every_value_of_runs_of_any_length_and_alignment() {
        let value = Vec3::new(0.25, -1.5, 7.0);
        let before = Vec3::new(9.0, 9.0, 9.0);
        for offset in 0..16 {
            for len in [0, 1, 5, 31, 32, 33, 47, 64, 100, 1280] {
                let mut image = vec![before; offset + len + 3];
                fill(&mut image[offset..offset + len], value);
                fence();
                for (i, v) in image.iter().enumerate() {
                    let expected = if (offset..offset + len).contains(&i) { value } else { before };
                    assert_eq!(*v, expected, "offset {offset} len {len} index {i}");
                }
            }
        }
    }
}
