//! The frame loop: one pass per sample position, averaged. Used by the command
//! line and the viewer's worker alike.

use super::{sample_offset, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
use crate::math::Radiance;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

pub struct FrameResult {
    pub width: u32,
    pub height: u32,
    /// Linear radiance, row-major, averaged over the samples.
    pub pixels: Vec<Radiance>,
    pub counts: RayCounts,
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
    let view = prepared.scene.camera.view(settings.width, settings.height);
    let n = (settings.width * settings.height) as usize;
    let mut sum = vec![Radiance::ZERO; n];
    let mut pass = vec![Radiance::ZERO; n];
    let mut counts = RayCounts::default();
    let spp = settings.spp.max(1);
    for i in 0..spp {
        let job = PassJob {
            prepared,
            view: &view,
            settings,
            offset: sample_offset(i, spp),
            rows: 0..settings.height,
            cancel,
        };
        counts += renderer.render_pass(&job, &mut pass);
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        for (s, p) in sum.iter_mut().zip(&pass) {
            *s += *p;
        }
        if let Some(done) = passes_done {
            done.fetch_add(1, Ordering::Relaxed);
        }
    }
    let inv = 1.0 / spp as f32;
    for s in &mut sum {
        *s *= inv;
    }
    Some(FrameResult { width: settings.width, height: settings.height, pixels: sum, counts })
}
