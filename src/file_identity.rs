//! Which files this process has read, and the check that no output is one of
//! them. A file is known by its device and inode as well as its resolved
//! path, so a hard link, a symlink or a `..` detour to an input is the same
//! input. Every disk read goes through `input::read_file`, which records here.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// One file on disk: device and inode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FileIdentity {
    device: u64,
    inode: u64,
}

impl FileIdentity {
    pub fn of_metadata(m: &std::fs::Metadata) -> FileIdentity {
        FileIdentity { device: m.dev(), inode: m.ino() }
    }

    /// The file at `path` (links followed), if there is one.
    pub fn of(path: &Path) -> Option<FileIdentity> {
        std::fs::metadata(path).ok().map(|m| FileIdentity::of_metadata(&m))
    }
}

/// An input as recorded: its identity and the path it was read under.
#[derive(Clone, Debug)]
struct InputRead {
    identity: FileIdentity,
    resolved: PathBuf,
    shown: PathBuf,
}

/// Every regular file read so far (a scene, its meshes, textures,
/// environment, a reference). The viewer reads scene after scene, so the
/// list is bounded: the oldest entries go first.
static INPUTS_READ: Mutex<Vec<InputRead>> = Mutex::new(Vec::new());
const MAX_RECORDED: usize = 4096;

/// Notes that `path` (opened as `metadata`) was read as input.
pub fn record_input(path: &Path, metadata: &std::fs::Metadata) {
    if !metadata.is_file() {
        return;
    }
    let entry = InputRead {
        identity: FileIdentity::of_metadata(metadata),
        resolved: std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
        shown: path.to_path_buf(),
    };
    let mut list = INPUTS_READ.lock().unwrap_or_else(|e| e.into_inner());
    if list.iter().any(|r| r.identity == entry.identity) {
        return;
    }
    if list.len() >= MAX_RECORDED {
        list.remove(0);
    }
    list.push(entry);
}

/// The resolved paths of every file read so far, in the order first read.
pub fn inputs_read() -> Vec<PathBuf> {
    INPUTS_READ.lock().unwrap_or_else(|e| e.into_inner()).iter().map(|r| r.resolved.clone()).collect()
}

/// Where writing `path` would land: the resolved path of the file (links
/// followed; for a file not made yet, its resolved folder joined with its
/// name) and the file's identity if it exists. `None` for special files
/// (`/dev/null`, a terminal), which any number of outputs may share.
fn output_place(path: &Path) -> Option<(PathBuf, Option<FileIdentity>)> {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => None,
        Ok(m) => Some((std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()), Some(FileIdentity::of_metadata(&m)))),
        Err(_) => {
            let name = path.file_name()?;
            let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
            Some((dir.join(name), None))
        }
    }
}

/// Refuses, in one sentence, outputs that are the same file as an input this
/// run read or as each other. Called once the inputs are read and before
/// any work is done, so a refused run changes nothing on disk.
pub fn check_outputs(outputs: &[&Path]) -> Result<(), String> {
    let places: Vec<_> = outputs.iter().map(|p| (p, output_place(p))).collect();
    for (i, (path, place)) in places.iter().enumerate() {
        let Some((resolved, identity)) = place else { continue };
        for (other, other_place) in &places[..i] {
            let Some((other_resolved, other_identity)) = other_place else { continue };
            if resolved == other_resolved || (identity.is_some() && identity == other_identity) {
                return Err(format!("{}: the same file is also the output {}; give each output its own name", path.display(), other.display()));
            }
        }
        let list = INPUTS_READ.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(input) = list.iter().find(|r| Some(r.identity) == *identity || r.resolved == *resolved) {
            return Err(format!(
                "{}: refusing to write over {}, which this run read as input; choose another output name",
                path.display(),
                input.shown.display()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_may_not_be_an_input_by_any_name() {
        let dir = std::env::temp_dir().join(format!("pinhole-file-identity-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let input = dir.join("scene.toml");
        std::fs::write(&input, b"x").unwrap();
        record_input(&input, &std::fs::metadata(&input).unwrap());
        std::fs::hard_link(&input, dir.join("hard.toml")).unwrap();
        std::os::unix::fs::symlink(&input, dir.join("soft.toml")).unwrap();
        for alias in [input.clone(), dir.join("sub/../scene.toml"), dir.join("hard.toml"), dir.join("soft.toml")] {
            let e = check_outputs(&[&alias]).unwrap_err();
            assert!(e.contains("read as input"), "{e}");
        }
        assert!(check_outputs(&[&dir.join("other.exr")]).is_ok());
        let e = check_outputs(&[&dir.join("a.exr"), &dir.join("sub/../a.exr")]).unwrap_err();
        assert!(e.contains("also the output"), "{e}");
        assert!(check_outputs(&[Path::new("/dev/null"), Path::new("/dev/null")]).is_ok());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
