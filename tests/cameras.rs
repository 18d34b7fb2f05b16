//! Cameras beyond the pinhole: the orthographic projection keeps parallel
//! lines parallel and draws the same pixels in both ray casters; a glTF's
//! orthographic camera is used; the thin lens equals the pinhole at
//! aperture 0 bit for bit, keeps its plane in focus sharp and blurs an edge
//! off it by the circle of confusion worked out by hand; the projections
//! that bend lines render in the ray casters; the CPU rasterizers draw the
//! orthographic camera (parallel lines parallel, the brute-force caster's
//! pixels) and refuse what they cannot draw in one sentence; bad values are refused naming the
//! file and the key.

mod common;

use pinhole::math::{Radiance, Vec3};
use pinhole::render::admit::admit;
use pinhole::render::inspect::debug::View;
use pinhole::render::{renderer_by_name, renderer_names, replay_pixel, PreparedScene, RenderSettings};
use pinhole::scene::camera::Projection;
use pinhole::scene::file::{load_scene_file, parse_scene};
use pinhole::scene::Scene;
use std::path::Path;

fn scene_of(text: &str) -> Scene {
    parse_scene(text, "test.toml", Path::new("."), "test").unwrap()
}

fn settings(scene: &Scene, w: u32, h: u32, spp: u32, view: View) -> RenderSettings {
    RenderSettings { width: w, height: h, spp, view, ..RenderSettings::for_scene(scene) }
}

fn render(renderer: &str, scene: &Scene, s: &RenderSettings) -> Vec<Radiance> {
    common::render(renderer, &PreparedScene::new(scene.clone()), s)
}

/// Two stripes on the floor along the view direction, 1 apart, reaching 30
/// units away: a perspective camera above them sees them converge.
fn stripes(camera: &str) -> String {
    format!(
        "[camera]\neye = [0.0, 3.0, 4.0]\ntarget = [0.0, 0.0, -4.0]\nnear = 0.1\nfar = 200.0\n{camera}\n\
         [render]\nbackground = [0.0, 0.0, 0.0]\n\
         [materials.white]\nlambertian = [0.8, 0.8, 0.8]\n\
         [[object]]\ntype = \"quad\"\nvertices = [[-0.6, 0.0, 2.0], [-0.4, 0.0, 2.0], [-0.4, 0.0, -30.0], [-0.6, 0.0, -30.0]]\nmaterial = \"white\"\n\
         [[object]]\ntype = \"quad\"\nvertices = [[0.4, 0.0, 2.0], [0.6, 0.0, 2.0], [0.6, 0.0, -30.0], [0.4, 0.0, -30.0]]\nmaterial = \"white\"\n"
    )
}

/// Per image row that shows both stripes, the distance in pixels between
/// their centres (each stripe: the mean column of its run of pixels that
/// are not the background of pixel (0, 0)).
fn stripe_separations(img: &[Radiance], w: u32, h: u32) -> Vec<f32> {
    let bg = img[0];
    let mut out = Vec::new();
    for y in 0..h as usize {
        let row = &img[y * w as usize..(y + 1) * w as usize];
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for (x, p) in row.iter().enumerate() {
            if (*p - bg).abs().max_element() > 1e-3 {
                match runs.last_mut() {
                    Some(r) if r.1 + 1 == x => r.1 = x,
                    _ => runs.push((x, x)),
                }
            }
        }
        if runs.len() == 2 {
            let centre = |r: (usize, usize)| (r.0 + r.1) as f32 * 0.5;
            out.push(centre(runs[1]) - centre(runs[0]));
        }
    }
    out
}

#[test]
fn orthographic_parallel_lines_stay_parallel() {
    let (w, h) = (160, 120);
    let spread = |camera: &str| {
        let scene = scene_of(&stripes(camera));
        let sep = stripe_separations(&render("raytrace:bvh", &scene, &settings(&scene, w, h, 1, View::Id)), w, h);
        assert!(sep.len() > 40, "{camera}: the stripes show in only {} rows", sep.len());
        let (lo, hi) = sep.iter().fold((f32::MAX, f32::MIN), |(a, b), &s| (a.min(s), b.max(s)));
        (lo, hi)
    };
    let (lo, hi) = spread("projection = \"orthographic\"\nheight = 6.0");
    // 1 world unit apart in a view 6 units high, 120 pixels: 20 pixels, in every row.
    assert!(hi - lo <= 1.0, "orthographic stripes' separation ranges over [{lo}, {hi}] pixels");
    assert!((lo - 20.0).abs() <= 1.0 && (hi - 20.0).abs() <= 1.0, "separation [{lo}, {hi}], 20 pixels by hand");
    // The same measurement sees the perspective camera's stripes converge.
    let (lo, hi) = spread("fov_y_deg = 60.0");
    assert!(hi - lo > 10.0, "perspective stripes' separation only ranges over [{lo}, {hi}]");
}

