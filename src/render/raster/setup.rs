//! Triangle setup, shared by every rasterizer variant: world to camera space,
//! back-face culling, near-plane clipping, projection to the image and the
//! pixel bounding box. The result is a list of screen-space triangles in scene
//! order, each remembering which scene triangle it came from.

use crate::render::raster::clip::{clip_frustum, clip_near, side_planes, triangle_vertices, ClipMode, ClipVertex, FrustumClip, SidePlane};
use crate::render::raster::rect::{sample_span, PixelRect};
use crate::render::raster::runs::Runs;
use crate::render::raster::subpixel;
use crate::math::lanes::Lane;
use crate::math::{Vec2, Vec3};
use crate::render::PassJob;
use crate::scene::{CameraView, Triangle};
use rayon::prelude::*;

/// Twice the signed area of the 2D triangle `a, b, p`: the edge function of edge
/// `a -> b` at `p`. In image coordinates (y down) it is positive on the inner
/// side of every edge of a triangle with positive area.
#[inline(always)]
pub fn edge_function(a: Vec2, b: Vec2, p: Vec2) -> f32 {
    edge_function_lanes(a, b, p.x, p.y)
}

/// `edge_function` at lanes of sample positions `(qx, qy)`: written once
/// over the lane type, so the scalar rasterizer and the eight-sample rows
/// of the visibility buffer compute the same bits.
#[inline(always)]
pub fn edge_function_lanes<L: Lane>(a: Vec2, b: Vec2, qx: L, qy: L) -> L {
    qx.splat(b.x - a.x) * (qy - qx.splat(a.y)) - qx.splat(b.y - a.y) * (qx - qx.splat(a.x))
}

/// `l0 c0 + l1 c1 + l2 c2`, summed left to right: screen-space weights
/// applied to a per-vertex attribute.
#[inline(always)]
fn weighted<L: Lane>(l: &[L; 3], c: [f32; 3]) -> L {
    l[0] * l[0].splat(c[0]) + l[1] * l[1].splat(c[1]) + l[2] * l[2].splat(c[2])
}

/// A projected (clipped) triangle ready to rasterize.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenTri {
    /// Index of the scene triangle this piece belongs to.
    pub tri: u32,
    /// Image positions (pixels), ordered so the signed area is positive.
    pub p: [Vec2; 3],
    /// The depth value at each vertex that is affine in image space: 1 /
    /// view depth through a perspective camera, the view depth itself
    /// through an orthographic one (`DepthEncoding` keys either).
    pub affine_depth: [f32; 3],
    /// Barycentrics in the original triangle per vertex, divided by view
    /// depth when `perspective`: affine in image space, so the
    /// perspective-correct weights are `sum / affine_depth` (orthographic:
    /// the sum itself).
    pub bz: [Vec3; 3],
    /// Seen through one centre of projection (else along parallel rays).
    pub perspective: bool,
    /// Pixels whose sample position may be covered, clamped to the image.
    pub bbox: PixelRect,
    /// 1 / (twice the signed area) for the vertex order in `p`.
    pub inv_area: f32,
}

impl ScreenTri {
    /// A screen triangle from projected vertices; `None` when it has no area or
    /// no sample of the image can fall inside it. Vertices 1 and 2 are swapped
    /// when needed to make the area positive.
    pub fn new(tri: u32, mut p: [Vec2; 3], mut affine_depth: [f32; 3], mut bz: [Vec3; 3], perspective: bool, off: Vec2, width: u32, height: u32) -> Option<ScreenTri> {
        let area = edge_function(p[0], p[1], p[2]);
        if !area.is_finite() || area == 0.0 {
            return None;
        }
        if area < 0.0 {
            p.swap(1, 2);
            affine_depth.swap(1, 2);
            bz.swap(1, 2);
        }
        // Padded by one fixed-point unit: snapping (fixed, tiled) moves a vertex
        // by up to half of one, which can bring a sample row or column into a
        // sliver that, unsnapped, just misses it. Coverage is decided by each
        // method's own edge tests, so the float variants are unaffected.
        let pad = Vec2::splat(1.0 / subpixel::ONE as f32);
        let lo = p[0].min(p[1]).min(p[2]) - pad;
        let hi = p[0].max(p[1]).max(p[2]) + pad;
        let (x0, x1) = sample_span(lo.x, hi.x, off.x, width);
        let (y0, y1) = sample_span(lo.y, hi.y, off.y, height);
        let bbox = PixelRect { x0, y0, x1, y1 };
        let inv_area = 1.0 / area.abs();
        (!bbox.is_empty()).then_some(ScreenTri { tri, p, affine_depth, bz, perspective, bbox, inv_area })
    }

