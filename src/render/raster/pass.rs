//! One sample pass of a rasterizer: set the triangles up, split the requested
//! rows into regions (bands of rows, or tiles), rasterize each region in
//! parallel into its own visibility buffer (triangles in scene order, then the
//! spheres), and resolve it into the output. Regions never share pixels, so
//! the result does not depend on the number of threads.
//!
//! A pass rasterizes one or more *layers*: one sample position each, with its
//! own setup and visibility buffer. Without MSAA there is one layer at the
//! pass's sample; with MSAA N there are N + 1: the pixel-centre layer that
//! shading reads and the N coverage samples (`msaa.rs`).
//!
//! The painter (`painter.rs`) draws no band in scene order: every layer sorts
//! all of the image's triangles and spheres back to front once, and each
//! band draws its share of that order with the depth test off.
//!
//! `replay_pixel` replays one pixel through this very code: the same setup and
//! coverage loops over the region holding the pixel (its row, or its tile),
//! with a recording `VisBuffer` that keeps that pixel's fragment history.

use crate::render::raster::fixed::{self, FixedTri};
use crate::render::raster::msaa;
use crate::render::raster::naive::{ray_test_rect, region_rays};
use crate::render::raster::rect::PixelRect;
use crate::render::raster::runs::Runs;
use crate::render::raster::setup::{bin_rows, bin_rows_by_id, setup_pass, ScreenTri};
use crate::render::raster::painter::{self, Paint};
use crate::render::raster::sphere::{all_sphere_bounds, raster_sphere, raster_spheres};
use crate::render::raster::stencil::StencilSetup;
use crate::render::raster::subpixel::snap_offset;
use crate::render::raster::tiled::{self, RectCoverage, TileGrid};
use crate::render::raster::vis_buffer::{DepthKey, FragmentRecorder, VisBuffer};
use crate::render::raster::method::Method;
use crate::render::raster::{barycentric, bbox, incremental, scanline, small};
use crate::math::prefetch::prefetch_value;
use crate::math::{Radiance, Vec2};
use crate::render::accel::bvh::BvhQuery;
use crate::render::inspect::pixel_record::PixelTrace;
use crate::render::inspect::debug;
use crate::render::{PassJob, PreparedScene, RayCounts, SceneQuery, ShadowMode};
use rayon::prelude::*;
use std::ops::Range;

/// How many triangles ahead of the one being drawn a band asks the cache
/// for the next record (`Layer::raster`).
const RECORDS_AHEAD: usize = 4;

/// The scene query for shadow and secondary rays of rasterized frames.
pub type Query<'a> = BvhQuery<'a>;

pub fn query(prepared: &PreparedScene) -> Query<'_> {
    BvhQuery::new(prepared)
}

use crate::render::raster::BAND_ROWS;

/// What a variant's coverage loop reads, set up once per layer: float screen
/// triangles, or fixed-point (snapped) ones.
enum Geometry {
    /// naive: every triangle against every sample of the region.
    AllTriangles,
    /// bbox: each scene triangle's grown box, binned by band.
    TriangleBoxes { boxes: Vec<(u32, PixelRect)>, bins: Vec<Vec<u32>> },
    /// barycentric, incremental, scanline: screen triangles binned by band.
    FloatTriangles { tris: Vec<ScreenTri>, bins: Vec<Vec<u32>> },
    /// fixed: fixed-point (snapped) triangles binned by band, by id.
    FixedTriangles { fts: Runs<FixedTri>, off: [i64; 2], bins: Vec<Vec<u32>> },
    /// tiled: fixed-point (snapped) triangles binned by tile, with their whole-tile coverage.
    FixedTriangleTiles { fts: Vec<FixedTri>, off: [i64; 2], bins: Vec<Vec<(u32, RectCoverage)>> },
    /// painter: fixed-point triangles and spheres in draw order, the order binned by band.
    Painted { fts: Vec<FixedTri>, off: [i64; 2], order: Vec<Paint>, bins: Vec<Vec<u32>> },
}

/// One sample position of a pass, set up.
pub struct Layer<'a> {
    pub job: PassJob<'a>,
    method: Method,
    geometry: Geometry,
    spheres: Vec<Option<PixelRect>>,
    csgs: Vec<crate::render::raster::csg::CsgSetup>,
    /// MSAA coverage sample index; `None` for the pass's own sample.
    pub sample: Option<u32>,
    /// `--shadows volume`: the volume faces the stencil pass draws.
    stencil: Option<StencilSetup>,
}

/// `job` with its sample at `offset` and its rows `rows`.
fn job_at_offset<'a>(job: &PassJob<'a>, offset: Vec2, rows: Range<u32>) -> PassJob<'a> {
    PassJob { offset, rows, ..*job }
}

