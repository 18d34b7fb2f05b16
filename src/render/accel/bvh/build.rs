//! Building the BVH: a binary tree by the binned surface area heuristic
//! (SAH), then collapsed into the 8-wide nodes the traversal reads.
//!
//! The tree depends on the primitives alone, never on the thread count:
//! subtrees are built in parallel, and the top nodes are binned in parallel
//! chunks whose bins merge by min, max and sums, which no order changes.
//! Each node's bounds come from its parent (the union of the bins on its
//! side of the split) and its centroid bounds from the parent's partition,
//! so every primitive is read twice per level: once to bin it, once to
//! partition it.

use crate::render::accel::bvh::{leaf_word, Aabb, Bvh, Node8, MAX_LEAF, STACK};
use crate::render::accel::scene_edges::SceneEdges;
use crate::render::accel::intersect::TriangleEdges;
use crate::scene::{PrimitiveId, Scene, Triangle};
use glam::{UVec3, Vec3, Vec3A};
use rayon::prelude::*;
use std::sync::Arc;

/// SAH costs of one node visit and one primitive test.
const COST_TRAVERSE: f32 = 1.0;
const COST_INTERSECT: f32 = 1.0;
/// Subtrees with more primitives than this are built in parallel.
const PARALLEL_MIN: usize = 4096;
/// Nodes with more primitives than this are binned in parallel chunks of
/// `BIN_CHUNK`.
const PARALLEL_BIN_MIN: usize = 32 * 1024;
const BIN_CHUNK: usize = 8 * 1024;
/// Below this depth the build splits by SAH; deeper it splits at the median,
/// which bounds the depth at MEDIAN_DEPTH + 32.
const MEDIAN_DEPTH: u32 = 32;

/// Triangle edges by scene index: what the build reads.
pub trait EdgeSource {
    fn count(&self) -> usize;
    fn edges(&self, i: usize) -> TriangleEdges;
}

impl EdgeSource for [TriangleEdges] {
    fn count(&self) -> usize {
        self.len()
    }
    fn edges(&self, i: usize) -> TriangleEdges {
        self[i]
    }
}

impl EdgeSource for Vec<TriangleEdges> {
    fn count(&self) -> usize {
        self.len()
    }
    fn edges(&self, i: usize) -> TriangleEdges {
        self[i]
    }
}

impl EdgeSource for SceneEdges {
    fn count(&self) -> usize {
        self.len()
    }
    fn edges(&self, i: usize) -> TriangleEdges {
        self[i]
    }
}

/// The scene's triangles, their edges made as `TriangleEdges::new` makes them.
impl EdgeSource for crate::scene::Triangles {
    fn count(&self) -> usize {
        self.len()
    }
    fn edges(&self, i: usize) -> TriangleEdges {
        TriangleEdges::new(&self.at(i))
    }
}

/// Triangles held apart from a scene, their edges made as for the scene's.
impl EdgeSource for [Triangle] {
    fn count(&self) -> usize {
        self.len()
    }
    fn edges(&self, i: usize) -> TriangleEdges {
        TriangleEdges::new(&self[i])
    }
}

/// Bounds and centroid of one primitive during the build.
#[derive(Clone, Copy)]
struct PrimRef {
    min: Vec3A,
    max: Vec3A,
    id: PrimitiveId,
}

impl PrimRef {
    #[inline(always)]
    fn centroid(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }
}

#[derive(Clone, Copy)]
pub(super) struct Bounds {
    min: Vec3A,
    max: Vec3A,
}