    /// A triangle given directly in image space at depth 1 (tests, coverage counts).
    pub fn flat(tri: u32, p: [Vec2; 3], off: Vec2, width: u32, height: u32) -> Option<ScreenTri> {
        ScreenTri::new(tri, p, [1.0; 3], [Vec3::X, Vec3::Y, Vec3::Z], true, off, width, height)
    }

    /// The interpolated `affine_depth` (1 / view depth, or the view depth
    /// through an orthographic camera) for screen-space weights `l`.
    #[inline(always)]
    pub fn affine_depth_at(&self, l: [f32; 3]) -> f32 {
        self.affine_depth_lanes(&l)
    }

    /// View depth interpolated linearly in image space for screen-space
    /// weights `l` (`--depth-buffer linear-z`): through a perspective
    /// camera not the surface's depth between the corners (which the
    /// reciprocal of `affine_depth_at(l)` is); through an orthographic one
    /// the same.
    #[inline]
    pub fn linear_z_at(&self, l: [f32; 3]) -> f32 {
        l[0] * self.vertex_depth(0) + l[1] * self.vertex_depth(1) + l[2] * self.vertex_depth(2)
    }

    /// `affine_depth_at` for lanes of weights.
    #[inline(always)]
    pub fn affine_depth_lanes<L: Lane>(&self, l: &[L; 3]) -> L {
        weighted(l, self.affine_depth)
    }

    /// The view depth at vertex `k`.
    pub fn vertex_depth(&self, k: usize) -> f32 {
        if self.perspective {
            1.0 / self.affine_depth[k]
        } else {
            self.affine_depth[k]
        }
    }

    /// Perspective-correct barycentrics (b1, b2) in the original triangle for
    /// screen-space weights `l`, given `depth = affine_depth_at(l)`.
    #[inline(always)]
    pub fn bary_at(&self, l: [f32; 3], depth: f32) -> [f32; 2] {
        self.bary_lanes(&l, depth)
    }

    /// `bary_at` for lanes of weights: (bz0 l0 + bz1 l1 + bz2 l2) / depth,
    /// its y and z; along parallel rays the weights need no division.
    #[inline(always)]
    pub fn bary_lanes<L: Lane>(&self, l: &[L; 3], depth: L) -> [L; 2] {
        let bz = &self.bz;
        let (b1, b2) = (weighted(l, [bz[0].y, bz[1].y, bz[2].y]), weighted(l, [bz[0].z, bz[1].z, bz[2].z]));
        if self.perspective {
            [b1 / depth, b2 / depth]
        } else {
            [b1, b2]
        }
    }

    /// Affine (screen-space) barycentrics (b1, b2) in the original triangle
    /// for screen-space weights `l`: what interpolating without the 1/z
    /// correction gives (the `affine` setting shows it).
    #[inline(always)]
    pub fn affine_bary_at(&self, l: [f32; 3]) -> [f32; 2] {
        let b = self.affine_weights(l);
        [b.y, b.z]
    }

    /// The 2D weights as weights of the original triangle's three vertices.
    #[inline(always)]
    pub fn affine_weights(&self, l: [f32; 3]) -> Vec3 {
        if !self.perspective {
            return (0..3).map(|k| self.bz[k] * l[k]).sum::<Vec3>();
        }
        (0..3).map(|k| self.bz[k] / self.affine_depth[k] * l[k]).sum::<Vec3>()
    }

    /// Screen-space (affine, NOT perspective-correct) weights of the sample `q`,
    /// each edge function evaluated directly, relative to the edge's start vertex.
    #[inline(always)]
    pub fn screen_weights(&self, q: Vec2) -> [f32; 3] {
        self.screen_weights_lanes(q.x, q.y)
    }

    /// `screen_weights` at lanes of sample positions `(qx, qy)`.
    #[inline(always)]
    pub fn screen_weights_lanes<L: Lane>(&self, qx: L, qy: L) -> [L; 3] {
        let (p, inv_area) = (&self.p, qx.splat(self.inv_area));
        [
            edge_function_lanes(p[1], p[2], qx, qy) * inv_area,
            edge_function_lanes(p[2], p[0], qx, qy) * inv_area,
            edge_function_lanes(p[0], p[1], qx, qy) * inv_area,
        ]
    }

