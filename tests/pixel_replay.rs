//! Click-a-pixel replay: the record of a pixel is made
//! by the renderer's own code path, so its final radiance equals the frame's
//! pixel exactly, for every renderer that can replay.

mod common;
use common::*;
use pinhole::render::{renderer_by_name, renderer_names, replay_pixel, PreparedScene, RenderSettings};


#[test]
fn replayed_radiance_equals_rendered_pixel() {
    let mut replayable = Vec::new();
    for scene_name in pinhole::scene::builtin::names() {
        let scene = builtin(scene_name);
        let mut settings = RenderSettings::for_scene(&scene);
        settings.width = 80;
        settings.height = 50;
        let prepared = PreparedScene::new(scene);
        for spp in [1, 4] {
            settings.spp = spp;
            for name in renderer_names() {
                let r = renderer_by_name(name).unwrap();
                let frame = render(name, &prepared, &settings);
                let mut checked = 0;
                for (x, y) in pixels(spp as u64 * 7919 + scene_name.len() as u64, 40, settings.width, settings.height) {
                    let Ok(replay) = replay_pixel(r.as_ref(), &prepared, &settings, x, y) else { break };
                    let stored = frame[(x + y * settings.width) as usize];
                    assert!(replay.radiance == stored, "{name} on {scene_name} spp {spp} pixel ({x}, {y}): replay {} vs frame {}", replay.radiance, stored);
                    checked += 1;
                }
                if checked > 0 && !replayable.contains(&name) {
                    replayable.push(name);
                }
            }
        }
    }
    println!("renderers that replay pixels: {replayable:?}");
    assert!(replayable.contains(&"raytrace:brute"));
}

#[test]
fn record_shows_the_hit_and_the_light() {
    // Pixel (300, 300) of triangle-ground sees the green triangle, lit.
    let scene = builtin("triangle-ground");
    let settings = RenderSettings::for_scene(&scene);
    let prepared = PreparedScene::new(scene);
    let r = renderer_by_name("raytrace:brute").unwrap();
    let replay = replay_pixel(r.as_ref(), &prepared, &settings, 300, 300).unwrap();
    let (_, trace, _) = &replay.samples[0];
    let eye = &trace.rays[0];
    assert_eq!(eye.depth, 0);
    assert_eq!(eye.tests.len(), 4, "brute force tests every triangle");
    let hit = eye.closest.expect("hits the triangle");
    assert_eq!((hit.object, hit.primitive), (0, 0));
    assert_eq!(trace.lights.len(), 1);
    let l = &trace.lights[0];
    assert!(l.blocker.is_none() && l.shadow_ray.is_some());
    assert!((l.contribution - replay.radiance).length() < 1e-7, "one light, no ambient: the contribution is the pixel");
    // A ground pixel in the triangle's shadow (lower right) records its blocker.
    let mut found = false;
    for (x, y) in (400..800).step_by(8).flat_map(|x| (380..500).step_by(8).map(move |y| (x, y))) {
        let replay = replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap();
        let t = &replay.samples[0].1;
        if t.rays[0].closest.is_some_and(|h| h.object >= 2) && t.lights[0].blocker.is_some() {
            found = true;
            assert_eq!(replay.radiance, pinhole::math::Vec3::ZERO);
            break;
        }
    }
    assert!(found, "some ground pixel in the lower right is in the triangle's shadow");
}
