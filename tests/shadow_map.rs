//! Shadow maps (CGPP 15.6.5) against ray-cast shadows: the same renderer
//! renders with `--shadows ray` (the reference) and `--shadows map`; every
//! pixel whose radiance differs by more than 1% is wrongly shadowed (darker:
//! acne, or a map too coarse) or wrongly lit (brighter: peter-panning, or a
//! caster missed). Images are small and maps modest so this runs in seconds.
//!
//! `cargo test --release --test shadow_map -- --ignored --nocapture` prints
//! the table of error against map size and bias for the README.

mod common;

use pinhole::math::{luminance, Radiance, Vec3};
use pinhole::render::inspect::debug::View;
use pinhole::render::shadow::map::{cube_face, ShadowMaps, DEFAULT_BIAS, DEFAULT_SIZE};
use pinhole::render::{replay_pixel, renderer_by_name, PreparedScene, RenderSettings, ShadowMode};
use pinhole::scene::{Light, PrimitiveId, Scene};
use std::time::Instant;

const W: u32 = 160;
const H: u32 = 100;

fn reference_scene(name: &str) -> Scene {
    let path = common::shared_dir().join("references").join(format!("{name}.toml"));
    pinhole::scene::load::load_scene(path.to_str().unwrap()).unwrap()
}

fn settings(scene: &Scene, shadows: ShadowMode, size: u32, bias: f32) -> RenderSettings {
    RenderSettings { width: W, height: H, shadows, shadow_map_size: size, shadow_map_bias: bias, ..RenderSettings::for_scene(scene) }
}

/// How a map-shadowed image departs from the ray-cast one.
#[derive(Debug, Clone, Copy)]
struct Errors {
    pixels: usize,
    /// Pixels lit in the reference (brighter than with every shadow).
    lit: usize,
    /// Pixels with some light shadowed in the reference.
    shadowed: usize,
    /// Darker with the map: acne (or a coarse map's jagged edge).
    wrongly_shadowed: usize,
    /// Brighter with the map: peter-panning (or a missed caster).
    wrongly_lit: usize,
}

impl Errors {
    fn differing(&self) -> usize {
        self.wrongly_shadowed + self.wrongly_lit
    }

    fn percent(&self) -> f64 {
        100.0 * self.differing() as f64 / self.pixels as f64
    }
}

fn darker(a: Radiance, b: Radiance) -> bool {
    let (la, lb) = (luminance(a), luminance(b));
    la < lb - 0.01 * lb - 1e-5
}

fn compare(map: &[Radiance], ray: &[Radiance], unshadowed: &[Radiance]) -> Errors {
    let mut e = Errors { pixels: map.len(), lit: 0, shadowed: 0, wrongly_shadowed: 0, wrongly_lit: 0 };
    for ((&m, &r), &u) in map.iter().zip(ray).zip(unshadowed) {
        if darker(r, u) {
            e.shadowed += 1;
        } else {
            e.lit += 1;
        }
        if darker(m, r) {
            e.wrongly_shadowed += 1;
        } else if darker(r, m) {
            e.wrongly_lit += 1;
        }
    }
    e
}

/// Renders `prepared` with ray-cast shadows, without shadows, and with maps
/// of each (size, bias), returning the errors of each and the time of the map frame.
struct Bench {
    prepared: PreparedScene,
    renderer: &'static str,
    ray: Vec<Radiance>,
    unshadowed: Vec<Radiance>,
}

impl Bench {
    fn new(scene: Scene, renderer: &'static str) -> Bench {
        let prepared = PreparedScene::new(scene);
        let s = &prepared.scene;
        let ray = common::render(renderer, &prepared, &settings(s, ShadowMode::Ray, DEFAULT_SIZE, DEFAULT_BIAS));
        let unshadowed = common::render(renderer, &prepared, &settings(s, ShadowMode::None, DEFAULT_SIZE, DEFAULT_BIAS));
        Bench { prepared, renderer, ray, unshadowed }
    }

    fn map(&self, size: u32, bias: f32) -> (Errors, f64) {
        let start = Instant::now();
        let img = common::render(self.renderer, &self.prepared, &settings(&self.prepared.scene, ShadowMode::Map, size, bias));
        let ms = start.elapsed().as_secs_f64() * 1e3;
        (compare(&img, &self.ray, &self.unshadowed), ms)
    }
}