impl Bounds {
    pub(super) const EMPTY: Bounds = Bounds { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    #[inline(always)]
    pub(super) fn grow(&mut self, min: Vec3A, max: Vec3A) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    #[inline(always)]
    fn union(a: Bounds, b: Bounds) -> Bounds {
        Bounds { min: a.min.min(b.min), max: a.max.max(b.max) }
    }

    /// Half the surface area (the SAH only needs ratios).
    #[inline(always)]
    fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

pub(super) fn aabb(b: Bounds) -> Aabb {
    Aabb { min: Vec3::from(b.min), max: Vec3::from(b.max) }
}

/// A primitive's box, padded so rounding in the ray tests cannot leave a hit
/// outside it.
fn padded(min: Vec3A, max: Vec3A) -> (Vec3A, Vec3A) {
    let extent = (max - min).max_element();
    let magnitude = min.abs().max(max.abs()).max_element();
    let pad = extent * 1.0e-5 + magnitude * 2.0e-6 + f32::MIN_POSITIVE;
    (min - Vec3A::splat(pad), max + Vec3A::splat(pad))
}

/// A triangle's padded box, from the edges the ray test uses.
#[inline]
pub(super) fn triangle_box(e: &TriangleEdges) -> (Vec3A, Vec3A) {
    let (v0, v1, v2) = (Vec3A::from(e.v0), Vec3A::from(e.v0 + e.e1), Vec3A::from(e.v0 + e.e2));
    padded(v0.min(v1).min(v2), v0.max(v1).max(v2))
}

/// A node of the binary tree the build makes, before it is collapsed into
/// 8-wide nodes.
enum BuildNode {
    Leaf { b: Bounds, first: u32, count: u32 },
    Inner { b: Bounds, kids: Box<[BuildNode; 2]> },
}

impl BuildNode {
    /// The primitive slots below this node, (first, count): a subtree's
    /// leaves cover one contiguous range, from its leftmost leaf's first
    /// slot to its rightmost leaf's last (two walks down its sides).
    fn span(&self) -> (u32, u32) {
        let mut left = self;
        while let BuildNode::Inner { kids, .. } = left {
            left = &kids[0];
        }
        let mut right = self;
        while let BuildNode::Inner { kids, .. } = right {
            right = &kids[1];
        }
        match (left, right) {
            (BuildNode::Leaf { first, .. }, BuildNode::Leaf { first: last, count, .. }) => (*first, last + count - first),
            _ => unreachable!("the walks end at leaves"),
        }
    }

    fn bounds(&self) -> Bounds {
        match self {
            BuildNode::Leaf { b, .. } | BuildNode::Inner { b, .. } => *b,
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    b: Bounds,
    n: u32,
}

impl Bin {
    const EMPTY: Bin = Bin { b: Bounds::EMPTY, n: 0 };
}

/// `NB` bins along each axis.
type Bins<const NB: usize> = [[Bin; NB]; 3];

/// Adds `refs` to `bins` by centroid: bin `k` of axis `a` gets the
/// primitives whose centroid's `a` maps to `k` under `origin` and `scale`.
fn bin_refs<const NB: usize>(bins: &mut Bins<NB>, refs: &[PrimRef], origin: Vec3A, scale: Vec3A) {
    let last = UVec3::splat(NB as u32 - 1);
    for r in refs {
        let k = ((r.centroid() - origin) * scale).as_uvec3().min(last);
        for (a, bins) in bins.iter_mut().enumerate() {
            let bin = &mut bins[k[a] as usize];
            bin.b.grow(r.min, r.max);
            bin.n += 1;
        }
    }
}

/// `bin_refs` over chunks in parallel, merged: min, max and sums give the
/// same bins in any order.
fn bin_refs_parallel<const NB: usize>(refs: &[PrimRef], origin: Vec3A, scale: Vec3A) -> Bins<NB> {
    refs.par_chunks(BIN_CHUNK)
        .map(|chunk| {
            let mut bins = [[Bin::EMPTY; NB]; 3];
            bin_refs::<NB>(&mut bins, chunk, origin, scale);
            bins
        })
        .reduce(
        || [[Bin::EMPTY; NB]; 3],
        |mut a, b| {
            for (a, b) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                a.b = Bounds::union(a.b, b.b);
                a.n += b.n;
            }
            a
        },
    )
}

/// What the SAH makes of a node.
enum Sah {
    /// Cheaper as a leaf.
    Leaf,
    /// Split at `mid`: `refs[..mid]` and `refs[mid..]` are the children,
    /// with these bounds and centroid bounds.
    Split { mid: usize, left: (Bounds, Bounds), right: (Bounds, Bounds) },
    /// No plane separates the centroids.
    None,
}

/// The binned SAH split of `refs` (bounds `b`, centroid bounds `cb`) with
/// `NB` bins per axis, and the partition of `refs` at it.
fn sah_split<const NB: usize>(refs: &mut [PrimRef], b: Bounds, cb: Bounds) -> Sah {
    let n = refs.len();
    let extent = cb.max - cb.min;
    let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(NB as f32 * 0.99999) / extent, Vec3A::ZERO);
    let mut bins = [[Bin::EMPTY; NB]; 3];
    if n > PARALLEL_BIN_MIN {
        bins = bin_refs_parallel::<NB>(refs, cb.min, scale);
    } else {
        bin_refs::<NB>(&mut bins, refs, cb.min, scale);
    }
    // The cheapest plane; the first (by axis, then plane) of equals. Only
    // planes just after an occupied bin are costed: every plane of a run
    // of empty bins after it splits the same way at the same cost, and the
    // first of them, the one kept, is the one just after it.
    let mut best = (f32::INFINITY, 0usize, 0usize);
    for (a, bins) in bins.iter().enumerate() {
        if extent[a] <= 0.0 {
            continue;
        }
        let mut occupied = [0u8; NB];
        let mut m = 0;
        for (i, bin) in bins.iter().enumerate() {
            occupied[m] = i as u8;
            m += (bin.n > 0) as usize;
        }
        let occupied = &occupied[..m];
        // Right to left: the cost of the right side of each split plane
        // (by the first bin on its right).
        let mut right_cost = [0.0f32; NB];
        let mut acc = Bounds::EMPTY;
        let mut cnt = 0u32;
        for &i in occupied[1..].iter().rev() {
            let bin = &bins[i as usize];
            acc = Bounds::union(acc, bin.b);
            cnt += bin.n;
            right_cost[i as usize] = acc.half_area() * cnt as f32;
        }
        let mut acc = Bounds::EMPTY;
        let mut cnt = 0u32;
        for w in occupied.windows(2) {
            let bin = &bins[w[0] as usize];
            acc = Bounds::union(acc, bin.b);
            cnt += bin.n;
            let cost = acc.half_area() * cnt as f32 + right_cost[w[1] as usize];
            if cost < best.0 {
                best = (cost, a, w[0] as usize + 1);
            }
        }
    }
    if !best.0.is_finite() {
        return Sah::None;
    }
    let split_cost = COST_TRAVERSE + COST_INTERSECT * best.0 / b.half_area().max(f32::MIN_POSITIVE);
    let leaf_cost = COST_INTERSECT * n as f32;
    if n <= MAX_LEAF && leaf_cost <= split_cost {
        return Sah::Leaf;
    }
    let (_, axis, plane) = best;
    // The children's bounds: the union of the bins on each side.
    let (mut lb, mut rb) = (Bounds::EMPTY, Bounds::EMPTY);
    for (i, bin) in bins[axis].iter().enumerate() {
        if i < plane {
            lb = Bounds::union(lb, bin.b);
        } else {
            rb = Bounds::union(rb, bin.b);
        }
    }
    // In-place partition, gathering each side's centroid bounds. The bin
    // index is computed as binning computed it.
    let (lo, s) = (cb.min[axis], scale[axis]);
    let in_left = |c: Vec3A| (((c[axis] - lo) * s) as u32).min(NB as u32 - 1) < plane as u32;
    let (mut lcb, mut rcb) = (Bounds::EMPTY, Bounds::EMPTY);
    let (mut i, mut j) = (0usize, n);
    while i < j {
        let c = refs[i].centroid();
        if in_left(c) {
            lcb.grow(c, c);
            i += 1;
        } else {
            rcb.grow(c, c);
            j -= 1;
            refs.swap(i, j);
        }
    }
    Sah::Split { mid: i, left: (lb, lcb), right: (rb, rcb) }
}

/// Bounds and centroid bounds of `refs`.
fn bounds_of(refs: &[PrimRef]) -> (Bounds, Bounds) {
    let (mut b, mut cb) = (Bounds::EMPTY, Bounds::EMPTY);
    for r in refs {
        b.grow(r.min, r.max);
        let c = r.centroid();
        cb.grow(c, c);
    }
    (b, cb)
}

/// The subtree over `refs` (in primitive slots from `first`), whose bounds
/// are `b` and centroid bounds `cb`.
fn build_rec(refs: &mut [PrimRef], first: u32, depth: u32, b: Bounds, cb: Bounds) -> BuildNode {
    let n = refs.len();
    let leaf = BuildNode::Leaf { b, first, count: n as u32 };
    if n <= 1 {
        return leaf;
    }
    let extent = cb.max - cb.min;
    let mut split = None;
    if depth < MEDIAN_DEPTH && extent.max_element() > 0.0 {
        // Fewer bins for small nodes: their sweeps would cost more than the binning.
        let sah = if n <= 32 {
            sah_split::<8>(refs, b, cb)
        } else if n <= 512 {
            sah_split::<16>(refs, b, cb)
        } else {
            sah_split::<32>(refs, b, cb)
        };
        match sah {
            Sah::Leaf => return leaf,
            Sah::Split { mid, left, right } if mid != 0 && mid != n => split = Some((mid, left, right)),
            _ => {}
        }
    }
    let (mid, left, right) = match split {
        Some(s) => s,
        None => {
            // No useful SAH split (coincident centroids, or too deep): a leaf
            // if small enough, else halves by the centroid median.
            if n <= MAX_LEAF {
                return leaf;
            }
            let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
            let mid = n / 2;
            refs.select_nth_unstable_by(mid, |p, q| p.centroid()[axis].total_cmp(&q.centroid()[axis]).then(p.id.cmp(&q.id)));
            (mid, bounds_of(&refs[..mid]), bounds_of(&refs[mid..]))
        }
    };
    let (l_refs, r_refs) = refs.split_at_mut(mid);
    let (l, r) = if n > PARALLEL_MIN {
        rayon::join(
            || build_rec(l_refs, first, depth + 1, left.0, left.1),
            || build_rec(r_refs, first + mid as u32, depth + 1, right.0, right.1),
        )
    } else {
        (build_rec(l_refs, first, depth + 1, left.0, left.1), build_rec(r_refs, first + mid as u32, depth + 1, right.0, right.1))
    };
    BuildNode::Inner { b, kids: Box::new([l, r]) }
}

/// Collapses the binary tree into the 8-wide one.
struct Collapse<'a> {
    nodes: Vec<Node8>,
    /// The primitives in slot order.
    refs: &'a [PrimRef],
    /// Whether any primitive is a sphere.
    spheres: bool,
    sphere_leaf_bounds: Vec<(u32, Aabb)>,
    leaves: usize,
    depth: u32,
}

/// A subtree over this many primitives or fewer becomes one leaf of the
/// 8-wide tree. The binary SAH splits such small sets (its node costs as
/// much as one primitive test), but in the wide tree most of them would be
/// nodes of two or three leaves, each a 256-byte node visited for a test
/// or two. Merged, the bunny's nodes take 1.7 MB instead of 3.6 MB (a
/// 4-wide tree over the same binary one: 2.4 MB), and single rays take as
/// many instructions as without the merge.
const MERGE_LEAF: u32 = 4;
const _: () = assert!(MERGE_LEAF as usize <= MAX_LEAF);

/// The children of a wide node standing for an inner binary node with
/// `kids`: its subtrees, the inner one of largest area opened into its two
/// (the last of equals) until there are eight of them or only leaves.
fn open_children(kids: &[BuildNode; 2]) -> ([&BuildNode; 8], usize) {
    let mut children: [&BuildNode; 8] = [&kids[1]; 8];
    children[0] = &kids[0];
    let mut len = 2;
    while len < 8 {
        let mut open = None;
        let mut largest = f32::NEG_INFINITY;
        for (i, c) in children[..len].iter().enumerate() {
            if let BuildNode::Inner { b, .. } = c {
                let area = b.half_area();
                if open.is_none() || area.total_cmp(&largest).is_ge() {
                    open = Some(i);
                    largest = area;
                }
            }
        }
        let Some(i) = open else { break };
        let BuildNode::Inner { kids, .. } = children[i] else { unreachable!() };
        children.copy_within(i + 1..len, i + 2);
        children[i] = &kids[0];
        children[i + 1] = &kids[1];
        len += 1;
    }
    (children, len)
}

impl Collapse<'_> {
    /// The word for binary subtree `t` at 8-wide level `level`: a leaf (a
    /// binary leaf, or a small subtree merged into one), or a node whose
    /// children are `t`'s descendants (the larger ones opened first).
    fn word(&mut self, t: &BuildNode, level: u32) -> u32 {
        self.depth = self.depth.max(level);
        let (first, count) = t.span();
        let kids = match t {
            BuildNode::Inner { kids, .. } if count > MERGE_LEAF => kids,
            _ => {
                self.leaves += 1;
                if self.spheres && self.refs[first as usize..(first + count) as usize].iter().any(|r| r.id.is_sphere()) {
                    self.sphere_leaf_bounds.push((first, aabb(t.bounds())));
                }
                return leaf_word(first, count);
            }
        };
        let (children, len) = open_children(kids);
        let index = self.nodes.len();
        self.nodes.push(Node8::EMPTY);
        let mut node = Node8::EMPTY;
        for (i, c) in children[..len].iter().enumerate() {
            let cb = c.bounds();
            for axis in 0..3 {
                node.planes[axis * 2][i] = cb.min[axis];
                node.planes[axis * 2 + 1][i] = cb.max[axis];
            }
            node.child[i] = self.word(c, level + 1);
            node.valid |= 1 << i;
        }
        self.nodes[index] = node;
        index as u32
    }
}

