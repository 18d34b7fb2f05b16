//! The fast ray caster: a bounding volume hierarchy over the scene's triangles
//! and analytic spheres, built with the binned surface area heuristic (SAH)
//! and traversed near child first.
//!
//! It must see exactly what the brute-force reference sees, so:
//! - leaves call the same `intersect_triangle` / `intersect_sphere` with the
//!   same `TriangleEdges` values (copied, reordered for locality);
//! - when two primitives are hit at exactly the same `t`, the one first in
//!   scene order wins (all triangles before all spheres, then by index), as
//!   brute force's strict `t < best_t` scan does;
//! - node bounds are padded and the slab test is widened a little, so a
//!   rounding difference between the box test and the primitive test can
//!   never cull a primitive the reference hits.
//!
//! Layout: 32-byte nodes; the two children of an interior node sit next to
//! each other in one 64-byte pair (one cache line), so traversal tests both
//! children's boxes from one line. Node 0 is the root, node 1 unused padding.

use super::brute::make_hit;
use super::cast_pass;
use super::intersect::{intersect_sphere, intersect_triangle, TriangleEdges};
use crate::math::{Radiance, Ray};
use crate::render::trace::{PrimitiveTest, Recorder};
use crate::render::{PassJob, PreparedScene, RayCounts, Renderer, SceneQuery};
use crate::scene::{PrimitiveKind, Scene, SurfaceHit};
use glam::{Vec3, Vec3A};

/// Primitive ids: triangle index, or sphere index with this bit set. Ordering
/// the ids as integers orders primitives as brute force scans them.
const SPHERE_BIT: u32 = 1 << 31;
const BINS: usize = 32;
/// Leaves never hold more than this; the SAH decides below it.
const MAX_LEAF: usize = 8;
/// SAH costs of one node visit and one primitive test.
const COST_TRAVERSE: f32 = 1.0;
const COST_INTERSECT: f32 = 1.0;
/// Subtrees with more primitives than this are built in parallel.
const PARALLEL_MIN: usize = 4096;
/// Below this depth the build splits by SAH; deeper it splits at the median,
/// which bounds the depth (and the traversal stack) at MEDIAN_DEPTH + 32.
const MEDIAN_DEPTH: u32 = 32;
const STACK: usize = 64;
/// The slab test's far distance is stretched by this factor (and the near
/// one shrunk) to absorb its rounding and that of the primitive tests.
const SLAB_WIDEN: f32 = 1.0e-5;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    pub fn contains(&self, o: &Aabb) -> bool {
        self.min.cmple(o.min).all() && self.max.cmpge(o.max).all()
    }

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }
}

/// What a node holds, for the viewer and the debugger.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeContent {
    Interior { left: u32, right: u32 },
    /// `count` primitives starting at `first` in the BVH's primitive order
    /// (see `Bvh::primitive`).
    Leaf { first: u32, count: u32 },
}

/// A node: bounds and either two children (`count == 0`, children at
/// `first`, `first + 1`) or `count` primitives starting at `first`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
struct Node {
    min: [f32; 3],
    first: u32,
    max: [f32; 3],
    count: u32,
}

#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
struct NodePair([Node; 2]);

/// The hierarchy, flattened, with the primitives in leaf order.
pub struct Bvh {
    pairs: Vec<NodePair>,
    /// Per primitive slot: the triangle's edges (unused for spheres).
    tris: Vec<TriangleEdges>,
    /// Per primitive slot: triangle index, or sphere index | SPHERE_BIT.
    ids: Vec<u32>,
    depth: u32,
}

/// Bounds and centroid of one primitive during the build.
#[derive(Clone, Copy)]
struct PrimRef {
    min: Vec3A,
    max: Vec3A,
    id: u32,
}

impl PrimRef {
    #[inline]
    fn centroid(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }
}

#[derive(Clone, Copy)]
struct Bounds {
    min: Vec3A,
    max: Vec3A,
}

