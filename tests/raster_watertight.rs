//! Watertightness: on random meshes with shared edges and vertices (jittered
//! grids, fans around one vertex, thin slivers, vertices exactly on pixel
//! centres), the fixed-point rasterizers cover every sample inside the mesh
//! exactly once: no cracks, no double hits. The float variants are measured
//! and reported, not required to be watertight.

use pinhole::math::Vec2;
use pinhole::render::raster::{coverage_counts, Method};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;
use std::collections::HashMap;

/// Wider and taller than one 32-pixel tile, not a multiple of it.
const W: u32 = 100;
const H: u32 = 70;

#[derive(Clone, Debug)]
struct Mesh {
    verts: Vec<Vec2>,
    tris: Vec<[usize; 3]>,
}

impl Mesh {
    fn triangles(&self) -> Vec<[Vec2; 3]> {
        self.tris.iter().map(|t| t.map(|i| self.verts[i])).collect()
    }
}

fn signed_area(p: [Vec2; 3]) -> f32 {
    (p[1] - p[0]).perp_dot(p[2] - p[0])
}

/// Triangles listed with one orientation must all keep it (a flipped triangle
/// would overlap its neighbours): `None` otherwise.
fn valid(verts: Vec<Vec2>, tris: Vec<[usize; 3]>, flips: &[bool]) -> Option<Mesh> {
    let areas: Vec<f32> = tris.iter().map(|t| signed_area(t.map(|i| verts[i]))).collect();
    let sign = areas[0].signum();
    if areas.iter().any(|a| a.signum() != sign || a.abs() < 1e-4) {
        return None;
    }
    let tris = tris.iter().zip(flips.iter().cycle()).map(|(t, &f)| if f { [t[0], t[2], t[1]] } else { *t }).collect();
    Some(Mesh { verts, tris })
}

fn centre(v: Vec2) -> Vec2 {
    v.floor() + Vec2::splat(0.5)
}

/// A grid of nx x ny jittered cells, each split along a random diagonal. Tiny
/// cell sizes make slivers; `on_centres` puts every vertex on a pixel centre.
fn grid() -> impl Strategy<Value = Option<Mesh>> {
    (
        (1usize..9, 1usize..9),
        (0.05f32..14.0, 0.05f32..14.0),
        (-10.0f32..60.0, -10.0f32..40.0),
        prop::collection::vec((-0.2f32..0.2, -0.2f32..0.2), 100),
        prop::collection::vec(any::<bool>(), 64),
        prop::collection::vec(any::<bool>(), 128),
        any::<bool>(),
    )
        .prop_map(|((nx, ny), (cw, ch), (ox, oy), jitter, diag, flips, on_centres)| {
            let (cw, ch) = if on_centres { (cw.round().max(4.0), ch.round().max(4.0)) } else { (cw, ch) };
            let mut verts = Vec::new();
            for j in 0..=ny {
                for i in 0..=nx {
                    let (jx, jy) = jitter[i + j * 10];
                    let v = Vec2::new(ox + (i as f32 + jx) * cw, oy + (j as f32 + jy) * ch);
                    verts.push(if on_centres { centre(v) } else { v });
                }
            }
            let id = |i: usize, j: usize| i + j * (nx + 1);
            let mut tris = Vec::new();
            for j in 0..ny {
                for i in 0..nx {
                    let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                    if diag[i + j * 8] {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    } else {
                        tris.push([a, b, d]);
                        tris.push([b, c, d]);
                    }
                }
            }
            valid(verts, tris, &flips)
        })
}

/// A fan of triangles around one shared vertex (a star-shaped polygon).
fn fan() -> impl Strategy<Value = Option<Mesh>> {
    (
        (0.0f32..100.0, 0.0f32..70.0),
        3usize..48,
        prop::collection::vec(0.05f32..1.0, 48),
        prop::collection::vec(0.3f32..40.0, 48),
        prop::collection::vec(any::<bool>(), 48),
        any::<bool>(),
    )
        .prop_map(|((cx, cy), k, steps, radii, flips, on_centres)| {
            let total: f32 = steps[..k].iter().sum();
            let mut angle = 0.0f32;
            let c = Vec2::new(cx, cy);
            let mut verts = vec![if on_centres { centre(c) } else { c }];
            for i in 0..k {
                let step = steps[i] / total * std::f32::consts::TAU;
                if step >= std::f32::consts::PI * 0.95 {
                    return None;
                }
                let v = c + Vec2::new(angle.cos(), angle.sin()) * radii[i];
                verts.push(if on_centres { centre(v) } else { v });
                angle += step;
            }
            let tris = (0..k).map(|i| [0, 1 + i, 1 + (i + 1) % k]).collect();
            valid(verts, tris, &flips)
        })
}

fn mesh() -> impl Strategy<Value = Mesh> {
    prop_oneof![grid(), fan()].prop_filter_map("a triangle flipped", |m| m)
}

/// Distance from `p` to the segment `a-b`.
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let s = ((p - a).dot(ab) / ab.length_squared().max(1e-30)).clamp(0.0, 1.0);
    (p - (a + ab * s)).length()
}

