//! Random numbers and direction sampling for the stochastic shading modes
//! (ambient occlusion, path tracing, photon mapping). Every number is a pure
//! function of (pixel, sample index, seed) and its position in the stream, so
//! images never depend on the thread count and a replayed pixel draws exactly
//! the numbers its frame drew.

use crate::math::lanes::{cos_sin_turns, Lane, V3};
use fearless_simd::{u16x16, u32x8, Bytes, Simd, SimdBase, SimdFrom};
use crate::math::{Vec2, Vec3};
use std::f32::consts::PI;

/// The uniform numbers of one sample: a counter hashed with the sample's key
/// (a counter-based generator: no state is shared between samples).
#[derive(Clone, Debug)]
pub struct SampleRng {
    key: u64,
    counter: u64,
    /// This sample's index among the pixel's `spp`, and the 2D dimensions
    /// drawn so far: the first `STRATIFIED_PAIRS` pairs are stratified
    /// across the pixel's samples (each sample takes its own cell, the
    /// cells shuffled per pixel and dimension), as a stratified sampler does.
    sample: u32,
    spp: u32,
    pairs: u32,
    /// `sqrt(spp)` when `spp` is a square (the cells form a grid), else 0
    /// (a Latin hypercube): fixed per stream, so worked out once.
    grid: u32,
}

/// `SampleRng::grid` for `spp` samples.
#[inline(always)]
fn grid_side(spp: u32) -> u32 {
    // Every stream of a frame asks this (one per sample and lane, even
    // where nothing is drawn), so the common counts skip the square root:
    // 4^k is the square of 2^k, and other powers of two are no squares.
    if spp.is_power_of_two() {
        let k = spp.trailing_zeros();
        return if k % 2 == 0 { 1 << (k / 2) } else { 0 };
    }
    let n = (spp as f32).sqrt().round() as u32;
    if n * n == spp { n } else { 0 }
}

/// How many 2D draws per sample are stratified across the pixel's samples;
/// later ones (deep bounces, where stratification no longer pays) are plain.
const STRATIFIED_PAIRS: u32 = 8;

/// The 64-bit finalizer of SplitMix64: a bijection that scrambles every input
/// bit into every output bit.
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// Two numbers in [0, 1) that are a pure function of `key` and `seed`
/// (for draws shared by every pixel, such as a pass's sub-pixel jitter).
pub fn hashed_unit_pair(key: u64, seed: u64) -> Vec2 {
    let h = mix64(key.wrapping_mul(GOLDEN) ^ mix64(seed ^ 0x5851_F42D_4C95_7F2D));
    // 24 bits each, so the f32 is exact and below 1.
    let unit = |bits: u64| (bits & 0xFF_FFFF) as f32 / (1u64 << 24) as f32;
    Vec2::new(unit(h), unit(h >> 32))
}

impl SampleRng {
    /// The stream of sample `sample` of pixel `pixel` (`x + y * width`).
    /// Cheap to make: the key is scrambled on the first draw, so samples
    /// that draw nothing (direct light only) pay nothing.
    #[inline]
    pub fn for_pixel(pixel: u32, sample: u32, seed: u64) -> SampleRng {
        SampleRng::stratified(pixel, sample, 1, seed)
    }

    /// As `for_pixel`, for sample `sample` of `spp`, with the first 2D draws
    /// stratified across the pixel's `spp` samples.
    #[inline]
    pub fn stratified(pixel: u32, sample: u32, spp: u32, seed: u64) -> SampleRng {
        // The key names the pixel only: the samples of a pixel share their
        // cell shuffles and differ in which cell they take.
        let key = (pixel as u64) ^ seed.wrapping_mul(GOLDEN).rotate_left(17);
        SampleRng { key, counter: (sample as u64) << 32, sample, spp: spp.max(1), pairs: 0, grid: grid_side(spp.max(1)) }
    }

    /// The stream of item `index` of an enumerated task (`stream` names the
    /// task, e.g. photon shooting), apart from every pixel's stream.
    pub fn for_index(stream: u64, index: u64, seed: u64) -> SampleRng {
        SampleRng { key: mix64(seed.wrapping_add(GOLDEN)) ^ mix64(stream.wrapping_mul(GOLDEN) ^ index) ^ (1 << 63), counter: 0, sample: 0, spp: 1, pairs: 0, grid: 1 }
    }