fn two_sided_scenes() -> Vec<Scene> {
    // Two-sided receivers and spheres can shadow themselves: where acne shows.
    vec![reference_scene("bunny_ground"), reference_scene("spheres_ground"), common::builtin("spheres")]
}

#[test]
fn default_bias_agrees_with_ray_cast_shadows() {
    let scenes: Vec<Scene> = ["bunny", "teapot", "spheres", "triangle-ground"]
        .iter()
        .map(|n| common::builtin(n))
        .chain(["bunny_ground", "spheres_ground"].iter().map(|n| reference_scene(n)))
        .collect();
    for scene in scenes {
        let name = scene.name.clone();
        for renderer in ["raytrace:bvh", "rasterize"] {
            let b = Bench::new(scene.clone(), renderer);
            let (e, _) = b.map(DEFAULT_SIZE, DEFAULT_BIAS);
            eprintln!("{name} {renderer}: {:.2}% differ {e:?}", e.percent());
            assert!(e.shadowed > 100, "{name}: the scene casts too little shadow to compare ({e:?})");
            assert!(e.percent() <= 0.5, "{name} {renderer}: {:.2}% of pixels differ from ray-cast shadows ({e:?})", e.percent());
        }
    }
}

#[test]
fn too_small_bias_shows_acne() {
    for scene in two_sided_scenes() {
        let name = scene.name.clone();
        let b = Bench::new(scene, "rasterize");
        let (acne, _) = b.map(512, 0.0);
        let (good, _) = b.map(512, DEFAULT_BIAS);
        eprintln!("{name}: bias 0 {acne:?}, default {good:?}");
        // Without bias about half the lit surface samples its own depth from a
        // texel centre nearer the light than itself: shadowed.
        assert!(acne.wrongly_shadowed * 5 > acne.lit, "{name}: too little acne at bias 0: {acne:?}");
        assert!(acne.wrongly_shadowed > 20 * good.wrongly_shadowed.max(1), "{name}: {acne:?} vs {good:?}");
        // Acne darkens; it does not light anything.
        assert!(acne.wrongly_lit * 100 < acne.pixels, "{name}: {acne:?}");
    }
    // A closed one-sided mesh over a one-sided ground stores only the faces
    // turned away from the light (what shadow rays can hit): no acne even without bias.
    let b = Bench::new(common::builtin("teapot"), "rasterize");
    let (e, _) = b.map(512, 0.0);
    assert!(e.percent() < 0.5, "teapot at bias 0: {e:?}");
}

/// The ray-cast distance from the shaded point to its blocker (first light
/// blocked), by replaying the pixel.
fn blocker_distance(b: &Bench, x: u32, y: u32) -> Option<f32> {
    let s = settings(&b.prepared.scene, ShadowMode::Ray, DEFAULT_SIZE, DEFAULT_BIAS);
    let r = renderer_by_name(b.renderer).unwrap();
    let replay = replay_pixel(r.as_ref(), &b.prepared, &s, x, y).ok()?;
    let trace = &replay.samples[0].1;
    trace.lights.iter().filter_map(|l| l.blocker.map(|b| b.t)).reduce(f32::min)
}

