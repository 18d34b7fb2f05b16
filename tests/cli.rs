//! The command line as scripts use it: outputs, JSON fields, and
//! errors that are one sentence with a non-zero exit, never a panic.

use std::path::PathBuf;
use std::process::{Command, Output};

fn pinhole(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().expect("run pinhole")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn assert_clean_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure, stderr: {err}");
    assert!(!err.contains("panicked") && !err.contains("internal error"), "panic: {err}");
    assert_eq!(err.trim().lines().count(), 1, "one line expected: {err}");
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
}

#[test]
fn render_png_exr_ppm_with_stats() {
    let png = tmp("t.png");
    let stats = tmp("t.json");
    let out = pinhole(&["render", "one-triangle", "-o", png.to_str().unwrap(), "--width", "80", "--height", "50", "--stats", stats.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (80, 50));
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in ["renderer", "width", "height", "spp", "threads", "triangles", "load_ms", "build_ms", "render_ms", "primary_rays", "shadow_rays", "secondary_rays"] {
        assert!(j.get(key).is_some(), "stats lack {key}: {j}");
    }
    assert_eq!(j["primary_rays"], 4000);
    assert_eq!(j["renderer"], "raytrace:bvh");

    let exr = tmp("t.exr");
    assert!(pinhole(&["render", "one-triangle", "-o", exr.to_str().unwrap(), "--width", "80", "--height", "50"]).status.success());
    let ppm = tmp("t.ppm");
    assert!(pinhole(&["render", "one-triangle", "-o", ppm.to_str().unwrap(), "--width", "8", "--height", "5"]).status.success());
    assert!(std::fs::read_to_string(&ppm).unwrap().starts_with("P3\n8 5\n255\n"));

    // compare: an image against itself has zero error; JSON has the contract's fields.
    let out = pinhole(&["compare", exr.to_str().unwrap(), exr.to_str().unwrap(), "--json"]);
    assert!(out.status.success());
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["rmse"], 0.0);
    assert!(j.get("rel_mse").is_some() && j.get("max_abs").is_some());
    assert_eq!(j["flip"], 0.0);
}

#[test]
fn bench_prints_json() {
    let out = pinhole(&["bench", "spheres", "--frames", "2", "--width", "64", "--height", "40", "--threads", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["threads"], 1);
    assert_eq!(j["primary_rays"], 64 * 40);
    assert!(j["render_ms_min"].as_f64().unwrap() <= j["render_ms"].as_f64().unwrap());
}

#[test]
fn list_names_everything() {
    let out = pinhole(&["list"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for name in ["raytrace:brute", "raytrace:bvh", "one-triangle", "triangle-ground", "teapot", "spheres", "bunny", "barycentric"] {
        assert!(text.contains(name), "list lacks {name}");
    }
}

#[test]
fn errors_are_one_sentence() {
    let png = tmp("e.png");
    let p = png.to_str().unwrap();
    assert_clean_error(&pinhole(&["render", "nope", "-o", p]), "built-in");
    assert_clean_error(&pinhole(&["render", "/nonexistent.toml", "-o", p]), "/nonexistent.toml");
    assert_clean_error(&pinhole(&["render", "one-triangle", "-o", p, "--renderer", "magic"]), "magic");
    assert_clean_error(&pinhole(&["render", "one-triangle", "-o", p, "--view", "xray"]), "xray");
    assert_clean_error(&pinhole(&["render", "one-triangle", "-o", p, "--spp", "0"]), "--spp");
    assert_clean_error(&pinhole(&["render", "one-triangle", "-o", p, "--threads", "0"]), "--threads");
    assert_clean_error(&pinhole(&["render", "one-triangle", "-o", "/tmp/x.gif"]), "unknown image type");
    assert_clean_error(&pinhole(&["render", "one-triangle", "-o", "/nonexistent-dir/x.png", "--width", "8", "--height", "5"]), "cannot write");
    let bad = tmp("bad.toml");
    std::fs::write(&bad, "[render]\nwidht = 3\n").unwrap();
    assert_clean_error(&pinhole(&["render", bad.to_str().unwrap(), "-o", p]), "bad.toml:2");
    assert_clean_error(&pinhole(&["compare", "/nonexistent.exr", p]), "/nonexistent.exr");
}

#[test]
fn chart_writes_png_and_csv() {
    let png = tmp("chart.png");
    let out = pinhole(&[
        "chart", "spheres", "-o", png.to_str().unwrap(), "--sweep", "spp", "--width", "40", "--height", "25", "--spp-list", "1,4", "--reference-spp", "16",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(image::open(&png).is_ok());
    let csv = std::fs::read_to_string(png.with_extension("csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], "renderer,spp,ms,rel_rmse,flip");
    assert_eq!(rows.len(), 5, "two renderers x two spp: {csv}");
    // More samples, less error (against a 16-spp reference with the same sample pattern family).
    let err = |row: &str| row.split(',').nth(3).unwrap().parse::<f64>().unwrap();
    assert!(err(rows[2]) < err(rows[1]), "{csv}");
    assert_clean_error(&pinhole(&["chart", "spheres", "-o", png.to_str().unwrap(), "--sweep", "spp", "--spp-list", "1,x"]), "--spp-list");
}

/// A full disk behind standard output is one sentence and a non-zero exit,
/// never a panic; a reader that goes away (`| head`) ends the program quietly.
#[test]
fn failed_standard_output_is_an_error_not_a_panic() {
    let bin = env!("CARGO_BIN_EXE_pinhole");
    if std::path::Path::new("/dev/full").exists() {
        for args in [vec!["list"], vec!["pixel", "one-triangle", "5", "5", "--width", "16", "--height", "16", "--json"]] {
            let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
            let out = std::process::Command::new(bin).args(&args).stdout(full).output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert!(err.contains("cannot write to standard output") && !err.contains("internal error"), "{args:?}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
        }
    }
    // Megabytes of JSON into a pipe whose reader closed at once.
    let mut child = std::process::Command::new(bin)
        .args(["pixel", "spheres", "10", "10", "--json", "--spp", "256", "--width", "32", "--height", "32"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.is_empty(), "a closed pipe printed: {err}");
}

/// opengl casts no shadow rays: asked for them (the default), it draws
/// shadow maps and says so on stderr, before it loads its driver (so the
/// notice is there with or without one).
#[test]
fn opengl_says_it_draws_shadow_maps_for_shadow_rays() {
    let png = tmp("gl.png");
    let stats = tmp("gl.json");
    let out = pinhole(&["render", "spheres", "--renderer", "opengl", "--width", "80", "--height", "50", "-o", png.to_str().unwrap(), "--stats", stats.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("note: opengl cannot trace shadow rays; drawing shadow maps instead (--shadows map)"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    if out.status.success() {
        let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        assert_eq!(j["shadows"], "map", "the statistics say what was drawn");
    } else {
        assert!(err.contains("no usable OpenGL driver"), "the only way this fails: {err}");
    }
    // Asked for what it draws, it says nothing.
    let out = pinhole(&["render", "spheres", "--renderer", "opengl", "--shadows", "none", "--width", "80", "--height", "50", "-o", png.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("note:"), "{}", String::from_utf8_lossy(&out.stderr));
    // Other renderers trace the rays asked for, without a note.
    let out = pinhole(&["render", "spheres", "--width", "80", "--height", "50", "-o", png.to_str().unwrap()]);
    assert!(out.status.success() && out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
}
