//! The bounding volume hierarchy over the scene's triangles and analytic
//! spheres, built with the binned surface area heuristic (SAH) in
//! `bvh/build.rs`, and the single-ray queries through it (`BvhQuery`),
//! traversed near child first with the kernels of `traverse.rs`.
//!
//! It must see exactly what the brute-force reference sees, so:
//! - leaves call the same `intersect_triangle` / `intersect_sphere` with the
//!   same `TriangleEdges` values (stored once, in leaf order for locality);
//! - when two primitives are hit at exactly the same `t`, the one first in
//!   scene order wins (all triangles before all spheres, then by index), as
//!   brute force's strict `t < best_t` scan does;
//! - node bounds are padded and the slab test is widened a little, so a
//!   rounding difference between the box test and the primitive test can
//!   never cull a primitive the reference hits.
//!
//! Layout: the binary SAH tree is collapsed into an 8-wide one (as Embree
//! does for AVX): each 256-byte node holds the boxes of up to eight
//! children in structure-of-arrays form, so one eight-lane slab test checks
//! them all, and a child word that is either a node index or a leaf (first
//! primitive, count). Half as many levels as a 4-wide tree means half as
//! many dependent node loads per ray, which is what an incoherent ray's
//! walk waits on.

use crate::render::accel::intersect::TriangleEdges;
use crate::render::accel::traverse::{slab_test8, test_leaf, test_triangle_leaf, BestHit, ChildOrder, PreparedRay};
use crate::math::lanes::{mask_bits, simd_level, V3};
use crate::math::prefetch::{prefetch, prefetch_lines};
use fearless_simd::{f32x8, Simd, SimdBase};
use crate::math::Ray;
use fearless_simd::dispatch;
use crate::render::inspect::pixel_record::{NoRecord, Recorder};
use crate::render::{BatchHit, Occluder, PreparedScene, RayCounts, SceneQuery};
use crate::scene::hit_lanes::TriangleHitInput;
use crate::scene::{PrimitiveId, PrimitiveKind, SurfaceHit};
use std::sync::Arc;
use glam::Vec3;

mod build;
use build::{aabb, triangle_box, Bounds};
pub use build::EdgeSource;

/// Leaves never hold more than this; the SAH decides below it.
const MAX_LEAF: usize = 8;
/// Traversal stack entries kept on the machine stack; deeper trees (which
/// need more than 7 per level) use a heap stack instead.
pub(super) const STACK: usize = 128;
/// Child words with this bit set are leaves: first primitive << 3 | count - 1.
pub(super) const LEAF_BIT: u32 = 1 << 31;

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

    /// The eight corners; bit 0 of the index picks max x, bit 1 max y,
    /// bit 2 max z.
    pub fn corners(&self) -> [Vec3; 8] {
        let (lo, hi) = (self.min, self.max);
        std::array::from_fn(|k| Vec3::new(if k & 1 == 0 { lo.x } else { hi.x }, if k & 2 == 0 { lo.y } else { hi.y }, if k & 4 == 0 { lo.z } else { hi.z }))
    }
}

/// What a node holds, for the viewer and the debugger.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NodeContent {
    /// Two to eight children, by node id.
    Interior { children: Vec<u32> },
    /// `count` primitives starting at `first` in the BVH's primitive order
    /// (see `Bvh::primitive`).
    Leaf { first: u32, count: u32 },
}

/// An 8-wide node: the children's boxes as planes (min x, max x, min y,
/// max y, min z, max z), one lane per child, and the children's words.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node8 {
    pub(super) planes: [[f32; 8]; 6],
    pub(super) child: [u32; 8],
    /// Bit i set when child slot i is used.
    pub(super) valid: u32,
}

impl Node8 {
    pub(super) const EMPTY: Node8 = Node8 { planes: [[0.0; 8]; 6], child: [0; 8], valid: 0 };

    /// Child slot `i`'s box, as the traversal tests it.
    fn child_box(&self, i: usize) -> Aabb {
        let p = &self.planes;
        Aabb { min: Vec3::new(p[0][i], p[2][i], p[4][i]), max: Vec3::new(p[1][i], p[3][i], p[5][i]) }
    }
}

