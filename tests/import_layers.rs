//! The crate's modules import each other downwards only:
//! `scripts/check_import_cycles.py` finds no cycle among the module files and
//! no import from a lower layer into a higher one. The script itself is
//! checked on small made-up trees, so a script that stopped finding cycles
//! could not let the first test pass.

use std::path::{Path, PathBuf};
use std::process::Command;

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_import_cycles.py")
}

/// Runs the checker on `src` and returns (exit status success, stdout).
fn check(src: &Path) -> (bool, String) {
    let out = Command::new("python3").arg(script()).arg(src).output().expect("python3 runs (the checker is a Python script)");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into_owned())
}

/// A made-up `src/` tree from (path, text) pairs, in a fresh temporary directory.
fn tree(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let root = std::env::temp_dir().join(format!("pinhole-import-layers-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    for (path, text) in files {
        let p = root.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    root
}

#[test]
fn the_crate_has_no_import_cycle_and_keeps_its_layers() {
    let (ok, out) = check(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(ok, "{out}");
}

#[test]
fn a_cycle_between_siblings_is_found() {
    let src = tree(
        "cycle",
        &[
            ("lib.rs", "pub mod render;\n"),
            ("render/mod.rs", "pub mod shade;\npub mod gi;\n"),
            ("render/shade.rs", "use crate::render::gi::bounce;\npub fn shade() {}\n"),
            ("render/gi.rs", "use super::shade::shade;\npub fn bounce() {}\n"),
        ],
    );
    let (ok, out) = check(&src);
    assert!(!ok, "{out}");
    assert!(out.contains("render::gi") && out.contains("render::shade"), "{out}");
}

#[test]
fn a_grouped_import_and_an_inline_path_are_read() {
    let src = tree(
        "grouped",
        &[
            ("lib.rs", "pub mod a;\npub mod b;\n"),
            ("a.rs", "use crate::{math::Vec3, b::{x, y}};\npub fn f() {}\n"),
            ("b.rs", "pub fn x() { crate::a::f() }\npub fn y() {}\n"),
        ],
    );
    let (ok, out) = check(&src);
    assert!(!ok && out.contains("2 files: a, b"), "{out}");
}

#[test]
fn a_parent_using_its_children_is_not_a_cycle_and_tests_are_skipped() {
    let src = tree(
        "parent",
        &[
            ("lib.rs", "pub mod render;\n"),
            ("render/mod.rs", "pub mod frame;\npub use frame::go;\npub struct Settings;\n"),
            ("render/frame.rs", "use crate::render::Settings;\npub fn go(_: Settings) {}\n#[cfg(test)]\nmod tests {\n    use crate::render::other::*;\n}\n"),
        ],
    );
    let (ok, out) = check(&src);
    assert!(ok, "{out}");
}

#[test]
fn an_upward_import_is_found_without_a_cycle() {
    let src = tree(
        "upward",
        &[
            ("lib.rs", "pub mod render;\npub mod scene;\n"),
            ("render/mod.rs", "pub mod accel;\npub mod transport;\n"),
            ("render/accel.rs", "use crate::render::transport::shade;\n"),
            ("render/transport.rs", "pub fn shade() {}\n"),
            ("scene/mod.rs", "pub fn load() { let _ = crate::render::accel::X; }\n"),
        ],
    );
    let (ok, out) = check(&src);
    assert!(!ok, "{out}");
    assert!(out.contains("render::accel -> render::transport"), "{out}");
    assert!(out.contains("scene -> render::accel"), "{out}");
}
