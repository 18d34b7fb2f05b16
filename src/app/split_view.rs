//! Two configurations side by side: A is the live view, B a second
//! configuration (renderer and render knobs) rendered by a second worker
//! with the same scene, camera and image size. The viewport shows them as a
//! wipe with a draggable divider or as their difference, and the error
//! between them over the whole view and over a dragged rectangle.

use crate::app::settings_store::ViewerSettings;
use crate::app::worker::{Request, Worker};
use crate::math::Radiance;
use eframe::egui;
use std::sync::Arc;
use std::time::Duration;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitMode {
    /// A left of the divider, B right of it.
    Wipe,
    /// B against A: red where B is brighter, blue where darker.
    Difference,
}

/// The error of B against A.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitError {
    /// rmse over the whole view, relative to A's mean radiance.
    pub whole: f64,
    /// The same over the dragged rectangle, when there is one.
    pub region: Option<f64>,
    /// Pixels that differ by more than 1e-4 relative.
    pub differing: u64,
}

pub struct SplitView {
    pub enabled: bool,
    pub mode: SplitMode,
    /// Configuration B (its renderer and knobs; view and display follow A).
    pub b: ViewerSettings,
    /// Where the divider stands, as a fraction of the image width.
    pub divider: f32,
    pub dragging_divider: bool,
    /// A rectangle of image pixels `[x0, y0, x1, y1)` whose error is shown.
    pub region: Option<[u32; 4]>,
    /// The image pixel where a region drag started.
    pub region_start: Option<(u32, u32)>,
    worker: Option<Worker>,
    generation: u64,
    last_sent: Option<Request>,
    pub texture: Option<egui::TextureHandle>,
    shown_version: u64,
    pub diff_texture: Option<egui::TextureHandle>,
    /// (A's version, B's version, region) the difference and error were computed for.
    measured: Option<(u64, u64, Option<[u32; 4]>)>,
    pub error: Option<SplitError>,
    /// Statistics of A's linear values over the dragged rectangle.
    pub region_stats: Option<crate::app::region_stats::RegionStats>,
}

impl Default for SplitView {
    fn default() -> Self {
        SplitView {
            enabled: false,
            mode: SplitMode::Wipe,
            b: ViewerSettings::default(),
            divider: 0.5,
            dragging_divider: false,
            region: None,
            region_start: None,
            worker: None,
            generation: 0,
            last_sent: None,
            texture: None,
            shown_version: 0,
            diff_texture: None,
            measured: None,
            error: None,
            region_stats: None,
        }
    }
}

impl SplitView {
    /// Turns the split on with B = `current` (the live configuration), or off.
    pub fn toggle(&mut self, current: &ViewerSettings) {
        self.enabled = !self.enabled;
        if self.enabled && self.worker.is_none() {
            self.b = current.clone();
        }
    }

    /// B becomes `settings` (e.g. a configuration from the Compare window).
    pub fn set_b(&mut self, settings: ViewerSettings) {
        self.b = settings;
        self.enabled = true;
    }

    /// The label of B's configuration.
    pub fn b_label(&self, a: &ViewerSettings) -> String {
        crate::chart::describe(&self.b.renderer, &self.b_settings(a, 1, 1))
    }

    /// B's render settings: its knobs, with A's view and image size.
    pub fn b_settings(&self, a: &ViewerSettings, width: u32, height: u32) -> crate::render::RenderSettings {
        crate::render::RenderSettings { view: a.render.view, ..self.b.render_settings(width, height) }
    }

    /// Asks B's worker for the image that goes with A's request `a` when
    /// anything differs from what it was last asked.
    pub fn sync(&mut self, a: &Request, a_settings: &ViewerSettings, scene: &crate::scene::Scene, scene_id: u64, repaint: Arc<dyn Fn() + Send + Sync>) {
        if !self.enabled {
            return;
        }
        let settings = self.b_settings(a_settings, a.settings.width, a.settings.height);
        let worker = self.worker.get_or_insert_with(|| Worker::start(repaint));
        if let Some(l) = &self.last_sent {
            if l.scene_id == scene_id && l.renderer == self.b.renderer && l.settings == settings && l.params.same_as(&a.params) && l.interactive == a.interactive {
                return;
            }
        }
        if self.last_sent.as_ref().is_none_or(|l| l.scene_id != scene_id) {
            // A new worker, or a new scene: B's worker needs it too.
            worker.set_scene(scene_id, Arc::new(scene.clone()));
        }
        self.generation += 1;
        let req = Request { generation: self.generation, settings, renderer: self.b.renderer.clone(), ..a.clone() };
        worker.request(req.clone());
        self.last_sent = Some(req);
    }

    /// Forgets what B's worker was asked, so the next `sync` hands it the scene again.
    pub fn scene_changed(&mut self) {
        self.last_sent = None;
    }

    /// Waits until B's worker finished its latest request (tests, screenshots).
    pub fn wait_idle(&self, timeout: Duration) -> bool {
        match &self.worker {
            Some(w) if self.enabled => w.wait_idle(self.generation, timeout),
            _ => true,
        }
    }

    /// Whether B's latest image is complete.
    pub fn idle(&self) -> bool {
        match &self.worker {
            Some(w) if self.enabled => {
                let o = w.shared.output.lock().unwrap();
                o.generation == self.generation && o.idle && o.complete
            }
            _ => true,
        }
    }

    /// The version of B's latest image (`None` before B has one).
    pub fn b_version(&self) -> Option<u64> {
        let o = self.worker.as_ref()?.shared.output.lock().unwrap();
        (o.width > 0).then_some(o.version)
    }