/// The hierarchy: 8-wide nodes, with the primitives in leaf order.
pub struct Bvh {
    pub(super) nodes: Vec<Node8>,
    /// The root's word: node 0, or a leaf when the scene is tiny.
    pub(super) root: u32,
    pub(super) root_bounds: Aabb,
    /// Per primitive slot: the triangle's edges (unused for spheres) and the
    /// primitive's id. The only copy of the edges: `PreparedScene::edges`
    /// reads them from here in scene order (`Bvh::edges_in_scene_order`).
    pub(super) prims: Arc<Vec<(TriangleEdges, PrimitiveId)>>,
    /// For the debugger: the bounds of leaves holding a sphere, by first
    /// slot (other bounds are recomputed from the nodes and the edges).
    sphere_leaf_bounds: Vec<(u32, Aabb)>,
    leaves: usize,
    depth: u32,
    /// True when a traversal may need more than `STACK` entries.
    pub(crate) deep: bool,
}

#[inline(always)]
fn leaf_word(first: u32, count: u32) -> u32 {
    debug_assert!(count >= 1 && count as usize <= MAX_LEAF && first < 1 << 28);
    LEAF_BIT | first << 3 | (count - 1)
}

#[inline(always)]
pub(super) fn leaf_range(word: u32) -> (usize, usize) {
    let first = ((word & !LEAF_BIT) >> 3) as usize;
    (first, first + (word & 7) as usize + 1)
}

impl Bvh {
    /// Starts loading a child's node (both its cache lines) or its leaf's
    /// first primitives into the cache; a hint only, it changes no result.
    #[inline(always)]
    pub(super) fn prefetch_child(&self, word: u32) {
        if word & LEAF_BIT == 0 {
            // A node fills whole cache lines (`align(64)`): no extra line for its end.
            prefetch_lines(self.nodes.as_ptr().wrapping_add(word as usize).cast(), std::mem::size_of::<Node8>() / 64);
        } else {
            prefetch(self.prims.as_ptr().wrapping_add(leaf_range(word).0).cast(), 2 * 64);
        }
    }

    /// Number of nodes: interior nodes plus leaves.
    pub fn node_count(&self) -> usize {
        self.nodes.len() + self.leaves
    }

