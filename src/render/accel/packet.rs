//! Rays traced as packets: the rays of a TILE_W x TILE_H pixel tile walk
//! the 8-wide BVH together. Each node is fetched once per packet and its eight
//! child boxes are tested against eight rays at a time, and each leaf
//! triangle against eight rays at a time (one SIMD lane per ray, at the
//! widest level the CPU has: `math::lanes::simd_level`), so the per-ray
//! latency chain of single-ray traversal becomes independent work.
//!
//! Every ray ends with exactly the hit `BvhQuery::closest` finds for it alone:
//! - a ray enters a node only when its own slab test (`slab_test8`, the
//!   single-ray test's arithmetic, lane by lane) accepts the box;
//! - leaves test only those rays, with the single test's arithmetic
//!   (`intersect_triangle_lanes`) and the same tie rule in the same order
//!   (on equal t the lower primitive id wins): the order in which the
//!   packet visits nodes cannot change any ray's winner; the padded boxes
//!   guarantee no true hit is culled by a box test in either traversal.
//!
//! This module only answers rays. The renderer that fills packets with a
//! tile's eye rays and shades what they meet is `raytrace::packet_tiles`.

use crate::render::accel::bvh::{leaf_range, BvhQuery, Node8, LEAF_BIT, STACK};
use crate::render::accel::intersect::{intersect_triangle_lanes, TriangleEdges};
use crate::render::accel::traverse::{slab_test8, test_leaf, BestHit, ChildOrder, SLAB_WIDEN};
use crate::math::lanes::{mask_bits, mask_from_bits, simd_level, V3};
use crate::math::Ray;
use crate::render::inspect::pixel_record::NoRecord;
use crate::render::BatchHit;
use crate::render::{Occluder, RayCounts};
use crate::scene::hit_lanes::{HitLanes, TriangleHitInput, HIT_LANES};
use crate::scene::{PrimitiveId, PrimitiveKind, Sphere, SurfaceHit};
use fearless_simd::{dispatch, f32x8, mask32x8, u32x8, Bytes, Select, Simd, SimdBase, SimdFloat, SimdFrom};
use glam::Vec3;
use std::mem::MaybeUninit;

pub const TILE_W: usize = 8;
pub const TILE_H: usize = 8;
/// Rays per packet: eight groups of eight (one SIMD register of lanes).
pub(crate) const P: usize = TILE_W * TILE_H;
const _: () = assert!(P == 64 && TILE_W % 4 == 0 && TILE_H % 2 == 0);

/// Rays in a packet.
pub const PACKET_RAYS: usize = P;

/// Where incoherent rays' packets (`closest_hybrid`, `occluded_hybrid`) go
/// on ray by ray: once this few of a packet's rays share an entry. The best
/// of 1-16 (with 8-64 rays a packet) on the first bounces of `bunny_ground`
/// and `cornell_gi` (`examples/bvh_speed.rs`); 8 to 24 are alike in frames.
pub const HYBRID_ALONE: u32 = 12;

#[derive(Clone, Copy)]
#[repr(C, align(16))]
pub(crate) struct Lanes(pub(crate) [f32; P]);

/// Image position within the tile of lane `i`: each group of four lanes is a
/// 2x2 quad, and each group of eight two quads side by side (a 4x2 block),
/// so a group's rays are as close together as they can be.
#[inline(always)]
pub fn lane_xy(i: usize) -> (usize, usize) {
    let (x, y) = LANE_XY[i];
    (x as usize, y as usize)
}

/// `lane_xy` for every lane, worked out once: a tile asks for it several
/// times per lane.
pub(crate) const LANE_XY: [(u8, u8); P] = {
    let mut table = [(0u8, 0u8); P];
    let mut i = 0;
    while i < P {
        let (g, q) = (i / 4, i % 4);
        table[i] = ((2 * (g % (TILE_W / 2)) + (q & 1)) as u8, (2 * (g / (TILE_W / 2)) + (q >> 1)) as u8);
        i += 1;
    }
    table
};

/// Which sample each lane of a tile holds: lane i is pass `lanes[i].0` (an
/// index into the call's jobs) at pixel `(x0 + lanes[i].1, y0 + lanes[i].2)`
/// of the tile at `(x0, y0)`, and its radiance goes to `out` at
/// `pass * pass_stride + y * width + x` (y counted from the band's top).
pub(crate) struct TileLayout {
    pub(crate) lanes: [(u8, u8, u8); P],
    pub(crate) pass_stride: usize,
}

impl TileLayout {
    /// One pass, TILE_W x TILE_H pixels: `lane_xy`'s lanes (which
    /// `shade_tile_batched::<false>` reads directly).
    pub(crate) const ONE_PASS: TileLayout = {
        let mut lanes = [(0u8, 0u8, 0u8); P];
        let mut i = 0;
        while i < P {
            lanes[i] = (0, LANE_XY[i].0, LANE_XY[i].1);
            i += 1;
        }
        TileLayout { lanes, pass_stride: 0 }
    };

    /// `passes` (2, 4, 8 or 16) passes of a tile of `P / passes` pixels
    /// (`pass_tile`), pixel by pixel: lane i is pass `i % passes` of the
    /// tile's pixel `i / passes` (row by row). A group of eight lanes is
    /// then one pixel's samples (or a few neighbours'), whose rays go down
    /// the tree almost as one, and a batch shades surfaces of one triangle.
    pub(crate) const fn passes(passes: usize) -> [(u8, u8, u8); P] {
        let (tile_w, _) = pass_tile(passes);
        let mut table = [(0u8, 0u8, 0u8); P];
        let mut i = 0;
        while i < P {
            let (pass, pixel) = (i % passes, i / passes);
            table[i] = (pass as u8, (pixel % tile_w) as u8, (pixel / tile_w) as u8);
            i += 1;
        }
        table
    }
}