    /// Swaps vertices 1 and 2 with their attributes (the area changes sign).
    pub fn swap_12(&mut self) {
        self.p.swap(1, 2);
        self.affine_depth.swap(1, 2);
        self.bz.swap(1, 2);
        self.inv_area = -self.inv_area;
    }
}

/// True when the single-sided test of the ray tracer would reject every eye
/// ray hitting this triangle: its geometric normal faces away from the eye
/// (from the direction the parallel rays come from, orthographic).
#[inline]
pub fn is_back_face(view: &CameraView, t: &Triangle) -> bool {
    if t.two_sided {
        return false;
    }
    let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
    view.toward_viewer(t.v[0]).dot(n) <= 0.0
}

/// A clipped piece's image positions, affine depth values and per-vertex
/// `bz` (see `ScreenTri`), as `view` projects them.
#[inline]
pub fn project_piece(view: &CameraView, piece: &[ClipVertex; 3]) -> ([Vec2; 3], [f32; 3], [Vec3; 3]) {
    let p = piece.map(|v| view.project_camera(v.pos));
    if !view.is_orthographic() {
        let inv_z = piece.map(|v| 1.0 / -v.pos.z);
        (p, inv_z, [piece[0].bary * inv_z[0], piece[1].bary * inv_z[1], piece[2].bary * inv_z[2]])
    } else {
        (p, piece.map(|v| -v.pos.z), piece.map(|v| v.bary))
    }
}


/// Culls, clips and projects one scene triangle, appending 0, 1 or 2 pieces.
/// Without `near_clip` a triangle reaching nearer than the near plane is
/// dropped instead of cut (the `near_clip` debug setting).
pub fn setup_triangle(view: &CameraView, t: &Triangle, index: u32, off: Vec2, near_clip: bool, out: &mut Vec<ScreenTri>) {
    setup_triangle_clipped(view, t, index, off, near_clip, None, out)
}

/// `setup_triangle`, with `frustum` (the grown side planes of
/// `clip::side_planes`) for `--clip frustum`: the triangle is also clipped
/// against the side planes, which drops it when nothing is left and shrinks
/// its pieces' pixel boxes to what is left. The pieces and their attributes
/// are those of the near clip either way.
pub fn setup_triangle_clipped(view: &CameraView, t: &Triangle, index: u32, off: Vec2, near_clip: bool, frustum: Option<&[SidePlane; 4]>, out: &mut Vec<ScreenTri>) {
    if is_back_face(view, t) {
        return;
    }
    let c = t.v.map(|v| view.to_camera(v));
    if c.iter().all(|c| -c.z >= view.far) {
        return;
    }
    if !near_clip && c.iter().any(|c| -c.z < view.near) {
        return;
    }
    let inside = match frustum {
        Some(planes) => match clip_frustum(c, view, planes) {
            FrustumClip::Outside => return,
            FrustumClip::Inside => None,
            FrustumClip::Cut(lo, hi) => {
                let pad = Vec2::ONE;
                let (x0, x1) = sample_span(lo.x - pad.x, hi.x + pad.x, off.x, view.width);
                let (y0, y1) = sample_span(lo.y - pad.y, hi.y + pad.y, off.y, view.height);
                Some(PixelRect { x0, y0, x1, y1 })
            }
        },
        None => None,
    };
    // Wholly in front of the near plane (nearly every triangle): the clip
    // would hand back the triangle itself, so it is not run.
    let whole = [triangle_vertices(c)];
    let clipped;
    let pieces = if c.iter().all(|c| -c.z >= view.near) {
        &whole[..]
    } else {
        clipped = clip_near(whole[0], view.near);
        clipped.as_slice()
    };
    let perspective = !view.is_orthographic();
    for piece in pieces {
        let (p, depth, bz) = project_piece(view, piece);
        if let Some(mut st) = ScreenTri::new(index, p, depth, bz, perspective, off, view.width, view.height) {
            if let Some(r) = inside {
                st.bbox = st.bbox.intersect(&r);
                if st.bbox.is_empty() {
                    continue;
                }
            }
            out.push(st);
        }
    }
}