impl Bounds {
    const EMPTY: Bounds = Bounds { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    #[inline]
    fn grow(&mut self, min: Vec3A, max: Vec3A) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    #[inline]
    fn union(a: Bounds, b: Bounds) -> Bounds {
        Bounds { min: a.min.min(b.min), max: a.max.max(b.max) }
    }

    /// Half the surface area (the SAH only needs ratios).
    #[inline]
    fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A primitive's box, padded so rounding in the ray tests cannot leave a hit
/// outside it.
fn padded(min: Vec3A, max: Vec3A) -> (Vec3A, Vec3A) {
    let extent = (max - min).max_element();
    let magnitude = min.abs().max(max.abs()).max_element();
    let pad = extent * 1.0e-5 + magnitude * 2.0e-6 + f32::MIN_POSITIVE;
    (min - Vec3A::splat(pad), max + Vec3A::splat(pad))
}

/// The build's tree before flattening.
enum Tmp {
    Leaf { b: Bounds, first: u32, count: u32 },
    Inner { b: Bounds, kids: Box<[Tmp; 2]> },
}

impl Tmp {
    fn bounds(&self) -> Bounds {
        match self {
            Tmp::Leaf { b, .. } | Tmp::Inner { b, .. } => *b,
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    b: Bounds,
    n: u32,
}

fn build_rec(refs: &mut [PrimRef], first: u32, depth: u32, max_depth: &mut u32) -> Tmp {
    *max_depth = (*max_depth).max(depth);
    let mut b = Bounds::EMPTY;
    let mut cb = Bounds::EMPTY;
    for r in refs.iter() {
        b.grow(r.min, r.max);
        let c = r.centroid();
        cb.grow(c, c);
    }
    let n = refs.len();
    let leaf = Tmp::Leaf { b, first, count: n as u32 };
    if n <= 1 {
        return leaf;
    }
    let extent = cb.max - cb.min;
    let mut mid = 0;
    if depth < MEDIAN_DEPTH && extent.max_element() > 0.0 {
        // Binned SAH over all three axes in one pass.
        let mut bins = [[Bin { b: Bounds::EMPTY, n: 0 }; BINS]; 3];
        let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(BINS as f32 * 0.99999) / extent, Vec3A::ZERO);
        for r in refs.iter() {
            let k = ((r.centroid() - cb.min) * scale).as_uvec3().min(glam::UVec3::splat(BINS as u32 - 1));
            for a in 0..3 {
                let bin = &mut bins[a][k[a] as usize];
                bin.b.grow(r.min, r.max);
                bin.n += 1;
            }
        }
        let mut best = (f32::INFINITY, 0usize, 0usize);
        for (a, bins) in bins.iter().enumerate() {
            if extent[a] <= 0.0 {
                continue;
            }
            // Right-to-left sweep: cost of the right side of each split plane.
            let mut right_cost = [0.0f32; BINS];
            let mut acc = Bounds::EMPTY;
            let mut cnt = 0u32;
            for i in (1..BINS).rev() {
                acc = Bounds::union(acc, bins[i].b);
                cnt += bins[i].n;
                right_cost[i] = if cnt > 0 { acc.half_area() * cnt as f32 } else { 0.0 };
            }
            let mut acc = Bounds::EMPTY;
            let mut cnt = 0u32;
            for i in 0..BINS - 1 {
                acc = Bounds::union(acc, bins[i].b);
                cnt += bins[i].n;
                if cnt == 0 || cnt as usize == n {
                    continue;
                }
                let cost = acc.half_area() * cnt as f32 + right_cost[i + 1];
                if cost < best.0 {
                    best = (cost, a, i + 1);
                }
            }
        }
        if best.0.is_finite() {
            let split_cost = COST_TRAVERSE + COST_INTERSECT * best.0 / b.half_area().max(f32::MIN_POSITIVE);
            let leaf_cost = COST_INTERSECT * n as f32;
            if n <= MAX_LEAF && leaf_cost <= split_cost {
                return leaf;
            }
            let (_, axis, plane) = best;
            let (lo, s) = (cb.min[axis], scale[axis]);
            let in_left = |r: &PrimRef| (((r.centroid()[axis] - lo) * s) as u32).min(BINS as u32 - 1) < plane as u32;
            // In-place partition.
            let (mut i, mut j) = (0usize, n);
            while i < j {
                if in_left(&refs[i]) {
                    i += 1;
                } else {
                    j -= 1;
                    refs.swap(i, j);
                }
            }
            mid = i;
        }
    }
    if mid == 0 || mid == n {
        // No useful SAH split (coincident centroids, or too deep): a leaf if
        // small enough, else halves by the centroid median.
        if n <= MAX_LEAF {
            return leaf;
        }
        let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
        mid = n / 2;
        refs.select_nth_unstable_by(mid, |p, q| p.centroid()[axis].total_cmp(&q.centroid()[axis]).then(p.id.cmp(&q.id)));
    }
    let (left, right) = refs.split_at_mut(mid);
    let (l, r) = if n > PARALLEL_MIN {
        let (mut dl, mut dr) = (depth, depth);
        let (l, r) = rayon::join(|| build_rec(left, first, depth + 1, &mut dl), || build_rec(right, first + mid as u32, depth + 1, &mut dr));
        *max_depth = (*max_depth).max(dl).max(dr);
        (l, r)
    } else {
        (build_rec(left, first, depth + 1, max_depth), build_rec(right, first + mid as u32, depth + 1, max_depth))
    };
    Tmp::Inner { b: Bounds::union(l.bounds(), r.bounds()), kids: Box::new([l, r]) }
}

fn to_node(b: Bounds, first: u32, count: u32) -> Node {
    Node { min: b.min.to_array(), first, max: b.max.to_array(), count }
}

/// Writes `t` into node slot `slot` and its subtree after it, depth first.
fn flatten(t: &Tmp, slot: usize, pairs: &mut Vec<NodePair>) {
    match t {
        Tmp::Leaf { b, first, count } => pairs[slot / 2].0[slot % 2] = to_node(*b, *first, *count),
        Tmp::Inner { b, kids } => {
            let child = pairs.len() * 2;
            pairs.push(NodePair::default());
            pairs[slot / 2].0[slot % 2] = to_node(*b, child as u32, 0);
            flatten(&kids[0], child, pairs);
            flatten(&kids[1], child + 1, pairs);
        }
    }
}

impl Bvh {
    /// Builds the hierarchy over every triangle (`edges`, in scene order) and
    /// every sphere of `scene`.
    pub fn build(scene: &Scene, edges: &[TriangleEdges]) -> Bvh {
        let mut refs: Vec<PrimRef> = Vec::with_capacity(edges.len() + scene.spheres.len());
        for (i, e) in edges.iter().enumerate() {
            let (v0, v1, v2) = (Vec3A::from(e.v0), Vec3A::from(e.v0 + e.e1), Vec3A::from(e.v0 + e.e2));
            let (min, max) = padded(v0.min(v1).min(v2), v0.max(v1).max(v2));
            refs.push(PrimRef { min, max, id: i as u32 });
        }
        for (i, s) in scene.spheres.iter().enumerate() {
            let (c, r) = (Vec3A::from(s.center), Vec3A::splat(s.radius.abs()));
            let (min, max) = padded(c - r, c + r);
            refs.push(PrimRef { min, max, id: i as u32 | SPHERE_BIT });
        }
        let mut depth = 0;
        let tree = build_rec(&mut refs, 0, 0, &mut depth);
        let mut pairs = Vec::with_capacity(refs.len() / 2 + 1);
        pairs.push(NodePair::default());
        flatten(&tree, 0, &mut pairs);
        drop(tree);
        let dummy = TriangleEdges { v0: Vec3::ZERO, e1: Vec3::ZERO, e2: Vec3::ZERO, two_sided: false };
        let ids: Vec<u32> = refs.iter().map(|r| r.id).collect();
        let tris = ids.iter().map(|&id| if id & SPHERE_BIT == 0 { edges[id as usize] } else { dummy }).collect();
        Bvh { pairs, tris, ids, depth }
    }

    /// Number of nodes (interior and leaves).
    pub fn node_count(&self) -> usize {
        self.pairs.len() * 2 - 1
    }

    /// Levels below the root of the deepest leaf (0 when the root is a leaf).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Bounds of the root: every primitive, slightly padded.
    pub fn bounds(&self) -> Aabb {
        self.node_bounds(0)
    }

    /// Index of the root node.
    pub const ROOT: u32 = 0;

    /// Bounds of node `index` (the root is 0; children come from `node_content`).
    pub fn node_bounds(&self, index: u32) -> Aabb {
        let n = self.node(index);
        Aabb { min: Vec3::from(n.min), max: Vec3::from(n.max) }
    }

    pub fn node_content(&self, index: u32) -> NodeContent {
        let n = self.node(index);
        if n.count == 0 && !self.ids.is_empty() {
            NodeContent::Interior { left: n.first, right: n.first + 1 }
        } else {
            NodeContent::Leaf { first: n.first, count: n.count }
        }
    }

    /// Number of primitive slots (triangles plus spheres).
    pub fn primitive_count(&self) -> usize {
        self.ids.len()
    }

    /// The primitive in slot `slot` of the leaf order.
    pub fn primitive(&self, slot: u32) -> (PrimitiveKind, u32) {
        decode(self.ids[slot as usize])
    }

    #[inline(always)]
    fn node(&self, index: u32) -> &Node {
        &self.pairs[(index >> 1) as usize].0[(index & 1) as usize]
    }
}

#[inline(always)]
fn decode(id: u32) -> (PrimitiveKind, u32) {
    if id & SPHERE_BIT == 0 { (PrimitiveKind::Triangle, id) } else { (PrimitiveKind::Sphere, id & !SPHERE_BIT) }
}

/// The ray, prepared for slab tests.
struct RayPre {
    origin: Vec3A,
    inv: Vec3A,
}

impl RayPre {
    #[inline(always)]
    fn new(ray: &Ray) -> RayPre {
        // A zero (or denormal) component gets a huge finite inverse, so the
        // slab test never computes 0 * inf.
        let fix = |d: f32| {
            let inv = 1.0 / d;
            if inv.is_finite() { inv } else { f32::MAX.copysign(d) }
        };
        RayPre { origin: Vec3A::from(ray.origin), inv: Vec3A::new(fix(ray.dir.x), fix(ray.dir.y), fix(ray.dir.z)) }
    }

    /// Whether the ray meets the node's box within [0, t_far], and where it enters.
    #[inline(always)]
    fn slab(&self, n: &Node, t_far: f32) -> (bool, f32) {
        let t1 = (Vec3A::from(n.min) - self.origin) * self.inv;
        let t2 = (Vec3A::from(n.max) - self.origin) * self.inv;
        let tn = t1.min(t2).max_element() * (1.0 - SLAB_WIDEN);
        let tf = t1.max(t2).min_element() * (1.0 + SLAB_WIDEN);
        (tn.max(0.0) <= tf.min(t_far), tn)
    }
}

/// Closest-hit and shadow queries through the scene's BVH.
pub struct BvhQuery<'a> {
    prepared: &'a PreparedScene,
}

impl<'a> BvhQuery<'a> {
    #[inline]
    pub fn new(prepared: &'a PreparedScene) -> BvhQuery<'a> {
        BvhQuery { prepared }
    }

    /// The traversal shared by both queries. `ANY` stops at the first hit.
    /// Returns (id, t, b1, b2) of the winning primitive.
    #[inline(always)]
    fn traverse<const ANY: bool, R: Recorder>(
        &self,
        ray: &Ray,
        t_max: f32,
        inside: bool,
        counts: &mut RayCounts,
        rec: &mut R,
    ) -> Option<(u32, f32, f32, f32)> {
        let bvh = &self.prepared.bvh;
        if bvh.ids.is_empty() {
            return None;
        }
        let spheres = &self.prepared.scene.spheres;
        let r = RayPre::new(ray);
        let mut best_t = t_max;
        let mut best_id = u32::MAX;
        let (mut best_b1, mut best_b2) = (0.0f32, 0.0f32);
        // Primitive tests accept t < limit: t_max, then just above best_t so
        // an equal-t hit on an earlier primitive can still win the tie.
        let mut limit = t_max;
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut sp = 0usize;
        if !r.slab(bvh.node(0), t_max).0 {
            return None;
        }
        let mut index = 0u32;
        'walk: loop {
            let node = bvh.node(index);
            counts.nodes += 1;
            if R::ENABLED {
                rec.node_visit(index);
            }
            if node.count == 0 {
                let (a, b) = (bvh.node(node.first), bvh.node(node.first + 1));
                let (hit_a, ta) = r.slab(a, best_t);
                let (hit_b, tb) = r.slab(b, best_t);
                match (hit_a, hit_b) {
                    (true, true) => {
                        let (near, far, t_far) = if ta <= tb { (node.first, node.first + 1, tb) } else { (node.first + 1, node.first, ta) };
                        stack[sp] = (far, t_far);
                        sp += 1;
                        index = near;
                        continue 'walk;
                    }
                    (true, false) => {
                        index = node.first;
                        continue 'walk;
                    }
                    (false, true) => {
                        index = node.first + 1;
                        continue 'walk;
                    }
                    (false, false) => {}
                }
            } else {
                let start = node.first as usize;
                let end = start + node.count as usize;
                for k in start..end {
                    let id = bvh.ids[k];
                    counts.tests += 1;
                    let found = if id & SPHERE_BIT == 0 {
                        let outcome = intersect_triangle(ray, &bvh.tris[k], limit);
                        if R::ENABLED {
                            rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Triangle, index: id, outcome });
                        }
                        outcome.ok()
                    } else {
                        let outcome = intersect_sphere(ray, &spheres[(id & !SPHERE_BIT) as usize], limit, inside && !ANY);
                        if R::ENABLED {
                            rec.primitive_test(PrimitiveTest {
                                kind: PrimitiveKind::Sphere,
                                index: id & !SPHERE_BIT,
                                outcome: outcome.map(|t| (t, 0.0, 0.0)),
                            });
                        }
                        outcome.ok().map(|t| (t, 0.0, 0.0))
                    };
                    if let Some((t, b1, b2)) = found {
                        if ANY {
                            return Some((id, t, b1, b2));
                        }
                        // t <= best_t here; on a tie the lower id (scene order) wins.
                        if t < best_t || id < best_id {
                            best_t = t;
                            best_id = id;
                            best_b1 = b1;
                            best_b2 = b2;
                            limit = f32::from_bits(t.to_bits() + 1);
                        }
                    }
                }
            }
            // Pop the next node that may still hold something nearer.
            loop {
                if sp == 0 {
                    break 'walk;
                }
                sp -= 1;
                let (next, t_enter) = stack[sp];
                if t_enter <= best_t {
                    index = next;
                    continue 'walk;
                }
            }
        }
        (best_id != u32::MAX).then_some((best_id, best_t, best_b1, best_b2))
    }
}

