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