/// The pixels (across, down) of a tile that holds `passes` passes (2, 4, 8
/// or 16) of each: a pixel's samples of those passes go down the tree
/// together, so a packet's rays stay close together and meet fewer boxes
/// and leaves than 8x8 pixels of one pass do.
pub(crate) const fn pass_tile(passes: usize) -> (usize, usize) {
    match passes {
        16 => (2, 2),
        8 => (4, 2),
        4 => (4, 4),
        _ => (8, 4),
    }
}

/// Most passes a tile holds.
pub const MAX_PASSES: usize = 16;

/// The lanes of tiles of 2, 4, 8 and 16 passes.
pub(crate) const PASS_LAYOUTS: [[(u8, u8, u8); P]; 4] = [TileLayout::passes(2), TileLayout::passes(4), TileLayout::passes(8), TileLayout::passes(16)];

/// The rays of one packet and their traversal state, structure of arrays.
pub struct Packet {
    pub rays: [Ray; P],
    pub t_max: [f32; P],
    pub(crate) origin: [Lanes; 3],
    pub(crate) dir: [Lanes; 3],
    pub(crate) inv: [Lanes; 3],
    /// The closest hit so far (t_max until one is found): the far end of the box tests.
    pub(crate) best_t: Lanes,
    /// Primitive tests accept t < limit: just above best_t once something is
    /// hit, so an equal-t hit on an earlier primitive can still win the tie.
    pub(crate) limit: [f32; P],
    pub(crate) best_id: [PrimitiveId; P],
    /// The closest hit's weights of its triangle's second and third corners.
    pub(crate) bary: [Lanes; 2],
}

impl Packet {
    /// Lays out the rays of lanes `8 g..8 g + 8` for the traversal (origins,
    /// directions and inverse directions as lanes, each far end as its
    /// best `t` and limit) and returns which of them enter the tree's root
    /// box. The same inverse and root test as a single ray's
    /// (`PreparedRay::new`, `slab1`), eight rays at a time; lanes without a
    /// ray are laid out too and left out by the caller.
    #[inline(always)]
    fn prepare_group<S: Simd>(&mut self, simd: S, g: usize, bvh: &crate::render::accel::bvh::Bvh) -> u8 {
        let lanes = 8 * g..8 * g + 8;
        let rays = &self.rays[lanes.clone()];
        let mut columns = [[0.0f32; 8]; 6];
        for (k, ray) in rays.iter().enumerate() {
            for a in 0..3 {
                columns[a][k] = ray.origin[a];
                columns[3 + a][k] = ray.dir[a];
            }
        }
        let t_max = f32x8::from_slice(simd, &self.t_max[lanes.clone()]);
        let (one, huge) = (f32x8::splat(simd, 1.0), f32x8::splat(simd, f32::MAX));
        let mut origin = [one; 3];
        let mut inv = [one; 3];
        for a in 0..3 {
            origin[a] = f32x8::simd_from(simd, columns[a]);
            let dir = f32x8::simd_from(simd, columns[3 + a]);
            // A zero (or denormal) component gets a huge finite inverse, as
            // in `PreparedRay::new`.
            let raw = one / dir;
            inv[a] = raw.is_finite().select(raw, huge.copysign(dir));
            self.origin[a].0[lanes.clone()].copy_from_slice(&columns[a]);
            self.dir[a].0[lanes.clone()].copy_from_slice(&columns[3 + a]);
            inv[a].store_slice(&mut self.inv[a].0[lanes.clone()]);
        }
        self.best_t.0[lanes.clone()].copy_from_slice(&self.t_max[lanes.clone()]);
        self.limit[lanes.clone()].copy_from_slice(&self.t_max[lanes]);
        if bvh.prims.is_empty() {
            return 0;
        }
        // The root box against the eight rays: `slab_test8`'s entry and exit
        // are `slab1`'s (scaling by the widening factor commutes with max and
        // min), so each ray enters the root exactly when it would alone.
        let (min, max) = (bvh.root_bounds.min, bvh.root_bounds.max);
        let planes = [f32x8::splat(simd, min.x), f32x8::splat(simd, max.x), f32x8::splat(simd, min.y), f32x8::splat(simd, max.y), f32x8::splat(simd, min.z), f32x8::splat(simd, max.z)];
        mask_bits(slab_test8(&planes, &origin, &inv, t_max).0)
    }

    pub fn new() -> Box<Packet> {
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let zero = Lanes([0.0; P]);
        Box::new(Packet {
            rays: [ray; P],
            t_max: [0.0; P],
            origin: [zero; 3],
            dir: [zero; 3],
            inv: [zero; 3],
            best_t: zero,
            limit: [0.0; P],
            best_id: [PrimitiveId::NONE; P],
            bary: [zero; 2],
        })
    }

    /// How many of the rays in `valid` hit something.
    pub fn hit_count(&self, valid: u64) -> u32 {
        (0..P).filter(|&i| valid & 1 << i != 0 && !self.best_id[i].is_none()).count() as u32
    }

