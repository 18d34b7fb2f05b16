//! The tiled rasterizer: triangles are binned into 32x32-pixel screen tiles,
//! tiles are rasterized in parallel, each with its own small depth and
//! visibility buffer. Inside a tile the triangle is tested against 8x8 blocks
//! first: a block entirely outside one edge is skipped, a block entirely
//! inside all three edges is filled without per-sample tests, and only the
//! blocks on an edge get a per-sample coverage mask. Everything runs on the
//! same exact fixed-point edge functions as `fixed`, so both variants cover the
//! same samples with the same weights: identical images, bit for bit.

use crate::render::raster::fixed::{self, FixedTri};
use crate::render::raster::rect::{PixelRect, TestCounter};
use crate::render::raster::subpixel::ONE;

/// Tile edge length in pixels.
pub const TILE: u32 = 32;
/// Block edge length in pixels (a block's coverage mask is one u64).
pub const BLOCK: u32 = 8;

/// How a rectangle of samples relates to a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RectCoverage {
    /// No sample is covered.
    Reject,
    /// Some samples may be covered: test each.
    Partial,
    /// Every sample is covered.
    Accept,
}

/// The tiles of the rows `[y0, y1)` of an image `width` wide, row-major.
#[derive(Clone, Copy, Debug)]
pub struct TileGrid {
    pub width: u32,
    pub y0: u32,
    pub y1: u32,
    pub nx: u32,
    pub ny: u32,
}

impl TileGrid {
    pub fn new(width: u32, y0: u32, y1: u32) -> TileGrid {
        TileGrid { width, y0, y1, nx: width.div_ceil(TILE), ny: y1.saturating_sub(y0).div_ceil(TILE) }
    }

    pub fn count(&self) -> usize {
        (self.nx * self.ny) as usize
    }

    pub fn rect(&self, t: usize) -> PixelRect {
        let (tx, ty) = (t as u32 % self.nx, t as u32 / self.nx);
        let x0 = tx * TILE;
        let y0 = self.y0 + ty * TILE;
        PixelRect::new(x0, y0, (x0 + TILE).min(self.width), (y0 + TILE).min(self.y1))
    }
}

/// Classifies the samples of the pixels in `r` against a (narrow) triangle:
/// edge functions are affine, so their extremes over the samples are at the
/// corner samples chosen by the signs of the edge's gradient.
#[inline]
pub fn classify(ft: &FixedTri, r: PixelRect, off: [i64; 2]) -> RectCoverage {
    let sx = [r.x0 as i64 * ONE + off[0], (r.x1 as i64 - 1) * ONE + off[0]];
    let sy = [r.y0 as i64 * ONE + off[1], (r.y1 as i64 - 1) * ONE + off[1]];
    let mut all_in = true;
    for k in 0..3 {
        let (ix, iy) = ((ft.a[k] >= 0) as usize, (ft.b[k] >= 0) as usize);
        let max: i64 = ft.edge_at(k, sx[ix], sy[iy]);
        if max < ft.bias[k] {
            return RectCoverage::Reject;
        }
        let min: i64 = ft.edge_at(k, sx[1 - ix], sy[1 - iy]);
        all_in &= min >= ft.bias[k];
    }
    if all_in { RectCoverage::Accept } else { RectCoverage::Partial }
}

/// Bins the triangles (in order) into the tiles they may cover, with the
/// whole-tile classification (always `Partial` for wide triangles).
pub fn bin_tiles(tris: &[FixedTri], grid: &TileGrid, off: [i64; 2]) -> Vec<Vec<(u32, RectCoverage)>> {
    let mut bins = vec![Vec::new(); grid.count()];
    let rows = PixelRect::new(0, grid.y0, grid.width, grid.y1);
    for (i, ft) in tris.iter().enumerate() {
        let r = ft.bbox.intersect(&rows);
        if r.is_empty() {
            continue;
        }
        let (tx0, tx1) = (r.x0 / TILE, (r.x1 - 1) / TILE);
        let (ty0, ty1) = ((r.y0 - grid.y0) / TILE, (r.y1 - 1 - grid.y0) / TILE);
        for ty in ty0..=ty1 {
            for tx in tx0..=tx1 {
                let t = (ty * grid.nx + tx) as usize;
                let class = if ft.wide || ft.ray || (tx0 == tx1 && ty0 == ty1) {
                    // A triangle inside one tile is classified per block anyway.
                    RectCoverage::Partial
                } else {
                    classify(ft, grid.rect(t).intersect(&r), off)
                };
                if class != RectCoverage::Reject {
                    bins[t].push((i as u32, class));
                }
            }
        }
    }
    bins
}

/// Visits, triangle by triangle in bin order, the covered samples of `tile`
/// with their screen-space weights (the same bits as `fixed::raster`).
#[inline]
pub fn tile_fragments<F: FnMut(&FixedTri, u32, u32, [f32; 3])>(tris: &[FixedTri], bin: &[(u32, RectCoverage)], tile: PixelRect, off: [i64; 2], tested: &mut impl TestCounter, mut emit: F) {
    tile_fragment_rows(tris, bin, tile, off, tested, |ft, x0, y, bits| {
        for x in fixed::row_pixels(x0, bits) {
            emit(ft, x, y, ft.weights(x, y));
        }
    });
}

