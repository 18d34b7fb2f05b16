//! The sub-pixel grid of the fixed-point rasterizers (`fixed`, `tiled`):
//! vertices and sample positions are snapped to 1/256 pixel, so edge functions
//! become exact integers.

use crate::math::Vec2;

/// Bits of sub-pixel precision of snapped vertices and samples.
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in fixed-point units.
pub const ONE: i64 = 1 << SUBPIXEL_BITS;
/// Grid units below which, on both axes, a triangle is small (half a pixel):
/// `small.rs` decides its coverage by rays instead of edge functions.
pub const SMALL_LIMIT: i64 = ONE / 2;
/// Snapped coordinates are clamped here, far beyond any image, so i128 never overflows.
const CLAMP: f64 = (1u64 << 60) as f64;

/// A coordinate in pixels snapped to the sub-pixel grid.
#[inline]
pub fn snap(v: f32) -> i64 {
    crate::math::rounding::round((v as f64) * ONE as f64).clamp(-CLAMP, CLAMP) as i64
}

/// The pass's sample offset snapped to the sub-pixel grid.
pub fn snap_offset(off: Vec2) -> [i64; 2] {
    [snap(off.x), snap(off.y)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snap_by_hand() {
        // 256 units per pixel, rounded to the nearest unit (halves away from zero).
        assert_eq!(snap(1.0), 256);
        assert_eq!(snap(-0.5), -128);
        assert_eq!(snap(0.25 / 256.0), 0);
        assert_eq!(snap(0.75 / 256.0), 1);
        assert_eq!(snap(-1.5 / 256.0), -2);
        assert_eq!(snap_offset(Vec2::new(0.5, 0.125)), [128, 32]);
        // Far off screen: clamped to 2^60 units.
        assert_eq!(snap(1.0e30), 1 << 60);
        assert_eq!(snap(f32::NEG_INFINITY), -(1 << 60));
    }
}
