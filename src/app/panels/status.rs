//! The status bar: renderer, resolution, samples so far, time per frame,
//! rays or fragments per second, triangles, and UI frames per second; and
//! under it, what the renderer draws otherwise than asked.

use eframe::egui;
use crate::app::worker::Output;
use crate::scene::Scene;

/// What the status bar shows: the status line (`status_text`), the UI's
/// frame rate, a passing note and the gate's notices. It edits nothing, so
/// it asks nothing of the viewer.
pub struct Status<'a> {
    pub line: String,
    pub ui_fps: f32,
    pub message: Option<&'a str>,
    pub notices: Vec<String>,
}

pub fn show(ui: &mut egui::Ui, status: Status) {
    let Status { line, ui_fps, message, notices } = status;
    egui::Panel::bottom("status-bar").show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.label(line);
            ui.separator();
            ui.label(format!("UI {ui_fps:.0} fps"));
            if let Some(m) = message {
                ui.separator();
                ui.label(m);
            }
        });
        // What the renderer draws otherwise than the panels ask (`render::admit`).
        for n in &notices {
            ui.colored_label(egui::Color32::from_rgb(230, 180, 60), n);
        }
    });
}

/// The status line as plain text: `renderer` drawing `scene`, as the
/// worker's latest output `o` reports it.
pub fn status_text(renderer: &str, scene: &Scene, o: &Output) -> String {
    let triangles = scene.total_triangles();
    let spheres = scene.spheres.len();
    let s = &o.stats;
    let c = &s.counts;
    let rays = c.primary + c.shadow + c.secondary;
    let per_s = |n: u64| si(n as f64 / (s.pass_ms / 1e3));
    let rate = if s.pass_ms <= 0.0 {
        "–".to_string()
    } else if c.fragments_shaded > 0 {
        // A rasterizer: fragments shaded, plus the shadow/secondary rays it cast.
        let rays = c.shadow + c.secondary;
        if rays > 0 {
            format!("{} fragments/s, {} rays/s", per_s(c.fragments_shaded), per_s(rays))
        } else {
            format!("{} fragments/s", per_s(c.fragments_shaded))
        }
    } else {
        format!("{} rays/s", per_s(rays))
    };
    let state = if let Some(e) = &o.error {
        format!("error: {e}")
    } else if o.complete {
        format!("done in {:.0} ms", s.frame_ms)
    } else if o.preview {
        "preview".into()
    } else {
        "rendering".into()
    };
    format!(
        "{renderer} | {}x{} | {}/{} spp{} | {:.1} ms/pass | {rate} | {triangles} triangles{} | first image {:.0} ms | {state}",
        o.width,
        o.height,
        o.passes,
        o.spp,
        s.noise.map_or(String::new(), |n| format!(" (noise ≈ {:.1}%)", n * 100.0)),
        s.pass_ms,
        if spheres > 0 { format!(", {spheres} spheres") } else { String::new() },
        s.first_image_ms,
    )
}

/// 1234567 -> "1.23 M".
pub fn si(v: f64) -> String {
    if v >= 1e9 {
        format!("{:.2} G", v / 1e9)
    } else if v >= 1e6 {
        format!("{:.2} M", v / 1e6)
    } else if v >= 1e3 {
        format!("{:.1} k", v / 1e3)
    } else {
        format!("{v:.0}")
    }
}