impl Bvh {
    /// Builds the hierarchy over every triangle (`edges`, in scene order) and
    /// every sphere of `scene`.
    pub fn build<E: EdgeSource + Sync + ?Sized>(scene: &Scene, edges: &E) -> Bvh {
        // Each triangle's edges are made twice, for its box here and for its
        // slot at the end, rather than kept: a copy would add 44 bytes per
        // triangle to the build's peak memory.
        let triangles = edges.count();
        let mut refs: Vec<PrimRef> = Vec::with_capacity(triangles + scene.spheres.len());
        (0..triangles)
            .into_par_iter()
            .map(|i| {
                let (min, max) = triangle_box(&edges.edges(i));
                PrimRef { min, max, id: PrimitiveId::triangle(i as u32) }
            })
            .collect_into_vec(&mut refs);
        for (i, s) in scene.spheres.iter().enumerate() {
            let (c, r) = (Vec3A::from(s.center), Vec3A::splat(s.radius.abs()));
            let (min, max) = padded(c - r, c + r);
            refs.push(PrimRef { min, max, id: PrimitiveId::sphere(i as u32) });
        }
        if refs.is_empty() {
            return Bvh {
                nodes: Vec::new(),
                root: leaf_word(0, 1),
                root_bounds: Aabb::EMPTY,
                prims: Arc::new(Vec::new()),
                sphere_leaf_bounds: Vec::new(),
                leaves: 0,
                depth: 0,
                deep: false,
            };
        }
        let (b, cb) = refs
            .par_chunks(BIN_CHUNK)
            .map(bounds_of)
            .reduce(|| (Bounds::EMPTY, Bounds::EMPTY), |x, y| (Bounds::union(x.0, y.0), Bounds::union(x.1, y.1)));
        let tree = build_rec(&mut refs, 0, 0, b, cb);
        let mut c = Collapse {
            nodes: Vec::with_capacity(refs.len() / 8 + 1),
            refs: &refs,
            spheres: !scene.spheres.is_empty(),
            sphere_leaf_bounds: Vec::new(),
            leaves: 0,
            depth: 0,
        };
        let root = c.word(&tree, 0);
        let root_bounds = aabb(tree.bounds());
        let Collapse { mut nodes, mut sphere_leaf_bounds, leaves, depth, .. } = c;
        nodes.shrink_to_fit();
        sphere_leaf_bounds.sort_unstable_by_key(|(first, _)| *first);
        // The primitive slots gathered while the binary tree is freed.
        let dummy = TriangleEdges::ZERO;
        let ((), prims) = rayon::join(
            move || drop(tree),
            || {
                let mut prims = Vec::new();
                refs.par_iter().map(|r| (if r.id.is_sphere() { dummy } else { edges.edges(r.id.index() as usize) }, r.id)).collect_into_vec(&mut prims);
                prims
            },
        );
        Bvh {
            nodes,
            root,
            root_bounds,
            prims: Arc::new(prims),
            sphere_leaf_bounds,
            leaves,
            depth,
            deep: (depth as usize + 1) * 7 >= STACK,
        }
    }

