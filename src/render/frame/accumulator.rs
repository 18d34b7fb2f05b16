//! The progressive frame: the per-pixel sum of the sample passes, rendered
//! band by band on request, with its running average, its final value and,
//! for the diff view, the reference it is compared with. The command line's
//! `render_frame` and the viewer's worker both drive one of these.

use super::FrameResult;
use crate::math::Radiance;
use crate::render::debug::{self, View};
use crate::render::raytrace::brute::BruteForce;
use crate::render::{sample_offset, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a sample adds to its pixel: itself when finite, nothing otherwise.
/// A NaN or infinite sample (a degenerate hit, a division by zero in a
/// shading formula) would otherwise poison the pixel for every later pass.
#[inline]
pub fn admitted(sample: Radiance) -> Radiance {
    if sample.is_finite() { sample } else { Radiance::ZERO }
}

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
    row_passes: Vec<u32>,
    /// Diff view: the sum of the reference `raytrace:brute`'s samples, rendered
    /// band by band beside the renderer's; the frame is the difference image.
    reference: Option<Vec<Radiance>>,
    counts: RayCounts,
    /// The next band starts at row `row` of pass `pass`.
    pass: u32,
    row: u32,
    /// The photon map every pass reads (`--gi photons`), built with the first band.
    photons: Option<std::sync::Arc<crate::render::photon_map::PhotonMap>>,
}

impl Accumulator {
    /// An empty frame of `settings.width` x `settings.height` pixels and
    /// `settings.spp` samples (at least one).
    pub fn new(settings: &RenderSettings) -> Accumulator {
        let diff = settings.view == View::Diff;
        let settings = if diff { RenderSettings { view: View::Shaded, ..settings.clone() } } else { settings.clone() };
        let n = settings.width as usize * settings.height as usize;
        Accumulator {
            spp: settings.spp.max(1),
            sum: vec![Radiance::ZERO; n],
            row_passes: vec![0; settings.height as usize],
            reference: diff.then(|| vec![Radiance::ZERO; n]),
            counts: RayCounts::default(),
            pass: 0,
            row: 0,
            photons: None,
            settings,
        }
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
        self.pass >= self.spp
    }

    /// Renders the next band of at most `max_rows` rows of the next pass and
    /// adds it in. Returns `None`, adding nothing, when `cancel` was raised
    /// while it rendered. Panics when the frame is complete.
    pub fn render_band(&mut self, renderer: &dyn Renderer, prepared: &PreparedScene, max_rows: u32, cancel: &AtomicBool) -> Option<Band> {
        assert!(!self.is_complete(), "render_band on a complete frame");
        let (width, height) = (self.settings.width, self.settings.height);
        if self.pass == 0 && self.row == 0 {
            super::build_shadow_maps(prepared, &self.settings);
            self.photons = super::build_photon_map(prepared, &self.settings);
        }
        let rows = self.row..(self.row + max_rows.max(1)).min(height);
        let mut counts = RayCounts::default();
        if !rows.is_empty() && width > 0 {
            let view = prepared.scene.camera.view(width, height);
            let job = PassJob {
                prepared,
                view: &view,
                settings: &self.settings,
                offset: sample_offset(self.pass, self.spp),
                sample: self.pass,
                photons: self.photons.as_deref(),
                rows: rows.clone(),
                cancel,
            };
            let w = width as usize;
            let span = rows.start as usize * w..rows.end as usize * w;
            let cancelled = || cancel.load(Ordering::Relaxed);
            // With one sample the pass is the frame: render straight into it
            // (a cancelled band is rendered again or the frame dropped, and
            // storing overwrites, so a half-written band never shows).
            let mut mine = if self.spp == 1 { Vec::new() } else { vec![Radiance::ZERO; span.len()] };
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
            if self.spp == 1 {
                // A read-only scan in parallel: writes only where a sample
                // is not finite (rarely), so the frame costs one pass of loads.
                self.sum[span.clone()].par_chunks_mut(8192).for_each(|chunk| {
                    for s in chunk.iter_mut().filter(|s| !s.is_finite()) {
                        *s = admitted(*s);
                    }
                });
            } else {
                for (s, p) in self.sum[span.clone()].iter_mut().zip(&mine) {
                    add_sample(s, *p, self.spp);
                }
            }
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
        let pass_done = self.row >= height;
        if pass_done {
            self.row = 0;
            self.pass += 1;
        }
        Some(Band { rows, pass, counts, pass_done })
    }

    /// The running average of `rows`: every pixel's sum over the passes its
    /// row holds (zero where none yet).
    pub fn mean_rows(&self, rows: Range<u32>) -> Vec<Radiance> {
        let w = self.settings.width as usize;
        let mut out = Vec::with_capacity(rows.len() * w);
        for y in rows {
            let passes = self.row_passes[y as usize];
            let row = &self.sum[y as usize * w..(y as usize + 1) * w];
            if passes == 0 {
                out.extend(std::iter::repeat_n(Radiance::ZERO, w));
            } else {
                out.extend(row.iter().map(|s| mean(*s, passes)));
            }
        }
        out
    }

    /// The finished frame: the average of the `spp` samples (one sample is
    /// the pixel itself), or for the diff view the difference image against
    /// the reference with its count of differing pixels.
    pub fn finish(self) -> FrameResult {
        let spp = self.spp;
        let average = |mut sum: Vec<Radiance>| {
            if spp > 1 {
                for s in &mut sum {
                    *s = final_value(*s, spp);
                }
            }
            sum
        };
        let mine = average(self.sum);
        let (pixels, differing_pixels) = match self.reference {
            Some(reference) => {
                let (image, count) = debug::diff_image(&mine, &average(reference));
                (image, Some(count))
            }
            None => (mine, None),
        };
        FrameResult { width: self.settings.width, height: self.settings.height, pixels, counts: self.counts, differing_pixels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::raytrace::bvh_renderer::BvhRayTracer;
    use crate::render::{render_frame, render_frame_in_bands};
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
        assert_eq!(admitted(Radiance::new(1.0, f32::NAN, 0.0)), Radiance::ZERO);
        assert_eq!(admitted(Radiance::new(1.0, 2.0, 3.0)), Radiance::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn bands_equal_the_whole_frame_bit_for_bit() {
        let p = prepared("spheres");
        for spp in [1, 3, 4] {
            let s = settings(&p, spp, View::Shaded);
            let cancel = AtomicBool::new(false);
            let whole = render_frame(&BvhRayTracer, &p, &s, &cancel, None).unwrap();
            let banded = render_frame_in_bands(&BvhRayTracer, &p, &s, &cancel, None, 5, None).unwrap();
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
        let banded = render_frame_in_bands(&Poisoned, &p, &s, &cancel, None, 4, None).unwrap();
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
