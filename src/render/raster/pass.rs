//! One sample pass of a rasterizer: set the triangles up, split the requested
//! rows into regions (bands of rows, or tiles), rasterize each region in
//! parallel into its own visibility buffer (triangles in scene order, then the
//! spheres), and resolve it into the output. Regions never share pixels, so
//! the result does not depend on the number of threads.

use super::fixed::{self, snap_all, snap_offset};
use super::setup::{bin_rows, setup_pass, PixelRect};
use super::sphere::{all_sphere_bounds, raster_spheres};
use super::tiled::{self, TileGrid};
use super::vis_buffer::{DepthKey, VisBuffer};
use super::{barycentric, incremental, scanline, Method, RasterOptions};
use crate::math::Radiance;
use crate::render::raytrace::bvh::BvhQuery;
use crate::render::{PassJob, PreparedScene, RayCounts};
use rayon::prelude::*;

/// The scene query for shadow and secondary rays of rasterized frames.
pub type Query<'a> = BvhQuery<'a>;

pub fn query(prepared: &PreparedScene) -> Query<'_> {
    BvhQuery::new(prepared)
}

/// Rows per band of the band-parallel variants.
pub const BAND_ROWS: u32 = 16;

/// Runs `raster_band(buffer, band index)` for every band of `BAND_ROWS` rows of
/// the job in parallel, then the spheres, then resolves each band into `out`.
pub fn bands<'a, F>(job: &PassJob, query: &Query<'a>, key: DepthKey, forward: bool, out: &mut [Radiance], raster_band: F) -> RayCounts
where
    F: Fn(&mut VisBuffer<Query<'a>>, usize) + Sync,
{
    let width = job.view.width as usize;
    if width == 0 || job.rows.is_empty() {
        return RayCounts::default();
    }
    let spheres = all_sphere_bounds(job.view, &job.prepared.scene.spheres, job.offset);
    out.par_chunks_mut(width * BAND_ROWS as usize)
        .enumerate()
        .map(|(b, chunk)| {
            if job.cancelled() {
                return RayCounts::default();
            }
            let y0 = job.rows.start + b as u32 * BAND_ROWS;
            let y1 = (y0 + BAND_ROWS).min(job.rows.end);
            let mut vb = VisBuffer::new(job, query, PixelRect::new(0, y0, job.view.width, y1), key, forward);
            raster_band(&mut vb, b);
            raster_spheres(&mut vb, &spheres);
            vb.finish(chunk)
        })
        .reduce(RayCounts::default, |mut a, b| {
            a += b;
            a
        })
}

/// The variants that rasterize projected triangles band by band.
pub fn render_bands(method: Method, options: RasterOptions, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
    let query = query(job.prepared);
    let tris = setup_pass(job);
    let forward = !options.early_depth;
    let key = DepthKey::NegInvZ;
    let (rows0, rows1) = (job.rows.start, job.rows.end);
    let off = job.offset;
    match method {
        Method::Fixed => {
            let off = snap_offset(off);
            let fts = snap_all(&tris, job.offset, job.view.width, job.view.height);
            let bins = bin_rows(fts.iter().map(|f| f.bbox), rows0, rows1, BAND_ROWS);
            bands(job, &query, key, forward, out, |vb, b| {
                let (rect, mut tested) = (vb.rect, 0);
                for &i in &bins[b] {
                    let ft = &fts[i as usize];
                    fixed::raster(ft, rect, off, &mut tested, |x, y, l| vb.triangle_fragment(&ft.st, x, y, l));
                }
                vb.counts.samples_tested += tested;
            })
        }
        Method::Incremental | Method::Barycentric | Method::Scanline => {
            let bins = bin_rows(tris.iter().map(|t| t.bbox), rows0, rows1, BAND_ROWS);
            bands(job, &query, key, forward, out, |vb, b| {
                let (rect, mut tested) = (vb.rect, 0);
                for &i in &bins[b] {
                    let st = &tris[i as usize];
                    let emit = |x, y, l| vb.triangle_fragment(st, x, y, l);
                    match method {
                        Method::Incremental => incremental::raster(st, rect, off, &mut tested, emit),
                        Method::Barycentric => barycentric::raster(st, rect, off, &mut tested, emit),
                        _ => scanline::raster(st, rect, off, &mut tested, emit),
                    }
                }
                vb.counts.samples_tested += tested;
            })
        }
        Method::Naive | Method::BBox | Method::Tiled => unreachable!("not a band variant"),
    }
}

/// The tiled variant: bin, then rasterize and resolve the tiles in parallel.
pub fn render_tiled(options: RasterOptions, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
    let width = job.view.width;
    if width == 0 || job.rows.is_empty() {
        return RayCounts::default();
    }
    let query = query(job.prepared);
    let off = snap_offset(job.offset);
    let fts = snap_all(&setup_pass(job), job.offset, width, job.view.height);
    let grid = TileGrid::new(width, job.rows.start, job.rows.end);
    let bins = tiled::bin(&fts, &grid, off);
    let spheres = all_sphere_bounds(job.view, &job.prepared.scene.spheres, job.offset);
    // Rows of tiles in parallel; the tiles of a row one after the other, each
    // resolved straight into the output through one reused buffer.
    out.par_chunks_mut(width as usize * tiled::TILE as usize)
        .enumerate()
        .map(|(ty, chunk)| {
            let mut counts = RayCounts::default();
            let first = grid.rect(ty * grid.nx as usize);
            let mut vb = VisBuffer::new(job, &query, first, DepthKey::NegInvZ, !options.early_depth);
            for tx in 0..grid.nx as usize {
                if job.cancelled() {
                    break;
                }
                let t = ty * grid.nx as usize + tx;
                let rect = grid.rect(t);
                vb.reset(rect);
                let mut tested = 0;
                tiled::tile_fragments(&fts, &bins[t], rect, off, &mut tested, |ft, x, y, l| vb.triangle_fragment(&ft.st, x, y, l));
                vb.counts.samples_tested += tested;
                raster_spheres(&mut vb, &spheres);
                counts += vb.finish_into(chunk, width as usize, rect.x0 as usize);
            }
            counts
        })
        .reduce(RayCounts::default, |mut a, b| {
            a += b;
            a
        })
}
