//! Debug views show their expected patterns on the book's one-triangle scene
//! (CGPP 15.4.1.2 and figure 15.6), in every renderer.

mod common;
use common::*;
use pinhole::math::{Radiance, Vec3};
use pinhole::render::inspect::debug::View;
use pinhole::render::{renderer_names, PreparedScene, RenderSettings};

const W: u32 = 200;
const H: u32 = 125;

fn render_view(renderer: &str, scene_name: &str, view: View) -> Vec<Radiance> {
    let scene = builtin(scene_name);
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = W;
    settings.height = H;
    settings.view = view;
    render(renderer, &PreparedScene::new(scene), &settings)
}

/// The renderers that draw debug views (`opengl` draws those coloured from
/// the surface alone and refuses the others through `Renderer::check`).
fn renderers_with_views() -> Vec<&'static str> {
    let scene = builtin("one-triangle");
    let settings = RenderSettings { view: View::Normal, ..RenderSettings::for_scene(&scene) };
    let names: Vec<&'static str> =
        renderer_names().into_iter().filter(|n| pinhole::render::renderer_by_name(n).unwrap().check(&scene, &settings).is_ok()).collect();
    assert!(names.len() >= 10, "{names:?}");
    names
}

fn at(img: &[Radiance], x: u32, y: u32) -> Vec3 {
    img[(x + y * W) as usize]
}

/// Pixel nearest to a world point of the one-triangle scene, moved `inset`
/// pixels towards the triangle's centroid so it lies inside.
fn vertex_pixel(v: Vec3, inset: f32) -> (u32, u32) {
    let scene = builtin("one-triangle");
    let view = scene.camera.view(W, H);
    let centroid = scene.triangles.at(0).v.iter().copied().sum::<Vec3>() / 3.0;
    let (p, _) = view.project(v).unwrap();
    let (c, _) = view.project(centroid).unwrap();
    let q = p + (c - p).normalize() * inset;
    (q.x as u32, q.y as u32)
}

#[test]
fn raydir_red_grows_rightwards_and_green_upwards() {
    for r in renderers_with_views() {
        let img = render_view(r, "one-triangle", View::Raydir);
        for x in 1..W {
            assert!(at(&img, x, 60).x > at(&img, x - 1, 60).x, "{r}: red must grow left to right");
        }
        for y in 1..H {
            assert!(at(&img, 100, y).y < at(&img, 100, y - 1).y, "{r}: green must grow bottom to top");
        }
        // Looking down -z: blue = (d.z + 1) / 2 stays below one half.
        assert!(img.iter().all(|c| c.z < 0.5));
    }
}

#[test]
fn barycentric_vertices_are_pure_channels() {
    let scene = builtin("one-triangle");
    let v = scene.triangles.at(0).v;
    for r in renderers_with_views() {
        let img = render_view(r, "one-triangle", View::Barycentric);
        for (k, vertex) in v.iter().enumerate() {
            let (x, y) = vertex_pixel(*vertex, 3.0);
            let c = at(&img, x, y);
            assert!(c[k] > 0.9, "{r}: near vertex {k} at ({x}, {y}) the colour is {c}");
            assert!((c.x + c.y + c.z - 1.0).abs() < 1e-4, "{r}: weights sum to one: {c}");
        }
        // Outside the triangle: black.
        assert_eq!(at(&img, 2, 2), Vec3::ZERO);
    }
}

