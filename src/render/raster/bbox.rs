//! The naive rasterizer restricted to each triangle's screen-space bounding box
//! (CGPP listings 15.23 and 15.24): the same 3D ray test, far fewer samples
//! tested. The box is that of the triangle's near-clipped projection, grown by
//! one pixel so that rounding can never lose a sample the ray test would hit;
//! the images equal the naive rasterizer's. The pass is in `pass.rs`.

use crate::render::raster::rect::PixelRect;
use crate::render::raster::setup::setup_pass;
use crate::render::PassJob;

/// Per scene triangle with any visible piece: its index and the box of all its pieces.
pub fn triangle_boxes(job: &PassJob) -> Vec<(u32, PixelRect)> {
    let (w, h) = (job.view.width, job.view.height);
    let mut boxes: Vec<(u32, PixelRect)> = Vec::new();
    for st in setup_pass(job) {
        let b = st.bbox.grown(1, w, h);
        match boxes.last_mut() {
            Some((tri, r)) if *tri == st.tri => {
                *r = PixelRect::new(r.x0.min(b.x0), r.y0.min(b.y0), r.x1.max(b.x1), r.y1.max(b.y1));
            }
            _ => boxes.push((st.tri, b)),
        }
    }
    boxes
}
