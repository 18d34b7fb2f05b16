//! A seeded mutation fuzzer over everything pinhole reads: scene TOML (the
//! built-in scenes, mutated), OBJ/MTL pairs, PLY meshes (ASCII and binary),
//! glTF files (the vendored samples, textured among them, mutated) and image files (PNG, EXR).
//!
//! Each case must end without a panic, with either an error of at most
//! three lines and `MAX_ERROR_CHARS` characters, or a scene that renders
//! (tiny) to finite pixels. The run is a pure function of the seed:
//! `PINHOLE_FUZZ_CASES=10000` runs more cases, `PINHOLE_FUZZ_SEED=N` other
//! ones; a failure prints the input that caused it. Every input that once
//! failed is kept in `REGRESSIONS` and checked on every run.

use pinhole::scene::Scene;
use pinhole::math::Vec3;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Longest error message accepted.
const MAX_ERROR_CHARS: usize = 1000;
/// Cases per input kind when `PINHOLE_FUZZ_CASES` is not set.
const DEFAULT_CASES: usize = 300;

/// Inputs that once crashed, hung or gave a bad message: (kind, file text).
/// Kinds: "toml", "obj" (with "mtl" = the MTL beside it, "OBJ\0MTL"), "ply", "gltf", "image".
const REGRESSIONS: &[(&str, &str)] = &[
    // tobj panicked on MTL colours with fewer than three numbers.
    ("obj", "mtllib a.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\0newmtl a\nKd 0.5\nKa 1\nKs 0.5\nKe 1\n"),
    ("obj", "mtllib a.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\0newmtl a\nKd -1 -1 -1\nNs -100\n"),
    ("obj", "v 0 0 0\nv 1 0 0\nv 0 1 1e38\nf 1 2 3\n\0"),
    ("obj", "mtllib a.mtl\nusemtl ghost\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\0newmtl a\nKs 3e38 3e38 3e38\n"),
    // Values whose squares overflow f32, and huge finite values.
    ("toml", "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nup = [0, 1e20, 0]\n[[light]]\ntype = \"directional\"\ndirection = [0, -1e20, -1e20]\nirradiance = [1, 1, 1]\n[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n"),
    ("toml", "[[light]]\ntype = \"point\"\nposition = [0, 1, 3]\npower = [3e38, 3e38, 3e38]\n[[object]]\ntype = \"sphere\"\ncenter = [0, 0, -3]\nradius = 1\n"),
    ("toml", "[[object]]\ntype = \"triangle\"\nvertices = [[-1e10, -1e10, -2], [1e10, -1e10, -2], [0, 1e10, -2]]\n"),
    ("toml", "[camera]\nfov_y_deg = 1e-45\n"),
    ("toml", "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, -3]\nradius = 1\nscale = 1e38\n"),
    ("toml", "[camera]\neye = [0, 0, 3, 99]\n"),
    ("toml", "[[object]]\ntype = \"quad\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\nscale = \"x\"\n"),
    // PLY headers that lie about their counts, lists longer than the file,
    // indices beyond the vertices, a property-less element counted in billions.
    ("ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
    ("ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n4294967295 0 1 2\n"),
    ("ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
    ("ply", "ply\nformat binary_little_endian 1.0\nelement nothing 4000000000\nelement vertex 3\nproperty uchar x\nproperty uchar y\nproperty uchar z\nelement face 1\nproperty list uchar uchar vertex_indices\nend_header\n\0\0\0\x01\0\0\0\x01\0\x03\0\x01\x02"),
    ("ply", "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n\0\0"),
    // glTF: an accessor past its view, a node cycle, a buffer outside the folder, a cut GLB.
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3000000, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 1]}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}"),
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"children\": [1]}, {\"children\": [0]}]}"),
    // The gltf crate's validation indexed a POSITION accessor beyond the list.
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 2}}]}]}"),
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"byteLength\": 4, \"uri\": \"../../../etc/passwd\"}]}"),
    ("gltf", "glTF\x02\0\0\0\x40\0\0\0\x20\0\0\0JSON{\"asset\": {\"version\": \"2.0\"}}"),
    // Vertex colours: fewer than the positions, and a colour of 2.
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"COLOR_0\": 1}}]}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}, {\"bufferView\": 0, \"componentType\": 5126, \"count\": 2, \"type\": \"VEC3\"}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}"),
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"COLOR_0\": 1}}]}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}, {\"bufferView\": 1, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteLength\": 36}], \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,AAAAQAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}"),
    // Textures: every slot naming a missing texture, an image in a view past
    // its buffer read as metallic-roughness, normal and emissive data with a
    // mirrored, nearest sampler.
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 7}, \"metallicRoughnessTexture\": {\"index\": 8}}, \"normalTexture\": {\"index\": 9}, \"emissiveTexture\": {\"index\": 10}}]}"),
    ("gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}], \"materials\": [{\"emissiveFactor\": [1, 1, 1], \"pbrMetallicRoughness\": {\"metallicRoughnessTexture\": {\"index\": 0}}, \"normalTexture\": {\"index\": 0, \"scale\": 2}, \"emissiveTexture\": {\"index\": 0}}], \"textures\": [{\"source\": 0, \"sampler\": 0}], \"samplers\": [{\"magFilter\": 9728, \"wrapS\": 33648, \"wrapT\": 33071}], \"images\": [{\"bufferView\": 1, \"mimeType\": \"image/png\"}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": 30, \"byteLength\": 4000}], \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}"),
];

