//! CSG objects in the rasterizer, through an A-buffer of scan-converted
//! fragments. What a sample sees of a CSG surface depends on every operand's
//! entry and exit along its eye ray, so for each object:
//!
//! - every triangle of its mesh operands is set up (near clipping and
//!   projection as `setup.rs` does them, but no back-face culling: a front
//!   face is where the eye ray *enters* the operand, a back face where it
//!   *exits*) and scan-converted by the watertight fixed-point loop
//!   (`fixed.rs`), whatever the variant, since a crack or a double hit would
//!   upset the count of entries and exits. Each covered sample gets a
//!   fragment: its depth t along the eye ray (from the perspective-correct
//!   barycentrics, as the rasterizers find a triangle's point), the operand,
//!   entry or exit, and the triangle with its barycentrics;
//! - every sphere operand gives each sample of its screen box (as
//!   `sphere.rs` bounds spheres) that its eye ray meets two fragments, the
//!   entry and the exit, from the analytic roots (how the rasterizer draws a
//!   sphere);
//! - the fragments go into an A-buffer (`abuffer.rs`): per sample, the list
//!   of all of them. Per sample the list is sorted by depth, each operand's
//!   fragments are counted into its inside intervals and the tree combines
//!   them with the interval rule of `render::accel::csg` (`resolve_lists`, the ray
//!   casters' own combination). An operand whose exits outnumber its entries
//!   was entered before the near plane, which clipped the entry away: it
//!   starts with an entry at -infinity.
//!
//! The boundary that wins is depth-tested against the frame drawn so far
//! like a sphere's fragment (`VisBuffer::csg_fragment`), and shading builds
//! its hit from that boundary and the eye ray (`render::accel::csg::surface_hit`).
//! The recorder gets the focus sample's sorted list and its intervals.

use crate::render::raster::abuffer::ABuffer;
use crate::render::raster::clip::{clip_near, triangle_vertices};
use crate::render::raster::fixed::FixedTri;
use crate::render::raster::rect::PixelRect;
use crate::render::raster::setup::{project_piece, ScreenTri};
use crate::render::raster::sphere::sphere_bounds;
use crate::render::raster::subpixel::snap_offset;
use crate::render::raster::vis_buffer::{DepthKey, FragmentRecorder, VisBuffer};
use crate::math::{Vec2, Vec3};
use crate::render::accel::csg::{count_intervals, leaves, resolve_lists, sphere_interval, Boundary, SurfaceRef};
use crate::render::inspect::pixel_record::{CsgABufferRecord, CsgFragmentRecord};
use crate::render::SceneQuery;
use crate::scene::csg::{Csg, CsgNode};
use crate::scene::CameraView;

/// One operand of a CSG object set up for a pass (one sample position).
pub enum OperandSetup {
    /// A mesh operand's triangles (both faces), each with whether it is a front face.
    Mesh(Vec<(FixedTri, bool)>),
    /// A sphere operand (`Csg::spheres` index) and the pixels whose sample may meet it.
    Sphere(u32, Option<PixelRect>),
}

/// One CSG object set up for a pass.
pub struct CsgSetup {
    /// Pixels whose sample may see the object (its bounding sphere's box);
    /// `None` when it is off screen.
    pub bounds: Option<PixelRect>,
    /// Its operands in leaf order (`render::accel::csg::leaves`).
    pub operands: Vec<OperandSetup>,
}

/// Every CSG object set up for the pass whose sample lies at `off`.
pub fn setup_csgs(view: &CameraView, csgs: &[Csg], off: Vec2) -> Vec<CsgSetup> {
    csgs.iter()
        .map(|c| {
            let bounds = sphere_bounds(view, &c.bounding_sphere(), off);
            let operands = match bounds {
                None => Vec::new(),
                Some(_) => leaves(c)
                    .iter()
                    .map(|leaf| match *leaf.node {
                        CsgNode::Mesh { first, end, .. } => OperandSetup::Mesh(setup_operand_mesh(view, c, first, end, off)),
                        CsgNode::Sphere(i) => OperandSetup::Sphere(i, sphere_bounds(view, &c.spheres[i as usize], off)),
                        CsgNode::Op { .. } => OperandSetup::Mesh(Vec::new()),
                    })
                    .collect(),
            };
            CsgSetup { bounds, operands }
        })
        .collect()
}

