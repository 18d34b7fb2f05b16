//! Every rasterizer variant against the brute-force ray caster on every
//! built-in scene (the brute-force caster is the reference): the same pixels except a small,
//! explained set, namely samples within one pixel of a projected triangle edge or of
//! a sphere's silhouette, where coverage rules and rounding legitimately differ.
//! Plus: thread-count independence, `fixed` == `tiled` bit for bit, forward
//! shading == early depth, and any row range renders the same rows.

use pinhole::math::{Radiance, Vec2, Vec3};
use pinhole::render::raster::{Method, Rasterizer};
use pinhole::render::accel::intersect::intersect_sphere;
use pinhole::render::{render_frame, sample_offset, PassJob, PreparedScene, RenderSettings, Renderer};
use pinhole::scene::{CameraView, Scene};
use std::sync::atomic::AtomicBool;

const W: u32 = 200;
const H: u32 = 125;

fn scene(name: &str) -> Scene {
    pinhole::scene::builtin::load_builtin(name).unwrap().unwrap()
}

fn settings(scene: &Scene) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.width = W;
    s.height = H;
    s.spp = 1;
    s
}

fn render(r: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings) -> Vec<Radiance> {
    render_frame(r, prepared, settings, &AtomicBool::new(false), None).unwrap().pixels
}

fn brute() -> Box<dyn Renderer> {
    pinhole::render::renderer_by_name("raytrace:brute").unwrap()
}

fn raster(m: Method) -> Rasterizer {
    Rasterizer::new(m)
}

/// Equal within `tol` relative, per channel.
fn same(a: Vec3, b: Vec3, tol: f32) -> bool {
    let d = (a - b).abs();
    let m = a.abs().max(b.abs());
    d.x <= tol * m.x + 1e-7 && d.y <= tol * m.y + 1e-7 && d.z <= tol * m.z + 1e-7
}

/// The tolerance two families' pixels are held to: 1e-4 relative, or 1e-2
/// where textures are read. The rasterizers interpolate uv from 2D weights,
/// the ray casters from the 3D intersection; both round differently, by
/// about 1e-7 of the triangle's size, and where a texture changes fast (a
/// checker square's edge magnified) that moves a bilinear lookup by up to
/// a few 1e-3 of its value (on `textures` at 200x125: 1% of the pixels
/// differ by more than 1e-4, 0.03% by more than 1e-3, none by 1e-2). A
/// wrong footprint moves whole regions by a mip level, far more than 1%.
fn tolerance(scene: &Scene) -> f32 {
    if scene.has_textures() { 1e-2 } else { 1e-4 }
}

// ---- The edge map: an independent computation of where edges and silhouettes project ----

/// Distance from `p` to the segment `a-b`.
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * s)).length()
}

/// The polygon of a camera-space triangle in front of z = -near (0, 3 or 4 vertices).
fn clip_polygon(c: [Vec3; 3], near: f32) -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..3 {
        let (a, b) = (c[i], c[(i + 1) % 3]);
        let (ina, inb) = (-a.z >= near, -b.z >= near);
        if ina {
            out.push(a);
        }
        if ina != inb {
            let s = (-a.z - near) / (b.z - a.z);
            let mut p = a + (b - a) * s;
            p.z = -near;
            out.push(p);
        }
    }
    out
}

/// Per pixel: is its sample within one pixel of a projected triangle edge
/// (after near clipping) or of a sphere's silhouette?
fn near_edge_map(scene: &Scene, view: &CameraView) -> Vec<bool> {
    let (w, h) = (view.width as usize, view.height as usize);
    let mut map = vec![false; w * h];
    let reach = 1.0 + 1e-3;
    for t in &scene.triangles {
        let c = t.v.map(|v| view.to_camera(v));
        let poly = clip_polygon(c, view.near);
        for i in 0..poly.len() {
            let a = view.project_camera(poly[i]);
            let b = view.project_camera(poly[(i + 1) % poly.len()]);
            let lo = a.min(b) - Vec2::splat(2.0);
            let hi = a.max(b) + Vec2::splat(2.0);
            let x0 = lo.x.max(0.0) as usize;
            let y0 = lo.y.max(0.0) as usize;
            let x1 = (hi.x.min(w as f32)).max(0.0) as usize;
            let y1 = (hi.y.min(h as f32)).max(0.0) as usize;
            for y in y0..y1 {
                for x in x0..x1 {
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    if segment_distance(p, a, b) <= reach {
                        map[x + y * w] = true;
                    }
                }
            }
        }
    }
    // Sphere silhouettes: the hit/miss status changes somewhere within one pixel.
    for s in &scene.spheres {
        for y in 0..h {
            for x in 0..w {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let hit = |q: Vec2| intersect_sphere(&view.eye_ray(q.x, q.y), s, f32::INFINITY, false).is_ok();
                let centre = hit(p);
                let changes = (0..16).any(|k| {
                    let a = k as f32 * std::f32::consts::TAU / 16.0;
                    [0.5f32, 1.0].iter().any(|&r| hit(p + Vec2::new(a.cos(), a.sin()) * r) != centre)
                });
                if changes {
                    map[x + y * w] = true;
                }
            }
        }
    }
    map
}