/// `scene` seen through an orthographic camera as high as its perspective
/// view is at the target's distance.
fn orthographic(mut scene: Scene) -> Scene {
    let c = &scene.camera;
    let fov_y = match c.fov {
        pinhole::scene::Fov::Y(d) => d,
        pinhole::scene::Fov::X(d) => d * scene.render.height as f32 / scene.render.width as f32,
    };
    let height = 2.0 * (c.target - c.eye).length() * (fov_y.to_radians() * 0.5).tan();
    scene.camera.projection = Projection::Orthographic { height };
    scene
}

#[test]
fn orthographic_ray_casters_agree_with_brute_force_and_replay() {
    for name in ["spheres", "cornell-box"] {
        let scene = orthographic(common::builtin(name));
        let s = settings(&scene, 96, 64, 1, View::Shaded);
        let reference = render("raytrace:brute", &scene, &s);
        let bvh = render("raytrace:bvh", &scene, &s);
        let same = reference.iter().zip(&bvh).filter(|(a, b)| (**a - **b).abs().max_element() <= 1e-4 * a.abs().max_element().max(1e-3)).count();
        assert!(same as f32 >= 0.995 * reference.len() as f32, "{name}: raytrace:bvh agrees on {same} of {} pixels", reference.len());
        // Not the perspective image: the camera really changed.
        let perspective = render("raytrace:brute", &common::builtin(name), &settings(&common::builtin(name), 96, 64, 1, View::Shaded));
        assert!(perspective.iter().zip(&reference).filter(|(a, b)| a != b).count() > 300, "{name}: orthographic looks like perspective");
        let prepared = PreparedScene::new(scene.clone());
        for (x, y) in [(48, 32), (10, 50), (80, 7)] {
            let replay = replay_pixel(renderer_by_name("raytrace:brute").unwrap().as_ref(), &prepared, &s, x, y).unwrap();
            assert_eq!(replay.radiance, reference[(y * 96 + x) as usize], "{name} ({x}, {y}): replay differs from the frame");
        }
    }
}

/// The CPU rasterizers that draw orthographic cameras: every variant but
/// the painter's algorithm, whose draw order needs an eye point.
fn orthographic_rasterizers() -> Vec<&'static str> {
    renderer_names().into_iter().filter(|n| n.starts_with("rasterize:") && *n != "rasterize:painter").collect()
}

#[test]
fn orthographic_rasterizers_keep_parallel_lines_parallel() {
    let (w, h) = (160, 120);
    let scene = scene_of(&stripes("projection = \"orthographic\"\nheight = 6.0"));
    for name in orthographic_rasterizers() {
        let sep = stripe_separations(&render(name, &scene, &settings(&scene, w, h, 1, View::Id)), w, h);
        assert!(sep.len() > 40, "{name}: the stripes show in only {} rows", sep.len());
        // The near ends (bottom rows) and the far ends (top rows) alike: 20 pixels by hand.
        let (near, far) = (sep[sep.len() - 1], sep[0]);
        let (lo, hi) = sep.iter().fold((f32::MAX, f32::MIN), |(a, b), &s| (a.min(s), b.max(s)));
        assert!(hi - lo <= 1.0 && (lo - 20.0).abs() <= 1.0 && (hi - 20.0).abs() <= 1.0, "{name}: separation over [{lo}, {hi}] pixels (near end {near}, far end {far}), 20 by hand");
    }
}

/// The share of pixels of `a` and `b` equal within the tolerance the
/// rasterizer agreement tests use (1e-4 relative, 1e-2 with textures).
fn agreement(a: &[Radiance], b: &[Radiance], tol: f32) -> f32 {
    let same = a.iter().zip(b).filter(|(a, b)| (**a - **b).abs().max_element() <= tol * a.abs().max_element().max(b.abs().max_element()).max(1e-3)).count();
    same as f32 / a.len() as f32
}

