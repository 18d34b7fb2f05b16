//! The viewer's Compare window driven like a user: open it, measure, see the
//! points plotted, click one and find the live view rendering it.

use eframe::egui;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pinhole::app::PinholeApp;
use std::time::{Duration, Instant};

#[path = "common/app.rs"]
mod app_common;
use app_common::{new_harness, small_scene, WAIT};

fn settle(h: &mut Harness<'static, PinholeApp>) {
    h.step();
    assert!(h.state_mut().wait_idle(WAIT), "the worker did not finish");
    h.step();
    h.step();
}

/// Steps the UI until the sweep has finished.
fn wait_for_sweep(h: &mut Harness<'static, PinholeApp>) {
    let start = Instant::now();
    while !h.state().compare.progress.lock().unwrap().finished {
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
    assert!(h.state().compare.open, "the Compare button opens the window");
    {
        let lab = &mut h.state_mut().compare;
        lab.reference_spp = 16;
        lab.cache_dir = None;
    }
    h.get_by_label("Measure").click();
    h.step();
    wait_for_sweep(&mut h);
    let lab = &h.state().compare;
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
    let current = h.state().settings.clone();
    let (target, pos) = points
        .iter()
        .filter(|(c, _)| c.renderer != current.renderer || c.settings.spp != current.spp || c.settings.gi != current.gi)
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
    assert_eq!(app.settings.renderer, target.renderer, "clicking {} applies its renderer", target.label);
    let applied = app.effective_settings();
    assert_eq!(pinhole::chart::describe(&app.settings.renderer, &applied), target.label);
    assert_eq!((applied.spp, applied.gi.clone(), applied.shadows), (target.settings.spp, target.settings.gi.clone(), target.settings.shadows));
}

#[test]
fn closing_the_window_cancels_a_sweep() {
    let mut h = new_harness(small_scene("cornell-gi"));
    settle(&mut h);
    h.key_press(egui::Key::C);
    h.step();
    assert!(h.state().compare.open, "C opens the Compare window");
    h.state_mut().compare.cache_dir = None;
    h.get_by_label("Measure").click();
    h.step();
    assert!(h.state().compare.running());
    h.key_press(egui::Key::C);
    h.step();
    assert!(!h.state().compare.open);
    wait_for_sweep(&mut h);
    let p = h.state().compare.progress.lock().unwrap();
    assert_eq!(p.stage, "cancelled");
    assert!(p.points.len() < p.total.max(1), "the sweep stopped early");
}
