//! Rounding to whole numbers without a library call. The binary targets
//! x86-64's baseline (SSE2, so that it runs on any x86-64), which has no
//! rounding instruction: `f32::floor`, `f32::ceil` and `f64::round` call
//! software routines of 20-40 instructions each, and the rasterizers'
//! set-up rounds several coordinates of every triangle. These give the
//! library's results bit for bit (the tests compare them) with a few
//! additions: adding 2^23 (2^52 for `f64`) to a smaller magnitude leaves
//! no bits below the units, so the sum is rounded to a whole number (to
//! the nearest, ties to even, the hardware's default), and subtracting it
//! again is exact.

/// Below this magnitude an `f32` may have a fraction; from it up every one
/// is whole (NaN and the infinities are not below it either).
const F32_WHOLE: f32 = 8_388_608.0; // 2^23
/// The same for `f64`.
const F64_WHOLE: f64 = 4_503_599_627_370_496.0; // 2^52

/// The whole number nearest `x` (ties to even), with `x`'s sign (so -0.3
/// gives -0); for |x| < 2^23.
#[inline(always)]
fn nearest_f32(x: f32) -> f32 {
    ((x.abs() + F32_WHOLE) - F32_WHOLE).copysign(x)
}

/// `x.floor()`.
#[inline]
pub fn floor(x: f32) -> f32 {
    if !(x.abs() < F32_WHOLE) {
        return x;
    }
    let r = nearest_f32(x);
    // The result has x's sign, zeros included (-0.3 gives -1, 0.7 gives +0).
    (if r > x { r - 1.0 } else { r }).copysign(x)
}

/// `x.ceil()`.
#[inline]
pub fn ceil(x: f32) -> f32 {
    if !(x.abs() < F32_WHOLE) {
        return x;
    }
    let r = nearest_f32(x);
    // As in `floor`: -0.7 gives -0, not the +0 of -1 + 1.
    (if r < x { r + 1.0 } else { r }).copysign(x)
}

/// `x.round()`: to the nearest whole number, halves away from zero.
#[inline]
pub fn round(x: f64) -> f64 {
    let a = x.abs();
    if !(a < F64_WHOLE) {
        return x;
    }
    let r = (a + F64_WHOLE) - F64_WHOLE;
    // A half taken down to an even number goes up instead: away from zero.
    let r = if a - r == 0.5 { r + 1.0 } else { r };
    r.copysign(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values where rounding changes: whole numbers, halves, their
    /// neighbours, zeros of both signs, the edges of the fast range, the
    /// infinities and NaN.
    fn edges_f32() -> Vec<f32> {
        let mut v = vec![0.0, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MIN_POSITIVE, f32::MAX, f32::MIN, F32_WHOLE, -F32_WHOLE];
        for base in [0.5f32, 1.0, 1.5, 2.5, 3.0, 1.0e6 + 0.5, F32_WHOLE / 2.0, F32_WHOLE - 0.5, F32_WHOLE] {
            for x in [base, -base] {
                v.extend([x, f32::from_bits(x.to_bits() + 1), f32::from_bits(x.to_bits() - 1)]);
            }
        }
        v
    }

    fn same_f32(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[test]
    fn floor_and_ceil_are_the_library_s() {
        let every_251st = (0..u32::MAX / 251).map(|i| f32::from_bits(i * 251));
        for x in edges_f32().into_iter().chain(every_251st) {
            assert!(same_f32(floor(x), x.floor()), "floor({x:e}) = {:e}, not {:e}", floor(x), x.floor());
            assert!(same_f32(ceil(x), x.ceil()), "ceil({x:e}) = {:e}, not {:e}", ceil(x), x.ceil());
        }
    }

    #[test]
    fn round_is_the_library_s() {
        let mut v: Vec<f64> = vec![0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN, f64::MAX, f64::MIN, F64_WHOLE, -F64_WHOLE];
        for base in [0.5f64, 1.0, 1.5, 2.5, 0.49999999999999994, 1.0e15 + 0.5, F64_WHOLE / 2.0 + 0.5, F64_WHOLE - 0.5, F64_WHOLE] {
            for x in [base, -base] {
                v.extend([x, f64::from_bits(x.to_bits() + 1), f64::from_bits(x.to_bits() - 1)]);
            }
        }
        // f32s scaled as the rasterizers' snapping scales them (by 256),
        // sampled, and f64 bit patterns spread over every exponent.
        let snapped = (0..u32::MAX / 251).map(|i| f32::from_bits(i * 251) as f64 * 256.0);
        let spread = (0..1u64 << 22).map(|i| f64::from_bits(i.wrapping_mul(0x9E37_79B9_7F4A_7C15)));
        for x in v.into_iter().chain(snapped).chain(spread) {
            let (ours, theirs) = (round(x), x.round());
            assert!(ours.to_bits() == theirs.to_bits() || (ours.is_nan() && theirs.is_nan()), "round({x:e}) = {ours:e}, not {theirs:e}");
        }
    }
}
