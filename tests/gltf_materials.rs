//! glTF materials and textures: a metallic-roughness material renders as
//! the TOML material written by hand from the model's formulas (with and
//! without textures, whose blue channel scales metalness and green
//! roughness), an emissive texture scales emission, a normal texture is
//! read as data and bends normals, samplers set the wrap
//! modes and cap the filter, and the Khronos BoxTextured sample puts each
//! texel where its uvs say and BoxVertexColors each colour where its
//! vertices say, checked against ray casts written here.

mod common;

use glam::{Vec2, Vec3};
use pinhole::render::inspect::debug::View;
use pinhole::render::{PreparedScene, RenderSettings};
use pinhole::scene::load::load_scene;
use pinhole::scene::texture::{TextureFilter, Wrap};
use pinhole::scene::Scene;
use std::path::{Path, PathBuf};

fn work_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-gltf-materials-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn render(scene: &Scene, renderer: &str, settings: &RenderSettings) -> Vec<Vec3> {
    common::render(renderer, &PreparedScene::new(scene.clone()), settings)
}


fn unbase64(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    } as u32;
    let digits: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::new();
    for c in digits.chunks(4) {
        let n = c.iter().enumerate().fold(0u32, |n, (k, &d)| n | value(d) << (18 - 6 * k));
        for k in 0..c.len() - 1 {
            out.push((n >> (16 - 8 * k)) as u8);
        }
    }
    out
}

/// A 2 x 2 PNG of one colour, as a data URI.
fn png_uri(rgb: [u8; 3]) -> String {
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb(rgb));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    format!("data:image/png;base64,{}", common::base64(bytes.get_ref()))
}

/// A UV sphere of radius 1 at the origin: positions (= normals) and
/// counter-clockwise triangles seen from outside.
fn sphere() -> (Vec<Vec3>, Vec<[u16; 3]>) {
    let (rings, segments) = (16u16, 32u16);
    let mut p = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
            p.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    let mut t = Vec::new();
    let at = |r: u16, s: u16| r * (segments + 1) + s;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s + 1));
            if r > 0 {
                t.push([a, b, d]);
            }
            if r + 1 < rings {
                t.push([d, b, c]);
            }
        }
    }
    (p, t)
}

/// Writes `sphere.gltf` (the sphere with `material`, a JSON object, and
/// `extra` top-level members such as textures) and `sphere.obj` (the same
/// triangles) into `dir`.
fn write_sphere(dir: &Path, material: &str, extra: &str) {
    let (p, t) = sphere();
    let mut bin = Vec::new();
    for v in &p {
        v.to_array().iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    for v in &p {
        v.to_array().iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    let uv_at = bin.len();
    for v in &p {
        [v.x * 0.5 + 0.5, v.y * 0.5 + 0.5].iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    let idx_at = bin.len();
    t.iter().flatten().for_each(|i| bin.extend(i.to_le_bytes()));
    let n = p.len();
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}}, "indices": 3, "material": 0}}]}}],
"materials": [{material}],
"accessors": [
 {{"bufferView": 0, "componentType": 5126, "count": {n}, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]}},
 {{"bufferView": 0, "byteOffset": {nb}, "componentType": 5126, "count": {n}, "type": "VEC3"}},
 {{"bufferView": 1, "componentType": 5126, "count": {n}, "type": "VEC2"}},
 {{"bufferView": 2, "componentType": 5123, "count": {ni}, "type": "SCALAR"}}],
"bufferViews": [{{"buffer": 0, "byteLength": {uv_at}}}, {{"buffer": 0, "byteOffset": {uv_at}, "byteLength": {uvl}}}, {{"buffer": 0, "byteOffset": {idx_at}, "byteLength": {il}}}],
"buffers": [{{"byteLength": {bl}, "uri": "data:application/octet-stream;base64,{b64}"}}]{extra}}}"#,
        nb = n * 12,
        ni = t.len() * 3,
        uvl = idx_at - uv_at,
        il = bin.len() - idx_at,
        bl = bin.len(),
        b64 = common::base64(&bin),
    );
    std::fs::write(dir.join("sphere.gltf"), json).unwrap();
    let mut obj = String::new();
    for v in &p {
        obj += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for v in &p {
        obj += &format!("vn {} {} {}\n", v.x, v.y, v.z);
    }
    for v in &p {
        obj += &format!("vt {} {}\n", v.x * 0.5 + 0.5, 1.0 - (v.y * 0.5 + 0.5));
    }
    for f in &t {
        let [a, b, c] = f.map(|i| i + 1);
        obj += &format!("f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n");
    }
    std::fs::write(dir.join("sphere.obj"), obj).unwrap();
}

