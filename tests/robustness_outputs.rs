//! Hostile use, second round: outputs that would destroy an input, options
//! at and past their bounds, references that make error meaningless,
//! inside-out solids, materials nothing draws, names that are both a
//! built-in scene and a folder, and saved settings out of range. Each case
//! is refused (or repaired) in one sentence, and a refused run leaves every
//! file byte for byte as it was.

use pinhole::math::Vec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

fn temp_dir() -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!("pinhole-robust2-{}-{}", std::process::id(), N.fetch_add(1, Ordering::Relaxed)));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn pinhole_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).current_dir(dir).args(args).output().expect("run pinhole")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Every file under `dir` with its bytes, sorted by name.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// A refused run: exit 1, one line on stderr containing `needle`.
fn assert_refused(out: &Output, needle: &str) {
    let e = stderr(out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "not one sentence: {e}");
    assert!(e.contains(needle), "{e} lacks {needle}");
}

const SCENE: &str = r#"[camera]
eye = [0, 0, 3]
target = [0, 0, 0]
[[light]]
type = "point"
position = [0, 2, 3]
power = [50, 50, 50]
[materials.g]
lambertian = [0.5, 0.5, 0.5]
texture = "textures/t.png"
[[object]]
type = "quad"
material = "g"
vertices = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]
uvs = [[0, 0], [1, 0], [1, 1], [0, 1]]
"#;

/// A scene folder: `s.toml` with its texture `textures/t.png`.
fn scene_dir() -> PathBuf {
    let d = temp_dir();
    std::fs::create_dir_all(d.join("textures")).unwrap();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    pinhole::image_io::save_image(&d.join("textures/t.png"), 4, 4, &[Vec3::new(0.8, 0.2, 0.1); 16], 1.0).unwrap();
    d
}

#[test]
fn no_output_may_be_an_input_or_another_output_by_any_name() {
    let d = scene_dir();
    std::fs::hard_link(d.join("textures/t.png"), d.join("hard.png")).unwrap();
    std::os::unix::fs::symlink(d.join("textures/t.png"), d.join("soft.png")).unwrap();
    std::os::unix::fs::symlink(d.join("s.toml"), d.join("soft.json")).unwrap();
    let before = snapshot(&d);
    let size = ["--width", "16", "--height", "12"];
    let cases: &[(&[&str], &str)] = &[
        (&["render", "s.toml", "-o", "o.exr", "--stats", "s.toml"], "read as input"),
        (&["render", "s.toml", "-o", "textures/t.png"], "read as input"),
        (&["render", "s.toml", "-o", "textures/../textures/t.png"], "read as input"),
        (&["render", "s.toml", "-o", "hard.png"], "read as input"),
        (&["render", "s.toml", "-o", "soft.png"], "read as input"),
        (&["render", "s.toml", "-o", "o.exr", "--stats", "soft.json"], "read as input"),
        (&["render", "s.toml", "-o", "x.exr", "--stats", "x.exr"], "also the output"),
        (&["render", "s.toml", "-o", "x.exr", "--stats", "./x.exr"], "also the output"),
        (&["chart", "s.toml", "-o", "textures/t.png", "--sweep", "spp", "--spp-list", "1"], "read as input"),
    ];
    for (args, needle) in cases {
        let args: Vec<&str> = args.iter().chain(&size).copied().collect();
        let out = pinhole_in(&d, &args);
        assert_refused(&out, needle);
        assert_eq!(snapshot(&d), before, "{args:?} changed a file");
    }
    // An output of its own is written.
    assert!(pinhole_in(&d, &["render", "s.toml", "-o", "fine.exr", "--width", "16", "--height", "12"]).status.success());
}

#[test]
fn bad_numbers_on_the_command_line_get_one_sentence_naming_the_option() {
    let d = temp_dir();
    for (args, needle) in [
        (&["render", "spheres", "-o", "o.exr", "--seed", "-1"][..], "--seed: \"-1\" is not a whole number from 0 to"),
        (&["pixel", "spheres", "-1", "0"][..], "argument X: \"-1\" is not a whole number from 0 to 4294967295"),
        (&["render", "spheres", "-o", "o.exr", "--spp", "lots"][..], "--spp: \"lots\" is not a whole number"),
        (&["bench", "spheres", "--frames", "4294967295"][..], "--frames 4294967295 is not between 1 and 10000"),
    ] {
        let out = pinhole_in(&d, args);
        let e = stderr(&out);
        assert!(!out.status.success(), "{args:?}");
        assert_eq!(e.trim_end().lines().count(), 1, "{args:?}: {e}");
        assert!(e.contains(needle), "{args:?}: {e}");
    }
}

