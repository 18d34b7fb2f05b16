//! Surface records for up to eight hits at once, in lanes (`HitLanes`:
//! structure of arrays), as batches shade them. A triangle hit's record
//! costs two square roots and two divisions in a chain (the geometric
//! normal, then the shading normal), which one hit at a time leaves the CPU
//! waiting on; here each step runs eight lanes wide (`math::lanes`), with
//! the same operations in the same order as `triangle_hit`, so every lane
//! is bit for bit the record `triangle_hit` builds. The records stay in
//! lanes for shading; `HitLanes::get` assembles one as a `SurfaceHit` where
//! one-sample code needs it.

use crate::scene::camera::CameraView;
use crate::scene::triangles::CornerRow;
use crate::scene::{Differentials, PrimitiveKind, Scene, SurfaceHit, Triangle};
use crate::math::lanes::{transpose8, mask_bits, mask_from_bits, simd_level, Lane, V3};
use crate::math::{Vec2, Vec3};
use fearless_simd::{dispatch, f32x8, Simd, SimdBase, SimdFrom};

/// Most hits one call builds.
pub const HIT_LANES: usize = 8;

/// Eight floats, one per lane.
pub type Floats = [f32; HIT_LANES];

/// What a triangle hit's record is built from: the triangle, the
/// barycentric weights of its corners, the ray's parameter and direction.
#[derive(Clone, Copy, Debug, Default)]
pub struct TriangleHitInput {
    pub index: u32,
    pub b: Vec3,
    pub t: f32,
    pub dir: Vec3,
}

impl TriangleHitInput {
    /// The hit on triangle `index` with weights b1 and b2 of its second and
    /// third corners, `t` along a ray towards `dir`: the corner weights as
    /// `Scene::primitive_hit` makes them (`1 - b1 - b2`, b1, b2).
    #[inline]
    pub fn new(index: u32, (b1, b2): (f32, f32), t: f32, dir: Vec3) -> TriangleHitInput {
        TriangleHitInput { index, b: Vec3::new(1.0 - b1 - b2, b1, b2), t, dir }
    }
}

/// Eye samples that see a triangle, as a rasterizer's buffers hold them:
/// the triangle, its barycentric weights b1 and b2 (b0 = 1 - b1 - b2) and
/// the sample's image position, whose eye ray is worked out in lanes.
#[derive(Clone, Copy, Debug, Default)]
pub struct EyeSamples {
    pub len: usize,
    pub index: [u32; HIT_LANES],
    pub b1: Floats,
    pub b2: Floats,
    pub px: Floats,
    pub py: Floats,
}

impl EyeSamples {
    #[inline(always)]
    pub fn push(&mut self, index: u32, b1: f32, b2: f32, p: Vec2) {
        let k = self.len;
        self.index[k] = index;
        self.b1[k] = b1;
        self.b2[k] = b2;
        self.px[k] = p.x;
        self.py[k] = p.y;
        self.len += 1;
    }
}

/// Up to eight `SurfaceHit`s, field by field (lane i of each array is hit
/// i's), so that shading loads them as vectors.
#[derive(Clone, Copy, Debug)]
pub struct HitLanes {
    pub position: [Floats; 3],
    pub geometric_normal: [Floats; 3],
    pub shading_normal: [Floats; 3],
    pub barycentric: [Floats; 3],
    pub uv: [Floats; 2],
    pub t: Floats,
    pub kind: [PrimitiveKind; HIT_LANES],
    pub primitive: [u32; HIT_LANES],
    pub object: [u32; HIT_LANES],
    pub material: [u32; HIT_LANES],
    /// Bit i: hit i is seen from the back.
    pub back_face: u8,
    pub diff: [Differentials; HIT_LANES],
}

impl Default for HitLanes {
    fn default() -> Self {
        Self::new()
    }
}

