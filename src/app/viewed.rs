//! What the viewport and its legend read: the frame on show and what it
//! was drawn from (settings, scene, the worker's output).

use crate::app::worker::Output;
use crate::render::RenderSettings;
use crate::scene::Scene;
use eframe::egui;
use std::sync::Mutex;

/// What the viewport and the legend read: the frame on show and what it was drawn from.
pub struct Viewed<'a> {
    /// The settings the worker renders with, at the image's size.
    pub settings: &'a RenderSettings,
    pub renderer: &'a str,
    /// The scene's exposure (a linear factor) and the display transform.
    pub exposure: f32,
    pub display: crate::display::DisplaySettings,
    pub scene: &'a Scene,
    pub scene_id: u64,
    /// The last render request sent: a replay for it is current.
    pub generation: u64,
    pub texture: Option<&'a egui::TextureHandle>,
    /// The worker's latest output (pixel values under the cursor, counts).
    pub output: &'a Mutex<Output>,
    /// The error views: what the image on show was compared with.
    pub error: Option<&'a crate::app::reference_view::Mapped>,
}

impl Viewed<'_> {
    /// Runs `f` on the worker's latest output under its lock.
    pub fn with_output<T>(&self, f: impl FnOnce(&Output) -> T) -> T {
        f(&self.output.lock().unwrap())
    }
}
