//! `--subsample N`: a grid of pixels traced, the rest interpolated; with
//! `--subsample-contrast C`, cells whose corners differ traced in full.
//! Checked against the full frame in both families.

use std::path::{Path, PathBuf};
use std::process::Command;

fn out_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-subsample-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Renders and returns (pixels, stats JSON).
fn render(args: &[&str], out: &Path) -> (Vec<[f32; 3]>, serde_json::Value) {
    let stats = out.with_extension("json");
    let o = Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .args(["render", "cornell-gi", "--width", "120", "--height", "90", "-o", out.to_str().unwrap(), "--stats", stats.to_str().unwrap()])
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(out).unwrap().into_rgb32f();
    (img.pixels().map(|p| p.0).collect(), serde_json::from_str(&std::fs::read_to_string(stats).unwrap()).unwrap())
}

fn rel_rmse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let (mut se, mut sum) = (0f64, 0f64);
    for (p, q) in a.iter().zip(b) {
        for c in 0..3 {
            se += ((p[c] - q[c]) as f64).powi(2);
            sum += q[c] as f64;
        }
    }
    (se / (a.len() * 3) as f64).sqrt() / (sum / (a.len() * 3) as f64)
}

#[test]
fn the_grid_is_traced_exactly_and_the_rest_interpolated_in_both_families() {
    let d = out_dir();
    for renderer in ["raytrace", "rasterize"] {
        let (full, full_stats) = render(&["--renderer", renderer], &d.join(format!("{renderer}-full.exr")));
        let (sub, stats) = render(&["--renderer", renderer, "--subsample", "4"], &d.join(format!("{renderer}-sub.exr")));
        // Columns 0, 4, ..., 116 and the last (119); rows 0, 4, ..., 88 and 89.
        let (xs, ys): (Vec<u32>, Vec<u32>) = ((0..120).step_by(4).chain([119]).collect(), (0..90).step_by(4).chain([89]).collect());
        assert_eq!(xs.len() * ys.len(), 31 * 24);
        if renderer == "raytrace" {
            assert_eq!(stats["primary_rays"], (31 * 24) as u64, "one eye ray per grid pixel");
            assert_eq!(full_stats["primary_rays"], 120 * 90);
        }
        for &y in &ys {
            for &x in &xs {
                let i = (x + y * 120) as usize;
                assert_eq!(sub[i], full[i], "{renderer}: grid pixel ({x}, {y}) is traced as in the full frame");
            }
        }
        // Between grid pixels the image is interpolated: edges are smeared, so
        // the error is large; refining the cells whose corners differ cures most of it.
        let smeared = rel_rmse(&sub, &full);
        let (refined, refined_stats) = render(&["--renderer", renderer, "--subsample", "4", "--subsample-contrast", "0.3"], &d.join(format!("{renderer}-refined.exr")));
        let cured = rel_rmse(&refined, &full);
        assert!(smeared > 0.1, "{renderer}: pure interpolation must miss the edges: {smeared}");
        assert!(cured < 0.04 && cured < smeared / 4.0, "{renderer}: refinement: {cured} vs {smeared}");
        if renderer == "raytrace" {
            let rays = refined_stats["primary_rays"].as_u64().unwrap();
            assert!(rays > 31 * 24 && rays < 120 * 90 * 6 / 10, "refinement traces some cells, not most: {rays}");
        }
    }
}

#[test]
fn bad_subsample_arguments_are_one_sentence() {
    let d = out_dir();
    let out = d.join("bad.png");
    for (args, needle) in [
        (vec!["--subsample", "3"], "--subsample 3"),
        (vec!["--subsample-contrast", "0.1"], "--subsample"),
        (vec!["--subsample", "4", "--subsample-contrast=-1"], "--subsample-contrast"),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_pinhole")).args(["render", "cornell-gi", "-o", out.to_str().unwrap()]).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle) && err.trim().lines().count() == 1, "{args:?}: {err}");
    }
}