    /// After `occluded_packet`: what blocks lane `i`, as `occluder` reports it.
    #[inline]
    pub fn occluder(&self, i: usize) -> Option<Occluder> {
        let id = self.best_id[i];
        (!id.is_none()).then(|| Occluder::new(id, self.best_t.0[i]))
    }

    /// The hit of lane `i` after `closest_packet`, as `closest` returns it.
    #[inline]
    pub fn hit(&self, query: &BvhQuery, i: usize) -> Option<SurfaceHit> {
        let id = self.best_id[i];
        if id.is_none() {
            return None;
        }
        let (b1, b2) = self.weights(i);
        Some(crate::render::accel::surface::primitive_hit(&query.prepared.scene, id, self.best_t.0[i], b1, b2, &self.rays[i]))
    }

    /// The hit of lane `i` after `closest_packet` or `closest_hybrid`, as
    /// `closest_for_batch` returns it.
    #[inline]
    pub fn batch_hit(&self, query: &BvhQuery, i: usize) -> Option<BatchHit> {
        let best = self.best(i);
        (!best.id.is_none()).then(|| query.batch_hit(&best, &self.rays[i]))
    }

    /// `batch_hit` of lane `i` when it found a triangle (what nearly every
    /// hit is), inlined into the caller: the enum of both kinds, joined
    /// from its two branches, went through memory, written a float at a
    /// time and read back in wider loads, which wait for those writes.
    #[inline(always)]
    pub fn triangle_hit_input(&self, i: usize) -> Option<TriangleHitInput> {
        let id = self.best_id[i];
        (id.kind() == PrimitiveKind::Triangle && !id.is_none()).then(|| TriangleHitInput::new(id.index(), self.weights(i), self.best_t.0[i], self.rays[i].dir))
    }

    /// Lane `i`'s closest hit so far, as a single ray's walk keeps it.
    #[inline(always)]
    fn best(&self, i: usize) -> BestHit {
        BestHit { t: self.best_t.0[i], limit: self.limit[i], id: self.best_id[i], bary: self.weights(i) }
    }

    /// Lane `i` takes `best` as its closest hit so far.
    #[inline(always)]
    fn set_best(&mut self, i: usize, best: &BestHit) {
        (self.best_t.0[i], self.limit[i], self.best_id[i]) = (best.t, best.limit, best.id);
        (self.bary[0].0[i], self.bary[1].0[i]) = best.bary;
    }

    /// Lane `i`'s hit weights (second and third corners).
    #[inline(always)]
    pub(crate) fn weights(&self, i: usize) -> (f32, f32) {
        (self.bary[0].0[i], self.bary[1].0[i])
    }

    /// `hit` of every lane in `valid`, written into `out`: triangle hits
    /// are built eight at a time (`Scene::triangle_hits`), the others one
    /// by one.
    pub fn hits_into(&self, query: &BvhQuery, valid: u64, out: &mut [Option<SurfaceHit>; P]) {
        let scene = &query.prepared.scene;
        let mut inputs = [TriangleHitInput::default(); HIT_LANES];
        let mut lanes = [0usize; HIT_LANES];
        let mut n = 0;
        let mut built = HitLanes::new();
        let mut build = |inputs: &[TriangleHitInput], lanes: &[usize], out: &mut [Option<SurfaceHit>; P]| {
            scene.triangle_hits(inputs, &mut built);
            for (k, &lane) in lanes.iter().enumerate() {
                out[lane] = Some(built.get(k));
            }
        };
        let mut m = valid;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            let id = self.best_id[i];
            if id.is_none() {
                out[i] = None;
            } else if id.kind() == PrimitiveKind::Triangle {
                inputs[n] = TriangleHitInput::new(id.index(), self.weights(i), self.best_t.0[i], self.rays[i].dir);
                lanes[n] = i;
                n += 1;
                if n == HIT_LANES {
                    build(&inputs, &lanes, out);
                    n = 0;
                }
            } else {
                out[i] = self.hit(query, i);
            }
        }
        build(&inputs[..n], &lanes[..n], out);
    }
}

/// The ranges of the packet's origins and inverse directions, per axis: a
/// box test on them (interval arithmetic) bounds every ray's own box test.
/// Floating-point operations are monotone, so the bounds hold for the
/// computed values too, not only the exact ones.
struct PacketBounds {
    o_lo: [f32; 3],
    o_hi: [f32; 3],
    inv_lo: [f32; 3],
    inv_hi: [f32; 3],
}

impl PacketBounds {
    /// The bounds over the lanes of `mask`, eight lanes at a time.
    #[inline(always)]
    fn new<S: Simd>(simd: S, pk: &Packet, mask: u64) -> PacketBounds {
        let (inf, neg_inf) = (f32x8::splat(simd, f32::INFINITY), f32x8::splat(simd, f32::NEG_INFINITY));
        let mut lo = [inf; 6];
        let mut hi = [neg_inf; 6];
        for g in 0..P / 8 {
            let gmask = (mask >> (8 * g)) as u8;
            if gmask == 0 {
                continue;
            }
            let active = mask_from_bits(simd, gmask);
            for a in 0..3 {
                for (k, lanes) in [(a, &pk.origin[a]), (3 + a, &pk.inv[a])] {
                    let v = f32x8::from_slice(simd, &lanes.0[8 * g..8 * g + 8]);
                    lo[k] = lo[k].min(active.select(v, inf));
                    hi[k] = hi[k].max(active.select(v, neg_inf));
                }
            }
        }
        let (lo, hi) = (lo.map(horizontal_min), hi.map(horizontal_max));
        PacketBounds { o_lo: [lo[0], lo[1], lo[2]], o_hi: [hi[0], hi[1], hi[2]], inv_lo: [lo[3], lo[4], lo[5]], inv_hi: [hi[3], hi[4], hi[5]] }
    }