    /// Uniform in [0, 1): 24 random bits, so 1.0 itself is never returned.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_bits() >> 40) as f32 * (1.0 / 16_777_216.0)
    }

    #[inline]
    fn next_bits(&mut self) -> u64 {
        if self.counter & 0xffff_ffff == 0 {
            self.key = mix64(self.key);
        }
        self.counter += 1;
        mix64(self.key.wrapping_add(self.counter.wrapping_mul(GOLDEN)))
    }

    /// A point in [0, 1)^2: jittered within this sample's cell of the
    /// pixel's stratification for the first draws, uniform after.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        match self.next_2d_begin() {
            Draw2d::Point(point) => point,
            Draw2d::Unplaced { jitter, shuffle } => {
                let second = if self.grid == 0 { permute(self.sample, self.spp, (shuffle >> 32) as u32) } else { 0 };
                self.place_2d(jitter, permute(self.sample, self.spp, shuffle as u32), second)
            }
        }
    }

    /// `next_2d` up to the choice of the sample's cell (see `Draw2d`):
    /// the steps `StreamLanes::next_2d` takes in lanes.
    #[inline(always)]
    fn next_2d_begin(&mut self) -> Draw2d {
        let jitter = Vec2::new(self.next_f32(), self.next_f32());
        if self.spp == 1 || self.pairs >= STRATIFIED_PAIRS {
            return Draw2d::Point(jitter);
        }
        // One shuffle of the cells per pixel and dimension, the same for
        // all the pixel's samples (derived from the key, not the counter).
        let shuffle = mix64(self.key ^ (self.pairs as u64 + 1).wrapping_mul(GOLDEN));
        self.pairs += 1;
        Draw2d::Unplaced { jitter, shuffle }
    }

    /// `next_2d`'s point from `next_2d_begin`'s jitter and the permuted
    /// sample index under the shuffle key's low half (`first`) and high
    /// half (`second`, read only for a Latin hypercube).
    #[inline]
    fn place_2d(&self, jitter: Vec2, first: u32, second: u32) -> Vec2 {
        place_in_cell(jitter, first, second, self.grid, self.spp)
    }

    /// The pixel's sample count (at least 1).
    #[inline]
    pub fn spp(&self) -> u32 {
        self.spp
    }
}

/// Up to eight streams' states side by side, for a draw that each of them
/// makes at the same point: the 64-bit hashes of eight streams are then
/// computed together in vector lanes, giving each stream the very bits its
/// own draws give (lanes not loaded hold a zero stream whose results are
/// ignored).
pub struct StreamLanes {
    key: [u64; 8],
    counter: [u64; 8],
    pairs: [u32; 8],
    spp: [u32; 8],
    sample: [u32; 8],
}

impl Default for StreamLanes {
    fn default() -> Self {
        // Counters past a first draw, so that lanes never loaded do not
        // make every draw scramble keys.
        StreamLanes { key: [0; 8], counter: [1; 8], pairs: [0; 8], spp: [1; 8], sample: [0; 8] }
    }
}

impl StreamLanes {
    /// Lane `k` takes `rng`'s state.
    #[inline(always)]
    pub fn load(&mut self, k: usize, rng: &SampleRng) {
        (self.key[k], self.counter[k], self.pairs[k], self.spp[k], self.sample[k]) = (rng.key, rng.counter, rng.pairs, rng.spp, rng.sample);
    }

    /// `rng` takes lane `k`'s state (after the draws), as if it had drawn them itself.
    #[inline(always)]
    pub fn store(&self, k: usize, rng: &mut SampleRng) {
        (rng.key, rng.counter, rng.pairs) = (self.key[k], self.counter[k], self.pairs[k]);
    }

    /// `SampleRng::next_bits` in every lane.
    #[inline(always)]
    fn next_bits(&mut self) -> [u64; 8] {
        // The key is scrambled at a sample's first draw only (a counter's
        // low half is zero then), rarely in lanes together.
        if self.counter.iter().any(|c| c & 0xffff_ffff == 0) {
            // Array maps of `mix64` compile to vector multiplies where the
            // SIMD level has them.
            let mixed = self.key.map(mix64);
            for k in 0..8 {
                if self.counter[k] & 0xffff_ffff == 0 {
                    self.key[k] = mixed[k];
                }
            }
        }
        let mut z = [0u64; 8];
        for k in 0..8 {
            self.counter[k] += 1;
            z[k] = self.key[k].wrapping_add(self.counter[k].wrapping_mul(GOLDEN));
        }
        z.map(mix64)
    }

    /// `SampleRng::next_f32` in every lane.
    #[inline(always)]
    pub fn next_f32(&mut self) -> [f32; 8] {
        self.next_bits().map(|b| (b >> 40) as f32 * (1.0 / 16_777_216.0))
    }

