//! glTF 2.0 scenes: the Khronos Box is red and covers the pixels its cube
//! projects to, the Cameras sample offers its perspective camera and its
//! orthographic one, a glTF whose two nodes share
//! one mesh renders the depth and normal images of the same geometry baked
//! into OBJ files in both renderer families while storing the mesh once,
//! and bad files are refused in one sentence naming the file and the
//! accessor, node or buffer at fault.

mod common;

use glam::{Mat4, Quat, Vec3};
use pinhole::render::inspect::debug::View;
use pinhole::render::{PreparedScene, RenderSettings};
use pinhole::scene::load::{load_scene, load_scene_with_camera};
use pinhole::scene::Scene;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf").join(name)
}

fn work_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-gltf-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn render(scene: &Scene, renderer: &str, view: View, w: u32, h: u32) -> Vec<Vec3> {
    let mut settings = RenderSettings::for_scene(scene);
    settings.width = w;
    settings.height = h;
    settings.view = view;
    common::render(renderer, &PreparedScene::new(scene.clone()), &settings)
}

/// Area of the convex hull of `points` (monotone chain).
fn hull_area(mut p: Vec<(f32, f32)>) -> f32 {
    p.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let cross = |o: (f32, f32), a: (f32, f32), b: (f32, f32)| (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0);
    let mut hull: Vec<(f32, f32)> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let pts: Vec<_> = if pass == 0 { p.clone() } else { p.iter().rev().copied().collect() };
        for q in pts {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0 {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    (0..hull.len()).map(|i| cross((0.0, 0.0), hull[i], hull[(i + 1) % hull.len()])).sum::<f32>().abs() * 0.5
}

#[test]
fn khronos_box_is_red_and_covers_its_cube() {
    let scene = load_scene(data("Box.gltf").to_str().unwrap()).unwrap();
    assert_eq!(scene.triangle_count(), 12);
    assert!(scene.warnings.iter().any(|w| w.contains("no lights")), "{:?}", scene.warnings);
    let (w, h) = (160, 100);
    let view = scene.camera.view(w, h);
    let corners: Vec<(f32, f32)> = (0..8)
        .map(|k| {
            let c = Vec3::new(if k & 1 == 0 { -0.5 } else { 0.5 }, if k & 2 == 0 { -0.5 } else { 0.5 }, if k & 4 == 0 { -0.5 } else { 0.5 });
            let (p, _) = view.project(c).unwrap();
            (p.x, p.y)
        })
        .collect();
    let expected = hull_area(corners);
    assert!(expected > 1000.0, "the cube fills part of the frame ({expected} pixels)");
    for renderer in ["raytrace", "rasterize"] {
        let img = render(&scene, renderer, View::Shaded, w, h);
        let bg = img[0];
        let covered: Vec<&Vec3> = img.iter().filter(|p| **p != bg).collect();
        let n = covered.len() as f32;
        assert!((n - expected).abs() < 0.03 * expected, "{renderer}: {n} pixels covered, the cube projects to {expected}");
        let red = covered.iter().filter(|p| p.x > 0.0 && p.x > 3.0 * p.y && p.x > 3.0 * p.z).count() as f32;
        assert!(red > 0.97 * n, "{renderer}: only {red} of {n} covered pixels are red");
    }
}

#[test]
fn khronos_cameras_offers_its_perspective_and_orthographic_cameras() {
    let path = data("Cameras.gltf");
    let scene = load_scene(path.to_str().unwrap()).unwrap();
    let mut names: Vec<&str> = scene.named_cameras.iter().map(|(n, _)| n.as_str()).collect();
    names.sort();
    assert_eq!(names, ["camera 0", "camera 1"]);
    // xmag = ymag = 1: a view two units high.
    assert_eq!(scene.named_cameras.iter().find(|(n, _)| n == "camera 1").unwrap().1.projection, pinhole::scene::camera::Projection::Orthographic { height: 2.0 });
    // By default the perspective camera, though the orthographic one's node comes first.
    assert_eq!(scene.camera.projection, pinhole::scene::camera::Projection::Perspective);
    assert_eq!(scene.camera.eye, Vec3::new(0.5, 0.5, 3.0));
    assert!((scene.camera.target - Vec3::new(0.5, 0.5, 2.0)).length() < 1e-6);
    assert_eq!((scene.render.width, scene.render.height), (800, 800), "aspectRatio 1 makes a square image");
    assert!(!scene.warnings.iter().any(|w| w.contains("orthographic")), "{:?}", scene.warnings);
    assert!(load_scene_with_camera(path.to_str().unwrap(), Some("camera 0")).is_ok());
    let e = load_scene_with_camera(path.to_str().unwrap(), Some("overview")).err().unwrap();
    assert!(e.contains("\"overview\"") && e.contains("\"camera 0\"") && e.contains("Cameras.gltf"), "{e}");
}

/// A unit cube with its bottom at y = 0, CCW faces seen from outside
/// (indices from 0), and a floor square at y = 0.
const CUBE_V: [[f32; 3]; 8] =
    [[-0.5, 0.0, -0.5], [0.5, 0.0, -0.5], [0.5, 1.0, -0.5], [-0.5, 1.0, -0.5], [-0.5, 0.0, 0.5], [0.5, 0.0, 0.5], [0.5, 1.0, 0.5], [-0.5, 1.0, 0.5]];
const CUBE_F: [u16; 36] = [0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5, 3, 7, 6, 3, 6, 2, 0, 1, 5, 0, 5, 4];
const FLOOR_V: [[f32; 3]; 4] = [[-4.0, 0.0, 4.0], [4.0, 0.0, 4.0], [4.0, 0.0, -4.0], [-4.0, 0.0, -4.0]];
const FLOOR_F: [u16; 6] = [0, 1, 2, 0, 2, 3];

/// The two copies' node transforms (translation, rotation, scale) and their parent's.
fn copies() -> [(Vec3, Quat, Vec3); 2] {
    [
        (Vec3::new(-1.2, 0.0, 0.0), Quat::from_rotation_y(0.5) * Quat::from_rotation_x(0.2), Vec3::new(1.0, 1.5, 0.7)),
        (Vec3::new(1.3, 0.2, -0.5), Quat::from_rotation_z(-0.3), Vec3::new(0.8, 0.6, 1.2)),
    ]
}
const PARENT: [f32; 3] = [0.0, 0.1, 0.2];


/// The shared-mesh glTF's binary buffer: cube positions, floor positions,
/// cube indices, floor indices.
fn buffer() -> Vec<u8> {
    let mut b = Vec::new();
    CUBE_V.iter().chain(FLOOR_V.iter()).flatten().for_each(|x| b.extend(x.to_le_bytes()));
    CUBE_F.iter().chain(FLOOR_F.iter()).for_each(|i| b.extend(i.to_le_bytes()));
    b
}

/// The shared-mesh glTF's JSON with `uri` as its buffer's URI (`None`: the GLB chunk).
fn shared_json(uri: Option<&str>) -> String {
    let [a, b] = copies();
    let node = |(t, r, s): (Vec3, Quat, Vec3)| {
        format!("{{\"mesh\": 0, \"translation\": [{}, {}, {}], \"rotation\": [{}, {}, {}, {}], \"scale\": [{}, {}, {}]}}", t.x, t.y, t.z, r.x, r.y, r.z, r.w, s.x, s.y, s.z)
    };
    let uri = uri.map(|u| format!(", \"uri\": \"{u}\"")).unwrap_or_default();
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [3, 2]}}],
"nodes": [{}, {}, {{"mesh": 1}}, {{"children": [0, 1], "translation": [{}, {}, {}]}}],
"meshes": [{{"name": "cube", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 2}}]}}, {{"name": "floor", "primitives": [{{"attributes": {{"POSITION": 1}}, "indices": 3}}]}}],
"accessors": [
 {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5]}},
 {{"bufferView": 0, "byteOffset": 96, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-4, 0, -4], "max": [4, 0, 4]}},
 {{"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}},
 {{"bufferView": 1, "byteOffset": 72, "componentType": 5123, "count": 6, "type": "SCALAR"}}],
"bufferViews": [{{"buffer": 0, "byteLength": 144}}, {{"buffer": 0, "byteOffset": 144, "byteLength": 84}}],
"buffers": [{{"byteLength": 228{uri}}}]}}"#,
        node(a),
        node(b),
        PARENT[0],
        PARENT[1],
        PARENT[2]
    )
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while b.len() % 4 != 0 {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(b);
    out
}

