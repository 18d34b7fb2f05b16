//! The painter's algorithm (CGFS ch. 12; Newell, Newell and Sancha 1972):
//! no depth buffer. The primitives are sorted back to front and drawn in
//! that order, each over the ones before it, so what a sample shows is the
//! last primitive drawn there.
//!
//! The order is made in two steps:
//!
//! 1. Sort by the farthest point of each primitive (its largest view depth:
//!    the farthest vertex of a triangle, centre + radius of a sphere), as
//!    CGFS sorts. Equal keys draw the later primitive in scene order first,
//!    so the earlier one ends on top, as the depth buffer's ties resolve.
//! 2. Newell-Newell-Sancha: the farthest primitive P is drawn only if no
//!    primitive Q whose depth extent overlaps P's could be hidden by it. P
//!    cannot hide Q when their screen boxes are disjoint, when P lies
//!    entirely on the far side of Q's plane, when Q lies entirely on the
//!    near side of P's plane, or when their (snapped) projections do not
//!    overlap. Failing all of those, if the same tests say Q may be drawn
//!    before P, Q moves to the front of the list and is checked in turn.
//!    A primitive moves at most once: a second move would be a cycle.
//!
//! Pairs that neither order satisfies - cyclic overlaps and primitives that
//! interpenetrate - are drawn in key order: there, and only there, the
//! algorithm is wrong, as the books warn (a correct painter would split
//! them). The tests per frame are bounded (`MAX_TESTS_PER_PRIMITIVE`); once
//! the budget is spent the rest is drawn in key order.
//!
//! Coverage is `fixed`'s (the same snapped triangles and top-left rule), and
//! spheres are drawn per pixel with their own front surface, so wherever the
//! order is right the image equals `rasterize:fixed`'s bit for bit.

use crate::render::raster::fixed::FixedTri;
use crate::render::raster::rect::PixelRect;
use crate::math::Vec3;
use crate::render::PassJob;
use std::collections::VecDeque;

/// Pair tests allowed per primitive per frame (layer), on average.
pub const MAX_TESTS_PER_PRIMITIVE: usize = 64;

/// One primitive of the draw order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Paint {
    /// Index into the layer's snapped triangles.
    Triangle(u32),
    /// Index into the scene's spheres.
    Sphere(u32),
}

/// How the ordering went, for tests and statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OrderStats {
    /// Pairs tested.
    pub tests: usize,
    /// Primitives moved ahead of the one the key put first.
    pub moves: usize,
    /// Overlapping pairs that no test could order (cycles, interpenetration).
    pub unresolved: usize,
    /// The test budget ran out.
    pub budget_spent: bool,
}

/// What the ordering tests need of a primitive, in camera space (eye at
/// the origin, looking down -z; depths are -z).
struct Item {
    paint: Paint,
    rect: PixelRect,
    zmin: f64,
    zmax: f64,
    shape: Shape,
}