    /// `SampleRng::next_2d_begin` in every lane: the jitters, the shuffle
    /// keys, and the lanes whose draw is stratified (`Draw2d::Unplaced`;
    /// the others' point is their jitter).
    #[inline(always)]
    fn next_2d_begin(&mut self) -> ([[f32; 8]; 2], [u64; 8], u8) {
        let jitter = [self.next_f32(), self.next_f32()];
        let mut stratified = 0u8;
        let mut z = [0u64; 8];
        for k in 0..8 {
            let s = self.spp[k] != 1 && self.pairs[k] < STRATIFIED_PAIRS;
            stratified |= (s as u8) << k;
            z[k] = self.key[k] ^ (self.pairs[k] as u64 + 1).wrapping_mul(GOLDEN);
            self.pairs[k] += s as u32;
        }
        (jitter, z.map(mix64), stratified)
    }

    /// `SampleRng::next_2d` in every lane (the points of lanes outside
    /// `lanes` mean nothing). Streams that share a power-of-two sample
    /// count (a frame's) have their cells' permutations made in lanes too.
    #[inline(always)]
    pub fn next_2d<S: Simd>(&mut self, simd: S, lanes: u8) -> [[f32; 8]; 2] {
        let (mut u, shuffle, stratified) = self.next_2d_begin();
        let placed = stratified & lanes;
        if placed == 0 {
            return u;
        }
        let spp = self.spp[placed.trailing_zeros() as usize];
        let grid = grid_side(spp);
        let shared = (0..8).all(|k| placed & 1 << k == 0 || self.spp[k] == spp);
        let (mut low, mut high) = ([0u32; 8], [0u32; 8]);
        if shared && spp.is_power_of_two() {
            low = permute_pow2_lanes(simd, self.sample, spp, shuffle.map(|key| key as u32));
            // Only a Latin hypercube (no square grid) reads the second.
            if grid == 0 {
                high = permute_pow2_lanes(simd, self.sample, spp, shuffle.map(|key| (key >> 32) as u32));
            }
        } else {
            for k in (0..8).filter(|k| placed & 1 << k != 0) {
                low[k] = permute(self.sample[k], self.spp[k], shuffle[k] as u32);
                high[k] = permute(self.sample[k], self.spp[k], (shuffle[k] >> 32) as u32);
            }
        }
        for k in (0..8).filter(|k| placed & 1 << k != 0) {
            let p = place_in_cell(Vec2::new(u[0][k], u[1][k]), low[k], high[k], grid_side(self.spp[k]), self.spp[k]);
            (u[0][k], u[1][k]) = (p.x, p.y);
        }
        u
    }
}

/// The largest float below 1: a point placed in the last cell stays in [0, 1).
const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// `SampleRng::place_2d` for a stream with `grid` and `spp`.
#[inline]
fn place_in_cell(jitter: Vec2, first: u32, second: u32, grid: u32, spp: u32) -> Vec2 {
    let n = grid;
    if n != 0 {
        let cell = first;
        let (column, row) = if n.is_power_of_two() { (cell & (n - 1), cell >> n.trailing_zeros()) } else { (cell % n, cell / n) };
        Vec2::new(over(column as f32 + jitter.x, n), over(row as f32 + jitter.y, n))
    } else {
        // Latin hypercube: a shuffled stratum per axis.
        Vec2::new(over(first as f32 + jitter.x, spp), over(second as f32 + jitter.y, spp))
    }
    .min(Vec2::splat(BELOW_ONE))
}

/// A 2D draw begun by `SampleRng::next_2d_begin`.
enum Draw2d {
    /// The point itself (this draw is not stratified).
    Point(Vec2),
    /// The jitter within the sample's cell, and the shuffle key whose
    /// permutations of the sample's index among the pixel's
    /// (`permute(sample, spp, key)` with the key's low half, and for a
    /// Latin hypercube also with its high half) pick the cell:
    /// `SampleRng::place_2d` takes them.
    Unplaced { jitter: Vec2, shuffle: u64 },
}

/// `x / n`. For a power of two it multiplies by the exact reciprocal, which
/// gives the same bits as the division without its latency: the common
/// sample counts (4, 16, 64, ...) take this path on every bounce.
#[inline(always)]
fn over(x: f32, n: u32) -> f32 {
    if n.is_power_of_two() { x * (1.0 / n as f32) } else { x / n as f32 }
}