    /// The children of `node` (bit mask) that some ray of the packet, with
    /// far end at most `far_max`, may meet: a superset of every ray's own
    /// slab test's mask. NaNs never cull. Also, when `CERTAIN`, the
    /// children that every ray of the packet meets, each ray's far end
    /// being at least `far_min` (a subset of the rays' own masks' common
    /// part: NaNs never certify), and below each child's lane a bound
    /// under every ray's entry into it.
    #[inline(always)]
    fn children_bounds<S: Simd, const CERTAIN: bool>(&self, simd: S, node: &Node8, far_max: f32, far_min: f32) -> (u32, u32, f32x8<S>) {
        let mut entry = f32x8::splat(simd, 0.0);
        let mut exit = f32x8::splat(simd, f32::INFINITY);
        // Bounds above every ray's entry and below every ray's exit: a
        // ray's entry along an axis is the lesser of its two plane
        // distances, so at most the lesser of their upper bounds; its exit
        // the greater, so at least the greater of their lower bounds.
        let mut entry_hi = f32x8::splat(simd, 0.0);
        let mut exit_lo = f32x8::splat(simd, f32::INFINITY);
        for a in 0..3 {
            let (p0, p1) = (f32x8::from_slice(simd, &node.planes[2 * a]), f32x8::from_slice(simd, &node.planes[2 * a + 1]));
            let (il, ih) = (f32x8::splat(simd, self.inv_lo[a]), f32x8::splat(simd, self.inv_hi[a]));
            let (ol, oh) = (f32x8::splat(simd, self.o_lo[a]), f32x8::splat(simd, self.o_hi[a]));
            let (a0l, a0h) = (p0 - oh, p0 - ol);
            let (a1l, a1h) = (p1 - oh, p1 - ol);
            let (q0, q1, q2, q3) = (a0l * il, a0l * ih, a0h * il, a0h * ih);
            let (r0, r1, r2, r3) = (a1l * il, a1l * ih, a1h * il, a1h * ih);
            let (q_lo, q_hi) = (q0.min(q1).min(q2.min(q3)), q0.max(q1).max(q2.max(q3)));
            let (r_lo, r_hi) = (r0.min(r1).min(r2.min(r3)), r0.max(r1).max(r2.max(r3)));
            entry = entry.max(q_lo.min(r_lo));
            exit = exit.min(q_hi.max(r_hi));
            if CERTAIN {
                entry_hi = entry_hi.max(q_hi.min(r_hi));
                exit_lo = exit_lo.min(q_lo.max(r_lo));
            }
        }
        let entry = entry * (1.0 - SLAB_WIDEN);
        let exit = (exit * (1.0 + SLAB_WIDEN)).min(far_max);
        // Culled only where entry > exit is certain (false for NaN).
        let possible = !(mask_bits(entry.simd_gt(exit)) as u32) & node.valid;
        if !CERTAIN {
            return (possible, 0, entry);
        }
        let entry_hi = entry_hi * (1.0 - SLAB_WIDEN);
        let exit_lo = (exit_lo * (1.0 + SLAB_WIDEN)).min(far_min);
        // Certain only where entry_hi <= exit_lo holds (false for NaN).
        let certain = mask_bits(entry_hi.simd_le(exit_lo)) as u32 & possible;
        (possible, certain, entry)
    }

    /// Whether every bound is finite, so that no product in
    /// `children_bounds` is a NaN that a min or max would drop.
    fn finite(&self) -> bool {
        [self.o_lo, self.o_hi, self.inv_lo, self.inv_hi].iter().all(|v| v.iter().all(|x| x.is_finite()))
    }
}

