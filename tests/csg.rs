//! Constructive solid geometry: hits and normals checked by hand, both
//! renderer families agreeing on the built-in csg scene, a CSG pixel's
//! replay, and bad csg input refused in one sentence.

mod common;

use common::{builtin, render};
use pinhole::math::{Ray, Vec3};
use pinhole::render::inspect::debug::View;
use pinhole::render::inspect::pixel_record::NoRecord;
use pinhole::render::accel::brute::BruteQuery;
use pinhole::render::accel::bvh::BvhQuery;
use pinhole::render::{renderer_by_name, replay_pixel, PreparedScene, RayCounts, RenderSettings, SceneQuery, ShadowMode};
use pinhole::scene::file::{load_scene_file, parse_scene};
use pinhole::scene::{PrimitiveKind, Scene, SurfaceHit};
use std::path::{Path, PathBuf};

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-csg-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A closed cube from -1 to 1, counter-clockwise seen from outside.
const CUBE: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 5 6 7\nf 5 7 8\nf 2 1 4\nf 2 4 3\nf 6 2 3\nf 6 3 7\nf 1 5 8\nf 1 8 4\nf 8 7 3\nf 8 3 4\nf 1 2 6\nf 1 6 5\n";

const MATERIALS: &str = "[materials.first]\nlambertian = [0.5, 0.5, 0.5]\n[materials.second]\nlambertian = [0.2, 0.2, 0.2]\n";

fn scene(objects: &str, base: &Path) -> Scene {
    parse_scene(&format!("{MATERIALS}{objects}"), "test.toml", base, "test").unwrap_or_else(|e| panic!("{e}"))
}

/// The closest hit of `ray` from both ray casters, which must agree.
fn hit(prepared: &PreparedScene, origin: Vec3, dir: Vec3) -> Option<SurfaceHit> {
    let ray = Ray::new(origin, dir.normalize());
    let a = BruteQuery(prepared).closest(&ray, f32::INFINITY, false, &mut RayCounts::default(), &mut NoRecord);
    let b = BvhQuery::new(prepared).closest(&ray, f32::INFINITY, false, &mut RayCounts::default(), &mut NoRecord);
    assert_eq!(a, b, "brute force and BVH differ");
    a
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() < 1e-4
}

fn close3(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-4
}

fn material(s: &Scene, name: &str) -> u32 {
    s.materials.iter().position(|m| m.name == name).unwrap() as u32
}

#[test]
fn a_lens_by_hand() {
    // Unit spheres at z = +0.6 and z = -0.6: their intersection is a lens
    // from z = -0.4 to z = 0.4.
    let s = scene(
        "[[object]]\ntype = \"csg\"\nop = \"intersection\"\n\
         a = { type = \"sphere\", center = [0.0, 0.0, 0.6], radius = 1.0, material = \"first\" }\n\
         b = { type = \"sphere\", center = [0.0, 0.0, -0.6], radius = 1.0, material = \"second\" }\n",
        Path::new("."),
    );
    let second = material(&s, "second");
    let p = PreparedScene::new(s);
    // Down the axis from z = 5: a is entered at z = 1.6, b at z = 0.4; the
    // lens begins where both are entered, on b, whose outward normal there is +z.
    let h = hit(&p, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).unwrap();
    assert_eq!(h.kind, PrimitiveKind::Csg);
    assert!(close(h.t, 4.6), "t {}", h.t);
    assert!(close3(h.geometric_normal, Vec3::Z) && close3(h.shading_normal, Vec3::Z), "{:?}", h.geometric_normal);
    assert_eq!(h.material, second);
    assert!(!h.back_face);
    // Off the axis at x = 0.3: b's surface at z = -0.6 + sqrt(1 - 0.09) = 0.353939.
    let h = hit(&p, Vec3::new(0.3, 0.0, 5.0), -Vec3::Z).unwrap();
    let z = -0.6 + (1.0f32 - 0.09).sqrt();
    assert!(close(h.t, 5.0 - z), "t {}", h.t);
    assert!(close3(h.geometric_normal, Vec3::new(0.3, 0.0, z + 0.6)), "{:?}", h.geometric_normal);
    // Along -x at z = 0.1, near the rim: a's chord half-length is
    // sqrt(1 - 0.5^2) = 0.866, b's sqrt(1 - 0.7^2) = 0.714; the lens begins
    // at b's entry, x = 0.714143, normal (0.714143, 0, 0.7).
    let h = hit(&p, Vec3::new(5.0, 0.0, 0.1), -Vec3::X).unwrap();
    let x = (1.0f32 - 0.49).sqrt();
    assert!(close(h.t, 5.0 - x), "t {}", h.t);
    assert!(close3(h.geometric_normal, Vec3::new(x, 0.0, 0.7)), "{:?}", h.geometric_normal);
    assert_eq!(h.material, second);
    // Through a only (x = 0.9 misses b, whose chord there needs |x| < 1): nothing.
    assert!(hit(&p, Vec3::new(0.0, 0.9, 5.0), -Vec3::Z).is_none());
}

