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

/// A coordinate in pixels snapped to a coarser grid of `bits` bits of
/// sub-pixel precision (`--subpixel-bits`, 0 to `SUBPIXEL_BITS`), in the
/// units of the full grid: `snap` itself at `SUBPIXEL_BITS`. With fewer
/// bits a vertex moves up to half a coarse step, and the edges with it.
#[inline]
pub fn snap_to(v: f32, bits: u32) -> i64 {
    let bits = bits.min(SUBPIXEL_BITS);
    let step = 1i64 << (SUBPIXEL_BITS - bits);
    crate::math::rounding::round((v as f64) * (1u64 << bits) as f64).clamp(-CLAMP / step as f64, CLAMP / step as f64) as i64 * step
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

    #[test]
    fn coarser_grids_by_hand() {
        // Full precision is `snap` itself.
        for v in [0.3, -7.77, 1.0 / 512.0, 1e30] {
            assert_eq!(snap_to(v, SUBPIXEL_BITS), snap(v), "{v}");
        }
        // 2 bits: quarter pixels, in 1/256 units.
        assert_eq!(snap_to(0.3, 2), 64);
        assert_eq!(snap_to(0.4, 2), 128);
        assert_eq!(snap_to(-0.2, 2), -64);
        // 0 bits: whole pixels.
        assert_eq!(snap_to(2.4, 0), 512);
        assert_eq!(snap_to(2.6, 0), 768);
    }
}
