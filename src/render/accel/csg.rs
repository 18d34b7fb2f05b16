//! Rays against constructive solid geometry (Computer Graphics from Scratch,
//! ch. 5; CGPP exercise 15.7): along a ray, each solid operand is a sorted
//! list of inside intervals over the whole line (a sphere: its two roots; a
//! closed mesh: every triangle crossing, an entry where the ray runs against
//! the geometric normal, an exit where it runs with it, turned into
//! intervals by counting); a node combines its operands' lists with its
//! boolean operation by one sweep over their boundaries. The hit is the first
//! boundary of the root's list with `0 < t < t_max`.
//!
//! The ray casters ask here after their BVH or scan. The rasterizers bring
//! their own per-operand lists, from the fragments of an A-buffer
//! (`raster/csg.rs`), and combine them with the same sweep (`resolve_lists`,
//! `count_intervals`), so the families agree wherever they see the same
//! boundaries. A CSG hit is an
//! ordinary `SurfaceHit` (kind `Csg`) with the winning operand surface's
//! material, uv and normal; the normal of a subtracted operand is flipped,
//! so it points out of the resulting solid (into a cavity).

use crate::math::{Ray, Vec2, Vec3};
use crate::render::{Occluder, RayCounts};
use crate::scene::csg::{Csg, CsgNode, CsgOp};
use crate::scene::{Differentials, PrimitiveKind, Scene, SurfaceHit};

/// Which operand surface a boundary lies on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SurfaceRef {
    /// `Csg::spheres[i]`.
    Sphere(u32),
    /// `Csg::triangles[index]`, with the barycentric weights of v1 and v2.
    Triangle { index: u32, b1: f32, b2: f32 },
}

/// One end of an inside interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    pub t: f32,
    pub surface: SurfaceRef,
    /// The leaf (operand solid) it belongs to, numbered depth first, `a` before `b`.
    pub leaf: u32,
    /// Under an odd number of subtractions: the resulting solid's outward
    /// normal is the surface's inward one.
    pub flipped: bool,
}

/// Where a ray is inside a solid: from `enter.t` to `exit.t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub enter: Boundary,
    pub exit: Boundary,
}

/// One operand solid's intervals along a ray (for the inspector).
#[derive(Clone, Debug, PartialEq)]
pub struct LeafIntervals {
    /// Its path in the tree: "a", "b.a", ...
    pub path: String,
    /// "sphere" or "mesh".
    pub kind: &'static str,
    pub intervals: Vec<Interval>,
}

/// Everything the interval rule did for one ray and one object.
#[derive(Clone, Debug, PartialEq)]
pub struct Explanation {
    pub object: u32,
    /// The operation at the top of the tree.
    pub op: CsgOp,
    pub leaves: Vec<LeafIntervals>,
    pub combined: Vec<Interval>,
    /// The boundary that became the hit, and whether it enters the solid.
    pub winner: Option<(Boundary, bool)>,
}

/// Whether the ray's segment `(t0, t1)` meets the box `[lo, hi]`.
#[inline]
fn segment_meets_box(ray: &Ray, lo: Vec3, hi: Vec3, t0: f32, t1: f32) -> bool {
    let inv = ray.dir.recip();
    let a = (lo - ray.origin) * inv;
    let b = (hi - ray.origin) * inv;
    // 0 * inf is NaN where the ray runs in a face's plane: min/max skip NaNs.
    let near = a.min(b).max_element().max(t0);
    let far = a.max(b).min_element().min(t1);
    !(near > far)
}

