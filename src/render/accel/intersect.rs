//! Ray-primitive intersection, shared by every method that casts rays (and by
//! the rasterizer's analytic spheres), so all of them agree bit for bit.

use crate::math::lanes::{Lane, V3};
use crate::math::{Ray, Vec3};
use crate::scene::{Sphere, Triangle};

/// A triangle prepared for Möller-Trumbore: one vertex and two edges.
/// Every BVH leaf slot holds one, so it is kept to 40 bytes: the two-sided
/// flag rides in the sign bit of the determinant bound, which is never
/// negative. Laid out as ten floats in this order (`repr(C)`), so a leaf's
/// triangles can be read into lanes as rows (`traverse::gather_triangles`).
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct TriangleEdges {
    pub v0: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
    /// `det_epsilon()`, negated for a two-sided triangle.
    epsilon_and_sides: f32,
}

const _: () = assert!(std::mem::size_of::<TriangleEdges>() == 40 && std::mem::align_of::<TriangleEdges>() == 4);

impl TriangleEdges {
    /// Edges of nothing (a placeholder that no ray hits).
    pub const ZERO: TriangleEdges = TriangleEdges { v0: Vec3::ZERO, e1: Vec3::ZERO, e2: Vec3::ZERO, epsilon_and_sides: 0.0 };

    pub fn new(t: &Triangle) -> TriangleEdges {
        let (e1, e2) = (t.v[1] - t.v[0], t.v[2] - t.v[0]);
        // det = -dir . (e1 x e2) carries a rounding error of a few ulps of |e1| |e2|.
        let det_epsilon = 8.0 * f32::EPSILON * e1.length() * e2.length();
        TriangleEdges { v0: t.v[0], e1, e2, epsilon_and_sides: if t.two_sided { -det_epsilon } else { det_epsilon } }
    }

    /// Determinants this small are rounding noise: the ray lies (nearly) in
    /// the triangle's plane, and the weights computed from them are garbage.
    #[inline(always)]
    pub fn det_epsilon(&self) -> f32 {
        self.epsilon_and_sides.abs()
    }

    /// Whether the triangle is hit from behind too.
    #[inline(always)]
    pub fn two_sided(&self) -> bool {
        self.epsilon_and_sides.is_sign_negative()
    }

    /// The ten floats: v0, e1, e2, then the signed determinant bound.
    #[inline(always)]
    pub fn as_floats(&self) -> &[f32; 10] {
        // SAFETY: `repr(C)` of three `Vec3`s (three f32s each, `repr(C)`)
        // and an f32: ten f32s, no padding, f32-aligned.
        unsafe { &*(self as *const TriangleEdges as *const [f32; 10]) }
    }
}

/// Why a ray-primitive test did not produce a hit (shown by the pixel inspector).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Miss {
    /// The ray runs parallel to the triangle's plane.
    Parallel,
    /// A single-sided triangle seen from behind.
    BackFace,
    /// The line meets the plane (or sphere) outside the primitive.
    Outside,
    /// The hit is behind the ray origin.
    Behind,
    /// The hit is beyond the current closest hit or the ray's end.
    Farther,
}

/// Outcome of one ray-triangle test: `t` and the barycentric weights of v1, v2.
pub type TriangleTest = Result<(f32, f32, f32), Miss>;

/// Möller-Trumbore ray-triangle test (CGPP listing 15.16 derives the same
/// weights). Accepts hits with `0 < t < t_max`; single-sided triangles are hit
/// only from the front, where the winding is counter-clockwise.
#[inline(always)]
pub fn intersect_triangle(ray: &Ray, tri: &TriangleEdges, t_max: f32) -> TriangleTest {
    let p = ray.dir.cross(tri.e2);
    let det = tri.e1.dot(p);
    // det = -dir . (e1 x e2): positive when the ray meets the front face.
    let det_epsilon = tri.det_epsilon();
    if tri.two_sided() {
        if !(det.abs() > det_epsilon) {
            return Err(Miss::Parallel);
        }
    } else if !(det > det_epsilon) {
        return Err(if det < -det_epsilon { Miss::BackFace } else { Miss::Parallel });
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri.v0;
    let b1 = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return Err(Miss::Outside);
    }
    let q = s.cross(tri.e1);
    let b2 = ray.dir.dot(q) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return Err(Miss::Outside);
    }
    let t = tri.e2.dot(q) * inv;
    if t <= 0.0 {
        return Err(Miss::Behind);
    }
    if t >= t_max {
        return Err(Miss::Farther);
    }
    Ok((t, b1, b2))
}

