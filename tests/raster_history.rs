//! The rasterizers' pixel history and cost view: replaying a pixel
//! runs the pass's own coverage loops with a recorder, so the record lists the
//! fragments in draw order with their depth tests and ends in the frame's
//! value, whatever the variant, shading mode, MSAA or view; the cost view
//! counts the work the rasterizer did at each pixel.

mod common;
use common::*;
use pinhole::math::{Radiance, Vec3};
use pinhole::render::inspect::debug::View;
use pinhole::render::raster::Method;
use pinhole::render::inspect::pixel_record::FragmentRecord;
use pinhole::render::{renderer_by_name, replay_pixel, PreparedScene, RenderSettings};
use pinhole::scene::PrimitiveKind;

fn small(scene: &pinhole::scene::Scene) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.width = 160;
    s.height = 100;
    s
}


fn summary(f: &[FragmentRecord]) -> Vec<(u32, bool)> {
    f.iter().map(|f| (f.primitive, f.passed_depth_test)).collect()
}

#[test]
fn triangle_over_ground_history() {
    // Pixel (300, 300) of triangle-ground (800x500) sees the green triangle
    // (object 0, triangle 0, in the plane z = -2) in front of the ground
    // (triangles 2 and 3 at y = -1). Triangle 1 is the green triangle's back
    // side (same vertices, opposite winding): culled, so never a fragment.
    let scene = builtin("triangle-ground");
    let settings = RenderSettings::for_scene(&scene);
    let prepared = PreparedScene::new(scene);
    let far = prepared.scene.camera.far;
    // The painter draws the ground first and has no depth test: tests/raster_painter.rs.
    for m in Method::ALL.into_iter().filter(|m| *m != Method::Painter) {
        for early_depth in [true, false] {
            let settings = RenderSettings { early_depth, ..settings.clone() };
            let r = renderer_by_name(m.name()).unwrap();
            let replay = replay_pixel(r.as_ref(), &prepared, &settings, 300, 300).unwrap();
            let (_, t, value) = &replay.samples[0];
            let what = format!("{} early_depth {early_depth}", m.name());
            // Draw order: the triangle passes against the cleared buffer (the far
            // plane), then the ground fails against the triangle's depth.
            assert_eq!(summary(&t.fragments), vec![(0, true), (3, false)], "{what}: {:?}", t.fragments);
            let (tri, ground) = (&t.fragments[0], &t.fragments[1]);
            assert!(t.fragments.iter().all(|f| f.kind == PrimitiveKind::Triangle && f.sample.is_none()));
            assert!((tri.stored_depth - far).abs() < 1e-3 * far, "{what}: {tri:?}");
            assert!((tri.depth - 2.0).abs() < 1e-4, "{what}: the triangle lies at view depth 2: {tri:?}");
            assert_eq!(ground.stored_depth, tri.depth, "{what}");
            assert!(ground.depth > 2.0, "{what}: {ground:?}");
            // Perspective-correct weights sum to one; on the z = -2 plane they
            // equal the 2D weights, on the slanted ground they do not.
            for f in &t.fragments {
                assert!((f.barycentric.x + f.barycentric.y + f.barycentric.z - 1.0).abs() < 1e-5);
            }
            if let (Some(s0), Some(s3)) = (tri.screen_barycentric, ground.screen_barycentric) {
                assert!((s0 - tri.barycentric).length() < 1e-4, "{what}");
                assert!((s3 - ground.barycentric).length() > 1e-2, "{what}");
            } else {
                assert!(matches!(m, Method::Naive | Method::BBox), "{what}: 2D weights missing");
            }
            // The triangle is shaded when it arrives in forward mode only; the
            // ground, which fails, never.
            assert_eq!(tri.shaded, (!early_depth).then_some(*value), "{what}");
            assert_eq!(ground.shaded, None);
            // The eye ray ends on the triangle; one light, its shadow ray clear.
            let hit = t.rays[0].closest.expect("the eye ray's surface");
            assert_eq!((hit.primitive, hit.object), (0, 0), "{what}");
            assert_eq!(t.lights.len(), 1, "{what}");
            assert!(t.lights[0].blocker.is_none() && t.lights[0].shadow_ray.is_some());
            assert!((t.lights[0].contribution - *value).length() < 1e-7, "{what}");
            assert!(value.y > 10.0 * value.x, "{what}: green");
        }
    }
}

#[test]
fn history_of_a_ground_pixel_in_the_triangles_shadow() {
    // Lower right of triangle-ground: only the ground covers; the light's shadow
    // ray is blocked by the triangle (its back side, triangle 1, can block it:
    // culling is for eye rays only).
    let scene = builtin("triangle-ground");
    let settings = RenderSettings::for_scene(&scene);
    let prepared = PreparedScene::new(scene);
    let r = renderer_by_name("rasterize").unwrap();
    let mut found = false;
    for (x, y) in (400..800).step_by(8).flat_map(|x| (380..500).step_by(8).map(move |y| (x, y))) {
        let replay = replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap();
        let t = &replay.samples[0].1;
        if t.fragments.len() == 1 && t.lights[0].blocker.is_some() {
            assert!(t.fragments[0].primitive >= 2 && t.fragments[0].passed_depth_test);
            assert_eq!(replay.radiance, Vec3::ZERO);
            found = true;
            break;
        }
    }
    assert!(found);
}

