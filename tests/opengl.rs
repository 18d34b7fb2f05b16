//! The `opengl` renderer against the brute-force ray caster on every
//! built-in scene (CSG and the forests' copies included), with `--shadows
//! none` (GL casts no shadow rays) and with `--shadows map` (GL's maps
//! against the CPU's) where the scene allows maps: at least 99% of pixels
//! within 1e-3 relative. The rest lie on silhouettes, where GL's coverage
//! (vertices snapped to 1/256 pixel, its own fill rule) and the ray test
//! decide differently, and where GPU float (interpolated positions and
//! normals, `pow`) rounds otherwise.
//!
//! The reference pixels come from `raytrace:bvh`, which gives brute
//! force's pixels exactly (tested with the BVH), in a fraction of the time.
//!
//! Without a usable OpenGL driver the tests print why and pass: the
//! renderer then refuses with one sentence, which is checked instead. With
//! `PINHOLE_REQUIRE_GL=1` (as CI runs them) a missing driver fails them
//! instead (see `driver`).

use pinhole::math::{Radiance, Vec3};
use pinhole::render::{render_frame, renderer_by_name, Interpolation, PreparedScene, RenderSettings, Renderer, ShadowMode};
use pinhole::scene::Scene;
use std::sync::atomic::AtomicBool;

mod common;
use common::{corner_form_factor, floor_under};

const W: u32 = 200;
const H: u32 = 125;

/// A built-in scene as the agreement tests draw it: the environment kept
/// for what rays that miss and mirrors see, but not as a light, which GL
/// samples by a fixed pattern of directions and the CPU renderers by
/// random ones (compared on their own,
/// `gl_environment_light_agrees_with_the_cpu_without_shadows`).
fn scene(name: &str) -> Scene {
    let mut sc = pinhole::scene::builtin::load_builtin(name).unwrap().unwrap();
    if let Some(env) = sc.environment.as_mut() {
        env.light = None;
    }
    sc
}

fn settings(scene: &Scene) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.width = W;
    s.height = H;
    s.shadows = ShadowMode::None;
    s
}

fn render(r: &dyn Renderer, prepared: &PreparedScene, settings: &RenderSettings) -> Vec<Radiance> {
    render_frame(r, prepared, settings, &AtomicBool::new(false), None).unwrap().pixels
}

/// Within 1e-3 relative per channel (1e-6 absolute near black).
fn close(a: Vec3, b: Vec3) -> bool {
    let d = (a - b).abs();
    let m = a.abs().max(b.abs());
    d.x <= 1e-3 * m.x + 1e-6 && d.y <= 1e-3 * m.y + 1e-6 && d.z <= 1e-3 * m.z + 1e-6
}

/// Set to `1` where a driver must exist (CI installs Mesa): a test that
/// would skip for want of one fails instead.
const REQUIRE_GL: &str = "PINHOLE_REQUIRE_GL";

/// The driver, or `None` after printing why the test is skipped. Every test
/// that needs GL starts here. Panics instead of skipping when
/// `PINHOLE_REQUIRE_GL=1`, so that a machine meant to run these tests
/// cannot pass them without running them.
fn driver() -> Option<String> {
    match pinhole::render::opengl::driver() {
        Ok(d) => Some(d),
        Err(e) if std::env::var(REQUIRE_GL).is_ok_and(|v| v == "1") => panic!("{REQUIRE_GL}=1 but there is no OpenGL driver: {e}"),
        Err(e) => {
            eprintln!("skipped: {e}");
            None
        }
    }
}

/// Fraction of pixels that agree, and the largest relative difference seen.
fn agreement(a: &[Radiance], b: &[Radiance]) -> (f64, usize) {
    let ok = a.iter().zip(b).filter(|(x, y)| close(**x, **y)).count();
    (ok as f64 / a.len() as f64, a.len() - ok)
}

/// The scenes the agreement test draws at `W` x `H`: every built-in one
/// (`textures` with its mirror by --reflections env), `forest-100` and
/// `forest-1`; `forest` has a test of its own.
/// Every built-in scene GL draws, but those lit by area lights and those
/// under classic lighting. GL lights area-lit scenes by a fixed pattern of
/// light samples, the CPU renderers by random ones, so their pixels differ
/// by design (the area lights' shadows are compared on their own,
/// `area_light_shadow_filters_in_gl_agree_with_the_cpu_maps`); classic
/// lighting it refuses (`admit`'s tests and `tests/classic_lighting.rs`
/// check that it says so).
fn agreement_scenes() -> Vec<&'static str> {
    let mut names = pinhole::scene::builtin::names();
    names.retain(|n| scene(n).emitters.is_empty() && scene(n).render.lighting == pinhole::scene::Lighting::Physical);
    names.extend(pinhole::scene::builtin::large_names().into_iter().filter(|n| *n != "forest"));
    names
}

/// `opengl` against the reference on `name` with `s`: the share of pixels
/// within 1e-3 and how many differ.
fn agreement_on(name: &str, s: &RenderSettings) -> (f64, usize) {
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let sc = scene(name);
    if let Err(e) = gl.check(&sc, s) {
        panic!("{name}: refused: {e}");
    }
    let prepared = PreparedScene::new(sc.clone());
    let a = render(gl.as_ref(), &prepared, s);
    let b = render(reference_renderer.as_ref(), &prepared, s);
    assert!(a.iter().all(|p| p.is_finite()), "{name}: a pixel is not finite");
    agreement(&a, &b)
}

