//! Fixed-point edge functions with the top-left fill rule: watertight.
//!
//! Vertices are snapped to a grid of 1/256 pixel (8 bits of sub-pixel
//! precision); sample positions too. Edge functions are then exact integers
//! (i64, or i128 for triangles reaching millions of pixels off screen), so two
//! triangles sharing an edge compute exactly opposite values there, and the
//! top-left rule gives a sample lying exactly on the edge to exactly one of them:
//! no cracks and no double hits, whatever the mesh.

use crate::render::raster::rect::{tested_rect, PixelRect, TestCounter};
use crate::math::lanes::{mask_bits, simd_level};
use fearless_simd::{dispatch, i32x8, Simd, SimdBase};
use crate::render::raster::setup::ScreenTri;
use crate::render::raster::subpixel::{snap_offset, snap_to, ONE, SUBPIXEL_BITS};
use crate::math::Vec2;
use std::ops::{Add, Mul, Sub};

/// Vertices within +-2^21 pixels use i64 edge functions: every product stays below 2^61.
const NARROW_LIMIT: i64 = 1 << 29;

/// Integer types the edge functions are evaluated in.
pub trait EdgeInt: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Ord + From<i64> {}

impl EdgeInt for i64 {}

impl EdgeInt for i128 {}

/// A screen triangle with snapped vertices and integer edge equations.
#[derive(Clone, Copy, Debug)]
pub struct FixedTri {
    /// The float triangle (vertices 1 and 2 swapped if the snapped area needed it);
    /// its depth and barycentric attributes are interpolated.
    pub st: ScreenTri,
    pub v: [[i64; 2]; 3],
    /// Edge k (opposite vertex k): E_k(q) = a_k (q.x - o_k.x) + b_k (q.y - o_k.y),
    /// positive inside, with o_k the edge's start vertex.
    pub a: [i64; 3],
    pub b: [i64; 3],
    /// 0 on top and left edges (samples exactly on them are inside), 1 otherwise:
    /// a sample is covered when E_k >= bias_k for all k.
    pub bias: [i64; 3],
    /// The pass's (unsnapped) sample offset: interpolation happens at the true sample.
    pub sample_off: Vec2,
    pub bbox: PixelRect,
    /// Needs i128 evaluation.
    pub wide: bool,
    /// Too small for the sub-pixel grid (`small.rs`): coverage is decided by the
    /// ray casters' 3D test instead of the edge functions (`a`, `b` and
    /// `bias` are then unused), and `bbox` is the float box grown by a pixel.
    pub ray: bool,
}

/// Smallest pixel index whose snapped sample `i * ONE + off` is >= `v`.
#[inline]
fn first_at_or_after(v: i64, off: i64) -> i64 {
    (v - off + ONE - 1).div_euclid(ONE)
}

impl FixedTri {
    /// `None` when the snapped triangle has no area or covers no sample of the image.
    pub fn new(st: &ScreenTri, off: [i64; 2], sample_off: Vec2, width: u32, height: u32) -> Option<FixedTri> {
        FixedTri::on_grid(st, SUBPIXEL_BITS, off, sample_off, width, height)
    }

