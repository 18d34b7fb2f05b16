//! The samples sweep (`pinhole chart --sweep spp`): each renderer at a list of
//! samples per pixel, timed and measured against a reference.

use crate::math::Radiance;
use crate::render::{self, PreparedScene, RenderSettings};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// One measured frame of the sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepPoint {
    pub renderer: String,
    pub spp: u32,
    /// Best of the timed frames, milliseconds.
    pub ms: f64,
    /// rmse relative to the reference's mean radiance.
    pub rel_rmse: f64,
    pub flip: f64,
}

/// Renders each renderer at each spp (`repeats` timed frames, best kept) and
/// measures it against `reference`. `progress` is called before each frame,
/// `notice` with what a renderer draws otherwise than asked (`render::admit`).
pub fn sweep(
    prepared: &PreparedScene,
    base: &RenderSettings,
    renderers: &[&str],
    spps: &[u32],
    reference: &[Radiance],
    repeats: u32,
    mut progress: impl FnMut(&str, u32),
    mut notice: impl FnMut(&str),
) -> Result<Vec<SweepPoint>, String> {
    let cancel = AtomicBool::new(false);
    let mut points = Vec::new();
    for name in renderers {
        let r = render::renderer_by_name(name)?;
        for &spp in spps {
            progress(r.name(), spp);
            let admitted = render::admit::admit(r.as_ref(), &prepared.scene, &RenderSettings { spp, ..base.clone() })?;
            admitted.notices.iter().chain(&admitted.caveats).for_each(|n| notice(n));
            r.ready(&admitted.settings)?;
            let settings = admitted.settings;
            let mut best = f64::INFINITY;
            let mut image = Vec::new();
            for _ in 0..repeats.max(1) {
                let start = Instant::now();
                let f = render::render_frame(r.as_ref(), prepared, &settings, &cancel, None).ok_or("cancelled")?;
                best = best.min(start.elapsed().as_secs_f64() * 1e3);
                image = f.pixels;
            }
            let m = crate::metrics::compare_images(&image, reference, settings.width as usize, settings.height as usize)?;
            points.push(SweepPoint {
                renderer: r.name().to_string(),
                spp,
                ms: best,
                rel_rmse: m.rmse / m.reference_mean.max(1e-12),
                flip: m.flip.unwrap_or(f64::NAN),
            });
        }
    }
    Ok(points)
}

pub fn to_csv(points: &[SweepPoint]) -> String {
    let mut s = String::from("renderer,spp,ms,rel_rmse,flip\n");
    for p in points {
        s.push_str(&format!("{},{},{:.3},{:.6},{:.6}\n", p.renderer, p.spp, p.ms, p.rel_rmse, p.flip));
    }
    s
}
