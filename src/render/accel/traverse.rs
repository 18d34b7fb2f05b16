//! The BVH traversal kernels that single rays (`bvh.rs`) and packets
//! (`packet.rs`) share: the slab test, the order children are visited in and
//! the leaf loop with its tie rule. Written once so both traversals find the
//! same hits; `#[inline(always)]` because they are the hot loops.

use crate::render::accel::intersect::{intersect_sphere, intersect_triangle, intersect_triangles_lanes, TriangleEdges, TriangleLanes};
use crate::math::lanes::{self, mask_bits, transpose8, V3};
use crate::math::Ray;
use crate::render::inspect::pixel_record::{PrimitiveTest, Recorder};
use crate::scene::{PrimitiveId, PrimitiveKind, Sphere};
use fearless_simd::{f32x8, mask32x8, Simd, SimdBase, SimdFrom};
use glam::{BVec4A, Vec3, Vec3A, Vec4};

/// The slab test's far distance is stretched by this factor (and the near
/// one shrunk) to absorb its rounding and that of the primitive tests.
pub const SLAB_WIDEN: f32 = 1.0e-5;

/// Four slab tests at once, lane by lane: ray `origin + t / inv` against the
/// box with planes (min x, max x, min y, max y, min z, max z), within
/// [0, t_far]: four of a node's boxes and one ray (`PreparedRay::slab8`,
/// a half at a time). Returns which lanes meet their box and where they
/// enter it.
#[inline(always)]
pub fn slab_test(planes: &[Vec4; 6], origin: &[Vec4; 3], inv: &[Vec4; 3], t_far: Vec4) -> (BVec4A, Vec4) {
    let p = planes;
    let (x0, x1) = ((p[0] - origin[0]) * inv[0], (p[1] - origin[0]) * inv[0]);
    let (y0, y1) = ((p[2] - origin[1]) * inv[1], (p[3] - origin[1]) * inv[1]);
    let (z0, z1) = ((p[4] - origin[2]) * inv[2], (p[5] - origin[2]) * inv[2]);
    let tn = x0.min(x1).max(y0.min(y1)).max(z0.min(z1)).max(Vec4::ZERO) * (1.0 - SLAB_WIDEN);
    let tf = (x0.max(x1).min(y0.max(y1)).min(z0.max(z1)) * (1.0 + SLAB_WIDEN)).min(t_far);
    (tn.cmple(tf), tn)
}

/// `slab_test` eight lanes wide, with the same arithmetic: eight of a
/// node's boxes against one ray (the single-ray walk), or one box against
/// eight rays (packets).
#[inline(always)]
pub fn slab_test8<S: Simd>(planes: &[f32x8<S>; 6], origin: &[f32x8<S>; 3], inv: &[f32x8<S>; 3], t_far: f32x8<S>) -> (mask32x8<S>, f32x8<S>) {
    let p = planes;
    let (x0, x1) = ((p[0] - origin[0]) * inv[0], (p[1] - origin[0]) * inv[0]);
    let (y0, y1) = ((p[2] - origin[1]) * inv[1], (p[3] - origin[1]) * inv[1]);
    let (z0, z1) = ((p[4] - origin[2]) * inv[2], (p[5] - origin[2]) * inv[2]);
    let tn = x0.min(x1).max(y0.min(y1)).max(z0.min(z1)).max(0.0) * (1.0 - SLAB_WIDEN);
    let tf = (x0.max(x1).min(y0.max(y1)).min(z0.max(z1)) * (1.0 + SLAB_WIDEN)).min(t_far);
    (tn.simd_le(tf), tn)
}

/// A ray prepared for slab tests: origin and inverse direction, each
/// component splatted over four lanes.
pub struct PreparedRay {
    pub origin: [Vec4; 3],
    pub inv: [Vec4; 3],
}

