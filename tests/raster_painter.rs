//! The painter's algorithm (`rasterize:painter`): no depth buffer, the
//! primitives drawn back to front. It must equal `rasterize:fixed` bit for
//! bit where a correct back-to-front order exists, and be wrong - against
//! `raytrace:brute`, while `fixed` is right - where none does: cyclic
//! overlaps and interpenetrating primitives (stress-painter, and the red
//! sphere half sunk into the ground of `spheres`).

mod common;
use common::*;
use pinhole::math::{Radiance, Vec2};
use pinhole::render::raster::fixed::snap_triangles;
use pinhole::render::raster::painter::{draw_order, OrderStats, Paint};
use pinhole::render::raster::setup::setup_pass;
use pinhole::render::raster::sphere::all_sphere_bounds;
use pinhole::render::{renderer_by_name, replay_pixel, PassJob, PreparedScene, RenderSettings};
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn small(scene: &pinhole::scene::Scene) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.width = 160;
    s.height = 100;
    s
}

/// Pixels whose colours differ by more than rounding could explain.
fn wrong_pixels(a: &[Radiance], b: &[Radiance]) -> usize {
    a.iter().zip(b).filter(|(p, q)| (**p - **q).abs().max_element() > 1e-3 * (1.0 + q.max_element())).count()
}

/// The painter's order for the pass at the pixel centres, and how it went.
fn order_of(prepared: &PreparedScene, settings: &RenderSettings) -> (Vec<Paint>, OrderStats) {
    let view = prepared.scene.camera.view(settings.width, settings.height);
    let cancel = AtomicBool::new(false);
    let off = Vec2::splat(0.5);
    let job = PassJob { prepared, view: &view, settings, offset: off, sample: 0, photons: None, active: None, rows: 0..settings.height, cancel: &cancel, keep_non_finite: false };
    let fts = snap_triangles(&setup_pass(&job), off, settings.width, settings.height);
    let spheres = all_sphere_bounds(&view, &prepared.scene.spheres, off);
    draw_order(&job, &fts, &spheres)
}

#[test]
fn painter_equals_fixed_where_a_back_to_front_order_exists() {
    // one-triangle: one triangle. triangle-ground: the triangle stands in
    // front of the ground and touches it at one vertex only. test-pattern and
    // cornell-gi: closed boxes and blocks whose faces meet only at edges (a
    // few pairs straddle each other's planes, but where they share samples
    // the key order is right). Not here: spheres and teapot, whose parts
    // interpenetrate (the red sphere sinks into the ground sphere, the
    // spout and handle into the body), and bunny, whose 69k triangles spend
    // the test budget (it matches at this size, but not at 800x500).
    for name in ["one-triangle", "triangle-ground", "test-pattern", "cornell-gi"] {
        let scene = builtin(name);
        let base = small(&scene);
        let prepared = PreparedScene::new(scene);
        let (_, stats) = order_of(&prepared, &base);
        assert!(!stats.budget_spent, "{name}: {stats:?}");
        if name == "one-triangle" || name == "triangle-ground" {
            assert_eq!(stats.unresolved, 0, "{name}: {stats:?}");
        }
        let cases = [base.clone(), RenderSettings { early_depth: false, ..base.clone() }, RenderSettings { spp: 4, ..base.clone() }, RenderSettings { msaa: 4, ..base.clone() }];
        for s in cases {
            let fixed = render("rasterize:fixed", &prepared, &s);
            let painter = render("rasterize:painter", &prepared, &s);
            let differ = fixed.iter().zip(&painter).filter(|(a, b)| a.to_array().map(f32::to_bits) != b.to_array().map(f32::to_bits)).count();
            assert_eq!(differ, 0, "{name} spp {} msaa {} early {}: painter differs from fixed", s.spp, s.msaa, s.early_depth);
        }
    }
}

#[test]
fn painter_is_wrong_where_no_order_exists_and_fixed_is_right() {
    let scene = builtin("stress-painter");
    let s = small(&scene);
    let prepared = PreparedScene::new(scene);
    let truth = render("raytrace:brute", &prepared, &s);
    let fixed = render("rasterize:fixed", &prepared, &s);
    let painter = render("rasterize:painter", &prepared, &s);
    let (wrong_fixed, wrong_painter) = (wrong_pixels(&fixed, &truth), wrong_pixels(&painter, &truth));
    println!("stress-painter 160x100: fixed {wrong_fixed} wrong pixels, painter {wrong_painter}");
    assert_eq!(wrong_fixed, 0);
    // One crossing of the cycle and half of the interpenetrating pair: hundreds.
    assert!(wrong_painter > 500, "{wrong_painter}");
    // The order found the problem pairs and could not order them.
    let (order, stats) = order_of(&prepared, &s);
    assert_eq!(order.len(), 5);
    assert!(stats.unresolved >= 2, "{stats:?}");

    // spheres: the red sphere's lower half lies inside the yellow ground
    // sphere. The painter draws the ground first (it reaches farthest), then
    // the whole red sphere over it.
    let scene = builtin("spheres");
    let s = small(&scene);
    let prepared = PreparedScene::new(scene);
    let fixed = render("rasterize:fixed", &prepared, &s);
    let painter = render("rasterize:painter", &prepared, &s);
    let truth = render("raytrace:brute", &prepared, &s);
    assert_eq!(wrong_pixels(&fixed, &truth), 0);
    let wrong = wrong_pixels(&painter, &truth);
    assert!(wrong > 50, "{wrong}");
    assert!(order_of(&prepared, &s).1.unresolved >= 1);
}

