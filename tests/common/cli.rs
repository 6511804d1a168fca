//! Calling `mpm-cli` from the CLI tests (`tests/cli/*.rs`, through `#[path]`).
#![allow(dead_code)]

use assert_cmd::Command;
use std::time::Duration;

/// The `mpm-cli` binary of this build, with a time limit: a hang is a failure,
/// not a stuck test.
pub fn cli() -> Command {
    let mut c = Command::cargo_bin("mpm-cli").unwrap();
    c.timeout(Duration::from_secs(300));
    c
}

/// The path of case `name` of `scenes/stability/` (a file the CLI reads).
pub fn stability_scene(name: &str) -> String {
    format!(
        "{}/../scenes/stability/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// Asserts that a command succeeded, showing its stderr if not.
pub fn assert_success(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A user's damped 1D column under its weight (B-spline, 16 elements, α = 0.6), with
/// the `column-equilibrium` reference: `converge` and `--out` tests start from it.
pub const DAMPED_COLUMN_1D: &str = r#"name = "my-column-1d"
dim = 1
basis = "bspline"
[mesh]
kind = "interval"
x = [0.0, 1.0]
elements = 16
[material]
young = 1e6
density = 1000.0
[[body]]
min = [0.0]
max = [1.0]
per_block = [4]
[[boundary]]
tag = "left"
fix = ["x"]
[[effect]]
kind = "gravity"
g = [-10.0]
[[effect]]
kind = "damping"
alpha = 0.6
[time]
courant = 0.5
t_end = 2.0
[reference]
kind = "column-equilibrium"
"#;

/// A scene file written to a fresh directory of its own (named after `name` and
/// the process), removed with the directory when dropped.
pub struct SceneFile {
    dir: std::path::PathBuf,
    /// The file, `FILE_NAME.toml` in the directory.
    pub path: std::path::PathBuf,
}

impl SceneFile {
    /// Writes `text` to `name.toml` in a new directory `psmpm-NAME-PID`.
    pub fn new(name: &str, text: &str) -> SceneFile {
        let dir = std::env::temp_dir().join(format!("psmpm-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        SceneFile { dir, path }
    }

    /// The file's path as text, for an argument list.
    pub fn arg(&self) -> &str {
        self.path.to_str().unwrap()
    }
}

impl Drop for SceneFile {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.dir).ok();
    }
}