impl HitLanes {
    /// Lanes that hold a tame placeholder (unit normals along z).
    pub const fn new() -> HitLanes {
        let zero = [0.0; HIT_LANES];
        let one = [1.0; HIT_LANES];
        HitLanes {
            position: [zero; 3],
            geometric_normal: [zero, zero, one],
            shading_normal: [zero, zero, one],
            barycentric: [zero; 3],
            uv: [zero; 2],
            t: zero,
            kind: [PrimitiveKind::Triangle; HIT_LANES],
            primitive: [0; HIT_LANES],
            object: [0; HIT_LANES],
            material: [0; HIT_LANES],
            back_face: 0,
            diff: [Differentials::ZERO; HIT_LANES],
        }
    }

    /// Hit `i` as a record.
    #[inline]
    pub fn get(&self, i: usize) -> SurfaceHit {
        let v3 = |a: &[Floats; 3]| Vec3::new(a[0][i], a[1][i], a[2][i]);
        SurfaceHit {
            position: v3(&self.position),
            geometric_normal: v3(&self.geometric_normal),
            shading_normal: v3(&self.shading_normal),
            barycentric: v3(&self.barycentric),
            uv: Vec2::new(self.uv[0][i], self.uv[1][i]),
            t: self.t[i],
            kind: self.kind[i],
            primitive: self.primitive[i],
            object: self.object[i],
            material: self.material[i],
            back_face: self.back_face & 1 << i != 0,
            diff: self.diff[i],
        }
    }

    /// Makes hit `i` the record `h`.
    #[inline]
    pub fn set(&mut self, i: usize, h: &SurfaceHit) {
        let put = |a: &mut [Floats; 3], v: Vec3| {
            a[0][i] = v.x;
            a[1][i] = v.y;
            a[2][i] = v.z;
        };
        put(&mut self.position, h.position);
        put(&mut self.geometric_normal, h.geometric_normal);
        put(&mut self.shading_normal, h.shading_normal);
        put(&mut self.barycentric, h.barycentric);
        self.uv[0][i] = h.uv.x;
        self.uv[1][i] = h.uv.y;
        self.t[i] = h.t;
        self.kind[i] = h.kind;
        self.primitive[i] = h.primitive;
        self.object[i] = h.object;
        self.material[i] = h.material;
        self.back_face = (self.back_face & !(1 << i)) | (h.back_face as u8) << i;
        self.diff[i] = h.diff;
    }

    /// Makes hit `i` hit `k` of `from`.
    #[inline]
    pub fn copy_lane(&mut self, i: usize, from: &HitLanes, k: usize) {
        for a in 0..3 {
            self.position[a][i] = from.position[a][k];
            self.geometric_normal[a][i] = from.geometric_normal[a][k];
            self.shading_normal[a][i] = from.shading_normal[a][k];
            self.barycentric[a][i] = from.barycentric[a][k];
        }
        self.uv[0][i] = from.uv[0][k];
        self.uv[1][i] = from.uv[1][k];
        self.t[i] = from.t[k];
        self.kind[i] = from.kind[k];
        self.primitive[i] = from.primitive[k];
        self.object[i] = from.object[k];
        self.material[i] = from.material[k];
        self.back_face = (self.back_face & !(1 << i)) | ((from.back_face >> k) & 1) << i;
        self.diff[i] = from.diff[k];
    }
}

impl Scene {
    /// `triangle_hit` for each of `inputs` (at most `HIT_LANES`), written to
    /// the lane of `out` of its position in `inputs`; lanes past them hold
    /// copies of lane 0.
    pub fn triangle_hits(&self, inputs: &[TriangleHitInput], out: &mut HitLanes) {
        assert!(inputs.len() <= HIT_LANES);
        if inputs.is_empty() {
            return;
        }
        let mut index = [inputs[0].index; HIT_LANES];
        let (mut b1, mut b2, mut t) = ([inputs[0].b.y; HIT_LANES], [inputs[0].b.z; HIT_LANES], [inputs[0].t; HIT_LANES]);
        let mut b0 = [inputs[0].b.x; HIT_LANES];
        let mut dir = [[inputs[0].dir.x; HIT_LANES], [inputs[0].dir.y; HIT_LANES], [inputs[0].dir.z; HIT_LANES]];
        for (k, input) in inputs.iter().enumerate() {
            index[k] = input.index;
            (b0[k], b1[k], b2[k], t[k]) = (input.b.x, input.b.y, input.b.z, input.t);
            (dir[0][k], dir[1][k], dir[2][k]) = (input.dir.x, input.dir.y, input.dir.z);
        }
        out.t = t;
        dispatch!(simd_level(), simd => {
            let w = [f32x8::simd_from(simd, b0), f32x8::simd_from(simd, b1), f32x8::simd_from(simd, b2)];
            triangle_hits8(simd, self, &index, inputs.len(), w, V3::from_soa(simd, &dir), out);
        });
    }

