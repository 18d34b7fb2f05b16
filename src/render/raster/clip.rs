//! Near-plane clipping in camera space (CGPP 15.6.3), and clipping against
//! every plane of the view volume (Computer Graphics from Scratch, ch. 11)
//! for `--clip frustum`.
//!
//! The eye rays start on the near plane, so the ray tracer never sees anything
//! nearer than `near`; the rasterizer gets the same result by cutting every
//! triangle with the plane z = -near before projecting it. A triangle that
//! crosses the plane becomes one triangle (one vertex in front) or a quad split
//! into two triangles (two vertices in front). Every clipped vertex carries its
//! barycentric coordinates in the ORIGINAL triangle, so fragments of the pieces
//! still describe points of the original triangle.

use crate::math::{Vec2, Vec3};
use crate::named::named_enum;
use crate::scene::CameraView;

named_enum! {
    /// Which planes of the view volume triangle setup clips against.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum ClipMode ("clip mode") {
        /// The near plane only: the pieces are what gets rasterized, and the
        /// pixel box of a piece is clamped to the image.
        #[default]
        Near = "near",
        /// The near plane and the four side planes: a triangle wholly
        /// outside one of them is dropped before projection, and the pixel
        /// box of each piece shrinks to the part inside the image. The
        /// pieces rasterized stay those of the near clip, so every fragment
        /// and every interpolated value is the same.
        Frustum = "frustum",
    }
}

/// Pixels by which the side planes of `clip_frustum_box` lie outside the
/// image: what the clipped polygon's rounding can move a point by is far
/// below it, so no sample inside the image is ever cut off.
pub const GUARD_PIXELS: f32 = 2.0;

/// A plane of the view volume in camera space: a point `p` is inside
/// when `n . p + d >= 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SidePlane {
    pub n: Vec3,
    pub d: f32,
}

impl SidePlane {
    /// How far inside `p` lies, in units of `|n|`.
    #[inline]
    pub fn distance(&self, p: Vec3) -> f32 {
        self.n.dot(p) + self.d
    }

    /// The same plane with a unit normal.
    pub fn normalized(&self) -> SidePlane {
        let l = self.n.length();
        SidePlane { n: self.n / l, d: self.d / l }
    }
}

/// The side planes of the view volume grown by `GUARD_PIXELS`, in camera
/// space, with inward normals: through the eye for a perspective camera,
/// parallel to the view axis for an orthographic one.
pub fn side_planes(view: &CameraView) -> [SidePlane; 4] {
    let gx = view.half_x * (1.0 + 2.0 * GUARD_PIXELS / view.width.max(1) as f32);
    let gy = view.half_y * (1.0 + 2.0 * GUARD_PIXELS / view.height.max(1) as f32);
    if view.is_orthographic() {
        // |x| <= gx  <=>  gx - x >= 0 and gx + x >= 0, and so on.
        let plane = |n: Vec3, d: f32| SidePlane { n, d };
        return [plane(Vec3::NEG_X, gx), plane(Vec3::X, gx), plane(Vec3::NEG_Y, gy), plane(Vec3::Y, gy)];
    }
    // x / -z <= gx  <=>  gx * -z - x >= 0, and so on.
    [Vec3::new(-1.0, 0.0, -gx), Vec3::new(1.0, 0.0, -gx), Vec3::new(0.0, -1.0, -gy), Vec3::new(0.0, 1.0, -gy)].map(|n| SidePlane { n, d: 0.0 })
}

/// What clipping against the whole view volume leaves of a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrustumClip {
    /// Wholly outside one plane: nothing.
    Outside,
    /// Wholly inside every plane: the triangle itself.
    Inside,
    /// Cut: the image-space box of what is left.
    Cut(Vec2, Vec2),
}

/// Clips the camera-space triangle `c` against the near plane and the side
/// planes of the view volume (Sutherland-Hodgman, one plane after the
/// other). Only the box of what is left is kept: the pixels a triangle can
/// cover. A triangle wholly inside or wholly outside one plane is decided
/// from its corners alone.
pub fn clip_frustum(c: [Vec3; 3], view: &CameraView, planes: &[SidePlane; 4]) -> FrustumClip {
    let mut inside = c.iter().all(|p| -p.z >= view.near);
    if c.iter().all(|p| -p.z < view.near) {
        return FrustumClip::Outside;
    }
    for n in planes {
        let d = c.map(|p| n.distance(p));
        if d.iter().all(|&d| d < 0.0) {
            return FrustumClip::Outside;
        }
        inside &= d.iter().all(|&d| d >= 0.0);
    }
    if inside {
        return FrustumClip::Inside;
    }
    match clip_frustum_box(c, view, planes) {
        Some((lo, hi)) => FrustumClip::Cut(lo, hi),
        None => FrustumClip::Outside,
    }
}

