//! The viewer's Gallery menu, driven like a user with egui_kittest: choosing
//! a case opens its scene with the failing setting applied and shows its
//! explanation; "apply cure" switches to the cure. The image shown is
//! checked against `render_frame` of the case's own scene and settings.

use egui_kittest::kittest::{NodeT, Queryable};
use egui_kittest::Harness;
use pinhole::app::PinholeApp;
use pinhole::math::Radiance;
use pinhole::render::{self, PreparedScene, ShadowMode};
use std::sync::atomic::AtomicBool;

#[path = "common/app.rs"]
mod app_common;
use app_common::{new_harness, small_scene, WAIT};

fn settle(h: &mut Harness<'static, PinholeApp>) {
    for _ in 0..200 {
        h.step();
        if !h.state().loading() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    h.step();
    assert!(h.state_mut().wait_idle(WAIT), "the worker did not finish");
    h.step();
    h.step();
}

/// What `pinhole render` gives for the app's scene, settings and renderer.
fn reference(app: &PinholeApp) -> Vec<Radiance> {
    let mut scene = (*app.scene()).clone();
    app.params().apply(&mut scene);
    let prepared = PreparedScene::new(scene);
    let renderer = render::renderer_by_name(&app.settings().renderer).unwrap();
    render::render_frame(renderer.as_ref(), &prepared, &app.effective_settings(), &AtomicBool::new(false), None).unwrap().pixels
}

fn open_case(h: &mut Harness<'static, PinholeApp>, name: &str) {
    h.get_by_label("Gallery").click();
    h.step();
    h.step();
    h.get_by_label(name).click();
    settle(h);
}

#[test]
fn the_gallery_menu_opens_a_case_with_its_failing_setting_then_its_cure() {
    let mut h = new_harness(small_scene("one-triangle"));
    settle(&mut h);
    open_case(&mut h, "shadow-acne");
    {
        let app = h.state();
        assert_eq!(app.scene().name, "stress-shadow");
        assert_eq!(app.settings().renderer, "rasterize:fixed", "the case's renderer, by its full name");
        let s = app.effective_settings();
        assert_eq!((s.shadows, s.shadow_map_bias), (ShadowMode::Map, 0.0), "the failing setting is applied");
        assert_eq!(app.gallery().map(|g| g.cured), Some(false));
        let shown = app.with_output(|o| o.linear.clone());
        assert_eq!(shown, reference(app), "the image is the failing setting's");
    }
    // The explanation is on screen, and the cure is a click away.
    h.get_by_label(pinhole::gallery::case_by_name("shadow-acne").unwrap().explanation);
    h.get_by_label("apply cure").click();
    settle(&mut h);
    let app = h.state();
    let s = app.effective_settings();
    assert_eq!((s.shadows, s.shadow_map_bias), (ShadowMode::Map, render::shadow::map::DEFAULT_BIAS));
    assert_eq!(app.gallery().map(|g| g.cured), Some(true));
    assert_eq!(app.with_output(|o| o.linear.clone()), reference(app));
}

#[test]
fn a_case_whose_cure_moves_the_scene_opens_the_moved_scene() {
    let mut h = new_harness(small_scene("one-triangle"));
    settle(&mut h);
    open_case(&mut h, "far-from-origin");
    assert_eq!(h.state().scene().camera.eye, pinhole::math::Vec3::splat(100_000.0) + pinhole::math::Vec3::new(0.0, 2.5, 5.0));
    h.get_by_label("apply cure").click();
    settle(&mut h);
    assert_eq!(h.state().scene().camera.eye, pinhole::math::Vec3::ZERO, "re-centred at the camera");
    // Leaving the case gives the user's own knobs back.
    h.get_by_label("leave").click();
    settle(&mut h);
    assert!(h.state().gallery().is_none());
}

/// Whether the radio button labelled `label` is the selected one.
fn radio_selected(h: &Harness<'static, PinholeApp>, label: &str) -> bool {
    h.get_by_label(label).accesskit_node().toggled() == Some(eframe::egui::accesskit::Toggled::True)
}

#[test]
fn the_shading_panel_shows_the_shadow_setting_a_gallery_case_renders_with() {
    let mut h = new_harness(small_scene("one-triangle"));
    settle(&mut h);
    assert!(radio_selected(&h, "ray") && !radio_selected(&h, "volume"), "ray shadows before the case");
    open_case(&mut h, "zpass-eye-in-shadow");
    // The case renders z-pass shadow volumes ...
    let s = h.state().effective_settings();
    assert_eq!((s.shadows, s.shadow_volume), (ShadowMode::Volume, render::shadow::volume::VolumeMode::ZPass));
    // ... and the Shading panel says so.
    assert!(radio_selected(&h, "volume"), "the shadows radio shows volume");
    assert!(!radio_selected(&h, "ray"));
    assert!(radio_selected(&h, "zpass") && !radio_selected(&h, "zfail"), "the volume count shows zpass");
    // The cure shows z-fail there; leaving gives the user's ray shadows back.
    h.get_by_label("apply cure").click();
    settle(&mut h);
    assert!(radio_selected(&h, "volume") && radio_selected(&h, "zfail"));
    h.get_by_label("leave").click();
    settle(&mut h);
    assert!(radio_selected(&h, "ray") && !radio_selected(&h, "volume"));
    assert_eq!(h.state().effective_settings().shadows, ShadowMode::Ray);
}