/// The triangles `first..end` of `csg` clipped at the near plane, projected
/// and snapped, front and back faces alike (`ScreenTri::tri` is the index
/// into `Csg::triangles`). Nothing is dropped beyond the far plane: an exit
/// there still closes an interval.
fn setup_operand_mesh(view: &CameraView, csg: &Csg, first: u32, end: u32, off: Vec2) -> Vec<(FixedTri, bool)> {
    let snapped = snap_offset(off);
    let mut out = Vec::new();
    for index in first..end {
        let t = &csg.triangles[index as usize];
        let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
        // Every eye ray meets the plane from the eye's side: against the
        // outward normal (an entry) when the eye lies in front of it.
        let entering = view.toward_viewer(t.v[0]).dot(n) > 0.0;
        let c = t.v.map(|v| view.to_camera(v));
        for piece in clip_near(triangle_vertices(c), view.near).as_slice() {
            let (p, depth, bz) = project_piece(view, piece);
            let Some(st) = ScreenTri::new(index, p, depth, bz, !view.is_orthographic(), off, view.width, view.height) else { continue };
            if let Some(ft) = FixedTri::new(&st, snapped, off, view.width, view.height) {
                out.push((ft, entering));
            }
        }
    }
    out
}

/// One fragment of the A-buffer: where the eye ray crosses an operand's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CsgFragment {
    /// Along the eye ray, from its origin on the near plane.
    pub t: f32,
    pub leaf: u32,
    pub surface: SurfaceRef,
    pub entering: bool,
    /// The triangle's screen-space weights, kept for the recorded pixel only.
    pub screen: Option<Vec3>,
}

/// Draws every CSG object (in scene order, after the spheres, as the ray
/// casters test them) into the region of `vb`.
pub fn raster_csgs<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, setups: &[CsgSetup]) {
    for (ci, setup) in setups.iter().enumerate() {
        let Some(b) = setup.bounds else { continue };
        let r = b.intersect(&vb.rect);
        if !r.is_empty() {
            let abuffer = scan_convert(vb, ci as u32, setup, r);
            resolve(vb, ci as u32, &abuffer);
        }
    }
}

/// The A-buffer of object `ci` over the samples of `r`: every operand's
/// fragments, operand by operand in leaf order.
fn scan_convert<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, ci: u32, setup: &CsgSetup, r: PixelRect) -> ABuffer<CsgFragment> {
    let job = vb.job;
    let view = job.view;
    let csg = &job.prepared.scene.csgs[ci as usize];
    let focus = vb.focus();
    let off = snap_offset(job.offset);
    let mut abuffer = ABuffer::new(r);
    for (leaf, operand) in setup.operands.iter().enumerate() {
        let leaf = leaf as u32;
        match operand {
            OperandSetup::Mesh(tris) => {
                let mut tested = vb.begin_tests();
                for (ft, entering) in tris {
                    let v = &csg.triangles[ft.st.tri as usize].v;
                    crate::render::raster::fixed::raster(ft, r, off, &mut tested, |x, y, l| {
                        let [b1, b2] = ft.st.bary_at(l, ft.st.affine_depth_at(l));
                        let p = job.sample_position(x, y);
                        let ray = view.eye_ray(p.x, p.y);
                        let point = v[0] * (1.0 - b1 - b2) + v[1] * b1 + v[2] * b2;
                        let t = (point - ray.origin).dot(ray.dir);
                        let screen = (focus == Some((x, y))).then(|| ft.st.affine_weights(l));
                        let surface = SurfaceRef::Triangle { index: ft.st.tri, b1, b2 };
                        abuffer.push(x, y, CsgFragment { t, leaf, surface, entering: *entering, screen });
                    });
                }
                vb.end_tests(tested);
            }
            OperandSetup::Sphere(si, bounds) => {
                let Some(sr) = bounds.map(|b| b.intersect(&r)).filter(|b| !b.is_empty()) else { continue };
                vb.add_tested(sr);
                let s = &csg.spheres[*si as usize];
                for y in sr.y0..sr.y1 {
                    for x in sr.x0..sr.x1 {
                        let p = job.sample_position(x, y);
                        let ray = view.eye_ray(p.x, p.y);
                        if let Some((t0, t1)) = sphere_interval(&ray, s.center, s.radius) {
                            let f = |t, entering| CsgFragment { t, leaf, surface: SurfaceRef::Sphere(*si), entering, screen: None };
                            abuffer.push(x, y, f(t0, true));
                            abuffer.push(x, y, f(t1, false));
                        }
                    }
                }
            }
        }
    }
    abuffer
}