#[test]
fn depth_increases_with_distance() {
    // The triangle lies in the plane z = -2: its distance from the eye grows
    // away from the image centre, so the corner near v1 is deeper than the centre.
    let scene = builtin("one-triangle");
    let v1 = scene.triangles.at(0).v[1];
    for r in renderers_with_views() {
        let img = render_view(r, "one-triangle", View::Depth);
        let (x, y) = vertex_pixel(v1, 3.0);
        let centre = at(&img, W / 2, H / 2).x;
        let corner = at(&img, x, y).x;
        assert!(corner > centre && centre > 0.0, "{r}: corner {corner} vs centre {centre}");
        let z = render_view(r, "one-triangle", View::Zbuffer);
        // 1/z is constant on a plane of constant z.
        assert!((at(&z, x, y).x - at(&z, W / 2, H / 2).x).abs() < 1e-5, "{r}");
    }
    // Across objects: on triangle-ground the far ground is deeper than the near ground.
    let img = render_view("raytrace:brute", "triangle-ground", View::Depth);
    assert!(at(&img, 5, H - 1).x < at(&img, 5, 75).x);
}

#[test]
fn normal_and_id_views() {
    let scene = builtin("one-triangle");
    let n0 = scene.triangles.at(0).n[0];
    for r in renderers_with_views() {
        let img = render_view(r, "one-triangle", View::Normal);
        let (x, y) = vertex_pixel(scene.triangles.at(0).v[0], 2.0);
        let c = at(&img, x, y) * 2.0 - Vec3::ONE;
        assert!(c.dot(n0) > 0.98, "{r}: normal near v0 is {c}, expected {n0}");
        let ids = render_view(r, "triangle-ground", View::Id);
        // The triangle (object 0) and the ground (objects 2, 3) differ in colour.
        assert_ne!(at(&ids, W / 2, 40), at(&ids, 5, H - 2), "{r}");
    }
}

#[test]
fn cost_view_shows_more_work_for_brute_force() {
    // Brute force tests every triangle of the teapot for each ray; the BVH tests few.
    let brute = render_view("raytrace:brute", "teapot", View::Cost);
    let bvh = render_view("raytrace:bvh", "teapot", View::Cost);
    let heat = |img: &[Radiance]| img.iter().map(|c| c.x + c.y + c.z).sum::<f32>() / img.len() as f32;
    assert!(heat(&brute) > 1.5 * heat(&bvh), "brute {} vs bvh {}", heat(&brute), heat(&bvh));
}

#[test]
fn diff_view_counts_differences_from_the_reference() {
    use pinhole::render::{render_frame, renderer_by_name};
    use std::sync::atomic::AtomicBool;
    let scene = builtin("teapot");
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = W;
    settings.height = H;
    settings.view = View::Diff;
    let prepared = PreparedScene::new(scene);
    let diff = |name: &str| render_frame(renderer_by_name(name).unwrap().as_ref(), &prepared, &settings, &AtomicBool::new(false), None).unwrap();
    let bvh = diff("raytrace:bvh");
    assert_eq!(bvh.differing_pixels, Some(0), "the BVH gives the reference's pixels");
    let raster = diff("rasterize");
    let n = raster.differing_pixels.unwrap();
    assert!(n > 0 && n < (W * H / 100) as u64, "edge pixels only: {n}");
    // Differing pixels are marked red or blue, at least half bright; the rest is dim.
    let marked = raster.pixels.iter().filter(|c| c.x >= 0.5 || c.z >= 0.5).count() as u64;
    assert_eq!(marked, n);
    // A real error is counted: a scene with a brighter light differs everywhere it is lit.
    let (img, count) = pinhole::render::inspect::debug::diff_image(&bvh.pixels.iter().map(|c| *c * 1.01 + Vec3::splat(1e-3)).collect::<Vec<_>>(), &bvh.pixels);
    assert_eq!(count, (W * H) as u64);
    assert!(img.iter().all(|c| c.x >= 0.5));
}