/// The camera, light and image shared by both scenes of a comparison.
const STAGE: &str = "[camera]\neye = [0.0, 0.6, 3.2]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n\
[render]\nwidth = 96\nheight = 72\nambient = [0.0, 0.0, 0.0]\n\
[[light]]\ntype = \"point\"\nposition = [2.0, 3.0, 3.0]\npower = [400.0, 400.0, 400.0]\n";

/// The glTF sphere placed in a scene file, and the OBJ sphere with the
/// hand-written material `toml_material` (the body of `[materials.m]`).
fn pair(dir: &Path, toml_material: &str) -> (Scene, Scene) {
    pair_with(dir, toml_material, "")
}

/// `pair` with `more` (objects) added to both scenes.
fn pair_with(dir: &Path, toml_material: &str, more: &str) -> (Scene, Scene) {
    let gltf = format!("{STAGE}{more}[[object]]\ntype = \"gltf\"\nfile = \"sphere.gltf\"\n");
    let toml = format!("{STAGE}{more}[materials.m]\n{toml_material}\n[[object]]\ntype = \"mesh\"\nfile = \"sphere.obj\"\nmaterial = \"m\"\n");
    std::fs::write(dir.join("gltf.toml"), gltf).unwrap();
    std::fs::write(dir.join("toml.toml"), toml).unwrap();
    (load_scene(dir.join("gltf.toml").to_str().unwrap()).unwrap(), load_scene(dir.join("toml.toml").to_str().unwrap()).unwrap())
}

/// rmse over mean of `a` against `b`, every channel of every pixel.
fn relative_rmse(a: &[Vec3], b: &[Vec3]) -> f64 {
    let (mut se, mut sum) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        for c in 0..3 {
            se += ((x[c] - y[c]) as f64).powi(2);
            sum += y[c] as f64;
        }
    }
    let n = (a.len() * 3) as f64;
    (se / n).sqrt() / (sum / n)
}

fn assert_renders_alike(tag: &str, gltf: &Scene, toml: &Scene, limit: f64) {
    let settings = RenderSettings::for_scene(toml);
    for renderer in ["raytrace", "rasterize"] {
        let (a, b) = (render(gltf, renderer, &settings), render(toml, renderer, &settings));
        let lit = b.iter().filter(|p| p.max_element() > 0.01).count();
        assert!(lit > a.len() / 5, "{tag}: the sphere fills part of the frame ({lit} lit pixels)");
        let e = relative_rmse(&a, &b);
        eprintln!("{tag} ({renderer}): rmse/mean {e:.6}");
        assert!(e < limit, "{tag} ({renderer}): rmse/mean {e:.5} between the glTF and the TOML material");
    }
}

#[test]
fn metallic_roughness_renders_as_the_toml_material_written_by_hand() {
    let dir = work_dir("factors");
    // Metallic 0, roughness 1: Lambert with the base colour plus GGX at
    // alpha 1 with Schlick's F0 = 0.04.
    write_sphere(&dir, r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}"#, "");
    let (gltf, toml) = pair(&dir, "lambertian = [0.8, 0.5, 0.3]\nglossy = [0.04, 0.04, 0.04]\nglossy_model = \"ggx\"\nroughness = 1.0\nfresnel = \"schlick\"");
    assert_renders_alike("metallic 0, roughness 1", &gltf, &toml, 0.02);
    // Metallic 0.6, roughness 0.5: k_L = b (1 - 0.6), F0 = 0.04 * 0.4 + b * 0.6, alpha 0.25.
    write_sphere(&dir, r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1.0], "metallicFactor": 0.6, "roughnessFactor": 0.5}}"#, "");
    let (gltf, toml) = pair(&dir, "lambertian = [0.32, 0.2, 0.12]\nglossy = [0.496, 0.316, 0.196]\nglossy_model = \"ggx\"\nroughness = 0.25\nfresnel = \"schlick\"");
    assert_renders_alike("metallic 0.6, roughness 0.5", &gltf, &toml, 0.02);
    // A metal shows its highlight: the two materials differ by more than the limit.
    let (_, lambert) = pair(&dir, "lambertian = [0.32, 0.2, 0.12]");
    let settings = RenderSettings::for_scene(&lambert);
    let e = relative_rmse(&render(&gltf, "raytrace", &settings), &render(&lambert, "raytrace", &settings));
    assert!(e > 0.05, "the glossy lobe must show ({e:.4})");
}

