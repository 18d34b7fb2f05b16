//! MSAA: N coverage samples per pixel, one shade per pixel per
//! primitive. It must cut the edge error against the 64-sample image like
//! supersampling does, while shading about once per pixel and leaving pixels
//! covered by one primitive exactly as the 1-sample image has them.

mod common;
use common::*;
use pinhole::math::Radiance;
use pinhole::render::{render_frame, renderer_by_name, replay_pixel, PreparedScene, RenderSettings};
use std::sync::atomic::AtomicBool;

fn rmse(a: &[Radiance], b: &[Radiance]) -> f64 {
    let s: f64 = a.iter().zip(b).map(|(x, y)| (*x - *y).length_squared() as f64).sum();
    (s / (3 * a.len()) as f64).sqrt()
}

fn settings(name: &str) -> (PreparedScene, RenderSettings) {
    let scene = builtin(name);
    let mut s = RenderSettings::for_scene(&scene);
    s.width = 160;
    s.height = 100;
    (PreparedScene::new(scene), s)
}

/// Pixels on a silhouette or crease of the 1-sample image: some neighbour
/// differs by more than `jump` in some channel.
fn edge_pixels(img: &[Radiance], w: usize, h: usize, jump: f32) -> Vec<usize> {
    let mut out = Vec::new();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let c = img[x + y * w];
            let near = [(1, 0), (0, 1), (-1, 0), (0, -1)].iter().any(|&(dx, dy): &(i32, i32)| {
                let n = img[(x as i32 + dx) as usize + (y as i32 + dy) as usize * w];
                (n - c).abs().max_element() > jump
            });
            if near {
                out.push(x + y * w);
            }
        }
    }
    out
}

#[test]
fn msaa_cuts_edge_error_with_one_shade_per_pixel() {
    for name in ["teapot", "spheres"] {
        let (prepared, base) = settings(name);
        let (w, h) = (base.width as usize, base.height as usize);
        let r = renderer_by_name("rasterize").unwrap();
        let frame = |s: &RenderSettings| render_frame(r.as_ref(), &prepared, s, &AtomicBool::new(false), None).unwrap();
        let reference = frame(&RenderSettings { spp: 64, ..base.clone() }).pixels;
        let one = frame(&base);
        let mean = reference.iter().map(|c| c.max_element()).sum::<f32>() / reference.len() as f32;
        let edges = edge_pixels(&one.pixels, w, h, 0.5 * mean);
        let at = |img: &[Radiance]| edges.iter().map(|&i| img[i]).collect::<Vec<_>>();
        let edge_rmse = |img: &[Radiance]| rmse(&at(img), &at(&reference));
        let e1 = edge_rmse(&one.pixels);
        let mut errors = Vec::new();
        for msaa in [2, 4, 8] {
            let m = frame(&RenderSettings { msaa, ..base.clone() });
            let e = edge_rmse(&m.pixels);
            println!(
                "{name}: {} edge pixels; msaa {msaa} edge rmse {e:.5} (1 sample {e1:.5}), whole image {:.5} ({:.5}); fragments shaded {} (1 sample {})",
                edges.len(),
                rmse(&m.pixels, &reference),
                rmse(&one.pixels, &reference),
                m.counts.fragments_shaded,
                one.counts.fragments_shaded
            );
            errors.push(e);
            // One shade per pixel per primitive: far fewer than one per sample
            // (pixels on the teapot's many small triangles shade each one they meet).
            let shaded = m.counts.fragments_shaded as f64 / one.counts.fragments_shaded as f64;
            assert!(shaded < 2.0, "{name} msaa {msaa}: {shaded}x the 1-sample shading");
            assert_eq!(m.counts.primary, one.counts.primary);
        }
        assert!(edges.len() > 50, "{name}: {} edge pixels", edges.len());
        assert!(errors[1] < 0.8 * e1, "{name}: msaa 4 edge rmse {} vs 1 sample {e1}", errors[1]);
        assert!(errors[2] < errors[1] && errors[0] < e1, "{name}: {errors:?} vs {e1}");
        // Supersampling at 4 spp shades four times.
        let ss = frame(&RenderSettings { spp: 4, ..base.clone() });
        assert!(ss.counts.fragments_shaded as f64 > 3.5 * one.counts.fragments_shaded as f64);
    }
}

#[test]
fn pixels_inside_one_primitive_equal_the_one_sample_image() {
    let (prepared, base) = settings("teapot");
    let msaa = RenderSettings { msaa: 4, ..base.clone() };
    let one = render("rasterize", &prepared, &base);
    let four = render("rasterize", &prepared, &msaa);
    let r = renderer_by_name("rasterize").unwrap();
    let (mut interior, mut edge, mut edge_differs) = (0, 0, 0);
    for y in (0..base.height).step_by(3) {
        for x in (0..base.width).step_by(3) {
            // What each sample sees, from the pixel's history: the last
            // fragment that passed its depth test at that sample (None = the
            // shading sample at the centre).
            let replay = replay_pixel(r.as_ref(), &prepared, &msaa, x, y).unwrap();
            let t = &replay.samples[0].1;
            let seen: Vec<Option<u32>> = [None, Some(0), Some(1), Some(2), Some(3)]
                .iter()
                .map(|s| t.fragments.iter().filter(|f| f.sample == *s && f.passed_depth_test).last().map(|f| f.primitive))
                .collect();
            let i = (x + y * base.width) as usize;
            if seen.iter().all(|s| *s == seen[0]) {
                interior += 1;
                assert!(four[i] == one[i], "pixel ({x}, {y}) sees only {:?}: {} vs {}", seen[0], four[i], one[i]);
            } else {
                edge += 1;
                edge_differs += (four[i] != one[i]) as u32;
            }
        }
    }
    println!("{interior} interior pixels, {edge} edge pixels of which {edge_differs} differ");
    assert!(interior > 3 * edge && edge > 20, "{interior} interior, {edge} edge");
    assert!(edge_differs * 2 > edge, "most edge pixels are antialiased");
}
