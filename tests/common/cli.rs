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
