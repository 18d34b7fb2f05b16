//! The packet ray caster's tiles: eye rays of a TILE_W x TILE_H pixel tile
//! traced as one packet (`accel::packet`), then the tile's shadow rays
//! towards each light as one packet too, and the tile shaded eight samples
//! at a time from those answers (`shade_tile_batched`, `shade_batch`).
//!
//! A frame of many samples hands over up to sixteen passes at once
//! (`cast_passes_packets`): a packet then holds a few pixels' samples of
//! all of them, rays much closer together than one sample of 8x8 pixels.

use crate::render::accel::bvh::BvhQuery;
use crate::render::raytrace::{cast_pass, with_eye_differentials};
use crate::math::lanes::simd_level;
use crate::math::{Radiance, Ray};
use crate::render::inspect::debug::View;
use crate::render::inspect::pixel_record::NoRecord;
use crate::render::transport::path_batch;
use crate::render::transport::path_batch::PathPool;
use crate::render::transport::shade_batch;
use crate::render::transport::shade_batch::Batch;
use crate::render::{resolve_sample, view_miss_without_ray, PassJob, RayCounts, SceneQuery, ShadowMode};
use crate::scene::hit_lanes::TriangleHitInput;
use crate::scene::{CameraView, PrimitiveKind};
use fearless_simd::{dispatch, f32x8, Simd, SimdBase, SimdFrom};
use glam::Vec3;
use rayon::prelude::*;
use crate::render::accel::packet::*;
use crate::render::transport::shadow_packets::shadow_packets;

/// `cast_pass` for the BVH: the same pixels, eye rays traced a tile at a
/// time; where frames are shaded in batches, the tile's shadow rays go as
/// one packet per light and its surfaces are shaded eight at a time
/// (`shade_tile_batched`). Bands of TILE_H rows run in parallel. The cost
/// view (per-ray work), very deep trees and scenes with CSG objects (which
/// the packets do not test) take the single-ray path, and so do cameras
/// other than the pinhole, whose rays the packets' eye rays
/// (`CameraView::eye_ray_lanes`) and empty tiles (`SeenTiles`) do not
/// describe.
pub fn cast_pass_packets(job: &PassJob, query: &BvhQuery, out: &mut [Radiance]) -> RayCounts {
    if query.prepared.bvh.deep || query.has_cutouts() || job.settings.view == View::Cost || !query.prepared.scene.csgs.is_empty() || !job.view.is_pinhole() {
        return cast_pass(job, query, out);
    }
    let width = job.view.width as usize;
    // Shading in batches, or a debug view that colours each batch's records.
    let batched = shade_batch::resolved_in_batches(job);
    // Tiles that cannot see the scene are filled at once, where they can be.
    let empty = SeenTiles::where_useful(query, job, (TILE_W, TILE_H), SeenTiles::LEVELS_WHOLE);
    out.par_chunks_mut(width * TILE_H)
        .enumerate()
        // Packets, batches and the path pool are made once per rayon job,
        // not per band (each tile overwrites what it reads, and a band
        // leaves its pool empty): their buffers then grow once per pass
        // and thread rather than in every band.
        .map_init(
            || {
                (Packet::new(), Packet::new(), [None; P], TileContext::new(job))
            },
            |(pk, shadow_pk, hits, context), (b, band)| {
                let mut counts = RayCounts::default();
                if job.cancelled() {
                    return counts;
                }
                let y0 = job.rows.start as usize + b * TILE_H;
                let rows = band.len() / width;
                for x0 in (0..width).step_by(TILE_W) {
                    if let Some((tiles, value)) = &empty {
                        if !tiles.may_see(b * TILE_H, x0) {
                            let x1 = (x0 + TILE_W).min(width);
                            for row in band.chunks_exact_mut(width) {
                                row[x0..x1].fill(*value);
                            }
                            counts.primary += ((x1 - x0) * rows) as u64;
                            continue;
                        }
                    }
                    let valid = eye_rays_into(job, pk, (x0, y0), width, rows);
                    counts.primary += valid.count_ones() as u64;
                    query.closest_packet(pk, valid, &mut counts);
                    if batched {
                        shade_tile_batched::<false>(std::slice::from_ref(job), &TileLayout::ONE_PASS, query, pk, valid, shadow_pk, context, band, (x0, y0), 0, width, &mut counts);
                        continue;
                    }
                    pk.hits_into(query, valid, hits);
                    let mut m = valid;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let (tx, ty) = lane_xy(i);
                        let p = job.sample_position((x0 + tx) as u32, (y0 + ty) as u32);
                        with_eye_differentials(job, p, &pk.rays[i], &mut hits[i]);
                        band[ty * width + x0 + tx] = resolve_sample(job, query, &pk.rays[i], hits[i].as_ref(), job.pixel_index((x0 + tx) as u32, (y0 + ty) as u32), &mut counts, &mut NoRecord);
                    }
                }
                context.paths.follow_into(job, query, &mut counts, band);
                if !job.keep_non_finite {
                    counts.non_finite += crate::render::finite::admit_all(band);
                }
                counts
            },
        )
        .reduce(RayCounts::default, |mut a, b| {
            a += b;
            a
        })
}

