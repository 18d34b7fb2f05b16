//! Whole-object culling: each copy made by an `instances` list is tested by
//! its bounding sphere against the planes of the view volume (Computer
//! Graphics from Scratch, ch. 11) before any of its triangles is set up.
//! A copy wholly outside one plane can cover no sample of the image, so
//! skipping it changes no pixel; the side planes are those of
//! `clip::side_planes`, a little outside the image.

use crate::render::raster::clip::{side_planes, SidePlane};
use crate::render::PassJob;
use crate::scene::{CameraView, InstanceInfo, Scene};
use std::ops::Range;

/// The triangles a pass sets up, and what culling did.
pub struct Visible {
    /// Ranges of triangle indices to set up, in scene order (those past
    /// `Scene::triangles` are the two-level layer's).
    pub spans: Vec<Range<usize>>,
    /// Copies kept and copies skipped.
    pub drawn: u64,
    pub culled: u64,
}

/// The view volume's planes in camera space, for spheres.
pub struct Frustum {
    sides: [SidePlane; 4],
    near: f32,
    far: f32,
}

impl Frustum {
    pub fn new(view: &CameraView) -> Frustum {
        Frustum { sides: side_planes(view).map(|p| p.normalized()), near: view.near, far: view.far }
    }

    /// False when the sphere lies wholly outside one of the planes.
    pub fn may_see(&self, view: &CameraView, center: glam::Vec3, radius: f32) -> bool {
        let c = view.to_camera(center);
        // Rounding in the transform is covered by growing the radius.
        let r = radius * (1.0 + 1e-4) + 1e-5 * (center - view.eye).length();
        if -c.z + r < self.near || -c.z - r > self.far {
            return false;
        }
        self.sides.iter().all(|p| p.distance(c) >= -r)
    }
}

/// Whether `job` culls copies at all.
fn culls(job: &PassJob) -> bool {
    job.settings.cull_instances && !job.prepared.scene.instances.is_empty()
}

/// The triangle ranges `job` sets up: every triangle but those of the copies
/// culled (all of them when culling is off).
pub fn visible_spans(job: &PassJob) -> Visible {
    let scene = &job.prepared.scene;
    if !culls(job) {
        return Visible { spans: vec![0..scene.total_triangles() as usize], drawn: scene.instances.len() as u64, culled: 0 };
    }
    let frustum = Frustum::new(job.view);
    spans_of(scene, |i| frustum.may_see(job.view, i.center, i.radius))
}

/// The ranges left when the copies `keep` rejects are taken out.
pub fn spans_of(scene: &Scene, keep: impl Fn(&InstanceInfo) -> bool) -> Visible {
    let mut spans: Vec<Range<usize>> = Vec::new();
    let (mut drawn, mut culled) = (0, 0);
    let mut at = 0;
    for inst in &scene.instances {
        if keep(inst) {
            drawn += 1;
            continue;
        }
        culled += 1;
        if at < inst.triangles.start {
            spans.push(at..inst.triangles.start);
        }
        at = inst.triangles.end;
    }
    let total = scene.total_triangles() as usize;
    if at < total {
        spans.push(at..total);
    }
    Visible { spans, drawn, culled }
}
