//! Area lights and the environment as lights: direct light from a quad and
//! from a sphere against their closed-form irradiance, direct light against
//! Mitsuba's `direct` reference in both families, the Cornell box lit by
//! its panel against Mitsuba's `path` reference, multiple importance
//! sampling beating each of its strategies, and bad emitters refused or
//! bounded.

mod common;
use common::*;
use pinhole::math::{Radiance, Vec3};
use pinhole::metrics::compare;
use pinhole::render::transport::gi::GiMode;
use pinhole::render::{PreparedScene, RenderSettings, ShadowMode};
use pinhole::scene::file::parse_scene;
use std::path::Path;

fn direct_settings(prepared: &PreparedScene, spp: u32, light_samples: u32) -> RenderSettings {
    let mut s = RenderSettings::for_scene(&prepared.scene);
    s.spp = spp;
    s.light_samples = light_samples;
    s.shadows = ShadowMode::Ray;
    s.gi.mode = GiMode::None;
    s
}

fn mean(img: &[Radiance]) -> Vec3 {
    img.iter().fold(Vec3::ZERO, |a, p| a + *p) / img.len() as f32
}

/// A Lambertian floor's radiance is albedo / pi times the irradiance, and a
/// uniform emitter of radiance L gives irradiance pi L F (F the form
/// factor): so the floor shows 0.5 * 2 * F. Under the centre of a 2 x 1
/// panel at height 1 (four corner rectangles) and under one of its corners,
/// in both families, within 1%.
#[test]
fn a_quad_light_gives_the_rectangles_irradiance() {
    let panel = r#"
[[object]]
type = "quad"
vertices = [[-1.0, 1.0, -0.5], [1.0, 1.0, -0.5], [1.0, 1.0, 0.5], [-1.0, 1.0, 0.5]]
material = "lamp"
"#;
    let centre = 4.0 * corner_form_factor(1.0, 0.5, 1.0);
    let corner = corner_form_factor(2.0, 1.0, 1.0);
    for (x, z, f) in [(0.0, 0.0, centre), (1.0, 0.5, corner)] {
        let prepared = PreparedScene::new(floor_under(panel, x, z));
        let expected = 0.5 * 2.0 * f;
        for renderer in ["raytrace", "rasterize"] {
            let got = mean(&render(renderer, &prepared, &direct_settings(&prepared, 64, 16))).x as f64;
            eprintln!("{renderer} at ({x}, {z}): {got:.5}, form factor says {expected:.5}");
            assert!((got / expected - 1.0).abs() < 0.01, "{renderer} at ({x}, {z}): {got} against {expected}");
        }
    }
}

/// A sphere of radius r whose centre is d straight above a surface gives
/// irradiance pi L (r / d)^2: the floor shows 0.5 * 2 * (r / d)^2. Spheres
/// are sampled by the cone they subtend.
#[test]
fn a_sphere_light_gives_its_cones_irradiance() {
    let ball = r#"
[[object]]
type = "sphere"
center = [0.0, 1.0, 0.0]
radius = 0.3
material = "lamp"
"#;
    let prepared = PreparedScene::new(floor_under(ball, 0.0, 0.0));
    let expected = 0.5 * 2.0 * 0.09;
    for renderer in ["raytrace", "rasterize"] {
        let got = mean(&render(renderer, &prepared, &direct_settings(&prepared, 64, 16))).x as f64;
        eprintln!("{renderer}: {got:.5}, closed form {expected:.5}");
        assert!((got / expected - 1.0).abs() < 0.01, "{renderer}: {got} against {expected}");
    }
    // A negative control: light sampling that ignored the cosine at the
    // emitter's side would not depend on the radius; here doubling it
    // quadruples the light.
    let big = PreparedScene::new(floor_under(&ball.replace("radius = 0.3", "radius = 0.6"), 0.0, 0.0));
    let got = mean(&render("raytrace", &big, &direct_settings(&big, 64, 16))).x as f64;
    assert!((got / (0.5 * 2.0 * 0.36) - 1.0).abs() < 0.01, "radius 0.6: {got}");
}