#[test]
fn metallic_roughness_texture_scales_metalness_by_blue_and_roughness_by_green() {
    let dir = work_dir("textures");
    let textured = |base: [u8; 3], mr: [u8; 3]| {
        format!(
            r#", "textures": [{{"source": 0}}, {{"source": 1}}], "images": [{{"uri": "{}"}}, {{"uri": "{}"}}]"#,
            png_uri(base),
            png_uri(mr)
        )
    };
    let material = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1.0], "metallicFactor": 0.6, "roughnessFactor": 0.5, "baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1}}}"#;
    // White textures leave the factors as they are.
    write_sphere(&dir, material, &textured([255, 255, 255], [0, 255, 255]));
    let (gltf, toml) = pair(&dir, "lambertian = [0.32, 0.2, 0.12]\nglossy = [0.496, 0.316, 0.196]\nglossy_model = \"ggx\"\nroughness = 0.25\nfresnel = \"schlick\"");
    assert!(gltf.materials.iter().any(|m| m.metallic.is_some()), "the textures make the lobes vary over the surface");
    assert_renders_alike("white textures", &gltf, &toml, 0.01);
    // Blue 0 makes it a dielectric; green 102 (0.4) makes roughness
    // 0.5 * 0.4 = 0.2 (alpha 0.04); red is not read. The base texture's
    // sRGB 188 is linear 0.5029 (the sRGB curve), halving the base colour.
    write_sphere(&dir, material, &textured([188, 188, 188], [255, 102, 0]));
    let b = 0.502886;
    let lambertian = [0.8 * b, 0.5 * b, 0.3 * b];
    let toml_material = format!(
        "lambertian = [{}, {}, {}]\nglossy = [0.04, 0.04, 0.04]\nglossy_model = \"ggx\"\nroughness = 0.04\nfresnel = \"schlick\"",
        lambertian[0], lambertian[1], lambertian[2]
    );
    let (gltf, toml) = pair(&dir, &toml_material);
    assert_renders_alike("blue 0, green 0.4, base 0.5", &gltf, &toml, 0.01);
    // Swapping the channels' meaning would make it a rough metal instead.
    let (_, metal) = pair(&dir, "lambertian = [0.0, 0.0, 0.0]\nglossy = [0.402, 0.251, 0.151]\nglossy_model = \"ggx\"\nroughness = 0.16\nfresnel = \"schlick\"");
    let settings = RenderSettings::for_scene(&metal);
    let e = relative_rmse(&render(&gltf, "raytrace", &settings), &render(&metal, "raytrace", &settings));
    assert!(e > 0.1, "channels read the other way round must differ ({e:.4})");
}

