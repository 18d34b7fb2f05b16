//! Visual debugging in the viewer, driven like a user with
//! egui_kittest: click a pixel and read its replayed record in the
//! inspector, move the selection with the arrow keys, switch debug views and
//! find their legends, zoom to pixel level, compare against the reference.

use eframe::egui;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pinhole::app::panels::inspector::final_radiance_text;
use pinhole::app::PinholeApp;
use pinhole::math::Radiance;
use pinhole::render::inspect::debug::View;
use pinhole::scene::Scene;

#[path = "common/app.rs"]
mod app_common;
use app_common::{new_harness, small_scene, WAIT};

fn harness(scene: Scene) -> Harness<'static, PinholeApp> {
    let mut h = new_harness(scene);
    settle(&mut h);
    h
}

/// Frames until the worker finished the image and the selection's replay,
/// and two more so the panels show both.
fn settle(h: &mut Harness<'static, PinholeApp>) {
    h.step();
    assert!(h.state_mut().wait_idle(WAIT), "the worker did not finish");
    assert!(h.state_mut().wait_inspector(WAIT), "the replay did not arrive");
    h.step();
    h.step();
}

fn pixel(app: &PinholeApp, x: u32, y: u32) -> Radiance {
    app.with_output(|o| {
        assert!(o.complete && o.error.is_none(), "frame not complete: {:?}", o.error);
        o.linear[(x + y * o.width) as usize]
    })
}

/// The screen position of the centre of image pixel (x, y).
fn pixel_pos(app: &PinholeApp, x: u32, y: u32) -> egui::Pos2 {
    let rect = app.viewport_rect().unwrap();
    let s = app.effective_settings();
    let scale = rect.width() / s.width as f32;
    rect.min + egui::vec2(x as f32 + 0.5, y as f32 + 0.5) * scale
}

fn click(h: &mut Harness<'static, PinholeApp>, pos: egui::Pos2) {
    h.hover_at(pos);
    h.step();
    h.drag_at(pos);
    h.step();
    h.drop_at(pos);
    h.step();
}

fn has_label(h: &Harness<'static, PinholeApp>, text: &str) -> bool {
    h.query_all_by_label_contains(text).next().is_some()
}

#[test]
fn clicking_a_pixel_shows_its_replayed_record() {
    let mut h = harness(small_scene("one-triangle"));
    let (x, y) = (80, 50);
    let pos = pixel_pos(h.state(), x, y);
    click(&mut h, pos);
    assert_eq!(h.state().inspect().selected, Some((x, y)));
    settle(&mut h);

    let app = h.state();
    let frame = pixel(app, x, y);
    let replayed = app.inspect().current(app.generation()).expect("a replay for the current frame");
    let record = replayed.result.as_ref().expect("the ray tracer replays pixels");
    assert_eq!(record.radiance, frame, "the replay's radiance is the frame's pixel, exactly");
    let (_, trace, _) = &record.samples[0];
    let hit = trace.rays[0].closest.expect("the eye ray hits the triangle");
    let object = app.scene().objects[hit.object as usize].name.clone();
    let light = trace.lights.first().expect("one light sample");
    let contribution = pinhole::app::inspect::fmt3(light.contribution);

    // The panel shows that record: the pixel, the eye ray, the hit object,
    // the light's contribution and the final radiance, equal to the frame's.
    assert!(has_label(&h, "Inspector"));
    assert!(has_label(&h, &format!("pixel ({x}, {y})")));
    assert!(has_label(&h, "eye ray"));
    assert!(has_label(&h, &format!("'{object}' (object {})", hit.object)), "hit object {object} not shown");
    assert!(has_label(&h, "contribution"));
    assert!(has_label(&h, &contribution), "light contribution {contribution} not shown");
    assert!(has_label(&h, &final_radiance_text(frame)), "final radiance not shown");
    assert!(has_label(&h, "= the frame's pixel, exactly"));
    assert!(has_label(&h, "displayed ["));
}

