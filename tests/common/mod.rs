//! Helpers the test files share: temporary directories, and the independent reader
//! of output files (Python's `meshio` for `.vtu`, `xml.etree` for `.pvd` and SVG).
//! Used by `tests/*.rs` as `mod common;` and by `tests/cli/*.rs` through `#[path]`;
//! each test file uses a part, hence `dead_code` is allowed here.
#![allow(dead_code)]

pub mod meshio;

use std::path::{Path, PathBuf};

/// A fresh (empty, existing) directory for the files of test `name`, under the
/// system temp dir; kept after the test for inspection.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("psmpm-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path under the system temp dir that does not exist yet (so that a test can
/// check that the code under test creates it), removed with its contents on drop.
pub struct TempDir(PathBuf);

impl TempDir {
    /// The path for test `name`, emptied.
    pub fn new(name: &str) -> Self {
        let path =
            std::env::temp_dir().join(format!("psmpm-test-{}-tmp-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        TempDir(path)
    }

    /// The same, created.
    pub fn created(name: &str) -> Self {
        let dir = TempDir::new(name);
        std::fs::create_dir_all(&dir.0).unwrap();
        dir
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// A file in it.
    pub fn join(&self, file: impl AsRef<Path>) -> PathBuf {
        self.0.join(file)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