    /// `triangle_hits` for eight ray hits already in lanes (a packet's
    /// group of eight rays that all found a triangle): triangles `index`,
    /// weights `b1` and `b2` of their second and third corners, `t` along
    /// rays towards `dir`. The same records, without packing inputs lane by
    /// lane.
    pub fn triangle_hits_of_rays(&self, index: &[u32; HIT_LANES], (b1, b2): (&Floats, &Floats), t: &Floats, dir: &[Floats; 3], out: &mut HitLanes) {
        out.t = *t;
        dispatch!(simd_level(), simd => {
            let (b1, b2) = (f32x8::simd_from(simd, *b1), f32x8::simd_from(simd, *b2));
            // `TriangleHitInput::new`'s corner weights.
            let w = [b1.splat(1.0) - b1 - b2, b1, b2];
            triangle_hits8(simd, self, index, HIT_LANES, w, V3::from_soa(simd, dir), out);
        });
    }

    /// For each eye sample of `samples`, the record of where its eye ray
    /// (`view.eye_ray`) meets its triangle, as `triangle_hit` builds it with
    /// `t` the hit position's distance along the ray; written to the lane of
    /// `out` of its position in `samples`, and the eye ray's directions to
    /// `dirs`. Lanes past them hold copies of lane 0.
    pub fn triangle_eye_hits(&self, view: &CameraView, samples: &EyeSamples, out: &mut HitLanes, dirs: &mut [Floats; 3]) {
        let n = samples.len;
        assert!(n <= HIT_LANES);
        if n == 0 {
            return;
        }
        // Only a partial group is copied to pad it: a full one (the common
        // case) was just written lane by lane, and a whole copy of it would
        // wait for those writes to reach the cache.
        let mut padded;
        let s = if n == HIT_LANES {
            samples
        } else {
            padded = *samples;
            for k in n..HIT_LANES {
                (padded.index[k], padded.b1[k], padded.b2[k], padded.px[k], padded.py[k]) = (padded.index[0], padded.b1[0], padded.b2[0], padded.px[0], padded.py[0]);
            }
            &padded
        };
        dispatch!(simd_level(), simd => triangle_eye_hits8(simd, self, view, s, out, dirs));
    }
}

#[inline(always)]
fn triangle_eye_hits8<S: Simd>(simd: S, scene: &Scene, view: &CameraView, s: &EyeSamples, out: &mut HitLanes, dirs: &mut [Floats; 3]) {
    let (b1, b2) = (f32x8::simd_from(simd, s.b1), f32x8::simd_from(simd, s.b2));
    // The rasterizers' weights, as `Vec3::new(1 - b1 - b2, b1, b2)`.
    let w = [b1.splat(1.0) - b1 - b2, b1, b2];
    let (origin, dir) = view.eye_ray_lanes(f32x8::simd_from(simd, s.px), f32x8::simd_from(simd, s.py));
    let position = triangle_hits8(simd, scene, &s.index, s.len, w, dir, out);
    // The eye ray's parameter at the hit: `(position - origin) . dir`.
    out.t = (position - origin).dot(dir).into();
    *dirs = dir.to_soa();
}

/// The corners of up to eight triangles in lanes: `attr[corner][k]` holds
/// attribute k of a `CornerRow` (position x, y, z, normal x, y, z, u, v)
/// of every lane's triangle.
struct CornerLanes<S: Simd> {
    attr: [[f32x8<S>; 8]; 3],
    /// Bit i set when lane i's triangle is flat: its normals are the
    /// geometric one (a stored triangle's rows hold zero normals).
    flat: u8,
    material: [u32; HIT_LANES],
    object: [u32; HIT_LANES],
}