/// The image-space box of what clipping `c` against the near plane and the
/// side planes leaves, or `None` when nothing is.
pub fn clip_frustum_box(c: [Vec3; 3], view: &CameraView, planes: &[SidePlane; 4]) -> Option<(Vec2, Vec2)> {
    const MAX: usize = 3 + 5;
    let mut poly = [Vec3::ZERO; MAX];
    let mut next = [Vec3::ZERO; MAX];
    poly[..3].copy_from_slice(&c);
    let mut n = 3;
    let near = view.near;
    let mut cut = |poly: &mut [Vec3; MAX], n: usize, dist: &dyn Fn(Vec3) -> f32| -> usize {
        let mut m = 0;
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let (da, db) = (dist(a), dist(b));
            if da >= 0.0 {
                next[m] = a;
                m += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                next[m] = a + (b - a) * (da / (da - db));
                m += 1;
            }
        }
        poly[..m].copy_from_slice(&next[..m]);
        m
    };
    n = cut(&mut poly, n, &|p: Vec3| -p.z - near);
    for plane in planes {
        if n == 0 {
            return None;
        }
        n = cut(&mut poly, n, &|p: Vec3| plane.distance(p));
    }
    if n == 0 {
        return None;
    }
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for p in &poly[..n] {
        // Points cut at the near plane may sit a rounding error nearer.
        let q = view.project_camera(Vec3::new(p.x, p.y, p.z.min(-near * 0.5)));
        lo = lo.min(q);
        hi = hi.max(q);
    }
    Some((lo, hi))
}

/// A camera-space vertex with its barycentric coordinates in the original triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    pub pos: Vec3,
    pub bary: Vec3,
}

/// The result of clipping one triangle: zero, one or two triangles.
#[derive(Clone, Copy, Debug)]
pub struct Clipped {
    tris: [[ClipVertex; 3]; 2],
    len: usize,
}