#[test]
fn newell_tests_fix_what_the_farthest_vertex_orders_wrongly() {
    // A triangle leaning back from depth 2 to depth 20 (the key puts it
    // first: farthest vertex 20) in front of a small upright triangle at
    // depth 5 (key 5, drawn second by the key: over the leaning one, wrong).
    // The small one lies entirely behind the leaning one's plane: the tests
    // move it ahead.
    let toml = r#"
[camera]
eye = [0.0, 0.0, 0.0]
target = [0.0, 0.0, -1.0]
fov_y_deg = 90.0
[render]
width = 100
height = 100
background = [0.0, 0.0, 0.0]
[[light]]
type = "point"
position = [0.0, 0.0, 0.0]
power = [10.0, 10.0, 10.0]
[materials.a]
lambertian = [0.8, 0.1, 0.1]
[materials.b]
lambertian = [0.1, 0.1, 0.8]
[[object]]
type = "triangle"
vertices = [[-1.0, -1.0, -2.0], [1.0, -1.0, -2.0], [0.0, 3.0, -20.0]]
material = "a"
[[object]]
type = "triangle"
vertices = [[-0.5, -2.0, -5.0], [0.5, -2.0, -5.0], [0.0, -1.0, -5.0]]
material = "b"
"#;
    let scene = pinhole::scene::file::parse_scene(toml, "test scene", Path::new("."), "lean").unwrap();
    let s = RenderSettings::for_scene(&scene);
    let prepared = PreparedScene::new(scene);
    let (order, stats) = order_of(&prepared, &s);
    assert_eq!(order, vec![Paint::Triangle(1), Paint::Triangle(0)], "{stats:?}");
    assert_eq!((stats.moves, stats.unresolved), (1, 0));
    let fixed = render("rasterize:fixed", &prepared, &s);
    let painter = render("rasterize:painter", &prepared, &s);
    assert!(fixed == painter);
    // The small triangle is hidden: nothing blue shows.
    assert!(painter.iter().all(|c| !(c.z > 2.0 * c.x)));
}

#[test]
fn replay_shows_the_overwrites_in_draw_order() {
    // triangle-ground pixel (300, 300) at 800x500: the ground triangle
    // (primitive 3) is drawn first, then the green triangle (0) over it, no
    // test failing; the frame shows the last one.
    let scene = builtin("triangle-ground");
    let settings = RenderSettings::for_scene(&scene);
    let prepared = PreparedScene::new(scene);
    let r = renderer_by_name("rasterize:painter").unwrap();
    let frame = render("rasterize:painter", &prepared, &settings);
    for early_depth in [true, false] {
        let s = RenderSettings { early_depth, ..settings.clone() };
        let replay = replay_pixel(r.as_ref(), &prepared, &s, 300, 300).unwrap();
        let t = &replay.samples[0].1;
        let order: Vec<_> = t.fragments.iter().map(|f| (f.primitive, f.passed_depth_test)).collect();
        assert_eq!(order, vec![(3, true), (0, true)], "{:?}", t.fragments);
        // The triangle was drawn over the ground, which lies deeper.
        assert!(t.fragments[1].depth < t.fragments[1].stored_depth);
        assert!(replay.radiance == frame[(300 + 300 * settings.width) as usize]);
        assert!(replay.radiance.y > 10.0 * replay.radiance.x, "green");
    }
}

#[test]
fn replays_equal_frames_on_the_stress_scene() {
    let scene = builtin("stress-painter");
    let base = small(&scene);
    let prepared = PreparedScene::new(scene);
    let r = renderer_by_name("rasterize:painter").unwrap();
    for s in [base.clone(), RenderSettings { spp: 4, ..base.clone() }, RenderSettings { msaa: 4, ..base.clone() }, RenderSettings { early_depth: false, ..base.clone() }] {
        let frame = render("rasterize:painter", &prepared, &s);
        for (x, y) in pixels(17, 40, s.width, s.height).into_iter().chain([(40, 45), (50, 50), (120, 55)]) {
            let replay = replay_pixel(r.as_ref(), &prepared, &s, x, y).unwrap();
            assert!(replay.radiance == frame[(x + y * s.width) as usize], "pixel ({x}, {y}) spp {} msaa {}", s.spp, s.msaa);
            assert!(replay.samples.iter().all(|(_, t, _)| t.fragments.iter().all(|f| f.passed_depth_test)));
        }
    }
}

#[test]
fn thread_count_and_row_bands_do_not_change_the_painter() {
    let scene = builtin("stress-painter");
    let s = small(&scene);
    let prepared = PreparedScene::new(scene);
    let one = render_with_threads(1, "rasterize:painter", &prepared, &s);
    let two = render_with_threads(2, "rasterize:painter", &prepared, &s);
    assert!(one == two);
    // Rendered in bands of 7 rows (as the viewer does): the same frame.
    let r = renderer_by_name("rasterize:painter").unwrap();
    let banded = pinhole::render::render_frame_with(r.as_ref(), &prepared, &s, &AtomicBool::new(false), pinhole::render::FrameOptions { bands: 14, ..Default::default() }).unwrap();
    assert!(banded.pixels == one);
}
