//! Built-in scenes: the TOML in `assets/scenes/` is compiled into the binary
//! (the models and textures it uses too, in `assets.rs`), so `pinhole render
//! teapot` works from anywhere.

use crate::scene::assets::BUILTIN_ROOT;
use crate::scene::file::parse_scene;
use crate::scene::Scene;
use std::path::Path;

const SCENES: &[(&str, &str)] = &[
    ("one-triangle", include_str!("../../assets/scenes/one-triangle.toml")),
    ("triangle-ground", include_str!("../../assets/scenes/triangle-ground.toml")),
    ("teapot", include_str!("../../assets/scenes/teapot.toml")),
    ("spheres", include_str!("../../assets/scenes/spheres.toml")),
    ("bunny", include_str!("../../assets/scenes/bunny.toml")),
    ("test-pattern", include_str!("../../assets/scenes/test-pattern.toml")),
    ("cornell-gi", include_str!("../../assets/scenes/cornell-gi.toml")),
    ("textures", include_str!("../../assets/scenes/textures.toml")),
    ("csg", include_str!("../../assets/scenes/csg.toml")),
    ("cornell-box", include_str!("../../assets/scenes/cornell-box.toml")),
    ("soft-shadows", include_str!("../../assets/scenes/soft-shadows.toml")),
    ("sky", include_str!("../../assets/scenes/sky.toml")),
    ("cgfs-spheres", include_str!("../../assets/scenes/cgfs-spheres.toml")),
];

/// The stress gallery's scenes (`gallery::cases`), each built to provoke
/// one failure. Loadable by name like the others, but listed apart: they are
/// meant to break renderers, so what holds on every built-in scene (the
/// renderers' agreement) does not hold on them.
const STRESS_SCENES: &[(&str, &str)] = &[
    ("stress-painter", include_str!("../../assets/scenes/stress-painter.toml")),
    ("stress-zfight", include_str!("../../assets/scenes/stress-zfight.toml")),
    ("stress-linear-z", include_str!("../../assets/scenes/stress-linear-z.toml")),
    ("stress-zpass", include_str!("../../assets/scenes/stress-zpass.toml")),
    ("stress-shadow", include_str!("../../assets/scenes/stress-shadow.toml")),
    ("stress-grazing", include_str!("../../assets/scenes/stress-grazing.toml")),
    ("stress-far", include_str!("../../assets/scenes/stress-far.toml")),
    ("stress-near", include_str!("../../assets/scenes/stress-near.toml")),
    ("stress-tjunction", include_str!("../../assets/scenes/stress-tjunction.toml")),
    ("stress-tjunction-shared", include_str!("../../assets/scenes/stress-tjunction-shared.toml")),
    ("stress-specular", include_str!("../../assets/scenes/stress-specular.toml")),
    ("stress-terminator", include_str!("../../assets/scenes/stress-terminator.toml")),
    ("stress-glossy-panel", include_str!("../../assets/scenes/stress-glossy-panel.toml")),
];

/// The scene the viewer opens when given none.
pub const DEFAULT_SCENE: &str = "teapot";

pub fn names() -> Vec<&'static str> {
    SCENES.iter().map(|(n, _)| *n).collect()
}

/// The stress gallery's scenes, by name.
pub fn stress_names() -> Vec<&'static str> {
    STRESS_SCENES.iter().map(|(n, _)| *n).collect()
}

/// The large scenes (`forest`): loadable by name, listed apart because
/// only the renderers that draw the two-level instance layer draw them.
pub fn large_names() -> Vec<&'static str> {
    crate::scene::forest::SCENES.iter().map(|(n, _, _)| *n).collect()
}

/// The TOML source of a built-in scene (stress and large scenes included).
pub fn source(name: &str) -> Option<&'static str> {
    if let Some(k) = crate::scene::forest::SCENES.iter().position(|(n, _, _)| *n == name) {
        const N: usize = crate::scene::forest::SCENES.len();
        static TEXTS: [std::sync::OnceLock<String>; N] = [const { std::sync::OnceLock::new() }; N];
        let (_, count, layout) = crate::scene::forest::SCENES[k];
        return Some(TEXTS[k].get_or_init(|| crate::scene::forest::source(count, layout)).as_str());
    }
    SCENES.iter().chain(STRESS_SCENES).find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Parses a built-in scene; `None` when there is no such name.
pub fn load_builtin(name: &str) -> Option<Result<Scene, String>> {
    let text = source(name)?;
    let base = Path::new(BUILTIN_ROOT).join("scenes");
    Some(parse_scene(text, &format!("built-in scene {name}"), &base, name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_scene_loads() {
        for name in names() {
            let scene = load_builtin(name).unwrap().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(scene.triangles.len() + scene.spheres.len() + scene.csgs.len() > 0, "{name} is empty");
            assert!(!scene.lights.is_empty() || scene.has_sampled_lights(), "{name} has no light");
        }
    }

    #[test]
    fn every_stress_scene_loads_and_is_listed_apart() {
        for name in stress_names() {
            assert!(!names().contains(&name), "{name} is listed with the ordinary scenes");
            let scene = load_builtin(name).unwrap().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(scene.triangles.len() + scene.spheres.len() > 0, "{name} is empty");
            assert!(!scene.lights.is_empty() || scene.has_sampled_lights(), "{name} has no light");
        }
    }

    #[test]
    fn book_scene_values() {
        let s = load_builtin("one-triangle").unwrap().unwrap();
        assert_eq!((s.render.width, s.render.height), (800, 500));
        assert_eq!(s.camera.fov, super::super::Fov::X(90.0));
        assert_eq!(s.triangles.len(), 1);
        assert_eq!(s.triangles.at(0).v[1], glam::Vec3::new(-1.9, -1.0, -2.0));
        let g = load_builtin("triangle-ground").unwrap().unwrap();
        assert_eq!(g.triangles.len(), 4);
    }
}