#[test]
fn arrow_keys_move_the_selection_and_escape_clears_it() {
    let mut h = harness(small_scene("one-triangle"));
    let pos = pixel_pos(h.state(), 80, 50);
    click(&mut h, pos);
    settle(&mut h);
    h.key_press(egui::Key::ArrowRight);
    h.step();
    h.key_press(egui::Key::ArrowDown);
    h.step();
    h.key_press(egui::Key::ArrowDown);
    settle(&mut h);
    assert_eq!(h.state().inspect().selected, Some((81, 52)));
    assert!(has_label(&h, "pixel (81, 52)"));
    let app = h.state();
    let r = app.inspect().current(app.generation()).unwrap().result.as_ref().unwrap();
    assert_eq!(r.radiance, pixel(app, 81, 52));
    assert!(has_label(&h, &final_radiance_text(r.radiance)));

    // Shift+arrow moves by 10, and the selection stays inside the image.
    h.key_press_modifiers(egui::Modifiers::SHIFT, egui::Key::ArrowLeft);
    h.step();
    assert_eq!(h.state().inspect().selected, Some((71, 52)));
    for _ in 0..20 {
        h.key_press_modifiers(egui::Modifiers::SHIFT, egui::Key::ArrowUp);
    }
    h.step();
    assert_eq!(h.state().inspect().selected, Some((71, 0)));

    h.key_press(egui::Key::Escape);
    h.step();
    h.step();
    assert_eq!(h.state().inspect().selected, None);
    assert!(!has_label(&h, "Inspector"), "the inspector closes with the selection");
}

#[test]
fn the_record_follows_the_renderer_and_rasterizers_show_their_history_or_why_not() {
    let mut h = harness(small_scene("triangle-ground"));
    let pos = pixel_pos(h.state(), 40, 90); // the ground, in the triangle's shadow or not
    click(&mut h, pos);
    settle(&mut h);
    for name in ["raytrace:brute", "rasterize"] {
        h.state_mut().settings_mut().renderer = pinhole::render::renderer_by_name(name).unwrap().name().to_string();
        settle(&mut h);
        let app = h.state();
        let replayed = app.inspect().current(app.generation()).expect("a replay for the new renderer");
        assert_eq!(replayed.renderer, app.settings().renderer);
        match &replayed.result {
            Ok(r) => {
                assert_eq!(r.radiance, pixel(app, 40, 90), "{name}: replay equals the frame");
                assert!(has_label(&h, &final_radiance_text(r.radiance)));
                if name.starts_with("raytrace") {
                    assert!(has_label(&h, "tests in order"), "brute force lists its primitive tests");
                } else if !r.samples[0].1.fragments.is_empty() {
                    assert!(has_label(&h, "fragment history"));
                }
            }
            Err(e) => assert!(has_label(&h, e), "{name}: the error is shown: {e}"),
        }
    }
}

#[test]
fn debug_views_show_their_legends() {
    let mut h = harness(small_scene("one-triangle"));
    assert!(!has_label(&h, "cost: work per pixel"), "no legend for the shaded view");
    // The top bar's combo lists every view.
    h.get_by_label("debug view").click();
    h.step();
    h.step();
    for v in View::ALL {
        assert!(h.query_by_label(v.name()).is_some(), "view {} missing from the combo", v.name());
    }
    h.get_by_label("cost").click();
    settle(&mut h);
    assert_eq!(h.state().settings().render.view, View::Cost);
    assert!(has_label(&h, "cost: work per pixel"));
    assert!(has_label(&h, "log scale up to 1024"));

    // V steps to the next view: diff, then shadowmap (or whatever follows cost).
    let next = View::ALL[(View::ALL.iter().position(|v| *v == View::Cost).unwrap() + 1) % View::ALL.len()];
    h.key_press(egui::Key::V);
    settle(&mut h);
    assert_eq!(h.state().settings().render.view, next);

    h.state_mut().settings_mut().render.view = View::Depth;
    settle(&mut h);
    assert!(has_label(&h, "depth: distance along the eye ray"));
    assert!(has_label(&h, "near = 0.100"), "near/far mapping shown");
    h.state_mut().settings_mut().render.view = View::Id;
    settle(&mut h);
    let name = h.state().scene().objects[0].name.clone();
    assert!(has_label(&h, &format!("0: {name}")), "id legend names the objects");
}

