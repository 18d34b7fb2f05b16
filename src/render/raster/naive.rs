//! The rasterizer obtained by swapping the ray caster's loops (CGPP listing
//! 15.22): for every triangle, for every pixel of the image, the 3D ray-triangle
//! test of the ray caster, with a depth buffer of ray distances. It makes the
//! same decisions as `raytrace:brute` (same rays, same test, same order, same
//! strict `<`), so its image is the reference image; it is just slow.

use super::pass::{bands, Query};
use super::vis_buffer::{DepthKey, VisBuffer};
use super::RasterOptions;
use crate::math::{Radiance, Ray};
use crate::render::raytrace::intersect::{intersect_triangle, Miss};
use crate::render::{PassJob, RayCounts};

/// The eye rays of the pixels of `vb`'s region, row-major.
pub fn region_rays(vb: &VisBuffer<Query>) -> Vec<Ray> {
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
pub fn ray_test_rect(vb: &mut VisBuffer<Query>, rays: &[Ray], tri: u32, rect: super::setup::PixelRect) {
    let edges = &vb.job.prepared.edges[tri as usize];
    vb.counts.samples_tested += rect.area();
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let i = vb.index(x, y);
            match intersect_triangle(&rays[i], edges, vb.depth[i]) {
                Ok((t, b1, b2)) => vb.ray_fragment(x, y, tri, t, b1, b2),
                Err(Miss::Farther) => vb.ray_depth_fail(),
                Err(_) => {}
            }
        }
    }
}

pub fn render(job: &PassJob, options: RasterOptions, out: &mut [Radiance]) -> RayCounts {
    let query = super::pass::query(job.prepared);
    let n = job.prepared.edges.len() as u32;
    bands(job, &query, DepthKey::RayT, !options.early_depth, out, |vb, _| {
        let rays = region_rays(vb);
        let rect = vb.rect;
        for tri in 0..n {
            if job.cancelled() {
                return;
            }
            ray_test_rect(vb, &rays, tri, rect);
        }
    })
}