#[test]
fn every_builtin_scene_agrees_with_brute_force() {
    // Nothing is refused: CSG objects are evaluated in the fragment
    // shader, the forests' copies instanced. Measured at 200x125 on
    // llvmpipe: 99.92% or more everywhere (worst forest-100 flat; csg,
    // spheres and textures 100%).
    let Some(driver) = driver() else { return };
    eprintln!("driver: {driver}");
    let mut worst = (1.0f64, String::new());
    let mut drawn = 0;
    for name in agreement_scenes() {
        let sc = scene(name);
        for interpolation in [Interpolation::Phong, Interpolation::Flat] {
            let s = RenderSettings { interpolation, reflections: pinhole::render::Reflections::Env, ..settings(&sc) };
            let (fraction, wrong) = agreement_on(name, &s);
            eprintln!("{name} {interpolation:?}: {:.3}% agree ({wrong} pixels differ)", fraction * 100.0);
            assert!(fraction >= 0.99, "{name} {interpolation:?}: only {:.3}% of pixels within 1e-3", fraction * 100.0);
            if fraction < worst.0 {
                worst = (fraction, format!("{name} {interpolation:?}"));
            }
            drawn += 1;
        }
    }
    eprintln!("worst: {} at {:.3}%", worst.1, worst.0 * 100.0);
    assert_eq!(drawn, 2 * agreement_scenes().len());
}

/// Each diffuse model and Fresnel term in the fragment shader against the
/// ray caster, on `spheres` and `teapot` with every material given the
/// model (and a glossy lobe, for the Fresnel terms): at least 99% of
/// pixels within 1e-3, per model. And the comparison can fail: the shader
/// drawing Lambert where the ray caster draws Oren-Nayar does not pass.
#[test]
fn each_reflection_model_agrees_with_the_ray_caster() {
    use pinhole::scene::material::{DiffuseModel, Fresnel};
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let conductor = Fresnel::Conductor { eta: Vec3::new(0.2, 0.9, 1.1), k: Vec3::new(3.9, 2.4, 2.2) };
    let variants = [
        ("oren-nayar", DiffuseModel::OrenNayar { sigma: 0.5 }, Fresnel::None),
        ("minnaert", DiffuseModel::Minnaert { darkening: 0.4 }, Fresnel::None),
        ("toon", DiffuseModel::Toon { bands: 3 }, Fresnel::None),
        ("schlick", DiffuseModel::Lambert, Fresnel::Schlick),
        ("conductor", DiffuseModel::Lambert, conductor),
    ];
    let with = |name: &str, diffuse: DiffuseModel, fresnel: Fresnel| {
        let mut sc = scene(name);
        for m in &mut sc.materials {
            m.diffuse_model = diffuse;
            m.fresnel = fresnel;
            if fresnel != Fresnel::None && !m.has_glossy() {
                m.glossy = Vec3::splat(0.3);
            }
        }
        sc
    };
    for name in ["spheres", "teapot"] {
        for (label, diffuse, fresnel) in variants {
            let sc = with(name, diffuse, fresnel);
            let s = settings(&sc);
            if let Err(e) = gl.check(&sc, &s) {
                panic!("{name} {label}: refused: {e}");
            }
            let prepared = PreparedScene::new(sc);
            let (a, b) = (render(gl.as_ref(), &prepared, &s), render(reference_renderer.as_ref(), &prepared, &s));
            assert!(a.iter().all(|p| p.is_finite()), "{name} {label}: a pixel is not finite");
            let (fraction, wrong) = agreement(&a, &b);
            eprintln!("{name} {label}: {:.3}% agree ({wrong} pixels differ)", fraction * 100.0);
            assert!(fraction >= 0.99, "{name} {label}: only {:.3}% of pixels within 1e-3", fraction * 100.0);
        }
    }
    let rough = PreparedScene::new(with("spheres", DiffuseModel::OrenNayar { sigma: 0.5 }, Fresnel::None));
    let lambert = PreparedScene::new(with("spheres", DiffuseModel::Lambert, Fresnel::None));
    let s = settings(&rough.scene);
    let (fraction, _) = agreement(&render(gl.as_ref(), &lambert, &s), &render(reference_renderer.as_ref(), &rough, &s));
    assert!(fraction < 0.99, "Lambert passes for Oren-Nayar on {:.2}% of pixels", fraction * 100.0);
}