#[test]
fn orthographic_rasterizers_agree_with_brute_force() {
    for name in ["spheres", "cornell-box", "textures"] {
        let scene = orthographic(common::builtin(name));
        let tol = if scene.has_textures() { 1e-2 } else { 1e-4 };
        let s = settings(&scene, 96, 64, 1, View::Shaded);
        let reference = render("raytrace:brute", &scene, &s);
        for r in orthographic_rasterizers() {
            let share = agreement(&reference, &render(r, &scene, &s), tol);
            assert!(share >= 0.995, "{name}: {r} agrees with raytrace:brute on {:.2}% of pixels", 100.0 * share);
        }
    }
}

#[test]
fn rasterizers_refuse_cameras_they_cannot_draw_in_one_sentence() {
    let mut cases = vec![("orthographic", orthographic(common::builtin("spheres")))];
    for (p, name) in [(Projection::Fisheye, "fisheye"), (Projection::Cylindrical, "cylindrical")] {
        let mut s = common::builtin("spheres");
        s.camera.projection = p;
        cases.push((name, s));
    }
    let mut lens = common::builtin("spheres");
    lens.camera.aperture = 0.05;
    cases.push(("aperture", lens));
    for (what, scene) in &cases {
        let s = settings(scene, 32, 24, 1, View::Shaded);
        for name in renderer_names() {
            let r = renderer_by_name(name).unwrap();
            let answer = admit(r.as_ref(), scene, &s);
            // Orthographic: every rasterizer but the painter's, and opengl (tests/opengl.rs draws it).
            let draws_orthographic = orthographic_rasterizers().contains(&name) || name == "opengl";
            if name.starts_with("raytrace:") || (*what == "orthographic" && draws_orthographic) {
                assert!(answer.is_ok(), "{name} refuses {what}: {answer:?}");
                continue;
            }
            let e = answer.expect_err(name);
            assert!(e.contains(what) && e.contains(name) && e.contains("raytrace:bvh"), "{name} on {what}: {e}");
            assert_eq!(e.matches(". ").count(), 0, "not one sentence: {e}");
            if matches!(*what, "fisheye" | "cylindrical") {
                assert!(e.contains("straight lines to stay straight"), "{e}");
            }
            if *what == "orthographic" {
                assert_eq!(name, "rasterize:painter", "{e}");
                assert!(e.contains("eye point"), "{e}");
            }
        }
    }
}

#[test]
fn fisheye_and_cylindrical_render_in_the_ray_casters() {
    for (projection, fov) in [("fisheye", 200.0), ("cylindrical", 300.0)] {
        let text = stripes(&format!("projection = \"{projection}\"\nfov_x_deg = {fov}"));
        let scene = scene_of(&text);
        let s = settings(&scene, 120, 60, 1, View::Id);
        let reference = render("raytrace:brute", &scene, &s);
        assert_eq!(reference, render("raytrace:bvh", &scene, &s), "{projection}: raytrace:bvh differs from raytrace:brute");
        let lit = reference.iter().filter(|p| (**p - reference[0]).abs().max_element() > 1e-3).count();
        assert!(lit > 20, "{projection}: the stripes cover {lit} pixels");
    }
}

/// A wall whose left edge is the line x = 0 at depth `depth` in front of a
/// camera at the origin looking down -z (60 degrees wide), with `lens`.
fn wall(depth: f32, lens: &str) -> Scene {
    scene_of(&format!(
        "[camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov_x_deg = 60.0\nnear = 0.05\nfar = 100.0\n{lens}\n\
         [render]\nbackground = [0.0, 0.0, 0.0]\n\
         [materials.white]\nlambertian = [0.8, 0.8, 0.8]\n\
         [[object]]\ntype = \"quad\"\nvertices = [[0.0, -50.0, -{depth}], [50.0, -50.0, -{depth}], [50.0, 50.0, -{depth}], [0.0, 50.0, -{depth}]]\nmaterial = \"white\"\n"
    ))
}

/// Where across the image the wall's coverage, averaged over the rows,
/// first reaches `level` (in pixels, interpolated between columns).
fn crossing(cover: &[f32], level: f32) -> f32 {
    let i = cover.windows(2).position(|p| p[0] < level && p[1] >= level).expect("the coverage never crosses the level");
    i as f32 + 0.5 + (level - cover[i]) / (cover[i + 1] - cover[i])
}

