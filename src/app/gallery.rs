//! The stress gallery in the viewer: a case opened from the Gallery menu
//! shows its scene with the failing setting applied (to the settings the
//! panels show), its one-line
//! explanation in a bar under the menu, and a button that applies the cure
//! (and one that brings the failure back).

use eframe::egui;
use crate::app::PinholeApp;
use crate::gallery::{self, GalleryCase, Setting};
use crate::app::settings_store::ViewerSettings;
use crate::render::RenderSettings;

/// The case on show, which of its settings, and the user's own renderer
/// and knobs from before it opened (given back when it closes).
#[derive(Clone)]
pub struct GalleryView {
    pub case: GalleryCase,
    pub cured: bool,
    own: (String, RenderSettings),
}

impl GalleryView {
    pub fn setting(&self) -> &Setting {
        if self.cured { &self.case.cured } else { &self.case.failing }
    }
}

impl PinholeApp {
    /// Opens gallery case `name` with its failing setting (`cured`: its cure):
    /// its scene (transformed when the setting says so), its renderer, and
    /// its knobs written over the user's, where the panels show them.
    pub fn open_gallery_case(&mut self, name: &str, cured: bool) {
        let case = match gallery::case_by_name(name) {
            Ok(case) => case,
            Err(e) => {
                self.error_bar = Some(e);
                return;
            }
        };
        let setting = if cured { &case.cured } else { &case.failing };
        let scene = match gallery::measure::scene_and_settings(&case, setting) {
            Ok((scene, _)) => scene,
            Err(e) => {
                self.error_bar = Some(e);
                return;
            }
        };
        let renderer = match crate::render::renderer_by_name(setting.renderer) {
            Ok(r) => r.name().to_string(),
            Err(e) => {
                self.error_bar = Some(e);
                return;
            }
        };
        // Another setting of a case on show starts from the user's own knobs too.
        let own = self.gallery.take().map_or_else(|| (self.settings.renderer.clone(), self.settings.render.clone()), |g| g.own);
        self.settings.render = own.1.clone();
        self.install_scene(scene, case.scene.to_string());
        self.settings.renderer = renderer;
        (setting.apply)(&mut self.settings.render);
        self.gallery = Some(GalleryView { case, cured, own });
    }

    /// Closes the case on show, if any, giving the user's own renderer and
    /// knobs back (those that go with a scene at their defaults).
    pub fn leave_gallery(&mut self) {
        if let Some(g) = self.gallery.take() {
            (self.settings.renderer, self.settings.render) = g.own;
            self.settings.reset_scene_knobs();
        }
    }

    /// The settings to save between runs: those in force, but the user's
    /// own renderer and knobs while a gallery case is on show.
    pub fn own_settings(&self) -> ViewerSettings {
        let mut s = self.settings.clone();
        if let Some(g) = &self.gallery {
            (s.renderer, s.render) = g.own.clone();
        }
        s
    }
}

/// What the gallery bar asks of the viewer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BarRequests {
    /// Show this case again, cured (`true`) or failing.
    pub show: Option<(&'static str, bool)>,
    /// Close the case, back to the user's own settings.
    pub leave: bool,
}

/// The bar under the menu while a gallery case is on show; it reads the
/// case and edits nothing.
pub fn show(ui: &mut egui::Ui, view: Option<&GalleryView>) -> BarRequests {
    let mut requests = BarRequests::default();
    let Some(g) = view else { return requests };
    egui::Panel::top("gallery-bar").show(ui, |ui| {
        ui.horizontal_wrapped(|ui| {
            ui.strong(format!("Gallery: {}", g.case.name));
            ui.label(format!("({}, knob: {})", g.case.method, g.case.knob));
            ui.separator();
            let (what, color) = if g.cured { ("cured", egui::Color32::from_rgb(80, 170, 80)) } else { ("failing", egui::Color32::from_rgb(220, 90, 80)) };
            ui.colored_label(color, format!("{what}: {} {}", g.setting().renderer, g.setting().description));
            if g.cured {
                if ui.button("show failure").clicked() {
                    requests.show = Some((g.case.name, false));
                }
            } else if ui.button("apply cure").clicked() {
                requests.show = Some((g.case.name, true));
            }
            if ui.button("leave").on_hover_text("back to your own settings on this scene").clicked() {
                requests.leave = true;
            }
        });
        ui.label(g.case.explanation);
    });
    requests
}