impl BvhQuery<'_> {
    /// Closest hits of the packet's rays whose bit is set in `valid`. The
    /// tree must not be `deep` (the stack is fixed).
    pub fn closest_packet(&self, pk: &mut Packet, valid: u64, counts: &mut RayCounts) {
        dispatch!(simd_level(), simd => self.trace_packet::<_, false, false>(simd, pk, valid, 0, counts));
    }

    /// `closest_packet` for incoherent rays: the packet walks together
    /// while more than `switch` of its rays are in an entry, then each of
    /// those rays walks the entry's subtree alone.
    pub fn closest_hybrid(&self, pk: &mut Packet, valid: u64, switch: u32, counts: &mut RayCounts) {
        dispatch!(simd_level(), simd => self.trace_packet::<_, false, true>(simd, pk, valid, switch, counts));
    }

    /// `occluded_packet` for incoherent rays, walked together and then
    /// alone as in `closest_hybrid`.
    pub fn occluded_hybrid(&self, pk: &mut Packet, valid: u64, switch: u32, counts: &mut RayCounts) {
        dispatch!(simd_level(), simd => self.trace_packet::<_, true, true>(simd, pk, valid, switch, counts));
    }

    /// Shadow rays: for each ray in `valid`, whether `occluder` finds
    /// something (then `Packet::occluder` is some). Which occluder is
    /// reported may differ from the single-ray query's (both stop at the
    /// first found); whether there is one cannot: with the far end fixed at
    /// t_max, a ray meets exactly the leaves it meets alone.
    pub fn occluded_packet(&self, pk: &mut Packet, valid: u64, counts: &mut RayCounts) {
        dispatch!(simd_level(), simd => self.trace_packet::<_, true, false>(simd, pk, valid, 0, counts));
    }

    /// The packet traversal, compiled for the SIMD level `simd` proves.
    #[inline(always)]
    fn trace_packet<S: Simd, const ANY: bool, const HYBRID: bool>(&self, simd: S, pk: &mut Packet, valid: u64, switch: u32, counts: &mut RayCounts) {
        let bvh = &self.prepared.bvh;
        debug_assert!(!bvh.deep);
        let spheres = &self.prepared.scene.spheres;
        pk.best_id = [PrimitiveId::NONE; P];
        let mut mask = 0u64;
        for g in 0..P / 8 {
            let lanes = (valid >> (8 * g)) as u8;
            if lanes != 0 {
                mask |= ((pk.prepare_group(simd, g, bvh) & lanes) as u64) << (8 * g);
            }
        }
        if mask == 0 {
            return;
        }
        let bounds = PacketBounds::new(simd, pk, mask);
        // Coherent packets (not the hybrid's scattered rays) often lie
        // wholly inside a node's child near the root.
        let certify = !HYBRID && bounds.finite();
        let mut stack: [MaybeUninit<(u32, u64)>; STACK] = [const { MaybeUninit::uninit() }; STACK];
        let mut len = 0usize;
        let mut word = bvh.root;
        let (mut visits, mut tests) = (0u64, 0u64);
        // Shadow rays that found an occluder.
        let mut done = 0u64;
        loop {
            if ANY {
                mask &= !done;
            }
            if HYBRID && mask != 0 && mask.count_ones() <= switch {
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    if ANY {
                        if let Some(b) = self.occluder_from_at(simd, &pk.rays[i], word, pk.best_t.0[i], counts) {
                            pk.set_best(i, &b);
                            done |= 1 << i;
                        }
                    } else {
                        let b = self.closest_from_at(simd, &pk.rays[i], word, pk.best(i), counts);
                        pk.set_best(i, &b);
                    }
                }
                mask = 0;
            }
            visits += mask.count_ones() as u64;
            if mask == 0 {
                // Every ray of this entry is done.
            } else if word & LEAF_BIT == 0 {
                let node = &bvh.nodes[word as usize];
                let mut child_mask = [0u64; 8];
                let mut child_near = [f32::INFINITY; 8];
                // The groups of eight lanes with an active ray, and their lanes'
                // far ends (-inf in inactive lanes, so their box tests fail).
                // Only the first `n_groups` are written and read: not cleared
                // per node (512 bytes).
                let mut groups: [MaybeUninit<(usize, f32x8<S>)>; P / 8] = [const { MaybeUninit::uninit() }; P / 8];
                let mut n_groups = 0;
                let mut far_all = f32x8::splat(simd, f32::NEG_INFINITY);
                let mut far_least = f32x8::splat(simd, f32::INFINITY);
                let mut pending = mask;
                while pending != 0 {
                    let g = pending.trailing_zeros() as usize / 8;
                    pending &= !(0xff << (8 * g));
                    let gmask = (mask >> (8 * g)) as u8;
                    let active = mask_from_bits(simd, gmask);
                    let best = f32x8::from_slice(simd, &pk.best_t.0[8 * g..8 * g + 8]);
                    let far = active.select(best, f32x8::splat(simd, f32::NEG_INFINITY));
                    far_all = far_all.max(far);
                    if certify {
                        far_least = far_least.min(active.select(best, f32x8::splat(simd, f32::INFINITY)));
                    }
                    groups[n_groups] = MaybeUninit::new((g, far));
                    n_groups += 1;
                }
                let far_max = horizontal_max(far_all);
                // Interval test: the children no ray of the packet can meet,
                // and (coherent packets) those every active ray meets, which
                // take the whole mask without each ray's own box test.
                let (mut valid_children, certain, entry) = if certify {
                    bounds.children_bounds::<S, true>(simd, node, far_max, horizontal_min(far_least))
                } else {
                    bounds.children_bounds::<S, false>(simd, node, far_max, 0.0)
                };
                if certain != 0 {
                    let entry: [f32; 8] = entry.into();
                    let mut m = certain;
                    while m != 0 {
                        let c = m.trailing_zeros() as usize;
                        m &= m - 1;
                        child_mask[c] = mask;
                        child_near[c] = entry[c];
                    }
                    valid_children &= !certain;
                }
                while valid_children != 0 {
                    let c = valid_children.trailing_zeros() as usize;
                    valid_children &= valid_children - 1;
                    // Child c's box in every lane, against eight rays at a time.
                    let planes: [f32x8<S>; 6] = std::array::from_fn(|k| f32x8::splat(simd, node.planes[k][c]));
                    let mut near = f32x8::splat(simd, f32::INFINITY);
                    let mut bits_all = 0u64;
                    for slot in &groups[..n_groups] {
                        // SAFETY: the first `n_groups` entries were written above.
                        let (g, t_far) = unsafe { slot.assume_init() };
                        let (hit, tn) = slab_test_rays8(simd, &planes, pk, 8 * g, t_far);
                        bits_all |= (mask_bits(hit) as u64) << (8 * g);
                        near = near.min(hit.select(tn, f32x8::splat(simd, f32::INFINITY)));
                    }
                    child_mask[c] = bits_all;
                    child_near[c] = horizontal_min(near);
                }
                // Nearest child next (its nearest ray's entry); the others pushed farthest first.
                let mut order = ChildOrder::new();
                for c in 0..8 {
                    if child_mask[c] != 0 {
                        order.insert((node.child[c], child_mask[c]), child_near[c]);
                    }
                }
                if let Some((nearest, farther)) = order.nearest_and_farther() {
                    for &(entry, _) in farther {
                        stack[len] = MaybeUninit::new(entry);
                        len += 1;
                    }
                    (word, mask) = nearest;
                    continue;
                }
            } else {
                let (start, end) = leaf_range(word);
                test_leaf_packet::<S, ANY>(simd, &bvh.prims[start..end], spheres, pk, mask, &mut done, &mut tests);
            }
            if len == 0 {
                break;
            }
            len -= 1;
            // SAFETY: entries below the old `len` were written above.
            (word, mask) = unsafe { stack[len].assume_init() };
        }
        counts.nodes += visits;
        counts.tests += tests;
    }
}