/// Every triangle of the scene set up for this pass, in scene order (setup
/// in parallel). Copies made by `instances` whose bounding sphere lies
/// outside the view volume are skipped whole (`cull::visible_spans`).
pub fn setup_pass(job: &PassJob) -> Vec<ScreenTri> {
    setup_pass_map(job, Some).joined()
}

/// `setup_pass`, each piece passed through `keep` as it is made, so that a
/// variant that converts the pieces (fixed point) never holds both lists;
/// the pieces run by run, as the threads made them.
pub fn setup_pass_map<T: Copy + Send + Sync>(job: &PassJob, keep: impl Fn(ScreenTri) -> Option<T> + Sync) -> Runs<T> {
    /// How many triangles ahead the set-up asks for the corners it will read.
    const CORNERS_AHEAD: usize = 8;
    const CHUNK: usize = 4096;
    let view = job.view;
    let rows = PixelRect::new(0, job.rows.start, view.width, job.rows.end);
    let scene = &job.prepared.scene;
    let spans = crate::render::raster::cull::visible_spans(job).spans;
    let chunks = chunks_of(scene, &spans, CHUNK);
    let frustum = (job.settings.clip == ClipMode::Frustum).then(|| side_planes(view));
    // A band of the image (the viewer renders a pass band by band) skips
    // the set-up of triangles that lie wholly above or below it.
    let banded = job.rows.start > 0 || job.rows.end < view.height;
    let pieces: Vec<Vec<T>> = chunks
        .into_par_iter()
        .map(|chunk| {
            let mut out = Vec::with_capacity(chunk.range.len());
            let near_clip = job.settings.near_clip;
            match chunk.copy {
                None => {
                    for i in chunk.range {
                        // The corners a few triangles on, while this one is set up.
                        scene.triangles.prefetch_corners(i + CORNERS_AHEAD);
                        // Setup reads the vertices and the sidedness alone.
                        let (v, two_sided) = scene.triangles.geometry(i);
                        if banded && misses_rows(view, &v, &job.rows) {
                            continue;
                        }
                        let t = Triangle { v, n: [Vec3::ZERO; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided };
                        setup_triangle_clipped(view, &t, i as u32, job.offset, near_clip, frustum.as_ref(), &mut out);
                    }
                }
                Some(k) => {
                    // A copy of the two-level layer: its triangles placed as flattening places them.
                    let layer = scene.layer.as_deref().expect("copies without a layer");
                    let inst = &layer.instances[k];
                    for local in chunk.range {
                        // Setup reads the vertices and the sidedness alone.
                        let (v, two_sided) = layer.world_vertices(inst, local);
                        if banded && misses_rows(view, &v, &job.rows) {
                            continue;
                        }
                        let t = Triangle { v, n: [Vec3::ZERO; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided };
                        setup_triangle_clipped(view, &t, inst.base + local as u32, job.offset, near_clip, frustum.as_ref(), &mut out);
                    }
                }
            }
            // Drop pieces outside the rows of this job.
            let mut kept = Vec::with_capacity(out.len());
            kept.extend(out.into_iter().filter(|st| !st.bbox.intersect(&rows).is_empty()).filter_map(&keep));
            kept
        })
        .collect();
    Runs::new(pieces)
}

/// Whether the triangle with corners `v` certainly covers no sample of
/// pixel rows `rows`: every corner in front of the near plane (no clipping
/// to come) and all of them projected more than two pixels above the first
/// row or below the last. Only a triangle whose pixel box misses the rows,
/// which the set-up would drop, is dropped here; one it keeps may still
/// miss them.
#[inline]
fn misses_rows(view: &CameraView, v: &[Vec3; 3], rows: &std::ops::Range<u32>) -> bool {
    let c = v.map(|v| view.to_camera(v));
    if c.iter().any(|c| !(-c.z >= view.near)) {
        return false;
    }
    let y = c.map(|c| view.project_camera(c).y);
    if !y.iter().all(|y| y.is_finite()) {
        return false;
    }
    let (lo, hi) = (y[0].min(y[1]).min(y[2]), y[0].max(y[1]).max(y[2]));
    hi < rows.start as f32 - 2.0 || lo > rows.end as f32 + 2.0
}

/// A run of triangles set up together: indices into `Scene::triangles`, or
/// mesh indices of copy `copy` of the two-level layer.
struct Chunk {
    copy: Option<usize>,
    range: std::ops::Range<usize>,
}

/// `spans` (triangle indices, in order) cut into runs of at most `size`
/// that never straddle a copy of the two-level layer.
fn chunks_of(scene: &crate::scene::Scene, spans: &[std::ops::Range<usize>], size: usize) -> Vec<Chunk> {
    let flat = scene.triangles.len();
    let mut out = Vec::new();
    let cut = |out: &mut Vec<Chunk>, copy: Option<usize>, r: std::ops::Range<usize>| {
        for s in (r.start..r.end).step_by(size) {
            out.push(Chunk { copy, range: s..(s + size).min(r.end) });
        }
    };
    for span in spans {
        if span.start < flat {
            cut(&mut out, None, span.start..span.end.min(flat));
        }
        if span.end <= flat {
            continue;
        }
        let Some(layer) = scene.layer.as_deref() else { continue };
        let start = span.start.max(flat);
        let mut k = layer.instances.partition_point(|i| (i.base as usize) <= start).saturating_sub(1);
        while k < layer.instances.len() {
            let inst = &layer.instances[k];
            let base = inst.base as usize;
            if base >= span.end {
                break;
            }
            let len = layer.meshes[inst.mesh as usize].len();
            let (a, b) = (start.max(base) - base, (span.end.min(base + len)).saturating_sub(base));
            if a < b {
                cut(&mut out, Some(k), a..b);
            }
            k += 1;
        }
    }
    out
}

/// For consecutive bands of `band` rows starting at `rows_start`, the indices
/// of the rectangles that overlap each band, in order.
pub fn bin_rows(rects: impl Iterator<Item = PixelRect>, rows_start: u32, rows_end: u32, band: u32) -> Vec<Vec<u32>> {
    bin_rows_by_id(rects.enumerate().map(|(i, r)| (i as u32, r)), rows_start, rows_end, band)
}

/// `bin_rows` of pieces named by ids (`Runs`) rather than by place.
pub fn bin_rows_by_id(rects: impl Iterator<Item = (u32, PixelRect)>, rows_start: u32, rows_end: u32, band: u32) -> Vec<Vec<u32>> {
    let n = (rows_end.saturating_sub(rows_start)).div_ceil(band) as usize;
    let mut bins = vec![Vec::new(); n];
    for (i, r) in rects {
        let y0 = r.y0.max(rows_start);
        let y1 = r.y1.min(rows_end);
        if y0 >= y1 || r.x0 >= r.x1 {
            continue;
        }
        for b in (y0 - rows_start) / band..=(y1 - 1 - rows_start) / band {
            bins[b as usize].push(i);
        }
    }
    bins
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_z_is_the_straight_line_between_the_corners_depths() {
        // Corners at view depths 1, 10 and 10; halfway between the first
        // two in image space, 1/z is affine: the surface's depth there is
        // 1 / 0.55, while z drawn straight across is 5.5.
        let st = ScreenTri::new(0, [Vec2::new(0.0, 0.0), Vec2::new(8.0, 0.0), Vec2::new(0.0, 8.0)], [1.0, 0.1, 0.1], [Vec3::X, Vec3::Y, Vec3::Z], true, Vec2::ZERO, 16, 16).unwrap();
        let l = [0.5, 0.5, 0.0];
        assert!((1.0 / st.affine_depth_at(l) - 1.0 / 0.55).abs() < 1e-5);
        assert!((st.linear_z_at(l) - 5.5).abs() < 1e-5);
    }
    use crate::scene::{Camera, Fov};

    #[test]
    fn orientation_is_normalised() {
        let p = [Vec2::new(1.0, 1.0), Vec2::new(5.0, 1.0), Vec2::new(1.0, 5.0)];
        let a = ScreenTri::flat(0, p, Vec2::splat(0.5), 10, 10).unwrap();
        let b = ScreenTri::flat(0, [p[0], p[2], p[1]], Vec2::splat(0.5), 10, 10).unwrap();
        // Same positions; the attributes follow their vertices.
        assert_eq!((a.p, a.bbox), (b.p, b.bbox));
        assert_eq!(b.bz, [Vec3::X, Vec3::Z, Vec3::Y]);
        assert!(edge_function(a.p[0], a.p[1], a.p[2]) > 0.0);
        assert_eq!(a.bbox, PixelRect::new(1, 1, 5, 5));
        // The weights of vertex 0 at the vertex itself.
        let w = a.screen_weights(a.p[0]);
        assert_eq!(w, [1.0, 0.0, 0.0]);
        assert!(ScreenTri::flat(0, [p[0], p[0], p[1]], Vec2::splat(0.5), 10, 10).is_none());
    }

    #[test]
    fn back_faces_match_the_ray_tracer() {
        // The book's triangle faces +z (towards the eye at the origin): front.
        let cam = Camera { fov: Fov::X(90.0), ..Camera::default() };
        let view = cam.view(80, 50);
        let mut t = Triangle {
            v: [Vec3::new(0.0, 1.0, -2.0), Vec3::new(-1.9, -1.0, -2.0), Vec3::new(1.6, -0.5, -2.0)],
            n: [Vec3::Z; 3],
            uv: [Vec2::ZERO; 3],
            material: 0,
            object: 0,
            two_sided: false,
        };
        assert!(!is_back_face(&view, &t));
        t.v.swap(1, 2);
        assert!(is_back_face(&view, &t));
        t.two_sided = true;
        assert!(!is_back_face(&view, &t));
    }

    #[test]
    fn crossing_triangle_projects_only_its_front_part() {
        // A long triangle on the floor, from in front of the camera to behind it:
        // it must come out clipped (never wrapped behind the eye).
        let cam = Camera { fov: Fov::Y(90.0), near: 0.5, ..Camera::default() };
        let view = cam.view(100, 100);
        let t = Triangle {
            v: [Vec3::new(-1.0, -1.0, -5.0), Vec3::new(1.0, -1.0, -5.0), Vec3::new(0.0, -1.0, 5.0)],
            n: [Vec3::Y; 3],
            uv: [Vec2::ZERO; 3],
            material: 0,
            object: 0,
            two_sided: true,
        };
        let mut out = Vec::new();
        setup_triangle(&view, &t, 7, Vec2::splat(0.5), true, &mut out);
        assert_eq!(out.len(), 2);
        for st in &out {
            assert_eq!(st.tri, 7);
            for k in 0..3 {
                // Every piece lies below the horizon (y > 50) and at depth >= near.
                assert!(st.p[k].y > 50.0, "{st:?}");
                assert!(st.affine_depth[k] <= 1.0 / 0.5 + 1e-6);
            }
        }
    }

    #[test]
    fn perspective_correct_matches_the_ray_cast_and_affine_does_not() {
        use crate::render::accel::intersect::{intersect_triangle, TriangleEdges};
        // A triangle slanted in depth: v0 near (depth 1), v1 and v2 far (depth 5).
        let cam = Camera { fov: Fov::Y(90.0), near: 0.1, ..Camera::default() };
        let view = cam.view(100, 100);
        let t = Triangle {
            v: [Vec3::new(-0.8, -0.8, -1.0), Vec3::new(4.0, -4.0, -5.0), Vec3::new(0.0, 4.0, -5.0)],
            n: [Vec3::Z; 3],
            uv: [Vec2::ZERO; 3],
            material: 0,
            object: 0,
            two_sided: true,
        };
        let mut out = Vec::new();
        setup_triangle(&view, &t, 0, Vec2::splat(0.5), true, &mut out);
        assert_eq!(out.len(), 1);
        let st = out[0];
        // Pixel (40, 55): its sample is inside the projection.
        let q = Vec2::new(40.5, 55.5);
        let l = st.screen_weights(q);
        assert!(l.iter().all(|&w| w > 0.0), "{l:?}");
        let inv_z = st.affine_depth_at(l);
        let [b1, b2] = st.bary_at(l, inv_z);
        let ray = view.eye_ray(q.x, q.y);
        let (_, r1, r2) = intersect_triangle(&ray, &TriangleEdges::new(&t), f32::INFINITY).unwrap();
        assert!((b1 - r1).abs() < 1e-5 && (b2 - r2).abs() < 1e-5, "perspective-correct ({b1}, {b2}) vs ray ({r1}, {r2})");
        // The screen-space (affine) weights are those of the projection, not of the surface point.
        // Map them back to the original vertex order (the setup may have swapped 1 and 2).
        let affine = st.affine_weights(l);
        assert!((affine.y - r1).abs() > 0.05 || (affine.z - r2).abs() > 0.05, "affine {affine:?} vs ray ({r1}, {r2})");
        // By hand: 1/z is affine in the image; at the vertices it is 1 and 1/5.
        assert!(st.affine_depth.contains(&1.0) && st.affine_depth.contains(&0.2));
        assert!(inv_z > 0.2 && inv_z < 1.0);
    }
}
