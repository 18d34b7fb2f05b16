//! Hostile input, one case per way it used to go wrong: every input file is
//! bounded and must be a regular file, allocations that input controls fail
//! early with one sentence, NaN and infinity never reach a pixel or a
//! metric, writes go through symlinks and special files, and out-of-range
//! values are refused with the valid range.

use pinhole::math::Vec3;
use pinhole::scene::file::load_scene_file;
use pinhole::scene::load::load_scene;
use pinhole::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

fn temp_dir() -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!("pinhole-robust-{}-{}", std::process::id(), N.fetch_add(1, Ordering::Relaxed)));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn pinhole(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().expect("run pinhole")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn load_err(dir: &Path, toml: &str) -> String {
    let p = write(dir, "s.toml", toml);
    match load_scene_file(&p) {
        Ok(_) => panic!("expected an error for:\n{toml}"),
        Err(e) => {
            assert_eq!(e.lines().count(), 1, "{e}");
            e
        }
    }
}

/// Renders `scene` at 16x12 with the ray tracer.
fn render_tiny(scene: Scene) -> Vec<Vec3> {
    let mut settings = pinhole::render::RenderSettings::for_scene(&scene);
    settings.width = 16;
    settings.height = 12;
    let prepared = pinhole::render::PreparedScene::new(scene);
    let r = pinhole::render::renderer_by_name("raytrace").unwrap();
    pinhole::render::render_frame(r.as_ref(), &prepared, &settings, &AtomicBool::new(false), None).unwrap().pixels
}

const CAMERA: &str = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n";
const LIGHT: &str = "[[light]]\ntype = \"point\"\nposition = [0, 2, 3]\npower = [50, 50, 50]\n";
const QUAD: &str = "[[object]]\ntype = \"quad\"\nvertices = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]\n";

/// CRC-32 (as PNG chunks use it), to forge a PNG header.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// A tiny valid PNG whose header then claims `w` x `h` pixels.
fn png_declaring(w: u32, h: u32) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::RgbImage::new(1, 1).write_to(&mut out, image::ImageFormat::Png).unwrap();
    let mut png = out.into_inner();
    png[16..20].copy_from_slice(&w.to_be_bytes());
    png[20..24].copy_from_slice(&h.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    png
}

#[test]
fn input_files_must_be_regular_and_bounded() {
    let d = temp_dir();
    // /dev/zero never ends and a FIFO never answers: both refused at once.
    for toml in [
        "[[object]]\ntype = \"mesh\"\nfile = \"/dev/zero\"\n".to_string(),
        format!("{QUAD}material = \"m\"\n[materials.m]\nlambertian = [1, 1, 1]\ntexture = \"/dev/zero\"\n"),
    ] {
        let e = load_err(&d, &toml);
        assert!(e.contains("/dev/zero") && e.contains("not a regular file"), "{e}");
    }
    assert!(Command::new("mkfifo").arg(d.join("fifo.obj")).status().unwrap().success());
    let e = load_err(&d, "[[object]]\ntype = \"mesh\"\nfile = \"fifo.obj\"\n");
    assert!(e.contains("fifo.obj") && e.contains("not a regular file"), "{e}");
    write(&d, "z.obj", "mtllib ../../../../../../dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let s = load_scene(d.join("z.obj").to_str().unwrap()).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("not a regular file")), "{:?}", s.warnings);
    let e = load_scene(d.to_str().unwrap()).err().unwrap();
    assert!(e.contains("directory"), "{e}");
}

#[test]
fn image_sizes_are_checked_from_the_header() {
    let d = temp_dir();
    write(&d, "huge.png", png_declaring(20000, 20000));
    write(&d, "big.png", png_declaring(12000, 12000));
    for name in ["huge.png", "big.png"] {
        let e = load_err(&d, &format!("{CAMERA}{QUAD}material = \"m\"\n[materials.m]\nlambertian = [1, 1, 1]\ntexture = \"{name}\"\n"));
        assert!(e.contains(name) && e.contains("pixels") || e.contains("per side"), "{e}");
    }
    // A texture nothing is drawn with is not read at all.
    let p = write(&d, "s.toml", format!("{CAMERA}{QUAD}[materials.unused]\nlambertian = [1, 1, 1]\ntexture = \"huge.png\"\n"));
    assert!(load_scene_file(&p).is_ok());
    write(&d, "a.obj", "mtllib a.mtl\nusemtl used\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write(&d, "a.mtl", "newmtl used\nKd 1 1 1\nnewmtl unused\nKd 1 1 1\nmap_Kd huge.png\n");
    assert!(load_scene(d.join("a.obj").to_str().unwrap()).is_ok());
    // compare reads through the same check.
    let out = pinhole(&["compare", d.join("huge.png").to_str().unwrap(), d.join("huge.png").to_str().unwrap()]);
    assert!(!out.status.success() && stderr(&out).contains("20000x20000"), "{}", stderr(&out));
}

#[test]
fn allocations_that_input_controls_fail_early() {
    let d = temp_dir();
    let out = pinhole(&["render", "one-triangle", "-o", d.join("a.exr").to_str().unwrap(), "--width", "16384", "--height", "16384"]);
    assert!(!out.status.success() && stderr(&out).contains("33554432 pixels"), "{}", stderr(&out));
    let lights: String = (0..200).map(|i| format!("[[light]]\ntype = \"point\"\nposition = [{i}, 2, 3]\npower = [1, 1, 1]\n")).collect();
    let scene = write(&d, "lights.toml", format!("{CAMERA}{QUAD}{lights}"));
    let out = pinhole(&["render", scene.to_str().unwrap(), "-o", d.join("a.png").to_str().unwrap(), "--shadows", "map"]);
    assert!(!out.status.success() && stderr(&out).contains("limit of 1024 MiB"), "{}", stderr(&out));
    let out = pinhole(&["render", "one-triangle", "-o", d.join("t.png").to_str().unwrap(), "--width", "8", "--height", "6", "--threads", "100000"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("warning: --threads 100000 is more than 256"), "{}", stderr(&out));
    let out = pinhole(&["chart", "one-triangle", "-o", d.join("c.png").to_str().unwrap(), "--sweep", "spp", "--reference-spp", "0"]);
    assert!(!out.status.success() && stderr(&out).contains("--reference-spp 0"), "{}", stderr(&out));
    let out = pinhole(&["pixel", "one-triangle", "10", "10", "--width", "64", "--height", "40", "--spp", "300", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((j["spp"].as_u64(), j["samples"].as_array().unwrap().len(), j["samples_omitted"].as_u64()), (Some(300), 256, Some(44)));
}

#[test]
fn non_finite_and_negative_texels_are_refused() {
    let d = temp_dir();
    for (name, bad) in [("nan.exr", f32::NAN), ("inf.exr", f32::INFINITY), ("neg.exr", -1.0)] {
        let px = vec![Vec3::ONE, Vec3::new(0.5, bad, 0.5)];
        pinhole::image_io::save_image(&d.join(name), 2, 1, &px, 1.0).unwrap();
        let e = load_err(&d, &format!("{CAMERA}{QUAD}material = \"m\"\n[materials.m]\nlambertian = [1, 1, 1]\ntexture = \"{name}\"\n"));
        assert!(e.contains(name) && e.contains("texel (1, 0)"), "{e}");
    }
    // compare and the metrics refuse non-finite images instead of reporting no difference.
    let nan = d.join("nan.exr");
    let out = pinhole(&["compare", nan.to_str().unwrap(), nan.to_str().unwrap()]);
    assert!(!out.status.success() && stderr(&out).contains("NaN or infinite"), "{}", stderr(&out));
}

#[test]
fn mtl_values_are_checked_as_scene_materials_are() {
    let d = temp_dir();
    write(&d, "a.obj", "mtllib a.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    for (mtl, needle) in [("Kd -1 -1 -1", "Kd"), ("Ns -100", "Ns"), ("Ks 3e38 0 0", "Ks"), ("Kd 1e39 1 1", "Kd")] {
        write(&d, "a.mtl", format!("newmtl a\n{mtl}\n"));
        let e = load_scene(d.join("a.obj").to_str().unwrap()).err().unwrap_or_else(|| panic!("{mtl} accepted"));
        assert!(e.contains("a.obj") && e.contains(needle) && e.contains("\"a\""), "{e}");
    }
}

#[test]
fn huge_vectors_are_directions_or_out_of_range() {
    let d = temp_dir();
    let plain = format!("{CAMERA}{LIGHT}{QUAD}");
    let base = render_tiny(load_scene_file(&write(&d, "a.toml", &plain)).unwrap());
    assert!(base.iter().any(|p| p.x > 0.0), "the quad is lit");
    // A huge up vector is a direction: the same image.
    let up = format!("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nup = [0, 1e20, 0]\n{LIGHT}{QUAD}");
    assert_eq!(render_tiny(load_scene_file(&write(&d, "b.toml", &up)).unwrap()), base);
    // So is a huge light direction.
    let dir = |d: &str| format!("{CAMERA}[[light]]\ntype = \"directional\"\ndirection = {d}\nirradiance = [2, 2, 2]\n{QUAD}");
    let small = render_tiny(load_scene_file(&write(&d, "c.toml", dir("[0, -1, -1]"))).unwrap());
    let huge = render_tiny(load_scene_file(&write(&d, "d.toml", dir("[0, -1e20, -1e20]"))).unwrap());
    assert!(small.iter().any(|p| p.x > 0.0));
    assert_eq!(huge, small);
    // Positions beyond the coordinate range are refused with the range.
    for toml in [
        format!("{CAMERA}{LIGHT}[[object]]\ntype = \"triangle\"\nvertices = [[-1e10, -1e10, 0], [1e10, -1e10, 0], [0, 1e10, 0]]\n"),
        format!("[camera]\neye = [0, 0, 1e20]\ntarget = [0, 0, 0]\n{LIGHT}{QUAD}"),
        format!("{CAMERA}{LIGHT}[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1e9\n"),
        format!("{CAMERA}{LIGHT}{QUAD}scale = 1e38\n"),
        format!("{CAMERA}{LIGHT}{QUAD}scale = 5e5\ntranslate = [8e5, 0, 0]\n"),
    ] {
        let e = load_err(&d, &toml);
        assert!(e.contains("1e6"), "{e}");
    }
    write(&d, "far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 1e38\nf 1 2 3\n");
    let e = load_scene(d.join("far.obj").to_str().unwrap()).err().unwrap();
    assert!(e.contains("far.obj") && e.contains("vertex 3") && e.contains("1e6"), "{e}");
    let e = load_err(&d, "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov_y_deg = 1e-45\n");
    assert!(e.contains("between 0.001 and 179.9"), "{e}");
    for key in ["lambertian = [3e38, 0, 0]", "sharpness = 3e38", "ior = 1e30"] {
        let e = load_err(&d, &format!("[materials.m]\n{key}\n"));
        assert!(e.contains("at most"), "{e}");
    }
}

#[test]
fn error_messages_are_short_and_say_what_is_allowed() {
    let d = temp_dir();
    let long = format!("[camera]\neye = \"{}\"\n", "A".repeat(5_000_000));
    let e = load_err(&d, &long);
    assert!(e.len() < 1000, "{} bytes", e.len());
    let e = load_err(&d, &format!("{QUAD}scale = \"big\"\n"));
    assert!(e.contains("one number or an array of three numbers"), "{e}");
    let e = load_err(&d, "[[object]]\ntype = \"mesh\"\nfile = \"a.obj\"\nnormals = \"wavy\"\n");
    assert!(e.contains("\"auto\", \"smooth\" or \"flat\""), "{e}");
    for toml in ["[camera]\neye = [0, 0, 3, 99]\n", "[[light]]\ntype = \"point\"\nposition = [0, 1, 2]\npower = [1, 1, 1, nan]\n"] {
        let e = load_err(&d, toml);
        assert!(e.contains("3 numbers, found 4"), "{e}");
    }
}

#[test]
fn suspicious_meshes_warn() {
    let d = temp_dir();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write(&d, "missing.obj", format!("mtllib nowhere.mtl\nusemtl a\n{tri}"));
    let s = load_scene(d.join("missing.obj").to_str().unwrap()).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("nowhere.mtl") && w.contains("default material")), "{:?}", s.warnings);
    write(&d, "undef.obj", format!("mtllib u.mtl\nusemtl ghost\n{tri}"));
    write(&d, "u.mtl", "newmtl real\nKd 1 1 1\n");
    let s = load_scene(d.join("undef.obj").to_str().unwrap()).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("usemtl ghost")), "{:?}", s.warnings);
    write(&d, "flat.obj", format!("{tri}v 2 2 2\nf 1 1 4\n"));
    let s = load_scene(d.join("flat.obj").to_str().unwrap()).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("skipped 1 triangles with zero area")), "{:?}", s.warnings);
}

#[test]
fn outputs_are_checked_before_rendering_and_written_through_links() {
    let d = temp_dir();
    // The output is checked before the scene is even loaded.
    let out = pinhole(&["render", "no-such-scene", "-o", d.join("missing/a.png").to_str().unwrap()]);
    assert!(!out.status.success() && stderr(&out).contains("missing/a.png"), "{}", stderr(&out));
    let out = pinhole(&["chart", "no-such-scene", "-o", d.join("missing/c.png").to_str().unwrap()]);
    assert!(!out.status.success() && stderr(&out).contains("missing/c.png"), "{}", stderr(&out));
    let real = write(&d, "real.json", "old");
    let link = d.join("link.json");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let png = d.join("t.png");
    let out = pinhole(&["render", "one-triangle", "-o", png.to_str().unwrap(), "--width", "8", "--height", "6", "--stats", link.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::read_to_string(&real).unwrap().contains("\"renderer\""));
    let out = pinhole(&["render", "one-triangle", "-o", png.to_str().unwrap(), "--width", "8", "--height", "6", "--stats", "/dev/null"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
}