fn median(mut v: Vec<f32>) -> f32 {
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

#[test]
fn too_large_bias_shows_peter_panning() {
    let b = Bench::new(reference_scene("bunny_ground"), "raytrace:bvh");
    let s = settings(&b.prepared.scene, ShadowMode::Map, 256, 8.0);
    let map = common::render(b.renderer, &b.prepared, &s);
    let e = compare(&map, &b.ray, &b.unshadowed);
    eprintln!("bias 8 at 256: {e:?}");
    // A good part of the shadow is gone...
    assert!(e.wrongly_lit * 10 > e.shadowed, "too little peter-panning: {e:?}");
    assert!(e.wrongly_shadowed * 100 < e.pixels, "{e:?}");
    // ...and what is gone lies near the contact: the ray-cast blockers of the
    // wrongly lit pixels are much nearer than those of the shadow as a whole.
    let (mut lost, mut all) = (Vec::new(), Vec::new());
    for y in 0..H {
        for x in 0..W {
            let i = (x + y * W) as usize;
            if !darker(b.ray[i], b.unshadowed[i]) {
                continue;
            }
            let Some(t) = blocker_distance(&b, x, y) else { continue };
            all.push(t);
            if darker(b.ray[i], map[i]) {
                lost.push(t);
            }
        }
    }
    let (m_lost, m_all) = (median(lost.clone()), median(all.clone()));
    eprintln!("median blocker distance: lost {m_lost} ({} px), all shadow {m_all} ({} px)", lost.len(), all.len());
    assert!(m_lost < 0.5 * m_all, "lost shadow is not at the contact: median blocker {m_lost} vs {m_all}");
}

#[test]
fn error_falls_as_resolution_rises() {
    for scene in two_sided_scenes() {
        let name = scene.name.clone();
        let b = Bench::new(scene, "rasterize");
        let errors: Vec<f64> = [64u32, 256, 1024].iter().map(|&n| b.map(n, DEFAULT_BIAS).0.percent()).collect();
        eprintln!("{name}: % differing at 64, 256, 1024: {errors:?}");
        assert!(errors[0] > errors[1] && errors[1] > errors[2], "{name}: {errors:?}");
    }
}

fn plane_scene(light: Light) -> Scene {
    let text = r#"
        [camera]
        eye = [0.0, 3.0, 4.0]
        target = [0.0, 0.0, 0.0]
        [[object]]
        type = "quad"
        vertices = [[-5.0, 0.0, 5.0], [5.0, 0.0, 5.0], [5.0, 0.0, -5.0], [-5.0, 0.0, -5.0]]
        two_sided = true
        [[object]]
        type = "sphere"
        center = [0.0, 1.0, 0.0]
        radius = 0.5
    "#;
    let mut scene = pinhole::scene::file::parse_scene(text, "test", std::path::Path::new("."), "plane").unwrap();
    scene.lights = vec![light];
    scene
}

#[test]
fn point_light_depths_by_hand() {
    let scene = plane_scene(Light::Point { position: Vec3::new(0.0, 3.0, 0.0), power: Vec3::ONE });
    let maps = ShadowMaps::build(&scene, 64, false);
    let faces = &maps.maps[0].faces;
    assert_eq!(faces.len(), 6);
    // Straight down (-y, face 3): texel (32, 32)'s ray leaves the light at
    // tangent offsets (+1/64, -1/64) and meets the sphere's top (y = 1.5):
    // distance 1.5 along the axis, radial 1.5 sqrt(1 + 2 / 64^2).
    assert_eq!(cube_face(Vec3::new(0.1, -1.0, 0.2)), 3);
    let d = faces[3].depth[32 + 32 * 64];
    let axis = 1.5f32;
    let h = 1.0 / 64.0;
    // The sphere's surface a little off the top: solve for the entry point exactly.
    let u = Vec3::new(h, -1.0, -h).normalize();
    let f = Vec3::new(0.0, 2.0, 0.0);
    let b = -f.dot(u);
    let expect = b - (0.25 - (f + u * b).length_squared()).sqrt();
    assert!((d - expect).abs() < 1e-4, "sphere top: {d} vs {expect} (about {axis})");
    assert_eq!(faces[3].id[32 + 32 * 64], PrimitiveId::sphere(0));
    // A texel near the face's corner sees the plane 3 below: radial 3 sqrt(1 + sx^2 + sy^2).
    let (x, y) = (2u32, 2u32);
    let sx = 2.0 * (x as f32 + 0.5) / 64.0 - 1.0;
    let sy = 1.0 - 2.0 * (y as f32 + 0.5) / 64.0;
    let d = faces[3].depth[(x + y * 64) as usize];
    assert!((d - 3.0 * (1.0 + sx * sx + sy * sy).sqrt()).abs() < 1e-4, "plane: {d}");
    assert!(faces[3].id[(x + y * 64) as usize] < PrimitiveId::triangle(2), "a quad triangle");
    // Looking up (+y, face 2) there is nothing.
    assert!(faces[2].depth.iter().all(|d| d.is_infinite()));
    assert!(faces[2].id.iter().all(|i| i.is_none()));
}

#[test]
fn directional_map_is_fitted_to_the_casters() {
    let scene = plane_scene(Light::Directional { direction: Vec3::NEG_Y, irradiance: Vec3::ONE });
    let maps = ShadowMaps::build(&scene, 64, false);
    let face = &maps.maps[0].faces[0];
    assert!(face.ortho);
    // The 10 x 10 ground is huge next to the sphere: the map covers the
    // sphere's 1 x 1 footprint (plus a texel), not the ground.
    assert!((face.view.half_x - 0.5).abs() < 0.05 && (face.view.half_y - 0.5).abs() < 0.05, "{} {}", face.view.half_x, face.view.half_y);
    // Depth is measured along the light from the sphere's centre: its top at -0.5.
    let d = face.depth[32 + 32 * 64];
    assert!((d + 0.5).abs() < 1e-3, "{d}");
    // Corners of the map miss the sphere and see the ground, 1 below the centre.
    assert!((face.depth[0] - 1.0).abs() < 1e-4, "{}", face.depth[0]);
}

#[test]
fn maps_do_not_depend_on_threads() {
    let scene = reference_scene("bunny_ground");
    let a = ShadowMaps::build(&scene, 128, false);
    let b = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| ShadowMaps::build(&scene, 128, true));
    for (fa, fb) in a.maps[0].faces.iter().zip(&b.maps[0].faces) {
        assert!(fa.depth == fb.depth && fa.id == fb.id);
    }
    // Both renderer families see the same map shadows where they see the same surfaces.
    let prepared = PreparedScene::new(scene);
    let s = settings(&prepared.scene, ShadowMode::Map, 256, DEFAULT_BIAS);
    let one = common::render_with_threads(1, "raytrace:bvh", &prepared, &s);
    let two = common::render_with_threads(2, "raytrace:bvh", &prepared, &s);
    assert!(one == two);
}