    /// Bytes the hierarchy holds: its nodes, its primitive slots and the
    /// debugger's sphere-leaf bounds, each as length times element size.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.nodes[..]) + size_of_val(&self.prims[..]) + size_of_val(&self.sphere_leaf_bounds[..])
    }

    /// Levels below the root of the deepest leaf (0 when the root is a leaf).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Bounds of the root: every primitive, slightly padded.
    pub fn bounds(&self) -> Aabb {
        self.root_bounds
    }

    /// Id of the root node (what `node_visit` reports and `node_content` takes).
    pub fn root(&self) -> u32 {
        self.root
    }

    /// Bounds of node `id`.
    pub fn node_bounds(&self, id: u32) -> Aabb {
        if id & LEAF_BIT == 0 {
            // The union of the children's boxes is exactly the node's own.
            let n = &self.nodes[id as usize];
            let mut b = Bounds::EMPTY;
            for i in (0..8).filter(|i| n.valid & 1 << i != 0) {
                let c = n.child_box(i);
                b.grow(c.min.into(), c.max.into());
            }
            aabb(b)
        } else {
            let (first, end) = leaf_range(id);
            if end > self.prims.len() {
                return Aabb::EMPTY;
            }
            if let Ok(i) = self.sphere_leaf_bounds.binary_search_by_key(&(first as u32), |(f, _)| *f) {
                return self.sphere_leaf_bounds[i].1;
            }
            // A leaf of triangles: the union of their boxes, made as the build made them.
            let mut b = Bounds::EMPTY;
            for (e, _) in &self.prims[first..end] {
                let (lo, hi) = triangle_box(e);
                b.grow(lo, hi);
            }
            aabb(b)
        }
    }

    /// Boxes that together hold every primitive: the children of the
    /// nodes `levels` below the root (or the leaves above them), as the
    /// nodes store them (so padded as the traversal sees them). For a
    /// tighter outline of the scene than the root's box.
    pub fn cut_boxes(&self, levels: u32) -> Vec<Aabb> {
        if self.prims.is_empty() {
            return Vec::new();
        }
        if self.root & LEAF_BIT != 0 {
            return vec![self.root_bounds];
        }
        let mut boxes = Vec::new();
        let mut nodes = vec![(self.root, 1)];
        while let Some((id, level)) = nodes.pop() {
            let n = &self.nodes[id as usize];
            for i in (0..8).filter(|i| n.valid & 1 << i != 0) {
                if level < levels && n.child[i] & LEAF_BIT == 0 {
                    nodes.push((n.child[i], level + 1));
                } else {
                    boxes.push(n.child_box(i));
                }
            }
        }
        boxes
    }

    pub fn node_content(&self, id: u32) -> NodeContent {
        if id & LEAF_BIT == 0 {
            let n = &self.nodes[id as usize];
            NodeContent::Interior { children: (0..8).filter(|i| n.valid & 1 << i != 0).map(|i| n.child[i]).collect() }
        } else {
            let (first, end) = leaf_range(id);
            let count = if self.prims.is_empty() { 0 } else { (end - first) as u32 };
            NodeContent::Leaf { first: first as u32, count }
        }
    }

    /// Number of primitive slots (triangles plus spheres).
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// The primitive in slot `slot` of the leaf order.
    pub fn primitive(&self, slot: u32) -> (PrimitiveKind, u32) {
        let id = self.prims[slot as usize].1;
        (id.kind(), id.index())
    }

    /// Calls `visit` with the edges and id of every primitive in a leaf
    /// whose box the ray meets before `t_max`, in no particular order: the
    /// candidates for queries that need every crossing along a ray, not the
    /// nearest one (shadow volume counts).
    pub fn for_each_candidate(&self, ray: &Ray, t_max: f32, mut visit: impl FnMut(&TriangleEdges, PrimitiveId)) {
        let r = PreparedRay::new(ray);
        if self.prims.is_empty() || !r.slab1(self.root_bounds.min, self.root_bounds.max, t_max) {
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(STACK);
        let mut word = self.root;
        loop {
            if word & LEAF_BIT == 0 {
                let node = &self.nodes[word as usize];
                let (mut mask, _) = r.slab8(&node.planes, node.valid, t_max);
                while mask != 0 {
                    stack.push(node.child[mask.trailing_zeros() as usize]);
                    mask &= mask - 1;
                }
            } else {
                let (start, end) = leaf_range(word);
                for (edges, id) in &self.prims[start..end] {
                    visit(edges, *id);
                }
            }
            match stack.pop() {
                Some(next) => word = next,
                None => break,
            }
        }
    }
}

/// One ray against the eight boxes of `node` (`traverse::slab_test8`):
/// which it meets within [0, t_far] (bits of the used slots), and where it
/// enters each.
#[inline(always)]
fn slab8_lanes<S: Simd>(simd: S, node: &Node8, origin: &[f32x8<S>; 3], inv: &[f32x8<S>; 3], t_far: f32) -> (u32, f32x8<S>) {
    let p = &node.planes;
    let planes = [
        f32x8::from_slice(simd, &p[0]),
        f32x8::from_slice(simd, &p[1]),
        f32x8::from_slice(simd, &p[2]),
        f32x8::from_slice(simd, &p[3]),
        f32x8::from_slice(simd, &p[4]),
        f32x8::from_slice(simd, &p[5]),
    ];
    let (hit, tn) = slab_test8(&planes, origin, inv, f32x8::splat(simd, t_far));
    (mask_bits(hit) as u32 & node.valid, tn)
}

/// The traversal stack: on the machine stack for ordinary trees.
trait Stack {
    fn push(&mut self, word: u32, t: f32);
    fn pop(&mut self) -> Option<(u32, f32)>;
}

struct ArrayStack {
    /// Entries below `len` are initialised (no per-ray clearing of the array).
    items: [std::mem::MaybeUninit<(u32, f32)>; STACK],
    len: usize,
}

impl ArrayStack {
    /// An empty stack; its entries are left uninitialised.
    #[inline(always)]
    fn new() -> ArrayStack {
        ArrayStack { items: [const { std::mem::MaybeUninit::uninit() }; STACK], len: 0 }
    }
}