#[test]
fn the_gallery_caps_threads_as_every_other_subcommand_does() {
    let d = temp_dir();
    let out = pinhole_in(&d, &["gallery", "-o", "g", "--case", "near-plane", "--threads", "5000"]);
    let e = stderr(&out);
    assert!(out.status.success(), "{e}");
    assert!(e.contains("--threads 5000 is more than 256; using 256"), "{e}");
    let out = pinhole_in(&d, &["gallery", "-o", "g", "--case", "near-plane", "--threads", "0"]);
    assert_refused(&out, "--threads must be at least 1");
}

#[test]
fn references_that_make_error_meaningless_are_refused() {
    let d = temp_dir();
    let (w, h) = (16u32, 12u32);
    let n = (w * h) as usize;
    let save = |name: &str, w: u32, h: u32, px: Vec<Vec3>| pinhole::image_io::save_image(&d.join(name), w, h, &px, 1.0).unwrap();
    save("zeros.exr", w, h, vec![Vec3::ZERO; n]);
    let mut negative = vec![Vec3::splat(0.5); n];
    negative[7] = Vec3::new(0.5, -0.25, 0.5);
    save("negative.exr", w, h, negative);
    save("small.exr", 8, 6, vec![Vec3::splat(0.5); 48]);
    for (file, needle) in [("zeros.exr", "black everywhere"), ("negative.exr", "1 pixels with negative values"), ("small.exr", "is 8x6 but")] {
        for sweep in ["methods", "spp"] {
            let out = pinhole_in(&d, &["chart", "spheres", "-o", "c.png", "--sweep", sweep, "--reference", file, "--width", "16", "--height", "12"]);
            assert_refused(&out, needle);
        }
    }
    assert!(!d.join("c.png").exists() && !d.join("c.csv").exists());
}

/// The cube as `assets/models/cube.obj` has it, with every face's winding reversed.
const INSIDE_OUT_CUBE: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 5 7 6\nf 5 8 7\nf 2 4 1\nf 2 3 4\nf 6 3 2\nf 6 7 3\nf 1 8 5\nf 1 4 8\nf 8 3 7\nf 8 4 3\nf 1 6 2\nf 1 5 6\n";

#[test]
fn an_inside_out_csg_operand_is_turned_right_side_out_with_a_warning() {
    let d = temp_dir();
    std::fs::write(d.join("cube.obj"), INSIDE_OUT_CUBE).unwrap();
    let scene = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n[render]\nbackground = [0, 0, 1]\n\
[[light]]\ntype = \"point\"\nposition = [0, 2, 5]\npower = [80, 80, 80]\n\
[[object]]\ntype = \"csg\"\nop = \"intersection\"\n\
a = { type = \"mesh\", file = \"cube.obj\", normals = \"flat\" }\n\
b = { type = \"sphere\", center = [0, 0, 0], radius = 1.3 }\n";
    std::fs::write(d.join("s.toml"), scene).unwrap();
    let loaded = pinhole::scene::file::load_scene_file(&d.join("s.toml")).unwrap();
    assert!(loaded.warnings.iter().any(|w| w.contains("inside out")), "{:?}", loaded.warnings);
    // The solid is drawn: the centre pixel is lit, not the blue background.
    let mut settings = pinhole::render::RenderSettings::for_scene(&loaded);
    (settings.width, settings.height) = (16, 12);
    let prepared = pinhole::render::PreparedScene::new(loaded);
    let r = pinhole::render::renderer_by_name("raytrace").unwrap();
    let frame = pinhole::render::render_frame(r.as_ref(), &prepared, &settings, &std::sync::atomic::AtomicBool::new(false), None).unwrap();
    let centre = frame.pixels[6 * 16 + 8];
    assert!(centre.x > 0.05 && centre.z < 0.9, "the inside-out solid vanished: {centre}");
}

