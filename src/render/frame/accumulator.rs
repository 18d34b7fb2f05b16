//! The progressive frame: the per-pixel sum of the sample passes, rendered
//! band by band on request, with its running average, its final value and,
//! for the diff view, the reference it is compared with (the wireframe view,
//! its lines, drawn over the average). The command line's
//! `render_frame` and the viewer's worker both drive one of these.

use crate::render::frame::FrameResult;
use crate::math::Radiance;
use crate::render::transport::sampling::luminance;
use crate::render::inspect::debug;
use crate::render::inspect::debug::View;
use crate::render::raytrace::brute_renderer::BruteForce;
use crate::render::inspect::wireframe;
use crate::render::inspect::wireframe::LineAlgorithm;
use crate::render::finite::admit_all;
use crate::render::{sample_offset, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

pub use crate::render::finite::admitted;

/// Adds one pass's sample to a pixel's sum. With one sample per pixel the
/// sample is stored as it is: adding it to zero would turn -0 into +0.
#[inline]
pub fn add_sample(sum: &mut Radiance, sample: Radiance, spp: u32) {
    if spp == 1 {
        *sum = admitted(sample);
    } else {
        *sum += admitted(sample);
    }
}

/// Adds a band's pass (`pass`) to its pixels' sums and sums of squared
/// luminance; with `--adaptive`, only to the pixels still `active`, whose
/// sample counts go up. Pixels are independent, so without `--adaptive`
/// (the frames that are timed) chunks go in parallel: at many samples per
/// pixel this loop would otherwise be a serial part of every pass.
/// Returns how many of the samples added were not finite (and added nothing).
fn add_pass(pass: &[Radiance], sum: &mut [Radiance], sum_sq: &mut [f32], adaptive: Option<(&[bool], &mut [u32])>, spp: u32) -> u64 {
    const CHUNK: usize = 8192;
    debug_assert!(spp > 1, "one sample is stored, not added");
    let add = |p: &Radiance, s: &mut Radiance, q: &mut f32| -> u64 {
        // `add_sample` with several samples, the check made once for both sums.
        let sample = admitted(*p);
        *s += sample;
        let l = luminance(sample);
        *q += l * l;
        u64::from(!p.is_finite())
    };
    match adaptive {
        None => pass
            .par_chunks(CHUNK)
            .zip(sum.par_chunks_mut(CHUNK))
            .zip(sum_sq.par_chunks_mut(CHUNK))
            .map(|((pass, sum), sum_sq)| pass.iter().zip(sum).zip(sum_sq).map(|((p, s), q)| add(p, s, q)).sum::<u64>())
            .sum(),
        Some((active, samples)) => {
            let mut non_finite = 0;
            for ((((p, s), q), &on), n) in pass.iter().zip(sum).zip(sum_sq).zip(active).zip(samples) {
                if on {
                    *n += 1;
                    non_finite += add(p, s, q);
                }
            }
            non_finite
        }
    }
}

/// Marks in `marks` the pixels of `pass` whose sample is not finite and
/// returns how many there are (the nan view, before the frame zeroes them).
fn mark_non_finite(pass: &[Radiance], marks: &mut [bool]) -> u64 {
    let mut found = 0;
    for (p, m) in pass.iter().zip(marks) {
        if !p.is_finite() {
            *m = true;
            found += 1;
        }
    }
    found
}

/// The average of a pixel whose sum holds `passes` samples.
#[inline]
pub fn mean(sum: Radiance, passes: u32) -> Radiance {
    sum * (1.0 / passes as f32)
}

/// A pixel's value once all `spp` samples are in: their average, or with one
/// sample the sample itself (unscaled: scaling by one would only cost time).
#[inline]
pub fn final_value(sum: Radiance, spp: u32) -> Radiance {
    if spp == 1 { sum } else { mean(sum, spp) }
}

/// Adaptive sampling looks at a pixel's error only after this many samples:
/// fewer say too little about its variance.
pub const ADAPTIVE_MIN_SAMPLES: u32 = 8;

/// The estimated relative error of a pixel's mean after `n` samples whose
/// luminances sum to `sum` and whose squares sum to `sum_sq`: the standard
/// error over the mean (floored at 1e-3, so black pixels count as settled).
#[inline]
pub fn relative_error(sum: f32, sum_sq: f32, n: u32) -> f32 {
    if n < 2 {
        return f32::INFINITY;
    }
    let k = n as f32;
    let mean = sum / k;
    let variance = ((sum_sq / k - mean * mean) * k / (k - 1.0)).max(0.0);
    (variance / k).sqrt() / mean.max(1e-3)
}

/// Whether adaptive sampling gives a pixel another sample: before
/// `ADAPTIVE_MIN_SAMPLES`, and after while its relative error exceeds
/// `target` and the budget `spp` is not spent. A function of the pixel's
/// own samples only, so a replayed pixel takes exactly the frame's samples.
#[inline]
pub fn wants_more(sum: Radiance, sum_sq: f32, n: u32, spp: u32, target: f32) -> bool {
    n < spp && (n < ADAPTIVE_MIN_SAMPLES || relative_error(luminance(sum), sum_sq, n) > target)
}

/// Adaptive sampling's bookkeeping: samples per pixel, and who still takes them.
struct Adaptive {
    target: f32,
    samples: Vec<u32>,
    active: Vec<bool>,
    /// No pixel wants another sample: the frame is complete early.
    settled: bool,
}

/// One band of one pass, as `Accumulator::render_band` rendered it.
#[derive(Clone, Debug)]
pub struct Band {
    pub rows: Range<u32>,
    /// The pass the band belongs to (0-based).
    pub pass: u32,
    /// What the renderer counted (the diff view's reference is not counted).
    pub counts: RayCounts,
    /// The band was the last of its pass.
    pub pass_done: bool,
}

/// A frame of `spp` stratified sample passes, accumulated band by band.
pub struct Accumulator {
    /// What every pass renders with: the frame's settings, shaded for the diff view.
    settings: RenderSettings,
    spp: u32,
    /// Sum of the samples per pixel, row-major, and per row how many passes it holds.
    sum: Vec<Radiance>,
    /// With more than one sample: per pixel the sum of the squared sample
    /// luminances, for the estimate of the noise left (`noise_estimate`).
    sum_sq: Vec<f32>,
    row_passes: Vec<u32>,
    /// Diff view: the sum of the reference `raytrace:brute`'s samples, rendered
    /// band by band beside the renderer's; the frame is the difference image.
    reference: Option<Vec<Radiance>>,
    counts: RayCounts,
    /// The next band starts at row `row` of pass `pass`.
    pass: u32,
    row: u32,
    /// `--adaptive`: per-pixel sample counts and the pixels still sampling.
    adaptive: Option<Adaptive>,
    /// The photon map every pass reads (`--gi photons`), built with the first band.
    photons: Option<std::sync::Arc<crate::render::transport::photon_map::PhotonMap>>,
    /// Wireframe view: the passes are shaded; the lines' pixels (made with
    /// the first band) are painted over the average.
    wireframe: Option<LineAlgorithm>,
    lines: Option<Vec<bool>>,
    /// False-colour view: the passes are shaded; the average is shown as
    /// its log2 luminance through the colour map (`display::false_colour`).
    false_colour: bool,
    /// Nan view: the passes are shaded, their non-finite samples left by
    /// the renderer for the frame to find; per pixel whether one had any.
    nan_marks: Option<Vec<bool>>,
    /// With more than one sample, what a band's pass renders before it is
    /// added to `sum`: kept from band to band, since a fresh buffer per
    /// band costs its allocation, zeroing and page faults every pass.
    pass_buffer: Vec<Radiance>,
    /// The rows and passes rendered (`limit_to`; the whole frame by default):
    /// the sums hold the whole frame's pixels, touched only there.
    rows: Range<u32>,
    passes: Range<u32>,
}

/// `n` zero radiances, written by every thread of the pool: a frame's sum
/// is megabytes (11 MB at 1280x720), and filling it on one thread kept the
/// others waiting before every frame.
fn zeros(n: usize) -> Vec<Radiance> {
    let mut v = Vec::with_capacity(n);
    v.par_extend(rayon::iter::repeat_n(Radiance::ZERO, n));
    v
}

/// The nan view of shaded pixels: the pixels that took a non-finite sample
/// in `NAN_MARK`, the others as their luminance, dimmed grey, so the marks
/// stand out against the picture they are in.
pub fn nan_view_in_place(pixels: &mut [Radiance], marks: &[bool]) {
    for (c, &marked) in pixels.iter_mut().zip(marks) {
        *c = if marked { NAN_MARK } else { Radiance::splat((luminance(*c) * NAN_DIM).clamp(0.0, NAN_DIM)) };
    }
}

/// The nan view's colour of a pixel that took a non-finite sample: magenta.
pub const NAN_MARK: Radiance = Radiance::new(1.0, 0.0, 1.0);
/// The nan view's other pixels are grey, at most this bright.
pub const NAN_DIM: f32 = 0.25;

/// The false-colour view of shaded pixels: each becomes the linear colour
/// whose sRGB encoding is the colour map's colour for its stop.
fn false_colour_in_place(pixels: &mut [Radiance]) {
    for c in pixels {
        *c = crate::display::false_colour::false_colour_linear(*c);
    }
}

impl Accumulator {
    /// An empty frame of `settings.width` x `settings.height` pixels and
    /// `settings.spp` samples (at least one).
    pub fn new(settings: &RenderSettings) -> Accumulator {
        Accumulator::reusing(settings, Vec::new())
    }

    /// `new`, keeping `spare` (a finished frame's pixels, say) as the sum's
    /// storage where it can: with one sample per pixel every band is
    /// rendered straight over its pixels (`render_band`), so a buffer of
    /// the frame's size is taken as it is. A fresh one would be filled with
    /// zeros, page by page faulted in, about 3-4% of a 1280x720 frame.
    pub fn reusing(settings: &RenderSettings, spare: Vec<Radiance>) -> Accumulator {
        let diff = settings.view == View::Diff;
        let wireframe = (settings.view == View::Wireframe).then_some(settings.lines);
        let false_colour = settings.view == View::FalseColour;
        let nan = settings.view == View::Nan;
        let settings = if settings.view.renders_shaded() { RenderSettings { view: View::Shaded, ..settings.clone() } } else { settings.clone() };
        let n = settings.width as usize * settings.height as usize;
        Accumulator {
            spp: settings.spp.max(1),
            sum: if settings.spp <= 1 && spare.len() == n { spare } else { zeros(n) },
            sum_sq: if settings.spp > 1 { vec![0.0; n] } else { Vec::new() },
            row_passes: vec![0; settings.height as usize],
            reference: diff.then(|| vec![Radiance::ZERO; n]),
            counts: RayCounts::default(),
            pass: 0,
            row: 0,
            photons: None,
            wireframe,
            lines: None,
            false_colour,
            nan_marks: nan.then(|| vec![false; n]),
            pass_buffer: Vec::new(),
            rows: 0..settings.height,
            passes: 0..settings.spp.max(1),
            adaptive: settings.adaptive.filter(|_| settings.spp > 1).map(|target| Adaptive {
                target,
                samples: vec![0; n],
                active: vec![true; n],
                settled: false,
            }),
            settings,
        }
    }

    /// Renders only `rows` and sample passes `passes` (within the frame's),
    /// with the sample indices, offsets and seeds of the whole frame there.
    /// Panics once rendering began.
    pub fn limit_to(&mut self, rows: Range<u32>, passes: Range<u32>) {
        assert!(self.pass == self.passes.start && self.row == self.rows.start, "limit_to after rendering began");
        assert!(rows.end <= self.settings.height && passes.end <= self.spp && !passes.is_empty(), "limit_to outside the frame");
        self.row = rows.start;
        self.pass = passes.start;
        self.rows = rows;
        self.passes = passes;
    }

    pub fn width(&self) -> u32 {
        self.settings.width
    }

    pub fn height(&self) -> u32 {
        self.settings.height
    }

    pub fn spp(&self) -> u32 {
        self.spp
    }

    /// Passes completed over the whole frame.
    pub fn passes_done(&self) -> u32 {
        self.pass
    }

    /// The row the next band starts at (0: a new pass begins).
    pub fn next_row(&self) -> u32 {
        self.row
    }

    /// Every sample of every pixel is in.
    pub fn is_complete(&self) -> bool {
        self.pass >= self.passes.end || self.adaptive.as_ref().is_some_and(|a| a.settled)
    }

    /// Samples taken over the whole frame so far.
    pub fn samples_taken(&self) -> u64 {
        match &self.adaptive {
            Some(a) => a.samples.iter().map(|n| *n as u64).sum(),
            None => self.row_passes.iter().map(|p| *p as u64).sum::<u64>() * self.settings.width as u64,
        }
    }

    /// How many samples pixel `i` (of row `y`) holds.
    #[inline]
    fn samples_of(&self, i: usize, y: usize) -> u32 {
        self.adaptive.as_ref().map_or(self.row_passes[y], |a| a.samples[i])
    }

    /// Renders the next band of at most `max_rows` rows of the next pass and
    /// adds it in. Returns `None`, adding nothing, when `cancel` was raised
    /// while it rendered. Panics when the frame is complete.
    pub fn render_band(&mut self, renderer: &dyn Renderer, prepared: &PreparedScene, max_rows: u32, cancel: &AtomicBool) -> Option<Band> {
        assert!(!self.is_complete(), "render_band on a complete frame");
        let (width, height) = (self.settings.width, self.settings.height);
        if self.pass == self.passes.start && self.row == self.rows.start {
            self.prepare_frame(prepared);
        }
        let rows = self.row..(self.row + max_rows.max(1)).min(self.rows.end);
        let mut counts = RayCounts::default();
        if !rows.is_empty() && width > 0 {
            let view = prepared.scene.camera.view(width, height);
            let w = width as usize;
            let span = rows.start as usize * w..rows.end as usize * w;
            let job = PassJob {
                prepared,
                view: &view,
                settings: &self.settings,
                offset: sample_offset(self.pass, self.spp, self.settings.gi.seed),
                sample: self.pass,
                photons: self.photons.as_deref(),
                active: self.adaptive.as_ref().map(|a| &a.active[span.clone()]),
                rows: rows.clone(),
                cancel,
                keep_non_finite: self.nan_marks.is_some(),
            };
            let cancelled = || cancel.load(Ordering::Relaxed);
            // With one sample the pass is the frame: render straight into it
            // (a cancelled band is rendered again or the frame dropped, and
            // storing overwrites, so a half-written band never shows).
            let mut mine = std::mem::take(&mut self.pass_buffer);
            if self.spp > 1 {
                mine.clear();
                mine.resize(span.len(), Radiance::ZERO);
            }
            let out = if self.spp == 1 { &mut self.sum[span.clone()] } else { &mut mine[..] };
            counts = renderer.render_pass(&job, out);
            if cancelled() {
                return None;
            }
            let mut theirs = self.reference.as_ref().map(|_| vec![Radiance::ZERO; span.len()]);
            if let Some(buf) = theirs.as_mut() {
                BruteForce.render_pass(&job, buf);
                if cancelled() {
                    return None;
                }
            }
            // The nan view finds the non-finite samples the renderer left.
            let marked = self.nan_marks.as_mut().map(|marks| {
                let pass = if self.spp == 1 { &self.sum[span.clone()] } else { &mine[..] };
                mark_non_finite(pass, &mut marks[span.clone()])
            });
            if self.spp == 1 {
                // A renderer that checks its bands as it writes them has
                // left nothing to do; for the others, a read-only scan in
                // parallel (`admit_all`).
                if !renderer.admits_its_samples() || marked.is_some() {
                    let zeroed: u64 = self.sum[span.clone()].par_chunks_mut(8192).map(admit_all).sum();
                    counts.non_finite += if marked.is_some() { 0 } else { zeroed };
                }
            } else {
                let adaptive = self.adaptive.as_mut().map(|a| (&a.active[span.clone()], &mut a.samples[span.clone()]));
                let zeroed = add_pass(&mine, &mut self.sum[span.clone()], &mut self.sum_sq[span.clone()], adaptive, self.spp);
                counts.non_finite += if marked.is_some() { 0 } else { zeroed };
            }
            counts.non_finite += marked.unwrap_or(0);
            // (A cancelled band returns above and drops the buffer: the
            // next band makes a new one.)
            self.pass_buffer = mine;
            if let (Some(sum), Some(buf)) = (self.reference.as_mut(), theirs.as_ref()) {
                for (s, p) in sum[span].iter_mut().zip(buf) {
                    add_sample(s, *p, self.spp);
                }
            }
        }
        for y in rows.clone() {
            self.row_passes[y as usize] += 1;
        }
        self.counts += counts;
        let pass = self.pass;
        self.row = rows.end;
        let pass_done = self.row >= self.rows.end;
        if pass_done {
            self.row = self.rows.start;
            self.pass += 1;
            let (sum, sum_sq, spp) = (&self.sum, &self.sum_sq, self.spp);
            let w = width as usize;
            let span = self.rows.start as usize * w..self.rows.end as usize * w;
            if let Some(a) = self.adaptive.as_mut() {
                let mut any = false;
                for i in span {
                    a.active[i] = a.active[i] && wants_more(sum[i], sum_sq[i], a.samples[i], spp, a.target);
                    any |= a.active[i];
                }
                a.settled = !any;
            }
        }
        Some(Band { rows, pass, counts, pass_done })
    }

    /// What every pass reads, made once before the first: shadow maps or
    /// volumes, the photon map, the wireframe's lines.
    fn prepare_frame(&mut self, prepared: &PreparedScene) {
        crate::render::frame::build_shadow_maps(prepared, &self.settings);
        self.photons = crate::render::frame::build_photon_map(prepared, &self.settings);
        if let Some(algorithm) = self.wireframe {
            let view = prepared.scene.camera.view(self.settings.width, self.settings.height);
            self.lines = Some(wireframe::line_mask(&prepared.scene, &view, algorithm));
        }
    }

    /// Whether `render_in_chunks` can render this frame: several samples,
    /// a fixed count of them, nothing rendered yet, and no view that needs
    /// work per pass beside the renderer's (the diff view's reference, the
    /// wireframe's lines).
    pub fn renders_in_chunks(&self) -> bool {
        self.spp > 1 && self.pass == self.passes.start && self.row == self.rows.start && self.adaptive.is_none() && self.reference.is_none() && self.wireframe.is_none() && self.nan_marks.is_none()
    }

    /// Renders the whole frame chunk by chunk: chunks of `chunk_rows` rows
    /// in parallel, each taking all its passes one after the other. No
    /// thread waits for the others at the end of a pass, and a chunk's
    /// passes meet the same part of the scene while it is still in cache.
    /// Every pixel adds its samples in pass order, as band by band, so the
    /// image is the same. `rows_done` counts rows times passes. Returns
    /// `None` when `cancel` was raised (the frame is then incomplete).
    pub fn render_in_chunks(&mut self, renderer: &dyn Renderer, prepared: &PreparedScene, chunk_rows: u32, cancel: &AtomicBool, rows_done: Option<&AtomicU64>) -> Option<()> {
        assert!(self.renders_in_chunks(), "render_in_chunks on a frame it cannot render");
        let (width, height, spp) = (self.settings.width, self.settings.height, self.spp);
        self.prepare_frame(prepared);
        let view = prepared.scene.camera.view(width, height);
        let (settings, photons) = (&self.settings, self.photons.as_deref());
        let chunk_rows = chunk_rows.max(1);
        let chunk = (chunk_rows * width).max(1) as usize;
        let (first_row, rows_end, passes_range) = (self.rows.start, self.rows.end, self.passes.clone());
        let span = first_row as usize * width as usize..self.rows.end as usize * width as usize;
        let counts = self.sum[span.clone()]
            .par_chunks_mut(chunk)
            .zip(self.sum_sq[span].par_chunks_mut(chunk))
            .enumerate()
            // One pass buffer per rayon job, not per chunk: a fresh one of
            // this size is mapped memory whose every page faults in.
            .map_init(Vec::new, |pass_buffers, (k, (sum, sum_sq))| {
                let rows = first_row + k as u32 * chunk_rows..(first_row + (k as u32 + 1) * chunk_rows).min(rows_end);
                // Up to `passes_at_once` passes rendered in one call (a ray
                // caster traces a pixel's samples of them together), then
                // added in pass order.
                let group = renderer.passes_at_once().clamp(1, passes_range.len() as u32) as usize;
                pass_buffers.clear();
                pass_buffers.resize(group * sum.len(), Radiance::ZERO);
                let mut counts = RayCounts::default();
                for first in passes_range.clone().step_by(group) {
                    if cancel.load(Ordering::Relaxed) {
                        break;
                    }
                    let passes = first..(first + group as u32).min(passes_range.end);
                    let jobs: Vec<PassJob> = passes
                        .clone()
                        .map(|pass| PassJob { prepared, view: &view, settings, offset: sample_offset(pass, spp, settings.gi.seed), sample: pass, photons, active: None, rows: rows.clone(), cancel, keep_non_finite: false })
                        .collect();
                    let buffers = &mut pass_buffers[..jobs.len() * sum.len()];
                    counts += renderer.render_passes(&jobs, buffers);
                    for pass_buffer in buffers.chunks(sum.len()) {
                        counts.non_finite += add_pass(pass_buffer, sum, sum_sq, None, spp);
                        if let Some(done) = rows_done {
                            done.fetch_add(rows.len() as u64, Ordering::Relaxed);
                        }
                    }
                }
                counts
            })
            .reduce(RayCounts::default, |mut a, b| {
                a += b;
                a
            });
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        self.counts += counts;
        let passes = self.passes.len() as u32;
        for y in self.rows.clone() {
            self.row_passes[y as usize] = passes;
        }
        self.pass = self.passes.end;
        Some(())
    }

    /// The running average of `rows`: every pixel's sum over the passes its
    /// row holds (zero where none yet).
    pub fn mean_rows(&self, rows: Range<u32>) -> Vec<Radiance> {
        let w = self.settings.width as usize;
        let mut out = Vec::with_capacity(rows.len() * w);
        let rows_start = rows.start as usize;
        for y in rows {
            let passes = self.row_passes[y as usize];
            let row = &self.sum[y as usize * w..(y as usize + 1) * w];
            if passes == 0 {
                out.extend(std::iter::repeat_n(Radiance::ZERO, w));
            } else if let Some(a) = &self.adaptive {
                let counts = &a.samples[y as usize * w..(y as usize + 1) * w];
                out.extend(row.iter().zip(counts).map(|(s, n)| mean(*s, (*n).max(1))));
            } else {
                out.extend(row.iter().map(|s| mean(*s, passes)));
            }
            if let Some(lines) = &self.lines {
                let at = out.len() - w;
                wireframe::draw_over(&mut out[at..], &lines[y as usize * w..(y as usize + 1) * w]);
            }
        }
        if self.false_colour {
            false_colour_in_place(&mut out);
        }
        if let Some(marks) = &self.nan_marks {
            let start = rows_start * w;
            let n = out.len();
            nan_view_in_place(&mut out, &marks[start..start + n]);
        }
        out
    }

    /// The noise left in the running average, as the estimated rmse over
    /// the image divided by its mean luminance: per pixel the sample
    /// variance of the luminance over the passes so far, divided by their
    /// number. `None` before two passes, or with one sample per pixel.
    pub fn noise_estimate(&self) -> Option<f32> {
        if self.sum_sq.is_empty() {
            return None;
        }
        let w = self.settings.width as usize;
        let (mut error2, mut mean_sum, mut n) = (0f64, 0f64, 0usize);
        for y in 0..self.row_passes.len() {
            for i in y * w..(y + 1) * w {
                let passes = self.samples_of(i, y);
                if passes < 2 {
                    continue;
                }
                let k = passes as f64;
                let m = luminance(self.sum[i]) as f64 / k;
                let variance = ((self.sum_sq[i] as f64 / k - m * m) * k / (k - 1.0)).max(0.0);
                error2 += variance / k;
                mean_sum += m;
                n += 1;
            }
        }
        (n > 0 && mean_sum > 0.0).then(|| ((error2 / n as f64).sqrt() / (mean_sum / n as f64)) as f32)
    }

    /// The finished frame: the average of the `spp` samples (one sample is
    /// the pixel itself), or for the diff view the difference image against
    /// the reference with its count of differing pixels.
    pub fn finish(self) -> FrameResult {
        let spp = self.spp;
        // Some of the passes only: their sums, for a merge to add up.
        if self.passes != (0..spp) {
            let summed = Some(self.passes.clone());
            return FrameResult { width: self.settings.width, height: self.settings.height, pixels: self.sum, counts: self.counts, differing_pixels: None, summed_passes: summed };
        }
        let average = |mut sum: Vec<Radiance>| {
            if spp > 1 {
                for s in &mut sum {
                    *s = final_value(*s, spp);
                }
            }
            sum
        };
        let mut mine: Vec<Radiance> = match &self.adaptive {
            Some(a) => self.sum.iter().zip(&a.samples).map(|(s, n)| mean(*s, (*n).max(1))).collect(),
            None => average(self.sum),
        };
        if let Some(lines) = &self.lines {
            wireframe::draw_over(&mut mine, lines);
        }
        if self.false_colour {
            false_colour_in_place(&mut mine);
        }
        if let Some(marks) = &self.nan_marks {
            nan_view_in_place(&mut mine, marks);
        }
        let (pixels, differing_pixels) = match self.reference {
            Some(reference) => {
                let (image, count) = debug::diff_image(&mine, &average(reference));
                (image, Some(count))
            }
            None => (mine, None),
        };
        FrameResult { width: self.settings.width, height: self.settings.height, pixels, counts: self.counts, differing_pixels, summed_passes: None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::raytrace::bvh_renderer::BvhRayTracer;
    use crate::render::{render_frame, render_frame_with, FrameOptions};
    use crate::scene::builtin;

    fn prepared(name: &str) -> PreparedScene {
        PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap())
    }

    fn settings(prepared: &PreparedScene, spp: u32, view: View) -> RenderSettings {
        RenderSettings { width: 24, height: 17, spp, view, ..RenderSettings::for_scene(&prepared.scene) }
    }

    fn bits(pixels: &[Radiance]) -> Vec<[u32; 3]> {
        pixels.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
    }

    /// Returns NaN for every third pixel of every pass, infinity for every
    /// fifth, else the BVH tracer's value.
    struct Poisoned;

    impl Renderer for Poisoned {
        fn name(&self) -> &'static str {
            "poisoned"
        }
        fn description(&self) -> &'static str {
            "test renderer with non-finite samples"
        }
        fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
            let counts = BvhRayTracer.render_pass(job, out);
            let first = job.rows.start as usize * job.settings.width as usize;
            for (i, p) in out.iter_mut().enumerate().map(|(i, p)| (i + first, p)) {
                if i % 3 == 0 {
                    p.y = f32::NAN;
                } else if i % 5 == 0 {
                    *p = Radiance::splat(f32::INFINITY);
                }
            }
            counts
        }
    }

    /// The noise estimate falls like 1/sqrt(passes) on a path-traced frame
    /// and is absent for deterministic single-sample frames.
    #[test]
    fn the_noise_estimate_falls_as_samples_add_up() {
        let p = prepared("cornell-gi");
        let mut s = settings(&p, 64, View::Shaded);
        s.gi.mode = crate::render::transport::gi::GiMode::Path;
        let mut a = Accumulator::new(&s);
        let mut at = Vec::new();
        while !a.is_complete() {
            a.render_band(&BvhRayTracer, &p, s.height, &AtomicBool::new(false)).unwrap();
            if [4, 64].contains(&a.passes_done()) {
                at.push(a.noise_estimate().unwrap());
            }
        }
        let ratio = at[1] / at[0];
        assert!((0.15..0.4).contains(&ratio), "4 -> 64 passes: {at:?}");
        assert_eq!(Accumulator::new(&settings(&p, 1, View::Shaded)).noise_estimate(), None);
    }

    #[test]
    fn non_finite_samples_never_reach_a_pixel() {
        let p = prepared("spheres");
        for spp in [1, 4] {
            let s = settings(&p, spp, View::Shaded);
            let f = render_frame(&Poisoned, &p, &s, &AtomicBool::new(false), None).unwrap();
            assert!(f.pixels.iter().all(|c| c.is_finite()), "spp {spp}");
            // A pixel whose every sample was non-finite is black.
            assert_eq!(f.pixels[0], Radiance::ZERO, "spp {spp}");
            let mut a = Accumulator::new(&s);
            a.render_band(&Poisoned, &p, 5, &AtomicBool::new(false)).unwrap();
            assert!(a.mean_rows(0..s.height).iter().all(|c| c.is_finite()), "spp {spp}");
        }
    }

    #[test]
    fn bands_equal_the_whole_frame_bit_for_bit() {
        let p = prepared("spheres");
        for spp in [1, 3, 4] {
            let s = settings(&p, spp, View::Shaded);
            let cancel = AtomicBool::new(false);
            let whole = render_frame(&BvhRayTracer, &p, &s, &cancel, None).unwrap();
            let banded = render_frame_with(&BvhRayTracer, &p, &s, &cancel, FrameOptions { bands: 5, ..FrameOptions::default() }).unwrap();
            assert_eq!(bits(&whole.pixels), bits(&banded.pixels), "spp {spp}");
            // (Ray counts may differ: packets are formed within a band.)
            assert_eq!(whole.counts.primary, banded.counts.primary);
            // Bands of uneven size, the running average read as the viewer reads it.
            let mut a = Accumulator::new(&s);
            let mut shown = vec![Radiance::ZERO; whole.pixels.len()];
            let mut size = 1;
            while !a.is_complete() {
                let band = a.render_band(&BvhRayTracer, &p, size, &cancel).unwrap();
                let w = s.width as usize;
                shown[band.rows.start as usize * w..band.rows.end as usize * w].copy_from_slice(&a.mean_rows(band.rows.clone()));
                size = size % 7 + 2;
            }
            assert_eq!(bits(&shown), bits(&whole.pixels), "spp {spp}: running average at the end");
            assert_eq!(bits(&a.finish().pixels), bits(&whole.pixels), "spp {spp}");
        }
    }

    /// A frame rendered chunk by chunk (each chunk's passes in a row) is the
    /// frame rendered pass by pass, bit for bit, with the same noise
    /// estimate and counts; on path-traced frames, whose samples draw random
    /// numbers per pixel and pass, and at a height that leaves a short chunk.
    #[test]
    fn chunks_equal_passes_bit_for_bit() {
        let p = prepared("cornell-gi");
        let cancel = AtomicBool::new(false);
        // 19 passes: sixteen handed over together, then three.
        for (spp, gi) in [(4, crate::render::transport::gi::GiMode::Path), (3, crate::render::transport::gi::GiMode::None), (19, crate::render::transport::gi::GiMode::Path)] {
            let mut s = settings(&p, spp, View::Shaded);
            s.height = 2 * BvhRayTracer.chunk_rows().unwrap() + 3;
            s.gi.mode = gi;
            let mut by_pass = Accumulator::new(&s);
            while !by_pass.is_complete() {
                by_pass.render_band(&BvhRayTracer, &p, s.height, &cancel).unwrap();
            }
            let mut chunked = Accumulator::new(&s);
            assert!(chunked.renders_in_chunks());
            let rows = AtomicU64::new(0);
            chunked.render_in_chunks(&BvhRayTracer, &p, BvhRayTracer.chunk_rows().unwrap(), &cancel, Some(&rows)).unwrap();
            assert!(chunked.is_complete() && !chunked.renders_in_chunks());
            assert_eq!(rows.load(Ordering::Relaxed), s.height as u64 * spp as u64);
            assert_eq!(chunked.noise_estimate().map(f32::to_bits), by_pass.noise_estimate().map(f32::to_bits), "spp {spp}");
            assert_eq!(chunked.samples_taken(), by_pass.samples_taken());
            let (a, b) = (chunked.finish(), by_pass.finish());
            assert_eq!(bits(&a.pixels), bits(&b.pixels), "spp {spp}");
            assert_eq!((a.counts.primary, a.counts.shadow, a.counts.secondary), (b.counts.primary, b.counts.shadow, b.counts.secondary));
            // `render_frame` takes this route.
            assert_eq!(bits(&render_frame(&BvhRayTracer, &p, &s, &cancel, None).unwrap().pixels), bits(&a.pixels));
        }
        let s = settings(&p, 2, View::Shaded);
        assert!(Accumulator::new(&s).render_in_chunks(&BvhRayTracer, &p, 4, &AtomicBool::new(true), None).is_none());
        // Frames that need work per pass beside the renderer's go pass by pass.
        for view in [View::Diff, View::Wireframe] {
            assert!(!Accumulator::new(&settings(&p, 2, view)).renders_in_chunks());
        }
        assert!(!Accumulator::new(&RenderSettings { adaptive: Some(0.1), ..s.clone() }).renders_in_chunks());
        assert!(!Accumulator::new(&settings(&p, 1, View::Shaded)).renders_in_chunks());
    }

    /// A one-sample frame rendered over a reused buffer
    /// (`Accumulator::reusing`, what `pinhole bench` does) is the frame
    /// rendered from zeros, bit for bit, for every renderer and view: so
    /// every renderer writes every pixel of its pass, and nothing of the
    /// buffer's former contents shows. (The OpenGL renderer reads back its
    /// whole framebuffer and needs a context, which this test does not.)
    #[test]
    fn a_reused_buffer_leaves_no_trace() {
        let cancel = AtomicBool::new(false);
        for scene in ["spheres", "teapot", "csg", "textures"] {
            let p = prepared(scene);
            for renderer in crate::render::renderers().iter().filter(|r| !r.name().starts_with("opengl")) {
                for view in View::ALL {
                    let s = settings(&p, 1, view);
                    let fresh = render_frame(renderer.as_ref(), &p, &s, &cancel, None).unwrap();
                    let stale = vec![Radiance::new(1234.5, -7.0, 0.25); fresh.pixels.len()];
                    let over = render_frame_with(renderer.as_ref(), &p, &s, &cancel, FrameOptions { spare: stale, ..FrameOptions::default() }).unwrap();
                    assert_eq!(bits(&over.pixels), bits(&fresh.pixels), "{scene}, {}, {view:?}", renderer.name());
                }
            }
        }
        // The comparison sees a renderer that leaves a pixel alone.
        struct SkipsFirstPixel;
        impl Renderer for SkipsFirstPixel {
            fn name(&self) -> &'static str {
                "skips-first-pixel"
            }
            fn description(&self) -> &'static str {
                "test renderer that leaves pixel 0 unwritten"
            }
            fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
                let mut mine = vec![Radiance::ZERO; out.len()];
                let counts = BvhRayTracer.render_pass(job, &mut mine);
                let skip = usize::from(job.rows.start == 0);
                out[skip..].copy_from_slice(&mine[skip..]);
                counts
            }
        }
        let p = prepared("spheres");
        let s = settings(&p, 1, View::Shaded);
        let stale = vec![Radiance::splat(1234.5); (s.width * s.height) as usize];
        let over = render_frame_with(&SkipsFirstPixel, &p, &s, &cancel, FrameOptions { spare: stale, ..FrameOptions::default() }).unwrap();
        assert_eq!(over.pixels[0], Radiance::splat(1234.5));
    }

    #[test]
    fn one_sample_is_stored_unscaled() {
        let mut sum = Radiance::new(5.0, 5.0, 5.0);
        add_sample(&mut sum, Radiance::new(-0.0, 1.0, 2.0), 1);
        assert_eq!(sum.x.to_bits(), (-0.0f32).to_bits());
        assert_eq!(final_value(sum, 1).x.to_bits(), (-0.0f32).to_bits());
        let mut sum = Radiance::ZERO;
        add_sample(&mut sum, Radiance::new(1.0, 2.0, 3.0), 2);
        add_sample(&mut sum, Radiance::new(3.0, 2.0, f32::NAN), 2);
        // The NaN sample adds nothing to any channel; the average still divides by two.
        assert_eq!(final_value(sum, 2), Radiance::new(0.5, 1.0, 1.5));
    }

    #[test]
    fn diff_counts_against_the_reference() {
        let p = prepared("spheres");
        let cancel = AtomicBool::new(false);
        // The reference against itself: nothing differs.
        let s = settings(&p, 1, View::Diff);
        let same = render_frame(&BruteForce, &p, &s, &cancel, None).unwrap();
        assert_eq!(same.differing_pixels, Some(0));
        // Against an image with non-finite samples zeroed: the count is what
        // `diff_image` finds between the two shaded frames.
        let shaded = |r: &dyn Renderer| render_frame(r, &p, &settings(&p, 1, View::Shaded), &cancel, None).unwrap().pixels;
        let (_, expected) = debug::diff_image(&shaded(&Poisoned), &shaded(&BruteForce));
        assert!(expected > 0);
        let diff = render_frame(&Poisoned, &p, &s, &cancel, None).unwrap();
        assert_eq!(diff.differing_pixels, Some(expected));
        // Band by band it is the same image and count.
        let banded = render_frame_with(&Poisoned, &p, &s, &cancel, FrameOptions { bands: 4, ..FrameOptions::default() }).unwrap();
        assert_eq!(bits(&banded.pixels), bits(&diff.pixels));
        assert_eq!(banded.differing_pixels, diff.differing_pixels);
    }

    #[test]
    fn cancelled_band_adds_nothing() {
        let p = prepared("spheres");
        let s = settings(&p, 2, View::Shaded);
        let mut a = Accumulator::new(&s);
        assert!(a.render_band(&BvhRayTracer, &p, 4, &AtomicBool::new(true)).is_none());
        assert_eq!((a.passes_done(), a.next_row()), (0, 0));
        assert!(a.mean_rows(0..4).iter().all(|c| *c == Radiance::ZERO));
        assert!(render_frame(&BvhRayTracer, &p, &s, &AtomicBool::new(true), None).is_none());
    }
}
