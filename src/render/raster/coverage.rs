//! Coverage counts: how many times each variant's coverage loop visits each
//! sample, without depth test or shading. Used by the watertightness tests (a
//! mesh must cover every interior sample exactly once) and suited to a crack
//! debug view.

use crate::render::raster::fixed::{self, snap_triangles};
use crate::render::raster::rect::PixelRect;
use crate::render::raster::setup::ScreenTri;
use crate::render::raster::subpixel::snap_offset;
use crate::render::raster::tiled::{self, TileGrid};
use crate::render::raster::method::Method;
use crate::render::raster::{barycentric, incremental, scanline};
use crate::math::Vec2;

/// Runs the coverage loop of `method` over 2D triangles given in image
/// coordinates (either winding), samples at `offset` inside each pixel, and
/// returns per pixel (row-major) how many triangles covered its sample.
/// `None` for the methods whose coverage is a 3D ray test (naive, bbox).
pub fn coverage_counts(method: Method, width: u32, height: u32, offset: Vec2, tris: &[[Vec2; 3]]) -> Option<Vec<u32>> {
    let sts: Vec<ScreenTri> = tris.iter().enumerate().filter_map(|(i, p)| ScreenTri::flat(i as u32, *p, offset, width, height)).collect();
    let full = PixelRect::new(0, 0, width, height);
    let mut counts = vec![0u32; (width * height) as usize];
    let mut tested = 0u64;
    let mut hit = |x: u32, y: u32| counts[(x + y * width) as usize] += 1;
    match method {
        Method::Incremental => sts.iter().for_each(|st| incremental::raster(st, full, offset, &mut tested, |x, y, _| hit(x, y))),
        Method::Barycentric => sts.iter().for_each(|st| barycentric::raster(st, full, offset, &mut tested, |x, y, _| hit(x, y))),
        Method::Scanline => sts.iter().for_each(|st| scanline::raster(st, full, offset, &mut tested, |x, y, _| hit(x, y))),
        // The painter draws with fixed's coverage loop.
        Method::Fixed | Method::Painter => {
            let off = snap_offset(offset);
            for ft in snap_triangles(&sts, offset, width, height) {
                fixed::raster(&ft, full, off, &mut tested, |x, y, _| hit(x, y));
            }
        }
        Method::Tiled => {
            let off = snap_offset(offset);
            let fts = snap_triangles(&sts, offset, width, height);
            let grid = TileGrid::new(width, 0, height);
            let bins = tiled::bin_tiles(&fts, &grid, off);
            for (t, bin) in bins.iter().enumerate() {
                tiled::tile_fragments(&fts, bin, grid.rect(t), off, &mut tested, |_, x, y, _| hit(x, y));
            }
        }
        Method::Naive | Method::BBox => return None,
    }
    Some(counts)
}