impl Stack for ArrayStack {
    #[inline(always)]
    fn push(&mut self, word: u32, t: f32) {
        self.items[self.len] = std::mem::MaybeUninit::new((word, t));
        self.len += 1;
    }
    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, f32)> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: every entry below the old `len` was written by `push`.
        Some(unsafe { self.items[self.len].assume_init() })
    }
}

impl Stack for Vec<(u32, f32)> {
    fn push(&mut self, word: u32, t: f32) {
        Vec::push(self, (word, t));
    }
    fn pop(&mut self) -> Option<(u32, f32)> {
        Vec::pop(self)
    }
}

/// Closest-hit and shadow queries through the scene's BVH.
pub struct BvhQuery<'a> {
    pub(crate) prepared: &'a PreparedScene,
    /// Whether every query is one walk of the flat BVH: no instances, no
    /// CSG objects, some primitives (`closest_for_batch_at`, `occluder_at`
    /// ask this per ray).
    flat_only: bool,
    /// Whether some material is cut out where its alpha is low: every hit
    /// is then checked (`past_cutouts`), and no query takes the flat or
    /// packet shortcuts, which do not check.
    cutouts: bool,
}

/// The most cut-away surfaces one query passes through before it stops
/// looking and reports nothing hit (a bound on the work per ray).
const MAX_CUTOUT_LAYERS: usize = 256;

