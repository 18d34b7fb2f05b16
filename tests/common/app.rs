//! Helpers shared by the viewer tests (egui_kittest).

use eframe::egui;
use egui_kittest::Harness;
use pinhole::app::PinholeApp;
use pinhole::scene::Scene;
use std::time::Duration;

/// How long a test waits for the render worker before failing.
pub const WAIT: Duration = Duration::from_secs(120);

/// A built-in or file scene at a small size, so frames finish quickly.
pub fn small_scene(name: &str) -> Scene {
    let mut scene = pinhole::scene::load::load_scene(name).unwrap();
    scene.render.width = 160;
    scene.render.height = 100;
    scene
}

/// The viewer in a 1280x800 headless harness, not yet settled.
pub fn new_harness(scene: Scene) -> Harness<'static, PinholeApp> {
    let app = PinholeApp::new_for_test(scene);
    Harness::builder()
        .with_size([1280.0, 800.0])
        .build_ui_state(|ui: &mut egui::Ui, app: &mut PinholeApp| app.ui(ui), app)
}