/// Ward's anisotropic lobe in the shader against the ray caster: on
/// spheres (the tangent along the latitude), on meshes with uvs (the
/// tangents from the uvs) and on triangles without (the fixed
/// perpendicular).
/// GL drawing the lobe turned by a quarter (alphas swapped) must not pass.
#[test]
fn ward_agrees_with_the_ray_caster() {
    use pinhole::scene::material::GlossyModel;
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let ward = |name: &str, au: f32, av: f32| {
        let mut sc = scene(name);
        for m in &mut sc.materials {
            m.glossy_model = GlossyModel::Ward;
            m.roughness_uv = glam::Vec2::new(au, av);
            m.glossy = Vec3::splat(0.5);
            // GL traces no mirror rays: the lobe alone is compared.
            m.mirror = Vec3::ZERO;
            m.transmission = Vec3::ZERO;
        }
        // The uvs' tangents, as a scene file naming Ward would have built them.
        sc.tangents = pinhole::scene::tangents::build_tangents(&sc);
        PreparedScene::new(sc)
    };
    for name in ["spheres", "textures", "teapot"] {
        let prepared = ward(name, 0.08, 0.4);
        let s = settings(&prepared.scene);
        if let Err(e) = gl.check(&prepared.scene, &s) {
            panic!("{name}: refused: {e}");
        }
        let (a, b) = (render(gl.as_ref(), &prepared, &s), render(reference_renderer.as_ref(), &prepared, &s));
        assert!(a.iter().all(|p| p.is_finite()), "{name}: a pixel is not finite");
        let (fraction, wrong) = agreement(&a, &b);
        eprintln!("{name} ward: {:.3}% agree ({wrong} pixels differ)", fraction * 100.0);
        assert!(fraction >= 0.99, "{name} ward: only {:.3}% of pixels within 1e-3", fraction * 100.0);
    }
    let (along, across) = (ward("spheres", 0.08, 0.4), ward("spheres", 0.4, 0.08));
    let s = settings(&along.scene);
    let (fraction, _) = agreement(&render(gl.as_ref(), &across, &s), &render(reference_renderer.as_ref(), &along, &s));
    assert!(fraction < 0.99, "the lobe turned by a quarter passes on {:.2}% of pixels", fraction * 100.0);
}

#[test]
fn the_forest_of_ten_thousand_copies_agrees_with_brute_force() {
    // 10,000 bunny copies (694 M triangles, never flattened): one mesh in
    // GL's buffers, each copy placed per instance. At 640x360 99.60% of
    // pixels agree; at 200x125 only 98.4%, where whole bunnies near the
    // horizon are a few pixels tall and GL's coverage (vertices snapped to
    // 1/256 pixel) picks another sub-pixel triangle than the ray: the CPU's
    // fixed-point rasterizer, snapping as GL does, differs on the very
    // same number of pixels there (393) and on 907 at 640x360.
    let Some(_) = driver() else { return };
    let sc = scene("forest");
    let s = RenderSettings { width: 640, height: 360, ..settings(&sc) };
    let (fraction, wrong) = agreement_on("forest", &s);
    eprintln!("forest 640x360: {:.3}% agree ({wrong} pixels differ)", fraction * 100.0);
    assert!(fraction >= 0.99, "forest: only {:.3}% of pixels within 1e-3", fraction * 100.0);
}

#[test]
fn a_wrong_light_or_camera_fails_the_comparison() {
    // The comparison above would notice a broken shader: dimming the light
    // in one renderer only, or moving its camera by a pixel, breaks it.
    if driver().is_none() {
        return;
    }
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let sc = scene("teapot");
    let s = settings(&sc);
    let reference = render(reference_renderer.as_ref(), &PreparedScene::new(sc.clone()), &s);
    let mut dim = sc.clone();
    if let Some(pinhole::scene::Light::Point { power, .. }) = dim.lights.first_mut() {
        *power *= 0.99;
    }
    let (f, _) = agreement(&render(gl.as_ref(), &PreparedScene::new(dim), &s), &reference);
    assert!(f < 0.99, "a 1% dimmer light still agrees on {:.2}%", f * 100.0);
    let mut moved = sc.clone();
    let step = (moved.camera.target - moved.camera.eye).length() * 0.01;
    moved.camera.eye.x += step;
    moved.camera.target.x += step;
    let (f, _) = agreement(&render(gl.as_ref(), &PreparedScene::new(moved), &s), &reference);
    assert!(f < 0.99, "a moved camera still agrees on {:.2}%", f * 100.0);
}

#[test]
fn shadow_maps_drawn_by_gl_agree_with_the_cpu_maps() {
    // --shadows map: GL draws each light's map from the CPU maps' own
    // cameras and looks it up as the CPU does; against the ray caster with
    // the CPU's maps. GL's stored depths are interpolated rather than taken
    // from the triangle's plane, and its map coverage follows GL's rules,
    // so a texel near a shadow boundary may decide otherwise.
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let mut worst = (1.0f64, "");
    for name in pinhole::scene::builtin::names() {
        let sc = scene(name);
        let s = RenderSettings { shadows: ShadowMode::Map, ..settings(&sc) };
        if gl.check(&sc, &s).is_err() {
            continue;
        }
        let prepared = PreparedScene::new(sc.clone());
        let a = render(gl.as_ref(), &prepared, &s);
        let (fraction, wrong) = agreement(&a, &render(reference_renderer.as_ref(), &prepared, &s));
        eprintln!("{name} map: {:.3}% agree ({wrong} pixels differ)", fraction * 100.0);
        assert!(fraction >= MAP_AGREEMENT, "{name}: only {:.3}% of pixels within 1e-3", fraction * 100.0);
        if fraction < worst.0 {
            worst = (fraction, name);
        }
        // The maps shadow something: without them the image differs.
        if name == "stress-shadow" || name == "teapot" {
            let none = render(gl.as_ref(), &prepared, &settings(&sc));
            assert!(agreement(&a, &none).0 < 0.99, "{name}: the maps change nothing");
        }
    }
    eprintln!("worst with maps: {} at {:.3}%", worst.1, worst.0 * 100.0);
}