    /// `new` with the vertices snapped to `bits` bits of sub-pixel
    /// precision (`--subpixel-bits`): the edges move with them, while the
    /// shading weights stay those of the exact vertices.
    pub fn on_grid(st: &ScreenTri, bits: u32, off: [i64; 2], sample_off: Vec2, width: u32, height: u32) -> Option<FixedTri> {
        let mut st = *st;
        let mut v = st.p.map(|p| [snap_to(p.x, bits), snap_to(p.y, bits)]);
        let area = |v: &[[i64; 2]; 3]| -> i128 {
            (v[1][0] - v[0][0]) as i128 * (v[2][1] - v[0][1]) as i128 - (v[1][1] - v[0][1]) as i128 * (v[2][0] - v[0][0]) as i128
        };
        let a2 = area(&v);
        if a2 == 0 {
            return None;
        }
        if a2 < 0 {
            v.swap(1, 2);
            st.swap_12();
        }
        let ends = [(1, 2), (2, 0), (0, 1)];
        let a = ends.map(|(s, e)| v[s][1] - v[e][1]);
        let b = ends.map(|(s, e)| v[e][0] - v[s][0]);
        let bias = [0, 1, 2].map(|k| if a[k] > 0 || (a[k] == 0 && b[k] > 0) { 0 } else { 1 });
        let wide = v.iter().flatten().any(|c| c.abs() > NARROW_LIMIT);
        let lo = [0, 1].map(|i| v.iter().map(|p| p[i]).min().unwrap());
        let hi = [0, 1].map(|i| v.iter().map(|p| p[i]).max().unwrap());
        let span = |lo: i64, hi: i64, off: i64, n: u32| -> (u32, u32) {
            let a = first_at_or_after(lo, off).clamp(0, n as i64);
            let b = ((hi - off).div_euclid(ONE) + 1).clamp(0, n as i64);
            (a as u32, b as u32)
        };
        let (x0, x1) = span(lo[0], hi[0], off[0], width);
        let (y0, y1) = span(lo[1], hi[1], off[1], height);
        let bbox = PixelRect::new(x0, y0, x1, y1);
        if bbox.is_empty() {
            return None;
        }
        Some(FixedTri { st, v, a, b, bias, sample_off, bbox, wide, ray: false })
    }

    /// `new`, except that a triangle whose snapped vertices span fewer than
    /// `subpixel::SMALL_LIMIT` units on both axes is kept for the ray test (`ray`),
    /// whatever its snapped area, with its float box grown by a pixel (as
    /// `rasterize:bbox` grows it) so that the 3D test can reach every sample
    /// it would hit. Its edge functions are still those of its snapped
    /// vertices (all zero when they are collinear), for the painter's
    /// overlap test.
    pub fn new_or_small(st: &ScreenTri, bits: u32, off: [i64; 2], sample_off: Vec2, width: u32, height: u32) -> Option<FixedTri> {
        let v = st.p.map(|p| [snap_to(p.x, bits), snap_to(p.y, bits)]);
        let extent = |i: usize| v.iter().map(|p| p[i]).max().unwrap() - v.iter().map(|p| p[i]).min().unwrap();
        if extent(0).max(extent(1)) >= crate::render::raster::subpixel::SMALL_LIMIT {
            return FixedTri::on_grid(st, bits, off, sample_off, width, height);
        }
        let bbox = st.bbox.grown(1, width, height);
        Some(match FixedTri::on_grid(st, bits, off, sample_off, width, height) {
            Some(ft) => FixedTri { bbox, ray: true, ..ft },
            None => FixedTri { st: *st, v, a: [0; 3], b: [0; 3], bias: [1; 3], sample_off, bbox, wide: false, ray: true },
        })
    }

    /// Exact edge function k at the snapped sample point `(sx, sy)`.
    #[inline(always)]
    pub fn edge_at<T: EdgeInt>(&self, k: usize, sx: i64, sy: i64) -> T {
        let o = self.v[(k + 1) % 3];
        T::from(self.a[k]) * T::from(sx - o[0]) + T::from(self.b[k]) * T::from(sy - o[1])
    }

    /// The three edge functions at the sample of pixel `(x, y)`.
    #[inline(always)]
    pub fn edges_at_pixel<T: EdgeInt>(&self, x: u32, y: u32, off: [i64; 2]) -> [T; 3] {
        let sx = x as i64 * ONE + off[0];
        let sy = y as i64 * ONE + off[1];
        [self.edge_at(0, sx, sy), self.edge_at(1, sx, sy), self.edge_at(2, sx, sy)]
    }

    #[inline(always)]
    pub fn covered<T: EdgeInt>(&self, e: &[T; 3]) -> bool {
        e[0] >= T::from(self.bias[0]) && e[1] >= T::from(self.bias[1]) && e[2] >= T::from(self.bias[2])
    }

    /// Screen-space weights at the sample of pixel `(x, y)`, from the unsnapped
    /// float vertices (snapping decides coverage only, so shading stays as
    /// accurate as the float variants'). Evaluated directly, not stepped: the
    /// same bits whichever loop asks.
    #[inline(always)]
    pub fn weights(&self, x: u32, y: u32) -> [f32; 3] {
        self.st.screen_weights(Vec2::new(x as f32 + self.sample_off.x, y as f32 + self.sample_off.y))
    }
}

