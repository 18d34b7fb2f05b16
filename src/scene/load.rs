//! Opening a scene by the argument the command line and the viewer take: a
//! built-in scene's name, a `.toml` scene file, a bare mesh (`.obj`,
//! `.ply`) or a glTF (`.gltf`, `.glb`). A bare word names a built-in scene
//! before a file of that name; anything with a folder separator or a scene
//! file's extension is a path.

use crate::scene::builtin;
use crate::scene::file::load_scene_file;
use crate::scene::mesh_file::frame_bare_mesh;
use crate::scene::Scene;
use std::path::PathBuf;

/// Where a scene argument points: a built-in name, a `.toml` or a bare mesh.
pub fn load_scene(arg: &str) -> Result<Scene, String> {
    load_scene_with_camera(arg, None)
}

/// `load_scene`, looking through the camera called `camera` (a glTF's):
/// refused when the scene has no camera of that name.
pub fn load_scene_with_camera(arg: &str, camera: Option<&str>) -> Result<Scene, String> {
    let path = PathBuf::from(arg);
    if crate::scene::gltf::is_gltf(&path) {
        return crate::scene::gltf::frame_bare_gltf(&path, camera);
    }
    let mut scene = load_scene_by_kind(arg, &path)?;
    if let Some(wanted) = camera {
        let found = scene.named_cameras.iter().find(|(n, _)| n == wanted).map(|(_, c)| c.clone());
        scene.camera = found.ok_or_else(|| {
            let names: Vec<String> = scene.named_cameras.iter().map(|(n, _)| format!("\"{n}\"")).collect();
            format!("{arg}: no camera is named \"{wanted}\" (its cameras: {})", if names.is_empty() { "none".into() } else { names.join(", ") })
        })?;
    }
    Ok(scene)
}

fn load_scene_by_kind(arg: &str, path: &std::path::Path) -> Result<Scene, String> {
    let is_mesh = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj") || e.eq_ignore_ascii_case("ply"));
    if is_mesh {
        return frame_bare_mesh(path);
    }
    // A path is what looks like one (a folder in it, or a scene file's
    // extension); a bare word is a built-in scene's name first, so a folder
    // called `textures` beside you does not hide the built-in `textures`
    // (`./textures` means the folder).
    let looks_like_path = arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR) || arg.ends_with(".toml");
    if looks_like_path || (builtin::source(arg).is_none() && path.exists()) {
        return load_scene_file(path);
    }
    builtin::load_builtin(arg).ok_or_else(|| {
        format!(
            "\"{arg}\" is neither a scene file nor a built-in scene (built-in: {})",
            builtin::names().join(", ")
        )
    })?
}