impl PreparedRay {
    #[inline(always)]
    pub fn new(ray: &Ray) -> PreparedRay {
        // A zero (or denormal) component gets a huge finite inverse, so the
        // slab test never computes 0 * inf. (One three-lane division: every
        // single ray pays for this before its first node.)
        let dir = Vec3A::from(ray.dir);
        let inv = Vec3A::ONE / dir;
        let inv = Vec3A::select(inv.is_finite_mask(), inv, Vec3A::splat(f32::MAX).copysign(dir));
        PreparedRay { origin: [Vec4::splat(ray.origin.x), Vec4::splat(ray.origin.y), Vec4::splat(ray.origin.z)], inv: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)] }
    }

    /// Which of a node's eight child boxes (`planes`, slots used as in
    /// `valid`) the ray meets within [0, t_far], as a bit mask, and where
    /// it enters each: `slab_test` on each half of the node. (The hot walk
    /// uses `slab_test8`, the same arithmetic in eight lanes.)
    #[inline(always)]
    pub fn slab8(&self, planes: &[[f32; 8]; 6], valid: u32, t_far: f32) -> (u32, [f32; 8]) {
        let mut mask = 0;
        let mut t_enter = [0.0; 8];
        for half in 0..2 {
            let lanes = 4 * half..4 * half + 4;
            let p = [0, 1, 2, 3, 4, 5].map(|k| Vec4::from_slice(&planes[k][lanes.clone()]));
            let (hit, tn) = slab_test(&p, &self.origin, &self.inv, Vec4::splat(t_far));
            mask |= hit.bitmask() << (4 * half);
            t_enter[lanes].copy_from_slice(&tn.to_array());
        }
        (mask & valid, t_enter)
    }

    /// The slab test for one box (the root's), the three axes in lanes:
    /// each axis's entry and exit are computed as `slab_test` does, then
    /// the latest entry (not before 0) is compared with the earliest exit
    /// (not after `t_far`).
    #[inline(always)]
    pub fn slab1(&self, min: Vec3, max: Vec3, t_far: f32) -> bool {
        let origin = Vec3A::new(self.origin[0].x, self.origin[1].x, self.origin[2].x);
        let inv = Vec3A::new(self.inv[0].x, self.inv[1].x, self.inv[2].x);
        let (a, b) = ((Vec3A::from(min) - origin) * inv, (Vec3A::from(max) - origin) * inv);
        let enter = (a.min(b) * (1.0 - SLAB_WIDEN)).max_element().max(0.0);
        let leave = (a.max(b) * (1.0 + SLAB_WIDEN)).min_element().min(t_far);
        enter <= leave
    }
}

/// The children of a node a traversal enters, ordered so that it continues
/// with the nearest and pushes the others farthest first (they then pop
/// nearest first). Insertion sort by descending entry distance; of equal
/// distances the one added last comes out as the nearer.
pub struct ChildOrder<T> {
    /// Room for a node's eight children.
    items: [(T, f32); 8],
    len: usize,
}

impl<T: Copy + Default> Default for ChildOrder<T> {
    #[inline(always)]
    fn default() -> ChildOrder<T> {
        ChildOrder::new()
    }
}

impl<T: Copy + Default> ChildOrder<T> {
    #[inline(always)]
    pub fn new() -> ChildOrder<T> {
        ChildOrder { items: [(T::default(), 0.0); 8], len: 0 }
    }

    /// Adds a child the ray (or packet) enters at `t_enter`.
    #[inline(always)]
    pub fn insert(&mut self, child: T, t_enter: f32) {
        let mut j = self.len;
        while j > 0 && self.items[j - 1].1 < t_enter {
            self.items[j] = self.items[j - 1];
            j -= 1;
        }
        self.items[j] = (child, t_enter);
        self.len += 1;
    }

    /// The child to visit next, and the others farthest first (to push in
    /// this order); `None` when no child was added.
    #[inline(always)]
    pub fn nearest_and_farther(&self) -> Option<(T, &[(T, f32)])> {
        self.items[..self.len].split_last().map(|(nearest, farther)| (nearest.0, farther))
    }
}

/// The best hit found so far along one ray.
#[derive(Clone, Copy, Debug)]
pub struct BestHit {
    /// Its ray parameter (t_max until something is hit): the far end of the
    /// box tests.
    pub t: f32,
    /// Primitive tests accept t < limit: t_max, then just above `t` once
    /// something is hit, so an equal-t hit on an earlier primitive can still
    /// win the tie.
    pub limit: f32,
    /// `PrimitiveId::NONE` until something is hit.
    pub id: PrimitiveId,
    /// A triangle hit's barycentric weights of v1 and v2.
    pub bary: (f32, f32),
}

