//! The stress gallery in the viewer: a case opened from the Gallery menu
//! shows its scene with the failing setting applied, its one-line
//! explanation in a bar under the menu, and a button that applies the cure
//! (and one that brings the failure back).

use eframe::egui;
use crate::app::PinholeApp;
use crate::gallery::{self, GalleryCase, Setting};
use crate::render::RenderSettings;

/// The case on show and which of its settings.
#[derive(Clone, Copy)]
pub struct GalleryView {
    pub case: GalleryCase,
    pub cured: bool,
}

impl GalleryView {
    pub fn setting(&self) -> &Setting {
        if self.cured { &self.case.cured } else { &self.case.failing }
    }
}

impl PinholeApp {
    /// Opens gallery case `name` with its failing setting (`cured`: its cure):
    /// its scene (transformed when the setting says so), its renderer, its
    /// knobs on top of the user's (`apply_gallery`).
    pub fn open_gallery_case(&mut self, name: &str, cured: bool) {
        let view = match gallery::case_by_name(name) {
            Ok(case) => GalleryView { case, cured },
            Err(e) => {
                self.error_bar = Some(e);
                return;
            }
        };
        let setting = view.setting();
        let scene = match gallery::measure::scene_and_settings(&view.case, setting) {
            Ok((scene, _)) => scene,
            Err(e) => {
                self.error_bar = Some(e);
                return;
            }
        };
        match crate::render::renderer_by_name(setting.renderer) {
            Ok(r) => self.settings.renderer = r.name().to_string(),
            Err(e) => {
                self.error_bar = Some(e);
                return;
            }
        }
        self.install_scene(scene, view.case.scene.to_string());
        self.gallery = Some(view);
    }

    /// The knobs of the gallery setting on show, if any, applied over `settings`.
    pub fn apply_gallery(&self, settings: &mut RenderSettings) {
        if let Some(g) = &self.gallery {
            (g.setting().apply)(settings);
        }
    }
}

/// The bar under the menu while a gallery case is on show.
pub fn show(app: &mut PinholeApp, ui: &mut egui::Ui) {
    let Some(g) = app.gallery else { return };
    let mut switch = None;
    let mut close = false;
    egui::Panel::top("gallery-bar").show(ui, |ui| {
        ui.horizontal_wrapped(|ui| {
            ui.strong(format!("Gallery: {}", g.case.name));
            ui.label(format!("({}, knob: {})", g.case.method, g.case.knob));
            ui.separator();
            let (what, color) = if g.cured { ("cured", egui::Color32::from_rgb(80, 170, 80)) } else { ("failing", egui::Color32::from_rgb(220, 90, 80)) };
            ui.colored_label(color, format!("{what}: {} {}", g.setting().renderer, g.setting().description));
            if g.cured {
                if ui.button("show failure").clicked() {
                    switch = Some(false);
                }
            } else if ui.button("apply cure").clicked() {
                switch = Some(true);
            }
            if ui.button("leave").on_hover_text("back to your own settings on this scene").clicked() {
                close = true;
            }
        });
        ui.label(g.case.explanation);
    });
    if let Some(cured) = switch {
        app.open_gallery_case(g.case.name, cured);
    }
    if close {
        app.gallery = None;
    }
}
