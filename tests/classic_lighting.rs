//! Classic lighting (`[render] lighting = "classic"`) on the built-in
//! `cgfs-spheres` against Computer Graphics from Scratch's tracer, written
//! again here in f64 in the book's own left-handed frame with the book's
//! values typed in (not read from the scene file): intensities without
//! falloff, an ambient light, raw (R.V)^s specular, shadows, and the
//! `reflective` blend (1 - r) local + r reflected down to the recursion
//! limit. Both families (the ray caster and the rasterizer) must give the
//! book's values; OpenGL refuses the scene in one sentence.

mod common;
use common::*;
use pinhole::math::Radiance;
use pinhole::render::{admit, renderer_by_name, PreparedScene, RenderSettings, ShadowMode};

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: V, k: f64) -> V {
    [a[0] * k, a[1] * k, a[2] * k]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn len(a: V) -> f64 {
    dot(a, a).sqrt()
}

struct BookSphere {
    center: V,
    radius: f64,
    color: V,
    specular: f64,
    reflective: f64,
}

/// Chapter 4's spheres (colours over 255).
const SPHERES: [BookSphere; 4] = [
    BookSphere { center: [0.0, -1.0, 3.0], radius: 1.0, color: [1.0, 0.0, 0.0], specular: 500.0, reflective: 0.2 },
    BookSphere { center: [-2.0, 1.0, 3.0], radius: 1.0, color: [0.0, 0.0, 1.0], specular: 500.0, reflective: 0.3 },
    BookSphere { center: [2.0, 1.0, 3.0], radius: 1.0, color: [0.0, 1.0, 0.0], specular: 10.0, reflective: 0.4 },
    BookSphere { center: [0.0, -5001.0, 0.0], radius: 5000.0, color: [1.0, 1.0, 0.0], specular: 1000.0, reflective: 0.5 },
];
const AMBIENT: f64 = 0.2;
const POINT: (f64, V) = (0.6, [2.0, 1.0, 0.0]);
const DIRECTIONAL: (f64, V) = (0.2, [1.0, 4.0, 4.0]);

/// The nearest sphere along O + t D with t in (t_min, t_max).
fn closest(o: V, d: V, t_min: f64, t_max: f64) -> Option<(usize, f64)> {
    let mut best: Option<(usize, f64)> = None;
    for (i, s) in SPHERES.iter().enumerate() {
        let co = sub(o, s.center);
        let (a, b, c) = (dot(d, d), 2.0 * dot(co, d), dot(co, co) - s.radius * s.radius);
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            continue;
        }
        for t in [(-b + disc.sqrt()) / (2.0 * a), (-b - disc.sqrt()) / (2.0 * a)] {
            if t > t_min && t < t_max && best.is_none_or(|(_, bt)| t < bt) {
                best = Some((i, t));
            }
        }
    }
    best
}

/// The book's ComputeLighting with shadows: a number that multiplies the colour.
fn lighting(p: V, n: V, v: V, s: f64) -> f64 {
    let mut i = AMBIENT;
    for (intensity, l, t_max) in [(POINT.0, sub(POINT.1, p), 1.0), (DIRECTIONAL.0, DIRECTIONAL.1, f64::INFINITY)] {
        if closest(p, l, 0.001, t_max).is_some() {
            continue;
        }
        let n_dot_l = dot(n, l);
        if n_dot_l > 0.0 {
            i += intensity * n_dot_l / (len(n) * len(l));
        }
        let r = sub(mul(n, 2.0 * dot(n, l)), l);
        let r_dot_v = dot(r, v);
        if r_dot_v > 0.0 {
            i += intensity * (r_dot_v / (len(r) * len(v))).powf(s);
        }
    }
    i
}

/// The book's TraceRay with reflections; misses are black.
fn trace(o: V, d: V, t_min: f64, t_max: f64, depth: u32) -> V {
    let Some((k, t)) = closest(o, d, t_min, t_max) else { return [0.0; 3] };
    let s = &SPHERES[k];
    let p = add(o, mul(d, t));
    let n = sub(p, s.center);
    let n = mul(n, 1.0 / len(n));
    let local = mul(s.color, lighting(p, n, mul(d, -1.0), s.specular));
    if depth == 0 || s.reflective <= 0.0 {
        return local;
    }
    let back = mul(d, -1.0);
    let r = sub(mul(n, 2.0 * dot(n, back)), back);
    add(mul(local, 1.0 - s.reflective), mul(trace(p, r, 0.001, f64::INFINITY, depth - 1), s.reflective))
}

/// The viewport direction of pixel (x, y)'s centre on a `size` x `size`
/// canvas, and which sphere the eye sees there.
fn book_ray(x: u32, y: u32, size: u32) -> V {
    let f = size as f64;
    [((x as f64 + 0.5) / f - 0.5), (0.5 - (y as f64 + 0.5) / f), 1.0]
}

const SIZE: u32 = 64;

fn settings(max_depth: u32) -> RenderSettings {
    let scene = builtin("cgfs-spheres");
    RenderSettings { width: SIZE, height: SIZE, spp: 1, shadows: ShadowMode::Ray, max_depth, ..RenderSettings::for_scene(&scene) }
}

