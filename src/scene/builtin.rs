//! Built-in scenes: the TOML in `assets/scenes/` and the models it uses are
//! compiled into the binary, so `pinhole render teapot` works from anywhere.

use super::Scene;
use std::path::{Component, Path, PathBuf};

/// The root that built-in scenes' relative paths resolve under.
pub const BUILTIN_ROOT: &str = "<builtin>";

const SCENES: &[(&str, &str)] = &[
    ("one-triangle", include_str!("../../assets/scenes/one-triangle.toml")),
    ("triangle-ground", include_str!("../../assets/scenes/triangle-ground.toml")),
    ("teapot", include_str!("../../assets/scenes/teapot.toml")),
    ("spheres", include_str!("../../assets/scenes/spheres.toml")),
    ("bunny", include_str!("../../assets/scenes/bunny.toml")),
    ("test-pattern", include_str!("../../assets/scenes/test-pattern.toml")),
];

const FILES: &[(&str, &[u8])] = &[
    ("models/teapot.obj", include_bytes!("../../assets/models/teapot.obj")),
    ("models/stanford-bunny.obj", include_bytes!("../../assets/models/stanford-bunny.obj")),
    ("models/suzanne.obj", include_bytes!("../../assets/models/suzanne.obj")),
    ("models/spot.obj", include_bytes!("../../assets/models/spot.obj")),
    ("textures/test-pattern.exr", include_bytes!("../../assets/textures/test-pattern.exr")),
];

/// The scene the viewer opens when given none.
pub const DEFAULT_SCENE: &str = "teapot";

pub fn names() -> Vec<&'static str> {
    SCENES.iter().map(|(n, _)| *n).collect()
}

/// The TOML source of a built-in scene.
pub fn source(name: &str) -> Option<&'static str> {
    SCENES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Parses a built-in scene; `None` when there is no such name.
pub fn load_builtin(name: &str) -> Option<Result<Scene, String>> {
    let text = source(name)?;
    let base = Path::new(BUILTIN_ROOT).join("scenes");
    Some(super::file::parse_scene(text, &format!("built-in scene {name}"), &base, name))
}

/// Reads a file a scene refers to: from the compiled-in assets for paths under
/// `BUILTIN_ROOT`, otherwise from disk.
pub fn read_asset(path: &Path) -> Result<Vec<u8>, String> {
    let clean = lexical_normalize(path);
    if let Ok(rest) = clean.strip_prefix(BUILTIN_ROOT) {
        let key = rest.to_string_lossy().replace('\\', "/");
        return FILES
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, bytes)| bytes.to_vec())
            .ok_or_else(|| format!("{}: no such built-in asset", path.display()));
    }
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Resolves `.` and `..` without touching the file system.
fn lexical_normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_scene_loads() {
        for name in names() {
            let scene = load_builtin(name).unwrap().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(scene.triangles.len() + scene.spheres.len() > 0, "{name} is empty");
            assert!(!scene.lights.is_empty(), "{name} has no light");
        }
    }

    #[test]
    fn book_scene_values() {
        let s = load_builtin("one-triangle").unwrap().unwrap();
        assert_eq!((s.render.width, s.render.height), (800, 500));
        assert_eq!(s.camera.fov, super::super::Fov::X(90.0));
        assert_eq!(s.triangles.len(), 1);
        assert_eq!(s.triangles[0].v[1], glam::Vec3::new(-1.9, -1.0, -2.0));
        let g = load_builtin("triangle-ground").unwrap().unwrap();
        assert_eq!(g.triangles.len(), 4);
    }

    #[test]
    fn builtin_paths_resolve() {
        assert!(read_asset(Path::new("<builtin>/scenes/../models/teapot.obj")).is_ok());
        assert!(read_asset(Path::new("<builtin>/scenes/../models/nope.obj")).is_err());
    }
}
