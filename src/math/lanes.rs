//! Arithmetic written once over a lane type: `f32` (one sample, for replays
//! and the scalar paths) or `f32x8` (eight samples, for frames). Code generic
//! over [`Lane`] runs the same IEEE operations in the same order in either
//! width, so a frame's eight-wide result equals the one-wide replay bit for
//! bit. That is why the trait offers only exactly rounded operations (add,
//! sub, mul, div, sqrt, compare, select, floor, bit moves) and builds
//! everything else (`pow`) from them: a library `powf` and a vector
//! approximation would round differently.
//!
//! No fused multiply-add anywhere: a CPU without FMA could not match it.

use fearless_simd::{f32x16, f32x8, mask32x16, mask32x8, u32x16, u32x8, Select, Simd, SimdBase, SimdFloat, SimdFrom, SimdInt};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Lanes of `f32` computed together.
pub trait Lane:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// One boolean per lane.
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask> + Not<Output = Self::Mask>;

    /// `x` in every lane (the SIMD context is taken from `self`).
    fn splat(self, x: f32) -> Self;
    fn sqrt(self) -> Self;
    fn floor(self) -> Self;
    fn gt(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn lt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn eq(self, other: Self) -> Self::Mask;
    /// Per lane `if mask { a } else { b }`.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// Whether any lane of `mask` is set.
    fn any(mask: Self::Mask) -> bool;
    /// Splits a positive normal number into `(e, m)` with `self = 2^e m`,
    /// `m` in [1, 2) and `e` an integer (as a float). Exact.
    fn exponent_mantissa(self) -> (Self, Self);
    /// `2^self` for integer-valued lanes in [-126, 127]. Exact.
    fn exp2_integer(self) -> Self;
    /// `self`'s magnitude with `sign`'s sign bit.
    fn copysign(self, sign: Self) -> Self;

    /// `a > b ? a : b`, the x86 `maxps` rule: the second operand when
    /// either is NaN (`f32::max` would pick the number, so it is not used).
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Self::select(self.gt(other), self, other)
    }

    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Self::select(self.lt(other), self, other)
    }
}

impl Lane for f32 {
    type Mask = bool;

