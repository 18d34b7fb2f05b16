//! Pixel rectangles: the regions, bounding boxes and spans every coverage
//! loop works on, and the count of the samples those loops test.

use crate::math::rounding;

/// A half-open rectangle of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32) -> PixelRect {
        PixelRect { x0, y0, x1, y1 }
    }

    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    pub fn intersect(&self, o: &PixelRect) -> PixelRect {
        PixelRect { x0: self.x0.max(o.x0), y0: self.y0.max(o.y0), x1: self.x1.min(o.x1), y1: self.y1.min(o.y1) }
    }

    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    pub fn area(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }

    /// Grown by `m` pixels on every side, clamped to `[0, w) x [0, h)`.
    pub fn grown(&self, m: u32, w: u32, h: u32) -> PixelRect {
        PixelRect { x0: self.x0.saturating_sub(m), y0: self.y0.saturating_sub(m), x1: (self.x1 + m).min(w), y1: (self.y1 + m).min(h) }
    }
}

/// Where the coverage loops count the samples they test: a plain total
/// (`u64`), or a total plus a per-pixel map for the cost view
/// (`vis_buffer::TestCountMap`). Called once per rectangle (or span) tested.
pub trait TestCounter {
    fn add(&mut self, r: PixelRect);
}

impl TestCounter for u64 {
    #[inline(always)]
    fn add(&mut self, r: PixelRect) {
        *self += r.area();
    }
}

/// The samples a triangle's coverage loop visits: its bounding box `bbox`
/// clipped to `rect`, counted in `tested`; `None` when nothing is left.
#[inline(always)]
pub fn tested_rect(bbox: &PixelRect, rect: &PixelRect, tested: &mut impl TestCounter) -> Option<PixelRect> {
    let r = bbox.intersect(rect);
    if r.is_empty() {
        return None;
    }
    tested.add(r);
    Some(r)
}

/// The pixels `i` in `[0, n)` whose sample `i + off` lies in `[lo, hi]`.
pub fn sample_span(lo: f32, hi: f32, off: f32, n: u32) -> (u32, u32) {
    if !(lo <= hi) {
        return (0, 0);
    }
    let a = rounding::ceil(lo - off).clamp(0.0, n as f32);
    let b = (rounding::floor(hi - off) + 1.0).clamp(0.0, n as f32);
    (a as u32, b as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_span_by_hand() {
        // Samples at x + 0.5: 2.5, 3.5 and 4.5 lie in [2.2, 4.5].
        assert_eq!(sample_span(2.2, 4.5, 0.5, 10), (2, 5));
        assert_eq!(sample_span(-3.0, 0.4, 0.5, 10), (0, 0));
        assert_eq!(sample_span(8.0, 100.0, 0.5, 10), (8, 10));
        assert_eq!(sample_span(f32::NAN, 1.0, 0.5, 10), (0, 0));
    }
}
