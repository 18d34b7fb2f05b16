//! The rasterizer obtained by swapping the ray caster's loops (CGPP listing
//! 15.22): for every triangle, for every pixel of the image, the 3D ray-triangle
//! test of the ray caster, with a depth buffer of ray distances. It makes the
//! same decisions as `raytrace:brute` (same rays, same test, same order, same
//! strict `<`), so its image is the reference image; it is just slow.
//! The pass itself (every triangle against the whole region) is in `pass.rs`.

use crate::render::raster::rect::PixelRect;
use crate::render::raster::vis_buffer::{FragmentRecorder, VisBuffer};
use crate::math::Ray;
use crate::render::accel::intersect::{intersect_triangle, Miss};
use crate::render::SceneQuery;

/// The eye rays of the pixels of `vb`'s region, row-major.
pub fn region_rays<Q: SceneQuery, R: FragmentRecorder>(vb: &VisBuffer<Q, R>) -> Vec<Ray> {
    let r = vb.rect;
    let mut rays = Vec::with_capacity(r.area() as usize);
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            let p = vb.job.sample_position(x, y);
            rays.push(vb.job.view.eye_ray(p.x, p.y));
        }
    }
    rays
}

/// Tests triangle `tri` against the pixels of `rect` (inside `vb`'s region).
#[inline]
pub fn ray_test_rect<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, rays: &[Ray], tri: u32, rect: PixelRect) {
    let edges = &vb.job.prepared.triangle_edges(tri);
    vb.add_tested(rect);
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let i = vb.index(x, y);
            match intersect_triangle(&rays[i], edges, vb.depth[i]) {
                Ok((t, b1, b2)) => vb.ray_fragment(x, y, tri, t, b1, b2),
                Err(Miss::Farther) => vb.ray_depth_fail(x, y, tri, &rays[i]),
                Err(_) => {}
            }
        }
    }
}
