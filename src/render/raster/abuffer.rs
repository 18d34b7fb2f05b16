//! An A-buffer (Carpenter 1984): for every sample of a region, the list of
//! all the fragments that covered it, not only the nearest. Each sample
//! keeps the index of its latest fragment and each fragment the index of
//! the one before it at the same sample, so drawing is one push and the
//! lists need no per-sample allocation. CSG objects resolve these lists
//! (`csg.rs`).

use crate::render::raster::rect::PixelRect;

const NONE: u32 = u32::MAX;

pub struct ABuffer<F> {
    rect: PixelRect,
    stride: usize,
    /// Per sample: its latest fragment, or `NONE`.
    heads: Vec<u32>,
    /// Every fragment, with the one drawn before it at its sample.
    nodes: Vec<(F, u32)>,
}

impl<F: Copy> ABuffer<F> {
    /// An empty A-buffer over the samples of `rect`.
    pub fn new(rect: PixelRect) -> ABuffer<F> {
        ABuffer { rect, stride: rect.width() as usize, heads: vec![NONE; rect.area() as usize], nodes: Vec::new() }
    }

    pub fn rect(&self) -> PixelRect {
        self.rect
    }

    /// Fragments drawn in all.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    #[inline(always)]
    fn index(&self, x: u32, y: u32) -> usize {
        (x - self.rect.x0) as usize + (y - self.rect.y0) as usize * self.stride
    }

    /// Adds fragment `f` to the list of sample `(x, y)` (inside the rect).
    #[inline]
    pub fn push(&mut self, x: u32, y: u32, f: F) {
        let i = self.index(x, y);
        let n = u32::try_from(self.nodes.len()).expect("more than 2^32 fragments in one A-buffer");
        self.nodes.push((f, self.heads[i]));
        self.heads[i] = n;
    }

    /// Replaces `out` with the fragments of sample `(x, y)` in draw order.
    pub fn fragments(&self, x: u32, y: u32, out: &mut Vec<F>) {
        out.clear();
        let mut k = self.heads[self.index(x, y)];
        while k != NONE {
            let (f, prev) = self.nodes[k as usize];
            out.push(f);
            k = prev;
        }
        out.reverse();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_keep_every_fragment_per_sample_in_draw_order() {
        let mut a = ABuffer::new(PixelRect::new(2, 3, 5, 5));
        a.push(2, 3, 'a');
        a.push(4, 4, 'b');
        a.push(2, 3, 'c');
        a.push(2, 3, 'd');
        let mut out = vec!['x'];
        a.fragments(2, 3, &mut out);
        assert_eq!(out, ['a', 'c', 'd']);
        a.fragments(4, 4, &mut out);
        assert_eq!(out, ['b']);
        a.fragments(3, 3, &mut out);
        assert!(out.is_empty());
        assert_eq!(a.len(), 4);
    }
}