impl SceneQuery for BvhQuery<'_> {
    fn closest<R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<SurfaceHit> {
        let (id, t, b1, b2) = self.traverse::<false, R>(ray, t_max, inside, counts, rec)?;
        let (kind, index) = decode(id);
        Some(make_hit(self.prepared, kind, index, t, b1, b2, ray))
    }

    fn occluder<R: Recorder>(&self, ray: &Ray, t_max: f32, counts: &mut RayCounts, rec: &mut R) -> Option<(PrimitiveKind, u32, f32)> {
        let (id, t, _, _) = self.traverse::<true, R>(ray, t_max, false, counts, rec)?;
        let (kind, index) = decode(id);
        Some((kind, index, t))
    }
}

pub struct BvhRayTracer;

impl Renderer for BvhRayTracer {
    fn name(&self) -> &'static str {
        "raytrace:bvh"
    }

    fn description(&self) -> &'static str {
        "ray casting through a SAH bounding volume hierarchy: same pixels as the reference, far fewer tests"
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        cast_pass(job, &BvhQuery::new(job.prepared), out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::raytrace::brute::{BruteForce, BruteQuery};
    use crate::render::trace::NoRecord;
    use crate::render::{debug::View, render_frame, RenderSettings, ShadowMode};
    use crate::scene::{builtin, Sphere, Triangle};
    use proptest::prelude::*;
    use std::sync::atomic::AtomicBool;

    /// SplitMix64: a tiny seeded generator for reproducible rays.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        fn f(&mut self) -> f32 {
            (self.next() >> 40) as f32 / (1u64 << 24) as f32
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
        fn unit(&mut self) -> Vec3 {
            loop {
                let v = Vec3::new(self.f(), self.f(), self.f()) * 2.0 - Vec3::ONE;
                if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                    return v.normalize();
                }
            }
        }
        fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
            lo + (hi - lo) * Vec3::new(self.f(), self.f(), self.f())
        }
    }

    fn key(h: &SurfaceHit) -> (PrimitiveKind, u32, u32, [u32; 3]) {
        (h.kind, h.primitive, h.t.to_bits(), h.barycentric.to_array().map(f32::to_bits))
    }

    /// Random rays for a scene: from inside its bounds, from outside towards
    /// it, at triangle vertices and edges (grazing), and along triangle planes.
    fn rays(scene: &Scene, rng: &mut Rng, n: usize) -> Vec<(Ray, f32)> {
        let (lo, hi) = scene.bounds().unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
        let (lo, hi) = (lo.max(Vec3::splat(-50.0)), hi.min(Vec3::splat(50.0)));
        let (lo, hi) = (lo.min(hi), hi.max(lo));
        let centre = (lo + hi) * 0.5;
        let radius = (hi - lo).length().max(1e-3);
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let t_max = if rng.below(4) == 0 { rng.f() * 2.0 * radius } else { f32::INFINITY };
            let ray = match i % 5 {
                0 => Ray::new(rng.in_box(lo, hi), rng.unit()),
                1 => {
                    let o = centre + rng.unit() * radius * 2.0;
                    Ray::new(o, (rng.in_box(lo, hi) - o).normalize())
                }
                2 | 3 if !scene.triangles.is_empty() => {
                    // Aim at a vertex or a point on an edge of a random triangle.
                    let t = &scene.triangles[rng.below(scene.triangles.len())];
                    let (a, b) = (rng.below(3), rng.below(3));
                    let s = if i % 5 == 2 { 0.0 } else { rng.f() };
                    let target = t.v[a] * (1.0 - s) + t.v[(a + 1 + b % 2) % 3] * s;
                    let o = if i % 2 == 0 {
                        centre + rng.unit() * radius * 2.0
                    } else {
                        // Grazing: start in the triangle's plane or just off it.
                        let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).normalize_or(Vec3::Y);
                        let along = n.cross(rng.unit()).normalize_or(Vec3::X);
                        let tilt = [0.0, 1e-3, -1e-3][rng.below(3)];
                        target + (along + n * tilt) * radius
                    };
                    Ray::new(o, (target - o).normalize_or(Vec3::Z))
                }
                _ => {
                    let o = rng.in_box(lo, hi);
                    let mut d = rng.unit();
                    // Axis-parallel directions exercise the zero-component slab case.
                    d[rng.below(3)] = 0.0;
                    Ray::new(o, d.normalize_or(Vec3::Y))
                }
            };
            out.push((ray, t_max));
        }
        out
    }

    /// Whether a reported hit is where the ray is: the point its barycentrics
    /// name and the point at its `t` agree. Möller-Trumbore loses this for
    /// rays lying in (or through a vertex of) a nearly degenerate triangle:
    /// its determinant is then rounding noise and the "hit" can sit anywhere
    /// on the ray, which no spatial structure can (or should) reproduce.
    fn accurate(ray: &Ray, t: f32, position: Vec3) -> bool {
        (ray.at(t) - position).length() <= 1e-4 * (1.0 + t + ray.origin.length())
    }

    /// Casts `rays` through both queries and fails on the first difference,
    /// except where brute force's own hit is numerically meaningless (see
    /// `accurate`); those must stay rare.
    fn assert_same_as_brute(prepared: &PreparedScene, rays: &[(Ray, f32)], what: &str) {
        let (bvh, brute) = (BvhQuery::new(prepared), BruteQuery(prepared));
        let (mut c1, mut c2) = (RayCounts::default(), RayCounts::default());
        let mut excused = 0;
        for (i, (ray, t_max)) in rays.iter().enumerate() {
            for inside in [false, true] {
                let a = bvh.closest(ray, *t_max, inside, &mut c1, &mut NoRecord);
                let b = brute.closest(ray, *t_max, inside, &mut c2, &mut NoRecord);
                if a.as_ref().map(key) != b.as_ref().map(key) && b.is_some_and(|h| !accurate(ray, h.t, h.position)) {
                    excused += 1;
                    continue;
                }
                assert_eq!(a.as_ref().map(key), b.as_ref().map(key), "{what}: ray {i} {ray:?} t_max {t_max} inside {inside}");
            }
            let a = bvh.occluder(ray, *t_max, &mut c1, &mut NoRecord);
            let b = brute.occluder(ray, *t_max, &mut c2, &mut NoRecord);
            if a.is_none() {
                if let Some((PrimitiveKind::Triangle, k, _)) = b {
                    let (t, b1, b2) = intersect_triangle(ray, &prepared.edges[k as usize], *t_max).unwrap();
                    let v = prepared.scene.triangles[k as usize].v;
                    if !accurate(ray, t, v[0] * (1.0 - b1 - b2) + v[1] * b1 + v[2] * b2) {
                        excused += 1;
                        continue;
                    }
                }
            }
            assert_eq!(a.is_some(), b.is_some(), "{what}: shadow ray {i} {ray:?} t_max {t_max}: bvh {a:?} brute {b:?}");
        }
        assert!(excused * 20 <= rays.len(), "{what}: {excused} of {} rays differ where brute force's hit is inaccurate", rays.len());
    }

    fn load(name: &str) -> PreparedScene {
        PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap())
    }

    #[test]
    fn closest_and_occluder_match_brute_force_on_builtin_scenes() {
        for name in builtin::names() {
            let prepared = load(name);
            let mut rng = Rng(0x5eed ^ name.len() as u64);
            let n = if prepared.edges.len() > 20_000 { 600 } else { 3000 };
            let rays = rays(&prepared.scene, &mut rng, n);
            assert_same_as_brute(&prepared, &rays, name);
        }
    }

    #[test]
    fn frames_match_brute_force_pixel_for_pixel() {
        for name in builtin::names() {
            let prepared = load(name);
            for view in [View::Shaded, View::Depth] {
                let settings = RenderSettings { width: 96, height: 54, shadows: ShadowMode::Ray, view, ..RenderSettings::for_scene(&prepared.scene) };
                let cancel = AtomicBool::new(false);
                let a = render_frame(&BvhRayTracer, &prepared, &settings, &cancel, None).unwrap();
                let b = render_frame(&BruteForce, &prepared, &settings, &cancel, None).unwrap();
                let bits = |p: &[Radiance]| p.iter().map(|c| c.to_array().map(f32::to_bits)).collect::<Vec<_>>();
                assert!(bits(&a.pixels) == bits(&b.pixels), "{name} {view:?}: images differ");
                assert_eq!((a.counts.primary, a.counts.shadow), (b.counts.primary, b.counts.shadow), "{name}");
                if prepared.edges.len() > 1000 {
                    assert!(a.counts.tests * 20 < b.counts.tests, "{name}: the BVH tests too many primitives");
                }
            }
        }
    }

    /// Every primitive in exactly one leaf; every node inside its parent; every
    /// primitive inside its leaf; leaves small.
    fn check_structure(bvh: &Bvh, scene: &Scene) {
        let total = scene.triangles.len() + scene.spheres.len();
        assert_eq!(bvh.primitive_count(), total);
        let mut seen = vec![0u32; total];
        let mut stack = vec![(Bvh::ROOT, 0u32)];
        let mut nodes = 0;
        let mut max_depth = 0;
        while let Some((i, depth)) = stack.pop() {
            nodes += 1;
            max_depth = max_depth.max(depth);
            let b = bvh.node_bounds(i);
            match bvh.node_content(i) {
                NodeContent::Interior { left, right } => {
                    for c in [left, right] {
                        assert!(b.contains(&bvh.node_bounds(c)), "node {i} does not contain child {c}");
                        stack.push((c, depth + 1));
                    }
                }
                NodeContent::Leaf { first, count } => {
                    assert!(count as usize <= MAX_LEAF || total <= MAX_LEAF);
                    for s in first..first + count {
                        let (kind, p) = bvh.primitive(s);
                        let (lo, hi) = match kind {
                            PrimitiveKind::Triangle => {
                                seen[p as usize] += 1;
                                let v = scene.triangles[p as usize].v;
                                (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
                            }
                            PrimitiveKind::Sphere => {
                                seen[scene.triangles.len() + p as usize] += 1;
                                let s = &scene.spheres[p as usize];
                                (s.center - s.radius, s.center + s.radius)
                            }
                        };
                        assert!(b.contains(&Aabb { min: lo, max: hi }), "leaf {i} does not contain {kind:?} {p}");
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "some primitive is missing or repeated");
        assert_eq!(nodes, bvh.node_count());
        assert_eq!(max_depth, bvh.depth());
    }

    #[test]
    fn build_covers_every_primitive_once_and_nests_bounds() {
        for name in builtin::names() {
            let prepared = load(name);
            check_structure(&prepared.bvh, &prepared.scene);
            let root = prepared.bvh.bounds();
            if let Some((lo, hi)) = prepared.scene.bounds() {
                assert!(root.contains(&Aabb { min: lo, max: hi }), "{name}");
            }
        }
    }

    #[test]
    fn sah_build_is_shallow_on_the_bunny() {
        let prepared = load("bunny");
        let bvh = &prepared.bvh;
        let n = prepared.edges.len();
        assert!(bvh.depth() < 40, "depth {}", bvh.depth());
        assert!(bvh.node_count() < 2 * n, "{} nodes for {n} triangles", bvh.node_count());
        // Interior nodes' children are adjacent pairs.
        if let NodeContent::Interior { left, right } = bvh.node_content(Bvh::ROOT) {
            assert_eq!(right, left + 1);
            assert_eq!(left % 2, 0);
        } else {
            panic!("the bunny's root is a leaf");
        }
    }

    #[test]
    fn empty_scene_has_no_hits() {
        let mut scene = builtin::load_builtin("one-triangle").unwrap().unwrap();
        scene.triangles.clear();
        scene.spheres.clear();
        let prepared = PreparedScene::new(scene);
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let q = BvhQuery::new(&prepared);
        assert!(q.closest(&ray, f32::INFINITY, false, &mut RayCounts::default(), &mut NoRecord).is_none());
        assert!(q.occluder(&ray, f32::INFINITY, &mut RayCounts::default(), &mut NoRecord).is_none());
    }

    #[test]
    fn equal_t_ties_go_to_the_first_primitive() {
        // Three copies of one triangle and a sphere touching it: brute force
        // reports triangle 0; so must the BVH, however it orders the leaves.
        let mut scene = builtin::load_builtin("one-triangle").unwrap().unwrap();
        let t = scene.triangles[0].clone();
        scene.triangles = vec![t.clone(); 40];
        scene.spheres.clear();
        let prepared = PreparedScene::new(scene);
        let mut rng = Rng(7);
        let rays = rays(&prepared.scene, &mut rng, 500);
        assert_same_as_brute(&prepared, &rays, "copies");
        let q = BvhQuery::new(&prepared);
        let c = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
        let n = t.geometric_normal();
        let hit = q.closest(&Ray::new(c + n, -n), f32::INFINITY, false, &mut RayCounts::default(), &mut NoRecord).unwrap();
        assert_eq!((hit.kind, hit.primitive), (PrimitiveKind::Triangle, 0));
    }

    fn soup_scene(tris: &[[[f32; 3]; 3]], spheres: &[([f32; 3], f32)], two_sided: bool) -> PreparedScene {
        let mut scene = builtin::load_builtin("one-triangle").unwrap().unwrap();
        let template = scene.triangles[0].clone();
        scene.triangles = tris
            .iter()
            .map(|v| {
                let v = v.map(Vec3::from);
                let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or(Vec3::Z);
                Triangle { v, n: [n; 3], two_sided, ..template.clone() }
            })
            .collect();
        scene.spheres = spheres
            .iter()
            .map(|&(c, r)| Sphere { center: Vec3::from(c), radius: r, material: 0, object: 0 })
            .collect();
        PreparedScene::new(scene)
    }

    /// Coordinates on a coarse grid, so vertices, edges and whole triangles
    /// coincide often; plus slivers (a vertex near the opposite edge).
    fn vertex() -> impl Strategy<Value = [f32; 3]> {
        prop::array::uniform3((-4i32..=4).prop_map(|k| k as f32 * 0.5))
    }

    fn triangle() -> impl Strategy<Value = [[f32; 3]; 3]> {
        prop_oneof![
            prop::array::uniform3(vertex()),
            (vertex(), vertex(), 0.0f32..1.0, -1e-3f32..1e-3).prop_map(|(a, b, s, e)| {
                let c = [a[0] + (b[0] - a[0]) * s + e, a[1] + (b[1] - a[1]) * s, a[2] + (b[2] - a[2]) * s - e];
                [a, b, c]
            }),
            prop::array::uniform3(prop::array::uniform3(-3.0f32..3.0)),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]
        #[test]
        fn random_soups_match_brute_force(
            tris in prop::collection::vec(triangle(), 1..120),
            dup in prop::collection::vec(any::<prop::sample::Index>(), 0..20),
            spheres in prop::collection::vec((vertex(), 0.1f32..2.0), 0..4),
            two_sided in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let mut tris = tris;
            for d in dup {
                let t = tris[d.index(tris.len())];
                tris.push(t);
            }
            let prepared = soup_scene(&tris, &spheres, two_sided);
            check_structure(&prepared.bvh, &prepared.scene);
            let mut rng = Rng(seed);
            let rays = rays(&prepared.scene, &mut rng, 400);
            assert_same_as_brute(&prepared, &rays, "soup");
        }
    }
}
