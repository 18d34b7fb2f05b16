//! Files a scene refers to: compiled-in assets (the built-in scenes' models
//! and textures, under `BUILTIN_ROOT`) or real paths on disk.

use crate::input::{read_file, InputKind};
use std::path::{Component, Path, PathBuf};

/// The root that built-in scenes' relative paths resolve under.
pub const BUILTIN_ROOT: &str = "<builtin>";

/// The compiled-in assets, by their path under `BUILTIN_ROOT`.
const FILES: &[(&str, &[u8])] = &[
    ("models/teapot.obj", include_bytes!("../../assets/models/teapot.obj")),
    ("models/stanford-bunny.obj", include_bytes!("../../assets/models/stanford-bunny.obj")),
    ("models/suzanne.obj", include_bytes!("../../assets/models/suzanne.obj")),
    ("models/spot.obj", include_bytes!("../../assets/models/spot.obj")),
    ("models/stress-bumps.obj", include_bytes!("../../assets/models/stress-bumps.obj")),
    ("models/stress-coarse-sphere.obj", include_bytes!("../../assets/models/stress-coarse-sphere.obj")),
    ("models/stress-tjunction.obj", include_bytes!("../../assets/models/stress-tjunction.obj")),
    ("models/stress-tjunction-shared.obj", include_bytes!("../../assets/models/stress-tjunction-shared.obj")),
    ("models/checker-ground.obj", include_bytes!("../../assets/models/checker-ground.obj")),
    ("models/cube.obj", include_bytes!("../../assets/models/cube.obj")),
    ("textures/test-pattern.exr", include_bytes!("../../assets/textures/test-pattern.exr")),
    ("textures/checker.png", include_bytes!("../../assets/textures/checker.png")),
    ("textures/globe.png", include_bytes!("../../assets/textures/globe.png")),
    ("textures/bumps-normal.png", include_bytes!("../../assets/textures/bumps-normal.png")),
    ("textures/sky.hdr", include_bytes!("../../assets/textures/sky.hdr")),
    ("textures/sky-sun.exr", include_bytes!("../../assets/textures/sky-sun.exr")),
];

/// Reads a file a scene refers to: from the compiled-in assets for paths under
/// `BUILTIN_ROOT`, otherwise from disk through the bounded reader.
pub fn read_asset(path: &Path, kind: InputKind) -> Result<Vec<u8>, String> {
    let clean = lexical_normalize(path);
    if let Ok(rest) = clean.strip_prefix(BUILTIN_ROOT) {
        let key = rest.to_string_lossy().replace('\\', "/");
        return FILES
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, bytes)| bytes.to_vec())
            .ok_or_else(|| format!("{}: no such built-in asset", path.display()));
    }
    read_file(path, kind)
}

/// One name per file a scene may refer to: the built-in asset's clean path,
/// or the real path on disk (links and `..` resolved), or, when the file
/// cannot be resolved, its clean path (reading it will then say why).
pub fn canonical_path(path: &Path) -> PathBuf {
    let clean = lexical_normalize(path);
    if clean.starts_with(BUILTIN_ROOT) {
        return clean;
    }
    std::fs::canonicalize(path).unwrap_or(clean)
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
    fn builtin_paths_resolve() {
        assert!(read_asset(Path::new("<builtin>/scenes/../models/teapot.obj"), InputKind::Mesh).is_ok());
        assert!(read_asset(Path::new("<builtin>/scenes/../models/nope.obj"), InputKind::Mesh).is_err());
    }
}