/// Per pixel: Some(true) when its centre is inside the mesh (more than 0.01 px
/// from its outline, beyond what snapping to 1/256 px can move), Some(false)
/// when clearly outside, None when on the outline.
fn inside_map(m: &Mesh) -> Vec<Option<bool>> {
    let mut uses: HashMap<(usize, usize), u32> = HashMap::new();
    for t in &m.tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let outline: Vec<(Vec2, Vec2)> = uses.iter().filter(|(_, n)| **n == 1).map(|((a, b), _)| (m.verts[*a], m.verts[*b])).collect();
    let tris = m.triangles();
    let mut map = Vec::with_capacity((W * H) as usize);
    for y in 0..H {
        for x in 0..W {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            if outline.iter().any(|&(a, b)| segment_distance(p, a, b) <= 0.01) {
                map.push(None);
                continue;
            }
            let inside = tris.iter().any(|t| {
                let area = signed_area(*t);
                let w = [signed_area([t[1], t[2], p]), signed_area([t[2], t[0], p]), signed_area([t[0], t[1], p])];
                w.iter().all(|&wk| wk / area >= -1e-4)
            });
            map.push(Some(inside));
        }
    }
    map
}

#[derive(Default, Debug)]
struct Faults {
    holes: usize,
    doubles: usize,
    outside: usize,
}

fn faults(m: &Mesh, method: Method) -> Faults {
    let counts = coverage_counts(method, W, H, Vec2::splat(0.5), &m.triangles()).unwrap();
    let mut f = Faults::default();
    for (c, inside) in counts.iter().zip(inside_map(m)) {
        match inside {
            Some(true) if *c == 0 => f.holes += 1,
            Some(false) if *c > 0 => f.outside += 1,
            _ => {}
        }
        if *c > 1 {
            f.doubles += 1;
        }
    }
    f
}

proptest! {
    // A fixed seed so CI is repeatable; set PROPTEST_RNG_SEED to explore (50
    // seeds x 400 meshes were swept clean after the fix for the case saved in
    // raster_watertight.proptest-regressions: a sliver that only its snapped
    // vertices bring onto a sample row, once culled by the unsnapped bounds).
    #![proptest_config(ProptestConfig {
        cases: 400,
        rng_seed: if std::env::var_os("PROPTEST_RNG_SEED").is_some() {
            ProptestConfig::default().rng_seed
        } else {
            proptest::test_runner::RngSeed::Fixed(0x7a7e_7719)
        },
        ..ProptestConfig::default()
    })]

    #[test]
    fn fixed_and_tiled_cover_every_inside_sample_exactly_once(m in mesh()) {
        let tris = m.triangles();
        for method in [Method::Fixed, Method::Tiled] {
            let f = faults(&m, method);
            prop_assert!(f.holes == 0 && f.doubles == 0 && f.outside == 0, "{}: {f:?}", method.name());
        }
        let fixed = coverage_counts(Method::Fixed, W, H, Vec2::splat(0.5), &tris);
        let tiled = coverage_counts(Method::Tiled, W, H, Vec2::splat(0.5), &tris);
        prop_assert_eq!(fixed, tiled);
    }
}

#[test]
fn the_coverage_check_sees_a_crack() {
    // Two triangles of a square sharing their diagonal y = x, and the same two
    // with the upper one moved a tenth of a pixel away: a crack along the diagonal.
    let sq = |gap: f32| -> Mesh {
        let verts = vec![
            Vec2::new(10.0, 10.0),
            Vec2::new(40.0, 10.0),
            Vec2::new(40.0, 40.0),
            Vec2::new(10.0, 40.0),
            Vec2::new(10.0 + gap, 10.0 - gap),
            Vec2::new(40.0 + gap, 40.0 - gap),
        ];
        Mesh { verts, tris: vec![[4, 1, 5], [0, 2, 3]] }
    };
    let whole = faults(&sq(0.0), Method::Fixed);
    assert_eq!((whole.holes, whole.doubles), (0, 0));
    let cracked = sq(0.1);
    let counts = coverage_counts(Method::Fixed, W, H, Vec2::splat(0.5), &cracked.triangles()).unwrap();
    // The samples on the diagonal y = x (pixel centres (i + 0.5, i + 0.5)) fall in the crack.
    let missing = (10..40).filter(|&i| counts[(i + i * W) as usize] == 0).count();
    assert_eq!(missing, 30);
}

#[test]
fn report_float_variant_cracks() {
    // Not a requirement: the float variants have no fill rule (shared edges are
    // drawn twice) and rounding can open holes. Count both over many meshes.
    let mut runner = TestRunner::deterministic();
    let strategy = mesh();
    let mut totals: Vec<(Method, Faults)> = [Method::Incremental, Method::Barycentric, Method::Scanline, Method::Fixed, Method::Tiled]
        .into_iter()
        .map(|m| (m, Faults::default()))
        .collect();
    let mut inside = 0;
    for _ in 0..300 {
        let m = strategy.new_tree(&mut runner).unwrap().current();
        inside += inside_map(&m).iter().filter(|v| **v == Some(true)).count();
        for (method, t) in &mut totals {
            let f = faults(&m, *method);
            t.holes += f.holes;
            t.doubles += f.doubles;
            t.outside += f.outside;
        }
    }
    println!("coverage faults over 300 random meshes ({inside} inside samples):");
    for (m, f) in &totals {
        println!("  {:>22}: {:>5} holes, {:>6} double hits, {:>4} outside", m.name(), f.holes, f.doubles, f.outside);
    }
    let fixed = &totals[3].1;
    assert_eq!((fixed.holes, fixed.doubles, fixed.outside), (0, 0, 0));
}