#[test]
fn a_sphere_minus_a_sphere_shows_its_inner_wall() {
    // A unit sphere at the origin minus a sphere of radius 0.6 at z = 1:
    // a cavity open towards +z whose floor is at z = 1 - 0.6 = 0.4.
    let s = scene(
        "[[object]]\ntype = \"csg\"\nop = \"difference\"\n\
         a = { type = \"sphere\", center = [0.0, 0.0, 0.0], radius = 1.0, material = \"first\" }\n\
         b = { type = \"sphere\", center = [0.0, 0.0, 1.0], radius = 0.6, material = \"second\" }\n",
        Path::new("."),
    );
    let second = material(&s, "second");
    let p = PreparedScene::new(s);
    // Down the axis: a is [4, 6] in t, b is [3.4, 4.6]; a minus b is [4.6, 6].
    // The hit is b's far wall, whose outward normal (towards b's centre's
    // far side, -z) is flipped: +z, into the cavity.
    let h = hit(&p, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(h.t, 4.6), "t {}", h.t);
    assert!(close3(h.geometric_normal, Vec3::Z), "{:?}", h.geometric_normal);
    assert_eq!(h.material, second);
    assert!(!h.back_face);
    // At x = 0.3: b's wall at z = 1 - sqrt(0.36 - 0.09) = 0.480385 (a's own
    // surface, at z = 0.954, lies inside b and is cut away). The normal
    // points from the wall towards b's centre: (-0.3, 0, 0.519615) / 0.6.
    let h = hit(&p, Vec3::new(0.3, 0.0, 5.0), -Vec3::Z).unwrap();
    let half = (0.36f32 - 0.09).sqrt();
    assert!(close(h.t, 4.0 + half), "t {}", h.t);
    assert!(close3(h.geometric_normal, Vec3::new(-0.3, 0.0, half) / 0.6), "{:?}", h.geometric_normal);
    let cavity_centre = Vec3::new(0.0, 0.0, 1.0);
    assert!(h.geometric_normal.dot(cavity_centre - h.position) > 0.0, "the normal points into the cavity");
    // Outside the cavity's reach (x = 0.8 misses b): a's own outer surface.
    let h = hit(&p, Vec3::new(0.8, 0.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(h.t, 5.0 - 0.6), "t {}", h.t);
    assert!(close3(h.geometric_normal, Vec3::new(0.8, 0.0, 0.6)));
    assert_eq!(h.material, material(&p.scene, "first"));
    // Shadow rays respect the cavity: from its inside out through the
    // opening nothing blocks; towards its floor the floor does, at t = 0.4.
    for q in [BruteQuery(&p).occluder(&Ray::new(Vec3::new(0.0, 0.0, 0.8), Vec3::Z), 10.0, &mut RayCounts::default(), &mut NoRecord)] {
        assert_eq!(q, None);
    }
    let down = Ray::new(Vec3::new(0.0, 0.0, 0.8), -Vec3::Z);
    let o = BvhQuery::new(&p).occluder(&down, 10.0, &mut RayCounts::default(), &mut NoRecord).unwrap();
    assert_eq!(o.kind, PrimitiveKind::Csg);
    assert!(close(o.t, 0.4), "t {}", o.t);
    assert!(BvhQuery::new(&p).occluder(&down, 0.39, &mut RayCounts::default(), &mut NoRecord).is_none());
}

#[test]
fn a_closed_mesh_operand() {
    let dir = temp_dir("mesh");
    std::fs::write(dir.join("cube.obj"), CUBE).unwrap();
    // The cube [-1, 1]^3 minus a sphere of radius 0.5 at the centre of its +z face.
    let s = scene(
        "[[object]]\ntype = \"csg\"\nop = \"difference\"\n\
         a = { type = \"mesh\", file = \"cube.obj\", material = \"first\" }\n\
         b = { type = \"sphere\", center = [0.0, 0.0, 1.0], radius = 0.5, material = \"second\" }\n",
        &dir,
    );
    assert!(s.triangles.is_empty(), "operand triangles stay out of the scene's list");
    let p = PreparedScene::new(s);
    // Into the dimple: its floor at z = 0.5, normal +z (flipped b).
    let h = hit(&p, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(h.t, 4.5) && close3(h.geometric_normal, Vec3::Z), "t {} n {:?}", h.t, h.geometric_normal);
    assert_eq!(h.material, material(&p.scene, "second"));
    // Beside it: the cube's face at z = 1, its geometric normal +z.
    let h = hit(&p, Vec3::new(0.8, 0.3, 5.0), -Vec3::Z).unwrap();
    assert!(close(h.t, 4.0) && close3(h.geometric_normal, Vec3::Z), "t {} n {:?}", h.t, h.geometric_normal);
    assert_eq!(h.material, material(&p.scene, "first"));
    // From the side along -x at height 0: the face x = 1, normal +x.
    let h = hit(&p, Vec3::new(5.0, 0.0, 0.0), -Vec3::X).unwrap();
    assert!(close(h.t, 4.0) && close3(h.geometric_normal, Vec3::X), "t {} n {:?}", h.t, h.geometric_normal);
    // The cube intersected with a sphere of radius 1.2: a corner ray at
    // (0.9, 0.9) passes 1.27 from the centre, outside the sphere: nothing.
    let s = scene(
        "[[object]]\ntype = \"csg\"\nop = \"intersection\"\n\
         a = { type = \"mesh\", file = \"cube.obj\" }\n\
         b = { type = \"sphere\", center = [0.0, 0.0, 0.0], radius = 1.2 }\n",
        &dir,
    );
    let p = PreparedScene::new(s);
    assert!(hit(&p, Vec3::new(0.9, 0.9, 5.0), -Vec3::Z).is_none());
    // Through the middle of a face: the cube's face (the sphere is entered earlier, at z = 1.2).
    let h = hit(&p, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(h.t, 4.0), "t {}", h.t);
}

/// Pixels where brute force and `other` differ by more than 1e-4 relative,
/// and how many of those lie away (more than one pixel) from an object
/// boundary of the id view.
fn compare(reference: &[Vec3], other: &[Vec3], ids: &[Vec3], w: u32, h: u32) -> (usize, usize) {
    let same = |a: Vec3, b: Vec3| {
        let d = (a - b).abs();
        let m = a.abs().max(b.abs());
        d.x <= 1e-4 * m.x + 1e-6 && d.y <= 1e-4 * m.y + 1e-6 && d.z <= 1e-4 * m.z + 1e-6
    };
    let (mut differ, mut inland) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = (x + y * w) as usize;
            if same(reference[i], other[i]) {
                continue;
            }
            differ += 1;
            let mut edge = false;
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                    if nx >= 0 && ny >= 0 && (nx as u32) < w && (ny as u32) < h && ids[(nx as u32 + ny as u32 * w) as usize] != ids[i] {
                        edge = true;
                    }
                }
            }
            if !edge {
                inland += 1;
            }
        }
    }
    (differ, inland)
}

