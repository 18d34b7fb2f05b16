//! 2D barycentric weights per pixel (CGPP 15.6.4.3, listings 15.25 to 15.28):
//! each weight is the distance of the sample from the opposite edge's line
//! divided by the distance of the vertex from that line. The sample is covered
//! when all weights are >= 0; the weights then interpolate 1/z and the
//! attributes over z (perspective-correct, CGPP 15.6.4.2).

use crate::render::raster::rect::{tested_rect, PixelRect, TestCounter};
use crate::render::raster::setup::ScreenTri;
use crate::math::Vec2;

/// Signed distance of `q` from the line through `a` and `b`: the line's normal
/// dotted with `q - a` (equal to `n.q + d` with `d = -n.a`, without the
/// cancellation between two large terms that form suffers far from the origin).
#[inline(always)]
pub fn line_distance(a: Vec2, b: Vec2, q: Vec2) -> f32 {
    let n = Vec2::new(a.y - b.y, b.x - a.x);
    n.dot(q - a) / n.length()
}

/// The barycentric weight of vertex `a` at `q` in the 2D triangle `a, b, c`.
#[inline(always)]
pub fn bary2d(a: Vec2, b: Vec2, c: Vec2, q: Vec2) -> f32 {
    line_distance(b, c, q) / line_distance(b, c, a)
}

/// Visits the covered samples of `st` inside `rect` with their screen-space weights.
#[inline]
pub fn raster<F: FnMut(u32, u32, [f32; 3])>(st: &ScreenTri, rect: PixelRect, off: Vec2, tested: &mut impl TestCounter, mut emit: F) {
    let Some(r) = tested_rect(&st.bbox, &rect, tested) else {
        return;
    };
    let [p0, p1, p2] = st.p;
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            let q = Vec2::new(x as f32 + off.x, y as f32 + off.y);
            let l = [bary2d(p0, p1, p2, q), bary2d(p1, p2, p0, q), bary2d(p2, p0, p1, q)];
            if l[0] >= 0.0 && l[1] >= 0.0 && l[2] >= 0.0 {
                emit(x, y, l);
            }
        }
    }
}
