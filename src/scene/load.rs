//! Opening a scene by the argument the command line and the viewer take: a
//! built-in scene's name, a `.toml` scene file or a bare `.obj`. A bare word
//! names a built-in scene before a file of that name; anything with a folder
//! separator or a scene file's extension is a path.

use crate::scene::builtin;
use crate::scene::file::load_scene_file;
use crate::scene::obj::frame_bare_obj;
use crate::scene::Scene;
use std::path::PathBuf;

/// Where a scene argument points: a built-in name, a `.toml` or a bare `.obj`.
pub fn load_scene(arg: &str) -> Result<Scene, String> {
    let path = PathBuf::from(arg);
    let is_obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if is_obj {
        return frame_bare_obj(&path);
    }
    // A path is what looks like one (a folder in it, or a scene file's
    // extension); a bare word is a built-in scene's name first, so a folder
    // called `textures` beside you does not hide the built-in `textures`
    // (`./textures` means the folder).
    let looks_like_path = arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR) || arg.ends_with(".toml");
    if looks_like_path || (builtin::source(arg).is_none() && path.exists()) {
        return load_scene_file(&path);
    }
    builtin::load_builtin(arg).ok_or_else(|| {
        format!(
            "\"{arg}\" is neither a scene file nor a built-in scene (built-in: {})",
            builtin::names().join(", ")
        )
    })?
}