/// Per column, the fraction of the wall's colour the image shows,
/// averaged over the rows (the id view: wall colour against background).
fn coverage(img: &[Radiance], w: u32, h: u32, wall: Vec3, bg: Vec3) -> Vec<f32> {
    let k = (wall - bg).abs().max_position();
    (0..w as usize).map(|x| (0..h as usize).map(|y| (img[y * w as usize + x][k] - bg[k]) / (wall[k] - bg[k])).sum::<f32>() / h as f32).collect()
}

/// Where a uniform disk's area to the left of a line reaches `level`:
/// `s` in units of the radius from the centre, from the area of a
/// circular segment, (s sqrt(1 - s^2) + asin s) / pi + 1/2.
fn disk_quantile(level: f32) -> f32 {
    let (mut lo, mut hi) = (-1.0f64, 1.0f64);
    for _ in 0..60 {
        let s = 0.5 * (lo + hi);
        let f = (s * (1.0 - s * s).sqrt() + s.asin()) / std::f64::consts::PI + 0.5;
        if f < level as f64 { lo = s } else { hi = s }
    }
    lo as f32
}

#[test]
fn thin_lens_keeps_the_focus_plane_sharp_and_blurs_by_the_circle_of_confusion() {
    let (w, h, spp) = (240, 24, 256);
    let (aperture, focus) = (0.3f32, 4.0f32);
    let lens = format!("aperture = {aperture}\nfocus_distance = {focus}");
    let edge_width = |depth: f32| {
        let scene = wall(depth, &lens);
        let s = settings(&scene, w, h, spp, View::Id);
        let img = render("raytrace:bvh", &scene, &s);
        // The wall's and the background's id colours: a pinhole sees them whole.
        let sharp = render("raytrace:bvh", &wall(depth, ""), &settings(&scene, w, h, 1, View::Id));
        let (bg, wall_colour) = (sharp[0], sharp[(w - 1) as usize]);
        let cover = coverage(&img, w, h, wall_colour, bg);
        let (a, b) = (crossing(&cover, 0.25), crossing(&cover, 0.75));
        // Centred on the pinhole's edge, the image's middle column.
        assert!(((a + b) * 0.5 - w as f32 * 0.5).abs() < 1.0, "depth {depth}: blur centred at {}", (a + b) * 0.5);
        b - a
    };
    // On the plane in focus: only the pixel's own sub-pixel spread.
    let in_focus = edge_width(focus);
    assert!(in_focus < 1.0, "the edge in focus spreads over {in_focus} pixels");
    // Off it, by hand: the lens point L and the edge point P at depth z
    // meet the focus plane at L + (P - L) F / z, so the lens disk of
    // radius A maps to a disk of radius A |1 - F / z| on it; a pixel is
    // 2 F tan(30 deg) / width there.
    for depth in [8.0f32, 2.5] {
        let radius_world = aperture * (1.0 - focus / depth).abs();
        let pixel = 2.0 * focus * 30f32.to_radians().tan() / w as f32;
        let radius_px = radius_world / pixel;
        let expected = (disk_quantile(0.75) - disk_quantile(0.25)) * radius_px;
        let measured = edge_width(depth);
        assert!((measured - expected).abs() < 0.08 * expected + 0.3, "depth {depth}: the edge spreads over {measured} pixels from 25% to 75%, {expected} by hand (blur radius {radius_px} px)");
    }
}

#[test]
fn aperture_zero_is_the_pinhole_bit_for_bit_and_an_open_lens_replays() {
    let mut pinhole_scene = common::builtin("cornell-gi");
    let mut s = settings(&pinhole_scene, 24, 18, 4, View::Shaded);
    s.gi.mode = pinhole::render::transport::gi::GiMode::Path;
    let mut closed = pinhole_scene.clone();
    closed.camera.aperture = 0.0;
    closed.camera.focus_distance = 2.5;
    pinhole_scene.camera.aperture = 0.0;
    let a = render("raytrace:bvh", &pinhole_scene, &s);
    let bits = |p: &[Radiance]| p.iter().map(|c| c.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&render("raytrace:bvh", &closed, &s)));
    assert_eq!(bits(&a), bits(&render("raytrace:brute", &closed, &s)));
    // Opened, the image changes, both ray casters make the same samples,
    // and a replayed pixel draws its frame's lens samples.
    let mut open = closed.clone();
    open.camera.aperture = 0.1;
    let b = render("raytrace:bvh", &open, &s);
    assert!(bits(&a) != bits(&b), "an open lens changed nothing");
    assert_eq!(bits(&b), bits(&render("raytrace:brute", &open, &s)));
    let prepared = PreparedScene::new(open.clone());
    for (x, y) in [(12, 9), (3, 16)] {
        let replay = replay_pixel(renderer_by_name("raytrace:bvh").unwrap().as_ref(), &prepared, &s, x, y).unwrap();
        assert_eq!(replay.radiance.to_array().map(f32::to_bits), b[(y * 24 + x) as usize].to_array().map(f32::to_bits), "({x}, {y})");
    }
}