/// The same geometry baked into OBJ text: each cube copy by its world matrix.
fn baked_obj() -> (String, String) {
    let parent = Mat4::from_translation(Vec3::from(PARENT));
    let mut cubes = String::new();
    for (k, (t, r, s)) in copies().into_iter().enumerate() {
        let m = parent * Mat4::from_scale_rotation_translation(s, r, t);
        for v in CUBE_V {
            let p = m.transform_point3(Vec3::from(v));
            cubes += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        for f in CUBE_F.chunks(3) {
            cubes += &format!("f {} {} {}\n", f[0] as usize + 1 + 8 * k, f[1] as usize + 1 + 8 * k, f[2] as usize + 1 + 8 * k);
        }
    }
    let mut floor = String::new();
    for v in FLOOR_V {
        floor += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    floor += "f 1 2 3\nf 1 3 4\n";
    (cubes, floor)
}

const HEAD: &str = "[camera]\neye = [0.5, 3.0, 6.0]\ntarget = [0.0, 0.6, 0.0]\nfov_y_deg = 45.0\nnear = 0.1\nfar = 50.0\n[render]\nwidth = 120\nheight = 80\n\
[[light]]\ntype = \"point\"\nposition = [2.0, 5.0, 3.0]\npower = [300.0, 300.0, 300.0]\n";

#[test]
fn shared_mesh_matches_baked_obj_and_is_stored_once() {
    let dir = work_dir("shared");
    let (cubes, floor) = baked_obj();
    std::fs::write(dir.join("cubes.obj"), cubes).unwrap();
    std::fs::write(dir.join("floor.obj"), floor).unwrap();
    std::fs::write(dir.join("shared.bin"), buffer()).unwrap();
    std::fs::write(dir.join("shared.gltf"), shared_json(Some("shared.bin"))).unwrap();
    std::fs::write(dir.join("embedded.gltf"), shared_json(Some(&format!("data:application/octet-stream;base64,{}", common::base64(&buffer()))))).unwrap();
    std::fs::write(dir.join("shared.glb"), glb(&shared_json(None), &buffer())).unwrap();
    std::fs::write(
        dir.join("obj.toml"),
        format!("{HEAD}[[object]]\ntype = \"mesh\"\nfile = \"cubes.obj\"\nnormals = \"flat\"\n[[object]]\ntype = \"mesh\"\nfile = \"floor.obj\"\nnormals = \"flat\"\n"),
    )
    .unwrap();
    let obj = load_scene(dir.join("obj.toml").to_str().unwrap()).unwrap();
    for file in ["shared.gltf", "embedded.gltf", "shared.glb"] {
        let toml = dir.join(format!("{file}.toml"));
        std::fs::write(&toml, format!("{HEAD}[[object]]\ntype = \"gltf\"\nfile = \"{file}\"\n")).unwrap();
        let g = load_scene(toml.to_str().unwrap()).unwrap_or_else(|e| panic!("{file}: {e}"));
        // The cube is stored once (12 triangles) for its two copies, the floor flattened.
        let layer = g.layer.as_ref().expect("the shared mesh is in the instance layer");
        assert_eq!((layer.meshes.len(), layer.instances.len(), layer.meshes[0].len()), (1, 2, 12), "{file}");
        assert_eq!(g.triangles.len(), 2, "{file}: only the floor is flattened");
        assert_eq!(g.total_triangles(), obj.total_triangles(), "{file}");
        for renderer in ["raytrace", "rasterize"] {
            for view in [View::Depth, View::Normal] {
                let (a, b) = (render(&obj, renderer, view, 120, 80), render(&g, renderer, view, 120, 80));
                let same = a.iter().zip(&b).filter(|(x, y)| (**x - **y).abs().max_element() <= 1e-3 * x.abs().max_element().max(1.0)).count();
                let share = same as f64 / a.len() as f64;
                assert!(share >= 0.995, "{file}: {renderer} {view:?}: only {:.2}% of pixels agree with the baked OBJ", 100.0 * share);
                assert!(a.iter().filter(|p| **p != a[0]).count() > 1000, "the view is not empty");
            }
        }
    }
}

#[test]
fn the_inspector_names_the_gltf_node_and_mesh_of_a_hit() {
    let dir = work_dir("parts");
    std::fs::write(dir.join("shared.bin"), buffer()).unwrap();
    std::fs::write(dir.join("shared.gltf"), shared_json(Some("shared.bin"))).unwrap();
    std::fs::write(dir.join("s.toml"), format!("{HEAD}[[object]]\ntype = \"gltf\"\nfile = \"shared.gltf\"\n")).unwrap();
    let scene = load_scene(dir.join("s.toml").to_str().unwrap()).unwrap();
    // The floor (node 2, flattened) and the cube's two copies (nodes 0 and 1, in the layer).
    let names: Vec<Option<&str>> = (0..scene.total_triangles() as u32).map(|i| scene.part_name(i)).collect();
    assert_eq!(&names[..2], &[Some("glTF node 2, mesh 1 \"floor\""); 2]);
    let mut copies: Vec<&str> = names[2..].iter().map(|n| n.expect("every copy's triangle is named")).collect();
    assert!(copies[..12].iter().all(|n| *n == copies[0]) && copies[12..].iter().all(|n| *n == copies[12]), "{copies:?}");
    copies.dedup();
    copies.sort();
    assert_eq!(copies, ["glTF node 0, mesh 0 \"cube\"", "glTF node 1, mesh 0 \"cube\""]);
    // A replayed pixel on the floor says so, in text and JSON, in both families.
    let settings = RenderSettings::for_scene(&scene);
    let prepared = PreparedScene::new(scene);
    let view = prepared.scene.camera.view(settings.width, settings.height);
    // A floor point in front of the cubes, inside the image.
    let p = [Vec3::new(2.5, 0.0, 2.0), Vec3::new(-2.5, 0.0, 2.0), Vec3::new(0.0, 0.0, 1.5)]
        .into_iter()
        .filter_map(|w| view.project(w).map(|(p, _)| p))
        .find(|p| p.x >= 0.0 && p.y >= 0.0 && p.x < settings.width as f32 && p.y < settings.height as f32)
        .expect("a floor point in view");
    let (x, y) = (p.x as u32, p.y as u32);
    for name in ["raytrace", "rasterize"] {
        let r = pinhole::render::renderer_by_name(name).unwrap();
        let replay = pinhole::render::replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap();
        let text = pinhole::render::inspect::pixel_report::to_text(name, &prepared.scene, x, y, &replay);
        assert!(text.contains("glTF node 2, mesh 1 \"floor\""), "{name}: {text}");
        let json = pinhole::render::inspect::pixel_report::to_json(name, &prepared.scene, x, y, &replay);
        assert_eq!(json["samples"][0]["rays"][0]["closest"]["part"], "glTF node 2, mesh 1 \"floor\"", "{name}: {json}");
    }
}

/// Each bad file is refused with one line naming the file and the place.
#[test]
fn bad_gltf_files_are_refused_with_the_file_and_place() {
    let dir = work_dir("bad");
    std::fs::write(dir.join("shared.bin"), buffer()).unwrap();
    let good = shared_json(Some("shared.bin"));
    let full_glb = glb(&shared_json(None), &buffer());
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        ("truncated.glb", full_glb[..full_glb.len() - 40].to_vec(), &["GLB"]),
        ("accessor.gltf", good.replace("\"count\": 36", "\"count\": 360").into_bytes(), &["accessor 2", "buffer view 1"]),
        ("index.gltf", good.replace("\"count\": 8,", "\"count\": 5,").into_bytes(), &["accessor 2", "beyond its 5 vertices"]),
        ("cycle.gltf", good.replace("{\"mesh\": 1}", "{\"mesh\": 1, \"children\": [3]}").replace("\"children\": [0, 1]", "\"children\": [0, 1, 2]").replace("\"nodes\": [3, 2]", "\"nodes\": [3]").into_bytes(), &["node 3", "cycle"]),
        ("outside.gltf", good.replace("shared.bin", "../shared.bin").into_bytes(), &["buffer 0", "outside"]),
        ("missing.gltf", good.replace("shared.bin", "nope.bin").into_bytes(), &["buffer 0", "nope.bin"]),
        ("draco.gltf", good.replacen("{\"asset\"", "{\"extensionsRequired\": [\"KHR_draco_mesh_compression\"], \"extensionsUsed\": [\"KHR_draco_mesh_compression\"], \"asset\"", 1).into_bytes(), &["KHR_draco_mesh_compression", "extensionsRequired"]),
        ("garbage.glb", b"glTF\x02\0\0\0\xff\xff\xff\xffJUNK".to_vec(), &["GLB"]),
        ("not-json.gltf", b"{\"asset\": [".to_vec(), &["JSON"]),
    ];
    for (name, bytes, words) in cases {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).unwrap();
        let e = match std::panic::catch_unwind(|| load_scene(path.to_str().unwrap())) {
            Ok(Err(e)) => e,
            Ok(Ok(_)) => panic!("{name}: loaded"),
            Err(_) => panic!("{name}: panicked"),
        };
        eprintln!("{name}: {e}");
        assert_eq!(e.lines().count(), 1, "{name}: {e}");
        assert!(e.contains(name), "{name}: the message does not name the file: {e}");
        for w in words {
            assert!(e.contains(w), "{name}: {e:?} does not contain {w:?}");
        }
    }
}
