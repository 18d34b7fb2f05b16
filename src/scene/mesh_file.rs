//! Mesh files by their extension (`.ply` read as PLY, anything else as
//! OBJ), and the scene framed around a bare one given on the command line.

use crate::scene::obj::{frame_camera, load_obj, LoadedMesh, MtlTextures, NormalMode};
use crate::scene::ply::load_ply;
use crate::scene::{ObjectInfo, Scene};
use std::path::Path;

/// Whether `path` names a PLY file (by its extension); other mesh files are read as OBJ.
pub fn is_ply(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply"))
}

/// The mesh file at `path`, read as PLY or OBJ by its extension.
pub fn load_mesh_file(path: &Path, mode: NormalMode, textures: MtlTextures) -> Result<LoadedMesh, String> {
    if is_ply(path) {
        load_ply(path, mode).map_err(|e| crate::input::bounded_message(&e))
    } else {
        load_obj(path, mode, textures)
    }
}

/// A scene around a bare mesh file (`.obj` or `.ply`): camera on +z looking
/// at the bounding-box centre with the whole box in view, one point light
/// above and behind it.
pub fn frame_bare_mesh(path: &Path) -> Result<Scene, String> {
    let mesh = load_mesh_file(path, NormalMode::Auto, MtlTextures::Used)?;
    let mut scene = Scene {
        name: path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "mesh".into()),
        ..Scene::default()
    };
    scene.warnings = mesh.warnings;
    if mesh.degenerate > 0 {
        scene.warnings.push(format!("{}: skipped {} triangles with zero area", path.display(), mesh.degenerate));
    }
    scene.materials = mesh.materials;
    let fallback = scene.default_material_index();
    scene.triangles = mesh
        .triangles
        .iter()
        .map(|mut t| {
            if t.material == u32::MAX {
                t.material = fallback;
            }
            t
        })
        .collect();
    scene.objects.push(ObjectInfo { name: scene.name.clone(), kind: "mesh".into(), triangles: 0..scene.triangles.len() });
    let (lo, hi) = scene.bounds().ok_or(format!("{}: the mesh has no geometry", path.display()))?;
    frame_camera(&mut scene, lo, hi);
    scene.triangles.share_corners();
    Ok(scene)
}

