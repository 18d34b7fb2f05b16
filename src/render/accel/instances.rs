//! Ray queries through the two-level instance layer (`scene::instanced`):
//! a BVH over the copies' world boxes, and one BVH per shared mesh in the
//! mesh's own space. A ray that enters a copy's box is carried into the
//! copy's space (by the inverse placement; the direction is not
//! normalized, so `t` keeps its meaning) only to walk the mesh's BVH. At a
//! leaf each triangle is made in world space exactly as flattening makes it
//! (`InstanceLayer::world_vertices`) and tested there with the world ray, so
//! `t` and the barycentrics are the bits a flattened copy gives, and the
//! leaf tie rule (`test_leaf`) sees the copies' virtual ids.
//!
//! The mesh BVHs' boxes are grown by `MESH_GROW` of the mesh's size: the ray
//! carried into a copy's space is off by rounding, and a grown box can only
//! make a traversal test more triangles, never miss one.

use crate::render::accel::bvh::{leaf_range, Bvh, LEAF_BIT};
use crate::render::accel::intersect::TriangleEdges;
use crate::render::accel::traverse::{test_leaf, BestHit, PreparedRay, SLAB_WIDEN};
use crate::math::Ray;
use crate::render::inspect::pixel_record::Recorder;
use crate::scene::instanced::InstanceLayer;
use crate::scene::{PrimitiveId, Scene, Triangle};
use glam::{Mat4, Vec3};

/// Growth of the mesh BVHs' boxes, relative to the mesh's largest extent.
const MESH_GROW: f32 = 1e-3;
/// Copies per leaf of the BVH over copies.
const TOP_LEAF: usize = 4;

/// A node of the BVH over copies: a box, then two children or a run of copies.
#[derive(Clone, Copy, Debug)]
struct TopNode {
    min: Vec3,
    max: Vec3,
    /// Leaf: first entry of `order`; interior: the left child (the right is next to it).
    first: u32,
    /// Copies in the leaf; 0 for an interior node.
    count: u32,
}

/// The layer's acceleration structures.
pub struct InstanceAccel {
    nodes: Vec<TopNode>,
    /// Copies in leaf order.
    order: Vec<u32>,
    /// Per copy: world to the copy's space.
    inverse: Vec<Mat4>,
    meshes: Vec<Bvh>,
}

fn grow_planes(bvh: &mut Bvh, by: f32) {
    for n in bvh.nodes.iter_mut() {
        for axis in 0..3 {
            n.planes[2 * axis].iter_mut().for_each(|p| *p -= by);
            n.planes[2 * axis + 1].iter_mut().for_each(|p| *p += by);
        }
    }
    bvh.root_bounds.min -= Vec3::splat(by);
    bvh.root_bounds.max += Vec3::splat(by);
}

impl InstanceAccel {
    pub fn build(layer: &InstanceLayer) -> InstanceAccel {
        let empty = Scene::default();
        let meshes: Vec<Bvh> = layer
            .meshes
            .iter()
            .map(|m| {
                let mut bvh = Bvh::build(&empty, &m[..]);
                let b = bvh.bounds();
                let extent = (b.max - b.min).max_element().max(b.min.abs().max(b.max.abs()).max_element() * 1e-3);
                grow_planes(&mut bvh, extent * MESH_GROW);
                bvh
            })
            .collect();
        let mut boxes = Vec::with_capacity(layer.instances.len());
        let mut inverse = Vec::with_capacity(layer.instances.len());
        for inst in &layer.instances {
            let m = inst.placement.matrix();
            inverse.push(m.inverse());
            let b = meshes[inst.mesh as usize].bounds();
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for c in b.corners() {
                let w = m.transform_point3(c);
                lo = lo.min(w);
                hi = hi.max(w);
            }
            let pad = (hi - lo).max_element() * 1e-4 + lo.abs().max(hi.abs()).max_element() * 1e-6;
            boxes.push((lo - Vec3::splat(pad), hi + Vec3::splat(pad)));
        }
        let mut order: Vec<u32> = (0..layer.instances.len() as u32).collect();
        let mut nodes = vec![TopNode { min: Vec3::ZERO, max: Vec3::ZERO, first: 0, count: 0 }];
        if !order.is_empty() {
            build_top(&mut nodes, 0, &mut order, 0, &boxes);
        }
        InstanceAccel { nodes, order, inverse, meshes }
    }