/// The share of pixels GL's shadow maps must agree on (see the test).
const MAP_AGREEMENT: f64 = 0.99;

#[test]
fn sample_passes_follow_the_sample_positions() {
    // --spp 4: four passes at the stratified positions, averaged as for the CPU renderers.
    if driver().is_none() {
        return;
    }
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let sc = scene("spheres");
    let s = RenderSettings { spp: 4, ..settings(&sc) };
    let prepared = PreparedScene::new(sc);
    let (f, wrong) = agreement(&render(gl.as_ref(), &prepared, &s), &render(reference_renderer.as_ref(), &prepared, &s));
    assert!(f >= 0.99, "spp 4: {:.3}% agree ({wrong} differ)", f * 100.0);
}

#[test]
fn unsupported_settings_are_refused_in_one_sentence() {
    let gl = renderer_by_name("opengl").unwrap();
    let sc = scene("teapot");
    let mut s = settings(&sc);
    s.shadows = ShadowMode::Ray;
    let e = gl.check(&sc, &s).unwrap_err();
    assert!(e.contains("--shadows none|map"), "{e}");
    assert!(!e.contains('\n'));
    // Mirrors only by environment lookups; glass not at all.
    let textured = scene("textures");
    let e = gl.check(&textured, &settings(&textured)).unwrap_err();
    assert!(e.contains("--reflections env") && !e.contains('\n'), "{e}");
    let mut glass = scene("teapot");
    glass.materials[0].transmission = Vec3::splat(0.5);
    let s = RenderSettings { reflections: pinhole::render::Reflections::Env, ..settings(&glass) };
    let e = gl.check(&glass, &s).unwrap_err();
    assert!(e.contains("glass") && !e.contains('\n'), "{e}");
}