fn relative_rmse(img: &[Radiance], reference: &[Radiance]) -> f64 {
    let m = compare(img, reference).unwrap();
    m.rmse / m.reference_mean
}

fn with_reference(toml: &Path, exr: &Path) -> (PreparedScene, Vec<Radiance>) {
    let scene = pinhole::scene::file::load_scene_file(toml).unwrap();
    let reference = pinhole::image_io::load_image(exr).unwrap();
    assert_eq!((reference.width, reference.height), (scene.render.width, scene.render.height));
    (PreparedScene::new(scene), reference.pixels)
}

/// Direct light from a panel and an emissive ball on diffuse surfaces,
/// against Mitsuba 3's `direct` integrator at 4096 spp: within 2% rmse/mean
/// at 64 spp with 16 light samples, in both families. Ignoring the ball,
/// or shadows, fails.
#[test]
fn direct_area_light_matches_mitsuba() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let (prepared, reference) = with_reference(&data.join("area_diffuse.toml"), &data.join("area_diffuse.exr"));
    for renderer in ["raytrace", "rasterize"] {
        let e = relative_rmse(&render(renderer, &prepared, &direct_settings(&prepared, 64, 16)), &reference);
        eprintln!("{renderer} --gi none --spp 64 --light-samples 16: rmse/mean {:.2}%", e * 100.0);
        assert!(e < 0.02, "{renderer}: {e}");
    }
    let mut unshadowed = direct_settings(&prepared, 64, 16);
    unshadowed.shadows = ShadowMode::None;
    let e = relative_rmse(&render("raytrace", &prepared, &unshadowed), &reference);
    eprintln!("without shadows: {:.2}%", e * 100.0);
    assert!(e > 0.04, "the bound cannot see missing shadows: {e}");
}

/// Mitsuba's own error on the Cornell box lit by its panel (rmse / mean,
/// independent seed): 6.18% at 64 spp, 2.16% at 256 spp.
const CORNELL_BOX_64: f64 = 0.0618;
const CORNELL_BOX_256: f64 = 0.0216;

fn cornell_box() -> (PreparedScene, Vec<Radiance>) {
    let dir = shared_dir().join("references");
    with_reference(&dir.join("cornell_box.toml"), &dir.join("cornell_box.exr"))
}

fn path_settings(prepared: &PreparedScene, spp: u32) -> RenderSettings {
    let mut s = direct_settings(prepared, spp, 1);
    s.gi.mode = GiMode::Path;
    s
}

/// The Cornell box lit by its emissive panel, path traced: within 1.25x
/// Mitsuba's own 64-spp error in both families (the 256-spp bound is the
/// ignored test below: about two minutes per family on two cores). Direct
/// light alone fails the bound.
#[test]
fn the_cornell_box_panel_matches_mitsuba() {
    let (prepared, reference) = cornell_box();
    for renderer in ["raytrace", "rasterize"] {
        let e = relative_rmse(&render(renderer, &prepared, &path_settings(&prepared, 64)), &reference);
        eprintln!("{renderer} --gi path --spp 64: rmse/mean {:.2}% (Mitsuba: {:.2}%)", e * 100.0, CORNELL_BOX_64 * 100.0);
        assert!(e <= 1.25 * CORNELL_BOX_64, "{renderer}: {e}");
    }
    let direct = relative_rmse(&render("raytrace", &prepared, &direct_settings(&prepared, 64, 1)), &reference);
    eprintln!("direct light alone: {:.2}%", direct * 100.0);
    assert!(direct > 2.0 * CORNELL_BOX_64, "direct light alone passes: {direct}");
}

#[test]
#[ignore]
fn the_cornell_box_panel_at_256_spp_is_within_mitsubas_noise() {
    let (prepared, reference) = cornell_box();
    for renderer in ["raytrace", "rasterize"] {
        let e = relative_rmse(&render(renderer, &prepared, &path_settings(&prepared, 256)), &reference);
        eprintln!("{renderer} --gi path --spp 256: rmse/mean {:.2}% (Mitsuba: {:.2}%)", e * 100.0, CORNELL_BOX_256 * 100.0);
        assert!(e <= 1.25 * CORNELL_BOX_256, "{renderer}: {e}");
    }
}