#[test]
fn both_families_agree_on_the_csg_scene() {
    let (w, h) = (160, 120);
    let scene = builtin("csg");
    assert_eq!(scene.csgs.len(), 3);
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = w;
    settings.height = h;
    let prepared = PreparedScene::new(scene);
    let reference = render("raytrace:brute", &prepared, &settings);
    let ids = render("raytrace:brute", &prepared, &RenderSettings { view: View::Id, ..settings.clone() });
    let sees_csg = ids.iter().filter(|c| **c != ids[0] && **c != ids[(w * h - 1) as usize]).count();
    assert!(sees_csg > 2000, "the csg objects cover {sees_csg} pixels");
    assert!(reference.iter().all(|p| p.is_finite()));
    assert_eq!(render("raytrace:bvh", &prepared, &settings), reference, "the BVH caster equals brute force");
    for name in ["rasterize:fixed", "rasterize:tiled", "rasterize:barycentric", "rasterize:scanline", "rasterize:bbox"] {
        let image = render(name, &prepared, &settings);
        let (differ, inland) = compare(&reference, &image, &ids, w, h);
        let agree = 1.0 - differ as f64 / (w * h) as f64;
        eprintln!("{name}: {:.3}% of pixels agree, {differ} differ, {inland} away from an object edge", agree * 100.0);
        assert!(agree >= 0.995, "{name}: only {:.3}% agree", agree * 100.0);
        assert_eq!(inland, 0, "{name}: pixels differ away from edges");
    }
}

