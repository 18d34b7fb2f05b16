//! The error views of `pinhole render` against a reference image: the
//! signed error is antisymmetric when image and reference swap places, and
//! each pixel's colour reads back, through the legend's scale (reported as
//! `error_scale`), as the luminance difference recomputed here from the two
//! linear EXRs; the relative view is viridis on the documented log scale.
//! Missing or mismatched references are one-sentence errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pinhole(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().expect("run pinhole")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-error-views-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

const SIZE: [&str; 4] = ["--width", "48", "--height", "32"];

/// Renders `teapot` with `config` and `extra` into `out`; the stats JSON
/// when asked for.
fn render(out: &Path, config: &[&str], extra: &[&str]) -> Option<serde_json::Value> {
    let stats = out.with_extension("json");
    let mut args = vec!["render", "teapot", "-o", out.to_str().unwrap(), "--stats", stats.to_str().unwrap()];
    args.extend_from_slice(&SIZE);
    args.extend_from_slice(config);
    args.extend_from_slice(extra);
    let o = pinhole(&args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).ok()
}

fn luminance(p: &image::Rgb<f32>) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// Two configurations that differ visibly, both ways: smooth against
/// faceted shading (a facet is brighter than the smooth surface on one
/// side of a vertex and darker on the other).
const A: [&str; 2] = ["--interpolation", "phong"];
const B: [&str; 2] = ["--interpolation", "flat"];

#[test]
fn signed_error_is_antisymmetric_and_reads_back_as_the_difference() {
    let (a_exr, b_exr, ab, ba) = (tmp("a.exr"), tmp("b.exr"), tmp("ab.png"), tmp("ba.png"));
    render(&a_exr, &A, &[]);
    render(&b_exr, &B, &[]);
    let j_ab = render(&ab, &A, &["--view", "signed-error", "--reference", b_exr.to_str().unwrap()]).unwrap();
    let j_ba = render(&ba, &B, &["--view", "signed-error", "--reference", a_exr.to_str().unwrap()]).unwrap();
    assert_eq!(j_ab["error_scale"], j_ba["error_scale"], "one scale whichever is the reference");
    let scale = j_ab["error_scale"].as_f64().unwrap() as f32;
    let (a, b) = (image::open(&a_exr).unwrap().into_rgb32f(), image::open(&b_exr).unwrap().into_rgb32f());
    let (ab, ba) = (image::open(&ab).unwrap().into_rgb8(), image::open(&ba).unwrap().into_rgb8());
    // The scale is the largest difference rounded up to 1, 2 or 5 times a
    // power of ten.
    let largest = a.pixels().zip(b.pixels()).map(|(p, q)| (luminance(p) - luminance(q)).abs()).fold(0.0f32, f32::max);
    assert!(largest > 0.01, "the configurations differ: {largest}");
    let power = 10f32.powf(largest.log10().floor());
    let nice = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * power).find(|v| *v >= largest * (1.0 - 1e-6)).unwrap();
    assert!((scale - nice).abs() <= 1e-6 * nice, "scale {scale}, largest {largest}, expected {nice}");
    let (mut brighter, mut darker) = (0, 0);
    for (x, y, p) in ab.enumerate_pixels() {
        let q = ba.get_pixel(x, y);
        assert_eq!([p[0], p[1], p[2]], [q[1], q[0], q[2]], "({x}, {y}): red and green exchange when A and B swap");
        assert_eq!(p[2], 0, "no blue");
        // Reading the legend: full red is +scale, full green -scale, black 0.
        let read = (p[0] as f32 - p[1] as f32) / 255.0 * scale;
        let d = luminance(a.get_pixel(x, y)) - luminance(b.get_pixel(x, y));
        assert!((read - d).abs() <= 1.0 / 255.0 * scale, "({x}, {y}): read {read}, difference {d}");
        assert!(p[0] == 0 || p[1] == 0);
        brighter += (d > 0.02 * scale) as u32;
        darker += (d < -0.02 * scale) as u32;
    }
    assert!(brighter > 10 && darker > 10, "both signs are seen: {brighter} brighter, {darker} darker");
}

#[test]
fn relative_error_is_viridis_on_a_log_scale_of_the_ratio() {
    const VIRIDIS: [[f32; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let (a_exr, b_exr, rel) = (tmp("ra.exr"), tmp("rb.exr"), tmp("rel.png"));
    render(&a_exr, &A, &[]);
    render(&b_exr, &B, &[]);
    let j = render(&rel, &A, &["--view", "error", "--reference", b_exr.to_str().unwrap()]).unwrap();
    assert_eq!(j["reference"], b_exr.to_str().unwrap());
    let (a, b) = (image::open(&a_exr).unwrap().into_rgb32f(), image::open(&b_exr).unwrap().into_rgb32f());
    let shown = image::open(&rel).unwrap().into_rgb8();
    let mut decades = std::collections::BTreeSet::new();
    for (x, y, p) in shown.enumerate_pixels() {
        let (la, lb) = (luminance(a.get_pixel(x, y)), luminance(b.get_pixel(x, y)));
        // |a - b| / b, b floored at 1e-3, on log10 from 1e-3 to 10.
        let r = (la - lb).abs() / lb.max(1e-3);
        let t = if r > 0.0 { ((r / 1e-3).log10() / 4.0).clamp(0.0, 1.0) } else { 0.0 };
        decades.insert((t * 4.0).floor() as i32);
        let i = ((t * 8.0).floor() as usize).min(7);
        let f = t * 8.0 - i as f32;
        for k in 0..3 {
            let want = VIRIDIS[i][k] * (1.0 - f) + VIRIDIS[i + 1][k] * f;
            assert!((p[k] as f32 - want).abs() <= 1.5, "({x}, {y}) channel {k}: {} vs {want} at ratio {r}", p[k]);
        }
    }
    assert!(decades.len() >= 2, "the errors span decades: {decades:?}");
}

#[test]
fn error_views_without_a_usable_reference_are_one_sentence() {
    let (small, out) = (tmp("small.exr"), tmp("never.png"));
    let o = pinhole(&["render", "spheres", "-o", small.to_str().unwrap(), "--width", "8", "--height", "8"]);
    assert!(o.status.success());
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--view", "signed-error"], "--reference"),
        (vec!["--view", "error", "--reference", small.to_str().unwrap()], "8x8"),
        (vec!["--view", "absolute-error", "--reference", "/nonexistent/ref.exr"], "ref.exr"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["render", "spheres", "-o", out.to_str().unwrap()];
        args.extend_from_slice(&SIZE);
        args.extend_from_slice(&extra);
        let o = pinhole(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?} should fail");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        assert!(err.contains(needle), "{err:?} should name {needle}");
    }
    assert!(!out.exists(), "no image is written");
}

#[test]
fn a_cropped_error_view_compares_with_the_references_rectangle() {
    // An image against itself is black everywhere in the signed view, also
    // cropped (the reference is cut to the crop), where an uncut reference
    // would misalign and show differences.
    let (full, crop) = (tmp("self.exr"), tmp("crop.png"));
    render(&full, &A, &[]);
    render(&crop, &A, &["--view", "signed-error", "--reference", full.to_str().unwrap(), "--crop", "10,5,40,30"]);
    let shown = image::open(&crop).unwrap().into_rgb8();
    assert_eq!(shown.dimensions(), (30, 25));
    assert!(shown.pixels().all(|p| p.0 == [0, 0, 0]));
}