/// `intersect_triangle` for lanes of rays against one triangle, with the
/// same arithmetic in the same order, so each lane's `(t, b1, b2)` is bit
/// for bit the single ray's. Returns the lanes that hit (`0 < t < limit`)
/// and the values (meaningless in the other lanes).
#[inline(always)]
pub fn intersect_triangle_lanes<L: Lane>(origin: V3<L>, dir: V3<L>, tri: &TriangleEdges, limit: L) -> (L::Mask, L, L, L) {
    let (zero, one) = (limit.splat(0.0), limit.splat(1.0));
    // A constant mask in each branch, so the sidedness test folds away.
    if tri.two_sided() {
        intersect_triangles_lanes(origin, dir, &TriangleLanes::splat(limit, tri, zero.lt(one)), limit)
    } else {
        intersect_triangles_lanes(origin, dir, &TriangleLanes::splat(limit, tri, one.lt(zero)), limit)
    }
}

/// Triangles in lanes (`TriangleEdges`' fields, the flag as a mask).
pub struct TriangleLanes<L: Lane> {
    pub v0: V3<L>,
    pub e1: V3<L>,
    pub e2: V3<L>,
    pub epsilon: L,
    pub two_sided: L::Mask,
}

impl<L: Lane> TriangleLanes<L> {
    /// `tri` in every lane (`like` gives the SIMD context), `two_sided`
    /// being its flag in every lane.
    #[inline(always)]
    fn splat(like: L, tri: &TriangleEdges, two_sided: L::Mask) -> Self {
        TriangleLanes { v0: V3::splat(like, tri.v0), e1: V3::splat(like, tri.e1), e2: V3::splat(like, tri.e2), epsilon: like.splat(tri.det_epsilon()), two_sided }
    }
}

/// `intersect_triangle` lane by lane, each lane a ray (`origin`, `dir`)
/// against a triangle, with the same arithmetic in the same order: the
/// lanes that hit (`0 < t < limit`) and their `(t, b1, b2)`, bit for bit
/// the single test's (meaningless in the other lanes). Rays in lanes
/// against one triangle (packets), or one ray against a leaf's triangles.
#[inline(always)]
pub fn intersect_triangles_lanes<L: Lane>(origin: V3<L>, dir: V3<L>, tri: &TriangleLanes<L>, limit: L) -> (L::Mask, L, L, L) {
    let (zero, one) = (limit.splat(0.0), limit.splat(1.0));
    let p = dir.cross(tri.e2);
    let det = tri.e1.dot(p);
    let front = det.gt(tri.epsilon);
    // |det| > epsilon for two-sided triangles (false for NaN, as there).
    let facing = front | (tri.two_sided & (-det).gt(tri.epsilon));
    let inv = one / det;
    let s = origin - tri.v0;
    let b1 = s.dot(p) * inv;
    let inside1 = zero.le(b1) & b1.le(one);
    let q = s.cross(tri.e1);
    let b2 = dir.dot(q) * inv;
    let inside2 = !(b2.lt(zero) | (b1 + b2).gt(one));
    let t = tri.e2.dot(q) * inv;
    let ahead = !(t.le(zero) | t.ge(limit));
    (facing & inside1 & inside2 & ahead, t, b1, b2)
}