/// `Renderer::render_passes` for the BVH: two to MAX_PASSES passes of the same
/// rows, pass k into `out[k * n..]` (n = the rows' pixels), traced as tiles
/// of a few pixels (`pass_tile`) with each pixel's samples of every pass in
/// one packet (`TileLayout::passes`), then shaded as `cast_pass_packets`
/// shades (a batch may hold samples of several passes: each lane keeps its
/// own sample index). Every sample is the one
/// `cast_pass_packets` makes for its pass: the same eye ray, hit, shadow
/// answers and shading. Runs on the calling thread (the frame's chunks are
/// what run in parallel). `None` where `cast_pass_packets` would not shade
/// in batches, or for one pass or more than MAX_PASSES: the caller then
/// renders pass by pass.
pub fn cast_passes_packets(jobs: &[PassJob], query: &BvhQuery, out: &mut [Radiance]) -> Option<RayCounts> {
    let first = jobs.first()?;
    let scene = &query.prepared.scene;
    if !(2..=MAX_PASSES).contains(&jobs.len()) || query.prepared.bvh.deep || query.has_cutouts() || first.settings.view == View::Cost || !scene.csgs.is_empty() || !shade_batch::batchable(first) || first.active.is_some() || !first.view.is_pinhole() {
        return None;
    }
    let width = first.view.width as usize;
    let rows = first.rows.len();
    let n = rows * width;
    debug_assert_eq!(out.len(), jobs.len() * n);
    let mut context = TileContext::new(first);
    let (mut pk, mut shadow_pk) = (Packet::new(), Packet::new());
    // The tile for the next power of two passes (lanes of missing passes
    // stay empty).
    let passes = jobs.len().next_power_of_two();
    let (tile_w, tile_h) = pass_tile(passes);
    let layout = TileLayout { lanes: PASS_LAYOUTS[passes.trailing_zeros() as usize - 1], pass_stride: n };
    let lanes = PassLanes::new(jobs, &layout);
    let mut counts = RayCounts::default();
    // The passes differ only in their sub-pixel offsets, inside the tiles.
    let empty = SeenTiles::where_useful(query, first, (tile_w, tile_h), SeenTiles::LEVELS_CHUNK);
    for ty0 in (0..rows).step_by(tile_h) {
        if first.cancelled() {
            break;
        }
        let y0 = first.rows.start as usize + ty0;
        for x0 in (0..width).step_by(tile_w) {
            if let Some((tiles, value)) = &empty {
                if !tiles.may_see(ty0, x0) {
                    let (x1, y1) = ((x0 + tile_w).min(width), (ty0 + tile_h).min(rows));
                    for pass in out.chunks_exact_mut(n) {
                        for row in pass[ty0 * width..y1 * width].chunks_exact_mut(width) {
                            row[x0..x1].fill(*value);
                        }
                    }
                    counts.primary += ((x1 - x0) * (y1 - ty0) * jobs.len()) as u64;
                    continue;
                }
            }
            let valid = dispatch!(simd_level(), simd => eye_rays_of_passes(simd, first.view, &lanes, &layout, &mut pk, (x0, y0), (tile_w, tile_h), width, rows - ty0));
            counts.primary += valid.count_ones() as u64;
            query.closest_packet(&mut pk, valid, &mut counts);
            shade_tile_batched::<true>(jobs, &layout, query, &pk, valid, &mut shadow_pk, &mut context, out, (x0, y0), ty0, width, &mut counts);
        }
    }
    context.paths.follow_into(first, query, &mut counts, out);
    Some(counts)
}

/// What the eye rays of a call's pass tiles need per group of eight lanes,
/// worked out once per call: each lane's pixel within the tile and its
/// pass's sub-pixel offset, as floats, and which lanes hold a pass.
struct PassLanes {
    dx: [[f32; 8]; P / 8],
    dy: [[f32; 8]; P / 8],
    offset_x: [[f32; 8]; P / 8],
    offset_y: [[f32; 8]; P / 8],
    with_pass: [u8; P / 8],
}

impl PassLanes {
    fn new(jobs: &[PassJob], layout: &TileLayout) -> PassLanes {
        let mut lanes = PassLanes { dx: [[0.0; 8]; P / 8], dy: [[0.0; 8]; P / 8], offset_x: [[0.0; 8]; P / 8], offset_y: [[0.0; 8]; P / 8], with_pass: [0; P / 8] };
        for (i, &(g, tx, ty)) in layout.lanes.iter().enumerate() {
            let (group, k) = (i / 8, i % 8);
            (lanes.dx[group][k], lanes.dy[group][k]) = (tx as f32, ty as f32);
            if let Some(job) = jobs.get(g as usize) {
                (lanes.offset_x[group][k], lanes.offset_y[group][k]) = (job.offset.x, job.offset.y);
                lanes.with_pass[group] |= 1 << k;
            }
        }
        lanes
    }
}

/// The eye rays of the pass tile at `(x0, y0)` laid out as `layout` says
/// (`rows` rows of the band are left, the tile `tile_w` pixels wide), as
/// `eye_rays_eight_wide` makes them; the lanes on a pixel.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn eye_rays_of_passes<S: Simd>(simd: S, view: &CameraView, lanes: &PassLanes, layout: &TileLayout, pk: &mut Packet, (x0, y0): (usize, usize), (tile_w, tile_h): (usize, usize), width: usize, rows: usize) -> u64 {
    let whole = x0 + tile_w <= width && rows >= tile_h;
    let (ox, oy) = (f32x8::splat(simd, x0 as f32), f32x8::splat(simd, y0 as f32));
    let mut valid = 0u64;
    for group in 0..P / 8 {
        let mut inside = lanes.with_pass[group];
        if !whole {
            for (k, &(_, tx, ty)) in layout.lanes[8 * group..8 * group + 8].iter().enumerate() {
                if x0 + tx as usize >= width || ty as usize >= rows {
                    inside &= !(1 << k);
                }
            }
        }
        if inside == 0 {
            continue;
        }
        // (x0 + dx) + offset, with x0 + dx an integer below 2^24: the
        // pixel's own `sample_position` in its lane's pass.
        let px = (ox + f32x8::simd_from(simd, lanes.dx[group])) + f32x8::simd_from(simd, lanes.offset_x[group]);
        let py = (oy + f32x8::simd_from(simd, lanes.dy[group])) + f32x8::simd_from(simd, lanes.offset_y[group]);
        store_eye_rays(view, pk, group, (px, py), inside);
        valid |= (inside as u64) << (8 * group);
    }
    valid
}

