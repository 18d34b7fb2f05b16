//! The nan view and `non_finite_samples`: a scene whose texture holds
//! infinite texels (made in memory: scene files refuse them) makes
//! non-finite samples wherever a lookup reads one. The frame marks exactly
//! the pixels whose replayed samples (traced one by one, apart from the
//! frame) include a non-finite value, and every renderer counts exactly
//! those samples, whether it marks them or zeroes them.

mod common;

use pinhole::math::Vec3;
use pinhole::render::inspect::debug::View;
use pinhole::render::{self, PreparedScene, RenderSettings};
use pinhole::scene::texture::Texture;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The test-pattern scene with its texture's texels infinite in a checker
/// of 8x8 blocks (so some pixels read infinity and others do not).
fn poisoned() -> PreparedScene {
    let mut scene = common::builtin("test-pattern");
    let material = scene.materials.iter_mut().find(|m| m.texture.is_some()).expect("the scene has a textured material");
    let t = material.texture.as_ref().unwrap();
    let (w, h) = (t.width(), t.levels[0].height);
    let mut texels = t.levels[0].texels.clone();
    for y in 0..h {
        for x in 0..w {
            if (x / 8 + y / 8) % 2 == 0 {
                texels[(y * w + x) as usize] = Vec3::splat(f32::INFINITY);
            }
        }
    }
    material.texture = Some(Arc::new(Texture::new(w, h, texels)));
    PreparedScene::new(scene)
}

fn settings(prepared: &PreparedScene, spp: u32, view: View) -> RenderSettings {
    RenderSettings { width: 40, height: 30, spp, view, ..RenderSettings::for_scene(&prepared.scene) }
}

/// Per pixel, how many of its replayed samples are not finite.
fn replayed_non_finite(prepared: &PreparedScene, s: &RenderSettings) -> Vec<u32> {
    let renderer = render::renderer_by_name("raytrace").unwrap();
    let shaded = RenderSettings { view: View::Shaded, ..s.clone() };
    let mut out = Vec::new();
    for y in 0..s.height {
        for x in 0..s.width {
            let replay = render::replay_pixel(renderer.as_ref(), prepared, &shaded, x, y).unwrap();
            out.push(replay.samples.iter().filter(|(_, _, v)| !v.is_finite()).count() as u32);
        }
    }
    out
}

#[test]
fn the_nan_view_marks_exactly_the_pixels_that_took_a_non_finite_sample() {
    let prepared = poisoned();
    for spp in [1, 4] {
        let s = settings(&prepared, spp, View::Nan);
        let truth = replayed_non_finite(&prepared, &s);
        let expected: u64 = truth.iter().map(|&n| n as u64).sum();
        let marked_pixels = truth.iter().filter(|&&n| n > 0).count();
        assert!(marked_pixels > 20 && marked_pixels < truth.len() - 20, "spp {spp}: the checker leaves some pixels finite: {marked_pixels}");
        let r = render::renderer_by_name("raytrace").unwrap();
        let frame = render::render_frame(r.as_ref(), &prepared, &s, &AtomicBool::new(false), None).unwrap();
        for (i, (p, &n)) in frame.pixels.iter().zip(&truth).enumerate() {
            assert_eq!(*p == render::frame::NAN_MARK, n > 0, "spp {spp}: pixel {i} ({p}) with {n} non-finite samples");
            assert!(p.is_finite());
        }
        assert_eq!(frame.counts.non_finite, expected, "spp {spp}");
        // The replay of a marked pixel in the nan view shows the mark.
        let at = truth.iter().position(|&n| n > 0).unwrap() as u32;
        let replay = render::replay_pixel(r.as_ref(), &prepared, &s, at % s.width, at / s.width).unwrap();
        assert_eq!(replay.radiance, render::frame::NAN_MARK);
    }
}

#[test]
fn every_renderer_counts_the_non_finite_samples_it_zeroes() {
    let prepared = poisoned();
    let cancel = AtomicBool::new(false);
    for spp in [1, 3] {
        let s = settings(&prepared, spp, View::Shaded);
        let expected: u64 = replayed_non_finite(&prepared, &s).iter().map(|&n| n as u64).sum();
        assert!(expected > 0);
        for name in ["raytrace", "raytrace:brute"] {
            let r = render::renderer_by_name(name).unwrap();
            let frame = render::render_frame(r.as_ref(), &prepared, &s, &cancel, None).unwrap();
            assert_eq!(frame.counts.non_finite, expected, "{name}, spp {spp}");
            assert!(frame.pixels.iter().all(|p| p.is_finite()));
            // Band by band (no chunks) the count is the same.
            let banded = render::render_frame_with(r.as_ref(), &prepared, &s, &cancel, render::FrameOptions { bands: 3, ..Default::default() }).unwrap();
            assert_eq!(banded.counts.non_finite, expected, "{name}, spp {spp}, in bands");
        }
        // The rasterizers see the same surfaces at the pixel centres but
        // may differ at edges: they count what they zero, and the nan view
        // marks as many pixels as it counts with one sample.
        for name in ["rasterize", "rasterize:naive"] {
            let r = render::renderer_by_name(name).unwrap();
            let shaded = render::render_frame(r.as_ref(), &prepared, &s, &cancel, None).unwrap();
            let nan = render::render_frame(r.as_ref(), &prepared, &RenderSettings { view: View::Nan, ..s.clone() }, &cancel, None).unwrap();
            assert!(shaded.counts.non_finite > 0, "{name}");
            assert_eq!(shaded.counts.non_finite, nan.counts.non_finite, "{name}, spp {spp}");
            let marked = nan.pixels.iter().filter(|p| **p == render::frame::NAN_MARK).count() as u64;
            if spp == 1 {
                assert_eq!(marked, nan.counts.non_finite, "{name}");
            }
            assert!(((expected as f64) - shaded.counts.non_finite as f64).abs() <= 0.1 * expected as f64, "{name}: {} against {expected}", shaded.counts.non_finite);
        }
    }
}

#[test]
fn a_finite_scene_counts_no_non_finite_samples_and_marks_nothing() {
    let prepared = PreparedScene::new(common::builtin("test-pattern"));
    let s = settings(&prepared, 1, View::Nan);
    let r = render::renderer_by_name("raytrace").unwrap();
    let frame = render::render_frame(r.as_ref(), &prepared, &s, &AtomicBool::new(false), None).unwrap();
    assert_eq!(frame.counts.non_finite, 0);
    assert!(frame.pixels.iter().all(|p| *p != render::frame::NAN_MARK));
    // The rest is the shaded image's luminance, dimmed: not all black.
    assert!(frame.pixels.iter().any(|p| p.x > 0.0 && p.x <= render::frame::NAN_DIM && p.x == p.y));
}

#[test]
fn statistics_report_non_finite_samples() {
    let dir = std::env::temp_dir().join(format!("pinhole-nan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (png, stats) = (dir.join("n.png"), dir.join("n.json"));
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .args(["render", "test-pattern", "-o", png.to_str().unwrap(), "--width", "32", "--height", "24", "--view", "nan", "--stats", stats.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(j["non_finite_samples"], 0);
    assert_eq!(j["view"], "nan");
}