impl<'a> Layer<'a> {
    /// Sets up the rows of `job` at sample `offset`; tiles are those of `grid`.
    fn new(method: Method, job: &PassJob<'a>, offset: Vec2, sample: Option<u32>, grid: &TileGrid) -> Layer<'a> {
        let job = job_at_offset(job, offset, job.rows.clone());
        let (r0, r1) = (job.rows.start, job.rows.end);
        let (w, h) = (job.view.width, job.view.height);
        let spheres = all_sphere_bounds(job.view, &job.prepared.scene.spheres, offset);
        let csgs = crate::render::raster::csg::setup_csgs(job.view, &job.prepared.scene.csgs, offset);
        let geometry = match method {
            Method::Naive => Geometry::AllTriangles,
            Method::BBox => {
                let boxes = bbox::triangle_boxes(&job);
                let bins = bin_rows(boxes.iter().map(|b| b.1), r0, r1, BAND_ROWS);
                Geometry::TriangleBoxes { boxes, bins }
            }
            Method::Barycentric | Method::Incremental | Method::Scanline => {
                let tris = setup_pass(&job);
                let bins = bin_rows(tris.iter().map(|t| t.bbox), r0, r1, BAND_ROWS);
                Geometry::FloatTriangles { tris, bins }
            }
            Method::Fixed => {
                let fts = fixed::setup_snapped_or_small_runs(&job, offset, w, h);
                let bins = bin_rows_by_id(fts.with_ids().map(|(id, f)| (id, f.bbox)), r0, r1, BAND_ROWS);
                Geometry::FixedTriangles { fts, off: snap_offset(offset), bins }
            }
            Method::Tiled => {
                let off = snap_offset(offset);
                let fts = fixed::setup_snapped_or_small(&job, offset, w, h);
                let bins = tiled::bin_tiles(&fts, grid, off);
                Geometry::FixedTriangleTiles { fts, off, bins }
            }
            Method::Painter => {
                // The order is made over the whole image, whatever rows this
                // job renders, so a band shows what the frame shows.
                let frame = job_at_offset(&job, offset, 0..h);
                let fts = fixed::setup_snapped_or_small(&frame, offset, w, h);
                let (order, _) = painter::draw_order(&frame, &fts, &spheres);
                let rects = order.iter().map(|p| match *p {
                    Paint::Triangle(t) => fts[t as usize].bbox,
                    Paint::Sphere(s) => spheres[s as usize].unwrap_or(PixelRect::new(0, 0, 0, 0)),
                });
                let bins = bin_rows(rects, r0, r1, BAND_ROWS);
                Geometry::Painted { fts, off: snap_offset(offset), order, bins }
            }
        };
        let stencil = uses_stencil(&job).then(|| StencilSetup::new(&job));
        Layer { job, method, geometry, spheres, csgs, sample, stencil }
    }

    /// Rasterizes this layer's triangles of region `region` (band or tile
    /// index), then the spheres, into `vb` (whose rect lies in that region).
    pub fn raster<Q: SceneQuery, R: FragmentRecorder>(&self, vb: &mut VisBuffer<Q, R>, region: usize) {
        let rect = vb.rect;
        match &self.geometry {
            Geometry::AllTriangles => {
                let rays = region_rays(vb);
                for tri in 0..self.job.prepared.scene.total_triangles() as u32 {
                    if self.job.cancelled() {
                        return;
                    }
                    ray_test_rect(vb, &rays, tri, rect);
                }
            }
            Geometry::TriangleBoxes { boxes, bins } => {
                let rays = region_rays(vb);
                for &i in &bins[region] {
                    let (tri, b) = boxes[i as usize];
                    let r = b.intersect(&rect);
                    if !r.is_empty() {
                        ray_test_rect(vb, &rays, tri, r);
                    }
                }
            }
            Geometry::FloatTriangles { tris, bins } => {
                let off = self.job.offset;
                let mut tested = vb.begin_tests();
                for &i in &bins[region] {
                    let st = &tris[i as usize];
                    let emit = |x, y, l| vb.triangle_fragment(st, x, y, l);
                    match self.method {
                        Method::Incremental => incremental::raster(st, rect, off, &mut tested, emit),
                        Method::Barycentric => barycentric::raster(st, rect, off, &mut tested, emit),
                        _ => scanline::raster(st, rect, off, &mut tested, emit),
                    }
                }
                vb.end_tests(tested);
            }
            Geometry::FixedTriangles { fts, off, bins } => {
                let mut tested = vb.begin_tests();
                let bin = &bins[region];
                for (k, &i) in bin.iter().enumerate() {
                    // A band reads its triangles' records in bin order, which
                    // jumps about the array: ask for one a few triangles
                    // ahead while this one is drawn.
                    if let Some(&ahead) = bin.get(k + RECORDS_AHEAD) {
                        prefetch_value(fts.get(ahead));
                    }
                    let ft = fts.get(i);
                    if ft.ray {
                        small::ray_test(vb, ft, rect, &mut tested);
                    } else {
                        fixed::raster_rows(ft, rect, *off, &mut tested, |x0, y, bits| vb.triangle_row(ft, x0, y, bits));
                    }
                }
                vb.end_tests(tested);
            }
            Geometry::FixedTriangleTiles { fts, off, bins } => {
                let mut tested = vb.begin_tests();
                // Runs of grid triangles go through the tile loop together;
                // each small one, in its place, through the ray test.
                let bin = &bins[region];
                let mut start = 0;
                for (j, &(i, _)) in bin.iter().enumerate() {
                    let ft = &fts[i as usize];
                    if ft.ray {
                        tiled::tile_fragment_rows(fts, &bin[start..j], rect, *off, &mut tested, |ft, x0, y, bits| vb.triangle_row(ft, x0, y, bits));
                        small::ray_test(vb, ft, rect, &mut tested);
                        start = j + 1;
                    }
                }
                tiled::tile_fragment_rows(fts, &bin[start..], rect, *off, &mut tested, |ft, x0, y, bits| vb.triangle_row(ft, x0, y, bits));
                vb.end_tests(tested);
            }
            Geometry::Painted { fts, off, order, bins } => {
                for &i in &bins[region] {
                    match order[i as usize] {
                        Paint::Triangle(t) => {
                            let ft = &fts[t as usize];
                            let mut tested = vb.begin_tests();
                            if ft.ray {
                                small::ray_test(vb, ft, rect, &mut tested);
                            } else {
                                fixed::raster(ft, rect, *off, &mut tested, |x, y, l| vb.triangle_fragment(&ft.st, x, y, l));
                            }
                            vb.end_tests(tested);
                        }
                        Paint::Sphere(s) => {
                            if let Some(b) = self.spheres[s as usize] {
                                raster_sphere(vb, s, b);
                            }
                        }
                    }
                }
            }
        }
        // The painter drew the spheres in its order.
        if !matches!(self.geometry, Geometry::Painted { .. }) {
            raster_spheres(vb, &self.spheres);
        }
        crate::render::raster::csg::raster_csgs(vb, &self.csgs);
        if let Some(stencil) = &self.stencil {
            vb.count_volumes(stencil);
        }
    }
}

/// Shadow volumes are counted into a stencil for the shaded view only.
fn uses_stencil(job: &PassJob) -> bool {
    job.settings.shadows == ShadowMode::Volume && job.settings.view == debug::View::Shaded
}

fn depth_key(method: Method) -> DepthKey {
    match method {
        Method::Naive | Method::BBox => DepthKey::RayT,
        _ => DepthKey::NegInvZ,
    }
}

/// The layers of a pass: the pass's sample, plus the MSAA coverage samples.
fn layers<'a>(method: Method, job: &PassJob<'a>, grid: &TileGrid) -> Vec<Layer<'a>> {
    let mut out = vec![Layer::new(method, job, job.offset, None, grid)];
    for (k, off) in msaa::sample_offsets(job.settings.msaa, job.offset, job.settings.spp).into_iter().enumerate() {
        out.push(Layer::new(method, job, off, Some(k as u32), grid));
    }
    out
}