/// splitmix64: small, seeded, and the same everywhere.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Tokens that have broken parsers before: boundaries of f32, non-finite
/// values, empty and unbalanced syntax, huge counts.
const TOKENS: &[&str] = &[
    "nan", "inf", "-inf", "-1", "0", "-0", "1e20", "1e38", "3e38", "1e39", "1e-45", "-1e10", "4294967295", "99999999999",
    "[", "]", "[]", "[0, 0, 0, 0]", "[1, 2]", "\"\"", "\"x\"", "=", "\n", "#", "{}", "[[object]]", "[[light]]", "[materials.m]",
    "type = \"sphere\"", "type = \"mesh\"", "file = \"/dev/zero\"", "texture = \"nope.png\"", "usemtl", "mtllib a.mtl", "f 1 2 3",
    "f 1 1 1", "f -1 -2 -3", "v 1e38 0 0", "vt", "vn 0 0 0", "Kd", "Ns", "map_Kd a.png", "newmtl", "1/2/3", "//", "o x",
];

/// One mutation of `input`: a token inserted, a number replaced, a byte
/// flipped, a line deleted or duplicated, or a range cut out.
fn mutate(rng: &mut Rng, input: &[u8]) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(2) {
        let at = rng.below(out.len() + 1);
        match rng.below(7) {
            0 => {
                let t = rng.pick(TOKENS).as_bytes();
                out.splice(at..at, t.iter().copied());
            }
            1 => {
                // Replace the number starting at or after `at`.
                if let Some(start) = out[at..].iter().position(|b| b.is_ascii_digit()).map(|p| p + at) {
                    let end = out[start..].iter().position(|b| !(b.is_ascii_digit() || *b == b'.' || *b == b'e')).map_or(out.len(), |p| p + start);
                    let t = rng.pick(TOKENS).as_bytes();
                    out.splice(start..end, t.iter().copied());
                }
            }
            2 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] ^= 1 << rng.below(8);
            }
            3 | 4 => {
                let text = String::from_utf8_lossy(&out).into_owned();
                let mut lines: Vec<&str> = text.lines().collect();
                if !lines.is_empty() {
                    let i = rng.below(lines.len());
                    if rng.below(2) == 0 {
                        lines.remove(i);
                    } else {
                        let l = lines[i];
                        lines.insert(i, l);
                    }
                }
                out = (lines.join("\n") + "\n").into_bytes();
            }
            5 if !out.is_empty() => {
                let end = (at + 1 + rng.below(32)).min(out.len());
                out.drain(at.min(end)..end);
            }
            _ => {
                let b = rng.below(256) as u8;
                out.insert(at, b);
            }
        }
    }
    out
}

thread_local! {
    /// This test's cases that loaded (and rendered), and that ended in an error.
    static COUNTS: std::cell::Cell<(usize, usize)> = const { std::cell::Cell::new((0, 0)) };
}