    #[inline(always)]
    fn splat(self, x: f32) -> f32 {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn floor(self) -> f32 {
        f32::floor(self)
    }
    #[inline(always)]
    fn gt(self, other: f32) -> bool {
        self > other
    }
    #[inline(always)]
    fn ge(self, other: f32) -> bool {
        self >= other
    }
    #[inline(always)]
    fn lt(self, other: f32) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: f32) -> bool {
        self <= other
    }
    #[inline(always)]
    fn eq(self, other: f32) -> bool {
        self == other
    }
    #[inline(always)]
    fn select(mask: bool, a: f32, b: f32) -> f32 {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn any(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (f32, f32) {
        let bits = self.to_bits();
        let e = ((bits >> 23) & 0xff) as f32 - 127.0;
        (e, f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000))
    }
    #[inline(always)]
    fn exp2_integer(self) -> f32 {
        f32::from_bits(((self + 127.0) as u32) << 23)
    }
    #[inline(always)]
    fn copysign(self, sign: f32) -> f32 {
        f32::copysign(self, sign)
    }
}

/// The `Lane` operations of a fearless_simd float vector: the same
/// calls whatever its width (`f32x16` is one AVX-512 register, or two
/// AVX2 halves that compute exactly what two `f32x8` would).
macro_rules! simd_lane {
    ($f:ident, $m:ident, $u:ident, $copysign:ident) => {
        impl<S: Simd> Lane for $f<S> {
            type Mask = $m<S>;

            #[inline(always)]
            fn splat(self, x: f32) -> Self {
                <$f<S> as SimdBase<S>>::splat(self.simd, x)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                SimdFloat::sqrt(self)
            }
            #[inline(always)]
            fn floor(self) -> Self {
                SimdFloat::floor(self)
            }
            #[inline(always)]
            fn gt(self, other: Self) -> Self::Mask {
                self.simd_gt(other)
            }
            #[inline(always)]
            fn ge(self, other: Self) -> Self::Mask {
                self.simd_ge(other)
            }
            #[inline(always)]
            fn lt(self, other: Self) -> Self::Mask {
                self.simd_lt(other)
            }
            #[inline(always)]
            fn le(self, other: Self) -> Self::Mask {
                self.simd_le(other)
            }
            #[inline(always)]
            fn eq(self, other: Self) -> Self::Mask {
                self.simd_eq(other)
            }
            #[inline(always)]
            fn select(mask: Self::Mask, a: Self, b: Self) -> Self {
                mask.select(a, b)
            }
            #[inline(always)]
            fn any(mask: Self::Mask) -> bool {
                fearless_simd::SimdMask::to_bitmask(mask) != 0
            }
            #[inline(always)]
            fn exponent_mantissa(self) -> (Self, Self) {
                let bits: $u<S> = self.to_bits();
                let biased: $u<S> = (bits >> 23) & 0xff;
                let e: $f<S> = biased.to_float::<$f<S>>() - 127.0;
                let m_bits: $u<S> = (bits & 0x007f_ffff) | 0x3f80_0000;
                (e, $f::from_bits(m_bits))
            }
            #[inline(always)]
            fn exp2_integer(self) -> Self {
                let biased: $u<S> = (self + 127.0).to_int::<$u<S>>();
                $f::from_bits(biased << 23)
            }
            #[inline(always)]
            fn copysign(self, sign: Self) -> Self {
                self.simd.$copysign(self, sign)
            }
        }
    };
}

simd_lane!(f32x8, mask32x8, u32x8, copysign_f32x8);
simd_lane!(f32x16, mask32x16, u32x16, copysign_f32x16);

/// `(cos 2 pi u, sin 2 pi u)` for `u` in [0, 1] (a fraction of a turn), to
/// within about 1e-7, for sampling directions. Written here rather than
/// taken from the library so that eight lanes and one round alike: the
/// turn is split exactly into a quarter turn `q` and a remainder `r` of at
/// most an eighth, whose sine and cosine come from short polynomials
/// (Cephes' `sinf` and `cosf` coefficients on [-pi/4, pi/4]); the quarter
/// turn then swaps and negates them.
#[inline(always)]
pub fn cos_sin_turns<L: Lane>(u: L) -> (L, L) {
    let four_u = u * u.splat(4.0);
    let q = (four_u + u.splat(0.5)).floor();
    // Exact: q is within one half of 4u, a multiple of its last place.
    let x = (four_u - q) * u.splat(std::f32::consts::FRAC_PI_2);
    let z = x * x;
    let sin = x + x * z * (u.splat(-1.666_665_5e-1) + z * (u.splat(8.332_161e-3) + z * u.splat(-1.951_529_6e-4)));
    let cos = u.splat(1.0) - u.splat(0.5) * z + z * z * (u.splat(4.166_664_6e-2) + z * (u.splat(-1.388_731_6e-3) + z * u.splat(2.443_315_7e-5)));
    // The quarter turn modulo 4: 0 and 4 leave (cos, sin); 1 gives
    // (-sin, cos); 2 (-cos, -sin); 3 (sin, -cos).
    let quarter = q - (q * u.splat(0.25)).floor() * u.splat(4.0);
    let odd = quarter.eq(u.splat(1.0)) | quarter.eq(u.splat(3.0));
    let (c, s) = (L::select(odd, sin, cos), L::select(odd, cos, sin));
    let negate_cos = quarter.eq(u.splat(1.0)) | quarter.eq(u.splat(2.0));
    let negate_sin = quarter.ge(u.splat(2.0));
    (L::select(negate_cos, -c, c), L::select(negate_sin, -s, s))
}

/// Whether every value is finite (no NaN, no infinity), eight lanes at a
/// time: x * 0 is a zero for a finite x and NaN otherwise, and a NaN
/// survives the sum. No branch per value: this runs over every pixel of a
/// frame. Four sums side by side, so that the loop is not one chain of
/// dependent additions (it ran at one add latency per eight values).
pub fn all_finite(values: &[f32]) -> bool {
    fn probe<S: Simd>(simd: S, values: &[f32]) -> bool {
        let zero = <f32x8<S> as SimdBase<S>>::splat(simd, 0.0);
        let mut acc = [zero; 4];
        let mut blocks = values.chunks_exact(32);
        for block in &mut blocks {
            for (k, a) in acc.iter_mut().enumerate() {
                *a += f32x8::from_slice(simd, &block[8 * k..8 * k + 8]) * zero;
            }
        }
        let tail = blocks.remainder().iter().fold(0.0f32, |a, &x| a + x * 0.0);
        let lanes: [f32; 8] = ((acc[0] + acc[1]) + (acc[2] + acc[3])).into();
        lanes.iter().fold(tail, |a, &x| a + x) == 0.0
    }
    fearless_simd::dispatch!(simd_level(), simd => probe(simd, values))
}

/// The SIMD level of this CPU, detected once; `dispatch!` runs code
/// generic over `Simd` at it.
pub fn simd_level() -> fearless_simd::Level {
    static LEVEL: std::sync::OnceLock<fearless_simd::Level> = std::sync::OnceLock::new();
    *LEVEL.get_or_init(fearless_simd::Level::new)
}

/// `c^s` for `c >= 0` and `s > 0`, as `2^(s log2 c)`, with the same
/// operations in every width. Relative error below 5e-6 where the result
/// is above 1e-9 (the BSDF leaves smaller values out), growing with
/// `|s log2 c|` below that; 0 for `c` zero or below the normal range.
#[inline(always)]
pub fn pow<L: Lane>(c: L, s: L) -> L {
    let x = s * log2(c);
    let x = x.max(c.splat(-126.0)).min(c.splat(126.0));
    let result = exp2(x);
    L::select(c.ge(c.splat(f32::MIN_POSITIVE)), result, c.splat(0.0))
}

/// `log2 c` for positive normal `c`: `c = 2^e m`, with `m` moved into
/// [sqrt(1/2), sqrt(2)) and `ln m = 2 atanh((m - 1) / (m + 1))` summed to
/// the t^9 term (|t| <= 0.172, so the next term is below 1e-9).
#[inline(always)]
fn log2<L: Lane>(c: L) -> L {
    let (e, m) = c.exponent_mantissa();
    let high = m.gt(c.splat(std::f32::consts::SQRT_2));
    let m = L::select(high, m * c.splat(0.5), m);
    let e = L::select(high, e + c.splat(1.0), e);
    let t = (m - c.splat(1.0)) / (m + c.splat(1.0));
    let t2 = t * t;
    let series = c.splat(1.0 / 9.0);
    let series = series * t2 + c.splat(1.0 / 7.0);
    let series = series * t2 + c.splat(1.0 / 5.0);
    let series = series * t2 + c.splat(1.0 / 3.0);
    let series = series * t2 + c.splat(1.0);
    e + t * series * c.splat(2.0 * std::f32::consts::LOG2_E)
}

/// `2^x` for x in [-126, 126]: `2^n 2^f` with `n = round(x)`, `|f| <= 1/2`
/// and `2^f = e^(f ln 2)` by its Taylor series to the 7th power (error
/// below 1e-8).
#[inline(always)]
pub fn exp2<L: Lane>(x: L) -> L {
    let n = (x + x.splat(0.5)).floor();
    let g = (x - n) * x.splat(std::f32::consts::LN_2);
    let mut p = x.splat(1.0 / 5040.0);
    for k in [720.0f32, 120.0, 24.0, 6.0, 2.0, 1.0, 1.0] {
        p = p * g + x.splat(1.0 / k);
    }
    p * n.exp2_integer()
}

/// A 3-vector of lanes: eight points, normals or colours at once with
/// `f32x8`, one with `f32`. Operations keep glam's order of arithmetic
/// (`dot` is `(x x' + y y') + z z'`), so the one-lane form equals glam's
/// `Vec3` results bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct V3<L> {
    pub x: L,
    pub y: L,
    pub z: L,
}