/// Where a lane's rows point before they are read.
static NO_ROW: CornerRow = [0.0; 8];

/// The corners of triangles `index` in lanes; lanes at or past `n` repeat
/// lane 0 (their results are dropped). Each corner of the eight triangles
/// is read as eight rows and transposed (the store keeps a corner as one
/// row), not copied a float at a time.
#[inline(always)]
fn gather_corners<S: Simd>(simd: S, scene: &Scene, index: &[u32; HIT_LANES], n: usize) -> CornerLanes<S> {
    // Every lane on one triangle (a pixel's samples, as the ray caster
    // batches them): its rows are read once and put in every lane.
    if index[1..n.max(1)].iter().all(|&i| i == index[0]) {
        if let Some(face) = scene.triangles.corner_rows(index[0] as usize) {
            let mut attr = [[f32x8::simd_from(simd, [0.0; HIT_LANES]); 8]; 3];
            for (corner, row) in attr.iter_mut().zip(face.corners) {
                for (lanes, &v) in corner.iter_mut().zip(row) {
                    *lanes = f32x8::simd_from(simd, [v; HIT_LANES]);
                }
            }
            let flat = if face.flat { u8::MAX } else { 0 };
            return CornerLanes { attr, flat, material: [face.material; HIT_LANES], object: [face.object; HIT_LANES] };
        }
    }
    let (mut flat, mut material, mut object) = (0u8, [0u32; HIT_LANES], [0u32; HIT_LANES]);
    let mut rows = [[&NO_ROW; HIT_LANES]; 3];
    for lane in 0..HIT_LANES {
        let i = if lane < n { index[lane] } else { index[0] };
        let Some(face) = scene.triangles.corner_rows(i as usize) else {
            return gather_placed_corners(simd, scene, index, n);
        };
        for k in 0..3 {
            rows[k][lane] = face.corners[k];
        }
        flat |= (face.flat as u8) << lane;
        material[lane] = face.material;
        object[lane] = face.object;
    }
    CornerLanes { attr: transpose_corners(simd, &rows), flat, material, object }
}

/// `gather_corners` where some lane's triangle is a copy of the two-level
/// layer (placed in world space, so not in the store): every lane's rows
/// are copied out first.
#[inline(always)]
fn gather_placed_corners<S: Simd>(simd: S, scene: &Scene, index: &[u32; HIT_LANES], n: usize) -> CornerLanes<S> {
    let (mut flat, mut material, mut object) = (0u8, [0u32; HIT_LANES], [0u32; HIT_LANES]);
    let mut placed = [[[0.0f32; 8]; 3]; HIT_LANES];
    for lane in 0..HIT_LANES {
        let i = if lane < n { index[lane] } else { index[0] };
        if let Some(face) = scene.triangles.corner_rows(i as usize) {
            for k in 0..3 {
                placed[lane][k] = *face.corners[k];
            }
            flat |= (face.flat as u8) << lane;
            material[lane] = face.material;
            object[lane] = face.object;
        } else {
            let tri: Triangle = scene.triangle(i);
            for k in 0..3 {
                let (v, nrm, uv) = (tri.v[k], tri.n[k], tri.uv[k]);
                placed[lane][k] = [v.x, v.y, v.z, nrm.x, nrm.y, nrm.z, uv.x, uv.y];
            }
            flat |= (tri.is_flat() as u8) << lane;
            material[lane] = tri.material;
            object[lane] = tri.object;
        }
    }
    let mut rows = [[&NO_ROW; HIT_LANES]; 3];
    for lane in 0..HIT_LANES {
        for k in 0..3 {
            rows[k][lane] = &placed[lane][k];
        }
    }
    CornerLanes { attr: transpose_corners(simd, &rows), flat, material, object }
}