/// A very glossy ball and a diffuse floor under a small bright panel and a
/// large dim one: light sampling alone is noisy in the ball's reflection
/// of the large panel, BSDF sampling alone on the floor under the small
/// one, and MIS is better than either.
const MIS_SCENE: &str = r#"
[camera]
eye = [0.0, 1.0, 3.5]
target = [0.0, 0.5, 0.0]
fov_y_deg = 40.0
[render]
width = 48
height = 36
ambient = [0.0, 0.0, 0.0]
background = [0.0, 0.0, 0.0]
[materials.small]
lambertian = [0.0, 0.0, 0.0]
emission = [60.0, 60.0, 60.0]
[materials.large]
lambertian = [0.0, 0.0, 0.0]
emission = [0.6, 0.6, 0.8]
[materials.glossy]
lambertian = [0.05, 0.05, 0.05]
glossy = [0.8, 0.8, 0.8]
sharpness = 800.0
[materials.floor]
lambertian = [0.6, 0.6, 0.6]
[[object]]
type = "quad"
vertices = [[-0.15, 2.5, -0.15], [0.15, 2.5, -0.15], [0.15, 2.5, 0.15], [-0.15, 2.5, 0.15]]
material = "small"
[[object]]
type = "quad"
vertices = [[-4.0, 4.0, -4.0], [4.0, 4.0, -4.0], [4.0, 4.0, 4.0], [-4.0, 4.0, 4.0]]
material = "large"
[[object]]
type = "sphere"
center = [0.0, 0.5, 0.0]
radius = 0.5
material = "glossy"
[[object]]
type = "quad"
vertices = [[-6.0, 0.0, 6.0], [6.0, 0.0, 6.0], [6.0, 0.0, -6.0], [-6.0, 0.0, -6.0]]
material = "floor"
"#;

/// Noise of an unbiased estimator without a reference: the rmse between two
/// renders with independent seeds is sqrt(2) times its own.
fn noise(prepared: &PreparedScene, settings: &RenderSettings) -> f64 {
    let mut a = settings.clone();
    a.gi.seed = 1;
    let mut b = settings.clone();
    b.gi.seed = 2;
    relative_rmse(&render("raytrace", prepared, &a), &render("raytrace", prepared, &b)) / 2f64.sqrt()
}

#[test]
fn mis_beats_each_strategy_alone() {
    let prepared = PreparedScene::new(scene_from(MIS_SCENE));
    let mis = direct_settings(&prepared, 16, 1);
    let light_alone = RenderSettings { mis: false, ..mis.clone() };
    let bsdf_alone = RenderSettings { light_samples: 0, ..mis.clone() };
    let (e_mis, e_light, e_bsdf) = (noise(&prepared, &mis), noise(&prepared, &light_alone), noise(&prepared, &bsdf_alone));
    eprintln!("16 spp noise (rmse/mean): MIS {:.2}%, light alone {:.2}%, BSDF alone {:.2}%", e_mis * 100.0, e_light * 100.0, e_bsdf * 100.0);
    assert!(e_mis < e_light && e_mis < e_bsdf, "MIS {e_mis}, light {e_light}, BSDF {e_bsdf}");
    // All three estimate the same image: their means at 256 spp agree.
    let means: Vec<Vec3> = [mis, light_alone, bsdf_alone]
        .into_iter()
        .map(|s| mean(&render("raytrace", &prepared, &RenderSettings { spp: 256, ..s })))
        .collect();
    for m in &means[1..] {
        assert!((m.x / means[0].x - 1.0).abs() < 0.02, "means differ: {means:?}");
    }
}

