//! `Scene::triangle_hit` for up to eight hits at once. A hit record costs
//! two square roots and two divisions in a chain (the geometric normal,
//! then the shading normal), which one hit at a time leaves the CPU
//! waiting on; here each step runs eight lanes wide (`math::lanes`), with
//! the same operations in the same order as `triangle_hit`, so every lane's
//! record is bit for bit the one `triangle_hit` builds.

use super::{Differentials, PrimitiveKind, Scene, SurfaceHit, Triangle};
use crate::math::lanes::{mask_bits, mask_from_bits, simd_level, Lane, V3};
use crate::math::{Vec2, Vec3};
use fearless_simd::{dispatch, f32x8, Simd, SimdFrom};

/// Most hits one call builds.
pub const HIT_LANES: usize = 8;

/// What a triangle hit's record is built from: the triangle, the
/// barycentric weights of its corners, the ray's parameter and direction.
#[derive(Clone, Copy, Debug, Default)]
pub struct TriangleHitInput {
    pub index: u32,
    pub b: Vec3,
    pub t: f32,
    pub dir: Vec3,
}

impl Scene {
    /// `triangle_hit` for each of `inputs` (at most `HIT_LANES`), handed to
    /// `put` with its position in `inputs`.
    pub fn triangle_hits(&self, inputs: &[TriangleHitInput], mut put: impl FnMut(usize, SurfaceHit)) {
        assert!(inputs.len() <= HIT_LANES);
        if inputs.is_empty() {
            return;
        }
        dispatch!(simd_level(), simd => triangle_hits8(simd, self, inputs, &mut put));
    }
}

/// The lanes' inputs, gathered from the scene (structure of arrays).
struct Gathered {
    v: [[Vec3; HIT_LANES]; 3],
    n: [[Vec3; HIT_LANES]; 3],
    /// The corners' texture coordinates, u and v apart.
    u: [[f32; HIT_LANES]; 3],
    v_coord: [[f32; HIT_LANES]; 3],
    /// Bit i set when lane i's triangle is flat: its normals are the geometric one.
    flat: u8,
    b: [[f32; HIT_LANES]; 3],
    dir: [Vec3; HIT_LANES],
    material: [u32; HIT_LANES],
    object: [u32; HIT_LANES],
}

impl Gathered {
    /// Lanes past `inputs` repeat lane 0 (their results are dropped).
    #[inline(always)]
    fn new(scene: &Scene, inputs: &[TriangleHitInput]) -> Gathered {
        let mut g = Gathered {
            v: [[Vec3::ZERO; HIT_LANES]; 3],
            n: [[Vec3::ZERO; HIT_LANES]; 3],
            u: [[0.0; HIT_LANES]; 3],
            v_coord: [[0.0; HIT_LANES]; 3],
            flat: 0,
            b: [[0.0; HIT_LANES]; 3],
            dir: [Vec3::ZERO; HIT_LANES],
            material: [0; HIT_LANES],
            object: [0; HIT_LANES],
        };
        for lane in 0..HIT_LANES {
            let input = if lane < inputs.len() { &inputs[lane] } else { &inputs[0] };
            let (v, n, uv) = match scene.triangles.stored(input.index as usize) {
                Some(s) => {
                    g.flat |= (s.n.is_none() as u8) << lane;
                    g.material[lane] = s.material;
                    g.object[lane] = s.object;
                    (s.v, s.n.unwrap_or([Vec3::ZERO; 3]), s.uv)
                }
                // A copy of the two-level layer, placed in world space.
                None => {
                    let tri: Triangle = scene.triangle(input.index);
                    g.material[lane] = tri.material;
                    g.object[lane] = tri.object;
                    (tri.v, tri.n, tri.uv)
                }
            };
            for k in 0..3 {
                g.v[k][lane] = v[k];
                g.n[k][lane] = n[k];
                g.u[k][lane] = uv[k].x;
                g.v_coord[k][lane] = uv[k].y;
            }
            g.b[0][lane] = input.b.x;
            g.b[1][lane] = input.b.y;
            g.b[2][lane] = input.b.z;
            g.dir[lane] = input.dir;
        }
        g
    }
}

/// `a b0 + b b1 + c b2`, as `hit_on` interpolates.
#[inline(always)]
fn interpolate<L: Lane>(a: V3<L>, b: V3<L>, c: V3<L>, w: &[L; 3]) -> V3<L> {
    a.scale(w[0]) + b.scale(w[1]) + c.scale(w[2])
}