impl<L: Lane> V3<L> {
    #[inline(always)]
    pub fn new(x: L, y: L, z: L) -> Self {
        V3 { x, y, z }
    }
    /// The constant `v` in every lane (the SIMD context taken from `like`).
    #[inline(always)]
    pub fn splat(like: L, v: glam::Vec3) -> Self {
        V3 { x: like.splat(v.x), y: like.splat(v.y), z: like.splat(v.z) }
    }
    #[inline(always)]
    pub fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// glam's `cross`, term for term.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        V3 { x: self.y * o.z - o.y * self.z, y: self.z * o.x - o.z * self.x, z: self.x * o.y - o.x * self.y }
    }
    #[inline(always)]
    pub fn length(self) -> L {
        self.dot(self).sqrt()
    }
    #[inline(always)]
    pub fn scale(self, s: L) -> Self {
        V3 { x: self.x * s, y: self.y * s, z: self.z * s }
    }
    #[inline(always)]
    pub fn div(self, s: L) -> Self {
        V3 { x: self.x / s, y: self.y / s, z: self.z / s }
    }
    /// glam's `normalize`: times `1 / length`.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self.scale(self.x.splat(1.0) / self.length())
    }
    /// glam's `normalize_or`: times `1 / length`, `fallback` where that is
    /// not a positive finite number.
    #[inline(always)]
    pub fn normalize_or(self, fallback: Self) -> Self {
        let rcp = self.x.splat(1.0) / self.length();
        let ok = rcp.gt(self.x.splat(0.0)) & rcp.lt(self.x.splat(f32::INFINITY));
        V3::select(ok, self.scale(rcp), fallback)
    }
    /// glam's `normalize_or_zero`.
    #[inline(always)]
    pub fn normalize_or_zero(self) -> Self {
        let zero = self.x.splat(0.0);
        self.normalize_or(V3 { x: zero, y: zero, z: zero })
    }
    /// Per lane `if mask { a } else { b }`.
    #[inline(always)]
    pub fn select(mask: L::Mask, a: Self, b: Self) -> Self {
        V3 { x: L::select(mask, a.x, b.x), y: L::select(mask, a.y, b.y), z: L::select(mask, a.z, b.z) }
    }
    /// Whether every component is zero, per lane.
    #[inline(always)]
    pub fn is_zero(self) -> L::Mask {
        let zero = self.x.splat(0.0);
        self.x.eq(zero) & self.y.eq(zero) & self.z.eq(zero)
    }
}

