//! `mpm-cli project`: output formats, the Gmsh path, and every kind of bad input.

#[path = "../common/cli.rs"]
mod common_cli;

use common_cli::cli;
use serde_json::Value;

fn data(name: &str) -> String {
    format!("{}/../tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Runs with arguments that must fail with exit status 2 and a one-line message.
fn input_error(args: &[&str]) -> String {
    let out = cli().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "args {args:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "not one line: {stderr}"
    );
    assert!(stderr.starts_with("error: "), "{stderr}");
    stderr
}

fn round(v: &Value, digits: usize) -> Value {
    match v {
        Value::Number(n) if n.is_f64() => {
            let x = n.as_f64().unwrap();
            Value::String(format!("{:.*e}", digits - 1, x))
        }
        Value::Array(a) => Value::Array(a.iter().map(|x| round(x, digits)).collect()),
        Value::Object(o) => Value::Object(
            o.iter()
                .filter(|(k, _)| k.as_str() != "seconds")
                .map(|(k, x)| (k.clone(), round(x, digits)))
                .collect(),
        ),
        other => other.clone(),
    }
}

#[test]
fn json_rows_have_the_documented_keys_and_orders() {
    let out = cli()
        .args(["project", "--levels", "3", "--format", "json"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let rows: Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 12);
    for r in rows {
        for key in [
            "basis",
            "mass",
            "n",
            "functions",
            "error",
            "error_dx",
            "order",
            "order_dx",
            "seconds",
        ] {
            assert!(r.get(key).is_some(), "missing {key}");
        }
    }
    assert!(rows[0]["order"].is_null());
    let ps_consistent_last = &rows[2];
    assert_eq!(ps_consistent_last["basis"], "ps");
    assert!(ps_consistent_last["order"].as_f64().unwrap() > 3.0);
    insta::assert_json_snapshot!(round(&Value::Array(rows.clone()), 3));
}

#[test]
fn table_has_a_header_and_one_row_per_level() {
    let out = cli()
        .args([
            "project",
            "--basis",
            "pl",
            "--mass",
            "consistent",
            "--levels",
            "2",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3);
    assert!(lines[0].split_whitespace().eq([
        "basis",
        "mass",
        "n",
        "functions",
        "error",
        "order",
        "error_dx",
        "order_dx",
        "seconds"
    ]));
    assert!(lines[2]
        .split_whitespace()
        .take(4)
        .eq(["pl", "consistent", "9", "81"]));
}

#[test]
fn projects_on_a_gmsh_mesh() {
    let mesh = data("square_hole.msh");
    let out = cli()
        .args([
            "project",
            "--basis",
            "ps,pl",
            "--mass",
            "consistent",
            "--mesh",
            &mesh,
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
    let rows: Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        assert!(r["n"].is_null() && r["order"].is_null());
        assert!(r["error"].as_f64().unwrap() < 0.05);
    }
    // PS is more accurate than PL on the same mesh.
    assert!(rows[0]["error"].as_f64().unwrap() < rows[1]["error"].as_f64().unwrap());
}

#[test]
fn bad_input_is_a_one_line_error_with_status_2() {
    assert!(input_error(&["project", "--basis", "ps,cubic"]).contains("unknown basis `cubic`"));
    assert!(input_error(&["project", "--basis", "bspline"]).contains("one-dimensional"));
    assert!(
        input_error(&["project", "--mass", "partial"]).contains("unknown mass option `partial`")
    );
    assert!(input_error(&["project", "--levels", "0"]).contains("between 1 and 6"));
    assert!(input_error(&["project", "--levels", "9"]).contains("got 9"));
    let missing = input_error(&["project", "--mesh", "/no/such/file.msh"]);
    assert!(missing.contains("/no/such/file.msh"), "{missing}");
    let dir = std::env::temp_dir().join(format!("psmpm-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.msh");
    std::fs::write(
        &bad,
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n2 one 0 0\n$EndNodes\n",
    )
    .unwrap();
    let msg = input_error(&["project", "--mesh", bad.to_str().unwrap()]);
    assert!(msg.contains("bad.msh:7:") && msg.contains("`one`"), "{msg}");
    let binary = dir.join("binary.msh");
    std::fs::write(&binary, "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n").unwrap();
    assert!(input_error(&["project", "--mesh", binary.to_str().unwrap()]).contains("binary"));
    // Unknown flags follow clap's conventions (status 2, usage on stderr).
    let out = cli().args(["project", "--bogus"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}