impl BestHit {
    #[inline(always)]
    pub fn nothing_before(t_max: f32) -> BestHit {
        BestHit { t: t_max, limit: t_max, id: PrimitiveId::NONE, bary: (0.0, 0.0) }
    }
}

/// Tests `ray` against the primitives of one leaf, counting each test in
/// `tests` and reporting it to `rec`. With `ANY` it stops at the first hit,
/// stores it in `best` and returns true. Otherwise `best` keeps the nearest
/// hit; on equal t the lower id (scene order) wins, as brute force's strict
/// `t < best_t` scan decides, so the order in which leaves are visited
/// cannot change which primitive wins. `inside` lets a refracted ray hit the
/// sphere it travels in from inside.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn test_leaf<const ANY: bool, R: Recorder>(
    prims: &[(TriangleEdges, PrimitiveId)],
    spheres: &[Sphere],
    ray: &Ray,
    inside: bool,
    best: &mut BestHit,
    tests: &mut u64,
    rec: &mut R,
) -> bool {
    for (tri, id) in prims {
        let id = *id;
        *tests += 1;
        let found = if !id.is_sphere() {
            let outcome = intersect_triangle(ray, tri, best.limit);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Triangle, index: id.index(), outcome });
            }
            outcome.ok()
        } else {
            let outcome = intersect_sphere(ray, &spheres[id.index() as usize], best.limit, inside);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Sphere, index: id.index(), outcome: outcome.map(|t| (t, 0.0, 0.0)) });
            }
            outcome.ok().map(|t| (t, 0.0, 0.0))
        };
        if let Some((t, b1, b2)) = found {
            if ANY {
                best.t = t;
                best.id = id;
                best.bary = (b1, b2);
                return true;
            }
            // t <= best.t here; on a tie the lower id (scene order) wins.
            if t < best.t || id < best.id {
                best.t = t;
                best.id = id;
                best.bary = (b1, b2);
                best.limit = f32::from_bits(t.to_bits() + 1);
            }
        }
    }
    false
}

/// The triangles of a leaf of two to eight (`prims`, no spheres) in
/// eight lanes; lanes past them repeat the first (their results are
/// dropped). Each triangle's first eight floats are read as a row and the
/// rows transposed, the last two copied one by one.
#[inline(always)]
fn gather_triangles<S: Simd>(simd: S, prims: &[(TriangleEdges, PrimitiveId)]) -> TriangleLanes<f32x8<S>> {
    let n = prims.len();
    let zero = f32x8::splat(simd, 0.0);
    let mut rows = [zero; 8];
    let (mut e2z, mut bound) = ([0.0f32; 8], [0.0f32; 8]);
    for k in 0..8 {
        let floats = prims[if k < n { k } else { 0 }].0.as_floats();
        rows[k] = f32x8::from_slice(simd, &floats[..8]);
        (e2z[k], bound[k]) = (floats[8], floats[9]);
    }
    let c = transpose8(rows);
    let (one, bound) = (f32x8::splat(simd, 1.0), f32x8::simd_from(simd, bound));
    TriangleLanes {
        v0: V3::new(c[0], c[1], c[2]),
        e1: V3::new(c[3], c[4], c[5]),
        e2: V3::new(c[6], c[7], f32x8::simd_from(simd, e2z)),
        // `det_epsilon()` and `two_sided()` of each: the bound's magnitude
        // and its sign bit (set on -0.0 too).
        epsilon: lanes::Lane::copysign(bound, one),
        two_sided: lanes::Lane::lt(lanes::Lane::copysign(one, bound), zero),
    }
}