// No closures or `array::map` below: they would be compiled apart from
// this function, without the SIMD level `dispatch` compiles it for.
#[inline(always)]
fn triangle_hits8<S: Simd>(simd: S, scene: &Scene, inputs: &[TriangleHitInput], put: &mut impl FnMut(usize, SurfaceHit)) {
    let g = Gathered::new(scene, inputs);
    let w = [f32x8::simd_from(simd, g.b[0]), f32x8::simd_from(simd, g.b[1]), f32x8::simd_from(simd, g.b[2])];
    let (v0, v1, v2) = (V3::gather(simd, &g.v[0]), V3::gather(simd, &g.v[1]), V3::gather(simd, &g.v[2]));
    // `Triangle::geometric_normal`, then `hit_on`'s steps in order.
    let geometric = (v1 - v0).cross(v2 - v0).normalize();
    let flat = mask_from_bits(simd, g.flat);
    let n0 = V3::select(flat, geometric, V3::gather(simd, &g.n[0]));
    let n1 = V3::select(flat, geometric, V3::gather(simd, &g.n[1]));
    let n2 = V3::select(flat, geometric, V3::gather(simd, &g.n[2]));
    let shading = interpolate(n0, n1, n2, &w).normalize_or(geometric);
    let back = geometric.dot(V3::gather(simd, &g.dir)).gt(w[0].splat(0.0));
    let geometric = V3::select(back, -geometric, geometric).scatter();
    let shading = V3::select(back, -shading, shading).scatter();
    let position = interpolate(v0, v1, v2, &w).scatter();
    let u: [f32; HIT_LANES] = (f32x8::simd_from(simd, g.u[0]) * w[0] + f32x8::simd_from(simd, g.u[1]) * w[1] + f32x8::simd_from(simd, g.u[2]) * w[2]).into();
    let v: [f32; HIT_LANES] = (f32x8::simd_from(simd, g.v_coord[0]) * w[0] + f32x8::simd_from(simd, g.v_coord[1]) * w[1] + f32x8::simd_from(simd, g.v_coord[2]) * w[2]).into();
    let back = mask_bits(back);
    for (lane, input) in inputs.iter().enumerate() {
        put(
            lane,
            SurfaceHit {
                position: position[lane],
                geometric_normal: geometric[lane],
                shading_normal: shading[lane],
                barycentric: input.b,
                uv: Vec2::new(u[lane], v[lane]),
                t: input.t,
                kind: PrimitiveKind::Triangle,
                primitive: input.index,
                object: g.object[lane],
                material: g.material[lane],
                back_face: back & 1 << lane != 0,
                diff: Differentials::ZERO,
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::scene::builtin;

    /// A tiny seeded generator (SplitMix64) for the barycentrics and rays.
    fn next(state: &mut u64) -> f32 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Every lane's record equals `triangle_hit`'s bit for bit, on every
    /// built-in scene's triangles (flat and smooth, two-sided, with uvs,
    /// copies of the two-level layer), seen from both sides, in batches of
    /// one to eight.
    #[test]
    fn eight_lanes_build_the_records_triangle_hit_builds() {
        let key = |h: &SurfaceHit| {
            let v = [h.position, h.geometric_normal, h.shading_normal, h.barycentric];
            (v.map(|v| v.to_array().map(f32::to_bits)), h.uv.to_array().map(f32::to_bits), h.t.to_bits(), h.primitive, h.object, h.material, h.back_face)
        };
        let mut compared = 0;
        let mut layer_compared = 0;
        let mut state = 7u64;
        // `forest-100` holds its trees as copies of the two-level layer.
        for name in builtin::names().into_iter().chain(["forest-100"]) {
            let scene = builtin::load_builtin(name).unwrap().unwrap();
            let total = scene.triangles.len() + scene.layer.as_ref().map_or(0, |l| l.triangle_count().min(20_000) as usize);
            let step = (total / 3000).max(1);
            let indices: Vec<u32> = (0..total).step_by(step).map(|i| i as u32).collect();
            for (c, chunk) in indices.chunks(1 + compared % HIT_LANES).enumerate() {
                let inputs: Vec<TriangleHitInput> = chunk
                    .iter()
                    .map(|&index| {
                        let (b1, b2) = (next(&mut state), next(&mut state));
                        let (b1, b2) = if b1 + b2 > 1.0 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) };
                        let dir = Vec3::new(next(&mut state) - 0.5, next(&mut state) - 0.5, next(&mut state) - 0.5).normalize_or(Vec3::Z);
                        TriangleHitInput { index, b: Vec3::new(1.0 - b1 - b2, b1, b2), t: next(&mut state) * 10.0, dir: if c % 2 == 0 { dir } else { -dir } }
                    })
                    .collect();
                let mut got = vec![None; inputs.len()];
                scene.triangle_hits(&inputs, |lane, hit| got[lane] = Some(hit));
                for (input, hit) in inputs.iter().zip(&got) {
                    let ray = Ray::new(Vec3::ZERO, input.dir);
                    let expected = scene.triangle_hit(input.index, input.b, input.t, &ray);
                    assert_eq!(key(hit.as_ref().unwrap()), key(&expected), "{name}: triangle {}", input.index);
                    compared += 1;
                    layer_compared += (input.index as usize >= scene.triangles.len()) as usize;
                }
            }
        }
        assert!(compared > 10_000 && layer_compared > 100, "{compared} records compared, {layer_compared} of layer copies");
    }
}
