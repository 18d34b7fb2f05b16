//! Lighting against ground truth: `--spp 64` renders of both families of
//! renderers against the Mitsuba 3 references in ../shared/references
//! (1024 spp, box filter), within 2% of the reference's mean radiance.
//! Negative controls show that the bound catches the classic bugs.

mod common;
use common::*;
use pinhole::math::{Radiance, Vec3};
use pinhole::metrics::compare;
use pinhole::render::{PreparedScene, RenderSettings};
use pinhole::scene::{Fov, Scene};

const BOUND: f64 = 0.02;

fn load_reference(name: &str) -> (Scene, Vec<Radiance>) {
    let dir = shared_dir().join("references");
    let scene = pinhole::scene::file::load_scene_file(&dir.join(format!("{name}.toml"))).unwrap();
    let exr = pinhole::image_io::load_image(&dir.join(format!("{name}.exr"))).unwrap();
    assert_eq!((exr.width, exr.height), (scene.render.width, scene.render.height));
    (scene, exr.pixels)
}

/// rmse relative to the reference mean.
fn relative_rmse(img: &[Radiance], reference: &[Radiance]) -> f64 {
    let m = compare(img, reference).unwrap();
    m.rmse / m.reference_mean
}

fn spp64(scene: &Scene) -> RenderSettings {
    let mut s = RenderSettings::for_scene(scene);
    s.spp = 64;
    s
}

fn check(name: &str) {
    let (scene, reference) = load_reference(name);
    let settings = spp64(&scene);
    let prepared = PreparedScene::new(scene);
    for renderer in ["raytrace", "rasterize"] {
        let img = render(renderer, &prepared, &settings);
        let e = relative_rmse(&img, &reference);
        println!("{name} {renderer}: rmse = {:.3}% of the reference mean", 100.0 * e);
        assert!(e < BOUND, "{name} {renderer}: rmse {:.3}% of the mean exceeds {}%", 100.0 * e, 100.0 * BOUND);
    }
}

#[test]
fn bunny_ground_matches_mitsuba() {
    check("bunny_ground");
}

#[test]
fn spheres_ground_matches_mitsuba() {
    check("spheres_ground");
}

/// The bound is tight enough to catch a missing 1/pi, a wrong field of view
/// and a flipped surface. Rendered at 16 spp to keep the test quick: the
/// correct image passes the bound already at 16 spp, so only the bug fails it.
#[test]
fn bound_catches_classic_bugs() {
    let (scene, reference) = load_reference("spheres_ground");
    let mut settings = spp64(&scene);
    settings.spp = 16;
    let ok = render("raytrace", &PreparedScene::new(scene.clone()), &settings);
    assert!(relative_rmse(&ok, &reference) < BOUND, "the correct image must pass first");

    // A BSDF missing its 1/pi: every lit pixel pi times too bright.
    let no_inv_pi: Vec<Radiance> = ok.iter().map(|c| *c * std::f32::consts::PI).collect();
    let e = relative_rmse(&no_inv_pi, &reference);
    assert!(e > BOUND, "missing 1/pi went unnoticed ({e})");

    // A field of view off by 2 degrees.
    let mut wrong_fov = scene.clone();
    wrong_fov.camera.fov = match wrong_fov.camera.fov {
        Fov::X(d) => Fov::X(d + 2.0),
        Fov::Y(d) => Fov::Y(d + 2.0),
    };
    let e = relative_rmse(&render("raytrace", &PreparedScene::new(wrong_fov), &settings), &reference);
    assert!(e > BOUND, "a wrong fov went unnoticed ({e})");

    // A flipped ground: reversed winding on a single-sided quad faces away.
    let mut flipped = scene.clone();
    flipped.triangles = scene
        .triangles
        .iter()
        .map(|mut t| {
            t.v.swap(1, 2);
            t.n = t.n.map(|n| -n);
            t.two_sided = false;
            t
        })
        .collect();
    let e = relative_rmse(&render("raytrace", &PreparedScene::new(flipped), &settings), &reference);
    assert!(e > BOUND, "a flipped normal went unnoticed ({e})");

    // Inverse-distance instead of inverse-square falloff, emulated by scaling
    // each light's power by its distance to the scene's centre.
    let mut falloff = scene;
    for l in falloff.lights.iter_mut() {
        if let pinhole::scene::Light::Point { position, power } = l {
            *power *= (*position - Vec3::new(0.0, 0.0, -3.0)).length();
        }
    }
    let e = relative_rmse(&render("raytrace", &PreparedScene::new(falloff), &settings), &reference);
    assert!(e > BOUND, "a wrong falloff went unnoticed ({e})");
}
