//! Indirect light: path tracing against Mitsuba 3's `path` reference of the
//! Cornell box (unbounded depth, 4096 spp), without bias as samples grow;
//! both renderer families giving the same image; replays and thread counts
//! that change nothing; photon mapping converging as photons are added.

mod common;
use common::*;
use pinhole::math::Radiance;
use pinhole::metrics::compare;
use pinhole::render::transport::gi::GiMode;
use pinhole::render::{self, PreparedScene, RenderSettings};
use pinhole::scene::Scene;

/// Mitsuba's own error against the reference (rmse / mean), measured with
/// an independent seed: 16.9% at 64 spp, 7.49% at 256 spp.
const MITSUBA_64: f64 = 0.169;
const MITSUBA_256: f64 = 0.0749;

fn cornell() -> (PreparedScene, Vec<Radiance>) {
    let dir = shared_dir().join("references");
    let scene: Scene = pinhole::scene::file::load_scene_file(&dir.join("cornell_gi.toml")).unwrap();
    let exr = pinhole::image_io::load_image(&dir.join("cornell_gi.exr")).unwrap();
    assert_eq!((exr.width, exr.height), (scene.render.width, scene.render.height));
    (PreparedScene::new(scene), exr.pixels)
}

fn path_settings(prepared: &PreparedScene, spp: u32) -> RenderSettings {
    let mut s = RenderSettings::for_scene(&prepared.scene);
    s.spp = spp;
    s.gi.mode = GiMode::Path;
    s
}

fn relative_rmse(img: &[Radiance], reference: &[Radiance]) -> f64 {
    let m = compare(img, reference).unwrap();
    m.rmse / m.reference_mean
}

/// Path tracing lands within 1.25x Mitsuba's own noise at 64 spp in both
/// families, and its error falls like 1/sqrt(spp) (16x the samples, at most
/// 0.3x the error): a biased estimator stalls above its bias instead. The
/// direct-light image, and a path tracer stopped after one bounce, fail.
#[test]
fn path_tracing_matches_mitsuba_and_converges() {
    let (prepared, reference) = cornell();
    let e64: Vec<f64> = ["raytrace", "rasterize"]
        .iter()
        .map(|r| {
            let e = relative_rmse(&render(r, &prepared, &path_settings(&prepared, 64)), &reference);
            eprintln!("{r} --gi path --spp 64: rmse/mean {:.2}% (Mitsuba 64 spp: {:.1}%)", e * 100.0, MITSUBA_64 * 100.0);
            assert!(e <= 1.25 * MITSUBA_64, "{r}: {e}");
            e
        })
        .collect();
    let e4 = relative_rmse(&render("raytrace", &prepared, &path_settings(&prepared, 4)), &reference);
    eprintln!("4 spp: {:.2}%, 64 spp: {:.2}%, ratio {:.3}", e4 * 100.0, e64[0] * 100.0, e64[0] / e4);
    assert!(e64[0] <= 0.3 * e4, "error fell from {e4} to {} only", e64[0]);

    // Negative controls: the bound sees missing light.
    let direct = relative_rmse(&render("raytrace", &prepared, &RenderSettings { spp: 64, ..RenderSettings::for_scene(&prepared.scene) }), &reference);
    assert!(direct > 2.0 * MITSUBA_64, "direct light alone passes: {direct}");
    let mut one_bounce = path_settings(&prepared, 64);
    one_bounce.gi.bounces = Some(1);
    let short = relative_rmse(&render("raytrace", &prepared, &one_bounce), &reference);
    eprintln!("one bounce: {:.2}%, direct only: {:.2}%", short * 100.0, direct * 100.0);
    assert!(short > 1.25 * MITSUBA_64, "one bounce passes: {short}");
}

/// The issue's bound at 256 spp (about a minute per family on two cores).
#[test]
#[ignore]
fn path_tracing_at_256_spp_is_within_mitsubas_noise() {
    let (prepared, reference) = cornell();
    for r in ["raytrace", "rasterize"] {
        let e = relative_rmse(&render(r, &prepared, &path_settings(&prepared, 256)), &reference);
        eprintln!("{r} --gi path --spp 256: rmse/mean {:.2}% (Mitsuba: {:.2}%)", e * 100.0, MITSUBA_256 * 100.0);
        assert!(e <= 1.25 * MITSUBA_256, "{r}: {e}");
    }
}

