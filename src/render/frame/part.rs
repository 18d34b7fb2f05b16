//! A part of a frame: a rectangle of its pixels and a range of its sample
//! passes. A crop is a rectangle, a tile a band of whole rows, a sample
//! range a span of passes; the frame loop renders all three the same way,
//! with the sample indices, offsets and seeds the whole frame would give
//! those pixels, so a part's pixels are the whole frame's there.

use crate::render::RenderSettings;
use std::ops::Range;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePart {
    /// Columns and rows of the full frame, end exclusive.
    pub x: Range<u32>,
    pub y: Range<u32>,
    /// Sample passes of every pixel, end exclusive.
    pub passes: Range<u32>,
}

impl FramePart {
    /// All of a frame of `settings`.
    pub fn whole(settings: &RenderSettings) -> FramePart {
        FramePart { x: 0..settings.width, y: 0..settings.height, passes: 0..settings.spp.max(1) }
    }

    /// Rows `i*h/n .. (i+1)*h/n`: the `i`-th of `n` bands of rows (0-based),
    /// which together cover the `h` rows once.
    pub fn band_rows(i: u32, n: u32, h: u32) -> Range<u32> {
        let at = |k: u32| (k as u64 * h as u64 / n.max(1) as u64) as u32;
        at(i)..at(i + 1)
    }

    /// Whether the part holds every sample pass (its pixels are then final
    /// values; otherwise sums of its passes).
    pub fn all_passes(&self, settings: &RenderSettings) -> bool {
        self.passes == (0..settings.spp.max(1))
    }

    pub fn width(&self) -> u32 {
        self.x.len() as u32
    }

    pub fn height(&self) -> u32 {
        self.y.len() as u32
    }

    /// Refuses, in one sentence, a part that is empty or reaches outside a
    /// frame of `settings`.
    pub fn check(&self, settings: &RenderSettings) -> Result<(), String> {
        let (w, h, spp) = (settings.width, settings.height, settings.spp.max(1));
        if self.x.is_empty() || self.y.is_empty() {
            return Err(format!("the region {},{},{},{} has no area", self.x.start, self.y.start, self.x.end, self.y.end));
        }
        if self.x.end > w || self.y.end > h {
            return Err(format!("the region {},{},{},{} reaches outside the {w}x{h} frame", self.x.start, self.y.start, self.x.end, self.y.end));
        }
        if self.passes.is_empty() || self.passes.end > spp {
            return Err(format!("the sample range {}..{} is not within the frame's 0..{spp} samples", self.passes.start, self.passes.end));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_row_once() {
        for h in [1u32, 7, 48, 100] {
            for n in 1..=h.min(9) {
                let mut next = 0;
                for i in 0..n {
                    let r = FramePart::band_rows(i, n, h);
                    assert_eq!(r.start, next);
                    assert!(!r.is_empty());
                    next = r.end;
                }
                assert_eq!(next, h);
            }
        }
    }

    #[test]
    fn empty_or_outside_parts_are_refused() {
        let s = RenderSettings { width: 64, height: 48, spp: 4, ..RenderSettings::default() };
        assert!(FramePart { x: 0..64, y: 0..48, passes: 0..4 }.check(&s).is_ok());
        assert!(FramePart { x: 3..3, y: 0..48, passes: 0..4 }.check(&s).unwrap_err().contains("no area"));
        assert!(FramePart { x: 0..65, y: 0..48, passes: 0..4 }.check(&s).unwrap_err().contains("outside the 64x48"));
        assert!(FramePart { x: 0..64, y: 0..48, passes: 2..5 }.check(&s).unwrap_err().contains("0..4"));
    }
}
