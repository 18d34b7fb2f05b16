//! PLY meshes: ASCII, binary little-endian and binary big-endian copies of
//! one mesh render the very image its OBJ does, bit for bit, in both
//! renderer families, opened bare and placed by a scene file; bad files are
//! refused in one sentence naming the file and the place, never a panic.
//!
//! The files are written by this test from one list of vertices and faces
//! (with quads and a pentagon, so that fans are split as OBJ splits them).

mod common;

use pinhole::render::{PreparedScene, RenderSettings};
use pinhole::scene::Scene;
use std::path::{Path, PathBuf};

/// A little house: a box with a pitched roof, smooth-shaded (no normals in
/// the files), with uvs; faces of three, four and five corners.
fn house() -> (Vec<[f32; 5]>, Vec<Vec<u32>>) {
    let v = vec![
        [-1.0, 0.0, -1.0, 0.0, 0.0],
        [1.0, 0.0, -1.0, 1.0, 0.0],
        [1.0, 1.0, -1.0, 1.0, 0.5],
        [-1.0, 1.0, -1.0, 0.0, 0.5],
        [-1.0, 0.0, 1.0, 0.0, 0.0],
        [1.0, 0.0, 1.0, 1.0, 0.0],
        [1.0, 1.0, 1.0, 1.0, 0.5],
        [-1.0, 1.0, 1.0, 0.0, 0.5],
        [0.0, 1.8, 1.0, 0.5, 1.0],
        [0.0, 1.8, -1.0, 0.5, 1.0],
    ];
    let f = vec![
        vec![4, 5, 6, 8, 7],  // front wall and gable: a pentagon
        vec![1, 0, 3, 9, 2],  // back wall and gable
        vec![0, 4, 7, 3],     // left wall
        vec![5, 1, 2, 6],     // right wall
        vec![0, 1, 5, 4],     // floor
        vec![7, 8, 9, 3],     // left roof
        vec![6, 2, 9, 8],     // right roof
    ];
    (v, f)
}

fn obj_text() -> String {
    let (v, f) = house();
    let mut s = String::new();
    for p in &v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for p in &v {
        s += &format!("vt {} {}\n", p[3], p[4]);
    }
    for face in &f {
        s += "f";
        for i in face {
            s += &format!(" {}/{}", i + 1, i + 1);
        }
        s += "\n";
    }
    s
}

fn ply_header(format: &str) -> String {
    let (v, f) = house();
    format!(
        "ply\nformat {format} 1.0\ncomment written by the pinhole tests\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float s\nproperty float t\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        v.len(),
        f.len()
    )
}

fn ply_ascii() -> Vec<u8> {
    let (v, f) = house();
    let mut s = ply_header("ascii");
    for p in &v {
        s += &format!("{} {} {} {} {} 200 100 50\n", p[0], p[1], p[2], p[3], p[4]);
    }
    for face in &f {
        s += &face.len().to_string();
        for i in face {
            s += &format!(" {i}");
        }
        s += "\n";
    }
    s.into_bytes()
}

fn ply_binary(big: bool) -> Vec<u8> {
    let (v, f) = house();
    let mut out = ply_header(if big { "binary_big_endian" } else { "binary_little_endian" }).into_bytes();
    let f32b = |x: f32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    let i32b = |x: i32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    for p in &v {
        for x in p {
            out.extend(f32b(*x));
        }
        out.extend([200, 100, 50]);
    }
    for face in &f {
        out.push(face.len() as u8);
        for &i in face {
            out.extend(i32b(i as i32));
        }
    }
    out
}

fn replace_bytes(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let at = bytes.windows(from.len()).position(|w| w == from).unwrap();
    [&bytes[..at], to, &bytes[at + from.len()..]].concat()
}

fn work_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-ply-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn load(path: &Path) -> Result<Scene, String> {
    pinhole::scene::load::load_scene(path.to_str().unwrap())
}

