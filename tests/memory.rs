//! The geometry's memory: each triangle's edges are stored once (in the
//! BVH's primitive slots) and read back in scene order unchanged, and
//! `bench` reports the bytes per triangle.

use pinhole::render::accel::intersect::TriangleEdges;
use pinhole::render::PreparedScene;
use std::process::Command;

fn same(a: &TriangleEdges, b: &TriangleEdges) -> bool {
    a.v0 == b.v0 && a.e1 == b.e1 && a.e2 == b.e2 && a.det_epsilon().to_bits() == b.det_epsilon().to_bits() && a.two_sided() == b.two_sided()
}

#[test]
fn edges_in_scene_order_are_the_triangles_own() {
    for name in ["bunny", "spheres", "teapot", "one-triangle", "cornell-gi"] {
        let scene = pinhole::scene::builtin::load_builtin(name).unwrap().unwrap();
        let prepared = PreparedScene::new(scene);
        let triangles = &prepared.scene.triangles;
        assert_eq!(prepared.edges.len(), triangles.len(), "{name}");
        assert_eq!(prepared.edges.iter().len(), triangles.len(), "{name}");
        for (i, (t, e)) in triangles.iter().zip(prepared.edges.iter()).enumerate() {
            let fresh = TriangleEdges::new(&t);
            assert!(same(e, &fresh) && same(&prepared.edges[i], &fresh), "{name}: triangle {i}");
        }
    }
}

#[test]
fn the_bunny_takes_under_120_bytes_per_triangle() {
    let scene = pinhole::scene::builtin::load_builtin("bunny").unwrap().unwrap();
    let prepared = PreparedScene::new(scene);
    let memory = prepared.memory();
    let per_triangle = memory.total() as f64 / prepared.scene.triangles.len() as f64;
    // About 36 for the triangle (20 for its record, its share of the corners
    // it shares with five others), 44 for its BVH slot (edges and id), 4 for
    // the view in scene order, the rest nodes. Corners of its own (96 more)
    // or a second copy of the edges (40 more) would break this.
    assert!(per_triangle < 120.0, "{per_triangle} bytes per triangle: {memory:?}");
    assert!(memory.scene_bytes < 40 * prepared.scene.triangles.len(), "{memory:?}");
    assert_eq!(memory.prepared_bytes, 4 * prepared.scene.triangles.len());
}

#[test]
fn bench_reports_bytes_per_triangle() {
    let out = Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .args(["bench", "teapot", "--frames", "1", "--width", "32", "--height", "20", "--threads", "1"])
        .output()
        .expect("run pinhole");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let n = j["triangles"].as_f64().unwrap();
    let sum = ["scene_bytes", "bvh_bytes", "prepared_bytes"].map(|k| j[k].as_f64().unwrap_or_else(|| panic!("{k} missing: {j}")));
    assert!(n > 0.0 && sum.iter().all(|&b| b > 0.0), "{j}");
    let per = j["bytes_per_triangle"].as_f64().unwrap();
    assert!((per * n - sum.iter().sum::<f64>()).abs() < 1.0, "{j}");
    assert!(j["load_ms"].as_f64().is_some() && j["build_ms"].as_f64().is_some(), "{j}");
    if cfg!(target_os = "linux") {
        assert!(j["peak_rss_bytes"].as_f64().unwrap() >= sum.iter().sum::<f64>(), "{j}");
    }
}