/// `test_leaf` (closest hit) for a leaf of two to eight triangles (no
/// spheres), nothing recorded: the ray (`origin`, `dir` in every lane)
/// against all of them at once (`intersect_triangles_lanes`, the single
/// test's arithmetic lane by lane), then the hits taken in primitive order
/// with `test_leaf`'s limit and tie rule. It finds what `test_leaf` finds
/// and counts the tests it counts. (Shadow rays keep the loop, which stops
/// at the first hit: testing all of a leaf at once made the rasterized
/// teapot's shadow rays 13% slower.)
#[inline(always)]
pub fn test_triangle_leaf<S: Simd>(simd: S, prims: &[(TriangleEdges, PrimitiveId)], origin: V3<f32x8<S>>, dir: V3<f32x8<S>>, best: &mut BestHit, tests: &mut u64) {
    let n = prims.len();
    debug_assert!((2..=8).contains(&n));
    *tests += n as u64;
    let triangles = gather_triangles(simd, prims);
    let (hit, t, b1, b2) = intersect_triangles_lanes(origin, dir, &triangles, f32x8::splat(simd, best.limit));
    let mut found = mask_bits(hit) as u32 & ((1u32 << n) - 1);
    if found == 0 {
        return;
    }
    let (t, b1, b2): ([f32; 8], [f32; 8], [f32; 8]) = (t.into(), b1.into(), b2.into());
    while found != 0 {
        let k = found.trailing_zeros() as usize;
        found &= found - 1;
        // The single test meets the limit as the leaf's earlier hits left
        // it (lower than or equal to the one the lanes were tested with).
        if !(t[k] < best.limit) {
            continue;
        }
        let id = prims[k].1;
        if t[k] < best.t || id < best.id {
            (best.t, best.id, best.bary) = (t[k], id, (b1[k], b2[k]));
            best.limit = f32::from_bits(t[k].to_bits() + 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::inspect::pixel_record::NoRecord;

    #[test]
    fn slab_test_by_hand() {
        // Four unit boxes along +x at 1, 3, 5 and 7; a ray along +x from the origin.
        // ... and four more at 9 to 15, the last of them off the axis.
        let planes = [
            [1.0, 3.0, 5.0, 7.0, 9.0, 11.0, 13.0, 15.0],
            [2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0],
            [-0.5; 8],
            [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, -0.1],
            [-0.5; 8],
            [0.5; 8],
        ];
        let ray = PreparedRay::new(&Ray::new(Vec3::ZERO, Vec3::X));
        let (mask, tn) = ray.slab8(&planes, 0xff, 5.5);
        assert_eq!(mask, 0b0111, "boxes entered before t = 5.5");
        assert_eq!(tn[0], 1.0 * (1.0 - SLAB_WIDEN));
        assert_eq!(tn[2], 5.0 * (1.0 - SLAB_WIDEN));
        assert_eq!(ray.slab8(&planes, 0xff, 100.0).0, 0b0111_1111, "the box off the axis is missed");
        assert_eq!(ray.slab8(&planes, 0b0101_0101, 100.0).0, 0b0101_0101, "unused slots never hit");
        assert_eq!(ray.slab8(&planes, 0xff, 100.0).1[5], 11.0 * (1.0 - SLAB_WIDEN));
        assert!(ray.slab1(Vec3::new(1.0, -0.5, -0.5), Vec3::new(2.0, 0.5, 0.5), 1.5));
        assert!(!ray.slab1(Vec3::new(1.0, 0.6, -0.5), Vec3::new(2.0, 1.5, 0.5), 10.0));
    }

    #[test]
    fn children_come_out_nearest_first_then_farthest_pushed_first() {
        let mut order = ChildOrder::<u32>::new();
        assert!(order.nearest_and_farther().is_none());
        for (child, t) in [(10, 3.0), (11, 1.0), (12, 2.0), (13, 4.0)] {
            order.insert(child, t);
        }
        let (nearest, farther) = order.nearest_and_farther().unwrap();
        assert_eq!(nearest, 11);
        assert_eq!(farther.iter().map(|c| c.0).collect::<Vec<_>>(), [13, 10, 12]);
        // Equal distances: the one added last is visited first.
        let mut tie = ChildOrder::<u32>::new();
        tie.insert(1, 2.0);
        tie.insert(2, 2.0);
        assert_eq!(tie.nearest_and_farther().unwrap().0, 2);
    }

    #[test]
    fn leaf_ties_go_to_the_lower_id_and_any_stops_at_the_first_hit() {
        use crate::render::accel::intersect::TriangleEdges;
        use crate::scene::Triangle;
        // The same triangle twice, listed with the higher id first, and a sphere behind it.
        let v = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let tri = Triangle { v, n: [Vec3::Z; 3], uv: [crate::math::Vec2::ZERO; 3], material: 0, object: 0, two_sided: true };
        let edges = TriangleEdges::new(&tri);
        let spheres = [Sphere { center: Vec3::new(0.0, 0.0, -3.0), radius: 1.0, material: 0, object: 0 }];
        let prims = [(edges, PrimitiveId::sphere(0)), (edges, PrimitiveId::triangle(5)), (edges, PrimitiveId::triangle(2))];
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z);
        let mut best = BestHit::nothing_before(f32::INFINITY);
        let mut tests = 0;
        assert!(!test_leaf::<false, _>(&prims, &spheres, &ray, false, &mut best, &mut tests, &mut NoRecord));
        assert_eq!((best.id, best.t, tests), (PrimitiveId::triangle(2), 1.0, 3));
        let mut any = BestHit::nothing_before(f32::INFINITY);
        assert!(test_leaf::<true, _>(&prims, &spheres, &ray, false, &mut any, &mut tests, &mut NoRecord));
        assert_eq!((any.id, any.t, tests), (PrimitiveId::sphere(0), 3.0, 4));
    }

    fn leaf_in_lanes<S: Simd>(simd: S, prims: &[(TriangleEdges, PrimitiveId)], ray: &Ray, best: &mut BestHit, tests: &mut u64) {
        let lanes = |v: Vec3| V3::new(f32x8::splat(simd, v.x), f32x8::splat(simd, v.y), f32x8::splat(simd, v.z));
        test_triangle_leaf(simd, prims, lanes(ray.origin), lanes(ray.dir), best, tests)
    }

    /// The eight-lane leaf test finds, bit for bit, what the one-by-one
    /// test finds, and counts the same tests: over random leaves of two to
    /// eight triangles (one- and two-sided, some repeated so that hits tie,
    /// some degenerate), random rays through them and random limits.
    #[test]
    fn leaf_lanes_find_what_the_leaf_loop_finds() {
        use crate::scene::Triangle;
        use fearless_simd::dispatch;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let point = |scale: f32, next: &mut dyn FnMut() -> f32| Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale;
        let (mut hits, mut leaves) = (0, 0);
        for _ in 0..3000 {
            let n = 2 + (next() * 7.0) as usize;
            let mut prims: Vec<(TriangleEdges, PrimitiveId)> = Vec::new();
            for k in 0..n {
                let edges = if k > 0 && next() < 0.2 {
                    prims[(next() * k as f32) as usize].0
                } else {
                    let v0 = point(2.0, &mut next);
                    let (a, b) = (point(2.0, &mut next), point(2.0, &mut next));
                    let v = if next() < 0.05 { [v0, v0 + a, v0 + a * 2.0] } else { [v0, v0 + a, v0 + b] };
                    let tri = Triangle { v, n: [Vec3::Z; 3], uv: [crate::math::Vec2::ZERO; 3], material: 0, object: 0, two_sided: next() < 0.5 };
                    TriangleEdges::new(&tri)
                };
                prims.push((edges, PrimitiveId::triangle((next() * 1000.0) as u32)));
            }
            let origin = point(6.0, &mut next);
            // Towards a point of one of the triangles (or near it).
            let aim = &prims[(next() * n as f32) as usize].0;
            let (u, v) = (next() * 1.2 - 0.1, next() * 0.6);
            let dir = (aim.v0 + aim.e1 * u + aim.e2 * v - origin).normalize();
            let ray = Ray::new(origin, dir);
            let limit = if next() < 0.5 { f32::INFINITY } else { 1.0 + next() * 6.0 };
            let (mut one, mut tests_one) = (BestHit::nothing_before(limit), 0u64);
            test_leaf::<false, _>(&prims, &[], &ray, false, &mut one, &mut tests_one, &mut NoRecord);
            let (mut wide, mut tests_wide) = (BestHit::nothing_before(limit), 0u64);
            dispatch!(crate::math::lanes::simd_level(), simd => leaf_in_lanes(simd, &prims, &ray, &mut wide, &mut tests_wide));
            assert_eq!((tests_one, one.id), (tests_wide, wide.id), "leaf of {n}");
            assert_eq!([one.t, one.limit, one.bary.0, one.bary.1].map(f32::to_bits), [wide.t, wide.limit, wide.bary.0, wide.bary.1].map(f32::to_bits));
            hits += !one.id.is_none() as u32;
            leaves += 1;
        }
        // The random leaves are hit often enough for the comparison to mean something.
        assert!(hits > leaves / 4, "{hits} hits in {leaves} leaves");
    }
}
