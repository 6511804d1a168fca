//! `mpm-cli run`: JSON lines and summary, the table, and bad input.

use assert_cmd::Command;
use serde_json::Value;

fn cli() -> Command {
    Command::cargo_bin("mpm-cli").unwrap()
}

#[test]
fn json_lines_then_a_summary_with_the_documented_keys() {
    let out = cli()
        .args([
            "run",
            "vibrating-bar",
            "--t-end",
            "0.5",
            "--diag-every",
            "250",
            "--format",
            "json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["step"], 250);
    assert_eq!(lines[1]["step"], 500);
    let summary = &lines[2];
    for key in [
        "scene",
        "basis",
        "mass",
        "functions",
        "particles",
        "steps",
        "t_end",
        "error",
        "max_condition",
        "max_lumped_rows",
        "energy_initial",
        "energy_final",
        "stable",
        "seconds",
    ] {
        assert!(summary.get(key).is_some(), "missing {key}");
    }
    assert_eq!(summary["functions"], 42);
    assert_eq!(summary["steps"], 500);
    assert_eq!(summary["stable"], true);
    let e = summary["error"].as_f64().unwrap();
    insta::assert_snapshot!(format!(
        "error={e:.4e} energy_final={:.6e} kinetic@250={:.6e}",
        summary["energy_final"].as_f64().unwrap(),
        lines[0]["kinetic"].as_f64().unwrap()
    ));
}

#[test]
fn table_and_summary_for_a_1d_scene() {
    let out = cli()
        .args([
            "run",
            "column-small-1d",
            "--basis",
            "pl1d",
            "--blocks",
            "16x1",
            "--t-end",
            "0.05",
            "--diag-every",
            "100",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.lines().next().unwrap().split_whitespace().eq([
        "step",
        "time",
        "kinetic",
        "strain",
        "potential",
        "total",
        "max_speed",
        "active",
        "lumped",
        "condition"
    ]));
    assert!(text.contains("column-small-1d · pl1d · consistent mass · 17 functions"));
    assert!(text.contains("stable"));
}

fn input_error(args: &[&str]) -> String {
    let out = cli().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"));
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    stderr
}

#[test]
fn bad_input_is_a_one_line_error_with_status_2() {
    assert!(input_error(&["run", "pendulum"]).contains("known: vibrating-bar"));
    assert!(input_error(&["run", "vibrating-bar", "--basis", "bspline"]).contains("1D"));
    assert!(input_error(&["run", "vibrating-bar", "--basis", "cubic"]).contains("unknown basis"));
    assert!(
        input_error(&["run", "vibrating-bar", "--mass", "heavy"]).contains("unknown mass strategy")
    );
    assert!(input_error(&["run", "vibrating-bar", "--blocks", "4by1"]).contains("--blocks"));
    assert!(input_error(&["run", "vibrating-bar", "--blocks", "0x1"]).contains("blocks"));
    assert!(input_error(&["run", "vibrating-bar", "--dt=-1"]).contains("dt"));
    assert!(input_error(&["run", "vibrating-bar", "--t-end", "0"]).contains("t_end"));
}

#[test]
fn a_particle_leaving_the_mesh_is_a_numerical_failure_with_status_1() {
    // A huge time step throws the bar's particles out of the mesh in one step.
    let out = cli()
        .args(["run", "vibrating-bar", "--dt", "100", "--t-end", "1000"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("step ") && stderr.contains("try"),
        "{stderr}"
    );
}

#[test]
fn scene_files_run_and_bad_ones_name_file_line_and_column() {
    let file = format!(
        "{}/../scenes/column-partial.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = cli()
        .args(["run", &file, "--t-end", "0.01", "--diag-every", "0"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("column-small · ps · partial mass · 249 functions"),
        "{text}"
    );
    let dir = std::env::temp_dir().join(format!("psmpm-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &str); 8] = [
        (
            "scene = \"vibrating-bar\"\nbasis = \"ps\"\ncolour = \"red\"\n",
            ":3:1: unknown field `colour`",
        ),
        (
            "scene = \"pendulum\"\n",
            ":1:9: scene: unknown scene `pendulum`",
        ),
        (
            "scene = \"vibrating-bar\"\n\ndt = \"small\"\n",
            ":3:6: invalid type",
        ),
        (
            "scene = \"vibrating-bar\"\ndt = -1.0\n",
            ":2:6: dt must be positive",
        ),
        (
            "scene = \"vibrating-bar\"\nbasis = \"bspline\"\n",
            ":2:9: basis `bspline` is 1D",
        ),
        (
            "scene = \"vibrating-bar\"\nblocks = [0, 1]\n",
            ":2:10: blocks must be between",
        ),
        (
            "scene = \"vibrating-bar\"\nmass = \"heavy\"\n",
            ":2:8: mass: unknown mass strategy",
        ),
        ("scene = \"vibrating-bar\"\nblocks = [4, 1\n", ":2:"),
    ];
    for (k, (text, expected)) in cases.iter().enumerate() {
        let path = dir.join(format!("bad{k}.toml"));
        std::fs::write(&path, text).unwrap();
        let msg = input_error(&["run", path.to_str().unwrap()]);
        assert!(
            msg.contains(&format!("bad{k}.toml{expected}")),
            "case {k}: {msg}"
        );
    }
}