enum Shape {
    /// The plane of the scene triangle (n . p = d) and its camera-space
    /// vertices; `tri` indexes the snapped triangles (exact 2D overlap test).
    Triangle { n: [f64; 3], d: f64, v: [[f64; 3]; 3], tri: usize },
    Sphere { c: [f64; 3], r: f64 },
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn f64v(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Which side of a triangle's plane the points are on, relative to the eye:
/// +1 all on the eye's side (or on the plane), -1 all on the far side (or on
/// the plane), 0 on both sides. Points within a relative tolerance of the
/// plane count as on it (shared vertices, coplanar neighbours).
fn side_of_plane(n: [f64; 3], d: f64, points: &[[f64; 3]]) -> i32 {
    let len = dot(n, n).sqrt();
    let eye = -d; // n . 0 - d
    if len == 0.0 || eye == 0.0 {
        return 0;
    }
    let scale = points.iter().flatten().fold(d.abs() / len, |m, c| m.max(c.abs()));
    let eps = 1e-6 * len * (1.0 + scale);
    let (mut near, mut far) = (false, false);
    for p in points {
        let s = (dot(n, *p) - d) * eye.signum();
        near |= s > eps;
        far |= s < -eps;
    }
    match (near, far) {
        (false, _) => -1,
        (true, false) => 1,
        (true, true) => 0,
    }
}

/// Signed distance of a sphere's centre from a triangle's plane, positive
/// on the eye's side, and the sphere's radius scaled the same way.
fn sphere_side(n: [f64; 3], d: f64, c: [f64; 3], r: f64) -> i32 {
    let len = dot(n, n).sqrt();
    let eye = -d;
    if len == 0.0 || eye == 0.0 {
        return 0;
    }
    let s = (dot(n, c) - d) * eye.signum() / len;
    if s >= r {
        1
    } else if s <= -r {
        -1
    } else {
        0
    }
}

/// True when the snapped projections of `a` and `b` share no sample: an
/// edge of one has the other's vertices strictly outside, or on the edge's
/// line with the third vertex outside (a shared edge, whose samples the
/// top-left rule gives to exactly one of them).
fn projections_disjoint(a: &FixedTri, b: &FixedTri) -> bool {
    let separated_by = |s: &FixedTri, o: &FixedTri| {
        (0..3).any(|k| {
            let e: [i128; 3] = [0, 1, 2].map(|j| s.edge_at::<i128>(k, o.v[j][0], o.v[j][1]));
            let (neg, zero) = (e.iter().filter(|x| **x < 0).count(), e.iter().filter(|x| **x == 0).count());
            neg == 3 || (neg == 1 && zero == 2)
        })
    };
    separated_by(a, b) || separated_by(b, a)
}

/// True when drawing `p` first and `q` over it is right wherever they overlap:
/// `p` can hide no part of `q`.
fn may_draw_before(p: &Item, q: &Item, fts: &[FixedTri]) -> bool {
    if p.zmin >= q.zmax || p.rect.intersect(&q.rect).is_empty() {
        return true;
    }
    match (&p.shape, &q.shape) {
        (Shape::Triangle { n: np, d: dp, v: vp, tri: tp }, Shape::Triangle { n: nq, d: dq, v: vq, tri: tq }) => {
            side_of_plane(*nq, *dq, vp) == -1 || side_of_plane(*np, *dp, vq) == 1 || projections_disjoint(&fts[*tp], &fts[*tq])
        }
        (Shape::Sphere { c, r }, Shape::Triangle { n, d, .. }) => sphere_side(*n, *d, *c, *r) == -1,
        (Shape::Triangle { n, d, .. }, Shape::Sphere { c, r }) => sphere_side(*n, *d, *c, *r) == 1,
        (Shape::Sphere { c: cp, r: rp }, Shape::Sphere { c: cq, r: rq }) => {
            // Disjoint spheres: the plane tangent to p, facing q, separates
            // them. An eye on q's side meets q before p along every ray.
            let axis = sub(*cq, *cp);
            let dist = dot(axis, axis).sqrt();
            dist > rp + rq && -dot(axis, *cp) / dist > *rp
        }
    }
}

/// The primitives of a layer in the order the painter draws them: `fts`
/// (the snapped triangles, every row of the image) and the spheres with
/// their bounds (`None`: not on screen).
pub fn draw_order(job: &PassJob, fts: &[FixedTri], spheres: &[Option<PixelRect>]) -> (Vec<Paint>, OrderStats) {
    let view = job.view;
    let scene = &job.prepared.scene;
    let mut items: Vec<Item> = Vec::with_capacity(fts.len() + spheres.len());
    for (i, ft) in fts.iter().enumerate() {
        let depths = [0, 1, 2].map(|k| ft.st.vertex_depth(k) as f64);
        let t = &scene.triangle(ft.st.tri);
        let v = t.v.map(|p| f64v(view.to_camera(p)));
        let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
        let d = dot(n, v[0]);
        items.push(Item {
            paint: Paint::Triangle(i as u32),
            rect: ft.bbox,
            zmin: depths.iter().copied().fold(f64::INFINITY, f64::min),
            zmax: depths.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            shape: Shape::Triangle { n, d, v, tri: i },
        });
    }
    for (si, b) in spheres.iter().enumerate() {
        let Some(rect) = b else { continue };
        let s = &scene.spheres[si];
        let c = f64v(view.to_camera(s.center));
        let r = s.radius as f64;
        items.push(Item { paint: Paint::Sphere(si as u32), rect: *rect, zmin: -c[2] - r, zmax: -c[2] + r, shape: Shape::Sphere { c, r } });
    }
    // Farthest first; equal keys: later in scene order first (triangles
    // come before spheres in scene order, as the other variants draw them).
    let mut sorted: Vec<usize> = (0..items.len()).collect();
    sorted.sort_by(|&a, &b| items[b].zmax.total_cmp(&items[a].zmax).then(b.cmp(&a)));

    let mut stats = OrderStats::default();
    let mut budget = MAX_TESTS_PER_PRIMITIVE * items.len();
    // Moved primitives sit at the front of `pending`; the rest keep their
    // key order behind them, so the scan for depth overlaps can stop at the
    // first unmoved primitive that lies entirely nearer than the front one.
    let mut pending: VecDeque<usize> = sorted.into();
    let mut moved = vec![false; items.len()];
    let mut out = Vec::with_capacity(items.len());
    while let Some(&p) = pending.front() {
        let mut move_ahead = None;
        for (i, &q) in pending.iter().enumerate().skip(1) {
            if !moved[q] && items[q].zmax <= items[p].zmin {
                break;
            }
            if budget == 0 {
                stats.budget_spent = true;
                break;
            }
            budget -= 1;
            stats.tests += 1;
            if may_draw_before(&items[p], &items[q], fts) {
                continue;
            }
            if !moved[q] && may_draw_before(&items[q], &items[p], fts) {
                move_ahead = Some(i);
                break;
            }
            stats.unresolved += 1;
        }
        match move_ahead {
            Some(i) => {
                let q = pending.remove(i).unwrap_or(p);
                moved[q] = true;
                stats.moves += 1;
                pending.push_front(q);
            }
            None => {
                pending.pop_front();
                out.push(items[p].paint);
            }
        }
    }
    (out, stats)
}
