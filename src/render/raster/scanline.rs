//! The span-filling rasterizer of Computer Graphics from Scratch ("Filled
//! triangles", "Shaded triangles", "Depth buffering"): sort the vertices by y,
//! walk the long edge and the two short edges row by row, and fill the span
//! between them, interpolating attributes along the edges and then across the
//! span (each sample evaluated from the span's ends). The interpolated attribute here is the vector of screen-space weights,
//! which the shared fragment code turns into 1/z and perspective-correct
//! barycentrics (the book's 1/z interpolation). It runs on the same clipped
//! triangles as every other variant and samples at the pass's sample positions.

use crate::render::raster::rect::{PixelRect, TestCounter};
use crate::render::raster::setup::ScreenTri;
use crate::math::{Vec2, Vec3};

/// Position and interpolated weights where the edge `a -> b` crosses row `ys`.
#[inline(always)]
fn edge_at_row(a: (Vec2, Vec3), b: (Vec2, Vec3), ys: f32) -> (f32, Vec3) {
    let dy = b.0.y - a.0.y;
    let s = if dy > 0.0 { ((ys - a.0.y) / dy).clamp(0.0, 1.0) } else { 0.0 };
    (a.0.x + (b.0.x - a.0.x) * s, a.1 + (b.1 - a.1) * s)
}

/// Visits the covered samples of `st` inside `rect`; the samples tested are the spans.
#[inline]
pub fn raster<F: FnMut(u32, u32, [f32; 3])>(st: &ScreenTri, rect: PixelRect, off: Vec2, tested: &mut impl TestCounter, mut emit: F) {
    let r = st.bbox.intersect(&rect);
    if r.is_empty() {
        return;
    }
    let mut v = [(st.p[0], Vec3::X), (st.p[1], Vec3::Y), (st.p[2], Vec3::Z)];
    v.sort_by(|a, b| a.0.y.total_cmp(&b.0.y));
    let [v0, v1, v2] = v;
    for y in r.y0..r.y1 {
        let ys = y as f32 + off.y;
        if ys < v0.0.y || ys > v2.0.y {
            continue;
        }
        let long = edge_at_row(v0, v2, ys);
        let short = if ys < v1.0.y { edge_at_row(v0, v1, ys) } else { edge_at_row(v1, v2, ys) };
        let (left, right) = if long.0 <= short.0 { (long, short) } else { (short, long) };
        let x0 = ((left.0 - off.x).ceil().max(r.x0 as f32)) as u32;
        let x1 = (((right.0 - off.x).floor() + 1.0).min(r.x1 as f32)).max(0.0) as u32;
        if x0 >= x1 {
            continue;
        }
        tested.add(PixelRect::new(x0, y, x1, y + 1));
        // Across the span: each sample's weights from the span's ends (a running
        // sum `w += step` drifts enough over a long span to move texture lookups).
        let width = right.0 - left.0;
        let inv_width = if width > 0.0 { 1.0 / width } else { 0.0 };
        for x in x0..x1 {
            let s = (x as f32 + off.x - left.0) * inv_width;
            let w = left.1 + (right.1 - left.1) * s;
            emit(x, y, [w.x, w.y, w.z]);
        }
    }
}