fn small(name: &str, mode: GiMode, spp: u32) -> (PreparedScene, RenderSettings) {
    let prepared = PreparedScene::new(builtin(name));
    let mut s = RenderSettings::for_scene(&prepared.scene);
    s.width = 64;
    s.height = 48;
    s.spp = spp;
    s.gi.mode = mode;
    s.gi.photons = 20_000;
    s.gi.ao_samples = 4;
    (prepared, s)
}

fn bits(img: &[Radiance]) -> Vec<[u32; 3]> {
    img.iter().map(|c| c.to_array().map(f32::to_bits)).collect()
}

/// The rasterizer finds the first hit and rays do the rest: with the same
/// seed, the pixels whose first hit both families agree on carry the same
/// indirect light, to the rounding the two hit computations differ by (the
/// same tolerance as without indirect light; a path that grazes an edge can
/// take another turn, so a few pixels may differ more).
#[test]
fn both_families_give_the_same_indirect_light() {
    for mode in [GiMode::Ao, GiMode::Path, GiMode::Photons] {
        for scene in ["cornell-gi", "teapot"] {
            let (prepared, s) = small(scene, mode, 2);
            let a = render("raytrace", &prepared, &s);
            let b = render("rasterize", &prepared, &s);
            let depth = RenderSettings { view: render::inspect::debug::View::Depth, ..s.clone() };
            let (da, db) = (render("raytrace", &prepared, &depth), render("rasterize", &prepared, &depth));
            let (mut same_hit, mut close) = (0usize, 0usize);
            for i in 0..a.len() {
                if (da[i] - db[i]).abs().max_element() <= 1e-5 {
                    same_hit += 1;
                    let tolerance = 1e-4 * a[i].max_element().max(1e-3);
                    close += ((a[i] - b[i]).abs().max_element() <= tolerance) as usize;
                }
            }
            eprintln!("{scene} {mode:?}: {close} of {same_hit} same-hit pixels agree");
            assert!(same_hit > a.len() * 9 / 10, "{scene} {mode:?}: {same_hit} of {} hits agree", a.len());
            assert!(close as f64 >= 0.99 * same_hit as f64, "{scene} {mode:?}: {close} of {same_hit} agree");
            assert!(a.iter().chain(&b).all(|c| c.is_finite()));
        }
    }
}

/// Frames follow a batch's paths together (Lambertian bounces sampled eight
/// lanes at a time, glossy ones and the rest of a path past a mirror or
/// glass one at a time); replays follow one path by recursion. They agree
/// bit for bit through every kind of surface, textures and CSG included.
/// Every pixel is replayed: a frame gathers samples from many pixels before
/// it follows their paths, and those gathered last in a region must not be
/// lost.
#[test]
fn path_replays_equal_frames_through_every_kind_of_surface() {
    for scene in ["spheres", "teapot", "textures", "csg", "bunny"] {
        let (prepared, mut s) = small(scene, GiMode::Path, 2);
        (s.width, s.height) = (37, 23);
        let every: Vec<(u32, u32)> = (0..s.height).flat_map(|y| (0..s.width).map(move |x| (x, y))).collect();
        for renderer in ["raytrace", "rasterize"] {
            replays_of_frame(renderer, &prepared, &s, every.clone(), scene);
        }
    }
}

/// Replays `at` of `renderer`'s frame, each asserted equal to its frame
/// pixel bit for bit (`label` names the case); the replays with their
/// pixels' values.
fn replays_of_frame(renderer: &str, prepared: &PreparedScene, s: &RenderSettings, at: Vec<(u32, u32)>, label: &str) -> Vec<((u32, u32), render::PixelReplay, Radiance)> {
    let frame = render(renderer, prepared, s);
    let r = render::renderer_by_name(renderer).unwrap();
    at.into_iter()
        .map(|(x, y)| {
            let replay = render::replay_pixel(r.as_ref(), prepared, s, x, y).unwrap();
            let i = (x + y * s.width) as usize;
            assert_eq!(bits(&[replay.radiance]), bits(&frame[i..i + 1]), "{label} {renderer} ({x}, {y})");
            ((x, y), replay, frame[i])
        })
        .collect()
}

