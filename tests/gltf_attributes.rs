//! What a glTF's vertices and textures carry besides positions: a
//! `TANGENT` attribute turns a normal texture's frame away from the one
//! the uvs give; each texture is read with its own sampler's wrap mode
//! (repeat, mirrored repeat, clamp) on uvs outside [0, 1], the base colour
//! and the emissive texture of one material each with their own; and a
//! mesh with vertex colours shared by two nodes, one of them mirroring,
//! shows its colours on both copies.

mod common;

use glam::Vec3;
use pinhole::render::inspect::debug::View;
use pinhole::render::{PreparedScene, RenderSettings};
use pinhole::scene::load::load_scene;
use pinhole::scene::material::Sampler;
use pinhole::scene::texture::{TextureFilter, Wrap};
use pinhole::scene::Scene;
use std::path::{Path, PathBuf};

fn work_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-gltf-attributes-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// One buffer of accessors, each in a view of its own, written as the
/// `buffers`, `bufferViews` and `accessors` of a glTF.
#[derive(Default)]
struct Buffer {
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl Buffer {
    /// Float elements of `n` components (`VEC2`, `VEC3` or `VEC4`); returns the accessor's index.
    fn floats<const N: usize>(&mut self, data: &[[f32; N]]) -> usize {
        let start = self.bin.len();
        data.iter().flatten().for_each(|f| self.bin.extend(f.to_le_bytes()));
        let bounds = if N == 3 {
            let lo: Vec<String> = (0..N).map(|k| data.iter().map(|e| e[k]).fold(f32::INFINITY, f32::min).to_string()).collect();
            let hi: Vec<String> = (0..N).map(|k| data.iter().map(|e| e[k]).fold(f32::NEG_INFINITY, f32::max).to_string()).collect();
            format!(r#", "min": [{}], "max": [{}]"#, lo.join(", "), hi.join(", "))
        } else {
            String::new()
        };
        self.add(start, format!(r#""componentType": 5126, "count": {}, "type": "VEC{N}"{bounds}"#, data.len()))
    }

    fn indices(&mut self, data: &[u16]) -> usize {
        let start = self.bin.len();
        data.iter().for_each(|i| self.bin.extend(i.to_le_bytes()));
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.add(start, format!(r#""componentType": 5123, "count": {}, "type": "SCALAR""#, data.len()))
    }

    fn add(&mut self, start: usize, accessor: String) -> usize {
        self.views.push(format!(r#"{{"buffer": 0, "byteOffset": {start}, "byteLength": {}}}"#, self.bin.len() - start));
        self.accessors.push(format!(r#"{{"bufferView": {}, {accessor}}}"#, self.views.len() - 1));
        self.accessors.len() - 1
    }

    /// A whole glTF: these buffers, and `rest` (the other top-level members).
    fn gltf(&self, rest: &str) -> String {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, {rest},
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{}],
  "accessors": [{}]}}"#,
            self.bin.len(),
            common::base64(&self.bin),
            self.views.join(", "),
            self.accessors.join(", ")
        )
    }
}

/// A PNG of `width` x 1 RGB texels, as a data URI.
fn png_row(texels: &[[u8; 3]]) -> String {
    let img = image::RgbImage::from_fn(texels.len() as u32, 1, |x, _| image::Rgb(texels[x as usize]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    format!("data:image/png;base64,{}", common::base64(bytes.get_ref()))
}

/// The camera every file here looks through: at z = 3, down -z; at z = 0
/// the 80 x 40 image spans 2.54 units either side of the centre.
const CAMERA: &str = r#""cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100, "aspectRatio": 2.0}}]"#;
const W: u32 = 80;
const H: u32 = 40;

/// The pixel column that sees x (at z = 0) on the middle row.
fn column(x: f32) -> u32 {
    // Half the image's height is 3 tan(yfov / 2) there; its width is twice its height.
    (40.0 + x * 40.0 / (2.0 * 3.0 * 0.4f32.tan())).floor() as u32
}

fn write(dir: &Path, name: &str, json: String) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, json).unwrap();
    path
}

fn render(scene: &Scene, renderer: &str, view: View) -> Vec<Vec3> {
    let settings = RenderSettings { width: W, height: H, view, ..RenderSettings::for_scene(scene) };
    common::render(renderer, &PreparedScene::new(scene.clone()), &settings)
}

/// The scene lit by an ambient term alone: each pixel is the albedo seen
/// (plus any emission).
fn unlit(path: &Path) -> Scene {
    let mut scene = load_scene(path.to_str().unwrap()).unwrap();
    scene.lights.clear();
    scene.render.ambient = Vec3::ONE;
    scene
}

/// A quad facing +z, x in [-w, w] and y in [-0.5, 0.5], its u running
/// from `u0` on the left to `u1` on the right.
fn quad(buffer: &mut Buffer, w: f32, (u0, u1): (f32, f32), tangent: Option<[f32; 4]>) -> String {
    let p = buffer.floats(&[[-w, -0.5, 0.0], [w, -0.5, 0.0], [w, 0.5, 0.0], [-w, 0.5, 0.0]]);
    let n = buffer.floats(&[[0.0, 0.0, 1.0]; 4]);
    let uv = buffer.floats(&[[u0, 1.0], [u1, 1.0], [u1, 0.0], [u0, 0.0]]);
    let t = tangent.map(|t| format!(r#", "TANGENT": {}"#, buffer.floats(&[t; 4]))).unwrap_or_default();
    let i = buffer.indices(&[0, 1, 2, 0, 2, 3]);
    format!(r#"{{"primitives": [{{"attributes": {{"POSITION": {p}, "NORMAL": {n}, "TEXCOORD_0": {uv}{t}}}, "indices": {i}, "material": 0}}]}}"#)
}

#[test]
fn a_tangent_attribute_turns_the_normal_texture_frame() {
    let dir = work_dir("tangent");
    // A normal texel leaning 30 degrees along the frame's tangent.
    let a = 30f32.to_radians();
    let lean = |c: f32| (c * 127.5 + 127.5).round() as u8;
    let texel = [lean(a.sin()), lean(0.0), lean(a.cos())];
    let file = |tangent: Option<[f32; 4]>, name: &str| {
        let mut buffer = Buffer::default();
        let mesh = quad(&mut buffer, 1.0, (0.0, 1.0), tangent);
        let rest = format!(
            r#""scenes": [{{"nodes": [0, 1]}}], "nodes": [{{"mesh": 0}}, {{"camera": 0, "translation": [0, 0, 3]}}], {CAMERA},
  "meshes": [{mesh}],
  "materials": [{{"normalTexture": {{"index": 0}}, "pbrMetallicRoughness": {{"metallicFactor": 0}}}}],
  "textures": [{{"source": 0}}], "images": [{{"uri": "{}"}}]"#,
            png_row(&[texel])
        );
        write(&dir, name, buffer.gltf(&rest))
    };
    // The uvs' frame has its tangent along +x; the file's says +y.
    let by_uvs = load_scene(file(None, "by_uvs.gltf").to_str().unwrap()).unwrap();
    let given = load_scene(file(Some([0.0, 1.0, 0.0, 1.0]), "given.gltf").to_str().unwrap()).unwrap();
    let centre = (40 + 20 * W) as usize;
    for renderer in ["raytrace", "rasterize"] {
        // The normal view shows (n + 1) / 2.
        let n_uvs = render(&by_uvs, renderer, View::Normal)[centre] * 2.0 - Vec3::ONE;
        let n_given = render(&given, renderer, View::Normal)[centre] * 2.0 - Vec3::ONE;
        eprintln!("{renderer}: normal by the uvs' frame {n_uvs}, by the TANGENT {n_given}");
        assert!((n_uvs - Vec3::new(a.sin(), 0.0, a.cos())).length() < 0.02, "{renderer}: by the uvs' frame the normal is {n_uvs}");
        assert!((n_given - Vec3::new(0.0, a.sin(), a.cos())).length() < 0.02, "{renderer}: with TANGENT +y the normal is {n_given}");
    }
}

/// Pixel columns where the quad of `sampled_quad` has u = -0.75, -0.25, 1.25 and 1.75.
fn wrap_columns() -> [u32; 4] {
    // The quad spans x in [-1.5, 1.5] with u from -1 to 2: u = x + 0.5.
    [-1.25f32, -0.75, 0.75, 1.25].map(column)
}

/// A quad with uvs from -1 to 2 across it, its material's base colour
/// texture (and, with `emissive`, its emissive texture) a black texel then
/// a white one, read with `samplers[0]` (and `samplers[1]`): glTF wrap mode
/// numbers, nearest filters.
fn sampled_quad(dir: &Path, name: &str, wraps: &[u32], emissive: bool) -> PathBuf {
    let mut buffer = Buffer::default();
    let mesh = quad(&mut buffer, 1.5, (-1.0, 2.0), None);
    let samplers: Vec<String> = wraps.iter().map(|w| format!(r#"{{"magFilter": 9728, "minFilter": 9728, "wrapS": {w}, "wrapT": 33071}}"#)).collect();
    let textures: Vec<String> = (0..wraps.len()).map(|k| format!(r#"{{"source": 0, "sampler": {k}}}"#)).collect();
    let emission = if emissive { r#", "emissiveTexture": {"index": 1}, "emissiveFactor": [1, 1, 1]"# } else { "" };
    let rest = format!(
        r#""scenes": [{{"nodes": [0, 1]}}], "nodes": [{{"mesh": 0}}, {{"camera": 0, "translation": [0, 0, 3]}}], {CAMERA},
  "meshes": [{mesh}],
  "materials": [{{"pbrMetallicRoughness": {{"metallicFactor": 0, "baseColorTexture": {{"index": 0}}}}{emission}}}],
  "samplers": [{}], "textures": [{}], "images": [{{"uri": "{}"}}]"#,
        samplers.join(", "),
        textures.join(", "),
        png_row(&[[0, 0, 0], [255, 255, 255]])
    );
    write(dir, name, buffer.gltf(&rest))
}

const REPEAT: u32 = 10497;
const CLAMP: u32 = 33071;
const MIRRORED: u32 = 33648;

#[test]
fn each_wrap_mode_reads_uvs_outside_the_unit_square_its_own_way() {
    let dir = work_dir("wrap");
    // The texel each mode reads at u = -0.75, -0.25, 1.25, 1.75 (0 black, 1 white).
    let cases = [("repeat", REPEAT, [0.0, 1.0, 0.0, 1.0]), ("clamp", CLAMP, [0.0, 0.0, 1.0, 1.0]), ("mirrored", MIRRORED, [1.0, 0.0, 1.0, 0.0])];
    for (name, mode, expected) in cases {
        let scene = unlit(&sampled_quad(&dir, &format!("{name}.gltf"), &[mode], false));
        for renderer in ["raytrace", "rasterize"] {
            let img = render(&scene, renderer, View::Shaded);
            let seen = wrap_columns().map(|x| img[(x + 20 * W) as usize].x);
            eprintln!("{name} ({renderer}): {seen:?}");
            for (got, want) in seen.iter().zip(expected) {
                assert!((got - want).abs() < 0.02, "{name} ({renderer}): {seen:?}, expected {expected:?}");
            }
        }
    }
}

#[test]
fn two_textures_of_one_material_keep_their_own_samplers() {
    let dir = work_dir("per-texture");
    // The base colour clamps, the emission mirrors; both nearest.
    let scene = unlit(&sampled_quad(&dir, "two.gltf", &[CLAMP, MIRRORED], true));
    let m = scene.materials.iter().find(|m| m.emission_map.is_some()).unwrap();
    assert_eq!(m.wrap, [Wrap::Clamp; 2]);
    assert_eq!(m.map_samplers.emission, Some(Sampler { wrap: [Wrap::MirroredRepeat, Wrap::Clamp], finest_filter: TextureFilter::Nearest }));
    // Each pixel is the clamped base colour plus the mirrored emission.
    let expected = [0.0 + 1.0, 0.0 + 0.0, 1.0 + 1.0, 1.0 + 0.0];
    for renderer in ["raytrace", "rasterize"] {
        let img = render(&scene, renderer, View::Shaded);
        let seen = wrap_columns().map(|x| img[(x + 20 * W) as usize].x);
        eprintln!("clamp + mirrored ({renderer}): {seen:?}");
        for (got, want) in seen.iter().zip(expected) {
            assert!((got - want).abs() < 0.03, "{renderer}: {seen:?}, expected {expected:?}");
        }
    }
}

#[test]
fn vertex_colours_show_on_every_copy_of_a_shared_mesh() {
    let dir = work_dir("shared-colours");
    let mut buffer = Buffer::default();
    // A unit quad, red on its left edge and blue on its right.
    let p = buffer.floats(&[[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]);
    let c = buffer.floats(&[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]);
    let i = buffer.indices(&[0, 1, 2, 0, 2, 3]);
    // Two copies: one moved left, one moved right and mirrored in x.
    let rest = format!(
        r#""scenes": [{{"nodes": [0, 1, 2]}}],
  "nodes": [{{"mesh": 0, "translation": [-1, 0, 0]}}, {{"mesh": 0, "translation": [1, 0, 0], "scale": [-1, 1, 1]}}, {{"camera": 0, "translation": [0, 0, 3]}}], {CAMERA},
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": {p}, "COLOR_0": {c}}}, "indices": {i}}}]}}]"#
    );
    let scene = unlit(&write(&dir, "shared.gltf", buffer.gltf(&rest)));
    assert!(scene.layer.is_some(), "the shared mesh is held once, in the instance layer");
    assert!(!scene.warnings.iter().any(|w| w.contains("vertex colours")), "{:?}", scene.warnings);
    let grey = scene.materials.iter().find(|m| m.name == "default").unwrap().lambertian.x;
    // Near each copy's left and right edges: how much red and blue.
    let left_copy = [column(-1.35), column(-0.65)];
    let right_copy = [column(0.65), column(1.35)];
    for renderer in ["raytrace", "rasterize"] {
        let img = render(&scene, renderer, View::Shaded);
        let at = |x: u32| img[(x + 20 * W) as usize] / grey;
        let (a_left, a_right, b_left, b_right) = (at(left_copy[0]), at(left_copy[1]), at(right_copy[0]), at(right_copy[1]));
        eprintln!("{renderer}: left copy {a_left} .. {a_right}, mirrored copy {b_left} .. {b_right}");
        // Left copy: red on its left, blue on its right (0.85 of each near its edge).
        for (c, red) in [(a_left, true), (a_right, false), (b_left, false), (b_right, true)] {
            let (major, minor) = if red { (c.x, c.z) } else { (c.z, c.x) };
            assert!((major - 0.85).abs() < 0.05 && (minor - 0.15).abs() < 0.05 && c.y < 0.01, "{renderer}: {c} (expected mostly {})", if red { "red" } else { "blue" });
        }
    }
}

