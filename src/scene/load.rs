//! Opening a scene by the argument the command line and the viewer take: a
//! built-in scene's name, a `.toml` scene file or a bare mesh (`.obj`, `.ply`).

use crate::scene::builtin;
use crate::scene::file::load_scene_file;
use crate::scene::mesh_file::frame_bare_mesh;
use crate::scene::Scene;
use std::path::PathBuf;

/// Where a scene argument points: a built-in name, a `.toml` or a bare mesh.
pub fn load_scene(arg: &str) -> Result<Scene, String> {
    let path = PathBuf::from(arg);
    let is_mesh = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj") || e.eq_ignore_ascii_case("ply"));
    if is_mesh {
        return frame_bare_mesh(&path);
    }
    if path.exists() || arg.ends_with(".toml") || arg.contains('/') {
        return load_scene_file(&path);
    }
    builtin::load_builtin(arg).ok_or_else(|| {
        format!(
            "\"{arg}\" is neither a scene file nor a built-in scene (built-in: {})",
            builtin::names().join(", ")
        )
    })?
}
