//! Whole frames and single pixels: `render_frame` runs an `Accumulator` to
//! completion, `replay_pixel` replays one of its pixels sample by sample.

mod accumulator;
pub mod part;
pub mod subsample;

pub use part::FramePart;

pub use subsample::Subsample;
pub use accumulator::{add_sample, admitted, final_value, mean, relative_error, wants_more, Accumulator, Band, ADAPTIVE_MIN_SAMPLES, NAN_DIM, NAN_MARK};

use crate::render::{sample_offset, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
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
    /// `None`: the pixels are final values. `Some(passes)`: a part of the
    /// frame's sample passes, whose pixels are their samples' sums (what a
    /// merge adds up before it divides by the frame's samples per pixel).
    pub summed_passes: Option<std::ops::Range<u32>>,
}

/// How a caller follows and feeds a frame beyond its settings: the
/// defaults (`FrameOptions::default()`) render it in one band per pass
/// with nothing reported.
pub struct FrameOptions<'a> {
    /// Counts finished passes, for progress display.
    pub passes_done: Option<&'a AtomicU32>,
    /// Each pass split into this many bands of rows, so that `rows_done`
    /// can report progress within a pass (long reference renders).
    /// Splitting costs the rasterizers one setup per band, so frames that
    /// are timed use one band.
    pub bands: u32,
    /// Counts finished rows over all passes.
    pub rows_done: Option<&'a AtomicU64>,
    /// Storage to render into where it fits (`Accumulator::reusing`): what a
    /// caller that renders frame after frame (`pinhole bench`) hands back
    /// from the frame before.
    pub spare: Vec<Radiance>,
    /// Only this part of the frame (a crop, a tile, a sample range); the
    /// result is the part's size. `None`: the whole frame.
    pub part: Option<FramePart>,
}

impl Default for FrameOptions<'_> {
    fn default() -> Self {
        FrameOptions { passes_done: None, bands: 1, rows_done: None, spare: Vec::new(), part: None }
    }
}

/// Why a part of the frame cannot be rendered alone with `settings`, if
/// it cannot: a range of the passes needs every pixel's samples to be
/// independent of the others' and of the passes before.
pub fn check_part(part: &FramePart, settings: &RenderSettings) -> Result<(), String> {
    part.check(settings)?;
    if !part.all_passes(settings) {
        use crate::render::inspect::debug::View;
        if settings.adaptive.is_some() {
            return Err("--sample-range cannot split --adaptive sampling, whose later samples depend on the earlier ones".into());
        }
        if settings.subsample.is_on() && settings.view == View::Shaded {
            return Err("--sample-range cannot split a --subsample frame, which interpolates every pass over the whole image".into());
        }
        if settings.view != View::Shaded && settings.view.renders_shaded() {
            return Err(format!("--sample-range cannot split the {} view, which is drawn over the finished average", settings.view.name()));
        }
    }
    Ok(())
}

/// The rectangle `part` of a whole frame's `pixels` (width `width`).
fn cut(pixels: &[Radiance], width: u32, part: &FramePart) -> Vec<Radiance> {
    let w = width as usize;
    part.y.clone().flat_map(|y| &pixels[y as usize * w + part.x.start as usize..y as usize * w + part.x.end as usize]).copied().collect()
}

/// Renders a whole frame of `settings.spp` samples. Returns `None` when
/// `cancel` was raised. `passes_done` (if given) counts finished passes, for
/// progress display.
pub fn render_frame(renderer: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings, cancel: &AtomicBool, passes_done: Option<&AtomicU32>) -> Option<FrameResult> {
    render_frame_with(renderer, prepared, settings, cancel, FrameOptions { passes_done, ..FrameOptions::default() })
}

/// `render_frame` followed and fed as `options` say.
pub fn render_frame_with(renderer: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings, cancel: &AtomicBool, options: FrameOptions) -> Option<FrameResult> {
    let FrameOptions { passes_done, bands, rows_done, spare, part } = options;
    let part = part.filter(|p| *p != FramePart::whole(settings));
    // The part is cut from the whole frame's rows: every column of them is
    // rendered (renderers take bands of whole rows).
    let cut_part = |mut frame: FrameResult| {
        if let Some(p) = &part {
            frame.pixels = cut(&frame.pixels, frame.width, p);
            frame.width = p.width();
            frame.height = p.height();
        }
        frame
    };
    // Sub-sampling interpolates shaded images; debug views show every pixel.
    // Its grid spans the whole frame, so a part of it is cut from the whole.
    if settings.subsample.is_on() && settings.view == crate::render::inspect::debug::View::Shaded {
        assert!(part.as_ref().is_none_or(|p| p.all_passes(settings)), "check_part refuses sample ranges of a sub-sampled frame");
        return subsample::render_subsampled(renderer, prepared, settings, cancel, passes_done).map(cut_part);
    }
    let mut frame = Accumulator::reusing(settings, spare);
    if let Some(p) = &part {
        frame.limit_to(p.y.clone(), p.passes.clone());
    }
    // Without a count of passes to report, a renderer that renders a few
    // rows as cheaply as many takes the frame chunk by chunk.
    if let (None, Some(rows)) = (passes_done, renderer.chunk_rows())
        && frame.renders_in_chunks()
    {
        frame.render_in_chunks(renderer, prepared, rows, cancel, rows_done)?;
        return Some(cut_part(frame.finish()));
    }
    let rows = part.as_ref().map_or(settings.height, |p| p.height());
    let band_rows = rows.div_ceil(bands.clamp(1, rows.max(1)));
    while !frame.is_complete() {
        let band = frame.render_band(renderer, prepared, band_rows, cancel)?;
        if let Some(done) = rows_done {
            done.fetch_add(band.rows.len() as u64, Ordering::Relaxed);
        }
        if let (true, Some(done)) = (band.pass_done, passes_done) {
            done.fetch_add(1, Ordering::Relaxed);
        }
    }
    Some(cut_part(frame.finish()))
}

