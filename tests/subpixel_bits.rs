//! `--subpixel-bits`: the grid the fixed-point rasterizers snap vertices
//! to. At the full 8 bits the image is the one they always drew; with
//! fewer, edges move by up to half a coarse step and the silhouettes drift
//! from the ray caster's.

mod common;
use common::*;
use pinhole::math::Radiance;
use pinhole::render::{PreparedScene, RenderSettings};

fn wrong_pixels(a: &[Radiance], b: &[Radiance]) -> usize {
    a.iter().zip(b).filter(|(p, q)| (**p - **q).abs().max_element() > 1e-3 * (1.0 + q.max_element())).count()
}

#[test]
fn fewer_sub_pixel_bits_move_the_edges_and_eight_change_nothing() {
    let scene = builtin("teapot");
    let mut s = RenderSettings::for_scene(&scene);
    (s.width, s.height) = (160, 100);
    let prepared = PreparedScene::new(scene);
    let truth = render("raytrace:brute", &prepared, &s);
    for renderer in ["rasterize:fixed", "rasterize:tiled"] {
        let default = render(renderer, &prepared, &s);
        let at = |bits| render(renderer, &prepared, &RenderSettings { subpixel_bits: bits, ..s.clone() });
        assert!(at(8) == default, "{renderer}: 8 bits is not the default grid");
        let wrong: Vec<usize> = [8, 4, 2, 0].iter().map(|&b| wrong_pixels(&at(b), &truth)).collect();
        println!("{renderer}: wrong pixels at 8, 4, 2, 0 bits: {wrong:?}");
        assert!(wrong[0] <= 10, "{renderer}: {wrong:?}");
        assert!(wrong[3] > wrong[2] && wrong[2] > wrong[0] && wrong[3] > 100, "{renderer}: {wrong:?}");
    }
}