/// The eye rays through image positions `(px, py)` into lanes `8 * group..`
/// of `pk`, with their far ends, for the lanes set in `lanes`.
#[inline(always)]
fn store_eye_rays<S: Simd>(view: &CameraView, pk: &mut Packet, group: usize, (px, py): (f32x8<S>, f32x8<S>), lanes: u8) {
    let (origin, dir) = view.eye_ray_lanes(px, py);
    let far: [f32; 8] = view.far_t_lanes(px, py).into();
    let (origin, dir) = (origin.scatter(), dir.scatter());
    for k in 0..8 {
        if lanes & (1 << k) != 0 {
            pk.rays[8 * group + k] = Ray::new(origin[k], dir[k]);
            pk.t_max[8 * group + k] = far[k];
        }
    }
}

/// The eye rays of the tile at `(x0, y0)` (`rows` rows of the band, the
/// image `width` wide) into `pk`, for the lanes on an active pixel, which it
/// returns. Made eight at a time with `CameraView::eye_ray_lanes`: the same
/// rays a pixel replay makes one at a time.
fn eye_rays_into(job: &PassJob, pk: &mut Packet, (x0, y0): (usize, usize), width: usize, rows: usize) -> u64 {
    dispatch!(simd_level(), simd => eye_rays_eight_wide(simd, job, pk, (x0, y0), width, rows))
}

/// Each group of eight lanes' pixel offsets in its tile, as floats (`LANE_XY`).
const GROUP_DX: [[f32; 8]; P / 8] = group_offsets(0);
const GROUP_DY: [[f32; 8]; P / 8] = group_offsets(1);

const fn group_offsets(axis: usize) -> [[f32; 8]; P / 8] {
    let mut table = [[0.0f32; 8]; P / 8];
    let mut i = 0;
    while i < P {
        let (x, y) = LANE_XY[i];
        table[i / 8][i % 8] = if axis == 0 { x as f32 } else { y as f32 };
        i += 1;
    }
    table
}

#[inline(always)]
fn eye_rays_eight_wide<S: Simd>(simd: S, job: &PassJob, pk: &mut Packet, (x0, y0): (usize, usize), width: usize, rows: usize) -> u64 {
    let mut valid = 0u64;
    // A tile wholly inside the image, in a pass without inactive pixels,
    // has every lane on a pixel: its sample positions are made as lanes.
    // (x0 + dx) + offset, with x0 + dx an integer below 2^24: the same
    // float as the pixel's own `sample_position`.
    let whole = x0 + TILE_W <= width && rows >= TILE_H && job.active.is_none();
    let (ox, oy) = (f32x8::splat(simd, x0 as f32), f32x8::splat(simd, y0 as f32));
    let (sx, sy) = (f32x8::splat(simd, job.offset.x), f32x8::splat(simd, job.offset.y));
    for g in 0..P / 8 {
        let (px, py, group) = if whole {
            ((ox + f32x8::from_slice(simd, &GROUP_DX[g])) + sx, (oy + f32x8::from_slice(simd, &GROUP_DY[g])) + sy, 0xffu8)
        } else {
            let (mut px, mut py) = ([0.0f32; 8], [0.0f32; 8]);
            let mut group = 0u8;
            for k in 0..8 {
                let (tx, ty) = lane_xy(8 * g + k);
                let (x, y) = ((x0 + tx) as u32, (y0 + ty) as u32);
                let p = job.sample_position(x, y);
                (px[k], py[k]) = (p.x, p.y);
                if x0 + tx < width && ty < rows && job.is_active(x, y) {
                    group |= 1 << k;
                }
            }
            (f32x8::simd_from(simd, px), f32x8::simd_from(simd, py), group)
        };
        if group == 0 {
            continue;
        }
        store_eye_rays(job.view, pk, g, (px, py), group);
        valid |= (group as u64) << (8 * g);
    }
    valid
}

/// What shading a tile needs beside its hits: which shadow rays are
/// blocked, per light (lane bits of the tile, and of the batch being
/// shaded; kept per rayon job so no tile or band allocates), and what holds
/// for the whole pass.
struct TileContext<'p> {
    tile: Vec<u64>,
    batch: Vec<u8>,
    /// `batch` for the batch after it, when the two are shaded together.
    next_batch: Vec<u8>,
    /// Whether hits need ray differentials (`with_eye_differentials`).
    textured: bool,
    /// What a sample that sees nothing shows, when no ray is needed for it
    /// (`view_miss_without_ray`).
    background: Option<Radiance>,
    /// The tile's surfaces in batches of eight, in lane order.
    batches: Vec<Batch>,
    /// With `--gi path`, the band's samples whose paths wait to be followed
    /// together (several tiles' worth, so that the lanes stay full as the
    /// paths end).
    paths: PathPool<'p>,
}