/// `tile_fragments` a row at a time: for each run of covered samples, the
/// triangle, the first sample's pixel `(x0, y)` and the covered samples of
/// pixels `x0..x0 + 8` in that row as bits (bit k: pixel `x0 + k`), in the
/// same order. For code that takes a row of samples at once.
#[inline]
pub fn tile_fragment_rows<F: FnMut(&FixedTri, u32, u32, u8)>(tris: &[FixedTri], bin: &[(u32, RectCoverage)], tile: PixelRect, off: [i64; 2], tested: &mut impl TestCounter, mut emit: F) {
    for &(i, class) in bin {
        let ft = &tris[i as usize];
        let r = ft.bbox.intersect(&tile);
        if r.is_empty() {
            continue;
        }
        if ft.wide {
            fixed::raster_rows(ft, r, off, tested, |x0, y, bits| emit(ft, x0, y, bits));
            continue;
        }
        let step_x = [0, 1, 2].map(|k| ft.a[k] * ONE);
        let step_y = [0, 1, 2].map(|k| ft.b[k] * ONE);
        let bx0 = tile.x0 + (r.x0 - tile.x0) / BLOCK * BLOCK;
        let by0 = tile.y0 + (r.y0 - tile.y0) / BLOCK * BLOCK;
        for by in (by0..r.y1).step_by(BLOCK as usize) {
            for bx in (bx0..r.x1).step_by(BLOCK as usize) {
                let br = PixelRect::new(bx, by, bx + BLOCK, by + BLOCK).intersect(&r);
                // Small rectangles (most of a fine mesh) are cheaper to test sample by sample.
                let c = match class {
                    RectCoverage::Accept => RectCoverage::Accept,
                    _ if br.area() <= 16 => RectCoverage::Partial,
                    _ => classify(ft, br, off),
                };
                if c == RectCoverage::Reject {
                    continue;
                }
                tested.add(br);
                if c == RectCoverage::Accept {
                    // Every sample covered: no edge function is needed.
                    let bits = ((1u32 << br.width()) - 1) as u8;
                    for y in br.y0..br.y1 {
                        emit(ft, br.x0, y, bits);
                    }
                    continue;
                }
                let mut row: [i64; 3] = ft.edges_at_pixel(br.x0, br.y0, off);
                // Partial block: a coverage mask (bit = dx + 8 dy), then the covered samples.
                let mut mask = 0u64;
                for dy in 0..br.height() {
                    let mut e = row;
                    for dx in 0..br.width() {
                        if ft.covered(&e) {
                            mask |= 1 << (dx + BLOCK * dy);
                        }
                        for k in 0..3 {
                            e[k] += step_x[k];
                        }
                    }
                    for k in 0..3 {
                        row[k] += step_y[k];
                    }
                }
                for dy in 0..br.height() {
                    let bits = (mask >> (BLOCK * dy)) as u8;
                    if bits != 0 {
                        emit(ft, br.x0, br.y0 + dy, bits);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;
    use crate::render::raster::setup::ScreenTri;
    use crate::render::raster::subpixel::snap_offset;

    #[test]
    fn classify_by_hand() {
        // Triangle (0,0), (64,0), (0,64) in a 64x64 image, samples at +0.5.
        let st = ScreenTri::flat(0, [Vec2::new(0.0, 0.0), Vec2::new(64.0, 0.0), Vec2::new(0.0, 64.0)], Vec2::splat(0.5), 64, 64).unwrap();
        let off = snap_offset(Vec2::splat(0.5));
        let ft = FixedTri::new(&st, off, Vec2::splat(0.5), 64, 64).unwrap();
        assert_eq!(classify(&ft, PixelRect::new(0, 0, 8, 8), off), RectCoverage::Accept);
        assert_eq!(classify(&ft, PixelRect::new(56, 56, 64, 64), off), RectCoverage::Reject);
        assert_eq!(classify(&ft, PixelRect::new(28, 28, 36, 36), off), RectCoverage::Partial);
        // The block just below the diagonal: its top-left sample (32.5, 24.5) has
        // x + y = 57 < 64, its bottom-right (39.5, 31.5) has 71: partial.
        assert_eq!(classify(&ft, PixelRect::new(32, 24, 40, 32), off), RectCoverage::Partial);
        // Block (24..32, 24..32): bottom-right sample 31.5 + 31.5 = 63 < 64: accept.
        assert_eq!(classify(&ft, PixelRect::new(24, 24, 32, 32), off), RectCoverage::Accept);
    }

    #[test]
    fn tile_grid_covers_the_rows() {
        let g = TileGrid::new(70, 5, 60);
        assert_eq!((g.nx, g.ny), (3, 2));
        assert_eq!(g.rect(0), PixelRect::new(0, 5, 32, 37));
        assert_eq!(g.rect(5), PixelRect::new(64, 37, 70, 60));
    }
}