/// A pseudo-random permutation of `0..len` chosen by `key`: `i` maps to a
/// distinct value below `len` (Kensler, "Correlated Multi-Jittered
/// Sampling", 2013: invertible hashing on the next power of two, walked
/// until it lands below `len`).
#[inline(always)]
pub fn permute(mut i: u32, len: u32, key: u32) -> u32 {
    if len <= 1 {
        return 0;
    }
    // All ones up to the highest bit of len - 1 (len >= 2 here).
    let w = u32::MAX >> (len - 1).leading_zeros();
    let p = key;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dcb303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e501cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860a3df);
        i &= w;
        i ^= i >> 5;
        // A power of two is never left: i <= w = len - 1 already.
        if len.is_power_of_two() || i < len {
            // `% len`, without a division when `len` is a power of two.
            let i = i.wrapping_add(p);
            return if len.is_power_of_two() { i & w } else { i % len };
        }
    }
}

/// `permute` of eight indices at once, each under its own key, all with
/// the same power-of-two `len`: the same arithmetic in 32-bit lanes (for a
/// power of two the walk ends after one round).
///
/// Only the low log2(len) bits of the answer are kept, and every step
/// (xor, multiply, add, shifts of the masked value) gives its low bits from
/// the low bits of what it takes. So for a `len` up to 2^16 the multiplies
/// keep only each lane's low 16 bits (16-bit multiplies, half the latency
/// of 32-bit ones on x86, where this chain of six waits on them): the
/// answer is the same bit for bit.
#[inline(always)]
fn permute_pow2_lanes<S: Simd>(simd: S, i: [u32; 8], len: u32, key: [u32; 8]) -> [u32; 8] {
    debug_assert!(len.is_power_of_two());
    if len <= 1 {
        return [0; 8];
    }
    let narrow = len <= 1 << 16;
    let mul = |a: u32x8<S>, b: u32x8<S>| -> u32x8<S> {
        if narrow {
            (a.bitcast::<u16x16<S>>() * b.bitcast::<u16x16<S>>()).bitcast()
        } else {
            a * b
        }
    };
    let w = u32x8::splat(simd, len - 1);
    let p = u32x8::simd_from(simd, key);
    let c = |v: u32| u32x8::splat(simd, v);
    let mut i = u32x8::simd_from(simd, i);
    i ^= p;
    i = mul(i, c(0xe170893d));
    i ^= p >> 16;
    i ^= (i & w) >> 4;
    i ^= p >> 8;
    i = mul(i, c(0x0929eb3f));
    i ^= p >> 23;
    i ^= (i & w) >> 1;
    i = mul(i, c(1) | p >> 27);
    i = mul(i, c(0x6935fa69));
    i ^= (i & w) >> 11;
    i = mul(i, c(0x74dcb303));
    i ^= (i & w) >> 2;
    i = mul(i, c(0x9e501cc3));
    i ^= (i & w) >> 2;
    i = mul(i, c(0xc860a3df));
    i &= w;
    i ^= i >> 5;
    ((i + p) & w).into()
}

/// Two unit tangents completing `n` (unit) to a right-handed orthonormal
/// basis, without a branch on a chosen axis (Duff et al., "Building an
/// Orthonormal Basis, Revisited", 2017).
#[inline]
pub fn tangents(n: Vec3) -> (Vec3, Vec3) {
    let (t, b) = tangents_lanes(V3::from(n));
    (t.into(), b.into())
}

/// `tangents` over lanes.
#[inline(always)]
pub fn tangents_lanes<L: Lane>(n: V3<L>) -> (V3<L>, V3<L>) {
    let one = n.z.splat(1.0);
    let sign = one.copysign(n.z);
    let a = -one / (sign + n.z);
    let b = n.x * n.y * a;
    (V3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x), V3::new(b, sign + n.y * n.y * a, -n.y))
}

/// `local` (z along `n`) in world space.
#[inline]
pub fn from_local(local: Vec3, n: Vec3) -> Vec3 {
    from_local_lanes(V3::from(local), V3::from(n)).into()
}

/// `from_local` over lanes.
#[inline(always)]
pub fn from_local_lanes<L: Lane>(local: V3<L>, n: V3<L>) -> V3<L> {
    let (t, b) = tangents_lanes(n);
    t.scale(local.x) + b.scale(local.y) + n.scale(local.z)
}

/// A direction about the local z axis with density cos(theta) / pi: points
/// spread uniformly on the unit disk, lifted onto the hemisphere (Malley).
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    cosine_hemisphere_lanes(u.x, u.y).into()
}