impl<'p> TileContext<'p> {
    /// Empty buffers for the tiles of `job`'s pass (or passes).
    fn new(job: &PassJob<'p>) -> TileContext<'p> {
        let scene = &job.prepared.scene;
        TileContext {
            tile: vec![0; scene.lights.len()],
            batch: vec![0; scene.lights.len()],
            next_batch: vec![0; scene.lights.len()],
            textured: scene.has_textures(),
            background: view_miss_without_ray(job),
            batches: (0..P / shade_batch::LANES).map(|_| Batch::new()).collect(),
            paths: if path_batch::takes(job) { PathPool::with_capacity(PATH_SAMPLES) } else { PathPool::new() },
        }
    }
}

/// Which tiles of a pass's rows can see the scene at all. An eye ray runs
/// forward from the near plane along the line from the eye through its
/// image position; a line that meets the part of a box in front of the
/// near plane passes inside the rectangle that part projects to
/// (`rect_in_front`). So a tile outside the rectangles of boxes that hold
/// every primitive (the tree's boxes a few levels down, `Bvh::cut_boxes`)
/// sees only the background, exactly as its rays would.
struct SeenTiles {
    /// Per tile (row-major, `columns` a row), whether some box's rectangle
    /// reaches it.
    seen: Vec<bool>,
    columns: usize,
    /// The tiles' size in pixels.
    tile: (usize, usize),
}

impl SeenTiles {
    /// Tree levels whose boxes outline the scene: three (up to 512 boxes)
    /// for a pass over the whole image; two (up to 64) for the many calls
    /// of a frame rendered chunk by chunk, each with its own few rows.
    const LEVELS_WHOLE: u32 = 3;
    const LEVELS_CHUNK: u32 = 2;
    /// Pixels added around each rectangle for the projection's rounding
    /// against the rays' (each far below a pixel at image scale).
    const MARGIN: f32 = 2.0;

    /// For the tiles of `job`'s rows, `tile_w` x `tile_h` pixels from the
    /// first row's left, the scene outlined by the boxes `levels` down.
    fn new(query: &BvhQuery, job: &PassJob, (tile_w, tile_h): (usize, usize), levels: u32) -> SeenTiles {
        let (width, rows) = (job.view.width as usize, job.rows.len());
        let columns = width.div_ceil(tile_w);
        let tile_rows = rows.div_ceil(tile_h);
        let mut seen = vec![false; columns * tile_rows];
        let top = job.rows.start as f32;
        for b in query.prepared.bvh.cut_boxes(levels) {
            // A box wholly behind the eye rays' start is seen by no tile;
            // one that is not finite, by every tile.
            let Some(rect) = Self::rect_in_front(job.view, b.corners()) else { continue };
            let (x0, x1, y0, y1) = match rect {
                r if [r.0, r.1, r.2, r.3].iter().all(|v| v.is_finite()) => (r.0 - Self::MARGIN, r.1 + Self::MARGIN, r.2 - top - Self::MARGIN, r.3 - top + Self::MARGIN),
                _ => (f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY),
            };
            if x1 < 0.0 || y1 < 0.0 || x0 > width as f32 || y0 > rows as f32 {
                continue;
            }
            // Tiles holding image positions in [x0, x1] x [y0, y1].
            let tile = |v: f32, size: usize, count: usize| ((v.max(0.0) / size as f32) as usize).min(count - 1);
            for ty in tile(y0, tile_h, tile_rows)..=tile(y1, tile_h, tile_rows) {
                seen[ty * columns + tile(x0, tile_w, columns)..=ty * columns + tile(x1, tile_w, columns)].fill(true);
            }
        }
        SeenTiles { seen, columns, tile: (tile_w, tile_h) }
    }

    /// The image rectangle (x0, x1, y0, y1) in pixels of the part of the
    /// box with world corners `corners` (indexed by bits: 1 x, 2 y, 4 z)
    /// that lies in front of the plane at half the near distance; `None`
    /// when none of it does. Eye rays start on the near plane and run
    /// forward, so they meet only that part (the half keeps points their
    /// rounding puts just behind the near plane); it is the box clipped by
    /// the plane, a convex solid whose corners are the box's corners in
    /// front and the points where its edges cross the plane, and a line
    /// through the eye that meets it projects inside the rectangle of
    /// those corners. (A box reaching behind the eye, as a floor under the
    /// camera does, still leaves out the tiles above its horizon.)
    fn rect_in_front(view: &CameraView, corners: [Vec3; 8]) -> Option<(f32, f32, f32, f32)> {
        let clip = 0.5 * view.near;
        let camera = corners.map(|c| view.to_camera(c));
        let mut rect = (f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY);
        // Whether every point projected to finite pixels (min and max would
        // pass over a NaN, and the rectangle would miss its point).
        let mut finite = true;
        let mut add = |c: Vec3| {
            let p = view.project_camera(c);
            finite &= p.is_finite();
            rect = (rect.0.min(p.x), rect.1.max(p.x), rect.2.min(p.y), rect.3.max(p.y));
        };
        let in_front = |c: Vec3| -c.z >= clip;
        let mut any = false;
        for (i, &a) in camera.iter().enumerate() {
            if in_front(a) {
                add(a);
                any = true;
            }
            for bit in [1, 2, 4] {
                let b = camera[i | bit];
                if i & bit == 0 && in_front(a) != in_front(b) {
                    // Where the edge a-b crosses z = -clip.
                    let s = (-clip - a.z) / (b.z - a.z);
                    add(Vec3::new(a.x + (b.x - a.x) * s, a.y + (b.y - a.y) * s, -clip));
                }
            }
        }
        // A NaN corner compares false above and leaves its mark here; a
        // point beyond the floats (a tiny near distance) is not bounded.
        if !finite || camera.iter().any(|c| !c.is_finite()) {
            return Some((f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY));
        }
        // The points above are off by their rounding, up to a few units in
        // the last place of the coordinates' magnitude (that of the box and
        // the eye), which the projection magnifies by up to 1 / clip: the
        // rectangle grows by a generous bound of that in pixels (a
        // thousandth of a pixel near an ordinary scene; much more for a
        // huge box whose edges cross the plane near the eye).
        let magnitude = corners.iter().fold(view.eye.abs().max_element(), |m, c| m.max(c.abs().max_element()));
        let pixels = 0.5 * (view.width as f32 / view.half_x).max(view.height as f32 / view.half_y);
        let grow = 64.0 * f32::EPSILON * magnitude / clip * pixels;
        // (A grow that is not finite leaves a rectangle that is not, which
        // the caller takes as every tile.)
        any.then_some((rect.0 - grow, rect.1 + grow, rect.2 - grow, rect.3 + grow))
    }