#[test]
fn pixel_replay_records_the_map_lookup() {
    let b = Bench::new(reference_scene("bunny_ground"), "raytrace:bvh");
    let s = settings(&b.prepared.scene, ShadowMode::Map, 512, DEFAULT_BIAS);
    let frame = common::render(b.renderer, &b.prepared, &s);
    let r = renderer_by_name(b.renderer).unwrap();
    // A pixel in the bunny's shadow on the ground, in both methods.
    let i = (0..frame.len()).find(|&i| darker(b.ray[i], b.unshadowed[i]) && darker(frame[i], b.unshadowed[i])).expect("a shadowed pixel");
    let (x, y) = (i as u32 % W, i as u32 / W);
    let replay = replay_pixel(r.as_ref(), &b.prepared, &s, x, y).unwrap();
    assert_eq!(replay.radiance, frame[i], "replay equals the frame");
    let trace = &replay.samples[0].1;
    assert!(trace.rays.iter().all(|r| !r.shadow), "no shadow ray is cast");
    let light = &trace.lights[0];
    assert!(light.shadow_ray.is_none());
    let t = light.blocker.expect("the map names the blocker").t;
    assert!(t > 0.0 && t < light.distance, "{t}");
    assert_eq!(light.contribution, Vec3::ZERO);
}

#[test]
fn shadowmap_view_lays_out_the_cube_faces() {
    let prepared = PreparedScene::new(reference_scene("bunny_ground"));
    let s = RenderSettings { width: 300, height: 200, view: View::Shadowmap, shadow_map_size: 128, ..RenderSettings::for_scene(&prepared.scene) };
    for renderer in ["raytrace:bvh", "rasterize"] {
        let img = common::render(renderer, &prepared, &s);
        // One point light: faces of 100 x 100 in a 3 x 2 grid (+x -x +y / -y +z -z).
        let darkest = (0..img.len()).min_by(|&a, &b| img[a].x.total_cmp(&img[b].x)).unwrap();
        let (x, y) = (darkest % 300, darkest / 300);
        assert!(x < 100 && y >= 100, "{renderer}: the ground below the light (face -y) is nearest, found ({x}, {y})");
        // Looking up (+y) sees nothing: white.
        assert_eq!(img[250 + 50 * 300], Vec3::ONE, "{renderer}");
        assert!(img.iter().all(|c| c.is_finite() && c.x >= 0.0 && c.x <= 1.0));
    }
}

