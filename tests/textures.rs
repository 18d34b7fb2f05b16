//! Texture filtering measured against the truth, and the two families'
//! footprints against each other, on the built-in `textures` scene.

use pinhole::math::{Radiance, Vec3};
use pinhole::render::{render_frame, renderer_by_name, PreparedScene, RenderSettings};
use pinhole::scene::texture::TextureFilter;
use pinhole::scene::Scene;
use std::sync::atomic::AtomicBool;

const W: u32 = 160;
const H: u32 = 100;

/// The `textures` scene with only its checkerboard ground (object 1), the
/// sky black: every error measured is the ground's.
fn ground_only() -> PreparedScene {
    let mut scene: Scene = pinhole::scene::builtin::load_builtin("textures").unwrap().unwrap();
    scene.triangles.retain(|t| t.object == 0);
    scene.spheres.clear();
    scene.environment = None;
    scene.render.background = Vec3::ZERO;
    PreparedScene::new(scene)
}

fn render(prepared: &PreparedScene, renderer: &str, filter: TextureFilter, spp: u32) -> Vec<Radiance> {
    let mut s = RenderSettings::for_scene(&prepared.scene);
    (s.width, s.height, s.spp, s.texture_filter) = (W, H, spp, filter);
    render_frame(renderer_by_name(renderer).unwrap().as_ref(), prepared, &s, &AtomicBool::new(false), None).unwrap().pixels
}

fn rmse(a: &[Radiance], b: &[Radiance]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(p, q)| (*p - *q).length_squared() as f64 / 3.0).sum();
    (sum / a.len() as f64).sqrt()
}

/// At 1 spp the error against a 256-spp `nearest` image (the pixel's
/// texture averaged by brute force) orders nearest > bilinear > trilinear,
/// and trilinear at 1 spp beats nearest at 4 spp: the pyramid averages the
/// texels a pixel covers once, ahead of time, which point samples only
/// approach with many samples.
#[test]
fn filtering_error_on_the_checkerboard() {
    let prepared = ground_only();
    let truth = render(&prepared, "raytrace", TextureFilter::Nearest, 256);
    let mut table = String::from("filter     spp 1     spp 4     spp 16\n");
    let mut err = std::collections::HashMap::new();
    for filter in TextureFilter::ALL {
        table += &format!("{:<10}", filter.name());
        for spp in [1, 4, 16] {
            let e = rmse(&render(&prepared, "raytrace", filter, spp), &truth);
            err.insert((filter, spp), e);
            table += &format!(" {e:.5}");
        }
        table += "\n";
    }
    println!("{table}");
    let e = |f, spp| err[&(f, spp)];
    use TextureFilter::*;
    assert!(e(Nearest, 1) > e(Bilinear, 1), "{table}");
    assert!(e(Bilinear, 1) > e(Trilinear, 1), "{table}");
    assert!(e(Trilinear, 1) < e(Nearest, 4), "{table}");
    // Trilinear reads a receding footprint at the level of its length and
    // blurs across its width; taps along the length read a finer level.
    for spp in [1, 4] {
        assert!(e(Anisotropic8, spp) < e(Trilinear, spp), "{table}");
        assert!(e(Anisotropic16, spp) <= e(Anisotropic2, spp), "{table}");
    }
}

/// The anisotropic read in both families and OpenGL: the rasterizer's
/// screen derivatives and the ray caster's differentials give the same
/// taps, and GL's shader reads what the CPU reads.
#[test]
fn anisotropic_filtering_agrees_across_the_families() {
    let prepared = ground_only();
    let a = render(&prepared, "raytrace", TextureFilter::Anisotropic8, 1);
    let b = render(&prepared, "rasterize", TextureFilter::Anisotropic8, 1);
    let trilinear = render(&prepared, "raytrace", TextureFilter::Trilinear, 1);
    let close = |x: &[Radiance], y: &[Radiance]| x.iter().zip(y).filter(|(p, q)| (**p - **q).abs().max_element() <= 1e-3 * (1.0 + q.max_element())).count() as f64 / x.len() as f64;
    assert!(close(&a, &b) >= 0.99, "{}", close(&a, &b));
    assert!(close(&a, &trilinear) < 0.9, "anisotropic reads as trilinear: {}", close(&a, &trilinear));
}