#[test]
fn a_csg_pixel_replays_as_the_frame_drew_it() {
    let scene = builtin("csg");
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = 160;
    settings.height = 120;
    let prepared = PreparedScene::new(scene);
    // The cavity of the sphere with the bite, seen from the camera.
    let (x, y) = (82, 50);
    for name in ["raytrace:brute", "raytrace:bvh", "rasterize:fixed", "rasterize:tiled", "rasterize:bbox"] {
        let frame = render(name, &prepared, &settings);
        let r = renderer_by_name(name).unwrap();
        let replay = replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap();
        assert_eq!(replay.radiance, frame[(x + y * settings.width) as usize], "{name}");
        let trace = &replay.samples[0].1;
        let eye = trace.rays[0].closest.expect("the pixel sees something");
        assert_eq!(eye.kind, PrimitiveKind::Csg, "{name}");
        assert_eq!(eye.material, prepared.scene.materials.iter().position(|m| m.name == "cavity").unwrap() as u32, "{name}: the cavity's wall");
        let report = pinhole::render::inspect::pixel_report::to_text(name, &prepared.scene, x, y, &replay);
        assert!(report.contains("combined (difference at the top)") && report.contains("won: t ="), "{report}");
        let json = pinhole::render::inspect::pixel_report::to_json(name, &prepared.scene, x, y, &replay);
        let csg = &json["samples"][0]["rays"][0]["csg"];
        assert_eq!(csg["op"], "difference", "{json}");
        assert_eq!(csg["operands"].as_array().map(Vec::len), Some(2), "{json}");
        assert_eq!(csg["won"]["operand"], "b", "{json}");
        assert_eq!(csg["won"]["boundary"], "entry", "{json}");
        assert_eq!(csg["won"]["normal_flipped"], true, "{json}");
    }
}