/// Resolves every sample of `abuffer` with the interval rule and hands the
/// winning boundaries to the depth test; records the focus sample's list.
fn resolve<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, ci: u32, abuffer: &ABuffer<CsgFragment>) {
    if abuffer.is_empty() {
        return;
    }
    let job = vb.job;
    let view = job.view;
    let csg = &job.prepared.scene.csgs[ci as usize];
    let focus = vb.focus();
    let r = abuffer.rect();
    let mut frags = Vec::new();
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            abuffer.fragments(x, y, &mut frags);
            if frags.is_empty() {
                continue;
            }
            // By depth; at equal depth entries first (as the count sorts them).
            frags.sort_by(|a, b| a.t.total_cmp(&b.t).then(b.entering.cmp(&a.entering)));
            let p = job.sample_position(x, y);
            let t_max = view.far_t(p.x, p.y);
            let recorded = focus == Some((x, y));
            let (winner, explanation) = resolve_lists(csg, t_max, recorded, |leaf, flipped| operand_intervals(&frags, leaf, flipped));
            if let Some(e) = explanation {
                let fragments = frags
                    .iter()
                    .map(|f| CsgFragmentRecord { t: f.t, leaf: f.leaf, surface: f.surface, entering: f.entering, screen_barycentric: f.screen })
                    .collect();
                vb.rec.csg_abuffer(CsgABufferRecord { csg: ci, sample: vb.sample, fragments, explanation: e });
            }
            if let Some((b, _)) = winner {
                let key = match vb.key {
                    DepthKey::RayT => b.t,
                    // The eye ray starts on the near plane: depth = near + t / |d|.
                    DepthKey::NegInvZ => vb.enc.key_at_depth(view.near + b.t / view.camera_dir(p.x, p.y).length()),
                };
                vb.csg_fragment(x, y, ci, b, key);
            }
        }
    }
}

/// The inside intervals of operand `leaf` from a sample's fragments, counted
/// as the ray casters count a mesh's crossings. Exits without entries before
/// them were entered before the near plane: an entry at -infinity each.
fn operand_intervals(frags: &[CsgFragment], leaf: u32, flipped: bool) -> Vec<crate::render::accel::csg::Interval> {
    let mut crossings: Vec<(Boundary, bool)> = Vec::new();
    let mut depth = 0i32;
    let mut unmatched = 0;
    for f in frags.iter().filter(|f| f.leaf == leaf) {
        if f.entering {
            depth += 1;
        } else if depth > 0 {
            depth -= 1;
        } else {
            unmatched += 1;
        }
        crossings.push((Boundary { t: f.t, surface: f.surface, leaf, flipped }, f.entering));
    }
    if let Some(&(first, _)) = crossings.first() {
        for _ in 0..unmatched {
            crossings.push((Boundary { t: f32::NEG_INFINITY, ..first }, true));
        }
    }
    count_intervals(crossings)
}
