//! The frame loop: one pass per sample position, averaged. Used by the command
//! line and the viewer's worker alike.

use super::{sample_offset, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
use crate::math::Radiance;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};

pub struct FrameResult {
    pub width: u32,
    pub height: u32,
    /// Linear radiance, row-major, averaged over the samples.
    pub pixels: Vec<Radiance>,
    pub counts: RayCounts,
    /// The diff view: how many pixels differ from the reference.
    pub differing_pixels: Option<u64>,
}

/// Renders a whole frame of `settings.spp` samples. Returns `None` when
/// `cancel` was raised. `passes_done` (if given) counts finished passes, for
/// progress display.
pub fn render_frame(
    renderer: &dyn Renderer,
    prepared: &PreparedScene,
    settings: &RenderSettings,
    cancel: &AtomicBool,
    passes_done: Option<&AtomicU32>,
) -> Option<FrameResult> {
    render_frame_in_bands(renderer, prepared, settings, cancel, passes_done, 1, None)
}

/// As `render_frame`, with each pass split into `bands` bands of rows so that
/// `rows_done` can report progress within a pass (long reference renders).
/// Splitting costs the rasterizers one setup per band, so frames that are
/// timed use one band.
pub fn render_frame_in_bands(
    renderer: &dyn Renderer,
    prepared: &PreparedScene,
    settings: &RenderSettings,
    cancel: &AtomicBool,
    passes_done: Option<&AtomicU32>,
    bands: u32,
    rows_done: Option<&AtomicU64>,
) -> Option<FrameResult> {
    if settings.view == super::debug::View::Diff {
        // Both images shaded; the reference is the brute-force caster.
        let shaded = RenderSettings { view: super::debug::View::Shaded, ..settings.clone() };
        let mine = render_frame_in_bands(renderer, prepared, &shaded, cancel, passes_done, bands, rows_done)?;
        let reference = super::raytrace::brute::BruteForce;
        let theirs = render_frame_in_bands(&reference, prepared, &shaded, cancel, None, bands, None)?;
        let (pixels, count) = super::debug::diff_image(&mine.pixels, &theirs.pixels);
        return Some(FrameResult { pixels, differing_pixels: Some(count), ..mine });
    }
    if settings.shadows == super::ShadowMode::Map || settings.view == super::debug::View::Shadowmap {
        // Build the shadow maps once, in parallel, before the passes look them up.
        prepared.shadow_maps(settings.shadow_map_size);
    }
    let view = prepared.scene.camera.view(settings.width, settings.height);
    let n = (settings.width * settings.height) as usize;
    let spp = settings.spp.max(1);
    // With one sample the pass is the frame: render straight into it (adding
    // to zero and scaling by one would not change a bit, only cost time).
    let mut sum = vec![Radiance::ZERO; n];
    let mut pass = if spp == 1 { Vec::new() } else { vec![Radiance::ZERO; n] };
    let mut counts = RayCounts::default();
    for i in 0..spp {
        let target = if spp == 1 { &mut sum } else { &mut pass };
        let band_rows = settings.height.div_ceil(bands.clamp(1, settings.height.max(1)));
        let width = settings.width as usize;
        for (b, out) in target.chunks_mut(band_rows as usize * width).enumerate() {
            let y0 = b as u32 * band_rows;
            let job = PassJob {
                prepared,
                view: &view,
                settings,
                offset: sample_offset(i, spp),
                rows: y0..y0 + (out.len() / width) as u32,
                cancel,
            };
            counts += renderer.render_pass(&job, out);
            if let Some(done) = rows_done {
                done.fetch_add(job.rows.len() as u64, Ordering::Relaxed);
            }
        }
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        if spp > 1 {
            for (s, p) in sum.iter_mut().zip(&pass) {
                *s += *p;
            }
        }
        if let Some(done) = passes_done {
            done.fetch_add(1, Ordering::Relaxed);
        }
    }
    if spp > 1 {
        let inv = 1.0 / spp as f32;
        for s in &mut sum {
            *s *= inv;
        }
    }
    Some(FrameResult { width: settings.width, height: settings.height, pixels: sum, counts, differing_pixels: None })
}

/// A pixel replayed sample by sample: the records, and the final value, which
/// is averaged exactly as `render_frame` averages it.
pub struct PixelReplay {
    pub samples: Vec<(crate::math::Vec2, super::trace::PixelTrace, Radiance)>,
    pub radiance: Radiance,
}

/// Replays pixel `(x, y)` of the frame `render_frame` would render.
pub fn replay_pixel(renderer: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings, x: u32, y: u32) -> Result<PixelReplay, String> {
    if x >= settings.width || y >= settings.height {
        return Err(format!("pixel ({x}, {y}) is outside the {}x{} image", settings.width, settings.height));
    }
    if settings.shadows == super::ShadowMode::Map || settings.view == super::debug::View::Shadowmap {
        prepared.shadow_maps(settings.shadow_map_size);
    }
    let view = prepared.scene.camera.view(settings.width, settings.height);
    let cancel = AtomicBool::new(false);
    let spp = settings.spp.max(1);
    let mut sum = Radiance::ZERO;
    let mut samples = Vec::new();
    for i in 0..spp {
        let offset = sample_offset(i, spp);
        let job = PassJob { prepared, view: &view, settings, offset, rows: y..y + 1, cancel: &cancel };
        let mut rec = super::trace::PixelTrace::new();
        let value = renderer
            .trace_pixel(&job, x, y, &mut rec)
            .ok_or_else(|| format!("{} cannot replay pixels yet", renderer.name()))?;
        sum += value;
        samples.push((offset, rec, value));
    }
    Ok(PixelReplay { samples, radiance: sum * (1.0 / spp as f32) })
}