#[test]
fn the_rasterizers_scan_convert_operand_triangles_into_an_a_buffer() {
    use pinhole::render::accel::csg::SurfaceRef;
    let scene = builtin("csg");
    let mut settings = RenderSettings::for_scene(&scene);
    settings.width = 160;
    settings.height = 120;
    let prepared = PreparedScene::new(scene);
    // A pixel on the rounded cube (object 2: (cube mesh ∩ sphere) minus a
    // sphere): the eye ray enters the cube through one face and leaves it
    // through another, well inside both triangles, inside the rounding sphere.
    let (x, y) = (110, 62);
    let csg = &prepared.scene.csgs[2];
    let reference = {
        let r = renderer_by_name("raytrace:brute").unwrap();
        replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap().samples[0].1.rays[0].closest.unwrap()
    };
    for name in ["rasterize:fixed", "rasterize:tiled", "rasterize:scanline", "rasterize:bbox"] {
        let r = renderer_by_name(name).unwrap();
        let replay = replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap();
        let trace = &replay.samples[0].1;
        let abuffers: Vec<_> = trace.csg_abuffers.iter().filter(|a| a.csg == 2).collect();
        assert_eq!(abuffers.len(), 1, "{name}: one A-buffer list for the object at the pixel");
        let a = abuffers[0];
        // Sorted by depth.
        assert!(a.fragments.windows(2).all(|w| w[0].t <= w[1].t), "{name}: {:?}", a.fragments);
        // The mesh operand (leaf 0, "a.a"): one entry on a front face and one
        // exit on a back face, each from the coverage loop (2D weights).
        let mesh: Vec<_> = a.fragments.iter().filter(|f| f.leaf == 0).collect();
        assert_eq!(mesh.iter().filter(|f| f.entering).count(), 1, "{name}: {mesh:?}");
        assert_eq!(mesh.iter().filter(|f| !f.entering).count(), 1, "{name}: {mesh:?}");
        for f in &mesh {
            let SurfaceRef::Triangle { index, .. } = f.surface else { panic!("{name}: a mesh fragment off a triangle: {f:?}") };
            let w = f.screen_barycentric.unwrap_or_else(|| panic!("{name}: a mesh fragment without 2D weights: {f:?}"));
            assert!(w.min_element() > 0.0 && (w.x + w.y + w.z - 1.0).abs() < 1e-5, "{name}: {w:?}");
            let tri = &csg.triangles[index as usize];
            let facing_eye = tri.geometric_normal().dot(trace.rays[0].ray.dir) < 0.0;
            assert_eq!(facing_eye, f.entering, "{name}: a front face enters, a back face exits");
        }
        // The rounding sphere (leaf 1): its two roots; the dimple (leaf 2) is missed.
        let sphere: Vec<_> = a.fragments.iter().filter(|f| f.leaf == 1).collect();
        assert_eq!(sphere.len(), 2, "{name}: {sphere:?}");
        assert!(sphere[0].entering && !sphere[1].entering && sphere.iter().all(|f| f.screen_barycentric.is_none()));
        assert!(a.fragments.iter().all(|f| f.leaf != 2), "{name}");
        // The winner: the mesh's entry, where the ray caster hits.
        let (won, entering) = a.explanation.winner.unwrap();
        assert!(entering && won.leaf == 0, "{name}: {won:?}");
        assert!(a.won(mesh[0]) && mesh[0].entering, "{name}");
        let eye = trace.rays[0].closest.unwrap();
        assert_eq!((eye.kind, eye.primitive, eye.t), (PrimitiveKind::Csg, 2, won.t), "{name}");
        assert!(close(eye.t, reference.t) && close3(eye.position, reference.position), "{name}: {eye:?} vs {reference:?}");
        assert_eq!(eye.geometric_normal, reference.geometric_normal, "{name}");
        // The report lists the A-buffer.
        let text = pinhole::render::inspect::pixel_report::to_text(name, &prepared.scene, x, y, &replay);
        assert!(text.contains("A-buffer: 4 fragment(s) sorted by depth") && text.contains("operand a.a (mesh triangle") && text.contains("entry  <- won"), "{text}");
        let json = pinhole::render::inspect::pixel_report::to_json(name, &prepared.scene, x, y, &replay);
        let list = json["samples"][0]["rays"][0]["csg"]["a_buffer"].as_array().cloned().unwrap_or_default();
        assert_eq!(list.len(), 4, "{json}");
        assert_eq!(list.iter().filter(|f| f["won"] == true).count(), 1, "{json}");
        assert_eq!(list.iter().filter(|f| f["kind"] == "triangle").count(), 2, "{json}");
    }
    // The ray casters keep their own account (no A-buffer).
    let r = renderer_by_name("raytrace:bvh").unwrap();
    let replay = replay_pixel(r.as_ref(), &prepared, &settings, x, y).unwrap();
    assert!(replay.samples[0].1.csg_abuffers.is_empty());
    let json = pinhole::render::inspect::pixel_report::to_json("raytrace:bvh", &prepared.scene, x, y, &replay);
    assert!(json["samples"][0]["rays"][0]["csg"]["a_buffer"].is_null() && json["samples"][0]["rays"][0]["csg"]["won"].is_object(), "{json}");
}