/// Each corner's eight rows (one per lane) as eight lanes of its attributes.
#[inline(always)]
fn transpose_corners<S: Simd>(simd: S, rows: &[[&CornerRow; HIT_LANES]; 3]) -> [[f32x8<S>; 8]; 3] {
    let zero = <f32x8<S> as SimdBase<S>>::splat(simd, 0.0);
    let mut attr = [[zero; 8]; 3];
    for (corner, corner_rows) in attr.iter_mut().zip(rows) {
        let mut m = [zero; 8];
        for (lane, row) in m.iter_mut().zip(corner_rows) {
            *lane = f32x8::from_slice(simd, *row);
        }
        *corner = transpose8(m);
    }
    attr
}

/// `a b0 + b b1 + c b2`, as `hit_on` interpolates.
#[inline(always)]
fn interpolate<L: Lane>(a: V3<L>, b: V3<L>, c: V3<L>, w: &[L; 3]) -> V3<L> {
    a.scale(w[0]) + b.scale(w[1]) + c.scale(w[2])
}

/// Builds every field of `out` but `t` for triangles `index` (lanes at or
/// past `n` repeat lane 0) hit with weights `w` by rays along `dir`;
/// returns the hit positions.
// No closures or `array::map` below: they would be compiled apart from
// this function, without the SIMD level `dispatch` compiles it for.
#[inline(always)]
fn triangle_hits8<S: Simd>(simd: S, scene: &Scene, index: &[u32; HIT_LANES], n: usize, w: [f32x8<S>; 3], dir: V3<f32x8<S>>, out: &mut HitLanes) -> V3<f32x8<S>> {
    let c = gather_corners(simd, scene, index, n);
    let a = &c.attr;
    let (v0, v1, v2) = (V3 { x: a[0][0], y: a[0][1], z: a[0][2] }, V3 { x: a[1][0], y: a[1][1], z: a[1][2] }, V3 { x: a[2][0], y: a[2][1], z: a[2][2] });
    // `Triangle::geometric_normal`, then `hit_on`'s steps in order.
    let geometric = (v1 - v0).cross(v2 - v0).normalize();
    // `hit_on`'s shading normal: the geometric one on flat triangles (all
    // lanes, the common batch, skip the blend), else the blend of the
    // corners' normals, renormalised.
    let shading = if c.flat == u8::MAX {
        geometric
    } else {
        let (n0, n1, n2) = (V3 { x: a[0][3], y: a[0][4], z: a[0][5] }, V3 { x: a[1][3], y: a[1][4], z: a[1][5] }, V3 { x: a[2][3], y: a[2][4], z: a[2][5] });
        V3::select(mask_from_bits(simd, c.flat), geometric, interpolate(n0, n1, n2, &w).normalize_or(geometric))
    };
    let back = geometric.dot(dir).gt(w[0].splat(0.0));
    out.geometric_normal = V3::select(back, -geometric, geometric).to_soa();
    out.shading_normal = V3::select(back, -shading, shading).to_soa();
    let position = interpolate(v0, v1, v2, &w);
    out.position = position.to_soa();
    out.barycentric = [w[0].into(), w[1].into(), w[2].into()];
    for (k, uv) in out.uv.iter_mut().enumerate() {
        let (uv0, uv1, uv2) = (a[0][6 + k], a[1][6 + k], a[2][6 + k]);
        *uv = (uv0 * w[0] + uv1 * w[1] + uv2 * w[2]).into();
    }
    out.kind = [PrimitiveKind::Triangle; HIT_LANES];
    out.primitive = *index;
    for lane in n..HIT_LANES {
        out.primitive[lane] = index[0];
    }
    out.object = c.object;
    out.material = c.material;
    out.back_face = mask_bits(back);
    out.diff = [Differentials::ZERO; HIT_LANES];
    position
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

    /// Corner weights (b0, b1, b2) of a point inside a triangle: two draws,
    /// folded back into the triangle when they leave it.
    fn weights_inside(state: &mut u64) -> Vec3 {
        let (b1, b2) = (next(state), next(state));
        let (b1, b2) = if b1 + b2 > 1.0 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) };
        Vec3::new(1.0 - b1 - b2, b1, b2)
    }

    /// What two records must share: every field's bits.
    #[allow(clippy::type_complexity)]
    fn record_bits(h: &SurfaceHit) -> ([[u32; 3]; 4], [u32; 2], u32, u32, u32, u32, bool) {
        let v = [h.position, h.geometric_normal, h.shading_normal, h.barycentric];
        (v.map(|v| v.to_array().map(f32::to_bits)), h.uv.to_array().map(f32::to_bits), h.t.to_bits(), h.primitive, h.object, h.material, h.back_face)
    }

    /// Row r, column c holds 8r + c; after the transpose vector c holds
    /// column c (at the machine's SIMD level).
    #[test]
    fn eight_rows_transpose_to_eight_columns() {
        fn check<S: Simd>(simd: S) {
            let zero = <f32x8<S> as SimdBase<S>>::splat(simd, 0.0);
            let mut rows = [zero; 8];
            for (r, row) in rows.iter_mut().enumerate() {
                let values: [f32; 8] = std::array::from_fn(|c| (8 * r + c) as f32);
                *row = f32x8::from_slice(simd, &values);
            }
            let columns = transpose8(rows);
            for (c, column) in columns.iter().enumerate() {
                let values: [f32; 8] = (*column).into();
                let expected: [f32; 8] = std::array::from_fn(|r| (8 * r + c) as f32);
                assert_eq!(values, expected, "column {c}");
            }
        }
        dispatch!(crate::math::lanes::simd_level(), simd => check(simd));
    }

    /// Every lane's record equals `triangle_hit`'s bit for bit, on every
    /// built-in scene's triangles (flat and smooth, two-sided, with uvs,
    /// copies of the two-level layer), seen from both sides, in batches of
    /// one to eight.
    #[test]
    fn eight_lanes_build_the_records_triangle_hit_builds() {
        let mut compared = 0;
        let mut layer_compared = 0;
        let mut one_triangle = 0;
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
                        // Every third chunk puts all its lanes on one
                        // triangle (read once, not gathered lane by lane).
                        let index = if c % 3 == 2 { chunk[0] } else { index };
                        let b = weights_inside(&mut state);
                        let dir = Vec3::new(next(&mut state) - 0.5, next(&mut state) - 0.5, next(&mut state) - 0.5).normalize_or(Vec3::Z);
                        TriangleHitInput { index, b, t: next(&mut state) * 10.0, dir: if c % 2 == 0 { dir } else { -dir } }
                    })
                    .collect();
                let mut got = HitLanes::new();
                scene.triangle_hits(&inputs, &mut got);
                for (lane, input) in inputs.iter().enumerate() {
                    let ray = Ray::new(Vec3::ZERO, input.dir);
                    let expected = scene.triangle_hit(input.index, input.b, input.t, &ray);
                    assert_eq!(record_bits(&got.get(lane)), record_bits(&expected), "{name}: triangle {}", input.index);
                    compared += 1;
                    one_triangle += (c % 3 == 2 && inputs.len() > 1) as usize;
                    layer_compared += (input.index as usize >= scene.triangles.len()) as usize;
                }
            }
        }
        assert!(compared > 10_000 && layer_compared > 100 && one_triangle > 1000, "{compared} records compared, {layer_compared} of layer copies, {one_triangle} in batches of one triangle");
    }

    /// A flat triangle is shaded with its geometric normal itself, not a
    /// renormalised blend of three copies of it (which differs in the last
    /// bits for some weights), one hit at a time and in lanes, batches of
    /// one triangle and of several.
    #[test]
    fn flat_triangles_shade_with_their_geometric_normal() {
        let mut state = 5u64;
        let mut flat_hits = 0;
        // The built-ins' flat triangles are mostly axis-aligned quads, whose
        // blend renormalises to the same bits anyway: the bunny made flat
        // has normals in every direction.
        let flat_bunny = include_str!("../../assets/scenes/bunny.toml").replace("\"smooth\"", "\"flat\"");
        let base = std::path::Path::new(crate::scene::assets::BUILTIN_ROOT).join("scenes");
        let scenes = builtin::names().into_iter().map(|name| (name, builtin::load_builtin(name).unwrap().unwrap()));
        for (name, scene) in scenes.chain([("flat bunny", crate::scene::file::parse_scene(&flat_bunny, "flat bunny", &base, "flat-bunny").unwrap())]) {
            let flat: Vec<u32> = (0..scene.triangles.len() as u32).filter(|&i| scene.triangle(i).is_flat()).take(20_000).collect();
            // Several weights on each triangle of the small scenes.
            let rounds = (8000 / flat.len().max(1)).clamp(1, 64);
            for (c, chunk) in flat.chunks(HIT_LANES).cycle().take(rounds * flat.len().div_ceil(HIT_LANES)).enumerate() {
                let inputs: Vec<TriangleHitInput> = chunk
                    .iter()
                    .map(|&index| {
                        let index = if c % 2 == 1 { chunk[0] } else { index };
                        TriangleHitInput { index, b: weights_inside(&mut state), t: 1.0, dir: Vec3::new(0.3, -0.5, -0.81).normalize() }
                    })
                    .collect();
                let mut got = HitLanes::new();
                scene.triangle_hits(&inputs, &mut got);
                for (lane, input) in inputs.iter().enumerate() {
                    let one = scene.triangle_hit(input.index, input.b, input.t, &Ray::new(Vec3::ZERO, input.dir));
                    for h in [one, got.get(lane)] {
                        assert_eq!(h.shading_normal.to_array().map(f32::to_bits), h.geometric_normal.to_array().map(f32::to_bits), "{name}: triangle {} at {:?}", input.index, input.b);
                    }
                    flat_hits += 1;
                }
            }
        }
        assert!(flat_hits > 25_000, "{flat_hits} hits on flat triangles");
    }

    /// A rasterizer's eye samples built in lanes give, bit for bit, the
    /// record a one-sample replay builds: the eye ray of `eye_ray`, `t` the
    /// hit position's distance along it (`VisBuffer::triangle_b_t`), then
    /// `triangle_hit`; and the eye rays' directions.
    #[test]
    fn eye_samples_in_lanes_are_the_replays_records() {
        let mut compared = 0;
        let mut state = 11u64;
        for name in builtin::names().into_iter().chain(["forest-100"]) {
            let scene = builtin::load_builtin(name).unwrap().unwrap();
            let total = scene.triangles.len() + scene.layer.as_ref().map_or(0, |l| l.triangle_count().min(20_000) as usize);
            let view = scene.camera.view(97, 61);
            let step = (total / 1000).max(1);
            let indices: Vec<u32> = (0..total).step_by(step).map(|i| i as u32).collect();
            for chunk in indices.chunks(1 + compared % HIT_LANES) {
                let mut samples = EyeSamples::default();
                for &index in chunk {
                    // Weights with full mantissas, as interpolation makes them
                    // (sums and differences of them round).
                    let (b1, b2) = (next(&mut state).powi(3) * 0.6, next(&mut state) * 0.3 + 0.0123);
                    samples.push(index, b1, b2, Vec2::new(next(&mut state) * 97.0, next(&mut state) * 61.0));
                }
                let (mut got, mut dirs) = (HitLanes::new(), [[0.0; HIT_LANES]; 3]);
                scene.triangle_eye_hits(&view, &samples, &mut got, &mut dirs);
                for k in 0..chunk.len() {
                    let ray = view.eye_ray(samples.px[k], samples.py[k]);
                    let b = Vec3::new(1.0 - samples.b1[k] - samples.b2[k], samples.b1[k], samples.b2[k]);
                    let v = scene.triangle_positions(samples.index[k]);
                    let t = (v[0] * b.x + v[1] * b.y + v[2] * b.z - ray.origin).dot(ray.dir);
                    let expected = scene.triangle_hit(samples.index[k], b, t, &ray);
                    assert_eq!(record_bits(&got.get(k)), record_bits(&expected), "{name}: triangle {}", samples.index[k]);
                    assert_eq!([dirs[0][k], dirs[1][k], dirs[2][k]].map(f32::to_bits), ray.dir.to_array().map(f32::to_bits));
                    compared += 1;
                }
            }
        }
        assert!(compared > 3000, "only {compared} records compared");
    }
}