/// What a case must satisfy: no panic, then a short error or finite pixels.
fn check(kind: &str, input: &[u8], result: std::thread::Result<Result<Option<Scene>, String>>) {
    let loaded = matches!(result, Ok(Ok(_)));
    COUNTS.with(|c| {
        let (l, r) = c.get();
        c.set(if loaded { (l + 1, r) } else { (l, r + 1) });
    });
    let shown = || String::from_utf8_lossy(&input[..input.len().min(4000)]).into_owned();
    match result {
        Err(_) => panic!("{kind} input panicked:\n{}", shown()),
        Ok(Err(e)) => {
            if std::env::var_os("PINHOLE_FUZZ_VERBOSE").is_some() {
                eprintln!("{kind}: {e}");
            }
            assert!(e.lines().count() <= 3 && e.chars().count() <= MAX_ERROR_CHARS, "{kind}: error too long ({} chars): {}\ninput:\n{}", e.len(), &e[..e.len().min(600)], shown());
        }
        Ok(Ok(Some(scene))) => {
            for renderer in ["raytrace", "rasterize"] {
                let pixels = render_tiny(&scene, renderer);
                if let Some(p) = pixels.iter().find(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite() && p.min_element() >= 0.0)) {
                    panic!("{kind}: {renderer} made pixel {p} from:\n{}", shown());
                }
            }
        }
        Ok(Ok(None)) => {}
    }
}

fn render_tiny(scene: &Scene, renderer: &str) -> Vec<pinhole::math::Vec3> {
    let mut settings = pinhole::render::RenderSettings::for_scene(scene);
    settings.width = 8;
    settings.height = 6;
    let prepared = pinhole::render::PreparedScene::new(scene.clone());
    let r = pinhole::render::renderer_by_name(renderer).unwrap();
    pinhole::render::render_frame(r.as_ref(), &prepared, &settings, &AtomicBool::new(false), None).expect("not cancelled").pixels
}

fn work_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-fuzz-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `body` and reports how many of its cases loaded; a fuzzer whose
/// mutations never load would test only the parsers' first checks.
fn counted(name: &str, body: impl FnOnce()) {
    COUNTS.with(|c| c.set((0, 0)));
    body();
    let (l, r) = COUNTS.with(|c| c.get());
    eprintln!("{name}: {l} cases loaded (scenes rendered with finite pixels), {r} refused with a short error");
    assert!(l > 0 && r > 0, "{name}: the mutations should both load and fail sometimes ({l} loaded, {r} refused)");
}

