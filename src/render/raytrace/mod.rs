//! The ray-casting renderers: for each pixel, find the closest surface along
//! the eye ray and hand it to shading. The queries that answer the rays live
//! in `render::accel` (`brute` is the book's reference, `bvh` the fast method
//! checked against it); this module drives them pass by pass: one ray per
//! pixel (`cast_pass`) and the BVH renderer (`bvh_renderer`).

pub mod brute_renderer;
pub mod bvh_renderer;
pub mod packet_tiles;

use crate::render::inspect::pixel_record::{NoRecord, Recorder};
use crate::render::{resolve_sample, PassJob, RayCounts, SceneQuery};
use crate::render::inspect::debug::{cost_color, View};
use crate::math::{Radiance, Ray, Vec2};
use crate::render::differentials::{with_ray_differentials, RayDifferential};
use crate::scene::SurfaceHit;
use rayon::prelude::*;

/// Casts one eye ray per pixel of `job.rows` through `query`, rows in parallel.
pub fn cast_pass<Q: SceneQuery>(job: &PassJob, query: &Q, out: &mut [Radiance]) -> RayCounts {
    let width = job.view.width as usize;
    out.par_chunks_mut(width)
        .enumerate()
        .map(|(i, row)| {
            let mut counts = RayCounts::default();
            if job.cancelled() {
                return counts;
            }
            let y = job.rows.start + i as u32;
            for (x, px) in row.iter_mut().enumerate() {
                if job.is_active(x as u32, y) {
                    *px = cast_pixel(job, query, x as u32, y, &mut counts, &mut NoRecord);
                }
            }
            if !job.keep_non_finite {
                counts.non_finite += crate::render::finite::admit_all(row);
            }
            counts
        })
        .reduce(RayCounts::default, |mut a, b| {
            a += b;
            a
        })
}

/// One eye ray: the sample of pixel `(x, y)` in this pass. `pinhole pixel`
/// calls this with a recording `rec` to replay exactly what the frame did.
#[inline]
pub fn cast_pixel<Q: SceneQuery, R: Recorder>(job: &PassJob, query: &Q, x: u32, y: u32, counts: &mut RayCounts, rec: &mut R) -> Radiance {
    let p = job.sample_position(x, y);
    let (ray, t_max) = job.eye_ray(x, y);
    counts.primary += 1;
    rec.ray(&ray, t_max, 0);
    let work_before = counts.nodes + counts.tests;
    let mut hit = query.closest(&ray, t_max, false, counts, rec);
    with_eye_differentials(job, p, &ray, &mut hit);
    rec.closest(hit.as_ref());
    if job.settings.view == View::Cost {
        let c = cost_color((counts.nodes + counts.tests - work_before) as f32);
        rec.shaded(0, c);
        return c;
    }
    resolve_sample(job, query, &ray, hit.as_ref(), job.pixel_index(x, y), counts, rec)
}

/// The eye ray's hit at image position `p` with the ray's differentials
/// carried to it (Igehy's transfer) and its normal map applied, when a
/// texture can read them.
/// In place, so that the (large) hit is not copied when there is nothing
/// to add.
#[inline]
pub fn with_eye_differentials(job: &PassJob, p: Vec2, ray: &Ray, hit: &mut Option<SurfaceHit>) {
    let scene = &job.prepared.scene;
    if let Some(h) = hit.as_mut().filter(|_| scene.has_textures()) {
        *h = with_ray_differentials(scene, &RayDifferential::eye(job.view, p.x, p.y), ray, *h);
        crate::scene::normal_map::apply(scene, job.settings.texture_filter, h);
    }
}