#[test]
fn opengl_asks_only_about_materials_something_is_drawn_with() {
    let d = temp_dir();
    let scene = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[[light]]\ntype = \"point\"\nposition = [0, 2, 3]\npower = [50, 50, 50]\n\
[materials.unused_glass]\ntransmission = [1, 1, 1]\nior = 1.5\n\
[materials.unused_mirror]\nmirror = [0.9, 0.9, 0.9]\n\
[[object]]\ntype = \"quad\"\nvertices = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]\n";
    std::fs::write(d.join("s.toml"), scene).unwrap();
    let loaded = pinhole::scene::file::load_scene_file(&d.join("s.toml")).unwrap();
    let gl = pinhole::render::renderer_by_name("opengl").unwrap();
    let settings = pinhole::render::RenderSettings::for_scene(&loaded);
    assert!(pinhole::render::admit::admit(gl.as_ref(), &loaded, &settings).is_ok());
    // Drawn with the glass, it is refused as before.
    let drawn = scene.replace("vertices", "material = \"unused_glass\"\nvertices");
    std::fs::write(d.join("s.toml"), drawn).unwrap();
    let loaded = pinhole::scene::file::load_scene_file(&d.join("s.toml")).unwrap();
    let e = pinhole::render::admit::admit(gl.as_ref(), &loaded, &settings).unwrap_err();
    assert!(e.contains("glass"), "{e}");
}

#[test]
fn a_bare_name_is_the_built_in_scene_and_a_path_is_the_file() {
    let d = temp_dir();
    std::fs::create_dir_all(d.join("textures")).unwrap();
    let out = pinhole_in(&d, &["render", "textures", "-o", "o.png", "--width", "16", "--height", "12"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = pinhole_in(&d, &["render", "./textures", "-o", "p.png", "--width", "16", "--height", "12"]);
    assert_refused(&out, "it is a directory");
}

#[test]
fn saved_settings_out_of_range_are_repaired_by_the_command_lines_bounds() {
    use pinhole::app::settings_store::ViewerSettings;
    let mut saved = ViewerSettings::default();
    saved.render.gi.ao_distance = f32::NAN;
    saved.render.gi.photons = 4_000_000_000;
    saved.render.shadow_bump = -1.0;
    saved.render.pcf_radius = f32::INFINITY;
    let (fixed, said) = saved.sanitized(&["raytrace:bvh"]);
    assert_eq!(fixed.render, ViewerSettings::default().render);
    assert_eq!(said.len(), 4, "{said:?}");
    for field in ["gi.ao_distance", "gi.photons", "shadow_bump", "pcf_radius"] {
        assert!(said.iter().any(|s| s.contains(field)), "{field} not named in {said:?}");
    }
    // The command line refuses the same value with the same bound.
    let out = pinhole_in(&temp_dir(), &["render", "spheres", "-o", "o.exr", "--photons", "4000000000"]);
    assert_refused(&out, "--photons 4000000000 is not between 1 and 50000000");
}

#[test]
fn a_photon_map_past_its_memory_budget_is_refused_before_it_is_built() {
    let d = temp_dir();
    let started = std::time::Instant::now();
    let out = pinhole_in(&d, &["render", "cornell-gi", "-o", "o.exr", "--gi", "photons", "--photons", "50000000", "--width", "32", "--height", "24"]);
    assert_refused(&out, "more than the photon map's budget of 4 GiB");
    assert!(stderr(&out).contains("per photon shot, measured on 4096"), "{}", stderr(&out));
    // Refused from the estimate, not after the build (which takes about a minute).
    assert!(started.elapsed().as_secs() < 30);
    assert!(!d.join("o.exr").exists());
}

#[test]
fn ctrl_c_stops_a_render_and_leaves_every_file_as_it_was() {
    let d = scene_dir();
    std::fs::write(d.join("o.exr"), b"an older image").unwrap();
    let before = snapshot(&d);
    // Minutes of work: still running when the interrupt comes.
    let child = Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .current_dir(&d)
        .args(["render", "cornell-gi", "-o", "o.exr", "--gi", "path", "--spp", "65536", "--width", "64", "--height", "48"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Past ten seconds, so the render has said how far it is.
    std::thread::sleep(std::time::Duration::from_millis(11_500));
    let sent = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(sent.success());
    let started = std::time::Instant::now();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(stderr(&out).contains("interrupted"), "{}", stderr(&out));
    // Not a terminal: the progress comes as whole lines, every ten seconds.
    assert!(stderr(&out).lines().any(|l| l.starts_with("rendering") && l.contains("s elapsed")), "no progress line: {}", stderr(&out));
    assert!(started.elapsed().as_secs() < 20, "the render did not stop promptly");
    assert_eq!(snapshot(&d), before, "an interrupted run changed or left a file");
}