#[test]
fn replays_equal_frames_with_msaa_forward_and_cost() {
    // tests/pixel_replay.rs covers the defaults; here the other knobs.
    for scene_name in ["teapot", "spheres"] {
        let scene = builtin(scene_name);
        let base = small(&scene);
        let prepared = PreparedScene::new(scene);
        let mut cases = Vec::new();
        for msaa in [1, 2, 4, 8] {
            for spp in [1, 4] {
                cases.push(RenderSettings { msaa, spp, ..base.clone() });
            }
        }
        cases.push(RenderSettings { early_depth: false, ..base.clone() });
        cases.push(RenderSettings { early_depth: false, view: View::Cost, ..base.clone() });
        cases.push(RenderSettings { view: View::Cost, ..base.clone() });
        cases.push(RenderSettings { view: View::Cost, msaa: 4, ..base.clone() });
        cases.push(RenderSettings { view: View::Barycentric, msaa: 4, ..base.clone() });
        for (c, settings) in cases.iter().enumerate() {
            for m in [Method::Fixed, Method::Tiled, Method::Incremental, Method::Scanline, Method::BBox, Method::Painter] {
                let r = renderer_by_name(m.name()).unwrap();
                let frame = render(m.name(), &prepared, settings);
                for (x, y) in pixels(c as u64 * 31 + 7, 12, settings.width, settings.height) {
                    let replay = replay_pixel(r.as_ref(), &prepared, settings, x, y).unwrap();
                    let stored = frame[(x + y * settings.width) as usize];
                    assert!(
                        replay.radiance == stored,
                        "{} on {scene_name}, msaa {} spp {} early {} view {:?}, pixel ({x}, {y}): {} vs {}",
                        m.name(),
                        settings.msaa,
                        settings.spp,
                        settings.early_depth,
                        settings.view,
                        replay.radiance,
                        stored
                    );
                    if settings.msaa > 1 && settings.view == View::Shaded {
                        // Every coverage sample's fragments are in the record, tagged.
                        let t = &replay.samples[0].1;
                        let tagged = t.fragments.iter().filter_map(|f| f.sample).max();
                        if t.fragments.iter().any(|f| f.sample.is_some()) {
                            assert!(tagged.unwrap() < settings.msaa);
                        }
                    }
                }
            }
        }
    }
}

fn heat(c: Radiance) -> f32 {
    // cost_color's stops grow in r + g + b: a monotonic read-back of the cost.
    c.x + c.y + c.z
}

#[test]
fn cost_view_counts_the_rasterizers_work() {
    let scene = builtin("teapot");
    let settings = RenderSettings { view: View::Cost, ..small(&scene) };
    let prepared = PreparedScene::new(scene);
    let (w, h) = (settings.width, settings.height);
    let fixed = render("rasterize:fixed", &prepared, &settings);
    // Classify pixels by their fragment history: background (no fragment),
    // one fragment, overdraw (two or more fragments at the pixel).
    let r = renderer_by_name("rasterize:fixed").unwrap();
    let mut classes: [Vec<f32>; 3] = Default::default();
    for (x, y) in pixels(99, 600, w, h) {
        let replay = replay_pixel(r.as_ref(), &prepared, &RenderSettings { view: View::Shaded, ..settings.clone() }, x, y).unwrap();
        let n = replay.samples[0].1.fragments.len().min(2);
        classes[n].push(heat(fixed[(x + y * w) as usize]));
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
    let (bg, one, over) = (mean(&classes[0]), mean(&classes[1]), mean(&classes[2]));
    println!("heat: background {bg} ({}), one fragment {one} ({}), overdraw {over} ({})", classes[0].len(), classes[1].len(), classes[2].len());
    assert!(classes.iter().all(|c| c.len() >= 10), "{:?}", classes.iter().map(Vec::len).collect::<Vec<_>>());
    assert!(bg < one && one < over, "background {bg}, one fragment {one}, overdraw {over}");
    // Far from the teapot nothing is tested: black.
    assert_eq!(fixed[0], Vec3::ZERO);
    // The chapter's progression: naive tests every triangle at every pixel,
    // bbox only within boxes; fixed tests the same boxes without the ray test.
    let naive = render("rasterize:naive", &prepared, &settings);
    let bbox = render("rasterize:bbox", &prepared, &settings);
    let total = |img: &[Radiance]| img.iter().map(|&c| heat(c)).sum::<f32>();
    assert!(total(&naive) > 1.5 * total(&bbox), "naive {} vs bbox {}", total(&naive), total(&bbox));
    assert!(naive.iter().all(|&c| heat(c) > 0.0), "naive tests every pixel");
    // Forward shading does at least the work of early depth at every pixel.
    let forward = render("rasterize:fixed", &prepared, &RenderSettings { early_depth: false, ..settings.clone() });
    assert!(forward.iter().zip(&fixed).all(|(f, e)| heat(*f) >= heat(*e) - 1e-6));
}