#[test]
fn an_operand_entered_before_the_near_plane_still_counts() {
    // The camera sits inside a large cube mesh operand: its entries lie
    // behind the near plane, clipped away, so the A-buffer holds only its
    // exits. Cube ∩ sphere is the sphere; cube minus sphere is the sphere's
    // inner wall. Both families must draw them.
    let dir = temp_dir("near");
    std::fs::write(dir.join("cube.obj"), CUBE).unwrap();
    let sphere = "{ type = \"sphere\", center = [0.3, 0.0, -2.0], radius = 0.8, material = \"second\" }";
    let head = "[camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov_y_deg = 60.0\n[render]\nwidth = 64\nheight = 48\n\
                [[light]]\ntype = \"point\"\nposition = [0.5, 0.5, 0.0]\npower = [50.0, 50.0, 50.0]\n";
    for op in ["intersection", "difference"] {
        let s = scene(
            &format!("{head}[[object]]\ntype = \"csg\"\nop = \"{op}\"\na = {{ type = \"mesh\", file = \"cube.obj\", scale = 4.0, material = \"first\" }}\nb = {sphere}\n"),
            &dir,
        );
        let settings = RenderSettings::for_scene(&s);
        let (w, h) = (settings.width, settings.height);
        let prepared = PreparedScene::new(s);
        let reference = render("raytrace:brute", &prepared, &settings);
        let ids = render("raytrace:brute", &prepared, &RenderSettings { view: View::Id, ..settings.clone() });
        for name in ["rasterize:fixed", "rasterize:bbox"] {
            let image = render(name, &prepared, &settings);
            let (differ, inland) = compare(&reference, &image, &ids, w, h);
            assert!(differ * 200 <= (w * h) as usize && inland == 0, "{op}, {name}: {differ} pixels differ, {inland} away from edges");
        }
        // The centre pixel sees the sphere: its near wall (∩) or its far wall (minus).
        let r = renderer_by_name("rasterize:fixed").unwrap();
        let replay = replay_pixel(r.as_ref(), &prepared, &settings, w / 2, h / 2).unwrap();
        let trace = &replay.samples[0].1;
        let hit = trace.rays[0].closest.expect("the centre sees the sphere");
        assert_eq!(hit.material, material(&prepared.scene, "second"), "{op}");
        let a = &trace.csg_abuffers[0];
        assert!(a.fragments.iter().filter(|f| f.leaf == 0).all(|f| !f.entering), "{op}: only the cube's exits are drawn");
        // Near x = 0.3 the sphere's walls lie at z = -2 -+ sqrt(0.8^2 - 0.3^2) = -2 -+ 0.742.
        let expected = if op == "intersection" { -1.258 } else { -2.742 };
        assert!((hit.position.z - expected).abs() < 0.02, "{op}: {:?}", hit.position);
    }
}

#[test]
fn renderers_that_cannot_draw_csg_say_so() {
    let scene = builtin("csg");
    let settings = RenderSettings::for_scene(&scene);
    let e = renderer_by_name("rasterize:painter").unwrap().check(&scene, &settings).unwrap_err();
    assert!(e.contains("csg"), "{e}");
    // opengl evaluates CSG in its fragment shader (untextured surfaces only).
    let gl = renderer_by_name("opengl").unwrap();
    if pinhole::render::opengl::driver().is_ok() {
        let none = RenderSettings { shadows: ShadowMode::None, ..settings.clone() };
        assert_eq!(gl.check(&scene, &none), Ok(()));
        let mut textured = scene.clone();
        let texture = builtin("textures").materials.iter().find_map(|m| m.texture.clone()).unwrap();
        for m in &mut textured.materials {
            m.texture = Some(texture.clone());
        }
        let e = gl.check(&textured, &none).unwrap_err();
        assert!(e.contains("csg") && e.contains("textures") && !e.contains('\n'), "{e}");
        let e = gl.check(&scene, &RenderSettings { shadows: ShadowMode::Map, ..settings.clone() }).unwrap_err();
        assert!(e.contains("csg"), "{e}");
    }
    for shadows in [ShadowMode::Map, ShadowMode::Volume] {
        let s = RenderSettings { shadows, ..settings.clone() };
        let e = renderer_by_name("raytrace").unwrap().check(&scene, &s).unwrap_err();
        assert!(e.contains("csg"), "{e}");
    }
    assert_eq!(renderer_by_name("rasterize").unwrap().check(&scene, &settings), Ok(()));
}

