//! `--aov`: the output EXR holds the image and, beside it, named layers of
//! raw values. Read back here with the `exr` crate (not the code that
//! wrote it): every layer asked for is present, the image channels are the
//! plain EXR's, and at sampled pixels the layers hold exactly what
//! `pinhole pixel --json` reports for the first sample's eye-ray hit.

mod common;

use std::collections::HashMap;
use std::path::PathBuf;
use std::process::{Command, Output};

fn pinhole(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).output().expect("run pinhole")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-aov-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

const SIZE: [&str; 4] = ["--width", "48", "--height", "32"];

/// Every channel of the EXR by name, each row-major.
fn channels(path: &PathBuf) -> (usize, HashMap<String, Vec<f32>>) {
    let image = exr::prelude::read_all_flat_layers_from_file(path).expect("a readable EXR");
    assert_eq!(image.layer_data.len(), 1, "one part");
    let layer = &image.layer_data[0];
    let width = layer.size.width();
    let mut out = HashMap::new();
    for c in &layer.channel_data.list {
        let values: Vec<f32> = match &c.sample_data {
            exr::prelude::FlatSamples::F32(v) => v.clone(),
            other => panic!("{}: not f32 samples: {other:?}", c.name),
        };
        out.insert(c.name.to_string(), values);
    }
    (width, out)
}

#[test]
fn aov_layers_hold_what_pixel_replays_report() {
    let (plain, layered) = (tmp("plain.exr"), tmp("layered.exr"));
    for scene in ["teapot", "test-pattern"] {
        let o = pinhole(&[&["render", scene, "-o", plain.to_str().unwrap()][..], &SIZE].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let o = pinhole(&[&["render", scene, "-o", layered.to_str().unwrap(), "--aov", "depth,normal,albedo,position,uv,id,material"][..], &SIZE].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(o.stderr.is_empty() || !String::from_utf8_lossy(&o.stderr).contains("--aov"), "no notice for the ray caster");
        let (width, ch) = channels(&layered);
        let mut names: Vec<&str> = ch.keys().map(String::as_str).collect();
        names.sort();
        assert_eq!(
            names,
            ["B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "id.Y", "material.Y", "normal.X", "normal.Y", "normal.Z", "position.X", "position.Y", "position.Z", "uv.U", "uv.V"]
        );
        // The image channels are the plain render's, unchanged.
        let (_, plain_ch) = channels(&plain);
        for c in ["R", "G", "B"] {
            assert_eq!(ch[c].iter().map(|v| v.to_bits()).collect::<Vec<_>>(), plain_ch[c].iter().map(|v| v.to_bits()).collect::<Vec<_>>(), "{scene} {c}");
        }
        let mut hits = 0;
        for (x, y) in common::pixels(7, 10, 48, 32) {
            let i = y as usize * width + x as usize;
            let o = pinhole(&[&["pixel", scene, &x.to_string(), &y.to_string(), "--json"][..], &SIZE].concat());
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            let closest = &j["samples"][0]["rays"][0]["closest"];
            let f = |v: &serde_json::Value| v.as_f64().unwrap() as f32;
            if closest.is_null() {
                assert_eq!((ch["depth.Z"][i], ch["id.Y"][i], ch["normal.X"][i]), (0.0, -1.0, 0.0), "{scene} ({x}, {y}): a miss");
                continue;
            }
            hits += 1;
            let at = format!("{scene} ({x}, {y})");
            // Raw values: the same f32 the replay printed, not colours.
            assert_eq!(ch["depth.Z"][i], f(&closest["t"]), "{at} depth");
            for (k, c) in ["X", "Y", "Z"].iter().enumerate() {
                assert_eq!(ch[&format!("normal.{c}")][i], f(&closest["shading_normal"][k]), "{at} normal.{c}");
                assert_eq!(ch[&format!("position.{c}")][i], f(&closest["position"][k]), "{at} position.{c}");
            }
            assert_eq!(ch["uv.U"][i], f(&closest["uv"][0]), "{at} u");
            assert_eq!(ch["uv.V"][i], f(&closest["uv"][1]), "{at} v");
            assert_eq!(ch["id.Y"][i], f(&closest["object"]), "{at} id");
            let n = (0..3).map(|k| ch[["normal.X", "normal.Y", "normal.Z"][k]][i].powi(2)).sum::<f32>();
            assert!((n - 1.0).abs() < 1e-4, "{at}: a unit normal, not (n + 1) / 2");
            assert!(ch["material.Y"][i] >= 0.0);
            for c in ["albedo.R", "albedo.G", "albedo.B"] {
                assert!((0.0..=1.0).contains(&ch[c][i]), "{at} {c}");
            }
        }
        assert!(hits >= 3, "{scene}: the sampled pixels see surfaces ({hits})");
    }
}

#[test]
fn bad_aov_requests_are_one_sentence_and_rasterizers_get_a_notice() {
    let (png, exr) = (tmp("bad.png"), tmp("bad.exr"));
    for (args, needle) in [
        (vec!["-o", exr.to_str().unwrap(), "--aov", "depth,velocity"], "velocity"),
        (vec!["-o", exr.to_str().unwrap(), "--aov", "depth,depth"], "twice"),
        (vec!["-o", png.to_str().unwrap(), "--aov", "depth"], "EXR"),
        (vec!["-o", exr.to_str().unwrap(), "--aov", "depth", "--tile", "0/2"], "--tile"),
    ] {
        let o = pinhole(&[&["render", "spheres"][..], &args, &SIZE].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        assert!(err.contains(needle), "{err:?} should name {needle}");
        assert!(!png.exists() && !exr.exists(), "nothing written");
    }
    let o = pinhole(&[&["render", "spheres", "-o", exr.to_str().unwrap(), "--aov", "depth", "--renderer", "rasterize"][..], &SIZE].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("note: --aov layers are cast through the BVH") && err.contains("rasterize"), "{err}");
    assert!(channels(&exr).1.contains_key("depth.Z"));
}
