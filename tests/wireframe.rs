//! `--view wireframe`: the shaded frame with every triangle edge drawn over
//! it, by the float DDA or the integer Bresenham (`--lines`), the same for
//! every renderer because the lines are drawn on the finished frame.

mod common;
use common::*;
use pinhole::math::Vec2;
use pinhole::render::inspect::debug::View;
use pinhole::render::inspect::wireframe::{line_mask, LineAlgorithm, LINE_COLOR};
use pinhole::render::{renderer_by_name, replay_pixel, PreparedScene, RenderSettings};

fn settings(scene: &pinhole::scene::Scene, lines: LineAlgorithm) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.width = 160;
    s.height = 100;
    s.view = View::Wireframe;
    s.lines = lines;
    s
}

#[test]
fn one_triangle_shows_its_three_edges_over_the_shaded_image() {
    let scene = builtin("one-triangle");
    let v = scene.triangles.at(0).v;
    let s = settings(&scene, LineAlgorithm::Float);
    let view = scene.camera.view(s.width, s.height);
    let prepared = PreparedScene::new(scene);
    for renderer in ["raytrace:bvh", "rasterize:fixed", "rasterize:painter"] {
        let img = render(renderer, &prepared, &s);
        let shaded = render(renderer, &prepared, &RenderSettings { view: View::Shaded, ..s.clone() });
        // Points along each edge, by hand from the projected vertices: the
        // pixel holding each (or a neighbour, for the rounding of the end
        // points) is line-coloured.
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (pa, _) = view.project(v[a]).unwrap();
            let (pb, _) = view.project(v[b]).unwrap();
            for k in 1..10 {
                let p: Vec2 = pa + (pb - pa) * (k as f32 / 10.0);
                let near_line = (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))).any(|(dx, dy)| {
                    let (x, y) = (p.x as i32 + dx, p.y as i32 + dy);
                    (0..s.width as i32).contains(&x) && (0..s.height as i32).contains(&y) && img[(x + y * s.width as i32) as usize] == LINE_COLOR
                });
                assert!(near_line, "{renderer}: edge {a}-{b} at {p}");
            }
        }
        // Off the lines the shaded image shows through unchanged; the
        // triangle's inside is not drawn over.
        let lines = img.iter().filter(|c| **c == LINE_COLOR).count();
        assert!(lines > 100 && lines < 1000, "{renderer}: {lines}");
        let changed = img.iter().zip(&shaded).filter(|(a, b)| a != b).count();
        assert!(changed <= lines, "{renderer}");
        assert!(img[(80 + 55 * 160) as usize] != LINE_COLOR);
    }
}

#[test]
fn float_and_integer_wireframes_agree_within_a_pixel_and_renderers_agree() {
    let scene = builtin("teapot");
    let view = scene.camera.view(160, 100);
    let f = line_mask(&scene, &view, LineAlgorithm::Float);
    let i = line_mask(&scene, &view, LineAlgorithm::Integer);
    let near = |m: &[bool], x: i32, y: i32| (-1..=1).any(|dy| (-1..=1).any(|dx| {
        let (a, b) = (x + dx, y + dy);
        (0..160).contains(&a) && (0..100).contains(&b) && m[(a + b * 160) as usize]
    }));
    for (m, other) in [(&f, &i), (&i, &f)] {
        for y in 0..100 {
            for x in 0..160 {
                if m[(x + y * 160) as usize] {
                    assert!(near(other, x, y), "({x}, {y})");
                }
            }
        }
    }
    let prepared = PreparedScene::new(scene);
    let s = settings(&prepared.scene, LineAlgorithm::Integer);
    let a = render("raytrace:bvh", &prepared, &s);
    let b = render("rasterize:tiled", &prepared, &s);
    for k in 0..a.len() {
        assert_eq!(a[k] == LINE_COLOR, i[k], "pixel {k}");
        assert_eq!(b[k] == LINE_COLOR, i[k], "pixel {k}");
    }
}

#[test]
fn replay_of_a_wireframe_pixel_equals_the_frame() {
    let scene = builtin("triangle-ground");
    let s = settings(&scene, LineAlgorithm::Float);
    let view = scene.camera.view(s.width, s.height);
    let mask = line_mask(&scene, &view, s.lines);
    let prepared = PreparedScene::new(scene);
    for name in ["raytrace:brute", "rasterize:fixed"] {
        let frame = render(name, &prepared, &s);
        let r = renderer_by_name(name).unwrap();
        let on = mask.iter().position(|m| *m).unwrap() as u32;
        for (x, y) in pixels(5, 20, s.width, s.height).into_iter().chain([(on % s.width, on / s.width)]) {
            let replay = replay_pixel(r.as_ref(), &prepared, &s, x, y).unwrap();
            assert!(replay.radiance == frame[(x + y * s.width) as usize], "{name} ({x}, {y})");
        }
    }
}
