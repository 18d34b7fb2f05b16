//! Edge functions stepped by additions (float): the classic half-space
//! rasterizer. Each edge function is affine in the image, so moving one pixel
//! right adds a constant; each row starts from one direct evaluation. A sample is
//! covered when all three are >= 0 (edges inclusive, no fill rule: a sample
//! exactly on a shared edge is drawn by both triangles and the depth test keeps
//! the earlier one; rounding in the stepped sums can leave rare holes, which
//! the `fixed` variant removes).

use crate::render::raster::rect::{tested_rect, PixelRect, TestCounter};
use crate::render::raster::setup::{edge_function, ScreenTri};
use crate::math::Vec2;

/// Visits the covered samples of `st` inside `rect` with their screen-space
/// weights; adds the samples tested to `tested`.
#[inline]
pub fn raster<F: FnMut(u32, u32, [f32; 3])>(st: &ScreenTri, rect: PixelRect, off: Vec2, tested: &mut impl TestCounter, mut emit: F) {
    let Some(r) = tested_rect(&st.bbox, &rect, tested) else {
        return;
    };
    let p = st.p;
    let inv_area = st.inv_area;
    // Edge k is the one opposite vertex k: E_k(q) = a_k q.x + b_k q.y + c_k.
    let ends = [(p[1], p[2]), (p[2], p[0]), (p[0], p[1])];
    let a = ends.map(|(s, e)| s.y - e.y);
    for y in r.y0..r.y1 {
        // Each row starts from a direct evaluation, so a row's values do not
        // depend on which band or tile it was rasterized in.
        let start = Vec2::new(r.x0 as f32 + off.x, y as f32 + off.y);
        let mut e = [0usize, 1, 2].map(|k| edge_function(ends[k].0, ends[k].1, start));
        for x in r.x0..r.x1 {
            if e[0] >= 0.0 && e[1] >= 0.0 && e[2] >= 0.0 {
                emit(x, y, [e[0] * inv_area, e[1] * inv_area, e[2] * inv_area]);
            }
            e[0] += a[0];
            e[1] += a[1];
            e[2] += a[2];
        }
    }
}