/// The two-sided Möller-Trumbore test over the whole line: `(t, b1, b2,
/// entering)`, `t` of either sign.
#[inline]
fn crossing(ray: &Ray, v0: Vec3, e1: Vec3, e2: Vec3) -> Option<(f32, f32, f32, bool)> {
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    let epsilon = 8.0 * f32::EPSILON * e1.length() * e2.length();
    if !(det.abs() > epsilon) {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - v0;
    let b1 = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = ray.dir.dot(q) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    // det > 0: the ray meets the front face, against the outward normal.
    t.is_finite().then_some((t, b1, b2, det > 0.0))
}

/// A sphere's interval over the whole line (Ray Tracing Gems ch. 7's
/// discriminant, as `intersect_sphere` forms it).
#[inline]
pub fn sphere_interval(ray: &Ray, center: Vec3, radius: f32) -> Option<(f32, f32)> {
    let f = ray.origin - center;
    let b = -f.dot(ray.dir);
    let l = f + ray.dir * b;
    let dist = l.length();
    let disc = (radius - dist) * (radius + dist);
    if !(disc >= 0.0) {
        return None;
    }
    let h = disc.sqrt();
    Some((b - h, b + h))
}

/// Crossings sorted by t turned into intervals: inside wherever more entries
/// than exits lie behind (a ray through an edge crosses both its triangles,
/// which the count absorbs).
fn mesh_intervals(csg: &Csg, first: u32, end: u32, ray: &Ray, leaf: u32, flipped: bool, tests: &mut u64) -> Vec<Interval> {
    let mut crossings: Vec<(Boundary, bool)> = Vec::new();
    for index in first..end {
        let tri = &csg.triangles[index as usize];
        *tests += 1;
        let (e1, e2) = (tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]);
        if let Some((t, b1, b2, entering)) = crossing(ray, tri.v[0], e1, e2) {
            crossings.push((Boundary { t, surface: SurfaceRef::Triangle { index, b1, b2 }, leaf, flipped }, entering));
        }
    }
    count_intervals(crossings)
}

/// One solid's boundaries along a line, `(boundary, entering)` in any order,
/// turned into its sorted inside intervals by counting: inside wherever more
/// entries than exits lie behind. Equal t: entries first, so touching pieces
/// stay one interval. The ray casters' mesh operands and the rasterizers'
/// A-buffer both come through here.
pub fn count_intervals(mut crossings: Vec<(Boundary, bool)>) -> Vec<Interval> {
    crossings.sort_by(|a, b| a.0.t.total_cmp(&b.0.t).then(b.1.cmp(&a.1)));
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut start = None;
    for (boundary, entering) in crossings {
        if entering {
            depth += 1;
            if depth == 1 {
                start = Some(boundary);
            }
        } else {
            depth -= 1;
            if depth == 0 {
                if let Some(enter) = start.take() {
                    out.push(Interval { enter, exit: boundary });
                }
            }
            depth = depth.max(0);
        }
    }
    out
}

/// Combines two sorted interval lists with `op` by one sweep over their
/// boundaries (ties: `a`'s first, entries before exits).
fn combine(op: CsgOp, a: &[Interval], b: &[Interval]) -> Vec<Interval> {
    // (boundary, from b, entering)
    let mut events: Vec<(Boundary, bool, bool)> = Vec::with_capacity(2 * (a.len() + b.len()));
    for (list, from_b) in [(a, false), (b, true)] {
        for iv in list {
            events.push((iv.enter, from_b, true));
            events.push((iv.exit, from_b, false));
        }
    }
    events.sort_by(|x, y| x.0.t.total_cmp(&y.0.t).then(y.2.cmp(&x.2)).then(x.1.cmp(&y.1)));
    let (mut in_a, mut in_b) = (0i32, 0i32);
    let mut start: Option<Boundary> = None;
    let mut out = Vec::new();
    for (boundary, from_b, entering) in events {
        let was = op.inside(in_a > 0, in_b > 0);
        let d = if entering { 1 } else { -1 };
        if from_b {
            in_b += d;
        } else {
            in_a += d;
        }
        let now = op.inside(in_a > 0, in_b > 0);
        match (was, now) {
            (false, true) => start = Some(boundary),
            (true, false) => {
                if let Some(enter) = start.take() {
                    out.push(Interval { enter, exit: boundary });
                }
            }
            _ => {}
        }
    }
    out
}