#[test]
fn hovering_and_the_selected_pixel_give_exact_cost_numbers() {
    let mut h = harness(small_scene("one-triangle"));
    h.state_mut().settings_mut().render.view = View::Cost;
    settle(&mut h);
    let pos = pixel_pos(h.state(), 80, 50);
    click(&mut h, pos);
    settle(&mut h);
    // The inspector opened beside the image, which moved: hover it again.
    let pos = pixel_pos(h.state(), 80, 50);
    h.hover_at(pos);
    settle(&mut h);
    let app = h.state();
    let r = app.inspect().current(app.generation()).unwrap().result.as_ref().unwrap();
    let eye = &r.samples[0].1.rays[0];
    let cost = eye.nodes_visited.len() + eye.tests.len() + eye.tests_omitted;
    assert!(has_label(&h, "cost (nodes + tests)"));
    // The legend reads the pixel under the cursor back from the heat scale.
    assert_eq!(app.inspect().hover, Some((80, 50)));
    assert!(has_label(&h, &format!("under the cursor: cost {cost}")), "cost {cost} under the cursor");
    assert_eq!(r.radiance, pixel(app, 80, 50));
}

#[test]
fn zooming_in_keeps_the_pixel_under_the_cursor_and_picks_pixels_exactly() {
    let mut h = harness(small_scene("one-triangle"));
    let before = h.state().viewport_rect().unwrap();
    let at = pixel_pos(h.state(), 30, 20);
    h.hover_at(at);
    h.step();
    h.event(egui::Event::Zoom(4.0));
    h.step();
    h.step();
    let app = h.state();
    let after = app.viewport_rect().unwrap();
    assert!((after.width() / before.width() - 4.0).abs() < 1e-3, "{before:?} -> {after:?}");
    // The image point under the cursor stays put (within a rounding pixel).
    let moved = pixel_pos(app, 30, 20) - at;
    assert!(moved.length() < 4.0 * 0.5 + 1.0, "pixel (30, 20) moved by {moved:?}");
    // A pixel is now 4 points wide: clicking picks exactly the one under the cursor.
    let p = pixel_pos(app, 33, 21) + egui::vec2(1.4, -1.4);
    click(&mut h, p);
    assert_eq!(h.state().inspect().selected, Some((33, 21)));
    // The fit button (or zoom 1) returns to the fitted image.
    h.get_by_label("fit").click();
    h.step();
    h.step();
    assert_eq!(h.state().inspect().zoom, 1.0);
    assert_eq!(h.state().viewport_rect().unwrap().size(), before.size());
}

#[test]
fn diff_view_counts_pixels_that_differ_from_brute_force() {
    let mut h = harness(small_scene("one-triangle"));
    h.state_mut().settings_mut().render.view = View::parse("diff").unwrap();
    settle(&mut h);
    // raytrace:bvh agrees with brute force: no differing pixel.
    assert_eq!(h.state().with_output(|o| o.differing_pixels), Some(0));
    assert!(has_label(&h, "differing pixels: 0"));
    // The diff image is what `render_frame` computes for the diff view.
    let app = h.state();
    let mut scene = (*app.scene()).clone();
    app.params().apply(&mut scene);
    let prepared = pinhole::render::PreparedScene::new(scene);
    let renderer = pinhole::render::renderer_by_name(&app.settings().renderer).unwrap();
    let f = pinhole::render::render_frame(renderer.as_ref(), &prepared, &app.effective_settings(), &Default::default(), None).unwrap();
    assert_eq!(app.with_output(|o| o.linear.clone()), f.pixels);
    assert_eq!(f.differing_pixels, Some(0));
}

#[test]
fn the_vertex_overlay_projects_each_distinct_vertex() {
    let mut h = harness(small_scene("triangle-ground"));
    h.get_by_label("vertices").click();
    h.step();
    h.step();
    let app = h.state();
    assert!(app.inspect().vertices);
    let (_, verts) = app.inspect().vertex_cache.as_ref().expect("vertices gathered");
    // Two coincident triangles and a two-triangle ground: 3 + 4 distinct corners.
    assert_eq!(verts.len(), 7);
}
