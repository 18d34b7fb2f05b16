//! Shading interpolation modes (flat, gouraud, phong) mean the same in the ray
//! tracer and the rasterizer, and each does what its name says.

mod common;
use common::*;
use pinhole::math::{Radiance, Vec3};
use pinhole::render::{Interpolation, PreparedScene, RenderSettings};

fn settings(scene: &pinhole::scene::Scene, mode: Interpolation) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.width = 160;
    s.height = 100;
    s.interpolation = mode;
    s
}

fn max_lum(img: &[Radiance]) -> f32 {
    img.iter().map(|c| pinhole::math::luminance(*c)).fold(0.0, f32::max)
}

#[test]
fn both_families_agree_in_every_mode() {
    for name in ["one-triangle", "teapot", "spheres"] {
        let scene = builtin(name);
        let prepared = PreparedScene::new(scene.clone());
        for mode in Interpolation::ALL {
            let s = settings(&scene, mode);
            let a = render("raytrace:brute", &prepared, &s);
            let b = render("rasterize", &prepared, &s);
            let same = a.iter().zip(&b).filter(|(x, y)| ((**x - **y).abs().max_element()) <= 1e-4 * x.max_element().max(y.max_element()) + 1e-7).count();
            let frac = same as f64 / a.len() as f64;
            assert!(frac >= 0.995, "{name} {mode:?}: only {:.2}% of pixels agree", 100.0 * frac);
        }
    }
}

#[test]
fn flat_uses_the_face_normal() {
    // Flat shading of the book's triangle equals Phong shading of the same
    // triangle with its vertex normals removed (so they default to the face normal).
    let scene = builtin("one-triangle");
    let mut plain = scene.clone();
    let n = plain.triangles.at(0).geometric_normal();
    plain.triangles.set(0, pinhole::scene::Triangle { n: [n; 3], ..plain.triangles.at(0) });
    let flat = render("raytrace:bvh", &PreparedScene::new(scene.clone()), &settings(&scene, Interpolation::Flat));
    let phong_plain = render("raytrace:bvh", &PreparedScene::new(plain), &settings(&scene, Interpolation::Phong));
    assert_eq!(flat, phong_plain);
    let phong = render("raytrace:bvh", &PreparedScene::new(scene.clone()), &settings(&scene, Interpolation::Phong));
    assert_ne!(flat, phong, "the leaning vertex normals must change the Phong image");
}

#[test]
fn gouraud_loses_the_interior_highlight_but_matches_at_vertices() {
    let scene = builtin("one-triangle");
    let prepared = PreparedScene::new(scene.clone());
    let s = settings(&scene, Interpolation::Gouraud);
    let gouraud = render("raytrace:bvh", &prepared, &s);
    let phong = render("raytrace:bvh", &prepared, &settings(&scene, Interpolation::Phong));
    // The highlight sits inside the triangle, away from every vertex.
    assert!(max_lum(&gouraud) < 0.8 * max_lum(&phong), "gouraud {} phong {}", max_lum(&gouraud), max_lum(&phong));
    // Next to a vertex both are the vertex's lighting.
    let view = scene.camera.view(s.width, s.height);
    let centroid = scene.triangles.at(0).v.iter().copied().sum::<Vec3>() / 3.0;
    for v in scene.triangles.at(0).v {
        let (p, _) = view.project(v).unwrap();
        let (c, _) = view.project(centroid).unwrap();
        let q = p + (c - p).normalize() * 2.0;
        let i = (q.x as u32 + q.y as u32 * s.width) as usize;
        let (g, ph) = (gouraud[i], phong[i]);
        assert!((g - ph).length() <= 0.1 * ph.length() + 1e-4, "near vertex {v}: gouraud {g} phong {ph}");
    }
}

#[test]
fn faceted_lights_each_triangle_once_at_its_centroid() {
    // The book's triangle, faceted: every pixel it covers holds one value,
    // and that value is Phong's at the centroid (the pixel whose centre is
    // nearest the centroid sees almost the same point, normal and uv).
    let scene = builtin("one-triangle");
    let prepared = PreparedScene::new(scene.clone());
    let s = settings(&scene, Interpolation::Faceted);
    let background = scene.render.background;
    for renderer in ["raytrace:bvh", "rasterize"] {
        let faceted = render(renderer, &prepared, &s);
        let covered: Vec<Radiance> = faceted.iter().copied().filter(|c| *c != background).collect();
        assert!(covered.len() > 1000, "{renderer}: {} pixels", covered.len());
        assert!(covered.iter().all(|c| *c == covered[0]), "{renderer}: more than one value on one triangle");
        let phong = render(renderer, &prepared, &settings(&scene, Interpolation::Phong));
        let view = scene.camera.view(s.width, s.height);
        let centroid = scene.triangles.at(0).v.iter().copied().sum::<Vec3>() / 3.0;
        let (c, _) = view.project(centroid).unwrap();
        let i = (c.x as u32 + c.y as u32 * s.width) as usize;
        assert!((phong[i] - covered[0]).length() <= 0.02 * phong[i].length(), "{renderer}: centroid {} against faceted {}", phong[i], covered[0]);
        // Phong varies over the same triangle (its highlight), faceted not.
        assert!(max_lum(&phong) > 1.2 * pinhole::math::luminance(covered[0]));
    }
}
