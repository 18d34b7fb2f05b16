//! A scene file that uses one OBJ in several objects parses it once per
//! (file, normal mode, texture mode) and still gives every object exactly the
//! triangles it gets when loaded on its own.

use pinhole::scene::file::parse_scene;
use pinhole::scene::obj::parses_on_this_thread;
use pinhole::scene::{Scene, Triangle};
use std::path::PathBuf;

fn models() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/models")
}

const MATERIALS: &str = "[materials.a]\nlambertian = [0.5, 0.4, 0.3]\n";

/// The objects, each a `[[object]]` table body. The teapot is named four
/// ways (one with `./`) under three keys; suzanne once.
const OBJECTS: &[&str] = &[
    "type = \"mesh\"\nfile = \"teapot.obj\"\nmaterial = \"a\"\n",
    "type = \"mesh\"\nfile = \"teapot.obj\"\nmaterial = \"a\"\ntranslate = [1, 2, 3]\nrotate_deg = [10, 20, 30]\nscale = [1, -2, 1]\n",
    "type = \"mesh\"\nfile = \"./teapot.obj\"\nmaterial = \"a\"\nscale = 2\n",
    "type = \"mesh\"\nfile = \"teapot.obj\"\nnormals = \"flat\"\nmaterial = \"a\"\n",
    "type = \"mesh\"\nfile = \"teapot.obj\"\ntwo_sided = true\n",
    "type = \"mesh\"\nfile = \"suzanne.obj\"\nmaterial = \"a\"\ntranslate = [0, 5, 0]\n",
];

fn scene_of(objects: &[&str]) -> Scene {
    let text: String = std::iter::once(MATERIALS.to_string()).chain(objects.iter().map(|o| format!("[[object]]\n{o}"))).collect::<Vec<_>>().join("\n");
    parse_scene(&text, "test.toml", &models(), "test").unwrap()
}

/// A triangle with its material named rather than numbered, so scenes whose
/// material lists differ can be compared.
fn named(scene: &Scene, t: &Triangle) -> (Triangle, String) {
    (Triangle { material: 0, ..t.clone() }, scene.materials[t.material as usize].name.clone())
}

#[test]
fn objects_sharing_an_obj_get_the_triangles_of_separate_loads() {
    let together = scene_of(OBJECTS);
    assert_eq!(together.objects.len(), OBJECTS.len());
    for (i, o) in OBJECTS.iter().enumerate() {
        let alone = scene_of(&[o]);
        let range = together.objects[i].triangles.clone();
        assert_eq!(range.len(), alone.triangles.len(), "object {}", i + 1);
        for (a, b) in together.triangles.range(range).zip(&alone.triangles) {
            let b = Triangle { object: i as u32, ..b.clone() };
            assert_eq!(named(&together, &a), named(&alone, &b), "object {}", i + 1);
        }
    }
    // The placements really differ, so the comparison above is not vacuous.
    let (first, second) = (&together.objects[0].triangles, &together.objects[1].triangles);
    assert_ne!(together.triangles.at(first.start).v, together.triangles.at(second.start).v);
}

#[test]
fn a_shared_obj_is_parsed_once_per_file_and_modes() {
    let before = parses_on_this_thread();
    let scene = scene_of(OBJECTS);
    // teapot (auto, scene material) x3, teapot (flat), teapot (auto, its own
    // MTL textures), suzanne: four distinct parses for six objects.
    assert_eq!(parses_on_this_thread() - before, 4);
    assert_eq!(scene.objects.len(), 6);

    let before = parses_on_this_thread();
    let many: Vec<&str> = std::iter::repeat_n(OBJECTS[1], 10).collect();
    let scene = scene_of(&many);
    assert_eq!(parses_on_this_thread() - before, 1);
    assert_eq!(scene.triangles.len(), 10 * scene.objects[0].triangles.len());
}
