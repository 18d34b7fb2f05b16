//! Switches that time an optimisation change no pixel: `--packets off`
//! traces `raytrace:bvh`'s frames one ray at a time, as a replay does,
//! and gives the image of the packets bit for bit, with eye rays, shadow
//! rays, mirror rays and path-traced bounces.

mod common;
use common::*;
use pinhole::render::transport::gi::GiMode;
use pinhole::render::{PreparedScene, RenderSettings};
use std::process::Command;

#[test]
fn ray_packets_change_no_pixel() {
    for (name, spp, path) in [("teapot", 1, false), ("textures", 2, false), ("cornell-gi", 4, true), ("bunny", 1, false)] {
        let scene = builtin(name);
        let mut s = RenderSettings::for_scene(&scene);
        (s.width, s.height, s.spp) = (96, 64, spp);
        if path {
            s.gi.mode = GiMode::Path;
        }
        let prepared = PreparedScene::new(scene);
        let packets = render("raytrace:bvh", &prepared, &s);
        let single = render("raytrace:bvh", &prepared, &RenderSettings { packets: false, ..s.clone() });
        let differ = packets.iter().zip(&single).filter(|(a, b)| a.to_array().map(f32::to_bits) != b.to_array().map(f32::to_bits)).count();
        assert_eq!(differ, 0, "{name}: {differ} pixels differ with --packets off");
    }
}

#[test]
fn the_command_line_takes_packets_on_and_off_only() {
    let out = std::env::temp_dir().join(format!("pinhole-packets-{}.png", std::process::id()));
    let run = |value: &str| Command::new(env!("CARGO_BIN_EXE_pinhole")).args(["render", "teapot", "--width", "16", "--height", "12", "--packets", value, "-o"]).arg(&out).output().unwrap();
    assert!(run("off").status.success());
    let bad = run("sometimes");
    assert!(!bad.status.success());
    let said = String::from_utf8_lossy(&bad.stderr);
    assert!(said.contains("--packets sometimes is neither on nor off"), "{said}");
    let _ = std::fs::remove_file(&out);
}