    /// The triangles' edges in scene order, read from the primitive slots.
    pub fn edges_in_scene_order(&self) -> SceneEdges {
        let triangles = self.prims.iter().filter(|(_, id)| !id.is_sphere()).count();
        let mut slot = vec![u32::MAX; triangles];
        for (k, (_, id)) in self.prims.iter().enumerate() {
            if !id.is_sphere() {
                slot[id.index() as usize] = k as u32;
            }
        }
        SceneEdges::new(Arc::clone(&self.prims), slot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    fn build_with_threads(scene: &Scene, threads: usize) -> Bvh {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| Bvh::build(scene, &scene.triangles))
    }

    /// Everything the traversal reads, as bits.
    fn fingerprint(bvh: &Bvh) -> (Vec<u32>, Vec<PrimitiveId>, u32, u32) {
        let nodes = bvh
            .nodes
            .iter()
            .flat_map(|n| n.planes.iter().flat_map(|p| p.map(f32::to_bits)).chain(n.child).chain([n.valid]))
            .collect();
        (nodes, bvh.prims.iter().map(|(_, id)| *id).collect(), bvh.root, bvh.depth)
    }

    #[test]
    fn the_tree_does_not_depend_on_the_thread_count() {
        // The bunny is large enough for parallel subtrees and parallel binning.
        let scene = builtin::load_builtin("bunny").unwrap().unwrap();
        assert!(scene.triangles.len() > 2 * PARALLEL_BIN_MIN);
        let one = fingerprint(&build_with_threads(&scene, 1));
        for threads in [2, 3] {
            assert!(one == fingerprint(&build_with_threads(&scene, threads)), "{threads} threads");
        }
    }

    #[test]
    fn a_split_hands_its_children_their_own_bounds() {
        // Thin triangles at x = 0, 5 and 9: the cheapest split puts the one
        // at 0 alone, and the bounds the split hands down (from the bins and
        // the partition) are those of the primitives on each side.
        let tri = |x: f32| {
            let (min, max) = padded(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x + 0.1, 0.1, 0.0));
            PrimRef { min, max, id: PrimitiveId::triangle(x as u32) }
        };
        for order in [[5.0, 0.0, 9.0], [9.0, 5.0, 0.0], [0.0, 9.0, 5.0]] {
            let mut refs: Vec<PrimRef> = order.into_iter().map(tri).collect();
            let (b, cb) = bounds_of(&refs);
            let Sah::Split { mid, left, right } = sah_split::<8>(&mut refs, b, cb) else { panic!("no split") };
            assert_eq!((mid, refs[0].id), (1, PrimitiveId::triangle(0)));
            let (lb, lcb) = bounds_of(&refs[..mid]);
            let (rb, rcb) = bounds_of(&refs[mid..]);
            assert_eq!([left.0, left.1, right.0, right.1].map(aabb), [lb, lcb, rb, rcb].map(aabb));
        }
    }
}