/// `cosine_hemisphere` over lanes, for the point (`ux`, `uy`).
#[inline(always)]
pub fn cosine_hemisphere_lanes<L: Lane>(ux: L, uy: L) -> V3<L> {
    let r = ux.sqrt();
    let (cos, sin) = cos_sin_turns(uy);
    V3::new(r * cos, r * sin, (ux.splat(1.0) - ux).max(ux.splat(0.0)).sqrt())
}

#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cosine_hemisphere_pdf_lanes(cos_theta)
}

/// `cosine_hemisphere_pdf` over lanes.
#[inline(always)]
pub fn cosine_hemisphere_pdf_lanes<L: Lane>(cos_theta: L) -> L {
    cos_theta.max(cos_theta.splat(0.0)) * cos_theta.splat(1.0 / PI)
}

/// A half vector about the local z axis with density
/// `(s + 1) / (2 pi) cos(theta_h)^s`, the distribution of the Blinn-Phong lobe.
#[inline]
pub fn blinn_phong_half(u: Vec2, sharpness: f32) -> Vec3 {
    let cos_h = u.x.powf(1.0 / (sharpness + 1.0));
    let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h)
}

/// The density of `blinn_phong_half`'s half vector, as a density of the
/// reflected direction: divided by the Jacobian `4 |w_o . h|` of reflection.
#[inline]
pub fn blinn_phong_pdf(n: Vec3, w_o: Vec3, w_i: Vec3, sharpness: f32) -> f32 {
    let h = (w_i + w_o).normalize_or_zero();
    let cos_h = n.dot(h);
    let o_h = w_o.dot(h);
    if cos_h <= 0.0 || o_h <= 0.0 {
        return 0.0;
    }
    (sharpness + 1.0) / (2.0 * PI) * cos_h.powf(sharpness) / (4.0 * o_h)
}

/// The reflection of `w` (pointing away from the surface) about `h`.
#[inline]
pub fn reflect(w: Vec3, h: Vec3) -> Vec3 {
    2.0 * w.dot(h) * h - w
}

/// Uniform on the unit sphere (photons leaving a point light).
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform on the unit disk (photons of a directional light leave a disk).
#[inline]
pub fn uniform_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    Vec2::new(r * phi.cos(), r * phi.sin())
}

/// Uniform on the unit disk by Shirley and Chiu's concentric map: the
/// unit square's nested squares go to nested circles, so strata of the
/// square stay compact on the disk (a lens's samples).
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let (a, b) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) = if a.abs() > b.abs() { (a, 0.25 * PI * (b / a)) } else { (b, 0.5 * PI - 0.25 * PI * (a / b)) };
    Vec2::new(r * phi.cos(), r * phi.sin())
}