/// The pass's triangles set up and snapped, run by run (`setup::setup_pass_map`),
/// in order: those under half a pixel kept for the ray test, the others
/// dropped when degenerate after snapping (`FixedTri::new_or_small`). The
/// list `fixed`, `tiled` and the painter draw.
pub fn setup_snapped_or_small(job: &crate::render::PassJob, sample_off: Vec2, width: u32, height: u32) -> Vec<FixedTri> {
    setup_snapped_or_small_runs(job, sample_off, width, height).joined()
}

/// `setup_snapped_or_small`, run by run as the threads made them.
pub fn setup_snapped_or_small_runs(job: &crate::render::PassJob, sample_off: Vec2, width: u32, height: u32) -> crate::render::raster::runs::Runs<FixedTri> {
    let off = snap_offset(sample_off);
    let bits = job.settings.subpixel_bits;
    crate::render::raster::setup::setup_pass_map(job, |st| FixedTri::new_or_small(&st, bits, off, sample_off, width, height))
}

/// Every triangle snapped (in order; dropped when degenerate after snapping).
pub fn snap_triangles(tris: &[ScreenTri], sample_off: Vec2, width: u32, height: u32) -> Vec<FixedTri> {
    use rayon::prelude::*;
    let off = snap_offset(sample_off);
    tris.par_iter().filter_map(|st| FixedTri::new(st, off, sample_off, width, height)).collect()
}

/// Visits the covered samples of `ft` inside `rect`, stepping the integer edge
/// functions by additions, with their screen-space weights.
#[inline]
pub fn raster<C: TestCounter, F: FnMut(u32, u32, [f32; 3])>(ft: &FixedTri, rect: PixelRect, off: [i64; 2], tested: &mut C, mut emit: F) {
    raster_rows(ft, rect, off, tested, |x0, y, bits| {
        for x in row_pixels(x0, bits) {
            emit(x, y, ft.weights(x, y));
        }
    });
}

/// The pixels of a row run (`raster_rows`): `x0 + k` for each set bit k of
/// `bits`, in order.
#[inline(always)]
pub fn row_pixels(x0: u32, bits: u8) -> impl Iterator<Item = u32> {
    let mut m = bits;
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let k = m.trailing_zeros();
            m &= m - 1;
            x0 + k
        })
    })
}

/// `raster` a row at a time: for each run of up to eight pixels of a row,
/// the first pixel `(x0, y)` and its covered samples as bits (bit k: pixel
/// `x0 + k`), in the same order. For code that takes a row of samples at once.
pub fn raster_rows<C: TestCounter, F: FnMut(u32, u32, u8)>(ft: &FixedTri, rect: PixelRect, off: [i64; 2], tested: &mut C, emit: F) {
    let Some(r) = tested_rect(&ft.bbox, &rect, tested) else {
        return;
    };
    if ft.wide {
        return raster_in::<i128, F>(ft, r, off, emit);
    }
    match NarrowEdges::new(ft, r, off) {
        Some(edges) => dispatch!(simd_level(), simd => raster_lanes(simd, &edges, r, emit)),
        None => raster_in::<i64, F>(ft, r, off, emit),
    }
}

/// The pixels of `r` (already counted as tested) one at a time, in `T`.
#[inline(always)]
fn raster_in<T: EdgeInt, F: FnMut(u32, u32, u8)>(ft: &FixedTri, r: PixelRect, off: [i64; 2], mut emit: F) {
    let step_x = [0, 1, 2].map(|k| T::from(ft.a[k]) * T::from(ONE));
    let step_y = [0, 1, 2].map(|k| T::from(ft.b[k]) * T::from(ONE));
    let bias = ft.bias.map(T::from);
    let mut row: [T; 3] = ft.edges_at_pixel(r.x0, r.y0, off);
    for y in r.y0..r.y1 {
        let mut e = row;
        let mut x0 = r.x0;
        while x0 < r.x1 {
            let n = (r.x1 - x0).min(8);
            let mut bits = 0u8;
            for k in 0..n {
                if e[0] >= bias[0] && e[1] >= bias[1] && e[2] >= bias[2] {
                    bits |= 1 << k;
                }
                e[0] = e[0] + step_x[0];
                e[1] = e[1] + step_x[1];
                e[2] = e[2] + step_x[2];
            }
            if bits != 0 {
                emit(x0, y, bits);
            }
            x0 += n;
        }
        row[0] = row[0] + step_y[0];
        row[1] = row[1] + step_y[1];
        row[2] = row[2] + step_y[2];
    }
}