impl<L: Lane> Add for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl<L: Lane> Sub for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

/// Component by component, as glam's `Vec3 * Vec3`.
impl<L: Lane> Mul for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 { x: self.x * o.x, y: self.y * o.y, z: self.z * o.z }
    }
}

impl<L: Lane> Neg for V3<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3 { x: -self.x, y: -self.y, z: -self.z }
    }
}

impl From<glam::Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: glam::Vec3) -> Self {
        V3 { x: v.x, y: v.y, z: v.z }
    }
}

impl From<V3<f32>> for glam::Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Self {
        glam::Vec3::new(v.x, v.y, v.z)
    }
}

impl<S: Simd> V3<f32x8<S>> {
    /// Lanes `start..start + 8` of three coordinate arrays.
    #[inline(always)]
    pub fn load(simd: S, xyz: [&[f32]; 3], start: usize) -> Self {
        V3 {
            x: f32x8::from_slice(simd, &xyz[0][start..start + 8]),
            y: f32x8::from_slice(simd, &xyz[1][start..start + 8]),
            z: f32x8::from_slice(simd, &xyz[2][start..start + 8]),
        }
    }
    /// Lanes from coordinate arrays (`[x, y, z]`, eight lanes each).
    #[inline(always)]
    pub fn from_soa(simd: S, xyz: &[[f32; 8]; 3]) -> Self {
        V3 { x: f32x8::simd_from(simd, xyz[0]), y: f32x8::simd_from(simd, xyz[1]), z: f32x8::simd_from(simd, xyz[2]) }
    }
    /// The lanes as coordinate arrays (`[x, y, z]`).
    #[inline(always)]
    pub fn to_soa(self) -> [[f32; 8]; 3] {
        [self.x.into(), self.y.into(), self.z.into()]
    }
    /// Eight vectors gathered into lanes.
    #[inline(always)]
    pub fn gather(simd: S, v: &[glam::Vec3; 8]) -> Self {
        V3 {
            x: f32x8::simd_from(simd, v.map(|v| v.x)),
            y: f32x8::simd_from(simd, v.map(|v| v.y)),
            z: f32x8::simd_from(simd, v.map(|v| v.z)),
        }
    }
    /// The eight vectors back out of the lanes.
    #[inline(always)]
    pub fn scatter(self) -> [glam::Vec3; 8] {
        let (x, y, z): ([f32; 8], [f32; 8], [f32; 8]) = (self.x.into(), self.y.into(), self.z.into());
        std::array::from_fn(|i| glam::Vec3::new(x[i], y[i], z[i]))
    }
}