#[test]
fn geometric_normal_triangle_and_material_ids() {
    for r in renderers_with_views() {
        // The book's triangle lies in z = -2: its face normal is +z everywhere,
        // while its vertex normals lean away.
        let g = render_view(r, "one-triangle", View::GeometricNormal);
        let c = at(&g, W / 2, H / 2) * 2.0 - Vec3::ONE;
        assert!((c - Vec3::Z).length() < 1e-5, "{r}: {c}");
        // triangle-ground: the two ground triangles are distinct triangles of
        // one material; the green triangle has another material.
        let tri = render_view(r, "triangle-ground", View::TriangleId);
        let mat = render_view(r, "triangle-ground", View::MaterialId);
        // Near left is in the first ground triangle, far right in the second
        // (the diagonal runs from far left to near right).
        let (left, right) = ((5, H - 2), (W - 5, 80));
        assert_ne!(at(&tri, left.0, left.1), at(&tri, right.0, right.1), "{r}: the ground's two triangles");
        assert_eq!(at(&mat, left.0, left.1), at(&mat, right.0, right.1), "{r}: one ground material");
        assert_ne!(at(&mat, W / 2, 40), at(&mat, left.0, left.1), "{r}: triangle vs ground material");
    }
}

#[test]
fn affine_interpolation_bends_the_uv_checker() {
    // The teapot's ground quad is strongly foreshortened: perspective-correct
    // uvs match the ray caster; affine ones (screen-space weights) do not.
    let scene = builtin("teapot");
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = W;
    settings.height = H;
    settings.view = View::Uv;
    let prepared = PreparedScene::new(scene);
    let reference = render("raytrace:brute", &prepared, &settings);
    let differing = |img: &[Radiance]| img.iter().zip(&reference).filter(|(a, b)| a != b).count() as f32 / img.len() as f32;
    for r in ["rasterize:barycentric", "rasterize:incremental", "rasterize:scanline", "rasterize:fixed", "rasterize:tiled"] {
        settings.affine = false;
        let correct = render(r, &prepared, &settings);
        settings.affine = true;
        let affine = render(r, &prepared, &settings);
        assert!(differing(&correct) < 0.005, "{r}: perspective-correct differs on {}", differing(&correct));
        assert!(differing(&affine) > 0.05, "{r}: affine differs on only {}", differing(&affine));
    }
}

/// In every view that colours only what is hit, the rasterizers fill the
/// pixels no primitive covers with the view's miss colour without making
/// their eye rays, and the ray caster the tiles that cannot see the scene;
/// both colour the covered pixels from hit records built eight at a time.
/// Each such pixel, empty or covered, is what the pixel replay (its eye ray
/// made and traced alone, its hit built alone) gives. The teapot leaves
/// most of the image empty.
#[test]
fn views_fill_empty_pixels_as_their_replays_show_them() {
    use pinhole::render::inspect::debug::miss_color;
    use pinhole::render::frame::replay_pixel;
    let views: Vec<View> = View::ALL.into_iter().filter(|v| miss_color(*v).is_some()).collect();
    assert!(views.contains(&View::Depth) && views.len() >= 8);
    let scene = builtin("teapot");
    let prepared = PreparedScene::new(scene.clone());
    for view in views {
        let mut settings = RenderSettings::for_scene(&scene);
        (settings.width, settings.height, settings.view) = (W, H, view);
        for name in ["rasterize:fixed", "rasterize:tiled", "rasterize:barycentric", "raytrace"] {
            let image = render(name, &prepared, &settings);
            let renderer = pinhole::render::renderer_by_name(name).unwrap();
            let (mut empty, mut covered) = (0, 0);
            for y in (0..H).step_by(7) {
                for x in (0..W).step_by(5) {
                    let replayed = replay_pixel(renderer.as_ref(), &prepared, &settings, x, y).unwrap().radiance;
                    assert_eq!(replayed.to_array().map(f32::to_bits), at(&image, x, y).to_array().map(f32::to_bits), "{name}, {view:?}, pixel ({x}, {y})");
                    if replayed == Vec3::ZERO { empty += 1 } else { covered += 1 }
                }
            }
            assert!(empty > 200 && covered > 50, "{name}, {view:?}: {empty} empty, {covered} covered");
        }
    }
}
