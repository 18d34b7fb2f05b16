//! Helpers shared by the integration tests.
#![allow(dead_code)]

use pinhole::math::Radiance;
use pinhole::render::{self, PreparedScene, RenderSettings};
use pinhole::scene::Scene;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// `../shared` next to the repository: references, models, bench scenes.
pub fn shared_dir() -> PathBuf {
    let dir = std::env::var_os("PINHOLE_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared"));
    assert!(dir.join("references").is_dir(), "the shared data is missing at {} (set PINHOLE_SHARED)", dir.display());
    dir
}

pub fn render(renderer: &str, prepared: &PreparedScene, settings: &RenderSettings) -> Vec<Radiance> {
    let r = render::renderer_by_name(renderer).unwrap();
    render::render_frame(r.as_ref(), prepared, settings, &AtomicBool::new(false), None).unwrap().pixels
}

pub fn builtin(name: &str) -> Scene {
    pinhole::scene::builtin::load_builtin(name).unwrap().unwrap()
}

/// Renders with a pool of exactly `threads` threads.
pub fn render_with_threads(threads: usize, renderer: &str, prepared: &PreparedScene, settings: &RenderSettings) -> Vec<Radiance> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| render(renderer, prepared, settings))
}

/// `n` pixels of a `w` x `h` image, chosen by a small deterministic
/// generator (xorshift) so failures repeat.
pub fn pixels(seed: u64, n: usize, w: u32, h: u32) -> Vec<(u32, u32)> {
    let mut s = seed | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s % w as u64) as u32, ((s >> 32) % h as u64) as u32)
        })
        .collect()
}

/// A scene from TOML text, with paths relative to the repository.
pub fn scene_from(text: &str) -> Scene {
    pinhole::scene::file::parse_scene(text, "test.toml", std::path::Path::new(env!("CARGO_MANIFEST_DIR")), "test").unwrap()
}

/// The form factor from a point to a rectangle `x` by `y` in a plane
/// parallel to the point's at distance `h`, with one corner straight above
/// the point (Howell's catalogue, configuration B-3; Cohen and Wallace).
pub fn corner_form_factor(x: f64, y: f64, h: f64) -> f64 {
    let (a, b) = (x / h, y / h);
    let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    (a / ra * (b / ra).atan() + b / rb * (a / rb).atan()) / (2.0 * std::f64::consts::PI)
}

/// A floor of albedo 0.5 under a light, seen straight from above at
/// (`x`, `z`) through a narrow camera that sits below the light.
pub fn floor_under(light: &str, x: f32, z: f32) -> Scene {
    scene_from(&format!(
        r#"
[camera]
eye = [{x}, 0.4, {ez}]
target = [{x}, 0.0, {z}]
fov_y_deg = 0.5
[render]
width = 4
height = 4
ambient = [0.0, 0.0, 0.0]
background = [0.0, 0.0, 0.0]
[materials.lamp]
lambertian = [0.0, 0.0, 0.0]
emission = [2.0, 2.0, 2.0]
[materials.floor]
lambertian = [0.5, 0.5, 0.5]
{light}
[[object]]
type = "quad"
vertices = [[-8.0, 0.0, 8.0], [8.0, 0.0, 8.0], [8.0, 0.0, -8.0], [-8.0, 0.0, -8.0]]
material = "floor"
"#,
        ez = z + 0.1
    ))
}

/// Standard base64 with padding, for data URIs in hand-written glTF files.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            s.push(if k <= c.len() { A[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    s
}