struct Agreement {
    differing: usize,
    far_from_edges: Vec<(usize, usize)>,
}

fn agreement(reference: &[Radiance], image: &[Radiance], edges: &[bool], w: usize, tol: f32) -> Agreement {
    let mut a = Agreement { differing: 0, far_from_edges: Vec::new() };
    for (i, (r, p)) in reference.iter().zip(image).enumerate() {
        if !same(*r, *p, tol) {
            a.differing += 1;
            if !edges[i] {
                a.far_from_edges.push((i % w, i / w));
            }
        }
    }
    a
}

/// The acceptance rule: at least 99.5% of pixels equal, and every differing pixel near an edge.
fn check(a: &Agreement, n: usize) -> Result<(), String> {
    if a.differing as f64 > 0.005 * n as f64 {
        return Err(format!("{} of {n} pixels differ", a.differing));
    }
    if !a.far_from_edges.is_empty() {
        let shown: Vec<_> = a.far_from_edges.iter().take(8).collect();
        return Err(format!("{} differing pixels are not near an edge, e.g. {shown:?}", a.far_from_edges.len()));
    }
    Ok(())
}

#[test]
fn every_variant_agrees_with_the_ray_caster() {
    let mut report = String::new();
    let mut failures = Vec::new();
    for name in pinhole::scene::builtin::names() {
        let scene = scene(name);
        let settings = settings(&scene);
        let view = scene.camera.view(W, H);
        let edges = near_edge_map(&scene, &view);
        let tol = tolerance(&scene);
        let prepared = PreparedScene::new(scene);
        let reference = render(brute().as_ref(), &prepared, &settings);
        for m in Method::ALL {
            if m == Method::Painter {
                continue; // wrong by design where primitives interpenetrate: tests/raster_painter.rs
            }
            let image = render(&raster(m), &prepared, &settings);
            assert!(image.iter().all(|p| p.is_finite()), "{} on {name}: non-finite pixel", m.name());
            let a = agreement(&reference, &image, &edges, W as usize, tol);
            report += &format!("{name:>16} {:>22}: {:>4} differing pixels, {} far from edges\n", m.name(), a.differing, a.far_from_edges.len());
            if let Err(e) = check(&a, (W * H) as usize) {
                failures.push(format!("{} on {name}: {e}", m.name()));
            }
        }
    }
    println!("{report}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_agreement_check_catches_errors() {
    let scene = scene("teapot");
    let settings = settings(&scene);
    let view = scene.camera.view(W, H);
    let edges = near_edge_map(&scene, &view);
    let prepared = PreparedScene::new(scene);
    let reference = render(brute().as_ref(), &prepared, &settings);
    let n = (W * H) as usize;
    assert!(check(&agreement(&reference, &reference, &edges, W as usize, 1e-4), n).is_ok());
    // The image shifted one pixel to the right: differs across every shaded gradient.
    let mut shifted = reference.clone();
    for y in 0..H as usize {
        for x in (1..W as usize).rev() {
            shifted[x + y * W as usize] = reference[x - 1 + y * W as usize];
        }
    }
    assert!(check(&agreement(&reference, &shifted, &edges, W as usize, 1e-4), n).is_err());
    // A handful of wrong pixels far from any edge: few enough for the 99.5% rule,
    // caught by the edge rule.
    let interior: Vec<usize> = (0..n).filter(|&i| !edges[i]).step_by(997).take(10).collect();
    assert_eq!(interior.len(), 10);
    let mut spotted = reference.clone();
    for &i in &interior {
        spotted[i] *= 1.01;
    }
    let a = agreement(&reference, &spotted, &edges, W as usize, 1e-4);
    assert_eq!(a.differing, 10);
    let e = check(&a, n).unwrap_err();
    assert!(e.contains("not near an edge"), "{e}");
    // The edge map itself: pixels on the teapot's outline are marked, most are not.
    let marked = edges.iter().filter(|&&e| e).count();
    assert!(marked > 200 && marked < n * 9 / 10, "{marked}");
}

fn with_threads<T: Send>(n: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(f)
}

#[test]
fn thread_count_does_not_change_images_and_fixed_equals_tiled() {
    for name in pinhole::scene::builtin::names() {
        let scene = scene(name);
        let mut settings = settings(&scene);
        settings.spp = 2;
        let prepared = PreparedScene::new(scene);
        let mut fixed = None;
        for m in [Method::Barycentric, Method::Incremental, Method::Scanline, Method::Fixed, Method::Tiled, Method::BBox] {
            let one = with_threads(1, || render(&raster(m), &prepared, &settings));
            let two = with_threads(2, || render(&raster(m), &prepared, &settings));
            assert!(one == two, "{} on {name}: 1 and 2 threads differ", m.name());
            match m {
                Method::Fixed => fixed = Some(one),
                Method::Tiled => assert!(fixed.as_ref() == Some(&one), "fixed and tiled differ on {name}"),
                _ => {}
            }
        }
    }
}

#[test]
fn forward_shading_gives_the_early_depth_image_with_more_shading() {
    for name in ["teapot", "spheres", "triangle-ground"] {
        let scene = scene(name);
        let settings = settings(&scene);
        let prepared = PreparedScene::new(scene);
        for m in [Method::Incremental, Method::Tiled, Method::BBox] {
            let r = |early_depth| render_frame(&Rasterizer::new(m), &prepared, &RenderSettings { early_depth, ..settings.clone() }, &AtomicBool::new(false), None).unwrap();
            let (early, forward) = (r(true), r(false));
            assert!(early.pixels == forward.pixels, "{} on {name}", m.name());
            let (ce, cf) = (early.counts, forward.counts);
            assert_eq!(ce.primary, (W * H) as u64);
            assert_eq!(cf.primary, (W * H) as u64);
            assert!(ce.samples_tested >= ce.samples_covered && ce.samples_covered > 0, "{ce:?}");
            assert_eq!(ce.samples_covered, cf.samples_covered);
            assert_eq!(ce.depth_fails, cf.depth_fails);
            // Early depth shades once per covered pixel; forward once per depth-test pass.
            assert!(ce.fragments_shaded <= ce.primary);
            assert_eq!(cf.fragments_shaded, cf.samples_covered - cf.depth_fails);
            assert!(cf.fragments_shaded >= ce.fragments_shaded, "{cf:?} vs {ce:?}");
            if name == "teapot" {
                assert!(cf.fragments_shaded > ce.fragments_shaded, "the teapot has overdraw");
            }
        }
    }
}

/// A band of rows renders as those rows of the whole frame: the set-up of
/// a band skips the triangles wholly above or below it, and must skip no
/// other (the bunny's many small triangles straddle every band's edges).
#[test]
fn any_row_range_renders_the_same_rows() {
    for name in ["teapot", "bunny"] {
        rows_render_as_in_the_frame(name);
    }
}

fn rows_render_as_in_the_frame(name: &str) {
    let scene = scene(name);
    let settings = settings(&scene);
    let prepared = PreparedScene::new(scene);
    let view = prepared.scene.camera.view(W, H);
    let cancel = AtomicBool::new(false);
    for m in Method::ALL {
        if m == Method::Naive {
            continue; // the same bands as bbox, just slower
        }
        let r = raster(m);
        let full = render(&r, &prepared, &settings);
        for rows in [0..H, 37..90, 3..4, 100..H, 0..1, 60..61, 61..77, 124..H] {
            let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: sample_offset(0, 1, 0), sample: 0, photons: None, active: None, rows: rows.clone(), cancel: &cancel, keep_non_finite: false };
            let mut out = vec![Radiance::ZERO; (W * rows.len() as u32) as usize];
            let counts = r.render_pass(&job, &mut out);
            assert_eq!(counts.primary, out.len() as u64);
            let expect = &full[(rows.start * W) as usize..(rows.end * W) as usize];
            assert!(out == expect, "{name} {} rows {rows:?}", m.name());
        }
    }
}