#[test]
fn settings_without_shadow_map_fields_still_load() {
    let scene = common::builtin("bunny");
    let s = RenderSettings::for_scene(&scene);
    let mut j = serde_json::to_value(&s).unwrap();
    let o = j.as_object_mut().unwrap();
    assert!(o.remove("shadow_map_size").is_some() && o.remove("shadow_map_bias").is_some());
    let back: RenderSettings = serde_json::from_value(j).unwrap();
    assert_eq!((back.shadow_map_size, back.shadow_map_bias), (DEFAULT_SIZE, DEFAULT_BIAS));
}

#[test]
fn cli_flags_and_their_errors() {
    let run = |args: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().unwrap();
    let out_png = std::env::temp_dir().join(format!("pinhole-shadow-map-{}.png", std::process::id()));
    let o = out_png.to_str().unwrap();
    for (arg, needle) in [("--shadow-map-size=0", "--shadow-map-size 0"), ("--shadow-map-size=100000", "between 1 and"), ("--shadow-bias=-1", "--shadow-bias -1"), ("--shadow-bias=nan", "--shadow-bias NaN")] {
        let out = run(&["render", "bunny", "-o", o, "--shadows", "map", arg]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.trim().lines().count() == 1 && err.contains(needle), "{arg}: {err}");
    }
    let out = run(&["render", "spheres", "-o", o, "--width", "60", "--height", "40", "--shadows", "map", "--shadow-map-size", "64", "--shadow-bias", "2", "--stats", "-"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((j["shadows"].as_str(), j["shadow_map_size"].as_u64(), j["shadow_map_bias"].as_f64()), (Some("map"), Some(64), Some(2.0)));
    assert_eq!(j["shadow_rays"], 0);
    assert!(j["shadow_map_ms"].as_f64().unwrap() > 0.0);
    let out = run(&["render", "spheres", "-o", o, "--width", "60", "--height", "40", "--view", "shadowmap"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_file(&out_png);
}

/// The README's table: error against map size and bias, with times, on the
/// reference scenes at their own resolution.
#[test]
#[ignore]
fn table_of_error_against_size_and_bias() {
    const BIASES: [f32; 7] = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 16.0];
    let head: Vec<String> = BIASES.iter().map(|b| format!("bias {b}")).collect();
    println!("| scene | map size | build ms | frame ms (map) | frame ms (ray) | {} |", head.join(" | "));
    println!("|---|---|---|---|---|{}", "---|".repeat(BIASES.len()));
    for scene in [reference_scene("bunny_ground"), reference_scene("spheres_ground"), common::builtin("teapot"), common::builtin("spheres")] {
        let (w, h) = (scene.render.width, scene.render.height);
        let prepared = PreparedScene::new(scene);
        let sc = &prepared.scene;
        let at = |shadows, size, bias| RenderSettings { width: w, height: h, ..settings(sc, shadows, size, bias) };
        let time = |s: &RenderSettings| {
            let mut best = f64::INFINITY;
            let mut img = Vec::new();
            for _ in 0..3 {
                let t = Instant::now();
                img = common::render("rasterize", &prepared, s);
                best = best.min(t.elapsed().as_secs_f64() * 1e3);
            }
            (img, best)
        };
        let (ray, ray_ms) = time(&at(ShadowMode::Ray, DEFAULT_SIZE, DEFAULT_BIAS));
        let unshadowed = common::render("rasterize", &prepared, &at(ShadowMode::None, DEFAULT_SIZE, DEFAULT_BIAS));
        for size in [128u32, 256, 512, 1024, 2048] {
            let build = (0..3).map(|_| ShadowMaps::build(sc, size, true).build_ms).fold(f64::INFINITY, f64::min);
            let mut cells = Vec::new();
            let mut map_ms = 0.0;
            for bias in BIASES {
                let (img, ms) = time(&at(ShadowMode::Map, size, bias));
                if bias == DEFAULT_BIAS {
                    map_ms = ms;
                }
                let e = compare(&img, &ray, &unshadowed);
                cells.push(format!("{:.2}% ({:.2} / {:.2})", e.percent(), 100.0 * e.wrongly_shadowed as f64 / e.pixels as f64, 100.0 * e.wrongly_lit as f64 / e.pixels as f64));
            }
            println!("| {} {w}x{h} | {size} | {build:.0} | {map_ms:.0} | {ray_ms:.0} | {} |", sc.name, cells.join(" | "));
        }
    }
}
