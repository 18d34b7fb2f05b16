//! The viewer's Compare window driven like a user: open it, measure, see the
//! points plotted, click one and find the live view rendering it.

use eframe::egui;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pinhole::app::PinholeApp;
use std::time::{Duration, Instant};

#[path = "common/app.rs"]
mod app_common;
use app_common::{WAIT, new_harness, settle, small_scene};

/// Steps the UI until the sweep has finished.
fn wait_for_sweep(h: &mut Harness<'static, PinholeApp>) {
    let start = Instant::now();
    while !h.state().compare().progress.lock().unwrap().finished {
        assert!(start.elapsed() < WAIT, "the sweep did not finish");
        h.step();
        std::thread::sleep(Duration::from_millis(50));
    }
    h.step();
    h.step();
}

#[test]
fn the_compare_window_plots_every_configuration_and_a_click_applies_one() {
    let mut h = new_harness(small_scene("spheres"));
    settle(&mut h);
    h.get_by_label("Compare").click();
    h.step();
    h.step();
    assert!(h.state().compare().open, "the Compare button opens the window");
    {
        let lab = h.state_mut().compare_mut();
        lab.reference_spp = 16;
        lab.cache_dir = None;
    }
    h.get_by_label("Measure").click();
    h.step();
    wait_for_sweep(&mut h);
    let lab = h.state().compare();
    let points = lab.progress.lock().unwrap().points.clone();
    assert!(lab.progress.lock().unwrap().error.is_none());
    assert!(points.len() >= 12, "{} configurations", points.len());
    assert!(lab.progress.lock().unwrap().reference.as_deref().unwrap().contains("path tracing"));

    // A point with no other marker near it on screen, and not the live view's configuration.
    let transform = lab.last_transform.expect("the plot was drawn");
    let metric = lab.metric;
    let screen = |m: &pinhole::chart::Measurement| {
        transform.position_from_point(&egui_plot::PlotPoint::new(m.ms.max(1e-3).log10(), metric.of(m).max(1e-6).log10()))
    };
    let current = h.state().settings().clone();
    let (target, pos) = points
        .iter()
        .filter(|(c, _)| c.renderer != current.renderer || c.settings.spp != current.render.spp || c.settings.gi != current.render.gi)
        .map(|(c, m)| (c.clone(), screen(m)))
        .find(|(_, p)| points.iter().filter(|(_, m)| screen(m).distance(*p) < 25.0).count() == 1)
        .expect("an isolated point");
    h.hover_at(pos);
    h.step();
    h.event(egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed: true, modifiers: egui::Modifiers::NONE });
    h.step();
    h.event(egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed: false, modifiers: egui::Modifiers::NONE });
    h.step();
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.settings().renderer, target.renderer, "clicking {} applies its renderer", target.label);
    let applied = app.effective_settings();
    assert_eq!(pinhole::chart::describe(&app.settings().renderer, &applied), target.label);
    assert_eq!((applied.spp, applied.gi.clone(), applied.shadows), (target.settings.spp, target.settings.gi.clone(), target.settings.shadows));
}

#[test]
fn closing_the_window_cancels_a_sweep() {
    let mut h = new_harness(small_scene("cornell-gi"));
    settle(&mut h);
    h.key_press(egui::Key::C);
    h.step();
    assert!(h.state().compare().open, "C opens the Compare window");
    h.state_mut().compare_mut().cache_dir = None;
    h.get_by_label("Measure").click();
    h.step();
    assert!(h.state().compare().running());
    h.key_press(egui::Key::C);
    h.step();
    assert!(!h.state().compare().open);
    wait_for_sweep(&mut h);
    let p = h.state().compare().progress.lock().unwrap();
    assert_eq!(p.stage, "cancelled");
    assert!(p.points.len() < p.total.max(1), "the sweep stopped early");
}

/// What `render_frame` gives for `renderer` and `settings` on the app's scene as edited.
fn rendered(app: &PinholeApp, renderer: &str, settings: &pinhole::render::RenderSettings) -> Vec<pinhole::math::Radiance> {
    let mut scene = (*app.scene()).clone();
    app.params().apply(&mut scene);
    let prepared = pinhole::render::PreparedScene::new(scene);
    let r = pinhole::render::renderer_by_name(renderer).unwrap();
    pinhole::render::render_frame(r.as_ref(), &prepared, settings, &std::sync::atomic::AtomicBool::new(false), None).unwrap().pixels
}

fn press(h: &Harness<'static, PinholeApp>, pos: egui::Pos2, pressed: bool, modifiers: egui::Modifiers) {
    h.event(egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers });
}

fn drag(h: &mut Harness<'static, PinholeApp>, from: egui::Pos2, to: egui::Pos2, modifiers: egui::Modifiers) {
    h.event(egui::Event::ModifiersChanged(modifiers));
    h.hover_at(from);
    h.step();
    press(h, from, true, modifiers);
    h.step();
    for k in 1..=4 {
        h.hover_at(from + (to - from) * (k as f32 / 4.0));
        h.step();
    }
    press(h, to, false, modifiers);
    h.step();
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
}