#[test]
fn emissive_texture_scales_emission_seen_and_sampled() {
    let dir = work_dir("emissive");
    // sRGB 128 is linear 0.21586.
    let with_texture = format!(r#", "textures": [{{"source": 0}}], "images": [{{"uri": "{}"}}]"#, png_uri([128, 128, 128]));
    write_sphere(&dir, r#"{"emissiveFactor": [1.0, 0.5, 0.25], "emissiveTexture": {"index": 0}, "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0}}"#, &with_texture);
    // A floor beside the sphere is lit by it: the sampled emitter's radiance counts there.
    let floor = "[[object]]\ntype = \"quad\"\nvertices = [[-3.0, -1.2, 2.0], [3.0, -1.2, 2.0], [3.0, -1.2, -3.0], [-3.0, -1.2, -3.0]]\n";
    let (mut gltf, mut toml) = pair_with(&dir, "lambertian = [0.5, 0.5, 0.5]\nglossy = [0.04, 0.04, 0.04]\nglossy_model = \"ggx\"\nroughness = 1.0\nfresnel = \"schlick\"\nemission = [0.21586, 0.10793, 0.053965]", floor);
    assert!(gltf.materials.iter().any(|m| m.emission_map.is_some()));
    assert_renders_alike("emissive texture", &gltf, &toml, 0.01);
    // Without the point light the floor shows the sphere's light alone.
    gltf.lights.clear();
    toml.lights.clear();
    let settings = RenderSettings::for_scene(&toml);
    let floor_pixels = |img: &[Vec3]| img[img.len() - 3 * settings.width as usize..].iter().map(|p| p.x as f64).sum::<f64>();
    let (a, b) = (render(&gltf, "raytrace", &settings), render(&toml, "raytrace", &settings));
    assert!(floor_pixels(&b) > 0.0, "the floor is lit by the emitter");
    assert!(relative_rmse(&a, &b) < 0.01, "the sampled emitter's light: rmse/mean {}", relative_rmse(&a, &b));
}

#[test]
fn normal_texture_is_linear_data_that_bends_the_shading_normal() {
    let dir = work_dir("normal");
    let material = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}, "normalTexture": {"index": 0}}"#;
    let with = |rgb: [u8; 3]| format!(r#", "textures": [{{"source": 0}}], "images": [{{"uri": "{}"}}]"#, png_uri(rgb));
    write_sphere(&dir, r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}}"#, "");
    let (plain, _) = pair(&dir, "lambertian = [1.0, 1.0, 1.0]");
    assert!(plain.materials.iter().all(|m| m.normal_map.is_none()));
    // (128, 128, 255) read as data is (0.502, 0.502, 1): straight out, within
    // a quarter of a degree. Read as sRGB it would lean by 30 degrees.
    write_sphere(&dir, material, &with([128, 128, 255]));
    let (flat, _) = pair(&dir, "lambertian = [1.0, 1.0, 1.0]");
    assert!(flat.materials.iter().any(|m| m.normal_map.is_some()));
    // A texel leaning 35 degrees along u.
    write_sphere(&dir, material, &with([201, 128, 232]));
    let (tilted, _) = pair(&dir, "lambertian = [1.0, 1.0, 1.0]");
    let settings = RenderSettings::for_scene(&plain);
    for renderer in ["raytrace", "rasterize"] {
        let base = render(&plain, renderer, &settings);
        let e_flat = relative_rmse(&render(&flat, renderer, &settings), &base);
        let e_tilted = relative_rmse(&render(&tilted, renderer, &settings), &base);
        eprintln!("normal texture ({renderer}): flat {e_flat:.5}, tilted {e_tilted:.5}");
        assert!(e_flat < 0.01, "{renderer}: a flat normal texture changes the image by {e_flat:.5}");
        assert!(e_tilted > 0.05, "{renderer}: a tilted normal texture changes the image by only {e_tilted:.5}");
    }
}

