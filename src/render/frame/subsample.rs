//! Sub-sampling: fewer rays than pixels. Each pass traces the pixels on a
//! grid every `step` pixels (and the last row and column), and fills the
//! pixels between from the four grid pixels around them by bilinear
//! interpolation: the cheapest preview, blind to anything smaller than the
//! grid. With a contrast threshold it also samples by importance in image
//! space: a grid cell whose corners differ by more than the threshold is
//! traced in full instead of interpolated. A feature that no corner sees
//! still goes unnoticed: that is where the method fails.

use crate::render::frame::accumulator::{add_sample, final_value};
use crate::render::frame::FrameResult;
use crate::math::Radiance;
use crate::render::{sample_offset, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

/// How a frame is sub-sampled (`--subsample`, `--subsample-contrast`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Subsample {
    /// Grid spacing in pixels; 1 traces every pixel.
    pub step: u32,
    /// Trace a cell in full when its corners' contrast exceeds this.
    pub contrast: Option<f32>,
}

impl Default for Subsample {
    fn default() -> Subsample {
        Subsample { step: 1, contrast: None }
    }
}

/// The grid spacings `--subsample` accepts.
pub const STEPS: [u32; 5] = [1, 2, 4, 8, 16];

impl Subsample {
    pub fn is_on(&self) -> bool {
        self.step > 1
    }
}

/// The traced columns (or rows) of a side of `len` pixels: every `step`-th,
/// and the last, so every pixel lies between two traced ones.
pub fn grid_lines(len: u32, step: u32) -> Vec<u32> {
    let mut lines: Vec<u32> = (0..len).step_by(step.max(1) as usize).collect();
    if len > 0 && lines.last() != Some(&(len - 1)) {
        lines.push(len - 1);
    }
    lines
}

/// The largest relative difference between any two of a cell's corners, per
/// channel: `(max - min) / (max + min)`, the contrast measure of adaptive
/// image sampling (0 where all agree, 1 where one is black and one is not).
pub fn contrast(corners: [Radiance; 4]) -> f32 {
    let lo = corners.iter().fold(Radiance::splat(f32::INFINITY), |a, c| a.min(*c));
    let hi = corners.iter().fold(Radiance::splat(f32::NEG_INFINITY), |a, c| a.max(*c));
    let c = (hi - lo) / (hi + lo).max(Radiance::splat(1e-6));
    c.max_element()
}

/// Renders a whole sub-sampled frame of `settings.spp` passes. `None` when
/// `cancel` was raised.
pub fn render_subsampled(renderer: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings, cancel: &AtomicBool, passes_done: Option<&AtomicU32>) -> Option<FrameResult> {
    let (w, h) = (settings.width, settings.height);
    let n = w as usize * h as usize;
    let spp = settings.spp.max(1);
    crate::render::frame::build_shadow_maps(prepared, settings);
    let photons = crate::render::frame::build_photon_map(prepared, settings);
    let view = prepared.scene.camera.view(w, h);
    let (xs, ys) = (grid_lines(w, settings.subsample.step), grid_lines(h, settings.subsample.step));
    let mut corners = vec![false; n];
    for &y in &ys {
        for &x in &xs {
            corners[(x + y * w) as usize] = true;
        }
    }
    let mut sum = vec![Radiance::ZERO; n];
    let mut counts = RayCounts::default();
    for pass in 0..spp {
        let trace = |active: &[bool], out: &mut [Radiance]| {
            let job = PassJob {
                prepared,
                view: &view,
                settings,
                offset: sample_offset(pass, spp, settings.gi.seed),
                sample: pass,
                photons: photons.as_deref(),
                active: Some(active),
                rows: 0..h,
                cancel,
                keep_non_finite: false,
            };
            renderer.render_pass(&job, out)
        };
        let mut image = vec![Radiance::ZERO; n];
        counts += trace(&corners, &mut image);
        let mut traced = corners.clone();
        if let Some(threshold) = settings.subsample.contrast {
            let mut refine = vec![false; n];
            let mut any = false;
            for_each_cell(&xs, &ys, |(x0, x1), (y0, y1)| {
                let at = |x: u32, y: u32| image[(x + y * w) as usize];
                if contrast([at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)]) > threshold {
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            let i = (x + y * w) as usize;
                            refine[i] = !traced[i];
                            any |= refine[i];
                        }
                    }
                }
            });
            if any {
                let mut more = vec![Radiance::ZERO; n];
                counts += trace(&refine, &mut more);
                for i in (0..n).filter(|&i| refine[i]) {
                    image[i] = more[i];
                    traced[i] = true;
                }
            }
        }
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        interpolate(&mut image, &traced, w, &xs, &ys);
        for (s, p) in sum.iter_mut().zip(&image) {
            add_sample(s, *p, spp);
        }
        if let Some(done) = passes_done {
            done.fetch_add(1, Ordering::Relaxed);
        }
    }
    for s in &mut sum {
        *s = final_value(*s, spp);
    }
    Some(FrameResult { width: w, height: h, pixels: sum, counts, differing_pixels: None, summed_passes: None })
}