/// The eight rays of lanes `start..start + 8` against one box
/// (`traverse::slab_test8`). (The box tests only prune: the padded boxes
/// and `SLAB_WIDEN` keep every true hit, so they need not match the single
/// ray's bit for bit, but they do.)
#[inline(always)]
fn slab_test_rays8<S: Simd>(simd: S, p: &[f32x8<S>; 6], pk: &Packet, start: usize, t_far: f32x8<S>) -> (mask32x8<S>, f32x8<S>) {
    let lanes = start..start + 8;
    let origin = [
        f32x8::from_slice(simd, &pk.origin[0].0[lanes.clone()]),
        f32x8::from_slice(simd, &pk.origin[1].0[lanes.clone()]),
        f32x8::from_slice(simd, &pk.origin[2].0[lanes.clone()]),
    ];
    let inv = [
        f32x8::from_slice(simd, &pk.inv[0].0[lanes.clone()]),
        f32x8::from_slice(simd, &pk.inv[1].0[lanes.clone()]),
        f32x8::from_slice(simd, &pk.inv[2].0[lanes]),
    ];
    slab_test8(p, &origin, &inv, t_far)
}

/// The least lane of `v`: the lanes' halves compared pairwise, then the
/// quarters, then the last two, each step taking `a < b ? a : b` as the
/// SIMD minimum does (so the answer is `reduce_min`'s, bit for bit). Written
/// out on the lanes because `reduce_min` is not inlined into the
/// traversal: three calls per child box. (With a NaN lane the answer is
/// unspecified; the traversal's lanes hold none: far ends are finite or
/// infinite, entries of boxes hit are not NaN, and a bound taken over a
/// NaN only culls less.)
#[inline(always)]
fn horizontal_min<S: Simd>(v: f32x8<S>) -> f32 {
    reduce_lanes(v.into(), |a, b| if a < b { a } else { b })
}

/// The greatest lane of `v` (as `horizontal_min`, with `a > b ? a : b`).
#[inline(always)]
fn horizontal_max<S: Simd>(v: f32x8<S>) -> f32 {
    reduce_lanes(v.into(), |a, b| if a > b { a } else { b })
}

/// `pick` over eight lanes in `reduce_min`'s order: halves, quarters, pair.
#[inline(always)]
fn reduce_lanes(l: [f32; 8], pick: impl Fn(f32, f32) -> f32) -> f32 {
    let h = [pick(l[0], l[4]), pick(l[1], l[5]), pick(l[2], l[6]), pick(l[3], l[7])];
    pick(pick(h[0], h[2]), pick(h[1], h[3]))
}