#[test]
fn the_wipe_shows_two_renderers_and_measures_their_difference() {
    let mut h = new_harness(small_scene("spheres"));
    settle(&mut h);
    h.key_press(egui::Key::B);
    h.step();
    assert!(h.state().split().enabled, "B shows two configurations");
    // B: the rasterizer without shadows; A stays the ray tracer with shadow rays.
    {
        let app = h.state_mut();
        app.split_mut().b.renderer = "rasterize:fixed".into();
        app.split_mut().b.render.shadows = pinhole::render::ShadowMode::None;
    }
    settle(&mut h);
    let app = h.state();
    let (w, hgt) = app.image_size();
    let b_settings = app.split().b_settings(app.settings(), w, hgt);
    let (_, _, b_image) = app.split().b_linear().expect("B rendered");
    assert_eq!(b_image, rendered(app, "rasterize:fixed", &b_settings), "B is the rasterizer's image");
    let a_image = app.with_output(|o| o.linear.clone());
    assert_eq!(a_image, rendered(app, &app.settings().renderer, &app.effective_settings()), "A is the live view");
    let e = app.split().error.expect("the error of B against A");
    assert!(e.whole > 0.01 && e.differing > 100, "shadows differ: {e:?}");

    // The divider follows a drag and the camera does not orbit.
    let rect = app.viewport_rect().unwrap();
    let camera = app.params().camera.clone();
    let at_divider = egui::pos2(rect.min.x + 0.5 * rect.width(), rect.center().y);
    drag(&mut h, at_divider, egui::pos2(rect.min.x + 0.25 * rect.width(), rect.center().y), egui::Modifiers::NONE);
    assert!((h.state().split().divider - 0.25).abs() < 0.02, "divider at {}", h.state().split().divider);
    assert_eq!(h.state().params().camera, camera, "dragging the divider does not move the camera");

    // Alt+drag measures a rectangle.
    drag(&mut h, rect.min + rect.size() * 0.6, rect.min + rect.size() * 0.9, egui::Modifiers::ALT);
    settle(&mut h);
    let [x0, y0, x1, y1] = h.state().split().region.expect("a region");
    assert!(x1 > x0 + 10 && y1 > y0 + 10, "{:?}", (x0, y0, x1, y1));
    assert!(h.state().split().error.unwrap().region.is_some());
    assert_eq!(h.state().params().camera, camera);
    region_statistics_are_numpys(&h, [x0, y0, x1, y1]);

    // X swaps A and B.
    h.key_press(egui::Key::X);
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.settings().renderer, "rasterize:fixed");
    assert_eq!(app.settings().render.shadows, pinhole::render::ShadowMode::None);
    assert_eq!(app.split().b.render.shadows, pinhole::render::ShadowMode::Ray);
    assert_eq!(app.with_output(|o| o.linear.clone()), b_image, "A now shows what B showed");

    // The difference view and closing.
    h.state_mut().split_mut().mode = pinhole::app::split_view::SplitMode::Difference;
    settle(&mut h);
    assert!(h.state().split().diff_texture.is_some());
    h.key_press(egui::Key::B);
    h.step();
    assert!(!h.state().split().enabled);
}

/// Sub-sampling in the viewer: the live view shows the sub-sampled frame
/// the command line renders (interpolated between the traced grid), not
/// the full one, and the status counts only the rays traced.
#[test]
fn the_viewer_shows_a_sub_sampled_frame() {
    let mut h = new_harness(small_scene("spheres"));
    settle(&mut h);
    let full = h.state().with_output(|o| o.linear.clone());
    h.state_mut().settings_mut().render.subsample = pinhole::render::frame::Subsample { step: 4, contrast: None };
    settle(&mut h);
    let app = h.state();
    let settings = app.effective_settings();
    assert_eq!(settings.subsample.step, 4);
    let shown = app.with_output(|o| o.linear.clone());
    assert_eq!(shown, rendered(app, &app.settings().renderer, &settings), "the live view is the sub-sampled frame");
    assert_ne!(shown, full, "interpolated pixels differ from traced ones somewhere");
    let (w, hgt) = app.image_size();
    let grid = |n: u32| n.div_ceil(4) + u32::from((n - 1) % 4 != 0);
    assert_eq!(app.with_output(|o| o.stats.counts.primary), (grid(w) * grid(hgt)) as u64, "{w}x{hgt}: one ray per grid pixel");
}

/// The dragged region's statistics equal numpy-style statistics (mean,
/// population std, median of the sorted values, min, max) computed here
/// from A's linear pixels in the same rectangle, and the bar shows them.
fn region_statistics_are_numpys(h: &Harness<'static, PinholeApp>, region: [u32; 4]) {
    let app = h.state();
    let stats = app.split().region_stats.expect("statistics of the dragged region");
    assert_eq!(stats.region, region);
    let [x0, y0, x1, y1] = region;
    let (w, _) = app.image_size();
    let a = app.with_output(|o| o.linear.clone());
    assert_eq!(stats.pixels, ((x1 - x0) * (y1 - y0)) as u64);
    assert_eq!(stats.non_finite, 0, "a rendered frame has no non-finite values");
    for k in 0..3 {
        let mut v: Vec<f64> = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y))).map(|(x, y)| a[(y * w + x) as usize][k] as f64).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let std = (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt();
        v.sort_by(f64::total_cmp);
        let m = v.len() / 2;
        let median = if v.len() % 2 == 1 { v[m] } else { (v[m - 1] + v[m]) / 2.0 };
        let c = stats.channels[k].expect("finite values");
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-6);
        assert!(close(c.mean, mean) && close(c.std, std) && close(c.median, median), "channel {k}: {c:?} vs mean {mean} std {std} median {median}");
        assert_eq!((c.min as f64, c.max as f64), (v[0], v[v.len() - 1]), "channel {k}");
    }
    assert!(stats.channels[0].unwrap().max > stats.channels[0].unwrap().min, "the region is not flat");
    h.get_by_label(&pinhole::app::panels::split_bar::region_text(&stats));
}