    /// `SeenTiles` for `job`'s tiles where tiles that see nothing can be
    /// filled without rays: a miss shows the background, or the debug
    /// view's colour for a miss, without a ray (that value is returned
    /// too), every pixel is in the pass, and the
    /// tree is all that rays meet.
    fn where_useful(query: &BvhQuery, job: &PassJob, tile: (usize, usize), levels: u32) -> Option<(SeenTiles, Radiance)> {
        match (view_miss_without_ray(job), job.active) {
            (Some(value), None) if query.bvh_packets().is_some() && !job.rows.is_empty() => Some((SeenTiles::new(query, job, tile, levels), value)),
            _ => None,
        }
    }

    /// Whether the tile at row `y` (counted from the first of the rows,
    /// a tile's first) and column `x` (a tile's first) may see the scene.
    fn may_see(&self, y: usize, x: usize) -> bool {
        self.seen[y / self.tile.1 * self.columns + x / self.tile.0]
    }
}



/// Samples a band gathers before following their paths: sixteen tiles.
/// The more a depth holds, the fuller the bounce rays' packets past the
/// first bounce (four tiles: `bunny_ground` path frames 3% slower;
/// forty-eight: no faster).
const PATH_SAMPLES: usize = 16 * P;

/// Lane `i`'s (pass, x, y) in its tile: `layout`'s, or with one pass
/// `lane_xy`'s (the table the compiler then reads directly).
#[inline(always)]
fn lane_of<const PASSES: bool>(layout: &TileLayout, i: usize) -> (usize, usize, usize) {
    if PASSES {
        let (g, x, y) = layout.lanes[i];
        (g as usize, x as usize, y as usize)
    } else {
        let (x, y) = lane_xy(i);
        (0, x, y)
    }
}

/// Shades one traced tile in batches of eight (`shade_batch`): the lanes
/// that see a surface are put into batches in lane order (a triangle's
/// record built in its batch, eight at a time; each lane keeps its own
/// pass's sample index), then the tile's shadow rays towards every light go as one
/// packet per light, then the batches are shaded, each light's visibility
/// read from its packet. In a debug view that colours what is hit
/// (`shade_batch::resolved_in_batches`) the batches' records are coloured
/// instead, with no shadow rays. Lane i holds the sample `layout` names, of pass
/// `jobs[layout.lanes[i].0]`; `band` holds the tile's rows from `row`, each
/// `width` pixels. Compiled apart for one pass (`PASSES` false: lanes as
/// `lane_xy`, every batch the one job's), which frames of one sample take
/// tile by tile, and for several.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn shade_tile_batched<'p, const PASSES: bool>(
    jobs: &[PassJob<'p>],
    layout: &TileLayout,
    query: &BvhQuery,
    pk: &Packet,
    valid: u64,
    shadow_pk: &mut Packet,
    context: &mut TileContext<'p>,
    band: &mut [Radiance],
    (x0, y0): (usize, usize),
    row: usize,
    width: usize,
    counts: &mut RayCounts,
) {
    let TileContext { tile: blocked, batch: lane_blocked, next_batch: next_blocked, textured, background, batches, paths } = context;
    let scene = &query.prepared.scene;
    let first = &jobs[0];
    let settings = first.settings;
    let interpolation = shade_batch::build_interpolation(first);
    let out_index = |i: usize| {
        let (g, tx, ty) = lane_of::<PASSES>(layout, i);
        g * layout.pass_stride + (row + ty) * width + x0 + tx
    };
    let mut filled = 0usize;
    let mut m = valid;
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        // A whole group of eight lanes that all see a triangle (most of a
        // tile's groups) fills a batch at once, from the packet's lanes.
        if i % 8 == 0 && (m >> i) & 0xff == 0xff && filled % shade_batch::LANES == 0 && !*textured && pk.best_id[i..i + 8].iter().all(|id| !id.is_none() && id.kind() == PrimitiveKind::Triangle) {
            let group = i..i + 8;
            let mut index = [0u32; 8];
            let (mut pixels, mut samples, mut slots) = ([0u32; 8], [0u32; 8], [0usize; 8]);
            for (k, lane) in group.clone().enumerate() {
                index[k] = pk.best_id[lane].index();
                let (g, tx, ty) = lane_of::<PASSES>(layout, lane);
                let job = if PASSES { &jobs[g] } else { first };
                pixels[k] = job.pixel_index((x0 + tx) as u32, (y0 + ty) as u32);
                samples[k] = job.sample;
                slots[k] = lane;
            }
            let t: &[f32; 8] = pk.best_t.0[group.clone()].try_into().expect("eight lanes");
            let (b1, b2): (&[f32; 8], &[f32; 8]) = (pk.bary[0].0[group.clone()].try_into().expect("eight lanes"), pk.bary[1].0[group.clone()].try_into().expect("eight lanes"));
            let dir: [[f32; 8]; 3] = std::array::from_fn(|a| pk.dir[a].0[group.clone()].try_into().expect("eight lanes"));
            debug_assert!(group.clone().enumerate().all(|(k, lane)| (0..3).all(|a| dir[a][k].to_bits() == pk.rays[lane].dir[a].to_bits())));
            batches[filled / shade_batch::LANES].fill_ray_triangles(scene, interpolation, &index, (b1, b2), t, &dir, pixels, samples, slots);
            filled += 8;
            m &= !(0xff << i);
            continue;
        }
        m &= m - 1;
        let (g, tx, ty) = lane_of::<PASSES>(layout, i);
        let job = if PASSES { &jobs[g] } else { first };
        let (x, y) = ((x0 + tx) as u32, (y0 + ty) as u32);
        let pixel = job.pixel_index(x, y);
        let id = pk.best_id[i];
        if id.is_none() {
            band[out_index(i)] = match background {
                Some(value) => *value,
                None => resolve_sample(job, query, &pk.rays[i], None, pixel, counts, &mut NoRecord),
            };
            continue;
        }
        let batch = &mut batches[filled / shade_batch::LANES];
        if id.kind() == PrimitiveKind::Triangle && !*textured {
            let input = TriangleHitInput::new(id.index(), pk.weights(i), pk.best_t.0[i], pk.rays[i].dir);
            batch.push_ray_triangle(input, pixel, job.sample, i);
        } else {
            let mut hit = pk.hit(query, i);
            if *textured {
                with_eye_differentials(job, job.sample_position(x, y), &pk.rays[i], &mut hit);
            }
            let hit = hit.expect("a lane with an id has a hit");
            batch.push(interpolation, &hit, pk.rays[i].dir, pixel, job.sample, i);
        }
        filled += 1;
    }
    let batches = &mut batches[..filled.div_ceil(shade_batch::LANES)];
    for batch in batches.iter_mut() {
        batch.build_pending(scene, first.view, interpolation);
    }
    if settings.view != View::Shaded {
        shade_batch::colour_batches(first, batches, |batch, j, colour| band[out_index(batch.slots[j])] = colour);
        return;
    }
    let shadows = settings.shadows == ShadowMode::Ray;
    if shadows {
        shadow_packets(query, settings, batches, |b, j| batches[b].slots[j], shadow_pk, blocked, counts);
    }
    // Each batch's lanes' bits of the tile's blocked rays, per light.
    let unpack = shadows.then_some(|_: usize, batch: &Batch, bits: &mut [u8]| {
        for (k, bits) in bits.iter_mut().enumerate() {
            *bits = (0..batch.len()).fold(0u8, |acc, j| acc | (((blocked[k] >> batch.slots[j]) & 1) as u8) << j);
        }
    });
    if path_batch::takes(first) {
        // The paths wait for those of the next tiles, to be followed
        // together (`PathPool::follow_into`, once it holds `PATH_SAMPLES`
        // and at the end of the band, or of the call with several passes).
        for (b, batch) in batches.iter_mut().enumerate() {
            if let Some(unpack) = &unpack {
                unpack(b, batch, lane_blocked);
            }
            // Where each lane's radiance goes in the band.
            let slots: [usize; shade_batch::LANES] = std::array::from_fn(|j| out_index(batch.slots[j]));
            path_batch::start_paths(first, query, batch, unpack.is_some().then_some(&lane_blocked[..]), &slots[..batch.len()], counts, paths);
            batch.clear();
        }
        if paths.len() >= PATH_SAMPLES {
            paths.follow_into(first, query, counts, band);
        }
        return;
    }
    shade_batch::shade_batches(first, query, batches, unpack, [lane_blocked, next_blocked], counts, |batch, j, value| band[out_index(batch.slots[j])] = value);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::RenderSettings;
    use crate::math::Vec2;
    use crate::render::inspect::pixel_record::NoRecord;
    use crate::render::{with_shading_hit, Interpolation, PreparedScene, SceneQuery};
    use crate::scene::builtin;

