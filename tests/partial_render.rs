//! Partial renders and their merge: a crop, N tiles and sample ranges
//! of a frame are the whole frame's pixels (tiles and crops bit for bit,
//! sample ranges to float rounding), and `pinhole merge` refuses parts that
//! do not belong together, writing nothing.

use pinhole::math::Radiance;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pinhole(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().expect("run pinhole")
}

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-partial-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ok(out: Output) -> Output {
    assert!(out.status.success(), "pinhole failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Renders `scene` with `args` plus `extra` into `out`.
fn render(scene: &str, args: &[&str], extra: &[&str], out: &Path) {
    let mut all = vec!["render", scene, "-o", out.to_str().unwrap(), "--width", "64", "--height", "48"];
    all.extend_from_slice(args);
    all.extend_from_slice(extra);
    ok(pinhole(&all));
}

fn load(path: &Path) -> pinhole::image_io::LinearImage {
    pinhole::image_io::load_image(path).unwrap()
}

fn bits(v: &[Radiance]) -> Vec<[u32; 3]> {
    v.iter().map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()]).collect()
}

fn merge(parts: &[PathBuf], out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["merge".to_string()];
    args.extend(parts.iter().map(|p| p.to_str().unwrap().to_string()));
    args.extend(["-o".to_string(), out.to_str().unwrap().to_string()]);
    args.extend(extra.iter().map(|s| s.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    pinhole(&args)
}

/// The configurations a part must reproduce exactly: the ray caster, a
/// rasterizer, the path tracer and photon mapping (whose map every part
/// builds from the whole scene).
const CONFIGS: &[(&str, &[&str])] = &[
    ("cornell-box", &["--renderer", "raytrace"]),
    ("cornell-box", &["--renderer", "rasterize"]),
    ("cornell-gi", &["--gi", "path", "--spp", "4"]),
    ("cornell-gi", &["--gi", "photons", "--photons", "2000"]),
];

#[test]
fn crops_and_tiles_are_the_whole_frame_bit_for_bit() {
    let d = dir("tiles");
    for (k, (scene, args)) in CONFIGS.iter().enumerate() {
        let whole_path = d.join(format!("whole{k}.exr"));
        render(scene, args, &[], &whole_path);
        let whole = load(&whole_path);

        let crop_path = d.join(format!("crop{k}.exr"));
        render(scene, args, &["--crop", "10,7,50,31"], &crop_path);
        let crop = load(&crop_path);
        assert_eq!((crop.width, crop.height), (40, 24));
        let expected: Vec<Radiance> = (7..31).flat_map(|y| (10..50).map(move |x| (x, y))).map(|(x, y)| whole.pixels[x + y * 64]).collect();
        assert_eq!(bits(&crop.pixels), bits(&expected), "{scene} {args:?}: the crop differs from the whole frame");

        let n = 5;
        let tiles: Vec<PathBuf> = (0..n).map(|i| d.join(format!("tile{k}-{i}.exr"))).collect();
        for (i, t) in tiles.iter().enumerate() {
            render(scene, args, &["--tile", &format!("{i}/{n}")], t);
        }
        let merged_path = d.join(format!("merged{k}.exr"));
        // Given out of order: the merge places parts by their records.
        let mut shuffled = tiles.clone();
        shuffled.reverse();
        ok(merge(&shuffled, &merged_path, &[]));
        let merged = load(&merged_path);
        assert_eq!((merged.width, merged.height), (64, 48));
        assert_eq!(bits(&merged.pixels), bits(&whole.pixels), "{scene} {args:?}: merged tiles differ from the whole frame");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Set to `1` where a driver must exist (CI installs Mesa): the OpenGL
/// test fails instead of skipping without one (as in tests/opengl.rs).
const REQUIRE_GL: &str = "PINHOLE_REQUIRE_GL";

/// The OpenGL renderer draws a tile's rows through a scissor over the
/// whole frame's viewport, so a tile's pixels are the whole frame's.
#[test]
fn opengl_tiles_are_the_whole_frame_bit_for_bit() {
    if let Err(e) = pinhole::render::opengl::driver() {
        assert!(!std::env::var(REQUIRE_GL).is_ok_and(|v| v == "1"), "{REQUIRE_GL}=1 but there is no OpenGL driver: {e}");
        eprintln!("skipped: {e}");
        return;
    }
    let d = dir("opengl");
    for (k, args) in [&["--renderer", "opengl", "--shadows", "map"][..], &["--renderer", "opengl", "--msaa", "4", "--spp", "2"][..]].iter().enumerate() {
        let whole_path = d.join(format!("whole{k}.exr"));
        render("cornell-box", args, &[], &whole_path);
        let whole = load(&whole_path);
        let n = 3;
        let tiles: Vec<PathBuf> = (0..n).map(|i| d.join(format!("tile{k}-{i}.exr"))).collect();
        for (i, t) in tiles.iter().enumerate() {
            render("cornell-box", args, &["--tile", &format!("{i}/{n}")], t);
        }
        let merged_path = d.join(format!("merged{k}.exr"));
        ok(merge(&tiles, &merged_path, &[]));
        assert_eq!(bits(&load(&merged_path).pixels), bits(&whole.pixels), "{args:?}: merged OpenGL tiles differ from the whole frame");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// rmse over the image divided by its mean, over all channels.
fn relative_rmse(a: &[Radiance], b: &[Radiance]) -> f64 {
    let (mut e2, mut m) = (0f64, 0f64);
    for (p, q) in a.iter().zip(b) {
        let d = *p - *q;
        e2 += (d.x as f64).powi(2) + (d.y as f64).powi(2) + (d.z as f64).powi(2);
        m += (q.x + q.y + q.z) as f64;
    }
    let n = 3.0 * a.len() as f64;
    (e2 / n).sqrt() / (m / n)
}

#[test]
fn sample_ranges_sum_to_the_whole_frame() {
    let d = dir("ranges");
    let args: &[&str] = &["--gi", "path", "--spp", "16"];
    let whole_path = d.join("whole.exr");
    let stats_path = d.join("whole.json");
    render("cornell-gi", args, &["--stats", stats_path.to_str().unwrap()], &whole_path);
    let whole = load(&whole_path);
    let ranges = ["0..5", "5..6", "6..16"];
    let parts: Vec<PathBuf> = (0..ranges.len()).map(|i| d.join(format!("range{i}.exr"))).collect();
    for (r, p) in ranges.iter().zip(&parts) {
        render("cornell-gi", args, &["--sample-range", r], p);
    }
    let merged_path = d.join("merged.exr");
    let merged_stats = d.join("merged.json");
    ok(merge(&parts, &merged_path, &["--stats", merged_stats.to_str().unwrap()]));
    let merged = load(&merged_path);
    let e = relative_rmse(&merged.pixels, &whole.pixels);
    assert!(e <= 1e-6, "merged sample ranges are {e} (rmse/mean) from the whole frame");
    // The ranges really are different samples: one alone is far off.
    let one = pinhole::part_file::read(&parts[0]).unwrap();
    let scaled: Vec<Radiance> = one.pixels.iter().map(|s| *s * (1.0 / 5.0)).collect();
    assert!(relative_rmse(&scaled, &whole.pixels) > 1e-3);

    // Tiles of sample ranges merge too.
    let mixed: Vec<PathBuf> = (0..4).map(|i| d.join(format!("mixed{i}.exr"))).collect();
    for (i, p) in mixed.iter().enumerate() {
        render("cornell-gi", args, &["--tile", &format!("{}/2", i / 2), "--sample-range", ["0..7", "7..16"][i % 2]], p);
    }
    let mixed_path = d.join("mixed.exr");
    ok(merge(&mixed, &mixed_path, &[]));
    assert!(relative_rmse(&load(&mixed_path).pixels, &whole.pixels) <= 1e-6);

    // The merged statistics are the whole render's, with summed counters.
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&merged_stats).unwrap()).unwrap();
    let w: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats_path).unwrap()).unwrap();
    for (key, _) in w.as_object().unwrap() {
        assert!(j.get(key).is_some(), "merged stats lack {key}");
    }
    assert_eq!(j["spp"], 16);
    assert_eq!(j["parts"], 3);
    assert_eq!(j["primary_rays"], w["primary_rays"]);
    assert!(j["wall_clock_ms"].as_f64().unwrap() > 0.0);
    assert_eq!(j["sample_range"], serde_json::Value::Null);
    let part_stats = |p: &PathBuf| pinhole::part_file::read(p).unwrap().record.stats["render_ms"].as_f64().unwrap();
    let summed: f64 = parts.iter().map(part_stats).sum();
    assert!((j["render_ms"].as_f64().unwrap() - summed).abs() < 1e-6);
    let _ = std::fs::remove_dir_all(&d);
}

/// Asserts a merge of `parts` fails in one sentence mentioning `needle` and writes nothing.
fn refused(parts: &[PathBuf], out: &Path, needle: &str) {
    let o = merge(parts, out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "merge should refuse ({needle}) but succeeded");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
    assert!(!out.exists(), "a refused merge wrote {}", out.display());
}

#[test]
fn merge_refuses_parts_that_do_not_belong_together() {
    let d = dir("refusals");
    let base: &[&str] = &["--spp", "4", "--gi", "path"];
    let t = |name: &str, scene: &str, extra: &[&str]| {
        let p = d.join(name);
        render(scene, base, extra, &p);
        p
    };
    let t0 = t("t0.exr", "cornell-gi", &["--tile", "0/3"]);
    let t1 = t("t1.exr", "cornell-gi", &["--tile", "1/3"]);
    let t2 = t("t2.exr", "cornell-gi", &["--tile", "2/3"]);
    let out = d.join("out.exr");
    ok(merge(&[t0.clone(), t1.clone(), t2.clone()], &out, &[]));
    std::fs::remove_file(&out).unwrap();

    refused(&[t0.clone(), t2.clone()], &out, "tile 1/3 is missing");
    refused(&[t0.clone(), t1.clone(), t1.clone(), t2.clone()], &out, "overlap");
    let other_scene = t("scene.exr", "cornell-box", &["--tile", "1/3"]);
    refused(&[t0.clone(), other_scene.clone(), t2.clone()], &out, "scene.exr: rendered from another scene");
    let other_seed = t("seed.exr", "cornell-gi", &["--tile", "1/3", "--seed", "7"]);
    refused(&[t0.clone(), other_seed.clone(), t2.clone()], &out, "seed.exr: rendered with other settings");
    let other_tiling = t("quarter.exr", "cornell-gi", &["--tile", "1/4"]);
    refused(&[t0.clone(), other_tiling, t1.clone(), t2.clone()], &out, "overlap");

    // A part of another version: its record rewritten, its pixels kept.
    let mut f = pinhole::part_file::read(&t1).unwrap();
    f.record.version = "0.0.1".into();
    let old = d.join("old.exr");
    std::fs::write(&old, pinhole::part_file::encode(&f.record, &f.pixels).unwrap()).unwrap();
    refused(&[t0.clone(), old, t2.clone()], &out, "old.exr: made by pinhole 0.0.1");

    // Sample ranges with a gap, and with an overlap.
    let r0 = t("r0.exr", "cornell-gi", &["--sample-range", "0..2"]);
    let r3 = t("r3.exr", "cornell-gi", &["--sample-range", "3..4"]);
    let r1 = t("r1.exr", "cornell-gi", &["--sample-range", "1..4"]);
    refused(&[r0.clone(), r3.clone()], &out, "samples 2..3");
    refused(&[r0.clone(), r1.clone()], &out, "r1.exr: its samples 1..4 overlap");
    refused(&[r0.clone()], &out, "samples 2..4");

    // Never over an input.
    let before = std::fs::read(&t0).unwrap();
    let o = merge(&[t0.clone(), t1.clone(), t2.clone()], &t0, &[]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("read as input"), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&t0).unwrap(), before);

    // A plain image is not a part.
    let plain = d.join("plain.exr");
    render("cornell-gi", base, &[], &plain);
    refused(&[t0, plain], &out, "plain.exr: not a pinhole part");
    let _ = std::fs::remove_dir_all(&d);
}

fn one_sentence_error(args: &[&str], needle: &str) {
    let o = pinhole(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} should fail");
    assert!(!err.contains("panicked") && !err.contains("internal error"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
}

#[test]
fn bad_parts_are_refused_in_one_sentence() {
    let d = dir("bad");
    let out = d.join("o.exr");
    let o = out.to_str().unwrap();
    let r = |extra: &[&str], needle: &str| {
        let mut a = vec!["render", "cornell-box", "-o", o, "--width", "64", "--height", "48"];
        a.extend_from_slice(extra);
        one_sentence_error(&a, needle);
        assert!(!out.exists());
    };
    r(&["--crop", "0,0,65,10"], "outside the 64x48 frame");
    r(&["--crop", "5,5,5,10"], "no area");
    r(&["--tile", "4/4"], "below 4");
    r(&["--tile", "0/0"], "at least 1");
    r(&["--tile", "0/49"], "more than the frame's 48 rows");
    r(&["--sample-range", "0..2"], "1 samples per pixel");
    r(&["--sample-range", "0..2", "--spp", "4", "--adaptive", "0.1"], "--adaptive");
    one_sentence_error(&["render", "cornell-box", "-o", d.join("o.png").to_str().unwrap(), "--tile", "0/2"], "written as .exr");
    let _ = std::fs::remove_dir_all(&d);
}

/// `merge --status DIR` while a tiled render is under way: the parts there,
/// the missing tile, an estimate of the time left, and files that are not
/// parts of the frame named; then, with every tile, that it is complete.
#[test]
fn status_names_the_missing_tiles_and_the_time_left() {
    let d = dir("status");
    let status = || {
        let out = ok(pinhole(&["merge", "--status", d.to_str().unwrap()]));
        String::from_utf8(out.stdout).unwrap()
    };
    assert!(status().contains("no parts yet"), "{}", status());
    let tile = |i: u32| render("cornell-gi", &["--gi", "path", "--spp", "2"], &["--tile", &format!("{i}/3")], &d.join(format!("t{i}.exr")));
    tile(0);
    tile(2);
    render("spheres", &[], &["--tile", "0/2"], &d.join("other.exr"));
    std::fs::write(d.join("junk.exr"), b"not an image").unwrap();
    let s = status();
    assert!(s.contains("2 parts hold 66.7% of the frame's samples"), "{s}");
    assert!(s.contains("missing tiles: 1/3"), "{s}");
    assert!(s.contains("s of rendering left"), "{s}");
    assert!(s.contains("other.exr: not counted: a part of another frame"), "{s}");
    assert!(s.contains("junk.exr: not counted"), "{s}");
    tile(1);
    let s = status();
    assert!(s.contains("3 parts hold 100.0%") && s.contains("every tile of 3 is there") && s.contains("complete"), "{s}");
    assert!(!s.contains("left"), "{s}");
    // It writes nothing: the folder holds what it held.
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 5);
}