/// A triangle's edge functions over a pixel rectangle when every value the
/// eight-lane loop forms there fits in 32 bits (most triangles: those a
/// few hundred pixels across or less). Integers, so the lanes find exactly
/// the coverage `raster_in` finds.
struct NarrowEdges {
    /// At the rectangle's first pixel.
    row: [i64; 3],
    step_x: [i32; 3],
    step_y: [i64; 3],
    bias: [i32; 3],
}

impl NarrowEdges {
    fn new(ft: &FixedTri, r: PixelRect, off: [i64; 2]) -> Option<NarrowEdges> {
        let row: [i64; 3] = ft.edges_at_pixel(r.x0, r.y0, off);
        // The lanes reach up to seven pixels past the rectangle's right end,
        // and one step of eight beyond that after the last run; the values
        // are linear in x and y, so the extremes are at the corners.
        let last_x = ((r.x1 - r.x0).div_ceil(8) * 8 + 7) as i64;
        let last_y = (r.y1 - r.y0 - 1) as i64;
        let fits = |v: i64| v.abs() < i32::MAX as i64;
        let mut step_x = [0i32; 3];
        let mut step_y = [0i64; 3];
        for k in 0..3 {
            let (sx, sy) = (ft.a[k] * ONE, ft.b[k] * ONE);
            let corners = [row[k], row[k] + sx * last_x, row[k] + sy * last_y, row[k] + sx * last_x + sy * last_y];
            if !corners.into_iter().all(fits) || !fits(8 * sx) {
                return None;
            }
            (step_x[k], step_y[k]) = (sx as i32, sy);
        }
        Some(NarrowEdges { row, step_x, step_y, bias: ft.bias.map(|b| b as i32) })
    }
}