/// Eight rows of eight as eight columns: three rounds of interleaving row
/// i with row i + 4 (after them, vector j holds element j of every row).
#[inline(always)]
pub fn transpose8<S: Simd>(mut m: [f32x8<S>; 8]) -> [f32x8<S>; 8] {
    for _ in 0..3 {
        let mut next = m;
        for i in 0..4 {
            let (low, high) = m[i].interleave(m[i + 4]);
            next[2 * i] = low;
            next[2 * i + 1] = high;
        }
        m = next;
    }
    m
}

/// Lane `i` of a mask as a bool.
#[inline(always)]
pub fn mask_bits<S: Simd>(mask: mask32x8<S>) -> u8 {
    fearless_simd::SimdMask::to_bitmask(mask) as u8
}

/// A mask from 8 bits (bit i = lane i).
#[inline(always)]
pub fn mask_from_bits<S: Simd>(simd: S, bits: u8) -> mask32x8<S> {
    fearless_simd::SimdMask::from_bitmask(simd, bits as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fearless_simd::{dispatch, Level};

    /// A NaN or an infinity anywhere (in any of the four sums, in either
    /// block of 32, or in the tail) is found; finite values of any size,
    /// zeros and subnormals are not.
    #[test]
    fn all_finite_finds_every_non_finite_value() {
        let finite: Vec<f32> = (0..77).map(|i| [f32::MAX, -f32::MAX, 0.0, -0.0, 1e-40, 3.5, f32::MIN_POSITIVE][i % 7]).collect();
        assert!(all_finite(&finite));
        assert!(all_finite(&[]));
        for at in 0..finite.len() {
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let mut v = finite.clone();
                v[at] = bad;
                assert!(!all_finite(&v), "{bad} at {at}");
            }
        }
    }

    fn pow8(c: [f32; 8], s: [f32; 8]) -> [f32; 8] {
        let level = Level::new();
        dispatch!(level, simd => pow(f32x8::simd_from(simd, c), f32x8::simd_from(simd, s)).into())
    }

    #[test]
    fn turns_give_cosine_and_sine_in_one_and_eight_lanes() {
        let mut worst = 0.0f64;
        for i in 0..=100_000u32 {
            let u = i as f32 / 100_000.0;
            let (c, s) = cos_sin_turns(u);
            let angle = std::f64::consts::TAU * u as f64;
            worst = worst.max((c as f64 - angle.cos()).abs()).max((s as f64 - angle.sin()).abs());
        }
        assert!(worst < 2.5e-7, "worst error {worst}");
        // Every quarter turn's end, where the quadrant logic switches.
        for (u, c, s) in [(0.0, 1.0, 0.0), (0.25, 0.0, 1.0), (0.5, -1.0, 0.0), (0.75, 0.0, -1.0), (1.0, 1.0, 0.0)] {
            let got = cos_sin_turns(u);
            assert!((got.0 - c).abs() < 1e-7 && (got.1 - s).abs() < 1e-7, "{u}: {got:?}");
        }
        let us = [0.0, 0.1, 0.124_999_99, 0.375, 0.5, 0.625_000_1, 0.9, 0.999_999_94];
        let wide = fearless_simd::dispatch!(simd_level(), simd => {
            let (c, s) = cos_sin_turns(f32x8::simd_from(simd, us));
            (<[f32; 8]>::from(c), <[f32; 8]>::from(s))
        });
        for (k, u) in us.iter().enumerate() {
            let (c, s) = cos_sin_turns(*u);
            assert_eq!((wide.0[k].to_bits(), wide.1[k].to_bits()), (c.to_bits(), s.to_bits()), "lane {k}");
        }
    }

    #[test]
    fn pow_is_close_to_libm() {
        let mut worst = 0.0f64;
        for i in 0..20_000 {
            let c = (i as f32 + 0.5) / 20_000.0;
            for s in [0.5f32, 1.0, 3.0, 10.0, 100.0, 1000.0, 5000.0] {
                let want = (c as f64).powf(s as f64);
                if want < 1e-9 {
                    continue;
                }
                let got = pow(c, s) as f64;
                worst = worst.max((got - want).abs() / want);
            }
        }
        assert!(worst < 5e-6, "worst relative error {worst}");
        assert_eq!(pow(0.0f32, 2.0), 0.0);
        assert_eq!(pow(1.0f32, 100.0), 1.0);
    }

    /// The eight-wide and one-wide results agree bit for bit, whatever SIMD
    /// level the CPU gives.
    #[test]
    fn pow_lanes_match_scalar_bits() {
        for k in 0..2_000 {
            let c: [f32; 8] = std::array::from_fn(|i| ((k * 8 + i) as f32 * 0.618_034).fract());
            let s: [f32; 8] = std::array::from_fn(|i| 1.0 + ((k * 8 + i) as f32 * 0.414_214).fract() * 500.0);
            let wide = pow8(c, s);
            for i in 0..8 {
                assert_eq!(wide[i].to_bits(), pow(c[i], s[i]).to_bits(), "c {} s {}", c[i], s[i]);
            }
        }
    }

    /// Sixteen lanes compute what one lane does, bit for bit, at every SIMD
    /// level this CPU offers (AVX-512 runs `f32x16` as one register, AVX2
    /// and SSE4.2 as halves or quarters): the power, the normalised
    /// direction and the selects that lighting builds from them.
    #[test]
    fn sixteen_lanes_match_one_lane_at_every_level() {
        fn check<S: Simd>(simd: S) {
            for k in 0..500 {
                let f = |i: usize, m: f32| ((k * 16 + i) as f32 * m).fract();
                let c: [f32; 16] = std::array::from_fn(|i| f(i, 0.618_034));
                let s: [f32; 16] = std::array::from_fn(|i| 1.0 + f(i, 0.414_214) * 500.0);
                let v: [[f32; 16]; 3] = [0.1, 0.7, 0.3].map(|m| std::array::from_fn(|i| f(i, m) - 0.5));
                let p: [f32; 16] = pow(f32x16::simd_from(simd, c), f32x16::simd_from(simd, s)).into();
                let n = V3::new(f32x16::simd_from(simd, v[0]), f32x16::simd_from(simd, v[1]), f32x16::simd_from(simd, v[2])).normalize_or_zero();
                let n: [[f32; 16]; 3] = [n.x.into(), n.y.into(), n.z.into()];
                let m: [f32; 16] = Lane::max(f32x16::simd_from(simd, c), f32x16::simd_from(simd, v[0])).into();
                for i in 0..16 {
                    assert_eq!(p[i].to_bits(), pow(c[i], s[i]).to_bits(), "pow lane {i}");
                    let one: glam::Vec3 = V3::new(v[0][i], v[1][i], v[2][i]).normalize_or_zero().into();
                    assert_eq!([n[0][i], n[1][i], n[2][i]].map(f32::to_bits), one.to_array().map(f32::to_bits), "normalize lane {i}");
                    assert_eq!(m[i].to_bits(), Lane::max(c[i], v[0][i]).to_bits(), "max lane {i}");
                }
            }
        }
        let level = Level::new();
        let mut levels = 0;
        if let Some(simd) = level.as_avx512() {
            check(simd);
            levels += 1;
        }
        if let Some(simd) = level.as_avx2() {
            check(simd);
            levels += 1;
        }
        if let Some(simd) = level.as_sse4_2() {
            check(simd);
            levels += 1;
        }
        assert!(levels > 0, "no SIMD level to check on this CPU");
    }

    #[test]
    fn normalize_or_zero_matches_glam() {
        for v in [glam::Vec3::new(1.0, 2.0, 3.0), glam::Vec3::ZERO, glam::Vec3::new(1e-30, 0.0, 0.0), glam::Vec3::new(-0.3, 0.7, 1e5)] {
            let ours: glam::Vec3 = V3::from(v).normalize_or_zero().into();
            assert_eq!(ours.to_array().map(f32::to_bits), v.normalize_or_zero().to_array().map(f32::to_bits), "{v}");
            assert_eq!(V3::from(v).dot(V3::from(v * 2.0)).to_bits(), v.dot(v * 2.0).to_bits());
        }
    }
}