fn pinhole(args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_pinhole"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

#[test]
fn render_teapot_headless_writes_an_exr() {
    if driver().is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("pinhole-opengl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("x.exr");
    let run = pinhole(&["render", "teapot", "--renderer", "opengl", "--width", "160", "--height", "100", "-o", out.to_str().unwrap()], &[]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let img = image::open(&out).unwrap().into_rgb32f();
    assert_eq!(img.dimensions(), (160, 100));
    assert!(img.pixels().any(|p| p.0[0] > 0.0), "the teapot is drawn");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn without_a_driver_opengl_says_so_and_the_rest_works() {
    // glvnd finds no EGL vendor library: no driver at all.
    let no_egl = [("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json")];
    let dir = std::env::temp_dir().join(format!("pinhole-nogl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("x.png");
    let run = pinhole(&["render", "one-triangle", "--renderer", "opengl", "--width", "40", "--height", "25", "-o", out.to_str().unwrap()], &no_egl);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    // The error is one sentence; the note on shadow rays (said before the
    // driver is looked for) comes before it.
    let errors: Vec<&str> = err.trim().lines().filter(|l| !l.starts_with("note: ")).collect();
    assert!(errors.len() == 1 && errors[0].contains("no usable OpenGL driver") && !err.contains("panicked"), "{err}");
    assert!(err.contains("note: opengl cannot trace shadow rays; drawing shadow maps instead"), "{err}");
    let run = pinhole(&["render", "one-triangle", "--renderer", "rasterize", "--width", "40", "--height", "25", "-o", out.to_str().unwrap()], &no_egl);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

/// Within `tol` relative per channel (1e-6 absolute near black).
fn close_within(a: Vec3, b: Vec3, tol: f32) -> bool {
    let d = (a - b).abs();
    let m = a.abs().max(b.abs());
    d.x <= tol * m.x + 1e-6 && d.y <= tol * m.y + 1e-6 && d.z <= tol * m.z + 1e-6
}

#[test]
fn textures_filtered_in_the_shader_agree_with_brute_force() {
    // The textures scene (mirror by --reflections env) with each filter
    // against the ray caster: the shaders read the CPU's own pyramid texel
    // by texel and filter it in float at the CPU's level of detail, and
    // take latitudes and longitudes with float-precise asin and atan (the
    // driver's asin is an approximation off by about 1e-4, which moved
    // the globe's and the environment's rows). What is left differs where
    // GL's interpolated uv rounds otherwise at a texel boundary.
    use pinhole::render::Reflections;
    use pinhole::scene::texture::TextureFilter;
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let reference_renderer = renderer_by_name("raytrace:bvh").unwrap();
    let sc = scene("textures");
    let prepared = PreparedScene::new(sc.clone());
    // (filter, share within 1e-3, share within 1e-2) required; measured
    // 100/100, 99.96/100 and 100/100% at 160x100 on llvmpipe (GL's own
    // filtering and asin gave 99.98, 98.9 and 98.5% within 1e-3).
    for (filter, tight, loose) in [
        (TextureFilter::Nearest, 0.999, 0.999),
        (TextureFilter::Bilinear, 0.995, 0.999),
        (TextureFilter::Trilinear, 0.995, 0.999),
        (TextureFilter::MipmapNearest, 0.995, 0.999),
        (TextureFilter::Anisotropic8, 0.995, 0.999),
    ] {
        let s = RenderSettings { width: 160, height: 100, texture_filter: filter, reflections: Reflections::Env, ..settings(&sc) };
        gl.check(&sc, &s).unwrap();
        let a = render(gl.as_ref(), &prepared, &s);
        let b = render(reference_renderer.as_ref(), &prepared, &s);
        assert!(a.iter().all(|p| p.is_finite()));
        let share = |tol: f32| a.iter().zip(&b).filter(|(x, y)| close_within(**x, **y, tol)).count() as f64 / a.len() as f64;
        let (f3, f2, f1) = (share(1e-3), share(1e-2), share(1e-1));
        eprintln!("textures {filter:?}: {:.3}% within 1e-3, {:.3}% within 1e-2, {:.3}% within 1e-1", f3 * 100.0, f2 * 100.0, f1 * 100.0);
        assert!(f3 >= tight && f2 >= loose, "textures {filter:?}: {:.3}% within 1e-3, {:.3}% within 1e-2", f3 * 100.0, f2 * 100.0);
    }
}

#[test]
fn msaa_through_gl_multisampling_is_close_to_the_cpu_rasterizers() {
    // --msaa 4: a multisampled framebuffer resolved by glBlitFramebuffer,
    // against the CPU rasterizer's MSAA. The image is drawn upside down so
    // that GL's standard 4-sample pattern lands on the CPU's D3D positions,
    // but GL shades a partly covered triangle at its centroid (the CPU: the
    // covered sample nearest the centre), so pixels on every edge, shared
    // edges inside a mesh too, are shaded at a slightly different point;
    // and its coverage follows its own vertex snapping.
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let cpu = renderer_by_name("rasterize").unwrap();
    let max = pinhole::render::opengl::max_samples().unwrap();
    for name in ["teapot", "spheres"] {
        let sc = scene(name);
        let s = RenderSettings { width: 160, height: 100, msaa: 4, ..settings(&sc) };
        gl.check(&sc, &s).unwrap();
        let prepared = PreparedScene::new(sc.clone());
        let a = render(gl.as_ref(), &prepared, &s);
        let b = render(cpu.as_ref(), &prepared, &s);
        let one = render(gl.as_ref(), &prepared, &RenderSettings { msaa: 1, ..s.clone() });
        assert!(a.iter().all(|p| p.is_finite()));
        let share = |x: &[Radiance], y: &[Radiance], tol: f32| x.iter().zip(y).filter(|(p, q)| close_within(**p, **q, tol)).count() as f64 / x.len() as f64;
        let (f3, f2) = (share(&a, &b, 1e-3), share(&a, &b, 1e-2));
        let changed = 1.0 - share(&a, &one, 1e-3);
        let rms = |x: &[Radiance], y: &[Radiance]| (x.iter().zip(y).map(|(p, q)| (*p - *q).length_squared() as f64).sum::<f64>() / x.len() as f64).sqrt();
        eprintln!(
            "{name} msaa 4: {:.3}% within 1e-3 and {:.3}% within 1e-2 of rasterize's; {:.2}% of pixels changed by MSAA; rms gl-cpu {:.5}, gl 1x-cpu 4x {:.5}",
            f3 * 100.0,
            f2 * 100.0,
            changed * 100.0,
            rms(&a, &b),
            rms(&one, &b)
        );
        assert!(changed > 0.005, "{name}: MSAA changed nothing");
        // Measured: teapot 84.2% / 93.9%, spheres 91.3% / 97.2%.
        assert!(f3 >= 0.8 && f2 >= 0.9, "{name}: only {:.3}% within 1e-3, {:.3}% within 1e-2", f3 * 100.0, f2 * 100.0);
        assert!(rms(&a, &b) < 0.5 * rms(&one, &b), "{name}: GL's MSAA is no closer to the CPU's than no MSAA");
    }
    let too_many = RenderSettings { msaa: 8, ..settings(&scene("teapot")) };
    if max < 8 {
        let e = gl.ready(&too_many).unwrap_err();
        assert!(e.contains("at most") && !e.contains('\n'), "{e}");
    }
}

#[test]
fn debug_views_from_gl_render_targets_agree_with_the_rasterizers() {
    // Each debug view GL draws: its fragments write the surface record
    // into extra render targets, coloured on the CPU by the same
    // `view_color` as every renderer, against `rasterize`'s view. What
    // differs lies on silhouettes (coverage), and where a view quantizes
    // (the uv checker's squares, an id's colour) a rounding apart.
    use pinhole::render::inspect::debug::View;
    use pinhole::render::Reflections;
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let cpu = renderer_by_name("rasterize").unwrap();
    let views = [View::Depth, View::Zbuffer, View::Normal, View::Barycentric, View::Id, View::Uv, View::Raydir, View::GeometricNormal, View::TriangleId, View::MaterialId];
    for name in ["teapot", "spheres", "test-pattern", "textures"] {
        let sc = scene(name);
        let prepared = PreparedScene::new(sc.clone());
        for view in views {
            let s = RenderSettings { width: 160, height: 100, view, reflections: Reflections::Env, ..settings(&sc) };
            gl.check(&sc, &s).unwrap();
            let a = render(gl.as_ref(), &prepared, &s);
            let b = render(cpu.as_ref(), &prepared, &s);
            assert!(a.iter().all(|p| p.is_finite()));
            // (The spheres scene has no triangles: its barycentric view is black.)
            if view != View::Barycentric {
                assert!(a.iter().filter(|p| **p != Vec3::ZERO).count() > a.len() / 10, "{name} {view:?}: nothing drawn");
            }
            let ok = a.iter().zip(&b).filter(|(x, y)| (**x - **y).abs().max_element() <= VIEW_TOLERANCE).count() as f64 / a.len() as f64;
            eprintln!("{name} {view:?}: {:.3}% within {VIEW_TOLERANCE}", ok * 100.0);
            assert!(ok >= 0.99, "{name} {view:?}: only {:.3}% of pixels within {VIEW_TOLERANCE}", ok * 100.0);
        }
    }
    let s = RenderSettings { view: View::Cost, ..settings(&scene("teapot")) };
    let e = gl.check(&scene("teapot"), &s).unwrap_err();
    assert!(e.contains("--view") && !e.contains('\n'), "{e}");
}

/// Largest per-channel difference of a debug view's colour counted as agreeing.
const VIEW_TOLERANCE: f32 = 1e-3;

#[test]
fn a_clicked_pixel_reports_what_gl_read_back() {
    // Not a replay: the row is drawn again and the render targets read at
    // the pixel. The surface is the one the ray caster finds there, and
    // the output is the frame's pixel.
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let sc = scene("teapot");
    let s = RenderSettings { width: 160, height: 100, ..settings(&sc) };
    let prepared = PreparedScene::new(sc.clone());
    let frame = render(gl.as_ref(), &prepared, &s);
    let brute = renderer_by_name("raytrace:brute").unwrap();
    let (x, y) = (80, 55);
    let replay = pinhole::render::replay_pixel(gl.as_ref(), &prepared, &s, x, y).unwrap();
    assert_eq!(replay.radiance, frame[(x + y * s.width) as usize]);
    let r = replay.samples[0].1.gl_readback.clone().expect("a GL readback");
    let h = r.surface.expect("the teapot is under the pixel");
    let reference = pinhole::render::replay_pixel(brute.as_ref(), &prepared, &s, x, y).unwrap();
    let hit = reference.samples[0].1.rays[0].closest.expect("brute force hits it too");
    assert_eq!((h.kind, h.primitive, h.object, h.material), (hit.kind, hit.primitive, hit.object, hit.material));
    assert!((h.position - hit.position).length() < 1e-3 * hit.t, "{} vs {}", h.position, hit.position);
    assert!((h.shading_normal - hit.shading_normal).length() < 1e-3, "{} vs {}", h.shading_normal, hit.shading_normal);
    assert!((h.barycentric - hit.barycentric).abs().max_element() < 1e-3);
    // A corner sees the background: no fragment.
    let corner = pinhole::render::replay_pixel(gl.as_ref(), &prepared, &s, 0, 0).unwrap();
    assert!(corner.samples[0].1.gl_readback.as_ref().unwrap().surface.is_none());
    // The CLI's pixel command says what it is.
    let run = pinhole(&["pixel", "teapot", "80", "55", "--renderer", "opengl", "--width", "160", "--height", "100", "--shadows", "none"], &[]);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(text.contains("GL readback, not a replay"), "{text}");
}

/// Per pixel, the fraction of the area light's direct light that a shadow
/// map lets through: the image with maps over the image without shadows,
/// where the light reaches (luminance above `LIT`); `None` elsewhere. With
/// one area light, no other light, no ambient term and `--mis off`, every
/// light sample of a pixel is multiplied by the same visibility, and the
/// samples drawn do not depend on the shadow mode, so the ratio is that
/// visibility exactly, whatever pattern of light samples a renderer uses.
fn visibility(mapped: &[Radiance], open: &[Radiance]) -> Vec<Option<f32>> {
    let lum = |c: Radiance| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    mapped.iter().zip(open).map(|(m, o)| (lum(*o) > LIT).then(|| lum(*m) / lum(*o))).collect()
}

/// Luminance below which a pixel counts as unlit by the area light.
const LIT: f32 = 1e-4;

#[test]
fn area_light_shadow_filters_in_gl_agree_with_the_cpu_maps() {
    // `soft-shadows` (one emissive panel, no other light): GL's visibility
    // of the panel per pixel (its cube map drawn by GL, read by the shader's
    // filter) against the CPU rasterizer's (its maps, `Taps`), for each
    // filter at two map sizes: within 1e-3 on at least 99% of the pixels
    // the panel lights in both. Measured on llvmpipe: see the printed figures.
    use pinhole::render::shadow::ShadowFilter;
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let cpu = renderer_by_name("rasterize").unwrap();
    let sc = scene("soft-shadows");
    assert!(sc.lights.is_empty() && sc.render.ambient == Vec3::ZERO && sc.emitters.lights.len() == 1, "the premise of `visibility`");
    let prepared = PreparedScene::new(sc.clone());
    // A PCF kernel of 9 x 9 taps, so its blur shows at both sizes.
    let open = RenderSettings { mis: false, light_samples: 2, pcf_radius: 4.0, ..settings(&sc) };
    let gl_open = render(gl.as_ref(), &prepared, &open);
    let cpu_open = render(cpu.as_ref(), &prepared, &open);
    let mut gl_pcss = Vec::new();
    for size in [256, 1024] {
        for filter in [ShadowFilter::None, ShadowFilter::Pcf, ShadowFilter::Pcss] {
            let s = RenderSettings { shadows: ShadowMode::Map, shadow_filter: filter, shadow_map_size: size, ..open.clone() };
            if let Err(e) = gl.check(&sc, &s) {
                panic!("refused: {e}");
            }
            let a = render(gl.as_ref(), &prepared, &s);
            assert!(a.iter().all(|p| p.is_finite()));
            let va = visibility(&a, &gl_open);
            let vb = visibility(&render(cpu.as_ref(), &prepared, &s), &cpu_open);
            let both: Vec<(f32, f32)> = va.iter().zip(&vb).filter_map(|(a, b)| a.zip(*b)).collect();
            let agree = both.iter().filter(|(a, b)| (a - b).abs() <= 1e-3).count() as f64 / both.len() as f64;
            let shadowed = both.iter().filter(|(_, b)| *b < 0.5).count();
            let penumbra = both.iter().filter(|(_, b)| *b > 0.05 && *b < 0.95).count();
            eprintln!("{filter:?} at {size}: {:.3}% of {} lit pixels within 1e-3 ({shadowed} in shadow, {penumbra} in penumbra)", agree * 100.0, both.len());
            // The panel lights most of the image, its shadows fall in view,
            // and the filters soften them.
            assert!(both.len() > va.len() / 2, "{filter:?} {size}: the panel lights only {} pixels", both.len());
            assert!(shadowed > 200, "{filter:?} {size}: no shadow ({shadowed} pixels)");
            if filter != ShadowFilter::None {
                assert!(penumbra > 200, "{filter:?} {size}: no penumbra ({penumbra} pixels)");
            }
            assert!(agree >= MAP_AGREEMENT, "{filter:?} at {size}: only {:.3}% of lit pixels within 1e-3", agree * 100.0);
            if filter == ShadowFilter::Pcss && size == 1024 {
                gl_pcss = va;
            }
        }
    }
    // The comparison can fail: GL's PCSS against the CPU's PCF.
    let s = RenderSettings { shadows: ShadowMode::Map, shadow_filter: ShadowFilter::Pcf, shadow_map_size: 1024, ..open.clone() };
    let vb = visibility(&render(cpu.as_ref(), &prepared, &s), &cpu_open);
    let both: Vec<(f32, f32)> = gl_pcss.iter().zip(&vb).filter_map(|(a, b)| a.zip(*b)).collect();
    let agree = both.iter().filter(|(a, b)| (a - b).abs() <= 1e-3).count() as f64 / both.len() as f64;
    assert!(agree < 0.99, "PCSS against PCF still agrees on {:.2}%", agree * 100.0);
}


#[test]
fn gl_area_lights_give_the_closed_form_irradiance() {
    // GL's fixed pattern of light samples, without shadows: a Lambertian
    // floor under a uniform emitter of radiance L shows albedo L F (F the
    // form factor). Under the centre and a corner of a 2 x 1 panel at
    // height 1, and under a sphere of radius r at height d (F = (r/d)^2),
    // with --light-samples 16 and 16 passes: within 1%.
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let panel = r#"
[[object]]
type = "quad"
vertices = [[-1.0, 1.0, -0.5], [1.0, 1.0, -0.5], [1.0, 1.0, 0.5], [-1.0, 1.0, 0.5]]
material = "lamp"
"#;
    let ball = r#"
[[object]]
type = "sphere"
center = [0.0, 1.0, 0.0]
radius = 0.3
material = "lamp"
"#;
    let cases = [
        (panel, 0.0, 0.0, 4.0 * corner_form_factor(1.0, 0.5, 1.0)),
        (panel, 1.0, 0.5, corner_form_factor(2.0, 1.0, 1.0)),
        (ball, 0.0, 0.0, 0.09),
        (&ball.replace("radius = 0.3", "radius = 0.6"), 0.0, 0.0, 0.36),
    ];
    for (light, x, z, f) in cases {
        let sc = floor_under(light, x, z);
        let s = RenderSettings { spp: 16, light_samples: 16, mis: false, shadows: ShadowMode::None, ..RenderSettings::for_scene(&sc) };
        gl.check(&sc, &s).unwrap();
        let img = render(gl.as_ref(), &PreparedScene::new(sc), &s);
        let got = img.iter().map(|p| p.x as f64).sum::<f64>() / img.len() as f64;
        let expected = 0.5 * 2.0 * f;
        eprintln!("opengl at ({x}, {z}): {got:.5}, closed form {expected:.5}");
        assert!((got / expected - 1.0).abs() < 0.01, "({x}, {z}): {got} against {expected}");
    }
}

/// Root-mean-square difference over the mean of `reference` (luminance).
fn relative_rmse(img: &[Radiance], reference: &[Radiance]) -> f64 {
    let lum = |c: Radiance| c.dot(Vec3::new(0.2126, 0.7152, 0.0722)) as f64;
    let mean = reference.iter().map(|c| lum(*c)).sum::<f64>() / reference.len() as f64;
    let mse = img.iter().zip(reference).map(|(a, b)| (lum(*a) - lum(*b)).powi(2)).sum::<f64>() / img.len() as f64;
    mse.sqrt() / mean
}

#[test]
fn gl_environment_light_agrees_with_the_cpu_without_shadows() {
    // `sky` (lit by the sky alone) with --shadows none --mis off, the
    // settings the gate gives GL there, all at 64 spp: GL's fixed patterns
    // of directions importance-sampled from the map against the CPU
    // rasterizer's light samples. GL's image lies no farther from the CPU's
    // than the CPU's own image with another seed does: its error is within
    // the CPU's noise. And the comparison can fail: with its environment
    // light taken away, GL's image is far off.
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let cpu = renderer_by_name("rasterize").unwrap();
    let sc = pinhole::scene::builtin::load_builtin("sky").unwrap().unwrap();
    assert!(sc.lights.is_empty() && sc.emitters.is_empty() && sc.environment.as_ref().is_some_and(|e| e.is_light()));
    let s = RenderSettings { width: 120, height: 80, spp: 64, light_samples: 4, mis: false, shadows: ShadowMode::None, ..RenderSettings::for_scene(&sc) };
    gl.check(&sc, &s).unwrap();
    let prepared = PreparedScene::new(sc.clone());
    let a = render(gl.as_ref(), &prepared, &s);
    assert!(a.iter().all(|p| p.is_finite()));
    let b = render(cpu.as_ref(), &prepared, &s);
    let mut reseeded = s.clone();
    reseeded.gi.seed ^= 0x5eed;
    let noise = relative_rmse(&render(cpu.as_ref(), &prepared, &reseeded), &b);
    let error = relative_rmse(&a, &b);
    let mut dark = sc.clone();
    dark.environment.as_mut().unwrap().light = None;
    let unlit = relative_rmse(&render(gl.as_ref(), &PreparedScene::new(dark), &s), &b);
    eprintln!("sky: GL against the CPU: {:.2}% rmse/mean; the CPU against itself with another seed: {:.2}%; GL without its environment light: {:.2}%", error * 100.0, noise * 100.0, unlit * 100.0);
    assert!(error <= noise, "GL's environment light is {:.2}% off, the CPU's noise {:.2}%", error * 100.0, noise * 100.0);
    assert!(unlit > 4.0 * noise, "the comparison cannot tell: {:.2}%", unlit * 100.0);
}

/// `sc` seen through an orthographic camera as high as its perspective
/// view is at the target's distance.
fn orthographic(mut sc: Scene) -> Scene {
    let c = &sc.camera;
    let fov_y = match c.fov {
        pinhole::scene::Fov::Y(d) => d,
        pinhole::scene::Fov::X(d) => d * sc.render.height as f32 / sc.render.width as f32,
    };
    let height = 2.0 * (c.target - c.eye).length() * (fov_y.to_radians() * 0.5).tan();
    sc.camera.projection = pinhole::scene::camera::Projection::Orthographic { height };
    sc
}

#[test]
fn gl_orthographic_camera_agrees_with_brute_force() {
    // Parallel rays in the vertex shader (w = 1, depth linear), the
    // fragments' eye rays, the spheres' and CSG objects' ray tests and
    // the texture footprints: every part of GL's camera.
    let Some(_) = driver() else { return };
    let gl = renderer_by_name("opengl").unwrap();
    let brute = renderer_by_name("raytrace:brute").unwrap();
    let names = agreement_scenes();
    let mut drawn = 0;
    for name in ["spheres", "textures", "csg", "cornell-box"] {
        if !names.contains(&name) {
            continue;
        }
        let sc = orthographic(scene(name));
        let s = RenderSettings { width: 96, height: 64, reflections: pinhole::render::Reflections::Env, ..settings(&sc) };
        pinhole::render::admit::admit(gl.as_ref(), &sc, &s).unwrap_or_else(|e| panic!("{name}: refused: {e}"));
        let prepared = PreparedScene::new(sc.clone());
        let a = render(gl.as_ref(), &prepared, &s);
        let b = render(brute.as_ref(), &prepared, &s);
        let (fraction, wrong) = agreement(&a, &b);
        eprintln!("{name} orthographic: {:.3}% agree ({wrong} pixels differ)", fraction * 100.0);
        assert!(fraction >= 0.995, "{name} orthographic: opengl agrees with raytrace:brute on only {:.3}% of pixels", fraction * 100.0);
        // Not the perspective image: the camera really changed.
        let perspective = render(gl.as_ref(), &PreparedScene::new(scene(name)), &s);
        assert!(agreement(&perspective, &a).1 > 300, "{name}: the orthographic image looks like the perspective one");
        drawn += 1;
    }
    assert!(drawn >= 3, "only {drawn} scenes drawn");
}