/// The rasterizer (screen-space derivatives) and the ray caster (ray
/// differentials) pick the same mip levels: with trilinear filtering on the
/// whole scene (mirror, globe, normal map, environment) at least 99.5% of
/// pixels agree within 1e-3 relative, and the rest within 1e-2.
#[test]
fn rasterize_and_raytrace_agree_on_textures() {
    let scene: Scene = pinhole::scene::builtin::load_builtin("textures").unwrap().unwrap();
    let prepared = PreparedScene::new(scene);
    let a = render(&prepared, "raytrace", TextureFilter::Trilinear, 1);
    let b = render(&prepared, "rasterize", TextureFilter::Trilinear, 1);
    let off = |tol: f32| {
        a.iter()
            .zip(&b)
            .filter(|(p, q)| {
                let (d, m) = ((**p - **q).abs(), p.abs().max(q.abs()));
                (0..3).any(|k| d[k] > tol * m[k] + 1e-6)
            })
            .count()
    };
    let n = a.len();
    let (loose, strict) = (off(1e-2), off(1e-3));
    println!("{strict} of {n} pixels differ by more than 1e-3, {loose} by more than 1e-2");
    assert!(strict as f64 <= 0.005 * n as f64, "{strict} of {n} pixels differ by more than 1e-3");
    // Edge pixels: coverage differs legitimately along silhouettes.
    assert!(loose as f64 <= 0.005 * n as f64, "{loose} of {n} pixels differ by more than 1e-2");
}

/// A normal map whose every texel points straight out (0.5, 0.5, 1) leaves
/// every pixel exactly as without one, in both families.
#[test]
fn a_flat_normal_map_changes_nothing_bit_for_bit() {
    use pinhole::scene::Texture;
    use std::sync::Arc;
    let plain: Scene = pinhole::scene::builtin::load_builtin("textures").unwrap().unwrap();
    let mut flat = plain.clone();
    let bumpy = flat.materials.iter().position(|m| m.normal_map.is_some()).unwrap();
    flat.materials[bumpy].normal_map = Some(Arc::new(Texture::new(2, 2, vec![Vec3::new(0.5, 0.5, 1.0); 4])));
    let mut none = plain.clone();
    none.materials[bumpy].normal_map = None;
    let (flat, none) = (PreparedScene::new(flat), PreparedScene::new(none));
    for renderer in ["raytrace", "rasterize"] {
        let a = render(&flat, renderer, TextureFilter::Trilinear, 1);
        let b = render(&none, renderer, TextureFilter::Trilinear, 1);
        let bits = |p: &[Radiance]| p.iter().map(|c| c.to_array().map(f32::to_bits)).collect::<Vec<_>>();
        assert!(bits(&a) == bits(&b), "{renderer}: a flat normal map changed the image");
    }
    // The real map does change it.
    let bumped = PreparedScene::new(plain);
    assert!(render(&bumped, "raytrace", TextureFilter::Trilinear, 1) != render(&none, "raytrace", TextureFilter::Trilinear, 1));
}

/// `--view mip`: below level 2 on the ground under the camera (blue to
/// cyan: red 0.1, blue 0.9), far coarser towards the horizon, dark grey on the untextured mirror; the
/// same in both families.
#[test]
fn the_mip_view_shows_the_level_read() {
    use pinhole::render::inspect::debug::{mip_color, View, MIP_UNTEXTURED};
    let scene: Scene = pinhole::scene::builtin::load_builtin("textures").unwrap().unwrap();
    let prepared = PreparedScene::new(scene);
    let frame = |renderer: &str| {
        let mut s = RenderSettings::for_scene(&prepared.scene);
        (s.width, s.height, s.view) = (W, H, View::Mip);
        render_frame(renderer_by_name(renderer).unwrap().as_ref(), &prepared, &s, &AtomicBool::new(false), None).unwrap().pixels
    };
    let a = frame("raytrace");
    let at = |x: u32, y: u32| a[(x + y * W) as usize];
    let near = at(W / 2, H - 1);
    assert!((near.x - 0.1).abs() < 1e-5 && (near.z - 0.9).abs() < 1e-5, "{near}");
    // Just below the horizon (row 41 of 100) the ground is read far coarser.
    let far = at(5, 41);
    assert!((far - mip_color(2.0)).length() > 0.3 && (far - mip_color(0.0)).length() > 0.3, "{far}");
    // The mirror sphere (right of centre) has no texture.
    assert_eq!(at(W * 69 / 100, H / 2), MIP_UNTEXTURED);
    let b = frame("rasterize");
    let same = a.iter().zip(&b).filter(|(p, q)| (**p - **q).abs().max_element() < 1e-3).count();
    assert!(same as f64 >= 0.995 * a.len() as f64, "{same} of {} pixels agree", a.len());
}