    /// Bytes held: the nodes, the inverse placements and the mesh BVHs.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.nodes[..]) + size_of_val(&self.order[..]) + size_of_val(&self.inverse[..]) + self.meshes.iter().map(Bvh::memory_bytes).sum::<usize>()
    }

    /// Tests `ray` against every copy it may hit before `best.t`, keeping the
    /// nearest hit in `best` (on equal `t` the lower id). With `ANY` it stops
    /// at the first hit and returns true.
    #[allow(clippy::too_many_arguments)]
    pub fn traverse<const ANY: bool, R: Recorder>(&self, layer: &InstanceLayer, ray: &Ray, best: &mut BestHit, visits: &mut u64, tests: &mut u64, rec: &mut R) -> bool {
        if self.order.is_empty() {
            return false;
        }
        let r = PreparedRay::new(ray);
        let mut stack: Vec<(u32, f32)> = Vec::with_capacity(64);
        if let Some(t) = enter(&r, &self.nodes[0], best.t) {
            stack.push((0, t));
        }
        while let Some((n, t_enter)) = stack.pop() {
            if t_enter > best.t {
                continue;
            }
            *visits += 1;
            let node = self.nodes[n as usize];
            if node.count == 0 {
                let (a, b) = (node.first, node.first + 1);
                let ta = enter(&r, &self.nodes[a as usize], best.t);
                let tb = enter(&r, &self.nodes[b as usize], best.t);
                // The nearer child is popped first.
                match (ta, tb) {
                    (Some(x), Some(y)) if x <= y => stack.extend([(b, y), (a, x)]),
                    (Some(x), Some(y)) => stack.extend([(a, x), (b, y)]),
                    (Some(x), None) => stack.push((a, x)),
                    (None, Some(y)) => stack.push((b, y)),
                    (None, None) => {}
                }
                continue;
            }
            for &k in &self.order[node.first as usize..(node.first + node.count) as usize] {
                if self.copy::<ANY, R>(layer, k as usize, ray, best, visits, tests, rec) {
                    return true;
                }
            }
        }
        false
    }

    /// The walk through copy `k`'s mesh BVH.
    #[allow(clippy::too_many_arguments)]
    fn copy<const ANY: bool, R: Recorder>(&self, layer: &InstanceLayer, k: usize, ray: &Ray, best: &mut BestHit, visits: &mut u64, tests: &mut u64, rec: &mut R) -> bool {
        let inst = &layer.instances[k];
        let bvh = &self.meshes[inst.mesh as usize];
        if bvh.prims.is_empty() {
            return false;
        }
        let inv = &self.inverse[k];
        let local = Ray { origin: inv.transform_point3(ray.origin), dir: inv.transform_vector3(ray.dir) };
        let r = PreparedRay::new(&local);
        if !r.slab1(bvh.root_bounds.min, bvh.root_bounds.max, best.t) {
            return false;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        let mut word = bvh.root;
        let mut leaf: [(TriangleEdges, PrimitiveId); 8] = [(TriangleEdges::ZERO, PrimitiveId::NONE); 8];
        loop {
            *visits += 1;
            if word & LEAF_BIT == 0 {
                let node = &bvh.nodes[word as usize];
                let (mut mask, _) = r.slab8(&node.planes, node.valid, best.t);
                while mask != 0 {
                    stack.push(node.child[mask.trailing_zeros() as usize]);
                    mask &= mask - 1;
                }
            } else {
                let (start, end) = leaf_range(word);
                for (slot, (_, id)) in leaf.iter_mut().zip(&bvh.prims[start..end]) {
                    let local_index = id.index() as usize;
                    let (v, two_sided) = layer.world_vertices(inst, local_index);
                    let t = Triangle { v, n: [Vec3::ZERO; 3], uv: [glam::Vec2::ZERO; 3], material: 0, object: 0, two_sided };
                    *slot = (TriangleEdges::new(&t), PrimitiveId::triangle(inst.base + local_index as u32));
                }
                if test_leaf::<ANY, R>(&leaf[..end - start], &[], ray, false, best, tests, rec) {
                    return true;
                }
            }
            match stack.pop() {
                Some(next) => word = next,
                None => return false,
            }
        }
    }
}

/// Where the ray enters the node's box before `t_far`, widened as the BVH's slab test is.
#[inline]
fn enter(r: &PreparedRay, n: &TopNode, t_far: f32) -> Option<f32> {
    let mut t = (0.0f32, t_far);
    for axis in 0..3 {
        let o = r.origin[axis].x;
        let inv = r.inv[axis].x;
        let (a, b) = ((n.min[axis] - o) * inv, (n.max[axis] - o) * inv);
        t.0 = t.0.max(a.min(b) * (1.0 - SLAB_WIDEN));
        t.1 = t.1.min(a.max(b) * (1.0 + SLAB_WIDEN));
    }
    (t.0 <= t.1).then_some(t.0)
}

/// Builds node `at` over `items` (copies, their entries of `order` from `first`), splitting at the median.
fn build_top(nodes: &mut Vec<TopNode>, at: usize, items: &mut [u32], first: u32, boxes: &[(Vec3, Vec3)]) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut clo, mut chi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for &i in items.iter() {
        let (a, b) = boxes[i as usize];
        lo = lo.min(a);
        hi = hi.max(b);
        let c = (a + b) * 0.5;
        clo = clo.min(c);
        chi = chi.max(c);
    }
    if items.len() <= TOP_LEAF {
        nodes[at] = TopNode { min: lo, max: hi, first, count: items.len() as u32 };
        return;
    }
    let ext = chi - clo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z { 0 } else if ext.y >= ext.z { 1 } else { 2 };
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |&a, &b| {
        let ca = boxes[a as usize].0[axis] + boxes[a as usize].1[axis];
        let cb = boxes[b as usize].0[axis] + boxes[b as usize].1[axis];
        ca.total_cmp(&cb)
    });
    let left = nodes.len();
    nodes.push(TopNode { min: Vec3::ZERO, max: Vec3::ZERO, first: 0, count: 0 });
    nodes.push(TopNode { min: Vec3::ZERO, max: Vec3::ZERO, first: 0, count: 0 });
    nodes[at] = TopNode { min: lo, max: hi, first: left as u32, count: 0 };
    let (l, r) = items.split_at_mut(mid);
    build_top(nodes, left, l, first, boxes);
    build_top(nodes, left + 1, r, first + mid as u32, boxes);
}