/// A pixel replays bit for bit what its frame computed, with the bounces
/// recorded; the image never depends on the number of threads.
#[test]
fn replays_and_threads_change_nothing() {
    for mode in [GiMode::Path, GiMode::Photons, GiMode::Ao] {
        let (prepared, s) = small("cornell-gi", mode, 3);
        let one = render_with_threads(1, "raytrace", &prepared, &s);
        let two = render_with_threads(3, "raytrace", &prepared, &s);
        assert!(bits(&one) == bits(&two), "{mode:?}: thread count changes the image");
        for renderer in ["raytrace", "rasterize"] {
            for ((x, y), replay, value) in replays_of_frame(renderer, &prepared, &s, pixels(7, 6, s.width, s.height), &format!("{mode:?}")) {
                if mode == GiMode::Path && value != prepared.scene.render.background {
                    assert!(replay.samples.iter().any(|(_, t, _)| !t.bounces.is_empty()), "{mode:?} {renderer} ({x}, {y}): no bounce recorded: {:?}", replay.samples.iter().map(|(_, t, _)| (t.rays.len(), t.bounces.len())).collect::<Vec<_>>());
                }
            }
        }
        // Another seed, another image.
        let mut other = s.clone();
        other.gi.seed = 1;
        if mode == GiMode::Path {
            assert!(bits(&render("raytrace", &prepared, &other)) != bits(&one), "{mode:?}: the seed changes nothing");
        }
    }
}

/// Photon mapping approaches the path-traced truth as photons are added,
/// down to the density estimate's bias: more photons, less error.
#[test]
fn photon_error_falls_with_more_photons() {
    let prepared = PreparedScene::new(builtin("cornell-gi"));
    let mut s = RenderSettings::for_scene(&prepared.scene);
    s.width = 100;
    s.height = 100;
    s.spp = 64;
    s.gi.mode = GiMode::Path;
    let truth = render("raytrace", &prepared, &s);
    s.spp = 1;
    s.gi.mode = GiMode::Photons;
    let mut errors = Vec::new();
    for photons in [2_000u32, 20_000, 200_000] {
        s.gi.photons = photons;
        let e = relative_rmse(&render("raytrace", &prepared, &s), &truth);
        eprintln!("{photons} photons: rmse/mean {:.2}% against 64-spp path tracing", e * 100.0);
        errors.push(e);
    }
    assert!(errors[1] < errors[0] && errors[2] < errors[1], "{errors:?}");
    // And the map adds light: without it the image is the direct light.
    let none = relative_rmse(&render("raytrace", &prepared, &RenderSettings { gi: Default::default(), ..s.clone() }), &truth);
    assert!(errors[2] < 0.5 * none, "photons {} vs direct only {none}", errors[2]);
}

/// A glass ball over a floor under a point light: the light it focuses
/// makes a bright spot in the middle of its own shadow. Photon mapping
/// stores the photons that came through the glass, so the spot appears;
/// without indirect light, and with path tracing from the eye (which can
/// never hit a point light through a refraction), the shadow stays dark there.
#[test]
fn photons_show_the_caustic_under_a_glass_ball() {
    let text = r#"
        [camera]
        eye = [0.0, 2.0, 3.0]
        target = [0.0, 0.0, 0.0]
        fov_y_deg = 30.0
        [render]
        width = 96
        height = 96
        background = [0.0, 0.0, 0.0]
        [[light]]
        type = "point"
        position = [0.0, 6.0, 0.0]
        power = [400.0, 400.0, 400.0]
        [materials.floor]
        lambertian = [0.8, 0.8, 0.8]
        [materials.glass]
        transmission = [1.0, 1.0, 1.0]
        ior = 1.5
        [[object]]
        type = "quad"
        vertices = [[-3.0, 0.0, 3.0], [3.0, 0.0, 3.0], [3.0, 0.0, -3.0], [-3.0, 0.0, -3.0]]
        material = "floor"
        [[object]]
        type = "sphere"
        center = [0.0, 0.9, 0.0]
        radius = 0.5
        material = "glass"
    "#;
    let scene = pinhole::scene::file::parse_scene(text, "caustic test", std::path::Path::new("."), "caustic").unwrap();
    let prepared = PreparedScene::new(scene);
    let mut s = RenderSettings::for_scene(&prepared.scene);
    s.gi.photons = 400_000;
    s.gi.photon_k = 32;
    // The camera looks past the ball at the floor beneath it.
    let view = prepared.scene.camera.view(s.width, s.height);
    let pixel_of = |p: pinhole::math::Vec3| {
        let q = view.project_camera(view.to_camera(p));
        (q.x as u32, q.y as u32)
    };
    let spot_and_ring = |img: &[Radiance]| {
        let at = |p: pinhole::math::Vec3| {
            let (x, y) = pixel_of(p);
            img[(x + y * s.width) as usize].x as f64
        };
        use pinhole::math::Vec3;
        let spot = at(Vec3::ZERO);
        // Floor points inside the ball's shadow but outside the focused spot.
        let ring = [Vec3::new(0.3, 0.0, 0.0), Vec3::new(-0.3, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.3), Vec3::new(0.0, 0.0, -0.3)].iter().map(|p| at(*p)).sum::<f64>() / 4.0;
        (spot, ring)
    };
    s.gi.mode = GiMode::Photons;
    let (spot, ring) = spot_and_ring(&render("raytrace", &prepared, &s));
    eprintln!("photons: spot {spot:.4}, ring {ring:.4}");
    assert!(spot > 3.0 * ring + 1e-3, "no caustic: spot {spot}, ring {ring}");
    s.gi.mode = GiMode::None;
    let (spot_none, _) = spot_and_ring(&render("raytrace", &prepared, &s));
    assert!(spot_none < 0.2 * spot, "the spot is there without photons: {spot_none}");
    s.gi.mode = GiMode::Path;
    s.spp = 16;
    let (spot_path, ring_path) = spot_and_ring(&render("raytrace", &prepared, &s));
    eprintln!("path: spot {spot_path:.4}, ring {ring_path:.4}");
    assert!(spot_path < 0.2 * spot, "path tracing found the caustic of a point light: {spot_path}");
}