/// Resolves the region of `vbs` (one buffer per layer) into `out`: one buffer
/// on its own, MSAA layers together.
fn resolve_region<Q: SceneQuery, R: FragmentRecorder>(vbs: &mut [VisBuffer<Q, R>], out: &mut [Radiance], stride: usize, x_offset: usize) -> RayCounts {
    if vbs.len() == 1 {
        vbs[0].resolve_into(out, stride, x_offset)
    } else {
        msaa::resolve_into(vbs, out, stride, x_offset)
    }
}

fn layer_buffers<'j, 'a, Q: SceneQuery>(layers: &'j [Layer<'a>], query: &'j Q, rect: PixelRect, key: DepthKey, forward: bool) -> Vec<VisBuffer<'j, 'a, Q>> {
    layers
        .iter()
        .map(|l| {
            let mut vb = VisBuffer::new(&l.job, query, rect, key, forward);
            vb.sample = l.sample;
            vb.set_painter(l.method == Method::Painter);
            vb
        })
        .collect()
}

/// Forward shading applies without MSAA only (MSAA shades once per pixel per
/// primitive), and not with shadow volumes: their stencil needs the whole
/// depth pass before any light is added (an engine's depth pre-pass). The
/// image is the same; early depth just shades fewer fragments.
fn shades_forward(job: &PassJob) -> bool {
    !job.settings.early_depth && job.settings.msaa <= 1 && !uses_stencil(job)
}