/// The intervals of `node` along `ray`, each leaf's own list from the ray
/// tests (spheres through their roots, meshes through their crossings).
fn node_intervals(csg: &Csg, ray: &Ray, tests: &mut u64, trace: &mut Option<&mut Vec<LeafIntervals>>) -> Vec<Interval> {
    let mut leaf_list = |node: &CsgNode, leaf: u32, flipped: bool| -> Vec<Interval> {
        match node {
            CsgNode::Sphere(i) => {
                *tests += 1;
                let s = &csg.spheres[*i as usize];
                match sphere_interval(ray, s.center, s.radius) {
                    Some((t0, t1)) => {
                        let b = |t| Boundary { t, surface: SurfaceRef::Sphere(*i), leaf, flipped };
                        vec![Interval { enter: b(t0), exit: b(t1) }]
                    }
                    None => Vec::new(),
                }
            }
            CsgNode::Mesh { first, end, lo, hi } => {
                if segment_meets_box(ray, *lo, *hi, f32::NEG_INFINITY, f32::INFINITY) {
                    mesh_intervals(csg, *first, *end, ray, leaf, flipped, tests)
                } else {
                    Vec::new()
                }
            }
            CsgNode::Op { .. } => Vec::new(),
        }
    };
    tree_intervals(&csg.root, "", false, &mut 0, trace, &mut leaf_list)
}

/// The intervals of `node`: each leaf's list from `leaf_list(leaf node, leaf
/// number, flipped)`, the lists combined up the tree by each node's
/// operation. `next_leaf` numbers the leaves depth first, `a` before `b`;
/// `trace` (the inspector's) collects each leaf's own list.
fn tree_intervals<F: FnMut(&CsgNode, u32, bool) -> Vec<Interval>>(
    node: &CsgNode,
    path: &str,
    flipped: bool,
    next_leaf: &mut u32,
    trace: &mut Option<&mut Vec<LeafIntervals>>,
    leaf_list: &mut F,
) -> Vec<Interval> {
    let kind = match node {
        CsgNode::Op { op, a, b } => {
            let join = |side: &str| if path.is_empty() { side.to_string() } else { format!("{path}.{side}") };
            let (pa, pb) = match trace {
                Some(_) => (join("a"), join("b")),
                None => (String::new(), String::new()),
            };
            let la = tree_intervals(a, &pa, flipped, next_leaf, trace, leaf_list);
            let lb = tree_intervals(b, &pb, flipped ^ (*op == CsgOp::Difference), next_leaf, trace, leaf_list);
            return combine(*op, &la, &lb);
        }
        CsgNode::Sphere(_) => "sphere",
        CsgNode::Mesh { .. } => "mesh",
    };
    let leaf = *next_leaf;
    *next_leaf += 1;
    let list = leaf_list(node, leaf, flipped);
    if let Some(t) = trace {
        t.push(LeafIntervals { path: path.to_string(), kind, intervals: list.clone() });
    }
    list
}

/// One leaf (operand solid) of an object, in the order the interval rule numbers them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leaf<'c> {
    pub node: &'c CsgNode,
    /// Under an odd number of subtractions (see `Boundary::flipped`).
    pub flipped: bool,
}

/// The leaves of `csg`, numbered as `Boundary::leaf` numbers them.
pub fn leaves(csg: &Csg) -> Vec<Leaf<'_>> {
    fn walk<'c>(node: &'c CsgNode, flipped: bool, out: &mut Vec<Leaf<'c>>) {
        match node {
            CsgNode::Op { op, a, b } => {
                walk(a, flipped, out);
                walk(b, flipped ^ (*op == CsgOp::Difference), out);
            }
            _ => out.push(Leaf { node, flipped }),
        }
    }
    let mut out = Vec::new();
    walk(&csg.root, false, &mut out);
    out
}

/// The interval rule over lists given per leaf (the rasterizers' A-buffer):
/// `leaf_list(leaf number, flipped)` is that leaf's sorted intervals; they
/// are combined up the tree exactly as the ray casters combine theirs. The
/// winning boundary below `t_max` for a ray from outside, and, with
/// `explain`, the whole account (`object` as in `explain`).
pub fn resolve_lists<F: FnMut(u32, bool) -> Vec<Interval>>(csg: &Csg, t_max: f32, explain: bool, mut leaf_list: F) -> (Option<(Boundary, bool)>, Option<Explanation>) {
    let mut leaves = Vec::new();
    let mut trace = explain.then_some(&mut leaves);
    let combined = tree_intervals(&csg.root, "", false, &mut 0, &mut trace, &mut |_, leaf, flipped| leaf_list(leaf, flipped));
    let winner = first_boundary(&combined, t_max, false);
    let e = explain.then(|| Explanation { object: csg.object, op: root_op(csg), leaves, combined, winner });
    (winner, e)
}

fn root_op(csg: &Csg) -> CsgOp {
    match &csg.root {
        CsgNode::Op { op, .. } => *op,
        _ => CsgOp::Union,
    }
}