/// Loads `text` as a scene file; returns the error, which must be one line
/// mentioning every one of `needles`.
fn error_of(dir: &Path, text: &str, needles: &[&str]) -> String {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let p = dir.join(format!("bad{}.toml", N.fetch_add(1, std::sync::atomic::Ordering::Relaxed)));
    std::fs::write(&p, text).unwrap();
    let err = load_scene_file(&p).err().unwrap_or_else(|| panic!("expected an error for:\n{text}"));
    for n in needles {
        assert!(err.contains(n), "error {err:?} does not mention {n:?}");
    }
    assert!(err.contains(&p.display().to_string()), "error {err:?} does not name the file");
    assert!(!err.contains('\n'), "error is not one line: {err:?}");
    err
}

#[test]
fn bad_csg_input_is_one_clear_sentence() {
    let dir = temp_dir("errors");
    std::fs::write(dir.join("cube.obj"), CUBE).unwrap();
    // The cube without its last face: open.
    std::fs::write(dir.join("open.obj"), CUBE.rsplit_once("f 1 6 5").unwrap().0).unwrap();
    let sphere = "{ type = \"sphere\", center = [0.0, 0.0, 0.0], radius = 1.0 }";
    error_of(
        &dir,
        &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"mesh\", file = \"open.obj\" }}\n"),
        &[":5:", "operand `b`", "open.obj", "not closed"],
    );
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"xor\"\na = {sphere}\nb = {sphere}\n"), &[":1:", "op", "\"xor\"", "union"]);
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\n"), &[":1:", "operand `b`"]);
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\nb = {sphere}\n"), &[":1:", "operand `a`"]);
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\na = {sphere}\nb = {sphere}\n"), &[":1:", "`op`"]);
    // Nested: the inner csg's missing operand is named by its path and line.
    error_of(
        &dir,
        &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"csg\", op = \"intersection\",\n  a = {sphere} }}\n"),
        &[":5:", "operand `b.b`"],
    );
    error_of(
        &dir,
        &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"triangle\", vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]] }}\n"),
        &[":5:", "operand `b`", "sphere, a closed mesh or a csg"],
    );
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"sphere\", radius = 1.0 }}\n"), &[":5:", "operand `b`", "center"]);
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"sphere\", centre = [0, 0, 0], radius = 1.0 }}\n"), &[":5", "centre"]);
    error_of(&dir, &format!("[[object]]\ntype = \"sphere\"\nop = \"union\"\ncenter = [0, 0, 0]\nradius = 1.0\n"), &[":1:", "`op`"]);
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\ntranslate = [1, 0, 0]\na = {sphere}\nb = {sphere}\n"), &[":1:", "translate"]);
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"mesh\", file = \"missing.obj\" }}\n"), &[":5:", "missing.obj"]);
    // Deep nesting is refused, not recursed into without end.
    let mut deep = sphere.to_string();
    for _ in 0..40 {
        deep = format!("{{ type = \"csg\", op = \"union\", a = {sphere}, b = {deep} }}");
    }
    error_of(&dir, &format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {deep}\n"), &["nested more than"]);
    // A closed mesh is accepted.
    let ok = dir.join("ok.toml");
    std::fs::write(&ok, format!("[[object]]\ntype = \"csg\"\nop = \"union\"\na = {sphere}\nb = {{ type = \"mesh\", file = \"cube.obj\", translate = [1, 0, 0] }}\n")).unwrap();
    let s = load_scene_file(&ok).unwrap();
    assert_eq!((s.csgs.len(), s.csgs[0].triangles.len(), s.csgs[0].spheres.len()), (1, 12, 1));
}