/// Ray-sphere test. Spheres are closed and hit from outside only: a ray that
/// starts inside (or on) the sphere does not hit it, which also keeps shadow
/// rays from re-hitting the sphere they leave. Refracted rays travelling inside
/// pass `allow_inside = true` to find the exit point of the sphere they are in.
///
/// The discriminant is formed from the perpendicular distance of the centre to
/// the line (Ray Tracing Gems, ch. 7) to stay accurate for huge spheres.
#[inline]
pub fn intersect_sphere(ray: &Ray, s: &Sphere, t_max: f32, allow_inside: bool) -> Result<f32, Miss> {
    let f = ray.origin - s.center;
    let b = -f.dot(ray.dir);
    let l = f + ray.dir * b; // centre-to-line vector
    let dist = l.length();
    let disc = (s.radius - dist) * (s.radius + dist);
    if disc < 0.0 {
        return Err(Miss::Outside);
    }
    let h = disc.sqrt();
    let (t_near, t_far) = (b - h, b + h);
    let origin_outside = f.length() > s.radius;
    let t = if origin_outside { t_near } else if allow_inside { t_far } else { return Err(Miss::Behind) };
    if t <= 0.0 {
        return Err(Miss::Behind);
    }
    if t >= t_max {
        return Err(Miss::Farther);
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// The lane form gives each ray the single test's outcome and, on a hit,
    /// its very bits, at one lane and at eight (whatever SIMD level runs).
    #[test]
    fn lanes_match_the_single_ray_test() {
        use fearless_simd::{dispatch, f32x8, SimdFrom};
        let mut seed = 12345u32;
        let mut next = move || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0
        };
        let mut hits = 0;
        for round in 0..4000 {
            let v = [Vec3::new(next(), next(), next()), Vec3::new(next(), next(), next()), Vec3::new(next(), next(), next())];
            let t = tri(v, round % 3 == 0);
            let rays: [Ray; 8] = std::array::from_fn(|_| {
                let origin = Vec3::new(next(), next(), next() + 2.0);
                let target = (v[0] + v[1] + v[2]) / 3.0 + Vec3::new(next(), next(), next()) * 0.5;
                Ray::new(origin, (target - origin).normalize())
            });
            let limit: [f32; 8] = std::array::from_fn(|i| if i == 7 { 1.5 } else { f32::INFINITY });
            let want: [TriangleTest; 8] = std::array::from_fn(|i| intersect_triangle(&rays[i], &t, limit[i]));
            let wide: (u8, [f32; 8], [f32; 8], [f32; 8]) = dispatch!(crate::math::lanes::simd_level(), simd => {
                let origin = V3::gather(simd, &rays.map(|r| r.origin));
                let dir = V3::gather(simd, &rays.map(|r| r.dir));
                let (hit, t8, b1, b2) = intersect_triangle_lanes(origin, dir, &t, f32x8::simd_from(simd, limit));
                (crate::math::lanes::mask_bits(hit), t8.into(), b1.into(), b2.into())
            });
            for i in 0..8 {
                let (one_hit, t1, b11, b21) = intersect_triangle_lanes(rays[i].origin.into(), rays[i].dir.into(), &t, limit[i]);
                assert_eq!(want[i].is_ok(), one_hit, "round {round} ray {i}");
                assert_eq!(want[i].is_ok(), wide.0 & 1 << i != 0, "round {round} ray {i}");
                if let Ok((tt, bb1, bb2)) = want[i] {
                    hits += 1;
                    assert_eq!([tt, bb1, bb2].map(f32::to_bits), [t1, b11, b21].map(f32::to_bits));
                    assert_eq!([tt, bb1, bb2].map(f32::to_bits), [wide.1[i], wide.2[i], wide.3[i]].map(f32::to_bits));
                }
            }
        }
        assert!(hits > 5000, "only {hits} hits compared");
    }

    fn tri(v: [Vec3; 3], two_sided: bool) -> TriangleEdges {
        TriangleEdges::new(&Triangle { v, n: [Vec3::Z; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided })
    }

    fn book_triangle() -> TriangleEdges {
        book_triangle_sided(false)
    }

    fn book_triangle_sided(two_sided: bool) -> TriangleEdges {
        tri([Vec3::new(0.0, 1.0, -2.0), Vec3::new(-1.9, -1.0, -2.0), Vec3::new(1.6, -0.5, -2.0)], two_sided)
    }

    #[test]
    fn hit_by_hand() {
        // Ray down -z through (0, 0): the plane z = -2 is at t = 2. Solving
        // (0,0) = v0 + b1 (v1 - v0) + b2 (v2 - v0): -1.9 b1 + 1.6 b2 = 0 and
        // -2 b1 - 1.5 b2 = -1, so b1 = 16/62 * ... computed exactly below.
        let r = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
        let (t, b1, b2) = intersect_triangle(&r, &book_triangle(), f32::INFINITY).unwrap();
        // From -1.9 b1 + 1.6 b2 = 0: b2 = 1.1875 b1; -2 b1 - 1.78125 b1 = -1 => b1 = 1/3.78125.
        let e_b1 = 1.0 / 3.78125;
        assert!((t - 2.0).abs() < 1e-6);
        assert!((b1 - e_b1).abs() < 1e-6, "{b1}");
        assert!((b2 - 1.1875 * e_b1).abs() < 1e-6, "{b2}");
    }

    #[test]
    fn rejects_with_reasons() {
        let t = book_triangle();
        let down = Vec3::new(0.0, 0.0, -1.0);
        // Outside: far to the right.
        assert_eq!(intersect_triangle(&Ray::new(Vec3::new(5.0, 0.0, 0.0), down), &t, 1e9), Err(Miss::Outside));
        // Behind: origin past the triangle.
        assert_eq!(intersect_triangle(&Ray::new(Vec3::new(0.0, 0.0, -3.0), -down), &t, 1e9), Err(Miss::BackFace));
        assert_eq!(intersect_triangle(&Ray::new(Vec3::new(0.0, 0.0, -3.0), down), &t, 1e9), Err(Miss::Behind));
        // Farther than t_max.
        assert_eq!(intersect_triangle(&Ray::new(Vec3::ZERO, down), &t, 1.5), Err(Miss::Farther));
        // Parallel.
        assert_eq!(intersect_triangle(&Ray::new(Vec3::ZERO, Vec3::X), &t, 1e9), Err(Miss::Parallel));
    }

    #[test]
    fn rays_in_the_plane_never_hit() {
        // A ray lying in the triangle's plane (z = -2) through its interior: the
        // determinant is rounding noise, and must not produce a hit elsewhere.
        for two_sided in [false, true] {
            let t = book_triangle_sided(two_sided);
            for dir in [Vec3::X, Vec3::new(0.6, 0.8, 0.0), Vec3::new(-0.28, 0.96, 1e-9)] {
                let r = Ray::new(Vec3::new(-3.0, -0.2, -2.0), dir);
                assert_eq!(intersect_triangle(&r, &t, 1e9), Err(Miss::Parallel), "{dir}");
            }
        }
        // The same in tilted planes, where the in-plane direction is only
        // in-plane up to rounding. A ray that grazes the plane at a tiny but
        // real angle has an ill-conditioned hit, so some error is expected;
        // what must not happen is a hit made of rounding noise, far from the
        // triangle (seen on the bunny before the determinant threshold).
        let mut seed = 0x9E3779B97F4A7C15u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut worst = 0.0f32;
        for _ in 0..20000 {
            let v = [Vec3::new(rnd(), rnd(), rnd()) * 3.0, Vec3::new(rnd(), rnd(), rnd()) * 3.0, Vec3::new(rnd(), rnd(), rnd()) * 3.0];
            let tri = TriangleEdges::new(&Triangle { v, n: [Vec3::Z; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided: true });
            let n = tri.e1.cross(tri.e2);
            if n.length() < 1e-3 {
                continue;
            }
            let (a, b) = (rnd(), rnd());
            let origin = v[0] + tri.e1 * a * 2.0 + tri.e2 * b * 2.0;
            let target = v[0] + tri.e1 * 0.3 + tri.e2 * 0.3;
            let r = Ray::new(origin, (target - origin).normalize());
            if let Ok((t, b1, b2)) = intersect_triangle(&r, &tri, 1e9) {
                let on_tri = v[0] + tri.e1 * b1 + tri.e2 * b2;
                let err = (r.at(t) - on_tri).length();
                worst = worst.max(err);
                assert!(err < 0.05, "hit at t = {t} is {err} from the triangle");
            }
        }
        eprintln!("worst in-plane hit error: {worst}");
    }

    #[test]
    fn two_sided_hits_from_behind() {
        let t = book_triangle_sided(true);
        assert!(t.two_sided() && !book_triangle().two_sided() && t.det_epsilon() == book_triangle().det_epsilon());
        let r = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z);
        let (dist, _, _) = intersect_triangle(&r, &t, 1e9).unwrap();
        assert!((dist - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sphere_by_hand() {
        let s = Sphere { center: Vec3::new(0.0, 0.0, -5.0), radius: 1.0, material: 0, object: 0 };
        let r = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(intersect_sphere(&r, &s, 1e9, false), Ok(4.0));
        assert_eq!(intersect_sphere(&r, &s, 3.0, false), Err(Miss::Farther));
        // Grazing at x = 0.6: t = 5 - sqrt(1 - 0.36) = 4.2.
        let r = Ray::new(Vec3::new(0.6, 0.0, 0.0), Vec3::new(0.0, 0.0, -1.0));
        assert!((intersect_sphere(&r, &s, 1e9, false).unwrap() - 4.2).abs() < 1e-5);
        let r = Ray::new(Vec3::new(1.01, 0.0, 0.0), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(intersect_sphere(&r, &s, 1e9, false), Err(Miss::Outside));
        // From inside: only refracted rays see the exit.
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(intersect_sphere(&r, &s, 1e9, false), Err(Miss::Behind));
        assert_eq!(intersect_sphere(&r, &s, 1e9, true), Ok(1.0));
    }

    #[test]
    fn huge_sphere_stays_accurate() {
        // The ground of the spheres scene: radius 5000, top at y = -1.
        let s = Sphere { center: Vec3::new(0.0, -5001.0, 0.0), radius: 5000.0, material: 0, object: 0 };
        let r = Ray::new(Vec3::ZERO, Vec3::new(0.0, -1.0, 1.0).normalize());
        let t = intersect_sphere(&r, &s, 1e9, false).unwrap();
        let p = r.at(t);
        assert!(((p - s.center).length() - 5000.0).abs() < 2e-3, "{p}");
        assert!((p.y + 1.0).abs() < 1e-3);
    }
}
