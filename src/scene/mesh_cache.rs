//! Mesh files (OBJ, PLY) parsed once per scene load: every object naming
//! the same file with the same normal and texture modes shares one parse,
//! and places its own copy of the triangles.

use crate::scene::assets::canonical_path;
use crate::scene::mesh_file::load_mesh_file;
use crate::scene::obj::{LoadedMesh, MtlTextures, NormalMode};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// What makes two loads of an OBJ give the same mesh: the file itself, the
/// folder its MTL and texture names resolve in (the folder of the path as
/// given, which a link can make differ from the file's own), the stem that
/// prefixes its material names, and the two modes.
#[derive(Clone, PartialEq, Eq, Hash)]
struct Key {
    file: PathBuf,
    base: PathBuf,
    stem: Option<std::ffi::OsString>,
    mode: NormalMode,
    textures: MtlTextures,
}

/// The meshes parsed so far during one scene load.
#[derive(Default)]
pub struct MeshCache {
    meshes: HashMap<Key, Rc<LoadedMesh>>,
}

impl MeshCache {
    /// The mesh at `path`, parsed now or shared with an earlier object.
    /// Failures are not kept: a failed load ends the scene load.
    pub fn load(&mut self, path: &Path, mode: NormalMode, textures: MtlTextures) -> Result<Rc<LoadedMesh>, String> {
        let key = Key {
            file: canonical_path(path),
            base: canonical_path(path.parent().unwrap_or(Path::new("."))),
            stem: path.file_stem().map(ToOwned::to_owned),
            mode,
            textures,
        };
        if let Some(mesh) = self.meshes.get(&key) {
            return Ok(Rc::clone(mesh));
        }
        let mesh = Rc::new(load_mesh_file(path, mode, textures)?);
        self.meshes.insert(key, Rc::clone(&mesh));
        Ok(mesh)
    }
}