/// Loads `text` as a scene file and returns its one-line error.
fn error_of(text: &str) -> String {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("pinhole-cameras-{}-{}", std::process::id(), N.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.toml");
    std::fs::write(&p, text).unwrap();
    let e = load_scene_file(&p).err().expect("expected an error");
    assert!(e.contains("bad.toml:") && !e.contains('\n'), "{e}");
    e
}

#[test]
fn bad_camera_values_are_refused_naming_the_file_and_key() {
    let cam = "[camera]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n";
    for h in ["0.0", "-2.0", "nan"] {
        let e = error_of(&format!("{cam}projection = \"orthographic\"\nheight = {h}\n"));
        assert!(e.contains("camera.height"), "{e}");
    }
    assert!(error_of(&format!("{cam}projection = \"orthographic\"\n")).contains("camera.height"));
    assert!(error_of(&format!("{cam}height = 2.0\n")).contains("camera.height"));
    assert!(error_of(&format!("{cam}projection = \"orthographic\"\nheight = 2.0\nfov_y_deg = 40.0\n")).contains("field of view"));
    assert!(error_of(&format!("{cam}projection = \"stereographic\"\n")).contains("camera.projection"));
    for a in ["-0.1", "nan", "inf"] {
        let e = error_of(&format!("{cam}aperture = {a}\n"));
        assert!(e.contains("camera.aperture"), "{e}");
    }
    assert!(error_of(&format!("{cam}aperture = 0.1\nfocus_distance = 0.0\n")).contains("camera.focus_distance"));
    assert!(error_of(&format!("{cam}aperture = 0.1\nprojection = \"fisheye\"\n")).contains("camera.aperture"));
    assert!(error_of(&format!("{cam}projection = \"fisheye\"\nfov_x_deg = 400.0\n")).contains("360"));
}

#[test]
fn a_gltf_orthographic_camera_is_used() {
    // One triangle of area 2 at z = -5, seen by an orthographic camera at
    // the origin with xmag 2, ymag 1: a view 4 x 2 units, so the triangle
    // covers a quarter of the image, and the image is twice as wide as high.
    let v: [[f32; 3]; 3] = [[-1.0, -1.0, -5.0], [1.0, -1.0, -5.0], [0.0, 1.0, -5.0]];
    let bytes: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
"nodes": [{{"mesh": 0}}, {{"camera": 0}}],
"cameras": [{{"type": "orthographic", "orthographic": {{"xmag": 2.0, "ymag": 1.0, "znear": 0.1, "zfar": 50.0}}}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
"accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, -5], "max": [1, 1, -5]}}],
"bufferViews": [{{"buffer": 0, "byteLength": 36}}],
"buffers": [{{"byteLength": 36, "uri": "data:application/octet-stream;base64,{}"}}]}}"#,
        common::base64(&bytes)
    );
    let dir = std::env::temp_dir().join(format!("pinhole-cameras-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ortho.gltf");
    std::fs::write(&path, json).unwrap();
    let scene = pinhole::scene::load::load_scene(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.camera.projection, Projection::Orthographic { height: 2.0 });
    assert!(!scene.warnings.iter().any(|w| w.contains("orthographic")), "{:?}", scene.warnings);
    let (w, h) = (scene.render.width, scene.render.height);
    assert_eq!(w, 2 * h, "xmag / ymag = 2 sizes the image");
    let img = render("raytrace:bvh", &scene, &settings(&scene, 200, 100, 1, View::Id));
    let bg = img[0];
    let covered = img.iter().filter(|p| (**p - bg).abs().max_element() > 1e-3).count() as f32 / img.len() as f32;
    assert!((covered - 0.25).abs() < 0.01, "the triangle covers {covered} of the image, a quarter by hand");
}
