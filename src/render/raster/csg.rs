//! CSG objects in the rasterizer. A CSG surface is not a list of triangles
//! to scan-convert: what a pixel sees depends on every operand's entry and
//! exit along its eye ray. So each object covers a conservative screen box
//! (its bounding sphere's, as `sphere.rs` bounds spheres), and every sample
//! in the box gathers the operands' entry and exit fragments along the very
//! eye ray the ray casters cast (spheres through the analytic roots, mesh
//! operands through their triangles' crossings), sorts them by depth and
//! resolves them with the interval rule of `render::csg` (an A-buffer per
//! pixel, built per pixel rather than from scan-converted fragments). The
//! surviving fragment is depth-tested against the frame drawn so far, like a
//! sphere's.

use super::rect::PixelRect;
use super::sphere::sphere_bounds;
use super::vis_buffer::{DepthKey, FragmentRecorder, VisBuffer};
use crate::math::Vec2;
use crate::render::SceneQuery;
use crate::scene::CameraView;
use crate::scene::csg::Csg;

/// Bounds on screen of every CSG object for this pass (`None`: not visible).
pub fn all_csg_bounds(view: &CameraView, csgs: &[Csg], off: Vec2) -> Vec<Option<PixelRect>> {
    csgs.iter().map(|c| sphere_bounds(view, &c.bounding_sphere(), off)).collect()
}

/// Draws every CSG object (in scene order, after the spheres, as the ray
/// casters test them) into the region of `vb`.
pub fn raster_csgs<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, bounds: &[Option<PixelRect>]) {
    let job = vb.job;
    let view = job.view;
    let scene = &job.prepared.scene;
    for (ci, b) in bounds.iter().enumerate() {
        let Some(b) = b else { continue };
        let r = b.intersect(&vb.rect);
        if r.is_empty() {
            continue;
        }
        vb.add_tested(r);
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let p = job.sample_position(x, y);
                let ray = view.eye_ray(p.x, p.y);
                let t_max = view.far_t(p.x, p.y);
                if let Some(hit) = crate::render::csg::closest(scene, ci as u32, &ray, t_max, false) {
                    let t = hit.t;
                    let key = match vb.key {
                        DepthKey::RayT => t,
                        DepthKey::NegInvZ => vb.enc.key(1.0 / (view.near + t / view.camera_dir(p.x, p.y).length())),
                    };
                    vb.csg_fragment(x, y, ci as u32, t, key);
                }
            }
        }
    }
}
