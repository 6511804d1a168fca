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
