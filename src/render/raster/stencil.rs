//! The stencil pass of `--shadows volume` (see `shadow_volume`): after a
//! region's depth pass, every light's shadow-volume faces are rasterized over
//! it, and each covered pixel with a visible surface adds the face's
//! crossing to that light's count: z-pass counts faces in front of the
//! visible surface, z-fail the faces behind it, against the split depth
//! `shadow_volume::split_depth`. Nonzero counts are shadow; `shade()` reads
//! them through `shadow::ApproximateShadows`.
//!
//! Depths are compared as the ray casters compare them: the face's plane
//! intersected with the pixel's eye ray gives its ray parameter, the visible
//! surface's hit gives the other (a GPU would compare interpolated depths).
//! Faces are clipped at the near plane only: there is no far plane for
//! volumes (as with GL's depth clamp), which z-fail needs. Every variant
//! rasterizes the faces with the watertight fixed-point loop (`fixed`), so
//! faces that share an edge never count a sample twice or miss it.

use crate::render::raster::clip::{clip_near, triangle_vertices};
use crate::render::raster::fixed::{self, FixedTri};
use crate::render::raster::BAND_ROWS;
use crate::render::raster::rect::PixelRect;
use crate::render::raster::setup::{bin_rows, ScreenTri};
use crate::render::raster::subpixel::snap_offset;
use crate::math::Vec3;
use crate::render::shadow::volume::{crossing, VolumeMode};
use crate::render::PassJob;
use rayon::prelude::*;

/// One volume face (or a piece of it cut by the near plane), set up for a
/// layer: its coverage, and its world plane `n . p = k` for the depth.
struct StencilTri {
    light: u32,
    ft: FixedTri,
    n: Vec3,
    k: f32,
}

/// The volume faces of every light, set up for one layer of a pass.
pub struct StencilSetup {
    /// Counts per pixel: one per light of the scene.
    pub lights: usize,
    mode: VolumeMode,
    tris: Vec<StencilTri>,
    /// Per band of `BAND_ROWS` rows from `rows_start`: the faces overlapping it.
    bins: Vec<Vec<u32>>,
    rows_start: u32,
    off: [i64; 2],
}

/// Where a pixel's eye ray starts, where it goes, and its split depth; `None`
/// where the pixel sees nothing (no count needed).
pub type PixelRay = Option<(Vec3, Vec3, f32)>;

impl StencilSetup {
    /// Sets the shadow volumes of `job`'s scene up for its rows and sample.
    pub fn new(job: &PassJob) -> StencilSetup {
        let volumes = job.prepared.shadow_volumes();
        let view = job.view;
        let (w, h) = (view.width, view.height);
        let off = job.offset;
        let soff = snap_offset(off);
        let mut tris = Vec::new();
        for (l, vol) in volumes.volumes.iter().enumerate() {
            let per_face = vol.faces.par_iter().map(|f| {
                let n = (f[1] - f[0]).cross(f[2] - f[0]);
                let k = n.dot(f[0]);
                let c = f.map(|v| view.to_camera(v));
                let mut out = Vec::new();
                for piece in clip_near(triangle_vertices(c), view.near).as_slice() {
                    let p = piece.map(|v| view.project_camera(v.pos));
                    let Some(st) = ScreenTri::new(0, p, [1.0; 3], [Vec3::X, Vec3::Y, Vec3::Z], true, off, w, h) else { continue };
                    let Some(ft) = FixedTri::new(&st, soff, off, w, h) else { continue };
                    out.push(StencilTri { light: l as u32, ft, n, k });
                }
                out
            });
            tris.extend(per_face.collect::<Vec<_>>().into_iter().flatten());
        }
        let bins = bin_rows(tris.iter().map(|t| t.ft.bbox), job.rows.start, job.rows.end, BAND_ROWS);
        StencilSetup { lights: volumes.volumes.len(), mode: job.settings.shadow_volume, tris, bins, rows_start: job.rows.start, off: soff }
    }

    /// Fills `stencil` (`lights` counts per pixel of `rect`, row-major) for
    /// the pixels whose eye rays `rays` gives (one per pixel of `rect`).
    pub fn count(&self, rect: PixelRect, rays: &[PixelRay], stencil: &mut [i32]) {
        stencil.fill(0);
        if rect.is_empty() || self.bins.is_empty() || rect.y0 < self.rows_start {
            return;
        }
        let stride = rect.width() as usize;
        let band = |y: u32| ((y - self.rows_start) / BAND_ROWS) as usize;
        let (b0, b1) = (band(rect.y0), band(rect.y1 - 1).min(self.bins.len() - 1));
        let mut tested = 0u64;
        for b in b0..=b1 {
            for &ti in &self.bins[b] {
                let t = &self.tris[ti as usize];
                // A face in several of the rect's bands is drawn from the first.
                if band(t.ft.bbox.y0.max(rect.y0)) != b {
                    continue;
                }
                let light = t.light as usize;
                fixed::raster(&t.ft, rect, self.off, &mut tested, |x, y, _| {
                    let i = (x - rect.x0) as usize + (y - rect.y0) as usize * stride;
                    let Some((o, d, split)) = rays[i] else { return };
                    let nd = t.n.dot(d);
                    let depth = (t.k - t.n.dot(o)) / nd;
                    if depth.is_finite() {
                        stencil[i * self.lights + light] += crossing(self.mode, depth, split, nd < 0.0);
                    }
                });
            }
        }
    }
}
