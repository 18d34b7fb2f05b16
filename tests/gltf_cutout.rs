//! glTF `alphaMode` MASK: a quad whose base-colour texture is opaque on its
//! left half and transparent on its right half stands in front of a green
//! wall. Every CPU renderer shows the quad's red where its alpha reaches
//! the cutoff and the wall through the cut-away half (also when the quad
//! is a copy in the instance layer); shadow rays pass
//! through the cut-away half only; OPAQUE and BLEND draw the whole quad;
//! the OpenGL renderer refuses the cutout in one sentence.

mod common;

use glam::Vec3;
use pinhole::render::accel::brute::BruteQuery;
use pinhole::render::accel::bvh::BvhQuery;
use pinhole::render::inspect::pixel_record::NoRecord;
use pinhole::render::{admit, PreparedScene, RayCounts, RenderSettings, SceneQuery};
use pinhole::scene::load::load_scene;
use pinhole::scene::Scene;
use pinhole::math::Ray;
use std::path::PathBuf;

fn work_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-gltf-cutout-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2 x 1 RGBA PNG, white: the left texel opaque, the right one transparent.
fn half_transparent_png() -> String {
    let img = image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba([255, 255, 255, if x == 0 { 255 } else { 0 }]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    format!("data:image/png;base64,{}", common::base64(bytes.get_ref()))
}

/// The front quad (x in [-1, 1], y in [-0.5, 0.5] at z = 0, u = 0 on its
/// left edge) with material 0, and a wall (x in [-3, 3], y in [-2, 2] at
/// z = -1) with material 1, seen by a camera at z = 3 looking down -z.
/// `alpha_mode` is the front material's alphaMode (it is two-sided, as
/// cut-out leaves are, so that shadow rays from the wall meet it).
fn write_scene(dir: &std::path::Path, alpha_mode: &str) -> PathBuf {
    write_scene_with(dir, alpha_mode, false)
}

/// `write_scene`; with `shared`, a second node uses the quad's mesh (out
/// of sight, far above), so that the quad is a copy in the instance layer.
fn write_scene_with(dir: &std::path::Path, alpha_mode: &str, shared: bool) -> PathBuf {
    let positions: [[f32; 3]; 8] = [
        [-1.0, -0.5, 0.0], [1.0, -0.5, 0.0], [1.0, 0.5, 0.0], [-1.0, 0.5, 0.0],
        [-3.0, -2.0, -1.0], [3.0, -2.0, -1.0], [3.0, 2.0, -1.0], [-3.0, 2.0, -1.0],
    ];
    let uvs: [[f32; 2]; 8] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    let indices: [u16; 12] = [0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 3];
    let mut bin = Vec::new();
    positions.iter().flatten().for_each(|f| bin.extend(f.to_le_bytes()));
    uvs.iter().flatten().for_each(|f| bin.extend(f.to_le_bytes()));
    indices.iter().for_each(|i| bin.extend(i.to_le_bytes()));
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2{more_nodes}]}}],
  "nodes": [{{"mesh": 0}}, {{"mesh": 1}}, {{"camera": 0, "translation": [0, 0, 3]}}{more}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1, "zfar": 100, "aspectRatio": 2.0}}}}],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 2}}, "indices": 4, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 1, "TEXCOORD_0": 3}}, "indices": 5, "material": 1}}]}}
  ],
  "materials": [
    {{"alphaMode": "{alpha_mode}", "alphaCutoff": 0.5, "doubleSided": true, "pbrMetallicRoughness": {{"baseColorFactor": [1, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1, "baseColorTexture": {{"index": 0}}}}}},
    {{"pbrMetallicRoughness": {{"baseColorFactor": [0, 1, 0, 1], "metallicFactor": 0, "roughnessFactor": 1}}}}
  ],
  "textures": [{{"source": 0, "sampler": 0}}],
  "samplers": [{{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}}],
  "images": [{{"uri": "{png}"}}],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 96}}, {{"buffer": 0, "byteOffset": 96, "byteLength": 64}}, {{"buffer": 0, "byteOffset": 160, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -0.5, 0], "max": [1, 0.5, 0]}},
    {{"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-3, -2, -1], "max": [3, 2, -1]}},
    {{"bufferView": 1, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 1, "byteOffset": 32, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "byteOffset": 0, "componentType": 5123, "count": 6, "type": "SCALAR"}},
    {{"bufferView": 2, "byteOffset": 12, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        png = half_transparent_png(),
        more_nodes = if shared { ", 3" } else { "" },
        more = if shared { r#", {"mesh": 0, "translation": [0, 100, 0]}"# } else { "" },
        len = bin.len(),
        data = common::base64(&bin)
    );
    let path = dir.join(format!("cutout_{}{}.gltf", alpha_mode.to_lowercase(), if shared { "_shared" } else { "" }));
    std::fs::write(&path, json).unwrap();
    path
}

/// The scene lit by an ambient term alone: each pixel is the albedo seen.
fn unlit(path: &std::path::Path) -> Scene {
    let mut scene = load_scene(path.to_str().unwrap()).unwrap();
    scene.lights.clear();
    scene.render.ambient = Vec3::ONE;
    scene
}

const W: u32 = 80;
const H: u32 = 40;

/// Pixels over the quad's opaque left half and its cut-away right half
/// (the quad spans x in [-1, 1]; the image is 2.54 units wide on each side
/// of the centre at the quad's depth).
const LEFT: (u32, u32) = (32, 20);
const RIGHT: (u32, u32) = (48, 20);

fn render(scene: &Scene, renderer: &str) -> Vec<Vec3> {
    let settings = RenderSettings { width: W, height: H, ..RenderSettings::for_scene(scene) };
    common::render(renderer, &PreparedScene::new(scene.clone()), &settings)
}

fn at(img: &[Vec3], (x, y): (u32, u32)) -> Vec3 {
    img[(x + y * W) as usize]
}

fn is_red(c: Vec3) -> bool {
    c.x > 0.5 && c.y < 0.05
}

fn is_green(c: Vec3) -> bool {
    c.y > 0.5 && c.x < 0.05
}

const CPU_RENDERERS: [&str; 10] = [
    "raytrace:brute",
    "raytrace:bvh",
    "rasterize:naive",
    "rasterize:bbox",
    "rasterize:barycentric",
    "rasterize:incremental",
    "rasterize:scanline",
    "rasterize:fixed",
    "rasterize:tiled",
    "rasterize:painter",
];

#[test]
fn a_masked_texel_shows_what_is_behind_it_in_every_cpu_renderer() {
    let dir = work_dir("mask");
    let scene = unlit(&write_scene(&dir, "MASK"));
    assert!(!scene.warnings.iter().any(|w| w.contains("MASK")), "{:?}", scene.warnings);
    for renderer in CPU_RENDERERS {
        let img = render(&scene, renderer);
        let (left, right) = (at(&img, LEFT), at(&img, RIGHT));
        assert!(is_red(left), "{renderer}: the opaque half shows {left}, not the quad's red");
        assert!(is_green(right), "{renderer}: the cut-away half shows {right}, not the wall's green behind it");
        // The whole cut-away half: no pixel there keeps the quad's red.
        let red_right = (RIGHT.0 - 6..RIGHT.0 + 6).filter(|&x| is_red(at(&img, (x, RIGHT.1)))).count();
        assert_eq!(red_right, 0, "{renderer}: {red_right} pixels of the cut-away half are red");
    }
}

#[test]
fn a_masked_copy_in_the_instance_layer_is_cut_out_too() {
    let dir = work_dir("mask-shared");
    let scene = unlit(&write_scene_with(&dir, "MASK", true));
    assert!(scene.layer.is_some(), "the quad's mesh is shared, so held in the instance layer");
    for renderer in ["raytrace:bvh", "rasterize:fixed", "rasterize:naive"] {
        let img = render(&scene, renderer);
        let (left, right) = (at(&img, LEFT), at(&img, RIGHT));
        assert!(is_red(left), "{renderer}: the opaque half shows {left}, not the quad's red");
        assert!(is_green(right), "{renderer}: the cut-away half shows {right}, not the wall's green behind it");
    }
}

#[test]
fn opaque_and_blend_draw_the_whole_quad_and_blend_says_so() {
    let dir = work_dir("opaque");
    for mode in ["OPAQUE", "BLEND"] {
        let scene = unlit(&write_scene(&dir, mode));
        let said = scene.warnings.iter().any(|w| w.contains("alphaMode BLEND (drawn opaque)"));
        assert_eq!(said, mode == "BLEND", "{mode}: {:?}", scene.warnings);
        for renderer in ["raytrace:bvh", "rasterize"] {
            let img = render(&scene, renderer);
            assert!(is_red(at(&img, RIGHT)), "{mode} ({renderer}): the right half shows {}, not the quad's red", at(&img, RIGHT));
        }
    }
}

#[test]
fn shadow_rays_pass_through_the_cut_away_half_only() {
    let dir = work_dir("shadow");
    let prepared = PreparedScene::new(load_scene(write_scene(&dir, "MASK").to_str().unwrap()).unwrap());
    let bvh = BvhQuery::new(&prepared);
    let brute = BruteQuery(&prepared);
    // From the wall towards a light at z = 2, through each half of the quad.
    for (x, blocked) in [(-0.5f32, true), (0.5, false)] {
        let ray = Ray::new(Vec3::new(x, 0.0, -0.999), Vec3::Z);
        let (mut a, mut b) = (RayCounts::default(), RayCounts::default());
        let found_bvh = bvh.occluder(&ray, 3.0, &mut a, &mut NoRecord);
        let found_brute = brute.occluder(&ray, 3.0, &mut b, &mut NoRecord);
        assert_eq!(found_bvh.is_some(), blocked, "bvh, x = {x}: {found_bvh:?}");
        assert_eq!(found_brute.is_some(), blocked, "brute, x = {x}: {found_brute:?}");
        // The closest hit from the camera's side sees the quad or the wall.
        let eye = Ray::new(Vec3::new(x, 0.0, 3.0), -Vec3::Z);
        let hit = bvh.closest(&eye, 100.0, false, &mut a, &mut NoRecord).unwrap();
        let expected_t = if blocked { 3.0 } else { 4.0 };
        assert!((hit.t - expected_t).abs() < 1e-3, "x = {x}: the eye ray stops at t = {}", hit.t);
    }
}

#[test]
fn opengl_refuses_a_cutout_in_one_sentence() {
    let dir = work_dir("opengl");
    let scene = unlit(&write_scene(&dir, "MASK"));
    let gl = pinhole::render::renderer_by_name("opengl").unwrap();
    let settings = RenderSettings { width: W, height: H, ..RenderSettings::for_scene(&scene) };
    let refusal = admit::admit(gl.as_ref(), &scene, &settings).unwrap_err();
    assert!(refusal.contains("alphaMode MASK"), "{refusal}");
}
