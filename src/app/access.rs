//! The viewer's state as seen from outside the crate (the egui_kittest
//! tests): named, read-only accessors, and a few clearly named ways to
//! change what a test sets up directly instead of through the widgets.

use crate::app::compare_lab::CompareLab;
use crate::app::gallery::GalleryView;
use crate::app::inspect::Inspect;
use crate::app::settings_store::ViewerSettings;
use crate::app::split_view::SplitView;
use crate::app::worker::SceneParams;
use crate::app::PinholeApp;
use crate::scene::Scene;
use eframe::egui;

impl PinholeApp {
    /// The scene as loaded (before the edits in `params`).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Camera, lights, materials and `[render]` values as edited.
    pub fn params(&self) -> &SceneParams {
        &self.params
    }

    /// The edited values, to change them as the panels would.
    pub fn params_mut(&mut self) -> &mut SceneParams {
        &mut self.params
    }

    /// The settings in force, those saved between runs included.
    pub fn settings(&self) -> &ViewerSettings {
        &self.settings
    }

    /// The settings in force, to change them as the panels would; the next
    /// frame renders with them.
    pub fn settings_mut(&mut self) -> &mut ViewerSettings {
        &mut self.settings
    }

    /// Every renderer this build has, in the menu's order.
    pub fn renderer_names(&self) -> &[&'static str] {
        &self.renderer_names
    }

    /// The status bar's line: renderer, size, samples, speed, state.
    pub fn status_line(&self) -> String {
        self.with_output(|o| crate::app::panels::status::status_text(&self.settings.renderer, &self.scene, o))
    }

    /// The number of the last render request sent.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The problem shown in the red bar, if any.
    pub fn error_bar(&self) -> Option<&str> {
        self.error_bar.as_deref()
    }

    /// The passing note in the status bar, if any.
    pub fn message(&self) -> Option<&str> {
        self.message.as_deref()
    }

    /// Where the image was drawn last frame, in points.
    pub fn viewport_rect(&self) -> Option<egui::Rect> {
        self.viewport_rect
    }

    /// Whether the Open dialog is showing.
    pub fn open_dialog_is_open(&self) -> bool {
        self.open_dialog.open
    }

    /// The path the Export dialog suggests or was given.
    pub fn export_path(&self) -> &str {
        &self.export.path
    }

    /// The selected pixel, its replay, zoom and overlays.
    pub fn inspect(&self) -> &Inspect {
        &self.inspect
    }

    /// The Compare window's measurements.
    pub fn compare(&self) -> &CompareLab {
        &self.compare
    }

    /// The Compare window's measurements, to start or steer a sweep.
    pub fn compare_mut(&mut self) -> &mut CompareLab {
        &mut self.compare
    }

    /// Configuration B beside the live one (A|B).
    pub fn split(&self) -> &SplitView {
        &self.split
    }

    /// Configuration B, to change how it is shown.
    pub fn split_mut(&mut self) -> &mut SplitView {
        &mut self.split
    }

    /// The stress-gallery case on show, if any.
    pub fn gallery(&self) -> Option<&GalleryView> {
        self.gallery.as_ref()
    }
}