    /// B's latest linear image, `(width, height, pixels)`.
    pub fn b_linear(&self) -> Option<(u32, u32, Vec<Radiance>)> {
        let o = self.worker.as_ref()?.shared.output.lock().unwrap();
        (o.width > 0).then(|| (o.width, o.height, o.linear.clone()))
    }

    /// Copies B's newest image into its texture and, when A or B or the region
    /// changed, recomputes the difference image and the error.
    pub fn update(&mut self, ctx: &egui::Context, a: (u32, u32, u64, &[Radiance]), exposure: f32, display: &crate::display::DisplaySettings) {
        let Some(worker) = self.worker.as_ref().filter(|_| self.enabled) else { return };
        let (b_version, bw, bh, b_linear, b_rgb) = {
            let o = worker.shared.output.lock().unwrap();
            if o.width == 0 {
                return;
            }
            (o.version, o.width, o.height, o.linear.clone(), (o.version != self.shown_version).then(|| o.rgb8.clone()))
        };
        if let Some(rgb) = b_rgb {
            let image = egui::ColorImage::from_rgb([bw as usize, bh as usize], &rgb);
            match &mut self.texture {
                Some(t) => t.set(image, egui::TextureOptions::NEAREST),
                None => self.texture = Some(ctx.load_texture("pinhole-frame-b", image, egui::TextureOptions::NEAREST)),
            }
            self.shown_version = b_version;
        }
        let (aw, ah, a_version, a_linear) = a;
        let key = (a_version, b_version, self.region);
        if self.measured == Some(key) {
            return;
        }
        if (aw, ah) != (bw, bh) || a_linear.len() != b_linear.len() {
            return; // one of them is still a preview of another size
        }
        self.measured = Some(key);
        self.error = Some(split_error(a_linear, &b_linear, aw, self.region));
        self.region_stats = self.region.map(|r| crate::app::region_stats::region_stats(a_linear, aw, r));
        let (diff, _) = crate::render::inspect::debug::diff_image(&b_linear, a_linear);
        let rgb = crate::display::image_rgb8(&diff, display.scale(exposure), display.tonemap, display.gamma);
        let image = egui::ColorImage::from_rgb([aw as usize, ah as usize], &rgb);
        match &mut self.diff_texture {
            Some(t) => t.set(image, egui::TextureOptions::NEAREST),
            None => self.diff_texture = Some(ctx.load_texture("pinhole-frame-diff", image, egui::TextureOptions::NEAREST)),
        }
    }

    /// Swaps A and B: the live view takes B's configuration and B takes A's.
    pub fn swap(&mut self, a: &mut ViewerSettings) {
        let old_a = a.clone();
        a.take_configuration(&self.b);
        self.b = old_a;
    }
}

/// B's rmse against A relative to A's mean, over the whole image and over `region`.
pub fn split_error(a: &[Radiance], b: &[Radiance], width: u32, region: Option<[u32; 4]>) -> SplitError {
    let rel = |indices: &mut dyn Iterator<Item = usize>| -> (f64, u64) {
        let (mut se, mut mean, mut n, mut differing) = (0.0f64, 0.0f64, 0u64, 0u64);
        for i in indices {
            let (x, y) = (a[i], b[i]);
            let mut differs = false;
            for k in 0..3 {
                let d = (y[k] - x[k]) as f64;
                se += d * d;
                mean += x[k] as f64;
                differs |= d.abs() > 1e-4 * (x[k].abs().max(y[k].abs()) as f64).max(1e-3);
            }
            n += 3;
            differing += differs as u64;
        }
        if n == 0 {
            return (0.0, 0);
        }
        ((se / n as f64).sqrt() / (mean / n as f64).max(1e-12), differing)
    };
    let (whole, differing) = rel(&mut (0..a.len().min(b.len())));
    let region = region.map(|[x0, y0, x1, y1]| {
        let w = width as usize;
        let mut it = (y0 as usize..y1 as usize).flat_map(move |y| (x0 as usize..x1 as usize).map(move |x| y * w + x)).filter(|&i| i < a.len().min(b.len()));
        rel(&mut it).0
    });
    SplitError { whole, region, differing }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn error_of_the_whole_view_and_of_a_region() {
        // A 4x2 image: B differs from A in pixel (3, 1) only.
        let a = vec![Vec3::ONE; 8];
        let mut b = a.clone();
        b[7] = Vec3::splat(3.0);
        let e = split_error(&a, &b, 4, Some([2, 1, 4, 2]));
        assert_eq!(e.differing, 1);
        // Whole: one pixel off by 2 in all channels over 8 pixels: sqrt(4/8) / 1.
        assert!((e.whole - 0.5f64.sqrt()).abs() < 1e-12, "{}", e.whole);
        // The region holds two pixels, one of them off: sqrt(4/2).
        assert!((e.region.unwrap() - 2f64.sqrt()).abs() < 1e-12);
        let same = split_error(&a, &a, 4, Some([0, 0, 1, 1]));
        assert_eq!((same.whole, same.region, same.differing), (0.0, Some(0.0), 0));
    }

    #[test]
    fn swapping_exchanges_the_configurations() {
        let mut a = ViewerSettings::default();
        a.renderer = "raytrace:bvh".into();
        a.render.spp = 4;
        let mut split = SplitView::default();
        split.toggle(&a);
        split.b.renderer = "rasterize:fixed".into();
        split.b.render.spp = 1;
        split.swap(&mut a);
        assert_eq!((a.renderer.as_str(), a.render.spp), ("rasterize:fixed", 1));
        assert_eq!((split.b.renderer.as_str(), split.b.render.spp), ("raytrace:bvh", 4));
    }
}
