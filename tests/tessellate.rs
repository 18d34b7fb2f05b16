//! `tessellate = N` on a sphere: the analytic sphere against meshes of
//! about N triangles. Their silhouettes and shading approach the exact
//! sphere's as N grows, in both families; bad counts are refused.

mod common;
use common::*;
use pinhole::math::Radiance;
use pinhole::render::{PreparedScene, RenderSettings};

fn scene(tessellate: Option<u32>) -> String {
    let key = tessellate.map_or(String::new(), |n| format!("tessellate = {n}\n"));
    format!(
        r#"
[camera]
eye = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
fov_y_deg = 40.0

[render]
width = 120
height = 90

[[light]]
type = "point"
position = [3.0, 4.0, 5.0]
power = [400.0, 400.0, 400.0]

[materials.clay]
lambertian = [0.8, 0.6, 0.4]

[[object]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "clay"
{key}"#
    )
}

fn wrong_pixels(a: &[Radiance], b: &[Radiance]) -> usize {
    a.iter().zip(b).filter(|(p, q)| (**p - **q).abs().max_element() > 0.02 * (0.05 + q.max_element())).count()
}

#[test]
fn tessellations_approach_the_analytic_sphere() {
    let exact = scene_from(&scene(None));
    let s = RenderSettings::for_scene(&exact);
    let truth = render("raytrace:brute", &PreparedScene::new(exact), &s);
    for renderer in ["raytrace", "rasterize"] {
        let mut wrong = Vec::new();
        for n in [20, 200, 2000, 20000] {
            let mesh = scene_from(&scene(Some(n)));
            assert!(mesh.spheres.is_empty() && mesh.triangles.len() as u32 >= n && (mesh.triangles.len() as u32) < 2 * n + 50);
            wrong.push(wrong_pixels(&render(renderer, &PreparedScene::new(mesh), &s), &truth));
        }
        println!("{renderer}: wrong pixels at 20, 200, 2000, 20000 triangles: {wrong:?}");
        assert!(wrong.windows(2).all(|w| w[1] < w[0]), "{renderer}: {wrong:?}");
        assert!(wrong[0] > 500 && wrong[3] < wrong[0] / 10, "{renderer}: {wrong:?}");
    }
}

#[test]
fn bad_triangle_counts_and_other_objects_are_refused() {
    let parse = |text: &str| pinhole::scene::file::parse_scene(text, "t.toml", std::path::Path::new("."), "t").map(|_| ()).unwrap_err();
    let too_many = parse(&scene(Some(2_000_000)));
    assert!(too_many.contains("tessellate must be a triangle count from 8 to 1000000, found 2000000"), "{too_many}");
    let zero = parse(&scene(Some(0)).replace("tessellate = 0", "tessellate = -3"));
    assert!(zero.contains("found -3"), "{zero}");
    let quad = parse(&scene(None).replace(
        "type = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        "type = \"quad\"\nvertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]\ntessellate = 100",
    ));
    assert!(quad.contains("`tessellate` is not a key of a quad object"), "{quad}");
}
