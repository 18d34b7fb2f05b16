//! Triangles too small for the sub-pixel grid of the fixed-point variants
//! (`fixed`, `tiled`, and the painter, which draws with `fixed`'s coverage):
//! coverage and barycentrics by the ray casters' 3D test.
//!
//! Snapping moves each vertex by up to half a grid unit (1/512 pixel) on each
//! axis. On a triangle a few units across that moves its edges by a good part
//! of its size: the distant bunnies of `forest` at 160x90 are made of
//! triangles 1 to 64 units across, and their snapped copies cover samples the
//! true ones miss (2D weights down to -0.16 at the sample). Exact 2D coverage
//! would not be enough either: projected vertices are f32 pixel positions,
//! good to about 2^-24 of the coordinate, so on a triangle a fraction of a
//! pixel across, far from the image's origin, the 2D weights differ from the
//! ray test's by 1e-4 to 1e-3, and so does the shading (the float
//! `rasterize:barycentric` differs from `raytrace` on 2.1% of `forest`'s
//! pixels at 160x90 for that reason alone).
//!
//! So a triangle whose snapped vertices span fewer than `SMALL_LIMIT` units (half a
//! pixel) on both axes is drawn as `rasterize:bbox` draws every triangle: the
//! eye ray of each sample in its box grown by a pixel goes through
//! `intersect_triangle`, as in the ray tracer, and a hit gives the
//! barycentrics the ray tracer computes; the depth key is -1/z of the hit.
//! On `forest`, pixels differing from `raytrace` by more than 1e-4 relative,
//! against this limit (0: every triangle on the grid; `pinhole compare`):
//!
//! | limit (units) | 0 | 32 | 64 | 128 | 256 |
//! |---|---:|---:|---:|---:|---:|
//! | 160x90 | 4.81% | 0.01% | 0 | 0 | 0 |
//! | 1280x720 | 2.63% | 1.90% | 0.91% | 0.25% | 0.003% |
//!
//! Half a pixel moves no pixel of the other built-in scenes at their own
//! sizes by 1e-6; at 200x125 and 96x64 it moves a few pixels of `bunny` and
//! `cornell-gi` by more than 1e-4, each to the ray tracer's value.
//!
//! The fixed-point edge rule (exact, watertight) holds between triangles at
//! least `SMALL_LIMIT` units across; where a small triangle meets another, their
//! shared edge is decided as the ray casters decide it.

use crate::render::raster::fixed::FixedTri;
use crate::render::raster::rect::{PixelRect, TestCounter};
use crate::render::raster::vis_buffer::{FragmentRecorder, VisBuffer};
use crate::render::accel::intersect::intersect_triangle;
use crate::render::SceneQuery;


/// Tests the small triangle `ft` against the samples of its box inside
/// `rect` with the eye rays of the buffer's sample position, up to the far
/// plane, counting them in `tested`.
#[inline]
pub fn ray_test<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, ft: &FixedTri, rect: PixelRect, tested: &mut impl TestCounter) {
    let r = ft.bbox.intersect(&rect);
    if r.is_empty() {
        return;
    }
    tested.add(r);
    let job = vb.job;
    let tri = ft.st.tri;
    let edges = job.prepared.triangle_edges(tri);
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            let p = job.sample_position(x, y);
            let ray = job.view.eye_ray(p.x, p.y);
            if let Ok((t, b1, b2)) = intersect_triangle(&ray, &edges, job.view.far_t(p.x, p.y)) {
                vb.small_triangle_fragment(x, y, tri, t, b1, b2);
            }
        }
    }
}