/// Adaptive sampling spends the budget where the noise is: pixels stop once
/// their estimated relative error is below the target, so the frame takes
/// far fewer samples than spp x pixels, noisy pixels take more than quiet
/// ones, and a replayed pixel takes exactly the samples its frame took.
#[test]
fn adaptive_sampling_stops_settled_pixels() {
    let (prepared, mut s) = small("cornell-gi", GiMode::Path, 128);
    s.adaptive = Some(0.1);
    let mut acc = render::frame::Accumulator::new(&s);
    let r = render::renderer_by_name("raytrace").unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    while !acc.is_complete() {
        acc.render_band(r.as_ref(), &prepared, s.height, &cancel).unwrap();
    }
    let taken = acc.samples_taken();
    let budget = (s.width * s.height * s.spp) as u64;
    eprintln!("adaptive 10%: {taken} samples of a budget of {budget} ({:.0}%)", 100.0 * taken as f64 / budget as f64);
    assert!(taken < budget * 3 / 4, "{taken} of {budget}");
    assert!(taken >= (s.width * s.height * render::frame::ADAPTIVE_MIN_SAMPLES) as u64);
    let frame = acc.finish().pixels;
    let full = render("raytrace", &prepared, &s);
    assert_eq!(bits(&frame), bits(&full), "render_frame takes the same adaptive samples");
    let mut counts = Vec::new();
    for (x, y) in pixels(3, 12, s.width, s.height) {
        let replay = render::replay_pixel(r.as_ref(), &prepared, &s, x, y).unwrap();
        assert_eq!(bits(&[replay.radiance]), bits(&frame[(x + y * s.width) as usize..][..1]), "({x}, {y})");
        counts.push(replay.samples.len());
    }
    assert!(counts.iter().min() < counts.iter().max(), "every pixel took the same samples: {counts:?}");
}

/// `pinhole pixel` tells a path bounce by bounce, as text and as JSON, and
/// the JSON's radiance is the frame's.
#[test]
fn the_pixel_command_replays_a_path() {
    let bin = env!("CARGO_BIN_EXE_pinhole");
    let args = ["pixel", "cornell-gi", "30", "40", "--gi", "path", "--spp", "2", "--width", "64", "--height", "64"];
    let text = std::process::Command::new(bin).args(args).output().unwrap();
    assert!(text.status.success());
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("sampled bounce(s)") && text.contains("pdf") && text.contains("throughput"), "{text}");
    let json = std::process::Command::new(bin).args(args).arg("--json").output().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let bounce = &v["samples"][0]["bounces"][0];
    for key in ["depth", "direction", "pdf", "weight", "throughput", "survival"] {
        assert!(!bounce[key].is_null(), "bounce lacks {key}: {bounce}");
    }
    let prepared = PreparedScene::new(builtin("cornell-gi"));
    let mut s = RenderSettings::for_scene(&prepared.scene);
    (s.width, s.height, s.spp, s.gi.mode) = (64, 64, 2, GiMode::Path);
    let frame = render("raytrace", &prepared, &s);
    let got: Vec<f32> = v["radiance"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect();
    let want = frame[(30 + 40 * 64) as usize];
    assert!((got[0] - want.x).abs() <= 1e-6 * want.x.max(1.0), "{got:?} vs {want}");
}
