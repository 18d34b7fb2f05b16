//! Untrusted input: bad scene files and OBJs give one clear message naming
//! the file, line and key, and never panic.

use pinhole::scene::file::load_scene_file;
use pinhole::scene::load::load_scene;
use std::path::{Path, PathBuf};

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-errors-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Loads `text` as a scene file and returns the error, which must mention every `needles`.
fn error_of(text: &str, needles: &[&str]) -> String {
    // One directory per call: the tests run in parallel.
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = temp_dir(&format!("toml{}", N.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    let p = write(&dir, "bad.toml", text);
    let err = match load_scene_file(&p) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    };
    for n in needles {
        assert!(err.contains(n), "error {err:?} does not mention {n:?}");
    }
    assert!(!err.contains('\n'), "error is not one line: {err:?}");
    err
}

const OK_HEADER: &str = "[camera]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n";

#[test]
fn missing_file() {
    let e = load_scene_file(Path::new("/nonexistent/scene.toml")).err().unwrap();
    assert!(e.contains("/nonexistent/scene.toml") && e.contains("cannot read"), "{e}");
    let e = load_scene("no-such-builtin").err().unwrap();
    assert!(e.contains("one-triangle"), "should list the built-in scenes: {e}");
}

#[test]
fn unknown_key_names_file_line_and_key() {
    let e = error_of(&format!("{OK_HEADER}\n[render]\nwidth = 10\nbackgruond = [0.0, 0.0, 0.0]\n"), &["bad.toml:", "backgruond"]);
    assert!(e.contains(":7:"), "line 7 expected: {e}");
    error_of("[[object]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\ncolour = 3\n", &["colour", ":5:"]);
}

#[test]
fn wrong_types() {
    error_of("[render]\nwidth = \"wide\"\n", &["bad.toml:2", "width"]);
    error_of("[camera]\neye = [0.0, 1.0]\n", &["bad.toml:2"]);
    error_of("[[light]]\ntype = \"point\"\nposition = [0.0, 1.0, 2.0]\npower = 10.0\n", &["bad.toml:4"]);
}

#[test]
fn bad_values() {
    error_of("[camera]\nnear = 5.0\nfar = 1.0\n", &["bad.toml:1", "near"]);
    error_of("[camera]\nfov_x_deg = 90.0\nfov_y_deg = 60.0\n", &["both"]);
    error_of("[render]\nwidth = 0\n", &["render.width"]);
    error_of("[[light]]\ntype = \"spot\"\nposition = [0.0, 1.0, 2.0]\n", &["light 1", "spot"]);
    error_of("[[light]]\ntype = \"point\"\nposition = [nan, 1.0, 2.0]\npower = [1.0, 1.0, 1.0]\n", &["position", "finite"]);
    error_of("[[light]]\ntype = \"point\"\nposition = [0.0, 1.0, 2.0]\npower = [-1.0, 1.0, 1.0]\n", &["power"]);
    error_of("[[object]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = -1.0\n", &["object 1", "radius"]);
    error_of("[[object]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"gold\"\n", &["gold", "not defined"]);
    error_of("[[object]]\ntype = \"triangle\"\nvertices = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]\n", &["zero area"]);
    error_of("[[object]]\ntype = \"triangle\"\nvertices = [[0.0, 0.0, 0.0], [inf, 1.0, 1.0], [2.0, 0.0, 2.0]]\n", &["finite"]);
    error_of("[[object]]\ntype = \"quad\"\nvertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]\n", &["4 vertices"]);
    error_of("[[object]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nscale = [1.0, 2.0, 1.0]\n", &["scale"]);
    error_of("[[object]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nfile = \"x.obj\"\n", &["`file` is not a key of a sphere"]);
    error_of("[[object]]\ntype = \"cone\"\n", &["cone"]);
    error_of("[materials.m]\nsharpness = nan\n", &["sharpness"]);
    error_of("this is not toml", &["bad.toml:1"]);
}

#[test]
fn bad_objs() {
    let dir = temp_dir("obj");
    let scene = |obj: &str| format!("[[object]]\ntype = \"mesh\"\nfile = \"{obj}\"\n");
    let check = |obj_name: &str, obj_text: Option<&str>, needles: &[&str]| {
        if let Some(t) = obj_text {
            write(&dir, obj_name, t);
        }
        let p = write(&dir, "s.toml", &scene(obj_name));
        let e = load_scene_file(&p).err().unwrap_or_else(|| panic!("{obj_name} should fail"));
        for n in needles {
            assert!(e.contains(n), "{e:?} lacks {n:?}");
        }
        // A bare .obj on the command line takes the same checks.
        if obj_text.is_some() {
            assert!(load_scene(dir.join(obj_name).to_str().unwrap()).is_err());
        }
    };
    check("missing.obj", None, &["s.toml:1", "missing.obj"]);
    check("range.obj", Some("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), &["range.obj"]);
    check("nan.obj", Some("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), &["nan.obj"]);
    check("flat.obj", Some("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), &["no triangles with area"]);
    check("garbage.obj", Some("v 0 0\nf a b c\n"), &["garbage.obj"]);
    check("normals.obj", Some("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//7\n"), &["normals.obj"]);
}

#[test]
fn degenerate_mesh_triangles_are_skipped_with_a_warning() {
    let dir = temp_dir("degenerate");
    write(&dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");
    let p = write(&dir, "s.toml", "[[object]]\ntype = \"mesh\"\nfile = \"m.obj\"\n");
    let s = load_scene_file(&p).unwrap();
    assert_eq!(s.triangles.len(), 1);
    assert!(s.warnings.iter().any(|w| w.contains("zero area")), "{:?}", s.warnings);
}

#[test]
fn good_file_with_placement_and_mtl() {
    let dir = temp_dir("good");
    write(&dir, "m.mtl", "newmtl red\nKd 0.9 0.1 0.1\nKs 0.2 0.2 0.2\nNs 50\n");
    write(&dir, "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
    let p = write(
        &dir,
        "s.toml",
        "[[object]]\ntype = \"mesh\"\nfile = \"m.obj\"\nscale = 2.0\nrotate_deg = [0.0, 90.0, 0.0]\ntranslate = [1.0, 0.0, 0.0]\n",
    );
    let s = load_scene_file(&p).unwrap();
    let t = &s.triangles.at(0);
    // (1,0,0) scaled by 2 -> (2,0,0), rotated 90 degrees about y -> (0,0,-2), translated -> (1,0,-2).
    assert!((t.v[1] - glam::Vec3::new(1.0, 0.0, -2.0)).length() < 1e-5, "{:?}", t.v);
    let m = &s.materials[t.material as usize];
    assert_eq!(m.lambertian, glam::Vec3::new(0.9, 0.1, 0.1));
    assert_eq!(m.glossy, glam::Vec3::splat(0.2));
    assert_eq!(m.sharpness, 50.0);
}

#[test]
fn bare_obj_is_framed() {
    let dir = temp_dir("bare");
    let p = write(&dir, "tri.obj", "v -1 -1 5\nv 1 -1 5\nv 0 1 5\nf 1 2 3\n");
    let s = load_scene(p.to_str().unwrap()).unwrap();
    let view = s.camera.view(s.render.width, s.render.height);
    assert!(s.camera.eye.z > 5.0, "camera on +z: {:?}", s.camera.eye);
    assert_eq!(s.lights.len(), 1);
    for v in s.triangles.at(0).v {
        let (q, _) = view.project(v).expect("in front of the camera");
        assert!(q.x >= 0.0 && q.x <= s.render.width as f32 && q.y >= 0.0 && q.y <= s.render.height as f32, "{q}");
    }
    let pinhole::scene::Light::Point { position, .. } = s.lights[0] else { panic!() };
    assert!(position.y > s.camera.eye.y && position.z > 5.0, "light above and on the camera's side");
}

/// MTL colours: `Kd 0.5` means grey (the format allows one number), and a
/// colour with two numbers or a word is an error naming the MTL file and
/// line. tobj alone panics on both.
#[test]
fn mtl_colours_with_one_or_two_numbers() {
    let dir = temp_dir("mtl");
    write(&dir, "a.obj", "mtllib a.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write(&dir, "a.mtl", "newmtl a\nKd 0.5\nKa 1\nKs 0.25\nKe 1\n");
    let scene = load_scene(&dir.join("a.obj").to_string_lossy()).unwrap();
    let m = scene.materials.iter().find(|m| m.name.ends_with("/a")).expect("material a");
    assert_eq!(m.lambertian, pinhole::math::Vec3::splat(0.5));
    assert_eq!(m.glossy, pinhole::math::Vec3::splat(0.25));
    for (mtl, needle) in [("newmtl a\nKd 0.5 0.2\n", "a.mtl:2: Kd takes one or three numbers"), ("newmtl a\n\nKs 0.1 x 0.3\n", "a.mtl:3: Ks takes numbers")] {
        write(&dir, "a.mtl", mtl);
        let err = load_scene(&dir.join("a.obj").to_string_lossy()).err().expect("an error");
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}
