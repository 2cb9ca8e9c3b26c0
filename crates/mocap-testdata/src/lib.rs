//! Where tests, examples and benchmarks find their data, in one place.
//!
//! Real motion capture for tests lives beside the repository in
//! `../shared/data` (CI has it; see its READMEs), or wherever
//! `MOCAP_SHARED_DATA` points. Tests that need it call [`shared_data`] and
//! return early, with a note, when it is absent. Small samples that ship with
//! the project are in `samples/` ([`sample`]).

use std::path::{Path, PathBuf};

/// The repository's root folder (the Cargo workspace).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The folder of real data: `MOCAP_SHARED_DATA`, else
/// `<repository>/../shared/data`. `None` (after printing a note on standard
/// error) when it does not exist.
pub fn shared_data() -> Option<PathBuf> {
    let dir = match std::env::var_os("MOCAP_SHARED_DATA") {
        Some(d) => PathBuf::from(d),
        None => repo_root().join("../shared/data"),
    };
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "note: shared data not found at {} (set MOCAP_SHARED_DATA); skipping",
            dir.display()
        );
        None
    }
}

/// A file or folder under the shared data, when the shared data is there.
pub fn shared(relative: impl AsRef<Path>) -> Option<PathBuf> {
    shared_data().map(|d| d.join(relative))
}

/// A sample bundled in `samples/`.
pub fn sample(name: &str) -> PathBuf {
    repo_root().join("samples").join(name)
}

/// The bundled 6.5-second Bandai walk.
pub fn sample_walk() -> PathBuf {
    sample("dataset-1_walk_normal_001.bvh")
}

/// The `.bvh` files directly in `dir`, sorted by name.
pub fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")))
        .collect();
    files.sort();
    files
}
