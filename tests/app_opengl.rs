//! The `opengl` renderer in the viewer, driven like a user with
//! egui_kittest: chosen in the viewer, its image equals what `pinhole
//! render --renderer opengl` writes for the same scene, and a clicked
//! pixel shows GL's readback (labelled as not a replay). Skipped, with the
//! reason printed, where no OpenGL driver exists, unless
//! `PINHOLE_REQUIRE_GL=1` asks for one (then it fails).

use eframe::egui;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pinhole::app::PinholeApp;

#[path = "common/app.rs"]
mod app_common;
use app_common::{WAIT, new_harness, settle, small_scene};

fn click(h: &mut Harness<'static, PinholeApp>, pos: egui::Pos2) {
    h.hover_at(pos);
    h.step();
    h.drag_at(pos);
    h.step();
    h.drop_at(pos);
    h.step();
}

#[test]
fn opengl_in_the_viewer_matches_the_cli_and_reads_back_a_clicked_pixel() {
    if !app_common::have_gl() {
        return;
    }
    let mut h = new_harness(small_scene("teapot"));
    settle(&mut h);
    h.state_mut().settings_mut().renderer = "opengl".into();
    h.state_mut().settings_mut().render.shadows = pinhole::render::ShadowMode::None;
    settle(&mut h);
    let (img, w, hgt) = h.state().with_output(|o| {
        assert!(o.complete && o.error.is_none(), "frame not complete: {:?}", o.error);
        (o.linear.clone(), o.width, o.height)
    });
    let background = h.state().scene().render.background;
    assert!(img.iter().filter(|p| **p != background).count() > img.len() / 10, "the teapot is drawn");

    // The same scene through the command line.
    let dir = std::env::temp_dir().join(format!("pinhole-app-opengl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("teapot.exr");
    let (ws, hs) = (w.to_string(), hgt.to_string());
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .args(["render", "teapot", "--renderer", "opengl", "--shadows", "none", "--width", &ws, "--height", &hs, "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let cli = image::open(&out).unwrap().into_rgb32f();
    assert_eq!(cli.dimensions(), (w, hgt));
    let differ = cli
        .pixels()
        .zip(&img)
        .filter(|(c, v)| (0..3).any(|i| (c.0[i] - v[i]).abs() > 1e-3 * v[i].abs().max(c.0[i].abs()) + 1e-6))
        .count();
    assert_eq!(differ, 0, "{differ} pixels differ between the viewer and the CLI");
    std::fs::remove_dir_all(&dir).ok();

    // Click the middle of the image: the inspector shows GL's readback.
    let rect = h.state().viewport_rect().unwrap();
    let (x, y) = (w / 2, hgt / 2 + 5);
    let pos = rect.min + egui::vec2(x as f32 + 0.5, y as f32 + 0.5) * (rect.width() / w as f32);
    click(&mut h, pos);
    assert_eq!(h.state().inspect().selected, Some((x, y)));
    h.step();
    assert!(h.state_mut().wait_inspector(WAIT), "the readback did not arrive");
    h.step();
    h.step();
    assert!(h.query_all_by_label_contains("GL readback, not a replay").next().is_some(), "the readback is labelled");
    assert!(h.query_all_by_label_contains("triangle").next().is_some(), "the primitive is named");
    // The context goes before the process exits, as the binary does it,
    // not in the C library's exit handlers while the driver's threads run.
    drop(h);
    pinhole::render::opengl::shutdown();
}