    /// `rect_in_front` by hand, the camera at the origin looking down -z
    /// (800x500): a box behind the eye has no rectangle; one reaching from
    /// behind the eye to beyond the near plane has the rectangle of its
    /// part in front (here, through the image's centre); a near distance
    /// so small that its points project beyond the floats gives every tile.
    #[test]
    fn boxes_are_clipped_at_the_near_plane() {
        let box_corners = |min: Vec3, max: Vec3| crate::render::accel::bvh::Aabb { min, max }.corners();
        let view = crate::scene::Camera::default().view(800, 500);
        assert_eq!(SeenTiles::rect_in_front(&view, box_corners(Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, 1.0, 2.0))), None);
        // Only a sliver of a thin slab behind the near plane: nothing.
        assert_eq!(SeenTiles::rect_in_front(&view, box_corners(Vec3::new(-1.0, -1.0, -0.04), Vec3::new(1.0, 1.0, 1.0))), None);
        let (x0, x1, y0, y1) = SeenTiles::rect_in_front(&view, box_corners(Vec3::new(-0.01, -0.01, -5.0), Vec3::new(0.01, 0.01, 5.0))).expect("a part in front");
        assert!([x0, x1, y0, y1].iter().all(|v| v.is_finite()));
        // Its part in front projects around the centre, no wider than at
        // the clip plane (half the near distance: 0.01 / 0.05 of the
        // image's half height, tan 30 degrees, over 250 pixels).
        let half = 0.01 / 0.05 / 30f32.to_radians().tan() * 250.0;
        assert!(x0 <= 400.0 && x1 >= 400.0 && y0 <= 250.0 && y1 >= 250.0, "{x0} {x1} {y0} {y1}");
        assert!(x1 - x0 <= 2.0 * half + 1.0 && x1 - x0 >= 2.0 * half - 1.0, "{x0} {x1} against half width {half}");
        let tiny = crate::scene::Camera { near: 1e-40, ..crate::scene::Camera::default() }.view(800, 500);
        let every = SeenTiles::rect_in_front(&tiny, box_corners(Vec3::new(-1.0, -1.0, -5.0), Vec3::new(1.0, 1.0, 5.0))).expect("a part in front");
        assert!(![every.0, every.1, every.2, every.3].iter().all(|v| v.is_finite()), "{every:?}");
    }

    /// Boxes reaching behind the eye leave out the tiles that cannot see
    /// the part of them in front: the built-in bunny's floor runs under
    /// and behind the camera, and the tiles above its horizon (the top
    /// rows of the image) are left out; `tiles_left_out_see_nothing` holds
    /// every left-out tile to seeing nothing.
    #[test]
    fn a_floor_behind_the_eye_leaves_the_sky_out() {
        let scene = builtin::load_builtin("bunny").unwrap().unwrap();
        let prepared = PreparedScene::new(scene);
        let query = BvhQuery::new(&prepared);
        let (w, h) = (160u32, 100u32);
        let view = prepared.scene.camera.view(w, h);
        let floor_behind = prepared.scene.triangles.iter().any(|t| t.v.iter().any(|&v| view.project(v).is_none()));
        assert!(floor_behind, "the floor should reach behind the near plane");
        let settings = RenderSettings::for_scene(&prepared.scene);
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: Vec2::splat(0.5), sample: 0, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false };
        let tiles = SeenTiles::new(&query, &job, (TILE_W, TILE_H), SeenTiles::LEVELS_WHOLE);
        let top_row_left_out = (0..w as usize).step_by(TILE_W).filter(|&x0| !tiles.may_see(0, x0)).count();
        assert!(top_row_left_out >= 10, "only {top_row_left_out} of the top row's {} tiles left out", (w as usize).div_ceil(TILE_W));
    }

    /// A tile `SeenTiles` leaves out holds no pixel whose eye ray meets
    /// anything: on every built-in scene without instances or CSG, from its
    /// own camera, from cameras turned so that the scene lies partly off
    /// the image or behind the eye, and from one looking away from it, in
    /// passes of rows starting mid-image.
    #[test]
    fn tiles_left_out_see_nothing() {
        let mut left_out = 0;
        for name in builtin::names() {
            let mut scene = builtin::load_builtin(name).unwrap().unwrap();
            let camera = scene.camera.clone();
            // The last turn looks back, the scene behind the eye.
            let turns = [Vec3::ZERO, Vec3::new(0.3, 0.0, 0.0), Vec3::new(-0.45, 0.2, 0.0), Vec3::new(0.0, -0.35, 0.1), Vec3::NAN];
            for (turn, rows) in turns.iter().zip([0..41u32, 7..41, 13..30, 0..41, 0..41]) {
                let forward = (camera.target - camera.eye).length();
                scene.camera.target = if turn.is_nan() { 2.0 * camera.eye - camera.target } else { camera.target + *turn * forward * 2.0 };
                let prepared = PreparedScene::new(scene.clone());
                let query = BvhQuery::new(&prepared);
                if query.bvh_packets().is_none() {
                    continue;
                }
                let (w, h) = (67u32, 41u32);
                let view = prepared.scene.camera.view(w, h);
                let settings = RenderSettings::for_scene(&prepared.scene);
                let cancel = std::sync::atomic::AtomicBool::new(false);
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: Vec2::splat(0.5), sample: 0, photons: None, active: None, rows: rows.clone(), cancel: &cancel, keep_non_finite: false };
                // The one-pass tiles and those of 2, 8 and 16 passes, each
                // with the outlines of both depths.
                let sizes = [(TILE_W, TILE_H), pass_tile(2), pass_tile(8), pass_tile(16)];
                for ((tile_w, tile_h), levels) in sizes.into_iter().flat_map(|size| [(size, SeenTiles::LEVELS_WHOLE), (size, SeenTiles::LEVELS_CHUNK)]) {
                    let tiles = SeenTiles::new(&query, &job, (tile_w, tile_h), levels);
                    for ty0 in (0..rows.len()).step_by(tile_h) {
                        for x0 in (0..w as usize).step_by(tile_w) {
                            if tiles.may_see(ty0, x0) {
                                continue;
                            }
                            left_out += 1;
                            for y in (rows.start as usize + ty0)..(rows.start as usize + ty0 + tile_h).min(rows.end as usize) {
                                for x in x0..(x0 + tile_w).min(w as usize) {
                                    // Sub-pixel offsets of any pass.
                                    for offset in [0.0, 0.5, 0.999] {
                                        let p = Vec2::new(x as f32 + offset, y as f32 + offset);
                                        let hit = query.closest(&view.eye_ray(p.x, p.y), view.far_t(p.x, p.y), false, &mut RayCounts::default(), &mut NoRecord);
                                        assert!(hit.is_none(), "{name}, turned {turn}: {tile_w}x{tile_h} tile at ({x0}, {ty0}) left out, but {p} sees something");
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        assert!(left_out > 50, "only {left_out} tiles left out: the test checks little");
    }


    /// Several passes traced together (`cast_passes_packets`) give each
    /// pass, bit for bit, what `cast_pass_packets` gives it alone: on every
    /// built-in scene without CSG, direct and path traced, two to sixteen
    /// passes (every tile layout, and lanes of a missing pass), an image
    /// whose width and rows cut the tiles, rows not starting at the top.
    #[test]
    fn passes_together_equal_passes_alone() {
        use crate::render::transport::gi::GiMode;
        use crate::render::{sample_offset, RenderSettings};
        use std::sync::atomic::AtomicBool;
        let cancel = AtomicBool::new(false);
        let mut compared = 0;
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            if !prepared.scene.csgs.is_empty() || prepared.bvh.deep {
                continue;
            }
            let query = BvhQuery::new(&prepared);
            let (w, h) = (23u32, 13u32);
            let view = prepared.scene.camera.view(w, h);
            for (gi, passes) in [(GiMode::None, 8u32), (GiMode::Path, 3), (GiMode::Path, 2), (GiMode::None, 4), (GiMode::Path, 16), (GiMode::None, 13)] {
                let mut settings = RenderSettings { width: w, height: h, spp: 2 * passes, ..RenderSettings::for_scene(&prepared.scene) };
                settings.gi.mode = gi;
                let rows = 2..h;
                let jobs: Vec<PassJob> = (passes..2 * passes)
                    .map(|pass| PassJob { prepared: &prepared, view: &view, settings: &settings, offset: sample_offset(pass, settings.spp, settings.gi.seed), sample: pass, photons: None, active: None, rows: rows.clone(), cancel: &cancel, keep_non_finite: false })
                    .collect();
                let n = (rows.len() * w as usize).max(1);
                let mut together = vec![Radiance::splat(-1.0); jobs.len() * n];
                let counts = cast_passes_packets(&jobs, &query, &mut together).expect("batched passes go together");
                let mut alone_counts = RayCounts::default();
                for (k, job) in jobs.iter().enumerate() {
                    let mut alone = vec![Radiance::splat(-2.0); n];
                    alone_counts += cast_pass_packets(job, &query, &mut alone);
                    let key = |v: &[Radiance]| v.iter().map(|r| r.to_array().map(f32::to_bits)).collect::<Vec<_>>();
                    assert_eq!(key(&together[k * n..(k + 1) * n]), key(&alone), "{name} {gi:?} pass {k} of {passes}");
                    compared += n;
                }
                assert_eq!((counts.primary, counts.shadow, counts.secondary), (alone_counts.primary, alone_counts.shadow, alone_counts.secondary), "{name} {gi:?}");
            }
            // One pass, or more than a packet holds, go pass by pass.
            let settings = RenderSettings { width: w, height: h, spp: 17, ..RenderSettings::for_scene(&prepared.scene) };
            let jobs: Vec<PassJob> = (0..17).map(|pass| PassJob { prepared: &prepared, view: &view, settings: &settings, offset: sample_offset(pass, 17, settings.gi.seed), sample: pass, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false }).collect();
            let mut out = vec![Radiance::ZERO; 17 * (w * h) as usize];
            assert!(cast_passes_packets(&jobs, &query, &mut out).is_none());
            assert!(cast_passes_packets(&jobs[..1], &query, &mut out[..(w * h) as usize]).is_none());
        }
        assert!(compared > 20_000, "only {compared} samples compared");
    }

    /// The shadow ray the pre-pass traces (`Batch::shadow_rays`, eight
    /// lanes at a time) is, bit for bit, the one `shade()` then asks for, so
    /// the packet's answer is used (were they to differ, the frame would
    /// still be right, only slower: no image test sees it). With and without
    /// the terminator lift, whose lanes are worked out one at a time.
    #[test]
    fn the_pre_pass_traces_the_shadow_ray_shade_casts() {
        use crate::render::transport::shade::shade;
        use crate::render::inspect::pixel_record::PixelTrace;
        use crate::render::RenderSettings;
        let bits = |(r, t): (Ray, f32)| (r.origin.to_array().map(f32::to_bits), r.dir.to_array().map(f32::to_bits), t.to_bits());
        let mut compared = 0;
        let mut lifted = 0;
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            let Some(light) = prepared.scene.lights.first() else { continue };
            let query = BvhQuery::new(&prepared);
            let (w, h) = (47u32, 35u32);
            let view = prepared.scene.camera.view(w, h);
            for (interpolation, lift) in [(Interpolation::Phong, true), (Interpolation::Flat, true), (Interpolation::Phong, false)] {
                let settings = RenderSettings { interpolation, shadows: ShadowMode::Ray, terminator_lift: lift, ..RenderSettings::for_scene(&prepared.scene) };
                let mut batch = Batch::new();
                let mut expected = Vec::new();
                let mut check = |batch: &mut Batch, expected: &mut Vec<Option<(Ray, f32)>>| {
                    let mut got = [None; shade_batch::LANES];
                    batch.shadow_rays(&prepared.scene, light, settings.shadow_bump, settings.terminator_lift, |j, ray, t_max| got[j] = Some((ray, t_max)));
                    for (j, e) in expected.iter().enumerate() {
                        assert_eq!(got[j].map(bits), e.map(bits), "{name} {interpolation:?} lift {lift} lane {j}");
                        compared += e.is_some() as u32;
                        if let Some((ray, _)) = e {
                            let hit = batch.hit(j);
                            lifted += (ray.origin != hit.position + ray.dir * settings.shadow_bump) as u32;
                        }
                    }
                    batch.clear();
                    expected.clear();
                };
                for (x, y) in (0..w).flat_map(|x| (0..h).map(move |y| (x, y))) {
                    let ray = view.eye_ray(x as f32 + 0.5, y as f32 + 0.5);
                    let Some(hit) = query.closest(&ray, view.far_t(x as f32 + 0.5, y as f32 + 0.5), false, &mut RayCounts::default(), &mut NoRecord) else { continue };
                    let mut trace = PixelTrace::new();
                    with_shading_hit(interpolation, &hit, |h| {
                        let mut path = crate::render::transport::gi::PathState::new(0, 0, 1, &settings.gi, None);
                        let mut sh = crate::render::transport::shading::Shading { scene: &prepared.scene, query: &query, settings: &settings, path: &mut path, counts: &mut RayCounts::default(), rec: &mut trace };
                        shade(&mut sh, h, -ray.dir, 0)
                    });
                    expected.push(trace.lights.iter().find(|l| l.light == 0).and_then(|l| l.shadow_ray));
                    batch.push(interpolation, &hit, ray.dir, 0, 0, 0);
                    if batch.is_full() {
                        check(&mut batch, &mut expected);
                    }
                }
                check(&mut batch, &mut expected);
            }
        }
        assert!(lifted > 0, "no lifted origin compared");
        assert!(compared > 1000, "only {compared} shadow rays compared");
    }
}