/// The first boundary of `list` with `0 < t < t_max`, and whether it enters
/// the solid. Exits count only for rays travelling inside (`inside`, as
/// refracted rays do for spheres); other rays that start inside the solid
/// do not see it from within, as with spheres.
fn first_boundary(list: &[Interval], t_max: f32, inside: bool) -> Option<(Boundary, bool)> {
    for iv in list {
        if iv.enter.t > 0.0 {
            return (iv.enter.t < t_max).then_some((iv.enter, true));
        }
        if inside && iv.exit.t > 0.0 {
            return (iv.exit.t < t_max).then_some((iv.exit, false));
        }
    }
    None
}

/// The hit of object `index` along `ray` with `0 < t < t_max`.
pub fn closest(scene: &Scene, index: u32, ray: &Ray, t_max: f32, inside: bool) -> Option<SurfaceHit> {
    let mut tests = 0;
    object_closest(scene, index, ray, t_max, inside, &mut tests)
}

fn object_closest(scene: &Scene, index: u32, ray: &Ray, t_max: f32, inside: bool, tests: &mut u64) -> Option<SurfaceHit> {
    let csg = &scene.csgs[index as usize];
    if !segment_meets_box(ray, csg.lo, csg.hi, 0.0, t_max) {
        return None;
    }
    let list = node_intervals(csg, ray, tests, &mut None);
    let (b, _) = first_boundary(&list, t_max, inside)?;
    Some(surface_hit(scene, index, b, ray))
}

/// The nearest CSG hit of the scene with `0 < t < t_max` (objects in order,
/// ties to the earlier one): what the ray casters test after everything else.
#[inline]
pub fn closest_in_scene(scene: &Scene, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts) -> Option<SurfaceHit> {
    if scene.csgs.is_empty() {
        return None;
    }
    let mut best: Option<SurfaceHit> = None;
    let mut limit = t_max;
    for i in 0..scene.csgs.len() as u32 {
        if let Some(h) = object_closest(scene, i, ray, limit, inside, &mut counts.tests) {
            limit = h.t;
            best = Some(h);
        }
    }
    best
}

/// The first CSG object entered along `ray` with `0 < t < t_max` (shadow rays).
#[inline]
pub fn occluder_in_scene(scene: &Scene, ray: &Ray, t_max: f32, counts: &mut RayCounts) -> Option<Occluder> {
    for (i, csg) in scene.csgs.iter().enumerate() {
        if !segment_meets_box(ray, csg.lo, csg.hi, 0.0, t_max) {
            continue;
        }
        let list = node_intervals(csg, ray, &mut counts.tests, &mut None);
        if let Some((b, _)) = first_boundary(&list, t_max, false) {
            return Some(Occluder { kind: PrimitiveKind::Csg, index: i as u32, t: b.t });
        }
    }
    None
}

/// The interval lists of object `index` along `ray`, each leaf's and the
/// combined one, and the boundary that wins below `t_max` (the inspector's
/// and `pinhole pixel`'s account of a CSG hit).
pub fn explain(scene: &Scene, index: u32, ray: &Ray, t_max: f32, inside: bool) -> Option<Explanation> {
    let csg = scene.csgs.get(index as usize)?;
    let mut leaves = Vec::new();
    let combined = node_intervals(csg, ray, &mut 0, &mut Some(&mut leaves));
    let winner = first_boundary(&combined, t_max, inside);
    Some(Explanation { object: csg.object, op: root_op(csg), leaves, combined, winner })
}

impl Explanation {
    /// Text lines: each operand's intervals, the combined ones, the winner.
    pub fn lines(&self) -> Vec<String> {
        let fmt = |list: &[Interval]| -> String {
            if list.is_empty() {
                return "none".into();
            }
            list.iter().map(|iv| format!("[{:.4}, {:.4}]", iv.enter.t, iv.exit.t)).collect::<Vec<_>>().join(" ")
        };
        let op = self.op.name();
        let mut out = Vec::new();
        for l in &self.leaves {
            out.push(format!("operand {} ({}): {}", l.path, l.kind, fmt(&l.intervals)));
        }
        out.push(format!("combined ({op} at the top): {}", fmt(&self.combined)));
        out.push(match &self.winner {
            Some((b, entering)) => format!(
                "won: t = {:.4}, the result's {}, on the surface of operand {} ({}){}",
                b.t,
                if *entering { "entry" } else { "exit" },
                self.leaves.get(b.leaf as usize).map(|l| l.path.as_str()).unwrap_or("?"),
                match b.surface {
                    SurfaceRef::Sphere(_) => "sphere".to_string(),
                    SurfaceRef::Triangle { index, .. } => format!("mesh triangle {index}"),
                },
                if b.flipped { ", its normal flipped (a subtracted surface)" } else { "" }
            ),
            None => "won: nothing (no boundary in front of the ray)".into(),
        });
        out
    }
}