/// Builds the shadow maps `settings` look up (`--shadows map`, the shadow-map
/// view) once, in parallel, before the passes or a replay need them; samples
/// would otherwise build them serially on first use. The same for the shadow
/// volumes (`--shadows volume`).
pub fn build_shadow_maps(prepared: &PreparedScene, settings: &RenderSettings) {
    if settings.shadows == crate::render::ShadowMode::Map || settings.view == crate::render::inspect::debug::View::Shadowmap {
        prepared.shadow_maps(settings.shadow_map_size);
    }
    if settings.shadows == crate::render::ShadowMode::Volume && settings.view == crate::render::inspect::debug::View::Shaded {
        prepared.shadow_volumes();
    }
}

/// The photon map the passes read, built (once, in parallel) before them,
/// when the settings ask for photon mapping on the shaded view.
pub fn build_photon_map(prepared: &PreparedScene, settings: &RenderSettings) -> Option<std::sync::Arc<crate::render::transport::photon_map::PhotonMap>> {
    (settings.gi.mode == crate::render::transport::gi::GiMode::Photons && settings.view.renders_shaded())
        .then(|| prepared.photon_map(&settings.gi, settings.shadow_bump))
}

/// A pixel replayed sample by sample: the records (with the samples as the
/// renderer returned them), and the final value, which is accumulated exactly
/// as `render_frame` accumulates it.
pub struct PixelReplay {
    pub samples: Vec<(crate::math::Vec2, crate::render::inspect::pixel_record::PixelTrace, Radiance)>,
    pub radiance: Radiance,
}

/// Replays pixel `(x, y)` of the frame `render_frame` would render.
pub fn replay_pixel(renderer: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings, x: u32, y: u32) -> Result<PixelReplay, String> {
    if x >= settings.width || y >= settings.height {
        return Err(format!("pixel ({x}, {y}) is outside the {}x{} image", settings.width, settings.height));
    }
    // The wireframe view is the shaded frame with lines over it: the samples
    // are shaded, and a pixel under a line takes the line's colour.
    // So is the false-colour view, mapped once the pixel's value is final,
    // and the nan view, marked when a sample is not finite. The error views
    // replay the shaded pixel (the reference is their caller's).
    use crate::render::inspect::debug::View;
    let wireframe = settings.view == View::Wireframe;
    let false_colour = settings.view == View::FalseColour;
    let nan = settings.view == View::Nan;
    let shaded = RenderSettings { view: View::Shaded, ..settings.clone() };
    let settings = if wireframe || false_colour || nan || settings.view.error_kind().is_some() { &shaded } else { settings };
    build_shadow_maps(prepared, settings);
    let photons = build_photon_map(prepared, settings);
    let view = prepared.scene.camera.view(settings.width, settings.height);
    let cancel = AtomicBool::new(false);
    let spp = settings.spp.max(1);
    let mut sum = Radiance::ZERO;
    let mut sum_sq = 0.0f32;
    let mut samples = Vec::new();
    // Adaptive sampling stops a pixel on its own samples alone, so the
    // replay stops where the frame stopped.
    let adaptive = settings.adaptive.filter(|_| spp > 1);
    for i in 0..spp {
        if adaptive.is_some_and(|target| !accumulator::wants_more(sum, sum_sq, i, spp, target)) {
            break;
        }
        let offset = sample_offset(i, spp, settings.gi.seed);
        let job = PassJob { prepared, view: &view, settings, offset, sample: i, photons: photons.as_deref(), active: None, rows: y..y + 1, cancel: &cancel, keep_non_finite: false };
        let mut rec = crate::render::inspect::pixel_record::PixelTrace::new();
        let value = renderer
            .trace_pixel(&job, x, y, &mut rec)
            .ok_or_else(|| format!("{} cannot replay pixels yet", renderer.name()))?;
        add_sample(&mut sum, value, spp);
        let l = crate::render::transport::sampling::luminance(admitted(value));
        sum_sq += l * l;
        samples.push((offset, rec, value));
    }
    let mut radiance = if adaptive.is_some() { mean(sum, samples.len() as u32) } else { final_value(sum, spp) };
    if wireframe && crate::render::inspect::wireframe::line_mask(&prepared.scene, &view, settings.lines)[(x + y * settings.width) as usize] {
        radiance = crate::render::inspect::wireframe::LINE_COLOR;
    }
    if false_colour {
        radiance = crate::display::false_colour::false_colour_linear(radiance);
    }
    if nan {
        let mut one = [radiance];
        accumulator::nan_view_in_place(&mut one, &[samples.iter().any(|(_, _, v)| !v.is_finite())]);
        radiance = one[0];
    }
    Ok(PixelReplay { samples, radiance })
}
