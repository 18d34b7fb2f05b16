//! `pinhole chart --sweep methods`: the configurations that matter for a
//! scene, measured against a truth that includes bounced light, written as
//! a CSV with the contract's columns and a PNG.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pinhole(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).env("PINHOLE_CACHE_DIR", cache).output().expect("run pinhole")
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-chart-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

struct Row {
    method: String,
    ms: f64,
    rel_rmse: f64,
    flip: f64,
}

fn rows(csv: &str) -> Vec<Row> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("method,ms,rel_rmse,flip"), "{csv}");
    lines
        .map(|l| {
            let f: Vec<&str> = l.rsplitn(4, ',').collect();
            Row { method: f[3].to_string(), ms: f[2].parse().unwrap(), rel_rmse: f[1].parse().unwrap(), flip: f[0].parse().unwrap() }
        })
        .collect()
}

/// Error levels that differ by more than 1.5x from their neighbours.
fn distinct_levels(rows: &[Row]) -> usize {
    let mut e: Vec<f64> = rows.iter().map(|r| r.rel_rmse).collect();
    e.sort_by(f64::total_cmp);
    1 + e.windows(2).filter(|w| w[1] > w[0] * 1.5).count()
}

fn chart(scene: &str, d: &Path, extra: &[&str]) -> (Vec<Row>, String) {
    let png = d.join(format!("{scene}.png"));
    let mut args = vec!["chart", scene, "-o", png.to_str().unwrap(), "--width", "64", "--height", "48", "--reference-spp", "64"];
    args.extend_from_slice(extra);
    let out = pinhole(&args, &d.join("cache"));
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{err}");
    assert!(image::open(&png).is_ok(), "no chart PNG");
    (rows(&std::fs::read_to_string(png.with_extension("csv")).unwrap()), err)
}

#[test]
fn teapot_and_cornell_sweep_at_least_twelve_methods_at_three_error_levels() {
    for scene in ["teapot", "cornell-gi"] {
        let d = dir(scene);
        let (rows, _) = chart(scene, &d, &[]);
        assert!(rows.len() >= 12, "{scene}: {} configurations", rows.len());
        assert!(distinct_levels(&rows) >= 3, "{scene}: error levels {:?}", rows.iter().map(|r| r.rel_rmse).collect::<Vec<_>>());
        assert!(rows.iter().all(|r| r.ms > 0.0 && r.rel_rmse.is_finite() && r.flip.is_finite()));
        // The truth includes bounced light: 64 path samples beat every direct-lighting method.
        let path = rows.iter().find(|r| r.method == "raytrace:bvh --spp 64 --gi path").expect("path row");
        let direct = rows.iter().find(|r| r.method == "raytrace:bvh --spp 16").expect("direct row");
        assert!(path.rel_rmse < direct.rel_rmse, "{scene}: path {} vs direct {}", path.rel_rmse, direct.rel_rmse);
        // Both families trace the same paths behind primary visibility.
        let hybrid = rows.iter().find(|r| r.method == "rasterize:fixed --spp 16 --gi path").unwrap();
        let traced = rows.iter().find(|r| r.method == "raytrace:bvh --spp 16 --gi path").unwrap();
        assert!((hybrid.rel_rmse / traced.rel_rmse - 1.0).abs() < 0.05, "{scene}: {} vs {}", hybrid.rel_rmse, traced.rel_rmse);
    }
}

#[test]
fn the_path_traced_reference_is_cached_between_runs() {
    let d = dir("cache");
    let (first, err1) = chart("spheres", &d, &[]);
    assert!(!err1.contains("(cached)"), "{err1}");
    assert_eq!(std::fs::read_dir(d.join("cache")).unwrap().count(), 1);
    let (second, err2) = chart("spheres", &d, &[]);
    assert!(err2.contains("(cached)"), "{err2}");
    // The same truth: every deterministic configuration measures the same error.
    for (a, b) in first.iter().zip(&second) {
        assert_eq!((&a.method, a.rel_rmse), (&b.method, b.rel_rmse));
    }
}