impl Clipped {
    pub fn as_slice(&self) -> &[[ClipVertex; 3]] {
        &self.tris[..self.len]
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// The corners of an unclipped triangle: camera-space positions with the unit barycentrics.
pub fn triangle_vertices(c: [Vec3; 3]) -> [ClipVertex; 3] {
    [
        ClipVertex { pos: c[0], bary: Vec3::X },
        ClipVertex { pos: c[1], bary: Vec3::Y },
        ClipVertex { pos: c[2], bary: Vec3::Z },
    ]
}

/// Keeps the part of the triangle with view depth `-z >= near` (Sutherland-Hodgman
/// against one plane). Winding is preserved. Points exactly on the plane count as
/// in front, so a triangle lying in the plane is kept whole.
pub fn clip_near(v: [ClipVertex; 3], near: f32) -> Clipped {
    let inside = |c: &ClipVertex| -c.pos.z >= near;
    let mut poly = [v[0]; 4];
    let mut n = 0;
    for i in 0..3 {
        let (a, b) = (v[i], v[(i + 1) % 3]);
        let (ia, ib) = (inside(&a), inside(&b));
        if ia {
            poly[n] = a;
            n += 1;
        }
        if ia != ib {
            // Always parameterised from the vertex in front, so two triangles
            // sharing this edge compute the very same crossing point.
            poly[n] = if ia { crossing(a, b, near) } else { crossing(b, a, near) };
            n += 1;
        }
    }
    let mut out = Clipped { tris: [[v[0]; 3]; 2], len: 0 };
    match n {
        3 => {
            out.tris[0] = [poly[0], poly[1], poly[2]];
            out.len = 1;
        }
        4 => {
            out.tris[0] = [poly[0], poly[1], poly[2]];
            out.tris[1] = [poly[0], poly[2], poly[3]];
            out.len = 2;
        }
        _ => {}
    }
    out
}

/// Where the edge from `front` (in front of the plane) to `back` meets z = -near.
fn crossing(front: ClipVertex, back: ClipVertex, near: f32) -> ClipVertex {
    let (df, db) = (-front.pos.z, -back.pos.z);
    let s = (df - near) / (df - db);
    let mut pos = front.pos + (back.pos - front.pos) * s;
    pos.z = -near;
    ClipVertex { pos, bary: front.bary + (back.bary - front.bary) * s }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn fully_in_front_is_unchanged() {
        let c = [Vec3::new(0.0, 0.0, -2.0), Vec3::new(1.0, 0.0, -2.0), Vec3::new(0.0, 1.0, -3.0)];
        let out = clip_near(triangle_vertices(c), 1.0);
        assert_eq!(out.len(), 1);
        assert_eq!(out.as_slice()[0], triangle_vertices(c));
    }

    #[test]
    fn fully_behind_is_dropped() {
        // All three vertices nearer than the near plane (one even behind the eye).
        let c = [Vec3::new(0.0, 0.0, -0.5), Vec3::new(1.0, 0.0, 0.5), Vec3::new(0.0, 1.0, -0.9)];
        assert!(clip_near(triangle_vertices(c), 1.0).is_empty());
    }

    #[test]
    fn one_vertex_in_front_gives_one_triangle() {
        // v0 at depth 3, v1 and v2 at depth 0 (in the eye plane); near = 1.
        // Edge v0-v1 crosses depth 1 at s = (3 - 1) / (3 - 0) = 2/3:
        //   position (0,0,-3) + 2/3 ((2,0,0) - (0,0,-3)) = (4/3, 0, -1), bary (1/3, 2/3, 0).
        // Edge v2-v0 (parameterised from v0) crosses at s = 2/3 too:
        //   position (0, 4/3, -1), bary (1/3, 0, 2/3).
        let c = [Vec3::new(0.0, 0.0, -3.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)];
        let out = clip_near(triangle_vertices(c), 1.0);
        assert_eq!(out.len(), 1);
        let t = out.as_slice()[0];
        assert_eq!(t[0].pos, c[0]);
        assert_eq!(t[0].bary, Vec3::X);
        assert!(close(t[1].pos, Vec3::new(4.0 / 3.0, 0.0, -1.0)), "{:?}", t[1]);
        assert!(close(t[1].bary, Vec3::new(1.0 / 3.0, 2.0 / 3.0, 0.0)));
        assert!(close(t[2].pos, Vec3::new(0.0, 4.0 / 3.0, -1.0)), "{:?}", t[2]);
        assert!(close(t[2].bary, Vec3::new(1.0 / 3.0, 0.0, 2.0 / 3.0)));
    }

    #[test]
    fn two_vertices_in_front_give_two_triangles() {
        // v0 and v1 at depth 2, v2 behind the eye at depth -2; near = 1.
        // Edge v1-v2 crosses at s = (2 - 1) / (2 + 2) = 1/4: position
        // (2,0,-2) + 1/4 ((0,2,2) - (2,0,-2)) = (1.5, 0.5, -1), bary (0, 3/4, 1/4).
        // Edge v2-v0, from v0: (0,0,-2) + 1/4 ((0,2,2) - (0,0,-2)) = (0, 0.5, -1), bary (3/4, 0, 1/4).
        let c = [Vec3::new(0.0, 0.0, -2.0), Vec3::new(2.0, 0.0, -2.0), Vec3::new(0.0, 2.0, 2.0)];
        let out = clip_near(triangle_vertices(c), 1.0);
        assert_eq!(out.len(), 2);
        let [a, b] = [out.as_slice()[0], out.as_slice()[1]];
        let p = Vec3::new(1.5, 0.5, -1.0);
        let q = Vec3::new(0.0, 0.5, -1.0);
        assert_eq!((a[0].pos, a[1].pos), (c[0], c[1]));
        assert!(close(a[2].pos, p) && close(a[2].bary, Vec3::new(0.0, 0.75, 0.25)), "{a:?}");
        assert_eq!(b[0].pos, c[0]);
        assert!(close(b[1].pos, p));
        assert!(close(b[2].pos, q) && close(b[2].bary, Vec3::new(0.75, 0.0, 0.25)), "{b:?}");
        // Every clipped vertex is the original triangle at its barycentrics.
        for t in out.as_slice() {
            for v in t {
                let from_bary = c[0] * v.bary.x + c[1] * v.bary.y + c[2] * v.bary.z;
                assert!(close(from_bary, v.pos), "{v:?}");
                assert!(-v.pos.z >= 1.0 - 1e-6);
            }
        }
        // Winding is kept: both pieces face the same way as the original.
        let n = (c[1] - c[0]).cross(c[2] - c[0]);
        for t in out.as_slice() {
            assert!((t[1].pos - t[0].pos).cross(t[2].pos - t[0].pos).dot(n) > 0.0);
        }
    }

    #[test]
    fn shared_edge_crossings_agree() {
        // Two triangles sharing the edge a-b that crosses the plane compute the same point.
        let a = Vec3::new(0.3, 0.1, -2.0);
        let b = Vec3::new(-0.7, 0.9, 0.4);
        let t1 = clip_near(triangle_vertices([a, b, Vec3::new(1.0, 1.0, -3.0)]), 0.5);
        let t2 = clip_near(triangle_vertices([b, a, Vec3::new(-1.0, -1.0, -3.0)]), 0.5);
        let on_plane = |c: &Clipped| -> Vec<Vec3> {
            c.as_slice().iter().flatten().filter(|v| v.pos.z == -0.5 && v.bary.z == 0.0).map(|v| v.pos).collect()
        };
        let (p1, p2) = (on_plane(&t1), on_plane(&t2));
        assert!(!p1.is_empty());
        assert!(p1.iter().all(|p| p2.contains(p)), "{p1:?} vs {p2:?}");
    }
}