impl<'a> BvhQuery<'a> {
    #[inline]
    pub fn new(prepared: &'a PreparedScene) -> BvhQuery<'a> {
        let cutouts = prepared.scene.has_cutouts();
        let flat_only = prepared.scene.csgs.is_empty() && prepared.instances.is_none() && !prepared.bvh.prims.is_empty() && !cutouts;
        BvhQuery { prepared, flat_only, cutouts }
    }

    /// Whether rays may pass through cut-away surfaces, which packets of
    /// rays do not check: frames then cast their rays one by one.
    #[inline]
    pub fn has_cutouts(&self) -> bool {
        self.cutouts
    }

    /// The hit of a walk that passes through cut-away surfaces. Without
    /// cutouts, one walk. With them, a shadow query too looks for the
    /// closest hit (the first occluder found may be cut away while a nearer
    /// one is not), and a hit where the surface is cut away is walked past:
    /// the ray goes on from just beyond it, its hits' `t` measured from the
    /// original origin.
    #[inline(always)]
    fn traverse<const ANY: bool, R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<BestHit> {
        if !self.cutouts {
            return self.traverse_once::<ANY, R>(ray, t_max, inside, counts, rec);
        }
        let scene = &self.prepared.scene;
        let mut start = 0.0f32;
        for _ in 0..MAX_CUTOUT_LAYERS {
            let rest = Ray { origin: ray.at(start), ..*ray };
            let best = self.traverse_once::<false, R>(&rest, t_max - start, inside, counts, rec)?;
            let t = start + best.t;
            if best.id.kind() != PrimitiveKind::Triangle || !scene.cut_out_at(best.id.index(), best.bary.0, best.bary.1) {
                return Some(BestHit { t, limit: t, ..best });
            }
            // Just beyond the cut-away surface, by a step relative to the
            // coordinates' size so that the same triangle is not met again.
            let at = ray.at(t);
            let step = 1e-5 * (1.0 + at.abs().max_element()) / ray.dir.length().max(f32::MIN_POSITIVE);
            start = t + step;
            if !(start < t_max) {
                return None;
            }
        }
        None
    }

    #[inline(always)]
    fn traverse_once<const ANY: bool, R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<BestHit> {
        let bvh = &self.prepared.bvh;
        if let (Some(accel), Some(layer)) = (&self.prepared.instances, &self.prepared.scene.layer) {
            let found = if bvh.prims.is_empty() { None } else { self.traverse_flat::<ANY, R>(ray, t_max, inside, counts, rec) };
            if ANY && found.is_some() {
                return found;
            }
            let mut best = found.unwrap_or(BestHit::nothing_before(t_max));
            let (mut visits, mut tests) = (0, 0);
            accel.traverse::<ANY, R>(layer, ray, &mut best, &mut visits, &mut tests, rec);
            counts.nodes += visits;
            counts.tests += tests;
            return (!best.id.is_none()).then_some(best);
        }
        if bvh.prims.is_empty() {
            return None;
        }
        self.traverse_flat::<ANY, R>(ray, t_max, inside, counts, rec)
    }

    /// The hit `closest` makes of `best` along `ray`, a triangle's as what
    /// its record is built from.
    #[inline]
    pub(super) fn batch_hit(&self, best: &BestHit, ray: &Ray) -> BatchHit {
        match best.id.kind() {
            PrimitiveKind::Triangle => BatchHit::Triangle(TriangleHitInput::new(best.id.index(), best.bary, best.t, ray.dir)),
            _ => BatchHit::Record(crate::render::accel::surface::primitive_hit(&self.prepared.scene, best.id, best.t, best.bary.0, best.bary.1, ray)),
        }
    }

    /// Starts loading the scene's record of triangle `id` (a hint only).
    #[inline(always)]
    fn prefetch_triangle(&self, id: PrimitiveId) {
        if id.kind() == PrimitiveKind::Triangle {
            let p = self.prepared.scene.triangles.record_ptr(id.index() as usize);
            prefetch(p, 20);
        }
    }

    /// The walk through the BVH over the flattened triangles and the spheres.
    #[inline(always)]
    fn traverse_flat<const ANY: bool, R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<BestHit> {
        // Compiled once per SIMD level: the eight-lane box test is one AVX
        // instruction per step where the CPU has it.
        dispatch!(simd_level(), simd => self.traverse_flat_at::<_, ANY, R>(simd, ray, t_max, inside, counts, rec))
    }

    /// `traverse_flat` at SIMD level `simd`, chosen by the caller.
    #[inline(always)]
    fn traverse_flat_at<S: Simd, const ANY: bool, R: Recorder>(&self, simd: S, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<BestHit> {
        if self.prepared.bvh.deep {
            self.traverse_with::<_, ANY, R, _>(simd, ray, t_max, inside, counts, rec, &mut Vec::new(), None)
        } else {
            let mut stack = ArrayStack::new();
            self.traverse_with::<_, ANY, R, _>(simd, ray, t_max, inside, counts, rec, &mut stack, None)
        }
    }

    /// A closest-hit walk of `ray` from node `word` on, with `best` found so
    /// far (the packets' hybrid walk hands its last rays over here).
    #[inline(always)]
    pub(super) fn closest_from_at<S: Simd>(&self, simd: S, ray: &Ray, word: u32, best: BestHit, counts: &mut RayCounts) -> BestHit {
        let mut stack = ArrayStack::new();
        self.traverse_with::<_, false, NoRecord, _>(simd, ray, best.t, false, counts, &mut NoRecord, &mut stack, Some((word, best))).unwrap_or(best)
    }

    /// A shadow walk of `ray` up to `t_max` from node `word` on: the first
    /// occluder found below it, if any.
    #[inline(always)]
    pub(super) fn occluder_from_at<S: Simd>(&self, simd: S, ray: &Ray, word: u32, t_max: f32, counts: &mut RayCounts) -> Option<BestHit> {
        let mut stack = ArrayStack::new();
        self.traverse_with::<_, true, NoRecord, _>(simd, ray, t_max, false, counts, &mut NoRecord, &mut stack, Some((word, BestHit::nothing_before(t_max))))
    }

    /// The traversal shared by both queries. `ANY` stops at the first hit.
    /// Returns the winning primitive's hit.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn traverse_with<S: Simd, const ANY: bool, R: Recorder, St: Stack>(&self, simd: S, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R, stack: &mut St, from: Option<(u32, BestHit)>) -> Option<BestHit> {
        let bvh = &self.prepared.bvh;
        let spheres = &self.prepared.scene.spheres;
        let r = PreparedRay::new(ray);
        // No separate test of the root's box: the root node's test of its
        // children's boxes (inside it) rejects a ray that misses the scene
        // at about the same cost, and most rays (bounces and shadow rays,
        // starting on a surface) start inside it.
        let origin = [f32x8::splat(simd, r.origin[0].x), f32x8::splat(simd, r.origin[1].x), f32x8::splat(simd, r.origin[2].x)];
        let inv = [f32x8::splat(simd, r.inv[0].x), f32x8::splat(simd, r.inv[1].x), f32x8::splat(simd, r.inv[2].x)];
        // The ray in every lane, for leaves of several triangles tested at
        // once by closest-hit queries (`test_triangle_leaf`); replays
        // record each test, one by one.
        let lanes_leaves = !ANY && !R::ENABLED && spheres.is_empty();
        let (ray_origin, ray_dir) = (V3::new(origin[0], origin[1], origin[2]), V3::new(f32x8::splat(simd, ray.dir.x), f32x8::splat(simd, ray.dir.y), f32x8::splat(simd, ray.dir.z)));
        let (mut word, mut best) = from.unwrap_or((bvh.root, BestHit::nothing_before(t_max)));
        let (mut visits, mut tests) = (0u64, 0u64);
        'walk: loop {
            visits += 1;
            if R::ENABLED {
                rec.node_visit(word);
            }
            if word & LEAF_BIT == 0 {
                let node = &bvh.nodes[word as usize];
                let (mask, tn) = slab8_lanes(simd, node, &origin, &inv, best.t);
                if mask != 0 {
                    if mask & (mask - 1) == 0 {
                        // One child (the most common case): it is read at
                        // once, so asking the cache for it first gains nothing.
                        word = node.child[mask.trailing_zeros() as usize];
                        continue 'walk;
                    }
                    // Ask for every child the ray enters now: the walk is a
                    // chain of dependent loads that miss the cache, and the
                    // bookkeeping below can hide part of the next one.
                    let mut m = mask;
                    while m != 0 {
                        bvh.prefetch_child(node.child[m.trailing_zeros() as usize]);
                        m &= m - 1;
                    }
                    let tn: [f32; 8] = tn.into();
                    if mask.count_ones() == 2 {
                        // The common case without the sort. On equal entry
                        // distances it takes the lower slot first, where
                        // `ChildOrder` would take the later one: either order
                        // finds the same hit (the leaf tie rule; only a ray
                        // almost in a triangle's plane, whose hit wanders out
                        // of the triangle's box, can tell them apart), and this
                        // one is kept because pixel replays record the visit order.
                        let (i, j) = (mask.trailing_zeros() as usize, 31 - mask.leading_zeros() as usize);
                        let (near, far) = if tn[i] <= tn[j] { (i, j) } else { (j, i) };
                        stack.push(node.child[far], tn[far]);
                        word = node.child[near];
                        continue 'walk;
                    }
                    let mut order = ChildOrder::new();
                    let mut m = mask;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        order.insert(node.child[i], tn[i]);
                    }
                    if let Some((nearest, farther)) = order.nearest_and_farther() {
                        for &(w, t) in farther {
                            stack.push(w, t);
                        }
                        word = nearest;
                        continue 'walk;
                    }
                }
            } else {
                let (start, end) = leaf_range(word);
                // Shadow rays (`ANY`) never start inside a sphere they may hit.
                let before = best.id;
                let prims = &bvh.prims[start..end];
                let stop = if lanes_leaves && prims.len() >= 2 {
                    test_triangle_leaf(simd, prims, ray_origin, ray_dir, &mut best, &mut tests);
                    false
                } else {
                    test_leaf::<ANY, R>(prims, spheres, ray, inside && !ANY, &mut best, &mut tests, rec)
                };
                if stop {
                    counts.nodes += visits;
                    counts.tests += tests;
                    return Some(best);
                }
                if !ANY && best.id != before {
                    // The hit record will read this triangle: start its load
                    // while the walk goes on.
                    self.prefetch_triangle(best.id);
                }
            }
            // Pop the next node that may still hold something nearer.
            while let Some((next, t_enter)) = stack.pop() {
                if t_enter <= best.t {
                    word = next;
                    continue 'walk;
                }
            }
            break;
        }
        counts.nodes += visits;
        counts.tests += tests;
        (!best.id.is_none()).then_some(best)
    }
}