#[test]
fn a_scene_reference_key_is_the_truth() {
    let d = dir("key");
    let exr = d.join("truth.exr");
    let out = pinhole(&["render", "spheres", "-o", exr.to_str().unwrap(), "--width", "64", "--height", "48"], &d);
    assert!(out.status.success());
    let source = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/spheres.toml")).unwrap();
    let scene = d.join("spheres.toml");
    std::fs::write(&scene, source.replacen("[render]", "[render]\nreference = \"truth.exr\"", 1)).unwrap();
    let (rows, err) = chart(scene.to_str().unwrap(), &d, &[]);
    assert!(err.contains("truth.exr"), "{err}");
    // The reference was rendered by raytrace:bvh at 1 spp: that row has no error at all.
    let same = rows.iter().find(|r| r.method == "raytrace:bvh").unwrap();
    assert_eq!(same.rel_rmse, 0.0);
    assert!(rows.iter().any(|r| r.rel_rmse > 0.01));
    // --reference names another file, which wins over the key; one of another size is an error.
    let small = d.join("small.exr");
    assert!(pinhole(&["render", "spheres", "-o", small.to_str().unwrap(), "--width", "32", "--height", "24"], &d).status.success());
    let png = d.join("x.png");
    let out = pinhole(&["chart", scene.to_str().unwrap(), "-o", png.to_str().unwrap(), "--width", "64", "--height", "48", "--reference", small.to_str().unwrap()], &d);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("32x24") && err.contains("64x48") && !err.contains("panicked"), "{err}");
}

#[test]
fn bad_chart_arguments_are_one_sentence() {
    let d = dir("bad");
    let png = d.join("c.png");
    for (args, needle) in [(vec!["--sweep", "colours"], "--sweep"), (vec!["--metric", "psnr"], "--metric")] {
        let mut all = vec!["chart", "spheres", "-o", png.to_str().unwrap()];
        all.extend(args);
        let out = pinhole(&all, &d);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(needle) && err.trim().lines().count() == 1, "{err}");
    }
}

/// `--sweep gi`: each method of indirect light as a curve, path tracing at
/// each of `--spp-list`; with more samples the path-traced error falls,
/// and a peer's CSV is read (and a bad one refused with its line).
#[test]
fn the_gi_sweep_draws_each_method_as_a_curve_beside_a_peer() {
    let d = dir("gi");
    let peer = d.join("peer.csv");
    std::fs::write(&peer, "series,label,ms,rel_rmse\nmitsuba,1 spp,5,1.2\nmitsuba,16 spp,50,0.4\n").unwrap();
    let (rows, err) = chart("cornell-gi", &d, &["--sweep", "gi", "--spp-list", "1,16", "--peer", peer.to_str().unwrap()]);
    let path: Vec<&Row> = rows.iter().filter(|r| r.method.contains("--gi path")).collect();
    assert_eq!(path.len(), 2, "path at 1 and 16 spp");
    assert!(path[1].rel_rmse < path[0].rel_rmse * 0.6, "16 spp must be well below 1 spp: {} vs {}", path[1].rel_rmse, path[0].rel_rmse);
    assert_eq!(rows.iter().filter(|r| r.method.contains("--gi photons")).count(), 4);
    assert!(rows.iter().filter(|r| !r.method.contains("--gi")).count() >= 3, "direct light only");
    assert!(err.contains("ambient"), "the scene has no ambient term, so ao is left out and the user is told: {err}");
    // The best path-traced and photon images beat direct light alone, which misses the bounced light.
    let direct = rows.iter().filter(|r| !r.method.contains("--gi")).map(|r| r.rel_rmse).fold(f64::INFINITY, f64::min);
    assert!(path[1].rel_rmse < direct, "{} vs {direct}", path[1].rel_rmse);

    std::fs::write(&peer, "series,label,ms,rel_rmse\nmitsuba,1 spp,five,1.2\n").unwrap();
    let png = d.join("bad.png");
    let out = pinhole(&["chart", "cornell-gi", "-o", png.to_str().unwrap(), "--sweep", "gi", "--peer", peer.to_str().unwrap()], &d);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("peer.csv:2") && err.contains("ms") && err.trim().lines().count() == 1, "{err}");
    let out = pinhole(&["chart", "cornell-gi", "-o", png.to_str().unwrap(), "--peer", peer.to_str().unwrap()], &d);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--peer"), "a peer only goes on the gi chart: {err}");
}
