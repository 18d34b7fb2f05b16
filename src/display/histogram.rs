//! A histogram of an image's luminance on a log2 axis: how many pixels fall
//! in each stop-wide bin from `false_colour::MIN_STOP` to `MAX_STOP` (black
//! and non-finite pixels in the first bin, brighter ones in the last), the
//! scale of the false-colour view.

use crate::display::false_colour::{stop_of, MAX_STOP, MIN_STOP};
use crate::math::Radiance;

/// Bins per stop.
pub const BINS_PER_STOP: usize = 4;

/// The number of bins: `BINS_PER_STOP` per stop of the false-colour scale.
pub const BINS: usize = (MAX_STOP - MIN_STOP) as usize * BINS_PER_STOP;

/// Counts per bin; bin `i` holds stops `MIN_STOP + i / BINS_PER_STOP` up to
/// the next bin's.
pub fn log_luminance(pixels: &[Radiance]) -> [u32; BINS] {
    let mut counts = [0u32; BINS];
    for &c in pixels {
        let at = ((stop_of(c) - MIN_STOP) * BINS_PER_STOP as f32) as usize;
        counts[at.min(BINS - 1)] += 1;
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn pixels_fall_in_the_bins_of_their_stops() {
        // Luminance 1 is stop 0: bin (0 - MIN_STOP) * BINS_PER_STOP. Black,
        // NaN and the too dark go in the first bin, the too bright in the last.
        let pixels = [Vec3::ONE, Vec3::ONE, Vec3::ZERO, Vec3::splat(f32::NAN), Vec3::splat(1e-9), Vec3::splat(1e9), Vec3::splat(0.5)];
        let h = log_luminance(&pixels);
        let one = (-MIN_STOP) as usize * BINS_PER_STOP;
        assert_eq!(h[one], 2);
        assert_eq!(h[one - BINS_PER_STOP], 1, "a stop below");
        assert_eq!(h[0], 3);
        assert_eq!(h[BINS - 1], 1);
        assert_eq!(h.iter().sum::<u32>(), pixels.len() as u32);
    }
}