fn render(scene: &Scene, renderer: &str) -> Vec<[u32; 3]> {
    let mut settings = RenderSettings::for_scene(scene);
    settings.width = 64;
    settings.height = 48;
    let prepared = PreparedScene::new(scene.clone());
    common::render(renderer, &prepared, &settings).iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn ascii_and_binary_ply_render_their_obj_bit_for_bit() {
    let dir = work_dir("same");
    std::fs::write(dir.join("house.obj"), obj_text()).unwrap();
    std::fs::write(dir.join("ascii.ply"), ply_ascii()).unwrap();
    std::fs::write(dir.join("le.ply"), ply_binary(false)).unwrap();
    std::fs::write(dir.join("be.ply"), ply_binary(true)).unwrap();
    let obj = load(&dir.join("house.obj")).unwrap();
    assert_eq!(obj.triangle_count(), 16, "the OBJ splits 2 pentagons and 5 quads into 16 triangles");
    for renderer in ["raytrace", "rasterize"] {
        let want = render(&obj, renderer);
        assert!(want.iter().filter(|p| p[0] != want[0][0]).count() > 500, "the house covers part of the image");
        for file in ["ascii.ply", "le.ply", "be.ply"] {
            let ply = load(&dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert_eq!(ply.triangle_count(), obj.triangle_count(), "{file}");
            assert!(ply.warnings.iter().any(|w| w.contains("vertex colours")), "{file}: {:?}", ply.warnings);
            assert!(render(&ply, renderer) == want, "{file}: {renderer} image differs from the OBJ's");
        }
    }
    // Placed by a scene file as `type = "mesh"`, with a placement.
    let scene_of = |file: &str| {
        format!("[camera]\neye = [2, 3, 6]\ntarget = [0, 0.8, 0]\n[[light]]\ntype = \"point\"\nposition = [3, 5, 4]\npower = [400, 400, 400]\n[[object]]\ntype = \"mesh\"\nfile = \"{file}\"\nrotate_deg = [0, 30, 0]\nscale = [1, 0.5, 2]\n")
    };
    for renderer in ["raytrace", "rasterize"] {
        std::fs::write(dir.join("obj.toml"), scene_of("house.obj")).unwrap();
        let want = render(&load(&dir.join("obj.toml")).unwrap(), renderer);
        for file in ["ascii.ply", "le.ply", "be.ply"] {
            std::fs::write(dir.join("ply.toml"), scene_of(file)).unwrap();
            assert!(render(&load(&dir.join("ply.toml")).unwrap(), renderer) == want, "{file} placed: {renderer} image differs");
        }
    }
}

/// Bad files: each refused with one line naming the file and the place.
#[test]
fn bad_ply_files_are_refused_with_the_file_and_place() {
    let dir = work_dir("bad");
    let ascii = String::from_utf8(ply_ascii()).unwrap();
    let le = ply_binary(false);
    let mut bad_index = le.clone();
    let last = bad_index.len() - 4;
    bad_index[last..].copy_from_slice(&1000i32.to_le_bytes());
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        ("lying-count.ply", ascii.replace("element vertex 10", "element vertex 4000000000").into_bytes(), &["4000000000", "vertex", "byte"]),
        ("lying-binary.ply", replace_bytes(&le, b"element face 7", b"element face 70000"), &["face", "byte"]),
        ("truncated.ply", le[..le.len() - 7].to_vec(), &["face 6", "byte"]),
        ("truncated-ascii.ply", ascii[..ascii.len() - 5].as_bytes().to_vec(), &["face 6", "byte"]),
        ("index.ply", bad_index, &["face 6", "vertex index 1000", "10 vertices"]),
        ("garbage.ply", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec(), &["not a PLY file"]),
        ("no-end.ply", b"ply\nformat ascii 1.0\nelement vertex 1\n".to_vec(), &["end_header"]),
        ("bad-number.ply", ascii.replacen("-1 0 -1", "-1 zero -1", 1).into_bytes(), &["vertex 0", "\"zero\""]),
        ("bad-type.ply", ascii.replace("property float z", "property quad z").into_bytes(), &["header line", "\"quad\""]),
    ];
    for (name, bytes, words) in cases {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).unwrap();
        let e = match std::panic::catch_unwind(|| load(&path)) {
            Ok(Err(e)) => e,
            Ok(Ok(_)) => panic!("{name}: loaded"),
            Err(_) => panic!("{name}: panicked"),
        };
        assert_eq!(e.lines().count(), 1, "{name}: {e}");
        assert!(e.contains(name), "{name}: the message does not name the file: {e}");
        for w in words {
            assert!(e.contains(w), "{name}: {e:?} does not contain {w:?}");
        }
    }
}
