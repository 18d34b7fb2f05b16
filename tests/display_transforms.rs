//! The display transform stays out of the data: `--tonemap`, `--exposure`
//! (stops) and `--gamma` change a PNG, never the EXR of the same render, and
//! the PNG's pixels are the EXR's through the published curves (computed
//! here independently of the code under test).

use std::path::PathBuf;
use std::process::{Command, Output};

fn pinhole(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().expect("run pinhole")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-display-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn render(out: &PathBuf, extra: &[&str]) {
    let mut args = vec!["render", "spheres", "-o", out.to_str().unwrap(), "--width", "48", "--height", "32"];
    args.extend_from_slice(extra);
    let o = pinhole(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

fn quantize(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[test]
fn tone_maps_change_the_png_and_never_the_exr() {
    let (exr_a, exr_b) = (tmp("std.exr"), tmp("aces.exr"));
    render(&exr_a, &[]);
    render(&exr_b, &["--tonemap", "aces", "--exposure", "2", "--gamma", "2.2"]);
    assert_eq!(std::fs::read(&exr_a).unwrap(), std::fs::read(&exr_b).unwrap(), "the EXR does not change with the display transform");

    let linear = image::open(&exr_a).unwrap().into_rgb32f();
    let (png_std, png_rh, png_ev, png_aces) = (tmp("std.png"), tmp("rh.png"), tmp("ev.png"), tmp("aces.png"));
    render(&png_std, &[]);
    render(&png_rh, &["--tonemap", "reinhard"]);
    render(&png_ev, &["--exposure", "1", "--gamma", "off"]);
    render(&png_aces, &["--tonemap", "aces"]);
    let read = |p: &PathBuf| image::open(p).unwrap().into_rgb8();
    let (std, rh, ev, aces) = (read(&png_std), read(&png_rh), read(&png_ev), read(&png_aces));
    assert_ne!(std.as_raw(), aces.as_raw(), "aces changes the PNG");
    assert_ne!(std.as_raw(), rh.as_raw(), "reinhard changes the PNG");
    let mut lit = 0;
    for (x, y, p) in linear.enumerate_pixels() {
        for ch in 0..3 {
            let v = p[ch].max(0.0);
            lit += (v > 0.05) as usize;
            // Standard: clip then sRGB; Reinhard: v / (1 + v) then sRGB;
            // one stop up without a curve: min(2v, 1) linear.
            assert_eq!(std.get_pixel(x, y)[ch], quantize(srgb(v.min(1.0))), "standard at ({x}, {y})");
            assert_eq!(rh.get_pixel(x, y)[ch], quantize(srgb(v / (1.0 + v))), "reinhard at ({x}, {y})");
            assert_eq!(ev.get_pixel(x, y)[ch], quantize((2.0 * v).min(1.0)), "exposure +1 at ({x}, {y})");
        }
    }
    assert!(lit > 100, "the scene has lit pixels to compare: {lit}");
}

#[test]
fn statistics_name_the_tone_map() {
    let (png, stats) = (tmp("s.png"), tmp("s.json"));
    render(&png, &["--tonemap", "khronos-neutral", "--stats", stats.to_str().unwrap()]);
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(j["tonemap"], "khronos-neutral");
    assert_eq!(j["gamma"], "srgb");
    assert_eq!(j["exposure_ev"], 0.0);
}

#[test]
fn bad_display_options_are_one_sentence() {
    let p = tmp("bad.png");
    for (args, needle) in [
        (vec!["--exposure", "NaN"], "--exposure"),
        (vec!["--exposure", "inf"], "--exposure"),
        (vec!["--tonemap", "filmic"], "--tonemap"),
        (vec!["--gamma", "1.8"], "--gamma"),
    ] {
        let mut a = vec!["render", "one-triangle", "-o", p.to_str().unwrap()];
        a.extend_from_slice(&args);
        let out = pinhole(&a);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        assert!(err.contains(needle), "{err:?} should name {needle}");
    }
    assert!(!p.exists(), "no image is written");
}

#[test]
fn false_colour_shows_each_pixels_stop_through_viridis() {
    // The shaded EXR's luminance, log2, placed on the 16-stop scale from
    // 2^-10 to 2^6 and looked up in viridis's nine published points: the
    // false-colour PNG shows that colour (within one 8-bit step, the frame
    // holds it as linear values the sRGB curve encodes back).
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
    let (exr, png) = (tmp("fc.exr"), tmp("fc.png"));
    render(&exr, &[]);
    render(&png, &["--view", "false-colour"]);
    let linear = image::open(&exr).unwrap().into_rgb32f();
    let shown = image::open(&png).unwrap().into_rgb8();
    let mut stops_seen = std::collections::BTreeSet::new();
    for (x, y, p) in linear.enumerate_pixels() {
        let l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        let stop = if l > 0.0 { l.log2().clamp(-10.0, 6.0) } else { -10.0 };
        stops_seen.insert(stop.round() as i32);
        let t = (stop + 10.0) / 16.0 * 8.0;
        let i = (t.floor() as usize).min(7);
        let f = t - i as f32;
        for k in 0..3 {
            let want = VIRIDIS[i][k] * (1.0 - f) + VIRIDIS[i + 1][k] * f;
            let got = shown.get_pixel(x, y)[k] as f32;
            assert!((got - want).abs() <= 1.5, "({x}, {y}) channel {k}: {got} vs {want} at stop {stop}");
        }
    }
    assert!(stops_seen.len() >= 3, "the scene spans several stops: {stops_seen:?}");
}