/// Calls `f` with each grid cell's column and row span (inclusive corners).
fn for_each_cell(xs: &[u32], ys: &[u32], mut f: impl FnMut((u32, u32), (u32, u32))) {
    for y in ys.windows(2) {
        for x in xs.windows(2) {
            f((x[0], x[1]), (y[0], y[1]));
        }
    }
}

/// Fills every pixel not `traced` from the four traced grid pixels around
/// it, weighted by its distance to each (bilinear). A frame one pixel wide
/// or high has cells of one line; they interpolate along it.
fn interpolate(image: &mut [Radiance], traced: &[bool], w: u32, xs: &[u32], ys: &[u32]) {
    let span = |lines: &[u32], v: u32| -> (u32, u32) {
        let k = lines.partition_point(|&l| l <= v).saturating_sub(1);
        (lines[k], lines[(k + 1).min(lines.len() - 1)])
    };
    let h = (image.len() / w.max(1) as usize) as u32;
    for y in 0..h {
        let (y0, y1) = span(ys, y);
        let fy = if y1 > y0 { (y - y0) as f32 / (y1 - y0) as f32 } else { 0.0 };
        for x in 0..w {
            let i = (x + y * w) as usize;
            if traced[i] {
                continue;
            }
            let (x0, x1) = span(xs, x);
            let fx = if x1 > x0 { (x - x0) as f32 / (x1 - x0) as f32 } else { 0.0 };
            let at = |x: u32, y: u32| image[(x + y * w) as usize];
            let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
            let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
            image[i] = top * (1.0 - fy) + bottom * fy;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_lines_include_the_last_pixel() {
        assert_eq!(grid_lines(9, 4), vec![0, 4, 8]);
        assert_eq!(grid_lines(10, 4), vec![0, 4, 8, 9]);
        assert_eq!(grid_lines(1, 4), vec![0]);
        assert_eq!(grid_lines(5, 1), vec![0, 1, 2, 3, 4]);
        assert!(grid_lines(0, 4).is_empty());
    }

    #[test]
    fn contrast_by_hand() {
        let c = |v: [f32; 4]| contrast(v.map(Radiance::splat));
        assert_eq!(c([0.5; 4]), 0.0);
        assert_eq!(c([0.0, 1.0, 1.0, 1.0]), 1.0);
        assert!((c([1.0, 3.0, 2.0, 2.0]) - 0.5).abs() < 1e-6);
        // Black everywhere: no contrast (and no division by zero).
        assert_eq!(c([0.0; 4]), 0.0);
    }

    #[test]
    fn interpolation_is_bilinear_between_the_traced_corners() {
        // 5 x 3 pixels, grid every 4 columns and 2 rows: corners at x 0 and 4, y 0 and 2.
        let (w, xs, ys) = (5u32, grid_lines(5, 4), grid_lines(3, 2));
        let mut image = vec![Radiance::ZERO; 15];
        let mut traced = vec![false; 15];
        for (x, y, v) in [(0u32, 0u32, 0.0f32), (4, 0, 4.0), (0, 2, 8.0), (4, 2, 12.0)] {
            image[(x + y * w) as usize] = Radiance::splat(v);
            traced[(x + y * w) as usize] = true;
        }
        interpolate(&mut image, &traced, w, &xs, &ys);
        // v = x + 4 y is bilinear, so it is reproduced exactly.
        for y in 0..3 {
            for x in 0..5 {
                assert!((image[(x + y * w) as usize].x - (x + 4 * y) as f32).abs() < 1e-6, "({x}, {y})");
            }
        }
    }
}
