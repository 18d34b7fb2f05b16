//! `forest` at 1280x720 in both families, as the `pinhole` binary renders it:
//! each run's peak resident memory stays under 1 GB, and the two images agree
//! (at most 0.5% of the pixels differ by more than 1e-4 relative). One test in
//! its own file, so no other test's process runs beside it; 9 s on two idle
//! cores (43 s while other builds shared them), nearly all of it the
//! rasterizer's setup of ~200 M triangles.

use std::process::Command;

const LIMIT_BYTES: f64 = 1e9;

/// Renders `forest` at its own 1280x720 with `renderer` into `out`; the stats JSON.
fn render(renderer: &str, out: &std::path::Path) -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .args(["render", "forest", "--renderer", renderer, "--stats", "-", "-o"])
        .arg(out)
        .output()
        .expect("run pinhole");
    assert!(o.status.success(), "{renderer}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("stats JSON")
}

#[test]
fn forest_at_1280x720_fits_in_1_gb_in_both_families_and_they_agree() {
    let dir = std::env::temp_dir().join(format!("pinhole-forest-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut images = Vec::new();
    for renderer in ["raytrace", "rasterize"] {
        let out = dir.join(format!("{}.exr", renderer));
        let j = render(renderer, &out);
        assert_eq!((j["width"].as_u64(), j["height"].as_u64()), (Some(1280), Some(720)), "{j}");
        assert_eq!(j["instances"].as_u64(), Some(10_000), "{j}");
        match j["peak_rss_bytes"].as_f64() {
            Some(peak) => {
                println!("forest 1280x720 {renderer}: peak RSS {:.0} MB, {} ms", peak / 1e6, j["render_ms"]);
                assert!(peak < LIMIT_BYTES, "{renderer}: peak RSS {peak} bytes");
                // A real measurement: at least the BVHs and meshes (15 MB).
                assert!(peak > 15e6, "{renderer}: peak RSS {peak} bytes");
            }
            None => assert!(!cfg!(target_os = "linux"), "no peak_rss_bytes on Linux: {j}"),
        }
        images.push(pinhole::image_io::load_image(&out).expect("read the image").pixels);
    }
    let (ray, raster) = (&images[0], &images[1]);
    let differing = ray
        .iter()
        .zip(raster)
        .filter(|(a, b)| {
            let (d, m) = ((**a - **b).abs(), a.abs().max(b.abs()));
            !(d.x <= 1e-4 * m.x + 1e-7 && d.y <= 1e-4 * m.y + 1e-7 && d.z <= 1e-4 * m.z + 1e-7)
        })
        .count();
    println!("forest 1280x720: {differing} of {} pixels differ between raytrace and rasterize", ray.len());
    assert!(differing as f64 <= 0.005 * ray.len() as f64, "{differing} of {} pixels differ", ray.len());
    let _ = std::fs::remove_dir_all(&dir);
}