/// `raster_in` eight pixels of a row at a time: the three edge functions of
/// eight neighbouring pixels in lanes, compared with their biases at once.
// No closures below: they would be compiled apart from this function,
// without the SIMD level `dispatch` compiles it for.
#[inline(always)]
fn raster_lanes<S: Simd, F: FnMut(u32, u32, u8)>(simd: S, edges: &NarrowEdges, r: PixelRect, mut emit: F) {
    #[inline(always)]
    fn splat<S: Simd>(simd: S, v: i32) -> i32x8<S> {
        <i32x8<S> as SimdBase<S>>::splat(simd, v)
    }
    let lane = i32x8::from_slice(simd, &[0, 1, 2, 3, 4, 5, 6, 7]);
    let offsets = [lane * splat(simd, edges.step_x[0]), lane * splat(simd, edges.step_x[1]), lane * splat(simd, edges.step_x[2])];
    let run = [splat(simd, 8 * edges.step_x[0]), splat(simd, 8 * edges.step_x[1]), splat(simd, 8 * edges.step_x[2])];
    let bias = [splat(simd, edges.bias[0]), splat(simd, edges.bias[1]), splat(simd, edges.bias[2])];
    let mut row = edges.row;
    for y in r.y0..r.y1 {
        let mut e = [splat(simd, row[0] as i32) + offsets[0], splat(simd, row[1] as i32) + offsets[1], splat(simd, row[2] as i32) + offsets[2]];
        let mut x0 = r.x0;
        while x0 < r.x1 {
            let n = (r.x1 - x0).min(8);
            let inside = e[0].simd_ge(bias[0]) & e[1].simd_ge(bias[1]) & e[2].simd_ge(bias[2]);
            let bits = mask_bits(inside) & (0xffu8 >> (8 - n));
            if bits != 0 {
                emit(x0, y, bits);
            }
            e = [e[0] + run[0], e[1] + run[1], e[2] + run[2]];
            x0 += n;
        }
        row = [row[0] + edges.step_y[0], row[1] + edges.step_y[1], row[2] + edges.step_y[2]];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cover(p: [Vec2; 3], w: u32, h: u32) -> Vec<(u32, u32)> {
        let st = ScreenTri::flat(0, p, Vec2::splat(0.5), w, h).unwrap();
        let off = snap_offset(Vec2::splat(0.5));
        let ft = FixedTri::new(&st, off, Vec2::splat(0.5), w, h).unwrap();
        let mut out = Vec::new();
        let mut tested = 0u64;
        raster(&ft, PixelRect::new(0, 0, w, h), off, &mut tested, |x, y, _| out.push((x, y)));
        out.sort();
        out
    }

    #[test]
    fn small_triangle_coverage_by_hand() {
        // Right triangle (0,0), (4,0), (0,4): the samples (x+0.5, y+0.5) with
        // x + y + 1 < 4 are strictly inside: x + y <= 2, six of them. The
        // samples with x + y + 1 == 4 lie on the hypotenuse, which in image
        // coordinates (y down) is a bottom-right edge: excluded.
        let c = cover([Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0), Vec2::new(0.0, 4.0)], 8, 8);
        assert_eq!(c, vec![(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (2, 0)]);
        // The mirrored triangle (4,4), (0,4), (4,0) owns that hypotenuse (its left
        // edge) and the rest of the square: the two together cover each of the
        // 16 samples exactly once.
        let d = cover([Vec2::new(4.0, 4.0), Vec2::new(0.0, 4.0), Vec2::new(4.0, 0.0)], 8, 8);
        assert_eq!(d.len(), 10);
        let mut all: Vec<_> = c.iter().chain(&d).copied().collect();
        all.sort();
        all.dedup();
        assert_eq!(all.len(), 16);
    }

    #[test]
    fn edge_values_by_hand() {
        // Triangle (1,1), (5,1), (1,5); sample of pixel (1,1) = (1.5, 1.5).
        // Twice the area = 16 px^2 = 16 * 256^2 units. Edge (5,1)->(1,5) at the
        // sample: (-4)(0.5) - (4)(-3.5) = 12 px^2; edges (1,5)->(1,1) and
        // (1,1)->(5,1): 2 px^2 each. Screen weights 12/16, 2/16, 2/16.
        let st = ScreenTri::flat(0, [Vec2::new(1.0, 1.0), Vec2::new(5.0, 1.0), Vec2::new(1.0, 5.0)], Vec2::splat(0.5), 8, 8).unwrap();
        let off = snap_offset(Vec2::splat(0.5));
        let ft = FixedTri::new(&st, off, Vec2::splat(0.5), 8, 8).unwrap();
        let e: [i64; 3] = ft.edges_at_pixel(1, 1, off);
        assert_eq!(e, [12 * 65536, 2 * 65536, 2 * 65536]);
        assert_eq!(ft.weights(1, 1), [0.75, 0.125, 0.125]);
        // Left edge x = 1 and top edge y = 1 are top-left; the hypotenuse is not.
        assert_eq!(ft.bias, [1, 0, 0]);
        assert_eq!(ft.bbox, PixelRect::new(1, 1, 5, 5));
    }

    #[test]
    fn triangles_under_half_a_pixel_take_the_ray_test() {
        let st = |p: [Vec2; 3]| ScreenTri::flat(0, p, Vec2::splat(0.5), 16, 16).unwrap();
        let off = snap_offset(Vec2::splat(0.5));
        let make = |p| FixedTri::new_or_small(&st(p), SUBPIXEL_BITS, off, Vec2::splat(0.5), 16, 16);
        // 0.49 px across: small, its box that of the float triangle grown by a pixel.
        let tiny = make([Vec2::new(4.3, 4.3), Vec2::new(4.79, 4.3), Vec2::new(4.3, 4.79)]).unwrap();
        assert!(tiny.ray);
        assert_eq!(tiny.bbox, st(tiny.st.p).bbox.grown(1, 16, 16));
        // A sliver whose snapped vertices are collinear (no area on the grid)
        // is kept for the ray test, where `new` drops it.
        let sliver = [Vec2::new(4.3, 4.5), Vec2::new(4.7, 4.5), Vec2::new(4.5, 4.5 + 0.3 / 256.0)];
        assert!(FixedTri::new(&st(sliver), off, Vec2::splat(0.5), 16, 16).is_none());
        assert!(make(sliver).unwrap().ray);
        // Half a pixel along one axis: on the grid, exactly as `new` makes it.
        let half = [Vec2::new(4.3, 4.3), Vec2::new(4.8, 4.3), Vec2::new(4.3, 4.8)];
        let (a, b) = (make(half).unwrap(), FixedTri::new(&st(half), off, Vec2::splat(0.5), 16, 16).unwrap());
        assert!(!a.ray);
        assert_eq!((a.v, a.a, a.b, a.bias, a.bbox), (b.v, b.a, b.b, b.bias, b.bbox));
    }

    /// The eight-lane loop hands over exactly the runs the one-pixel loop
    /// does, on random triangles from a few pixels to thousands across
    /// (those fall back to 64 bits), over the whole image and over tiles.
    #[test]
    fn lanes_cover_exactly_what_one_pixel_at_a_time_covers() {
        let mut state = 11u64;
        let mut next = move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        };
        let (w, h) = (300u32, 200u32);
        let off = snap_offset(Vec2::splat(0.5));
        let (mut narrow, mut wider, mut runs) = (0, 0, 0);
        for i in 0..4000 {
            let scale = [3.0, 20.0, 150.0, 6000.0][i % 4];
            let centre = Vec2::new(next() * w as f32, next() * h as f32);
            let mut p = [0, 1, 2].map(|_| centre + Vec2::new(next() - 0.5, next() - 0.5) * scale);
            if i % 2 == 1 {
                // Vertices on the half-pixel grid: edges through samples, where
                // only the tie rule decides.
                p = p.map(|v| (v * 2.0).round() / 2.0);
            }
            let Some(st) = ScreenTri::flat(0, p, Vec2::splat(0.5), w, h) else { continue };
            let Some(ft) = FixedTri::new(&st, off, Vec2::splat(0.5), w, h) else { continue };
            let rect = if i % 3 == 0 {
                let (x, y) = ((next() * w as f32) as u32 / 64 * 64, (next() * h as f32) as u32 / 64 * 64);
                PixelRect::new(x, y, (x + 64).min(w), (y + 64).min(h))
            } else {
                PixelRect::new(0, 0, w, h)
            };
            let mut lanes = Vec::new();
            raster_rows(&ft, rect, off, &mut 0u64, |x, y, bits| lanes.push((x, y, bits)));
            let mut one_by_one = Vec::new();
            if let Some(r) = tested_rect(&ft.bbox, &rect, &mut 0u64) {
                raster_in::<i64, _>(&ft, r, off, |x, y, bits| one_by_one.push((x, y, bits)));
                if NarrowEdges::new(&ft, r, off).is_some() { narrow += 1 } else { wider += 1 }
            }
            assert_eq!(lanes, one_by_one, "triangle {i}: {p:?} in {rect:?}");
            runs += lanes.len();
        }
        assert!(narrow > 1000 && wider > 100 && runs > 10_000, "{narrow} narrow, {wider} wider, {runs} runs");
    }

    #[test]
    fn huge_triangles_use_exact_wide_arithmetic() {
        // A triangle reaching ten million pixels off screen still covers the
        // image exactly like its small, similar counterpart inside the image.
        let big = [Vec2::new(-1.0e7, -1.0e7), Vec2::new(3.0e7, -1.0e7), Vec2::new(-1.0e7, 3.0e7)];
        let st = ScreenTri::flat(0, big, Vec2::splat(0.5), 16, 16).unwrap();
        let off = snap_offset(Vec2::splat(0.5));
        let ft = FixedTri::new(&st, off, Vec2::splat(0.5), 16, 16).unwrap();
        assert!(ft.wide);
        let mut n = 0;
        let mut tested = 0u64;
        raster(&ft, PixelRect::new(0, 0, 16, 16), off, &mut tested, |_, _, _| n += 1);
        assert_eq!(n, 256);
    }
}