/// The surface record of boundary `b` of object `index` along `ray`.
pub fn surface_hit(scene: &Scene, index: u32, b: Boundary, ray: &Ray) -> SurfaceHit {
    let csg = &scene.csgs[index as usize];
    let t = b.t;
    let (position, outward, shading, uv, barycentric, material) = match b.surface {
        SurfaceRef::Sphere(i) => {
            let s = &csg.spheres[i as usize];
            let position = ray.at(t);
            let outward = ((position - s.center) / s.radius).normalize_or(Vec3::Y);
            let u = 0.5 + outward.z.atan2(outward.x) * -0.5 * std::f32::consts::FRAC_1_PI;
            let v = 0.5 + outward.y.clamp(-1.0, 1.0).asin() * std::f32::consts::FRAC_1_PI;
            (position, outward, outward, Vec2::new(u, v), Vec3::ZERO, s.material)
        }
        SurfaceRef::Triangle { index: ti, b1, b2 } => {
            let tri = &csg.triangles[ti as usize];
            let w = Vec3::new(1.0 - b1 - b2, b1, b2);
            let position = tri.v[0] * w.x + tri.v[1] * w.y + tri.v[2] * w.z;
            let outward = tri.geometric_normal();
            let shading = (tri.n[0] * w.x + tri.n[1] * w.y + tri.n[2] * w.z).normalize_or(outward);
            let uv = tri.uv[0] * w.x + tri.uv[1] * w.y + tri.uv[2] * w.z;
            (position, outward, shading, uv, w, tri.material)
        }
    };
    let sign = if b.flipped { -1.0 } else { 1.0 };
    let (mut n, mut ns) = (outward * sign, shading * sign);
    let back_face = n.dot(ray.dir) > 0.0;
    if back_face {
        n = -n;
        ns = -ns;
    }
    SurfaceHit {
        position,
        geometric_normal: n,
        shading_normal: ns,
        barycentric,
        uv,
        t,
        kind: PrimitiveKind::Csg,
        primitive: index,
        object: csg.object,
        material,
        back_face,
        diff: Differentials::ZERO,
    }
}

/// Settings under which CSG objects cannot be drawn, as one sentence: shadow
/// maps and shadow volumes are built from triangles and spheres only, and the
/// wireframe and shadow-map views draw those only.
pub fn check(scene: &Scene, settings: &crate::render::RenderSettings) -> Result<(), String> {
    use crate::render::inspect::debug::View;
    use crate::render::ShadowMode;
    if scene.csgs.is_empty() {
        return Ok(());
    }
    if matches!(settings.shadows, ShadowMode::Map | ShadowMode::Volume) {
        return Err(format!(
            "--shadows {} cannot include csg objects (shadow maps and volumes are built from triangles and spheres); use --shadows ray or none",
            settings.shadows.name()
        ));
    }
    if matches!(settings.view, View::Wireframe | View::Shadowmap) {
        return Err(format!("the {} view cannot show csg objects (it draws triangles and spheres only)", settings.view.name()));
    }
    Ok(())
}

/// For a CSG hit found along `ray` (bounded by `t_max`): the intervals and
/// the winning boundary as text lines (`Explanation::lines`); `None` for
/// other hits. A hit on an exit boundary (seen from inside) was found by a
/// ray travelling inside the solid.
pub fn explain_hit(scene: &Scene, hit: &SurfaceHit, ray: &Ray, t_max: f32) -> Option<Explanation> {
    if hit.kind != PrimitiveKind::Csg {
        return None;
    }
    explain(scene, hit.primitive, ray, t_max, hit.back_face)
}