fn cases() -> usize {
    std::env::var("PINHOLE_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(DEFAULT_CASES)
}

fn seed(kind: u64) -> Rng {
    let base = std::env::var("PINHOLE_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    Rng(base ^ (kind << 32))
}

/// Parses the text twice: against the built-in root (so mutated built-in
/// scenes still find their models) and as a file beside the test assets
/// (`a.obj`, `a.mtl`, `a.png`, `a.exr`), through the bounded reader.
fn run_toml(dir: &Path, text: &[u8]) {
    let text_s = String::from_utf8_lossy(text).into_owned();
    let base = Path::new(pinhole::scene::assets::BUILTIN_ROOT).join("scenes");
    let r = catch_unwind(AssertUnwindSafe(|| pinhole::scene::file::parse_scene(&text_s, "fuzz.toml", &base, "fuzz").map(Some)));
    check("toml", text, r);
    let p = dir.join("s.toml");
    std::fs::write(&p, text).unwrap();
    let r = catch_unwind(AssertUnwindSafe(|| pinhole::scene::file::load_scene_file(&p).map(Some)));
    check("toml file", text, r);
}

fn run_obj(dir: &Path, obj: &[u8], mtl: &[u8]) {
    std::fs::write(dir.join("a.obj"), obj).unwrap();
    std::fs::write(dir.join("a.mtl"), mtl).unwrap();
    let path = dir.join("a.obj");
    let r = catch_unwind(AssertUnwindSafe(|| pinhole::scene::load::load_scene(path.to_str().unwrap()).map(Some)));
    let mut shown = obj.to_vec();
    shown.extend_from_slice(b"\n--- a.mtl ---\n");
    shown.extend_from_slice(mtl);
    check("obj", &shown, r);
}

fn run_ply(dir: &Path, bytes: &[u8]) {
    let path = dir.join("m.ply");
    std::fs::write(&path, bytes).unwrap();
    let r = catch_unwind(AssertUnwindSafe(|| pinhole::scene::load::load_scene(path.to_str().unwrap()).map(Some)));
    check("ply", bytes, r);
}

fn run_gltf(dir: &Path, bytes: &[u8]) {
    let name = if bytes.starts_with(b"glTF") { "m.glb" } else { "m.gltf" };
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let r = catch_unwind(AssertUnwindSafe(|| pinhole::scene::load::load_scene(path.to_str().unwrap()).map(Some)));
    check("gltf", bytes, r);
}

fn run_image(dir: &Path, name: &str, bytes: &[u8]) {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let r = catch_unwind(AssertUnwindSafe(|| {
        let img = pinhole::image_io::load_image(&path);
        if let Ok(img) = &img {
            assert_eq!(img.pixels.len(), img.width as usize * img.height as usize);
        }
        let tex = pinhole::scene::texture::load_texture(&path);
        if let Ok(t) = &tex {
            assert!(t.levels.iter().flat_map(|l| l.texels.iter()).all(|c| c.is_finite() && c.min_element() >= 0.0), "texture with bad texels");
        }
        tex.map(|_| None)
    }));
    check("image", bytes, r);
}

fn test_assets(dir: &Path) {
    let obj = "mtllib a.mtl\nusemtl a\nv -1 -1 -2\nv 1 -1 -2\nv 0 1 -2\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    std::fs::write(dir.join("a.obj"), obj).unwrap();
    std::fs::write(dir.join("a.mtl"), "newmtl a\nKd 0.8 0.8 0.8\nKs 0.1 0.1 0.1\nNs 20\nmap_Kd a.png\n").unwrap();
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([(x * 60) as u8, (y * 60) as u8, 128])).write_to(&mut png, image::ImageFormat::Png).unwrap();
    std::fs::write(dir.join("a.png"), png.into_inner()).unwrap();
    let px: Vec<_> = (0..16).map(|i| pinhole::math::Vec3::splat(i as f32 / 8.0)).collect();
    pinhole::image_io::save_image(&dir.join("a.exr"), 4, 4, &px, 1.0).unwrap();
}

#[test]
fn regressions_stay_fixed() {
    let dir = work_dir("regressions");
    test_assets(&dir);
    for (kind, input) in REGRESSIONS {
        match *kind {
            "toml" => run_toml(&dir, input.as_bytes()),
            "obj" => {
                let (obj, mtl) = input.split_once('\0').unwrap();
                run_obj(&dir, obj.as_bytes(), mtl.as_bytes());
            }
            "ply" => run_ply(&dir, input.as_bytes()),
            "gltf" => run_gltf(&dir, input.as_bytes()),
            _ => run_image(&dir, "r.png", input.as_bytes()),
        }
    }
    // Names of any length are echoed in messages; the messages stay short.
    let long = "A".repeat(1_000_000);
    for toml in [
        format!("[materials.{long}]\nsharpness = nan\n"),
        format!("[[object]]\ntype = \"{long}\"\n"),
        format!("[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"{long}\"\n"),
        format!("[camera]\neye = \"{long}\"\n"),
        format!("[camera]\n{long} = 1\n"),
    ] {
        run_toml(&dir, toml.as_bytes());
    }
    run_obj(&dir, format!("o {long}\nv 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").as_bytes(), b"");
    run_obj(&dir, b"mtllib a.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", format!("newmtl {long}\nKd -1 0 0\n").as_bytes());
}

#[test]
fn mutated_scene_files() {
    let dir = work_dir("toml");
    test_assets(&dir);
    let mut rng = seed(1);
    let mut corpus: Vec<String> = pinhole::scene::builtin::names()
        .into_iter()
        .filter(|n| *n != "bunny")
        .filter_map(pinhole::scene::builtin::source)
        .map(str::to_string)
        .collect();
    corpus.push("[[object]]\ntype = \"mesh\"\nfile = \"a.obj\"\n[[light]]\ntype = \"point\"\nposition = [0, 1, 2]\npower = [10, 10, 10]\n".into());
    corpus.push("[materials.m]\nlambertian = [1, 1, 1]\ntexture = \"a.exr\"\n[[object]]\ntype = \"quad\"\nmaterial = \"m\"\nvertices = [[-1, -1, -2], [1, -1, -2], [1, 1, -2], [-1, 1, -2]]\nscale = [1, 2, 1]\n".into());
    corpus.push(
        "[[object]]\ntype = \"csg\"\nop = \"difference\"\na = { type = \"sphere\", center = [0, 0, -3], radius = 1.0 }\n\
         b = { type = \"csg\", op = \"union\", a = { type = \"sphere\", center = [0.5, 0.5, -2.5], radius = 0.6 }, b = { type = \"mesh\", file = \"a.obj\" } }\n\
         [[light]]\ntype = \"point\"\nposition = [0, 1, 2]\npower = [10, 10, 10]\n"
            .into(),
    );
    counted("scene files", || {
        for _ in 0..cases() {
            let seed_text = rng.pick(&corpus).clone();
            let input = mutate(&mut rng, seed_text.as_bytes());
            run_toml(&dir, &input);
        }
    });
}

#[test]
fn mutated_meshes() {
    let dir = work_dir("obj");
    let mut rng = seed(2);
    let obj = "mtllib a.mtl\no thing\nv -1 -1 -2\nv 1 -1 -2\nv 1 1 -2\nv -1 1 -2\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1 4/1/1\nusemtl b\nf 1 3 4\n";
    let mtl = "newmtl a\nKd 0.8 0.2 0.2\nKs 0.5 0.5 0.5\nNs 50\nnewmtl b\nKd 0.1 0.9 0.1\nmap_Kd a.png\n";
    test_assets(&dir);
    counted("meshes", || {
        for _ in 0..cases() {
            let (o, m) = match rng.below(3) {
                0 => (mutate(&mut rng, obj.as_bytes()), mtl.as_bytes().to_vec()),
                1 => (obj.as_bytes().to_vec(), mutate(&mut rng, mtl.as_bytes())),
                _ => (mutate(&mut rng, obj.as_bytes()), mutate(&mut rng, mtl.as_bytes())),
            };
            run_obj(&dir, &o, &m);
        }
    });
}

#[test]
fn mutated_images() {
    let dir = work_dir("image");
    test_assets(&dir);
    let png = std::fs::read(dir.join("a.png")).unwrap();
    let exr = std::fs::read(dir.join("a.exr")).unwrap();
    let mut rng = seed(3);
    counted("images", || for _ in 0..cases() {
        let (name, base) = if rng.below(2) == 0 { ("m.png", &png) } else { ("m.exr", &exr) };
        // Byte flips and insertions, never whole-line edits: these are binary.
        let mut bytes = base.clone();
        for _ in 0..1 + rng.below(6) {
            let i = rng.below(bytes.len());
            match rng.below(3) {
                0 => bytes[i] ^= 1 << rng.below(8),
                1 => bytes[i] = *rng.pick(&[0u8, 0xff, 0x7f, 0x80]),
                _ => bytes.truncate(i.max(8)),
            }
        }
        run_image(&dir, name, &bytes);
    });
}

/// Every numeric option at its documented bound (drawn) and just beyond it
/// (refused in one sentence naming the option), on the command line.
/// Bounds whose drawing alone is heavy (50 million photons, 4096-texel
/// cube maps) are checked only beyond.
#[test]
fn options_at_and_just_beyond_their_bounds() {
    let dir = work_dir("options");
    let run = |extra: &[&str]| {
        let mut args = vec!["render", "one-triangle", "-o", "o.exr"];
        for size in [["--width", "8"], ["--height", "6"]] {
            if extra[0] != size[0] {
                args.extend_from_slice(&size);
            }
        }
        args.extend_from_slice(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_pinhole")).current_dir(&dir).args(&args).output().unwrap()
    };
    let cases: &[(&str, Option<&str>, &[&str])] = &[
        ("--spp", Some("1"), &["0", "65537", "-1", "nan"]),
        ("--width", Some("1"), &["0", "16385", "-8"]),
        ("--height", Some("16384"), &["0", "16385"]),
        ("--light-samples", Some("4096"), &["4097", "-1"]),
        ("--pcf-radius", Some("64"), &["64.001", "-0.5", "nan", "inf"]),
        ("--bump", Some("0"), &["-1e-9", "nan", "inf"]),
        ("--shadow-map-size", Some("1"), &["0", "4097"]),
        ("--shadow-bias", Some("0"), &["-0.1", "nan"]),
        ("--msaa", Some("8"), &["3", "16", "0"]),
        ("--adaptive", Some("1e-6"), &["0", "-1", "inf"]),
        ("--subsample", Some("16"), &["3", "32", "0"]),
        ("--bounces", Some("100"), &["101", "-1", "many"]),
        ("--ao-samples", Some("4096"), &["0", "4097"]),
        ("--ao-distance", Some("inf"), &["0", "-1", "nan"]),
        ("--photons", Some("1"), &["0", "50000001"]),
        ("--photon-k", Some("4096"), &["0", "4097"]),
        ("--final-gather", Some("4096"), &["4097"]),
        ("--seed", Some("18446744073709551615"), &["18446744073709551616", "-1"]),
        ("--threads", Some("1"), &["0", "-2"]),
    ];
    for (flag, at, beyond) in cases {
        if let Some(v) = at {
            let out = run(&[flag, v]);
            assert!(out.status.success(), "{flag} {v}: {}", String::from_utf8_lossy(&out.stderr));
            let img = pinhole::image_io::load_image(&dir.join("o.exr")).unwrap();
            assert!(img.pixels.iter().all(|p| p.is_finite()), "{flag} {v}: a pixel is not finite");
        }
        for v in *beyond {
            let out = run(&[flag, v]);
            let e = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{flag} {v} was accepted");
            assert_eq!(e.trim_end().lines().count(), 1, "{flag} {v}: {e}");
            assert!(e.contains(flag), "{flag} {v}: the error does not name the option: {e}");
        }
    }
}

/// References for charts with random sizes and pixels (black, negative,
/// NaN, ordinary): each is accepted only when error against it means
/// something, and refused otherwise in one sentence.
#[test]
fn reference_images_of_every_kind() {
    let dir = work_dir("references");
    let mut rng = seed(7);
    let (mut accepted, mut refused) = (0, 0);
    for case in 0..cases().min(200) {
        let (w, h) = *rng.pick(&[(16u32, 12u32), (16, 12), (8, 6), (17, 12)]);
        let kind = rng.below(4);
        let pixels: Vec<Vec3> = (0..w * h)
            .map(|_| {
                let v = (rng.below(1000) as f32) / 500.0;
                match (kind, rng.below(40)) {
                    (0, _) => Vec3::ZERO,
                    (1, 0) => Vec3::new(v, -v - 0.01, v),
                    (2, 0) => Vec3::new(f32::NAN, v, v),
                    _ => Vec3::splat(v),
                }
            })
            .collect();
        let path = dir.join(format!("r{case}.exr"));
        pinhole::image_io::save_image(&path, w, h, &pixels, 1.0).unwrap();
        match pinhole::chart::reference::load_reference_file(&path, 16, 12) {
            Ok(img) => {
                accepted += 1;
                assert!(img.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0), "case {case}");
                assert!(img.pixels.iter().any(|p| p.max_element() > 0.0), "case {case}: an all-black reference was accepted");
            }
            Err(e) => {
                refused += 1;
                assert_eq!(e.lines().count(), 1, "case {case}: {e}");
                assert!(e.contains(&format!("r{case}.exr")), "case {case}: {e}");
            }
        }
    }
    assert!(accepted > 0 && refused > 0, "{accepted} accepted, {refused} refused");
}

/// The closed cube with a random set of faces wound the other way: all of
/// them (inside out) is turned right side out with a warning and renders;
/// some of them is refused as not consistently wound.
#[test]
fn closed_meshes_turned_inside_out() {
    let dir = work_dir("inside-out");
    let faces = [[5, 6, 7], [5, 7, 8], [2, 1, 4], [2, 4, 3], [6, 2, 3], [6, 3, 7], [1, 5, 8], [1, 8, 4], [8, 7, 3], [8, 3, 4], [1, 2, 6], [1, 6, 5]];
    let mut rng = seed(8);
    for case in 0..40 {
        let flip_all = case % 2 == 0;
        let mut obj = String::from("v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n");
        let mut flipped = 0;
        for f in faces {
            let flip = flip_all || rng.below(2) == 0;
            flipped += flip as usize;
            let [a, b, c] = if flip { [f[0], f[2], f[1]] } else { f };
            obj += &format!("f {a} {b} {c}\n");
        }
        std::fs::write(dir.join("cube.obj"), &obj).unwrap();
        let scene = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n[[light]]\ntype = \"point\"\nposition = [0, 2, 5]\npower = [80, 80, 80]\n\
[[object]]\ntype = \"csg\"\nop = \"union\"\na = { type = \"mesh\", file = \"cube.obj\" }\nb = { type = \"sphere\", center = [3, 0, 0], radius = 0.5 }\n";
        std::fs::write(dir.join("s.toml"), scene).unwrap();
        match pinhole::scene::file::load_scene_file(&dir.join("s.toml")) {
            Ok(s) => {
                assert!(flipped == 0 || flipped == faces.len(), "case {case}: {flipped} faces flipped yet accepted");
                assert_eq!(s.warnings.iter().any(|w| w.contains("inside out")), flipped == faces.len(), "case {case}: {:?}", s.warnings);
                let pixels = render_tiny(&s, "raytrace");
                assert!(pixels.iter().all(|p| p.is_finite()));
            }
            Err(e) => {
                assert!(flipped > 0 && flipped < faces.len(), "case {case}: {e}");
                assert_eq!(e.lines().count(), 1, "{e}");
            }
        }
    }
}

/// Outputs reached through random chains of symlinks, `..` and hard links:
/// refused exactly when they land on an input.
#[test]
fn output_paths_that_alias_inputs() {
    let dir = work_dir("alias");
    std::fs::create_dir_all(dir.join("a/b")).unwrap();
    let input = dir.join("a/scene.toml");
    std::fs::write(&input, "x").unwrap();
    // Read through the one reader, as a scene is.
    pinhole::input::read_file(&input, pinhole::input::InputKind::Scene).unwrap();
    let mut rng = seed(9);
    for case in 0..60 {
        let target_is_input = rng.below(2) == 0;
        let name = if target_is_input { "scene.toml".to_string() } else { format!("out{case}.exr") };
        let path = match rng.below(3) {
            0 => dir.join("a/b/..").join(&name),
            1 => {
                let link = dir.join(format!("link{case}"));
                std::os::unix::fs::symlink(dir.join("a").join(&name), &link).unwrap();
                link
            }
            _ => {
                if target_is_input {
                    let hard = dir.join(format!("hard{case}.toml"));
                    std::fs::hard_link(&input, &hard).unwrap();
                    hard
                } else {
                    dir.join("a/./").join(&name)
                }
            }
        };
        let r = pinhole::file_identity::check_outputs(&[&path]);
        assert_eq!(r.is_err(), target_is_input, "case {case}: {} -> {r:?}", path.display());
    }
}

#[test]
fn mutated_ply_meshes() {
    let dir = work_dir("ply");
    let mut rng = seed(4);
    let ascii = "ply\nformat ascii 1.0\ncomment a square and a triangle\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
                 property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 2\n\
                 property list uchar int vertex_indices\nend_header\n-1 -1 -2 0 0 1 0 0\n1 -1 -2 0 0 1 1 0\n1 1 -2 0 0 1 1 1\n-1 1 -2 0 0 1 0 1\n\
                 0 2 -3 0 0 1 0.5 0.5\n4 0 1 2 3\n3 3 2 4\n";
    let mut binary = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                       element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    for p in [[-1.0f32, -1.0, -2.0], [1.0, -1.0, -2.0], [1.0, 1.0, -2.0], [-1.0, 1.0, -2.0]] {
        p.iter().for_each(|x| binary.extend(x.to_le_bytes()));
    }
    binary.push(4);
    [0u32, 1, 2, 3].iter().for_each(|i| binary.extend(i.to_le_bytes()));
    counted("ply meshes", || {
        for _ in 0..cases() {
            if rng.below(2) == 0 {
                run_ply(&dir, &mutate(&mut rng, ascii.as_bytes()));
            } else {
                // Binary: byte flips, special bytes and cuts, never line edits.
                let mut bytes = binary.clone();
                for _ in 0..1 + rng.below(4) {
                    let i = rng.below(bytes.len());
                    match rng.below(3) {
                        0 => bytes[i] ^= 1 << rng.below(8),
                        1 => bytes[i] = *rng.pick(&[0u8, 0xff, 0x7f, 0x80]),
                        _ => bytes.truncate(i.max(4)),
                    }
                }
                run_ply(&dir, &bytes);
            }
        }
    });
}

#[test]
fn mutated_gltf_files() {
    let dir = work_dir("gltf");
    let mut rng = seed(5);
    let samples = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf");
    let corpus: Vec<Vec<u8>> = ["Box.gltf", "Cameras.gltf", "BoxTextured.gltf", "BoxVertexColors.gltf"].iter().map(|f| std::fs::read(samples.join(f)).unwrap()).collect();
    counted("gltf files", || {
        for _ in 0..cases() {
            let seed_bytes = rng.pick(&corpus).clone();
            let input = mutate(&mut rng, &seed_bytes);
            run_gltf(&dir, &input);
        }
    });
}