#[test]
fn samplers_set_wrap_per_axis_and_cap_the_filter() {
    let dir = work_dir("samplers");
    let extra = format!(
        r#", "samplers": [{{"magFilter": 9728, "minFilter": 9728, "wrapS": 33648, "wrapT": 33071}}], "textures": [{{"source": 0, "sampler": 0}}], "images": [{{"uri": "{}"}}]"#,
        png_uri([255, 255, 255])
    );
    write_sphere(&dir, r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#, &extra);
    let (gltf, _) = pair(&dir, "lambertian = [1.0, 1.0, 1.0]");
    let m = gltf.materials.iter().find(|m| m.texture.is_some()).unwrap();
    assert_eq!(m.wrap, [Wrap::MirroredRepeat, Wrap::Clamp]);
    assert_eq!(m.finest_filter, TextureFilter::Nearest);
    // Linear magnification without mipmaps: bilinear at most.
    let extra = extra.replace(r#""magFilter": 9728, "minFilter": 9728"#, r#""magFilter": 9729, "minFilter": 9729"#);
    write_sphere(&dir, r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#, &extra);
    let (gltf, _) = pair(&dir, "lambertian = [1.0, 1.0, 1.0]");
    assert_eq!(gltf.materials.iter().find(|m| m.texture.is_some()).unwrap().finest_filter, TextureFilter::Bilinear);
}

/// The BoxTextured sample read here without pinhole: its triangles in
/// world space (the root node turns +y to -z) with their uvs, and its
/// texture as linear texels (row 0 at the top).
struct IndependentBox {
    triangles: Vec<([Vec3; 3], [Vec2; 3])>,
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

fn independent_box(path: &Path) -> IndependentBox {
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let uri = |v: &serde_json::Value| unbase64(v["uri"].as_str().unwrap().split_once(",").unwrap().1);
    let buffer = uri(&json["buffers"][0]);
    let f32_at = |o: usize| f32::from_le_bytes(buffer[o..o + 4].try_into().unwrap());
    // Index view at 768, positions at 288 within view 1 (stride 12), uvs in view 2 at 576 (stride 8).
    let index = |k: usize| u16::from_le_bytes(buffer[768 + 2 * k..770 + 2 * k].try_into().unwrap()) as usize;
    let position = |i: usize| {
        let o = 288 + 12 * i;
        let p = Vec3::new(f32_at(o), f32_at(o + 4), f32_at(o + 8));
        // The node's matrix: columns (1, 0, 0), (0, 0, -1), (0, 1, 0).
        Vec3::new(p.x, p.z, -p.y)
    };
    let uv = |i: usize| Vec2::new(f32_at(576 + 8 * i), f32_at(580 + 8 * i));
    let triangles = (0..12).map(|t| ([0, 1, 2].map(|c| position(index(3 * t + c))), [0, 1, 2].map(|c| uv(index(3 * t + c))))).collect();
    let png = image::load_from_memory(&uri(&json["images"][0])).unwrap().to_rgb8();
    let linear = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    };
    let texels = png.pixels().map(|p| Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))).collect();
    IndependentBox { triangles, width: png.width() as usize, height: png.height() as usize, texels }
}

#[test]
fn khronos_box_textured_puts_each_texel_where_its_uvs_say() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/BoxTextured.gltf");
    let mut scene = load_scene(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.triangle_count(), 12);
    // Unlit, with ambient 1: each pixel is its albedo, the texel itself.
    scene.lights.clear();
    scene.render.ambient = Vec3::ONE;
    let (w, h) = (120u32, 90u32);
    let settings = RenderSettings { width: w, height: h, texture_filter: TextureFilter::Nearest, ..RenderSettings::for_scene(&scene) };
    let expected = independent_box(&path);
    let view = scene.camera.view(w, h);
    for renderer in ["raytrace", "rasterize"] {
        let img = render(&scene, renderer, &settings);
        let (mut checked, mut agree) = (0, 0);
        let mut colours: Vec<[u32; 3]> = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let ray = view.eye_ray(x as f32 + 0.5, y as f32 + 0.5);
                let (o, d) = (ray.origin, ray.dir);
                // The nearest triangle (Moller-Trumbore), with barycentrics.
                let mut best: Option<(f32, f32, f32, usize)> = None;
                for (k, (v, _)) in expected.triangles.iter().enumerate() {
                    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
                    let p = d.cross(e2);
                    let det = e1.dot(p);
                    if det.abs() < 1e-9 {
                        continue;
                    }
                    let s = o - v[0];
                    let b1 = s.dot(p) / det;
                    let q = s.cross(e1);
                    let b2 = d.dot(q) / det;
                    let t = e2.dot(q) / det;
                    if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && t > 0.0 && best.is_none_or(|b| t < b.0) {
                        best = Some((t, b1, b2, k));
                    }
                }
                let Some((_, b1, b2, k)) = best else { continue };
                // Away from triangle edges and texel borders, where rounding may choose either side.
                if b1.min(b2).min(1.0 - b1 - b2) < 0.02 {
                    continue;
                }
                let uvs = expected.triangles[k].1;
                let uv = uvs[0] * (1.0 - b1 - b2) + uvs[1] * b1 + uvs[2] * b2;
                let (tx, ty) = (uv.x * expected.width as f32, uv.y * expected.height as f32);
                if (tx.fract() - 0.5).abs() > 0.35 || (ty.fract() - 0.5).abs() > 0.35 {
                    continue;
                }
                // glTF's v runs down the image: row = v * height, repeated.
                let (col, row) = ((tx.floor() as i64).rem_euclid(expected.width as i64) as usize, (ty.floor() as i64).rem_euclid(expected.height as i64) as usize);
                let texel = expected.texels[col + row * expected.width];
                let got = img[(x + y * w) as usize];
                checked += 1;
                if (got - texel).abs().max_element() < 2e-3 {
                    agree += 1;
                }
                let key = texel.to_array().map(|c| (c * 255.0) as u32);
                if !colours.contains(&key) {
                    colours.push(key);
                }
            }
        }
        eprintln!("{renderer}: {agree} of {checked} checked pixels show their texel; {} texel colours seen", colours.len());
        assert!(checked > 1500, "{renderer}: only {checked} pixels checked");
        assert!(colours.len() >= 4, "{renderer}: the checked pixels see {} texel colours; the test needs a varied texture", colours.len());
        assert!(agree as f32 >= 0.99 * checked as f32, "{renderer}: {agree} of {checked} pixels show the texel their uvs name");
    }
    // The same file, its texture read upside down, would fail: the logo is
    // not symmetric (a check of the check).
    let flipped = (0..expected.height).flat_map(|r| (0..expected.width).map(move |c| (c, r))).filter(|&(c, r)| (expected.texels[c + r * expected.width] - expected.texels[c + (expected.height - 1 - r) * expected.width]).abs().max_element() > 0.05).count();
    assert!(flipped > expected.width * expected.height / 10, "{flipped} texels differ from their mirror rows");
}