/// Pixels well inside each sphere's image (their 3x3 neighbours see the
/// same sphere), and each sphere's brightest such pixel (a highlight).
fn chosen_pixels() -> Vec<(u32, u32)> {
    let sees = |x: u32, y: u32| closest([0.0; 3], book_ray(x, y, SIZE), 1.0, f64::INFINITY).map(|(k, _)| k);
    let mut out = Vec::new();
    for k in 0..SPHERES.len() {
        let inside: Vec<(u32, u32)> = (1..SIZE - 1)
            .flat_map(|y| (1..SIZE - 1).map(move |x| (x, y)))
            .filter(|&(x, y)| (0..3).all(|j| (0..3).all(|i| sees(x + i - 1, y + j - 1) == Some(k))))
            .collect();
        assert!(!inside.is_empty(), "sphere {k} is not in view");
        out.push(inside[inside.len() / 2]);
        let bright = inside.iter().copied().max_by(|a, b| {
            let v = |p: (u32, u32)| trace([0.0; 3], book_ray(p.0, p.1, SIZE), 1.0, f64::INFINITY, 3).iter().sum::<f64>();
            v(*a).total_cmp(&v(*b))
        });
        out.extend(bright);
    }
    out
}

fn differs(got: Radiance, want: V) -> f64 {
    (0..3).map(|c| (got[c] as f64 - want[c]).abs()).fold(0.0, f64::max)
}

#[test]
fn both_families_give_the_books_values() {
    let prepared = PreparedScene::new(builtin("cgfs-spheres"));
    for depth in [0u32, 1, 3] {
        let s = settings(depth);
        let book: Vec<V> = (0..SIZE * SIZE).map(|i| trace([0.0; 3], book_ray(i % SIZE, i / SIZE, SIZE), 1.0, f64::INFINITY, depth)).collect();
        for name in ["raytrace:bvh", "rasterize"] {
            let image = render(name, &prepared, &s);
            for (x, y) in chosen_pixels() {
                let (got, want) = (image[(x + y * SIZE) as usize], book[(x + y * SIZE) as usize]);
                eprintln!("{name} depth {depth} pixel ({x}, {y}): {got}, the book {want:.5?}");
                assert!(differs(got, want) < 1e-3, "{name} depth {depth} pixel ({x}, {y}): {got}, the book {want:?}");
            }
            // Everywhere but at silhouettes and shadow edges (where the
            // book's 0.001 and our shadow bump, and f32 against f64, may
            // pick different sides), the whole image.
            let close = image.iter().zip(&book).filter(|(g, w)| differs(**g, **w) < 2e-3).count();
            let share = close as f64 / image.len() as f64;
            eprintln!("{name} depth {depth}: {:.2}% of pixels within 2e-3 of the book", share * 100.0);
            assert!(share >= 0.98, "{name} depth {depth}: only {:.2}% of pixels within 2e-3 of the book", share * 100.0);
        }
    }
}

#[test]
fn reflections_and_the_recursion_limit_matter() {
    // The values the test checks are not those of a scene without the
    // blend: the book's depth 0 and depth 3 differ at the chosen pixels,
    // and so do the renders.
    let prepared = PreparedScene::new(builtin("cgfs-spheres"));
    let (flat, deep) = (render("raytrace:bvh", &prepared, &settings(0)), render("raytrace:bvh", &prepared, &settings(3)));
    let moved = chosen_pixels().into_iter().filter(|&(x, y)| differs(flat[(x + y * SIZE) as usize], {
        let d = deep[(x + y * SIZE) as usize];
        [d.x as f64, d.y as f64, d.z as f64]
    }) > 1e-2).count();
    assert!(moved >= 4, "the recursion limit changes only {moved} of the chosen pixels");
    // Physical lighting of the same scene is far from the book's values:
    // the check above could fail.
    let mut physical = builtin("cgfs-spheres");
    physical.render.lighting = pinhole::scene::Lighting::Physical;
    let image = render("raytrace:bvh", &PreparedScene::new(physical), &settings(3));
    let wrong = chosen_pixels().into_iter().filter(|&(x, y)| {
        differs(image[(x + y * SIZE) as usize], trace([0.0; 3], book_ray(x, y, SIZE), 1.0, f64::INFINITY, 3)) > 1e-2
    });
    assert!(wrong.count() >= 4, "physical lighting gives the book's values too");
}

#[test]
fn opengl_refuses_classic_lighting_in_one_sentence() {
    let scene = builtin("cgfs-spheres");
    let s = RenderSettings::for_scene(&scene);
    let e = admit::admit(renderer_by_name("opengl").unwrap().as_ref(), &scene, &s).unwrap_err();
    assert!(e.contains("lighting = \"classic\""), "{e}");
    assert_eq!(e.matches(". ").count(), 0, "one sentence: {e}");
}

#[test]
fn what_classic_lighting_cannot_draw_is_refused() {
    let scene = builtin("cgfs-spheres");
    let bvh = renderer_by_name("raytrace:bvh").unwrap();
    let mut s = RenderSettings::for_scene(&scene);
    s.gi.mode = pinhole::render::transport::gi::GiMode::Path;
    let e = admit::admit(bvh.as_ref(), &scene, &s).unwrap_err();
    assert!(e.contains("--gi path"), "{e}");
    let s = RenderSettings::for_scene(&scene);
    let mut ggx = scene.clone();
    ggx.materials[0].glossy_model = pinhole::scene::material::GlossyModel::Ggx;
    let e = admit::admit(bvh.as_ref(), &ggx, &s).unwrap_err();
    assert!(e.contains("glossy_model \"ggx\""), "{e}");
    let mut bright = scene.clone();
    bright.materials[0].mirror = pinhole::math::Vec3::splat(1.5);
    assert!(admit::admit(bvh.as_ref(), &bright, &s).unwrap_err().contains("reflective"));
    assert!(admit::admit(bvh.as_ref(), &scene, &s).is_ok());
}

#[test]
fn an_unknown_lighting_model_is_refused_naming_the_key() {
    let e = pinhole::scene::file::parse_scene("[render]\nlighting = \"gouraud\"\n", "x.toml", std::path::Path::new("."), "x").unwrap_err();
    assert!(e.contains("x.toml") && e.contains("render.lighting"), "{e}");
}
