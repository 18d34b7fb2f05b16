//! The admission gate in the viewer: where a renderer draws other settings
//! than the panels ask for (`render::admit`), the Shading panel shows the
//! setting in force beside the one asked. Skipped, with the reason printed,
//! where no OpenGL driver exists, unless `PINHOLE_REQUIRE_GL=1` asks for one.

use egui_kittest::kittest::Queryable;
use pinhole::render::ShadowMode;

#[path = "common/app.rs"]
mod app_common;
use app_common::{new_harness, settle, small_scene};

#[test]
fn shading_panel_shows_the_shadow_maps_opengl_draws_for_shadow_rays() {
    if !app_common::have_gl() {
        return;
    }
    let mut h = new_harness(small_scene("teapot"));
    settle(&mut h);
    assert_eq!(h.state().settings().render.shadows, ShadowMode::Ray, "the scene asks for shadow rays");
    assert!(h.query_by_label_contains("in force:").is_none(), "the ray tracer draws what is asked");

    h.state_mut().settings_mut().renderer = "opengl".into();
    settle(&mut h);
    let notices = h.state().with_output(|o| o.notices.clone());
    assert_eq!(notices.len(), 1, "{notices:?}");
    assert!(notices[0].contains("shadow maps"), "{notices:?}");
    // The panel still asks for rays, and says what is drawn instead.
    assert_eq!(h.state().settings().render.shadows, ShadowMode::Ray);
    h.get_by_label(&format!("in force: map — {}", notices[0]));

    // Asking for maps: nothing substituted, no line.
    h.state_mut().settings_mut().render.shadows = ShadowMode::Map;
    settle(&mut h);
    assert!(h.query_by_label_contains("in force:").is_none(), "maps are drawn as asked");
}