const LAMP_OVER_FLOOR: &str = r#"
[camera]
eye = [0.0, 1.0, 3.0]
target = [0.0, 0.0, 0.0]
[render]
width = 8
height = 6
[materials.lamp]
lambertian = [0.0, 0.0, 0.0]
emission = EMISSION
[materials.floor]
lambertian = [0.5, 0.5, 0.5]
[[object]]
type = "quad"
vertices = [[-0.5, 2.0, -0.5], [0.5, 2.0, -0.5], [0.5, 2.0, 0.5], [-0.5, 2.0, 0.5]]
material = "lamp"
[[object]]
type = "quad"
vertices = [[-4.0, 0.0, 4.0], [4.0, 0.0, 4.0], [4.0, 0.0, -4.0], [-4.0, 0.0, -4.0]]
material = "floor"
"#;

fn all_finite(img: &[Radiance]) -> bool {
    img.iter().all(|p| p.is_finite())
}

/// Negative or NaN emission is refused in one sentence naming the
/// material and the key; a huge but finite one renders finite pixels.
#[test]
fn bad_emission_is_refused_by_name() {
    for bad in ["[-1.0, 0.0, 0.0]", "[nan, 1.0, 1.0]", "[inf, 1.0, 1.0]"] {
        let text = LAMP_OVER_FLOOR.replace("EMISSION", bad);
        let err = parse_scene(&text, "lamp.toml", Path::new("."), "lamp").unwrap_err();
        eprintln!("{bad}: {err}");
        assert!(err.contains("lamp") && err.contains("emission"), "{bad}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    let prepared = PreparedScene::new(scene_from(&LAMP_OVER_FLOOR.replace("EMISSION", "[1e6, 1e6, 1e6]")));
    assert!(all_finite(&render("raytrace", &prepared, &direct_settings(&prepared, 4, 4))));
}

/// An emitter without area: a collinear quad is refused in one sentence
/// naming the object; degenerate triangles of an emissive mesh are
/// skipped with a warning. Either way no pixel is NaN.
#[test]
fn a_zero_area_emitter_is_refused_or_reported() {
    let text = LAMP_OVER_FLOOR.replace("EMISSION", "[5.0, 5.0, 5.0]").replace(
        "[[-0.5, 2.0, -0.5], [0.5, 2.0, -0.5], [0.5, 2.0, 0.5], [-0.5, 2.0, 0.5]]",
        "[[-0.5, 2.0, 0.0], [0.0, 2.0, 0.0], [0.5, 2.0, 0.0], [1.0, 2.0, 0.0]]",
    );
    let err = parse_scene(&text, "lamp.toml", Path::new("."), "lamp").unwrap_err();
    assert!(err.contains("object") && err.contains("zero area"), "{err}");
    let dir = std::env::temp_dir().join(format!("pinhole-flat-lamp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // One good triangle and one whose corners coincide.
    std::fs::write(dir.join("lamp.obj"), "v 0 2 0\nv 1 2 0\nv 0 2 1\nv 1 2 1\nf 1 2 3\nf 4 4 4\n").unwrap();
    let text = LAMP_OVER_FLOOR.replace("EMISSION", "[5.0, 5.0, 5.0]").replacen(
        "type = \"quad\"\nvertices = [[-0.5, 2.0, -0.5], [0.5, 2.0, -0.5], [0.5, 2.0, 0.5], [-0.5, 2.0, 0.5]]",
        &format!("type = \"mesh\"\nfile = \"{}\"", dir.join("lamp.obj").display()),
        1,
    );
    let scene = scene_from(&text);
    eprintln!("{:?}", scene.warnings);
    assert!(scene.warnings.iter().any(|w| w.contains("zero area")), "{:?}", scene.warnings);
    assert_eq!(scene.emitters.len(), 1);
    let prepared = PreparedScene::new(scene);
    let img = render("raytrace", &prepared, &direct_settings(&prepared, 4, 4));
    assert!(all_finite(&img) && mean(&img).x > 0.0);
    std::fs::remove_dir_all(&dir).ok();
}

/// An environment image that is black everywhere is reported and lights
/// nothing; one holding infinities or NaN is refused, naming the file and
/// the texel.
#[test]
fn a_black_or_infinite_environment_is_reported_and_finite() {
    let dir = std::env::temp_dir().join(format!("pinhole-env-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (w, h) = (16u32, 8u32);
    let black = vec![Vec3::ZERO; (w * h) as usize];
    let mut infinite = vec![Vec3::splat(0.5); (w * h) as usize];
    infinite[3] = Vec3::new(f32::INFINITY, 1.0, 1.0);
    infinite[40] = Vec3::splat(f32::NAN);
    for (name, texels, expect) in [("black.exr", &black, "black everywhere"), ("infinite.exr", &infinite, "is inf")] {
        let path = dir.join(name);
        pinhole::image_io::save_image(&path, w, h, texels, 1.0).unwrap();
        let text = format!(
            r#"
[camera]
eye = [0.0, 1.0, 3.0]
target = [0.0, 0.0, 0.0]
[render]
width = 8
height = 6
[environment]
file = "{}"
[materials.floor]
lambertian = [0.5, 0.5, 0.5]
[[object]]
type = "sphere"
center = [0.0, 0.5, 0.0]
radius = 0.5
material = "floor"
"#,
            path.display()
        );
        if name == "infinite.exr" {
            // Refused at load, naming the file and the texel.
            let err = parse_scene(&text, "test.toml", Path::new("."), "test").unwrap_err();
            eprintln!("{name}: {err}");
            assert!(err.contains("infinite.exr") && err.contains(expect), "{err}");
            continue;
        }
        let scene = scene_from(&text);
        eprintln!("{name}: {:?}", scene.warnings);
        assert!(scene.warnings.iter().any(|w| w.contains(expect)), "{name}: {:?}", scene.warnings);
        let prepared = PreparedScene::new(scene);
        let img = render("raytrace", &prepared, &direct_settings(&prepared, 4, 4));
        assert!(all_finite(&img), "{name}");
        assert_eq!(mean(&img), Vec3::ZERO, "a black sky lights nothing");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A million emissive triangles: the emitter tables stay near a few dozen
/// bytes per triangle (the outline is the bounding box past its limit),
/// sampling picks among them, and the image is finite.
#[test]
fn a_million_emissive_triangles_stay_bounded() {
    use pinhole::scene::Triangle;
    let mut scene = scene_from(&LAMP_OVER_FLOOR.replace("EMISSION", "[1.0, 1.0, 1.0]"));
    let lamp = scene.materials.iter().position(|m| m.name == "lamp").unwrap() as u32;
    let n = 1000usize;
    let step = 2.0 / n as f32;
    let down = Vec3::NEG_Y;
    for i in 0..n {
        for j in 0..n / 2 {
            let (x, z) = (-1.0 + i as f32 * step, -0.5 + j as f32 * step);
            let a = Vec3::new(x, 2.5, z);
            let (b, c, d) = (a + Vec3::new(step, 0.0, 0.0), a + Vec3::new(step, 0.0, step), a + Vec3::new(0.0, 0.0, step));
            for v in [[a, b, c], [a, c, d]] {
                scene.triangles.push(Triangle { v, n: [down; 3], uv: [Default::default(); 3], material: lamp, object: 0, two_sided: false });
            }
        }
    }
    scene.refresh_emitters();
    let emitters = &scene.emitters;
    assert!(emitters.len() >= 1_000_000, "{}", emitters.len());
    let bytes = emitters.heap_bytes();
    eprintln!("{} emitters in {:.1} MB ({} bytes each)", emitters.len(), bytes as f64 / 1e6, bytes / emitters.len());
    assert!(bytes < 64 * emitters.len(), "{bytes} bytes");
    assert!(emitters.lights.iter().all(|l| l.outline.len() <= 4096));
    let prepared = PreparedScene::new(scene);
    let img = render("raytrace", &prepared, &direct_settings(&prepared, 2, 4));
    assert!(all_finite(&img) && mean(&img).x > 0.0);
}

/// Soft shadows from shadow maps, against the ray-traced shadow of the
/// panel on `soft-shadows`: a plain map (the centre's hard shadow) is
/// farthest, PCF blurs every edge alike and comes closer, PCSS (a blocker
/// search, then PCF as wide as the penumbra) closest. In both families.
#[test]
fn shadow_filters_approach_the_area_shadow_in_order() {
    let mut scene = builtin("soft-shadows");
    (scene.render.width, scene.render.height) = (160, 120);
    let prepared = PreparedScene::new(scene);
    let mut truth = direct_settings(&prepared, 16, 16);
    truth.shadows = ShadowMode::Ray;
    let truth_img = render("raytrace", &prepared, &truth);
    use pinhole::render::shadow::ShadowFilter;
    for renderer in ["raytrace", "rasterize"] {
        let errors: Vec<f64> = [ShadowFilter::None, ShadowFilter::Pcf, ShadowFilter::Pcss]
            .into_iter()
            .map(|filter| {
                let mut s = direct_settings(&prepared, 16, 16);
                s.shadows = ShadowMode::Map;
                s.shadow_filter = filter;
                s.pcf_radius = 3.0;
                let e = relative_rmse(&render(renderer, &prepared, &s), &truth_img);
                eprintln!("{renderer} --shadows map --shadow-filter {}: rmse/mean {:.2}%", filter.name(), e * 100.0);
                e
            })
            .collect();
        assert!(errors[2] < errors[1] && errors[1] < errors[0], "{renderer}: none {}, pcf {}, pcss {}", errors[0], errors[1], errors[2]);
    }
}

/// Mitsuba's own error on `sky_bunny` at 64 spp (one light and one BSDF
/// sample combined by MIS, rmse / mean, independent seed).
const SKY_BUNNY_64: f64 = 0.0697;

fn sky_bunny() -> (PreparedScene, Vec<Radiance>) {
    let dir = shared_dir().join("references");
    with_reference(&dir.join("sky_bunny.toml"), &dir.join("sky_bunny.exr"))
}

/// The bunny, a clay ball's floor and a GGX ball lit by the HDR sky alone,
/// `--gi none`: within 1.25x Mitsuba's own 64-spp error in both families.
/// Leaving the sky's light out (a plain background) fails.
#[test]
fn the_sky_lights_the_bunny_as_mitsuba_does() {
    let (prepared, reference) = sky_bunny();
    for renderer in ["raytrace", "rasterize"] {
        let e = relative_rmse(&render(renderer, &prepared, &direct_settings(&prepared, 64, 1)), &reference);
        eprintln!("{renderer} sky_bunny --gi none --spp 64: rmse/mean {:.2}% (Mitsuba: {:.2}%)", e * 100.0, SKY_BUNNY_64 * 100.0);
        assert!(e <= 1.25 * SKY_BUNNY_64, "{renderer}: {e}");
    }
    let mut unlit = prepared.scene.clone();
    unlit.environment.as_mut().unwrap().light = None;
    let unlit = PreparedScene::new(unlit);
    let e = relative_rmse(&render("raytrace", &unlit, &direct_settings(&unlit, 16, 1)), &reference);
    assert!(e > 0.5, "without the sky's light the image still passes: {e}");
}

/// Importance sampling the sky by luminance x sin(theta) against finding it
/// by BSDF (cosine, for the diffuse surfaces) sampling alone, at 16 spp: at
/// most half the error. The small sun makes cosine sampling very noisy.
#[test]
fn sampling_the_sky_beats_cosine_sampling() {
    let (prepared, reference) = sky_bunny();
    let sampled = relative_rmse(&render("raytrace", &prepared, &direct_settings(&prepared, 16, 1)), &reference);
    let cosine = relative_rmse(&render("raytrace", &prepared, &direct_settings(&prepared, 16, 0)), &reference);
    eprintln!("sky_bunny at 16 spp: environment sampling (MIS) {:.1}%, BSDF sampling alone {:.1}%", sampled * 100.0, cosine * 100.0);
    assert!(sampled <= 0.5 * cosine, "{sampled} against {cosine}");
}

/// Photons leave the emissive panel and the sky too: with `--gi photons`
/// the Cornell box's mean radiance is within 2% of Mitsuba's path-traced
/// reference, where direct light alone is more than 10% short; on `sky`
/// (lit by the environment alone) photon mapping's mean is within 3% of
/// path tracing's, where direct light alone is more than 5% short.
#[test]
fn photons_leave_area_lights_and_the_sky() {
    let lum = |img: &[Radiance]| {
        let m = mean(img);
        (0.2126 * m.x + 0.7152 * m.y + 0.0722 * m.z) as f64
    };
    let (prepared, reference) = cornell_box();
    let with_gi = |prepared: &PreparedScene, mode: GiMode, spp: u32| {
        let mut s = direct_settings(prepared, spp, 1);
        s.gi.mode = mode;
        lum(&render("raytrace", prepared, &s))
    };
    let truth = lum(&reference);
    let (photons, direct) = (with_gi(&prepared, GiMode::Photons, 4), with_gi(&prepared, GiMode::None, 4));
    eprintln!("cornell_box mean luminance: photons {photons:.4}, direct {direct:.4}, Mitsuba {truth:.4}");
    assert!((photons / truth - 1.0).abs() < 0.02, "photons {photons} against {truth}");
    assert!(direct < 0.9 * truth, "direct light alone {direct} is not short of {truth}");

    let mut sky = builtin("sky");
    (sky.render.width, sky.render.height) = (80, 60);
    let sky = PreparedScene::new(sky);
    let (photons, path, direct) = (with_gi(&sky, GiMode::Photons, 16), with_gi(&sky, GiMode::Path, 64), with_gi(&sky, GiMode::None, 16));
    eprintln!("sky mean luminance: photons {photons:.4}, path {path:.4}, direct {direct:.4}");
    assert!((photons / path - 1.0).abs() < 0.03, "photons {photons} against path {path}");
    assert!(direct < 0.95 * path, "direct light alone {direct} is not short of {path}");
}

/// A replayed pixel lists its light samples: on the Cornell box's floor
/// area-light samples with a point on the panel, a density and an MIS
/// weight in [0, 1], and the BSDF strategy's ray; their contributions are
/// the pixel's direct light from the panel. With `--mis off` the BSDF ray
/// is gone and every weight is 1.
#[test]
fn replays_list_every_light_sample() {
    use pinhole::render::inspect::pixel_record::SampledLightKind;
    let mut scene = builtin("cornell-box");
    (scene.render.width, scene.render.height) = (60, 60);
    let prepared = PreparedScene::new(scene);
    let raytrace = pinhole::render::renderer_by_name("raytrace").unwrap();
    let settings = direct_settings(&prepared, 1, 4);
    // A pixel on the floor, left of the bunny, in the panel's light.
    let (x, y) = (12, 56);
    let replay = pinhole::render::replay_pixel(raytrace.as_ref(), &prepared, &settings, x, y).unwrap();
    let frame = render("raytrace", &prepared, &settings);
    assert_eq!(replay.radiance, frame[(x + y * 60) as usize], "the replay is the frame's pixel");
    let lights = &replay.samples[0].1.sampled_lights;
    eprintln!("{lights:#?}");
    let area: Vec<_> = lights.iter().filter(|l| matches!(l.kind, SampledLightKind::Area(_))).collect();
    assert_eq!(area.len(), 4, "four light samples");
    assert!(area.iter().all(|l| l.point.is_some_and(|p| (p.y - 1.98).abs() < 1e-3) && l.pdf > 0.0 && (0.0..=1.0).contains(&l.mis_weight)));
    assert!(lights.iter().any(|l| l.kind == SampledLightKind::BsdfHit), "the BSDF strategy's ray is listed");
    let direct: Vec3 = lights.iter().map(|l| l.contribution).sum();
    assert!(direct.x > 0.0 && direct.x <= replay.radiance.x + 1e-6, "{direct} of {}", replay.radiance);

    let off = RenderSettings { mis: false, ..settings };
    let replay = pinhole::render::replay_pixel(raytrace.as_ref(), &prepared, &off, x, y).unwrap();
    let lights = &replay.samples[0].1.sampled_lights;
    assert!(lights.iter().all(|l| l.kind != SampledLightKind::BsdfHit && l.mis_weight == 1.0), "{lights:#?}");
}