#[test]
fn the_textured_box_draws_in_every_view_the_renderers_share() {
    // The uv view shows the file's uvs (v turned up), in both families.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/BoxTextured.gltf");
    let scene = load_scene(path.to_str().unwrap()).unwrap();
    let settings = RenderSettings { width: 64, height: 48, view: View::Uv, ..RenderSettings::for_scene(&scene) };
    let a = render(&scene, "raytrace", &settings);
    let b = render(&scene, "rasterize", &settings);
    let same = a.iter().zip(&b).filter(|(x, y)| (**x - **y).abs().max_element() < 1e-3).count();
    assert!(same as f32 >= 0.99 * a.len() as f32, "{same} of {} pixels agree", a.len());
}

#[test]
fn khronos_box_vertex_colors_multiply_the_base_colour() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/BoxVertexColors.gltf");
    // The file's colours are its positions (a unit RGB cube): read here.
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let buffer = unbase64(json["buffers"][0]["uri"].as_str().unwrap().split_once(",").unwrap().1);
    let vec3_at = |o: usize| Vec3::from_array(std::array::from_fn(|k| f32::from_le_bytes(buffer[o + 4 * k..o + 4 * k + 4].try_into().unwrap())));
    assert!((0..24).all(|i| vec3_at(72 + 12 * i) == vec3_at(72 + 576 + 12 * i)), "COLOR_0 equals POSITION");
    let mut scene = load_scene(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.vertex_colours.len(), 12);
    assert!(!scene.warnings.iter().any(|w| w.contains("vertex colours")), "{:?}", scene.warnings);
    // Unlit, ambient 1: each pixel is the default grey times the colour.
    scene.lights.clear();
    scene.render.ambient = Vec3::ONE;
    let grey = scene.materials[scene.triangle(0).material as usize].lambertian;
    let (w, h) = (100u32, 80u32);
    let settings = RenderSettings { width: w, height: h, ..RenderSettings::for_scene(&scene) };
    let view = scene.camera.view(w, h);
    for renderer in ["raytrace", "rasterize"] {
        let img = render(&scene, renderer, &settings);
        let (mut checked, mut agree, mut lo, mut hi) = (0, 0, Vec3::ONE, Vec3::ZERO);
        for y in 0..h {
            for x in 0..w {
                // The ray against the box [0, 1]^3 (slabs).
                let ray = view.eye_ray(x as f32 + 0.5, y as f32 + 0.5);
                let (t0, t1) = ((Vec3::ZERO - ray.origin) / ray.dir, (Vec3::ONE - ray.origin) / ray.dir);
                let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
                if !(near < far && near > 0.0) {
                    continue;
                }
                let p = ray.origin + ray.dir * near;
                // Away from the cube's edges, where a pixel may see either face.
                let inner = p.to_array().iter().filter(|c| **c > 0.01 && **c < 0.99).count();
                if inner < 2 {
                    continue;
                }
                let expected = grey * p.clamp(Vec3::ZERO, Vec3::ONE);
                let got = img[(x + y * w) as usize];
                checked += 1;
                if (got - expected).abs().max_element() < 2e-3 {
                    agree += 1;
                }
                (lo, hi) = (lo.min(p), hi.max(p));
            }
        }
        eprintln!("{renderer}: {agree} of {checked} pixels are the grey times their vertex colour");
        // The colours seen span most of red and green (the face towards the camera is blue 1).
        assert!(checked > 1000 && (hi - lo).x > 0.8 && (hi - lo).y > 0.8, "{renderer}: {checked} pixels checked, colours from {lo} to {hi}");
        assert!(agree as f32 >= 0.99 * checked as f32, "{renderer}: {agree} of {checked} pixels");
    }
}