/// Luminance weights of linear sRGB (Rec. 709), for choosing between lobes
/// and for Russian roulette.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn streams_are_pure_functions_of_their_key() {
        let draw = |mut r: SampleRng| (0..8).map(|_| r.next_f32().to_bits()).collect::<Vec<_>>();
        assert_eq!(draw(SampleRng::for_pixel(7, 3, 1)), draw(SampleRng::for_pixel(7, 3, 1)));
        assert_ne!(draw(SampleRng::for_pixel(7, 3, 1)), draw(SampleRng::for_pixel(7, 4, 1)));
        assert_ne!(draw(SampleRng::for_pixel(7, 3, 1)), draw(SampleRng::for_pixel(8, 3, 1)));
        assert_ne!(draw(SampleRng::for_pixel(7, 3, 1)), draw(SampleRng::for_pixel(7, 3, 2)));
        assert_ne!(draw(SampleRng::for_pixel(0, 0, 0)), draw(SampleRng::for_index(1, 0, 0)));
    }

    #[test]
    fn division_by_a_power_of_two_is_exact_multiplication() {
        // `over` must give the bits of `x / n` (images stay what they were).
        let mut r = SampleRng::for_index(3, 0, 0);
        for n in [1u32, 2, 4, 8, 16, 64, 1024, 3, 5, 100] {
            for _ in 0..10_000 {
                let x = r.next_f32() * n as f32 + r.next_f32();
                assert_eq!(over(x, n).to_bits(), (x / n as f32).to_bits(), "{x} / {n}");
            }
        }
    }

    #[test]
    fn grid_side_is_the_square_root_of_squares_only() {
        for spp in 1..=70_000u32 {
            let root = (1..=spp).take_while(|r| r * r <= spp).last().unwrap();
            let expected = if root * root == spp { root } else { 0 };
            assert_eq!(grid_side(spp), expected, "spp {spp}");
        }
    }

    #[test]
    fn permute_is_a_permutation() {
        for len in [1u32, 2, 3, 5, 16, 17, 64, 100, 1000] {
            for key in [0u32, 1, 0xdead_beef, 12345] {
                let mut seen: Vec<u32> = (0..len).map(|i| permute(i, len, key)).collect();
                seen.sort();
                assert_eq!(seen, (0..len).collect::<Vec<_>>(), "len {len} key {key}");
            }
        }
    }

    #[test]
    fn permuting_eight_at_once_matches_one_at_a_time() {
        let mut r = SampleRng::for_index(11, 0, 0);
        // Around 2^16, where the lanes change from 16-bit to 32-bit multiplies.
        for len in [1u32, 2, 4, 8, 16, 64, 256, 1 << 15, 1 << 16, 1 << 17, 1 << 20] {
            for _ in 0..200 {
                let i: [u32; 8] = std::array::from_fn(|_| (r.next_f32() * len as f32) as u32);
                let key: [u32; 8] = std::array::from_fn(|_| r.next_bits() as u32);
                let wide = fearless_simd::dispatch!(crate::math::lanes::simd_level(), simd => permute_pow2_lanes(simd, i, len, key));
                for k in 0..8 {
                    assert_eq!(wide[k], permute(i[k], len, key[k]), "len {len}, index {}, key {:#x}", i[k], key[k]);
                }
            }
        }
    }

    #[test]
    fn a_2d_draw_in_two_steps_is_the_draw_in_one() {
        for spp in [1u32, 2, 4, 5, 8, 9, 16] {
            for sample in 0..spp {
                let (mut one, mut two) = (SampleRng::stratified(77, sample, spp, 5), SampleRng::stratified(77, sample, spp, 5));
                for _ in 0..12 {
                    let want = one.next_2d();
                    let got = match two.next_2d_begin() {
                        Draw2d::Point(p) => p,
                        Draw2d::Unplaced { jitter, shuffle: key } => {
                            let (n, i) = (two.spp, two.sample);
                            two.place_2d(jitter, permute(i, n, key as u32), if two.grid == 0 { permute(i, n, (key >> 32) as u32) } else { u32::MAX })
                        }
                    };
                    assert_eq!(got.to_array().map(f32::to_bits), want.to_array().map(f32::to_bits), "spp {spp}, sample {sample}");
                }
            }
        }
    }

    /// The lanes of `streams` whose bit is set in `loaded`, side by side.
    fn load_lanes(streams: &[SampleRng], loaded: u8) -> StreamLanes {
        let mut lanes = StreamLanes::default();
        for (k, r) in streams.iter().enumerate() {
            if loaded & 1 << k != 0 {
                lanes.load(k, r);
            }
        }
        lanes
    }

    #[test]
    fn draws_in_lanes_are_each_streams_own() {
        // Streams at their first draw (the key is scrambled then), midway,
        // past the stratified pairs, with one sample, and one whose
        // counter's low half wraps at the second draw.
        let mut streams: Vec<SampleRng> = (0..8u32).map(|k| SampleRng::stratified(1000 + k, k % 4, [16, 16, 1, 9, 16, 5, 16, 16][k as usize], 3)).collect();
        for _ in 0..3 {
            streams[1].next_2d();
        }
        for _ in 0..9 {
            streams[4].next_2d();
        }
        streams[6].counter |= 0xffff_ffff;
        for round in 0..12 {
            // Lane 3 is left out in odd rounds, as a lane without a sample is.
            let loaded = if round % 2 == 1 { 0b1111_0111u8 } else { 0xff };
            let mut lanes = load_lanes(&streams, loaded);
            let skipped = lanes.next_f32();
            // Every third round draws whole points, the others begin them.
            let whole = (round % 3 == 2).then(|| fearless_simd::dispatch!(crate::math::lanes::simd_level(), simd => lanes.next_2d(simd, loaded)));
            let (jitter, shuffle, stratified) = if whole.is_none() { lanes.next_2d_begin() } else { Default::default() };
            for (k, r) in streams.iter_mut().enumerate() {
                if loaded & 1 << k == 0 {
                    continue;
                }
                let mut one = r.clone();
                assert_eq!(skipped[k].to_bits(), one.next_f32().to_bits(), "lane {k}, round {round}");
                if let Some(u) = whole {
                    assert_eq!([u[0][k], u[1][k]].map(f32::to_bits), one.next_2d().to_array().map(f32::to_bits), "lane {k}, round {round}");
                    lanes.store(k, r);
                    assert_eq!((r.key, r.counter, r.pairs), (one.key, one.counter, one.pairs));
                    continue;
                }
                match one.next_2d_begin() {
                    Draw2d::Point(p) => {
                        assert_eq!(stratified & 1 << k, 0);
                        assert_eq!([jitter[0][k], jitter[1][k]].map(f32::to_bits), p.to_array().map(f32::to_bits));
                    }
                    Draw2d::Unplaced { jitter: j, shuffle: key } => {
                        assert_ne!(stratified & 1 << k, 0);
                        assert_eq!([jitter[0][k], jitter[1][k]].map(f32::to_bits), j.to_array().map(f32::to_bits));
                        assert_eq!(shuffle[k], key, "lane {k}, round {round}");
                    }
                }
                lanes.store(k, r);
                assert_eq!((r.key, r.counter, r.pairs), (one.key, one.counter, one.pairs), "lane {k}, round {round}");
            }
        }
    }

    #[test]
    fn whole_points_in_lanes_are_each_streams_own_at_a_shared_count() {
        // A frame's streams share their sample count: squares of powers of
        // two (cells in lanes), other powers of two (a Latin hypercube),
        // and counts that are no powers of two.
        for spp in [4u32, 16, 64, 2, 8, 32, 9, 6] {
            let mut streams: Vec<SampleRng> = (0..8u32).map(|k| SampleRng::stratified(500 + k / 2, (k * 3) % spp, spp, 9)).collect();
            for round in 0..12 {
                let loaded = if round % 2 == 1 { 0b0110_1101u8 } else { 0xff };
                let mut lanes = load_lanes(&streams, loaded);
                let u = fearless_simd::dispatch!(crate::math::lanes::simd_level(), simd => lanes.next_2d(simd, loaded));
                for (k, r) in streams.iter_mut().enumerate() {
                    if loaded & 1 << k != 0 {
                        let want = r.next_2d();
                        assert_eq!([u[0][k], u[1][k]].map(f32::to_bits), want.to_array().map(f32::to_bits), "spp {spp}, lane {k}, round {round}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_pixels_samples_take_one_cell_each() {
        // The first 2D draw of each of a pixel's 16 samples lands in its own
        // cell of the 4x4 grid; later draws of the same samples too.
        for spp in [16u32, 5] {
            for pair in 0..3 {
                let mut cells: Vec<(u32, u32)> = (0..spp)
                    .map(|s| {
                        let mut r = SampleRng::stratified(99, s, spp, 7);
                        let mut p = r.next_2d();
                        for _ in 0..pair {
                            p = r.next_2d();
                        }
                        let n = if spp == 16 { 4.0 } else { spp as f32 };
                        ((p.x * n) as u32, if spp == 16 { (p.y * n) as u32 } else { 0 })
                    })
                    .collect();
                if spp == 16 {
                    cells.sort();
                    cells.dedup();
                    assert_eq!(cells.len(), 16, "pair {pair}");
                } else {
                    let mut xs: Vec<u32> = cells.iter().map(|c| c.0).collect();
                    xs.sort();
                    assert_eq!(xs, (0..spp).collect::<Vec<_>>(), "pair {pair}");
                }
            }
        }
    }

    #[test]
    fn uniform_numbers_fill_the_unit_interval_evenly() {
        // 64 bins, 64k draws over many streams: every bin within 5 sigma.
        let mut bins = [0u32; 64];
        for p in 0..4096 {
            let mut r = SampleRng::for_pixel(p, p % 5, 42);
            for _ in 0..16 {
                let u = r.next_f32();
                assert!((0.0..1.0).contains(&u));
                bins[(u * 64.0) as usize] += 1;
            }
        }
        let expect = 4096.0 * 16.0 / 64.0;
        for (i, b) in bins.iter().enumerate() {
            assert!((*b as f32 - expect).abs() < 5.0 * expect.sqrt(), "bin {i}: {b}");
        }
    }

    #[test]
    fn tangents_complete_an_orthonormal_basis() {
        let mut r = SampleRng::for_index(9, 0, 0);
        for _ in 0..1000 {
            let n = uniform_sphere(r.next_2d());
            let (t, b) = tangents(n);
            for (x, y) in [(t, b), (t, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-5);
            }
            for v in [t, b] {
                assert!((v.length() - 1.0).abs() < 1e-5);
            }
            assert!((t.cross(b) - n).length() < 1e-4, "right-handed");
        }
        let (t, b) = tangents(-Vec3::Z);
        assert!(t.is_finite() && b.is_finite());
    }

    /// Pearson's chi-square test of sampled directions against a density
    /// over the hemisphere, binned in (cos theta, phi) with the expected
    /// counts integrated numerically, bins of small expectation pooled (as
    /// Mitsuba tests its BSDF sampling). Returns (statistic, threshold).
    pub(crate) fn chi_square(sample: &mut dyn FnMut(Vec2) -> Option<Vec3>, pdf: &dyn Fn(Vec3) -> f32, n: usize) -> (f64, f64) {
        const CT: usize = 16;
        const PH: usize = 32;
        let mut observed = vec![0f64; CT * PH];
        let mut r = SampleRng::for_index(77, 0, 5);
        for _ in 0..n {
            if let Some(w) = sample(r.next_2d()) {
                if w.z <= 0.0 {
                    continue;
                }
                let ct = ((w.z * CT as f32) as usize).min(CT - 1);
                let ph = (((w.y.atan2(w.x) / (2.0 * PI)).rem_euclid(1.0) * PH as f32) as usize).min(PH - 1);
                observed[ct * PH + ph] += 1.0;
            }
        }
        // Expected: integrate pdf over each bin (area element d(cos) d(phi)).
        const SUB: usize = 12;
        let mut expected = vec![0f64; CT * PH];
        for ct in 0..CT {
            for ph in 0..PH {
                let mut sum = 0f64;
                for i in 0..SUB {
                    for j in 0..SUB {
                        let c = (ct as f64 + (i as f64 + 0.5) / SUB as f64) / CT as f64;
                        let p = (ph as f64 + (j as f64 + 0.5) / SUB as f64) / PH as f64 * 2.0 * std::f64::consts::PI;
                        let s = (1.0 - c * c).max(0.0).sqrt();
                        let w = Vec3::new((s * p.cos()) as f32, (s * p.sin()) as f32, c as f32);
                        sum += pdf(w) as f64;
                    }
                }
                let area = (1.0 / CT as f64) * (2.0 * std::f64::consts::PI / PH as f64);
                expected[ct * PH + ph] = sum / (SUB * SUB) as f64 * area * n as f64;
            }
        }
        // Pool bins expecting fewer than 5 samples into one.
        let (mut stat, mut dof) = (0f64, 0i64);
        let (mut pool_o, mut pool_e) = (0f64, 0f64);
        for (o, e) in observed.iter().zip(&expected) {
            if *e < 5.0 {
                pool_o += o;
                pool_e += e;
            } else {
                stat += (o - e) * (o - e) / e;
                dof += 1;
            }
        }
        if pool_e > 0.0 {
            stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e.max(1.0);
            dof += 1;
        }
        let k = (dof - 1).max(1) as f64;
        // Wilson-Hilferty: the chi-square quantile at p = 1e-4 (z = 3.72).
        let z = 3.72;
        let threshold = k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3);
        (stat, threshold)
    }

    #[test]
    fn cosine_sampling_matches_its_density() {
        let (stat, threshold) = chi_square(&mut |u| Some(cosine_hemisphere(u)), &|w| cosine_hemisphere_pdf(w.z), 200_000);
        assert!(stat < threshold, "chi-square {stat} >= {threshold}");
        // A wrong density must fail the same test: uniform instead of cosine.
        let (stat, threshold) = chi_square(&mut |u| Some(cosine_hemisphere(u)), &|_| 1.0 / (2.0 * PI), 200_000);
        assert!(stat > threshold, "the test cannot tell cosine from uniform: {stat}");
    }

    #[test]
    fn blinn_phong_sampling_matches_its_density() {
        for sharpness in [1.0f32, 10.0, 100.0] {
            for w_o in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.9, 0.3).normalize()] {
                let (stat, threshold) = chi_square(
                    &mut |u| Some(reflect(w_o, blinn_phong_half(u, sharpness))),
                    &|w_i| blinn_phong_pdf(Vec3::Z, w_o, w_i, sharpness),
                    200_000,
                );
                assert!(stat < threshold, "s {sharpness}, w_o {w_o}: chi-square {stat} >= {threshold}");
            }
        }
    }

    #[test]
    fn disk_and_sphere_samples_are_unit() {
        let mut r = SampleRng::for_index(3, 0, 0);
        let mut mean = Vec3::ZERO;
        for _ in 0..20_000 {
            let w = uniform_sphere(r.next_2d());
            assert!((w.length() - 1.0).abs() < 1e-5);
            mean += w;
            assert!(uniform_disk(r.next_2d()).length() <= 1.0 + 1e-6);
        }
        assert!((mean / 20_000.0).length() < 0.03, "uniform: mean {mean}");
    }
}
