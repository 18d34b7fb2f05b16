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

/// Whether an OpenGL driver exists; prints why a test is skipped when none
/// does. With `PINHOLE_REQUIRE_GL=1` (CI installs Mesa and sets it) a
/// missing driver panics instead, so such a machine cannot pass a GL test
/// without running it.
#[allow(dead_code)] // not every viewer test draws with GL
pub fn have_gl() -> bool {
    match pinhole::render::opengl::driver() {
        Ok(_) => true,
        Err(e) if std::env::var("PINHOLE_REQUIRE_GL").is_ok_and(|v| v == "1") => panic!("PINHOLE_REQUIRE_GL=1 but there is no OpenGL driver: {e}"),
        Err(e) => {
            eprintln!("skipped: {e}");
            false
        }
    }
}

/// One frame, then waits for the worker to finish the render in flight and
/// lets two more frames show its image and the panels that follow it.
#[allow(dead_code)] // not every viewer test waits for a render
pub fn settle(h: &mut Harness<'static, PinholeApp>) {
    h.step();
    assert!(h.state_mut().wait_idle(WAIT), "the worker did not finish");
    h.step();
    h.step();
}