/// The leaf loop of `traverse::test_leaf` for the rays of `mask`, each
/// triangle tested against eight rays at a time (`intersect_triangle_lanes`,
/// the single test's arithmetic lane by lane) with each lane's own limit,
/// and the same tie rule applied per ray in the same primitive order: every
/// ray ends with the hit it finds alone. Spheres are tested ray by ray.
/// With `ANY`, a ray stops at its first hit (its bit set in `done`).
#[inline(always)]
fn test_leaf_packet<S: Simd, const ANY: bool>(
    simd: S,
    prims: &[(TriangleEdges, PrimitiveId)],
    spheres: &[Sphere],
    pk: &mut Packet,
    mask: u64,
    done: &mut u64,
    tests: &mut u64,
) {
    let mut active = mask;
    for prim in prims {
        let (tri, id) = (&prim.0, prim.1);
        *tests += active.count_ones() as u64;
        if id.is_sphere() {
            let mut m = active;
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
                let mut best = pk.best(i);
                let mut sphere_tests = 0;
                if test_leaf::<ANY, _>(std::slice::from_ref(prim), spheres, &pk.rays[i], false, &mut best, &mut sphere_tests, &mut NoRecord) {
                    *done |= 1 << i;
                    active &= !(1 << i);
                }
                pk.set_best(i, &best);
            }
            continue;
        }
        let mut groups = active;
        while groups != 0 {
            let g = groups.trailing_zeros() as usize / 8;
            groups &= !(0xff << (8 * g));
            let lanes = (active >> (8 * g)) as u8;
            let base = 8 * g;
            let origin = V3::load(simd, [&pk.origin[0].0, &pk.origin[1].0, &pk.origin[2].0], base);
            let dir = V3::load(simd, [&pk.dir[0].0, &pk.dir[1].0, &pk.dir[2].0], base);
            let limit = f32x8::from_slice(simd, &pk.limit[base..base + 8]);
            let (hit, t, b1, b2) = intersect_triangle_lanes(origin, dir, tri, limit);
            let found = mask_bits(hit) & lanes;
            if found == 0 {
                continue;
            }
            // Every lane's update at once (each lane is its own ray): as
            // `test_leaf`, t <= best here, and the hit is taken when nearer
            // or, on a tie, when its id is lower; a shadow ray takes its
            // first and is done.
            let ids: &mut [u32] = bytemuck::cast_slice_mut(&mut pk.best_id[base..base + 8]);
            let old_id = u32x8::from_slice(simd, ids);
            let new_id = u32x8::splat(simd, bytemuck::cast(id));
            let best = f32x8::from_slice(simd, &pk.best_t.0[base..base + 8]);
            let take = if ANY {
                mask_from_bits(simd, found)
            } else {
                let nearer = t.simd_lt(best) | new_id.simd_lt(old_id);
                nearer & mask_from_bits(simd, found)
            };
            take.select(t, best).store_slice(&mut pk.best_t.0[base..base + 8]);
            take.select(new_id, old_id).store_slice(ids);
            for (w, lanes) in [b1, b2].into_iter().zip(&mut pk.bary) {
                let slot = &mut lanes.0[base..base + 8];
                take.select(w, f32x8::from_slice(simd, slot)).store_slice(slot);
            }
            if ANY {
                *done |= (found as u64) << base;
                active &= !((found as u64) << base);
            } else {
                // Just above the new best, so that a tie can still be won.
                let above: f32x8<S> = (t.bitcast::<u32x8<S>>() + 1).bitcast();
                let limit = &mut pk.limit[base..base + 8];
                take.select(above, f32x8::from_slice(simd, limit)).store_slice(limit);
            }
        }
    }
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;
    use crate::render::inspect::pixel_record::NoRecord;
    use crate::render::{PreparedScene, SceneQuery};
    use crate::scene::builtin;

    /// Every lane's hit is bit for bit the single-ray hit, on every builtin
    /// scene, with tiles cut by the image edges and off-centre samples.
    #[test]
    fn packets_find_the_single_ray_hits() {
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            // Frames of scenes with CSG objects cast single rays (`cast_pass_packets`).
            if prepared.bvh.deep || !prepared.scene.csgs.is_empty() {
                continue;
            }
            let (w, h) = (61u32, 37u32);
            let view = prepared.scene.camera.view(w, h);
            let query = BvhQuery::new(&prepared);
            let mut pk = Packet::new();
            let key = |h: &Option<SurfaceHit>| h.as_ref().map(|h| (h.kind, h.primitive, h.t.to_bits(), h.barycentric.to_array().map(f32::to_bits)));
            for offset in [Vec2::splat(0.5), Vec2::new(0.125, 0.875)] {
                for y0 in (0..h as usize).step_by(TILE_H) {
                    for x0 in (0..w as usize).step_by(TILE_W) {
                        let mut valid = 0u64;
                        for i in 0..P {
                            let (x, y) = (x0 + lane_xy(i).0, y0 + lane_xy(i).1);
                            if x < w as usize && y < h as usize {
                                let p = Vec2::new(x as f32, y as f32) + offset;
                                pk.rays[i] = view.eye_ray(p.x, p.y);
                                pk.t_max[i] = view.far_t(p.x, p.y);
                                valid |= 1 << i;
                            }
                        }
                        query.closest_packet(&mut pk, valid, &mut RayCounts::default());
                        for i in (0..P).filter(|i| valid & 1 << i != 0) {
                            let single = query.closest(&pk.rays[i], pk.t_max[i], false, &mut RayCounts::default(), &mut NoRecord);
                            assert_eq!(key(&pk.hit(&query, i)), key(&single), "{name}: tile ({x0}, {y0}) lane {i}");
                        }
                    }
                }
            }
        }
    }

    /// A child that the interval test proves entered by every ray of a
    /// packet is entered by each of them in its own box test, and every
    /// child a ray enters is one the test leaves possible: eye packets of
    /// every built-in scene, against every node of its tree, with far
    /// ends at the eye rays' limits and cut short to half of them.
    #[test]
    fn children_proved_entered_are_entered_by_every_ray() {
        let proved = dispatch!(simd_level(), simd => check_proofs(simd));
        // The proof is not vacuous: eye packets lie inside many boxes.
        assert!(proved > 100, "only {proved} children proved entered");
    }

    fn check_proofs<S: Simd>(simd: S) -> usize {
        let mut proved = 0;
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            let bvh = &prepared.bvh;
            if bvh.deep || bvh.root & LEAF_BIT != 0 {
                continue;
            }
            // The nodes of the tree's top four levels, where packets lie
            // wholly inside boxes.
            let mut nodes = vec![bvh.root];
            let mut level = vec![bvh.root];
            for _ in 0..3 {
                level = level.iter().flat_map(|&n| bvh.nodes[n as usize].child.iter().zip(0..8).filter(move |&(&c, k)| bvh.nodes[n as usize].valid & 1 << k != 0 && c & LEAF_BIT == 0).map(|(&c, _)| c)).collect();
                nodes.extend(&level);
            }
            // Benchmark-sized pixels, every fifth tile of them.
            let (w, h) = (640u32, 400u32);
            let view = prepared.scene.camera.view(w, h);
            let mut pk = Packet::new();
            for (y0, x0) in (0..h as usize).step_by(5 * TILE_H).flat_map(|y| (0..w as usize).step_by(5 * TILE_W).map(move |x| (y, x))) {
                for i in 0..P {
                    let (x, y) = ((x0 + lane_xy(i).0) as f32 + 0.5, (y0 + lane_xy(i).1) as f32 + 0.5);
                    pk.rays[i] = view.eye_ray(x, y);
                    pk.t_max[i] = view.far_t(x, y);
                }
                for g in 0..P / 8 {
                    pk.prepare_group(simd, g, bvh);
                }
                for shorten in [1.0f32, 0.5] {
                    let far: Vec<f32> = (0..P).map(|i| pk.best_t.0[i] * shorten).collect();
                    let bounds = PacketBounds::new(simd, &pk, u64::MAX);
                    assert!(bounds.finite(), "{name}");
                    let (far_min, far_max) = (far.iter().copied().fold(f32::INFINITY, f32::min), far.iter().copied().fold(0.0, f32::max));
                    for node in nodes.iter().map(|&n| &bvh.nodes[n as usize]) {
                        let (possible, certain, _) = bounds.children_bounds::<S, true>(simd, node, far_max, far_min);
                        for c in 0..8 {
                            let planes: [f32x8<S>; 6] = std::array::from_fn(|k| f32x8::splat(simd, node.planes[k][c]));
                            let mut entered = 0u64;
                            for g in 0..P / 8 {
                                let t_far = f32x8::from_slice(simd, &far[8 * g..8 * g + 8]);
                                entered |= (mask_bits(slab_test_rays8(simd, &planes, &pk, 8 * g, t_far).0) as u64) << (8 * g);
                            }
                            if node.valid & 1 << c != 0 && entered != 0 {
                                assert!(possible & 1 << c != 0, "{name}: a child entered but culled");
                            }
                            if certain & 1 << c != 0 {
                                assert_eq!(entered, u64::MAX, "{name}: a child proved entered by all, missed by some");
                                proved += 1;
                            }
                        }
                    }
                }
            }
        }
        proved
    }

    /// Incoherent rays (bounces: from each eye hit of a small image, one
    /// random direction off the surface) in packets, walked together and
    /// then alone from every switch point (`closest_hybrid`, from never to
    /// always alone), find what each ray finds alone, bit for bit; as
    /// shadow rays (`occluded_hybrid`), whether something blocks them.
    #[test]
    fn hybrid_packets_find_the_single_ray_hits() {
        use crate::render::transport::sampling::{cosine_hemisphere, from_local, SampleRng};
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            if prepared.bvh.deep || !prepared.scene.csgs.is_empty() || prepared.instances.is_some() {
                continue;
            }
            let (w, h) = (29u32, 23u32);
            let view = prepared.scene.camera.view(w, h);
            let query = BvhQuery::new(&prepared);
            let mut rays = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                    if let Some(hit) = query.closest(&view.eye_ray(px, py), view.far_t(px, py), false, &mut RayCounts::default(), &mut NoRecord) {
                        let mut rng = SampleRng::for_index(7, (x + y * w) as u64, 0);
                        rays.push(hit.spawn_ray_front(from_local(cosine_hemisphere(rng.next_2d()), hit.geometric_normal), 1e-4));
                    }
                }
            }
            let key = |h: Option<BatchHit>| {
                h.map(|h| match h {
                    BatchHit::Triangle(t) => (0, t.index, t.t.to_bits(), t.b.to_array().map(f32::to_bits)),
                    BatchHit::Record(r) => (1, r.primitive, r.t.to_bits(), r.barycentric.to_array().map(f32::to_bits)),
                })
            };
            let mut pk = Packet::new();
            for switch in [0, 1, 4, 12, 64] {
                for chunk in rays.chunks(P) {
                    for (k, ray) in chunk.iter().enumerate() {
                        pk.rays[k] = *ray;
                        pk.t_max[k] = f32::INFINITY;
                    }
                    let valid = u64::MAX >> (64 - chunk.len());
                    query.closest_hybrid(&mut pk, valid, switch, &mut RayCounts::default());
                    for (k, ray) in chunk.iter().enumerate() {
                        let single = query.closest_for_batch(ray, f32::INFINITY, false, &mut RayCounts::default());
                        assert_eq!(key(pk.batch_hit(&query, k)), key(single), "{name}: switch {switch}, ray {k}");
                        // The triangle-only shortcut is `batch_hit` where that names a triangle.
                        let triangle = pk.triangle_hit_input(k).map(BatchHit::Triangle);
                        let expected = pk.batch_hit(&query, k).filter(|h| matches!(h, BatchHit::Triangle(_)));
                        assert_eq!(key(triangle), key(expected), "{name}: triangle input, switch {switch}, ray {k}");
                    }
                    // As shadow rays, with far ends that cut some of them
                    // short of what they hit.
                    for (k, ray) in chunk.iter().enumerate() {
                        pk.rays[k] = *ray;
                        pk.t_max[k] = [0.05, 0.5, 5.0][k % 3];
                    }
                    query.occluded_hybrid(&mut pk, valid, switch, &mut RayCounts::default());
                    for (k, ray) in chunk.iter().enumerate() {
                        let single = query.occluder(ray, pk.t_max[k], &mut RayCounts::default(), &mut NoRecord);
                        assert_eq!(pk.occluder(k).is_some(), single.is_some(), "{name}: shadow, switch {switch}, ray {k}");
                    }
                }
            }
        }
    }
}