impl SceneQuery for BvhQuery<'_> {
    fn closest<R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<SurfaceHit> {
        let best = self.traverse::<false, R>(ray, t_max, inside, counts, rec);
        let scene = &self.prepared.scene;
        // CSG objects are kept out of the hierarchy and tested after it.
        if !scene.csgs.is_empty() {
            let limit = best.as_ref().map_or(t_max, |b| b.t);
            if let Some(h) = crate::render::accel::csg::closest_in_scene(scene, ray, limit, inside, counts) {
                return Some(h);
            }
        }
        let best = best?;
        Some(crate::render::accel::surface::primitive_hit(&scene, best.id, best.t, best.bary.0, best.bary.1, ray))
    }

    // Inlined into the pool's bounce loop, its only caller in frames: the
    // hit (a large enum) is then built in place rather than returned and
    // moved twice (-2.6% instructions on a cornell_gi path frame).
    #[inline(always)]
    fn closest_for_batch(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts) -> Option<BatchHit> {
        if !self.prepared.scene.csgs.is_empty() {
            return self.closest(ray, t_max, inside, counts, &mut NoRecord).map(BatchHit::Record);
        }
        let best = self.traverse::<false, NoRecord>(ray, t_max, inside, counts, &mut NoRecord)?;
        Some(self.batch_hit(&best, ray))
    }

    #[inline(always)]
    fn closest_for_batch_at<S: Simd>(&self, simd: S, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts) -> Option<BatchHit> {
        // Scenes with instances or CSG objects take the general way.
        if !self.flat_only {
            return self.closest_for_batch(ray, t_max, inside, counts);
        }
        let best = self.traverse_flat_at::<S, false, NoRecord>(simd, ray, t_max, inside, counts, &mut NoRecord)?;
        Some(self.batch_hit(&best, ray))
    }

    fn bvh_packets(&self) -> Option<&BvhQuery<'_>> {
        (self.flat_only && !self.prepared.bvh.deep).then_some(self)
    }

    fn occluder<R: Recorder>(&self, ray: &Ray, t_max: f32, counts: &mut RayCounts, rec: &mut R) -> Option<Occluder> {
        match self.traverse::<true, R>(ray, t_max, false, counts, rec) {
            Some(best) => Some(Occluder::new(best.id, best.t)),
            None if self.prepared.scene.csgs.is_empty() => None,
            None => crate::render::accel::csg::occluder_in_scene(&self.prepared.scene, ray, t_max, counts),
        }
    }

    #[inline(always)]
    fn occluder_at<S: Simd>(&self, simd: S, ray: &Ray, t_max: f32, counts: &mut RayCounts) -> Option<Occluder> {
        // Scenes with instances or CSG objects take the general way.
        if !self.flat_only {
            return self.occluder(ray, t_max, counts, &mut NoRecord);
        }
        let best = self.traverse_flat_at::<S, true, NoRecord>(simd, ray, t_max, false, counts, &mut NoRecord)?;
        Some(Occluder::new(best.id, best.t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::accel::brute::BruteQuery;
    use crate::render::accel::intersect::intersect_triangle;
    use crate::render::inspect::pixel_record::NoRecord;
    use crate::scene::{builtin, Scene, Sphere, Triangle};
    use proptest::prelude::*;
    use glam::Vec3A;

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
                    let t = &scene.triangles.at(rng.below(scene.triangles.len()));
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

    /// Whether the point at a hit's `t` lies in the padded box of its
    /// triangle, as every box test assumes. A ray almost in the triangle's
    /// plane gets a `t` that wanders along the ray, out of any box holding
    /// the triangle: then which of two equal triangles wins depends on the
    /// order the walk meets their boxes in, and no box test can keep it.
    fn within_its_box(prepared: &PreparedScene, ray: &Ray, h: &SurfaceHit) -> bool {
        if h.kind != PrimitiveKind::Triangle {
            return true;
        }
        let (lo, hi) = triangle_box(&prepared.edges[h.primitive as usize]);
        let p = Vec3A::from(ray.at(h.t));
        p.cmpge(lo).all() && p.cmple(hi).all()
    }

    /// Casts `rays` through both queries and fails on the first difference,
    /// except where brute force's own hit is numerically meaningless (see
    /// `accurate` and `within_its_box`); those must stay rare.
    fn assert_same_as_brute(prepared: &PreparedScene, rays: &[(Ray, f32)], what: &str) {
        let (bvh, brute) = (BvhQuery::new(prepared), BruteQuery(prepared));
        let (mut c1, mut c2) = (RayCounts::default(), RayCounts::default());
        let mut excused = 0;
        for (i, (ray, t_max)) in rays.iter().enumerate() {
            for inside in [false, true] {
                let a = bvh.closest(ray, *t_max, inside, &mut c1, &mut NoRecord);
                let b = brute.closest(ray, *t_max, inside, &mut c2, &mut NoRecord);
                if a.as_ref().map(key) != b.as_ref().map(key) && b.is_some_and(|h| !accurate(ray, h.t, h.position) || !within_its_box(prepared, ray, &h)) {
                    excused += 1;
                    continue;
                }
                assert_eq!(a.as_ref().map(key), b.as_ref().map(key), "{what}: ray {i} {ray:?} t_max {t_max} inside {inside}");
            }
            let a = bvh.occluder(ray, *t_max, &mut c1, &mut NoRecord);
            let b = brute.occluder(ray, *t_max, &mut c2, &mut NoRecord);
            if a.is_none() {
                if let Some(Occluder { kind: PrimitiveKind::Triangle, index: k, .. }) = b {
                    let (t, b1, b2) = intersect_triangle(ray, &prepared.edges[k as usize], *t_max).unwrap();
                    let v = prepared.scene.triangles.at(k as usize).v;
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

    /// Every primitive in exactly one leaf; every node inside its parent; every
    /// primitive inside its leaf; leaves small.
    fn check_structure(bvh: &Bvh, scene: &Scene) {
        let total = scene.triangles.len() + scene.spheres.len();
        assert_eq!(bvh.primitive_count(), total);
        let mut seen = vec![0u32; total];
        let mut stack = vec![(bvh.root(), 0u32)];
        let mut nodes = 0;
        let mut max_depth = 0;
        while let Some((i, depth)) = stack.pop() {
            nodes += 1;
            max_depth = max_depth.max(depth);
            let b = bvh.node_bounds(i);
            match bvh.node_content(i) {
                NodeContent::Interior { children } => {
                    assert!((2..=8).contains(&children.len()), "node {i} has {} children", children.len());
                    for c in children {
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
                                let v = scene.triangles.at(p as usize).v;
                                (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
                            }
                            PrimitiveKind::Sphere => {
                                seen[scene.triangles.len() + p as usize] += 1;
                                let s = &scene.spheres[p as usize];
                                (s.center - s.radius, s.center + s.radius)
                            }
                            PrimitiveKind::Csg => panic!("csg objects are kept out of the BVH"),
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
            // CSG objects are kept out of the hierarchy.
            let in_bvh = Scene { csgs: Vec::new(), ..prepared.scene.clone() };
            if let Some((lo, hi)) = in_bvh.bounds() {
                assert!(root.contains(&Aabb { min: lo, max: hi }), "{name}");
            }
        }
    }

    #[test]
    fn sah_build_is_shallow_on_the_bunny() {
        let prepared = load("bunny");
        let bvh = &prepared.bvh;
        let n = prepared.edges.len();
        // Eight-wide: about log8 of its leaves (a 4-wide tree has 11 levels).
        assert!(bvh.depth() <= 8, "depth {}", bvh.depth());
        assert!(bvh.node_count() < n, "{} nodes for {n} triangles", bvh.node_count());
        // Nodes hold more than four children on average (up to eight).
        let interior = bvh.nodes.len();
        let children: u32 = bvh.nodes.iter().map(|n| n.valid.count_ones()).sum();
        assert!(children as f32 > 4.5 * interior as f32, "{children} children in {interior} nodes");
        assert!(matches!(bvh.node_content(bvh.root()), NodeContent::Interior { .. }));
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
        let t = scene.triangles.at(0).clone();
        scene.triangles = vec![t.clone(); 40].into();
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
        let template = scene.triangles.at(0).clone();
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
        // A fixed seed (unless PROPTEST_RNG_SEED is set to explore), so
        // every run tests the same soups. A duplicated triangle hit by a
        // grazing ray whose computed hit point lies outside its padded box
        // is excused (`within_its_box`): which duplicate wins there depends
        // on the order the walk meets their boxes, a limit of exact
        // tie-breaking between coincident triangles, not a wrong surface.
        #![proptest_config(ProptestConfig {
            cases: 48,
            failure_persistence: None,
            rng_seed: if std::env::var_os("PROPTEST_RNG_SEED").is_some() { ProptestConfig::default().rng_seed } else { proptest::test_runner::RngSeed::Fixed(0x5eed) },
            ..ProptestConfig::default()
        })]
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