/// Renders `job.rows` of one pass of `method` into `out`, counting the
/// copies made by `instances` that its setup draws and culls.
pub fn render(method: Method, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
    let mut counts = render_regions(method, job, out);
    if method != Method::Naive && !job.prepared.scene.instances.is_empty() {
        let v = crate::render::raster::cull::visible_spans(job);
        counts.instances_drawn += v.drawn;
        counts.instances_culled += v.culled;
    }
    counts
}

fn render_regions(method: Method, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
    let width = job.view.width;
    if width == 0 || job.rows.is_empty() {
        return RayCounts::default();
    }
    let query = query(job.prepared);
    let grid = TileGrid::new(width, job.rows.start, job.rows.end);
    let layers = layers(method, job, &grid);
    let (key, forward) = (depth_key(method), shades_forward(job));
    let sum = |mut a: RayCounts, b: RayCounts| {
        a += b;
        a
    };
    if method == Method::Tiled {
        // Rows of tiles in parallel; the tiles of a row one after the other,
        // each resolved straight into the output through reused buffers.
        return out
            .par_chunks_mut(width as usize * tiled::TILE as usize)
            .enumerate()
            .map(|(ty, chunk)| {
                let mut counts = RayCounts::default();
                let mut vbs = layer_buffers(&layers, &query, grid.rect(ty * grid.nx as usize), key, forward);
                for tx in 0..grid.nx as usize {
                    if job.cancelled() {
                        break;
                    }
                    let t = ty * grid.nx as usize + tx;
                    let rect = grid.rect(t);
                    for (l, vb) in layers.iter().zip(&mut vbs) {
                        vb.reset(rect);
                        l.raster(vb, t);
                    }
                    counts += resolve_region(&mut vbs, chunk, width as usize, rect.x0 as usize);
                }
                counts
            })
            .reduce(RayCounts::default, sum);
    }
    out.par_chunks_mut(width as usize * BAND_ROWS as usize)
        .enumerate()
        // A rayon job's bands reuse its buffers (reset per band): a fresh
        // set per band cost its allocation and the clearing of every array.
        // Depth keys that are ray parameters clear each pixel to its own
        // far end, made with the buffer: those buffers are made per band.
        .map_init(
            || None,
            |kept: &mut Option<Vec<VisBuffer<_>>>, (b, chunk)| {
                if job.cancelled() {
                    return RayCounts::default();
                }
                let y0 = job.rows.start + b as u32 * BAND_ROWS;
                let y1 = (y0 + BAND_ROWS).min(job.rows.end);
                let rect = PixelRect::new(0, y0, width, y1);
                let vbs = match kept {
                    Some(vbs) if key == DepthKey::NegInvZ => {
                        vbs.iter_mut().for_each(|vb| vb.reset(rect));
                        vbs
                    }
                    _ => kept.insert(layer_buffers(&layers, &query, rect, key, forward)),
                };
                for (l, vb) in layers.iter().zip(vbs.iter_mut()) {
                    l.raster(vb, b);
                }
                resolve_region(vbs, chunk, width as usize, 0)
            },
        )
        .reduce(RayCounts::default, sum)
}

/// Replays pixel `(x, y)` of the pass `render` draws for all rows of the
/// image (as `render_frame` does), recording its fragment
/// history and shading into `rec`. Returns the value `render` stores there.
pub fn replay_pixel(method: Method, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Radiance {
    let (width, height) = (job.view.width, job.view.height);
    let query = query(job.prepared);
    // The pass is set up as a frame sets it up (all rows: `render_frame`
    // renders each pass in one job); band variants then rasterize only the
    // pixel's row of its band (a pixel's coverage and values do not depend on
    // the rows around it), tiled the pixel's whole tile.
    let frame = job_at_offset(job, job.offset, 0..height);
    let grid = TileGrid::new(width, 0, height);
    let layers = layers(method, &frame, &grid);
    let (rect, region) = if method == Method::Tiled {
        let t = (y / tiled::TILE * grid.nx + x / tiled::TILE) as usize;
        (grid.rect(t), t)
    } else {
        (PixelRect::new(0, y, width, y + 1), (y / BAND_ROWS) as usize)
    };
    let (key, forward) = (depth_key(method), shades_forward(job));
    let mut vbs: Vec<_> = layers
        .iter()
        .map(|l| {
            let mut vb = VisBuffer::with_recorder(&l.job, &query, rect, key, forward, PixelTrace::new(), (x, y));
            vb.sample = l.sample;
            vb.set_painter(l.method == Method::Painter);
            vb
        })
        .collect();
    for (l, vb) in layers.iter().zip(&mut vbs) {
        l.raster(vb, region);
    }
    let i = vbs[0].index(x, y);
    let value = if vbs.len() == 1 { vbs[0].resolve(i, x, y) } else { msaa::resolve(&mut vbs, i, x, y) };
    // The layers' records in layer order: the pass's sample, then the coverage samples.
    for vb in vbs {
        rec.append(vb.rec);
    }
    value
}
