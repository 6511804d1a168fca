//! `mpm-cli stability`: the matrix of cases × mass strategies, its JSON structure,
//! the cells known to be stable, determinism across threads, and bad arguments.

#[path = "../common/cli.rs"]
mod common_cli;

use common_cli::cli;
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let out = cli().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

const QUICK: [&str; 4] = [
    "b2-nx5",
    "b4-ppe16-h0.25",
    "b5b-blocks-1x8-p12",
    "free-incline",
];

#[test]
fn quick_matrix_with_lumped_and_partial() {
    let cells = json(&[
        "stability",
        "--cases",
        "quick",
        "--mass",
        "lumped,partial",
        "--format",
        "json",
    ]);
    let cells = cells.as_array().unwrap();
    // Cases in order, the strategies in the order given within each case.
    let order: Vec<(String, String)> = cells
        .iter()
        .map(|c| {
            (
                c["case"].as_str().unwrap().to_string(),
                c["mass"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    let expected: Vec<(String, String)> = QUICK
        .iter()
        .flat_map(|case| ["lumped", "partial"].map(|m| (case.to_string(), m.to_string())))
        .collect();
    assert_eq!(order, expected);
    for c in cells {
        for key in [
            "case",
            "mass",
            "stable",
            "completed",
            "reason",
            "measure",
            "error",
            "roughness",
            "roughness_rms",
            "max_condition",
            "lumped_rows",
            "deactivated",
            "functions",
            "particles",
            "steps",
            "dt",
            "t_end",
            "energy_growth",
            "us_per_step",
            "seconds",
        ] {
            assert!(c.get(key).is_some(), "{}: missing {key}", c["case"]);
        }
        // A reason exactly when the cell is not stable; every cell has a condition
        // estimate (the case files ask for it).
        assert_eq!(c["stable"].as_bool().unwrap(), c["reason"].is_null(), "{c}");
        assert!(c["max_condition"].as_f64().unwrap() >= 1.0, "{c}");
    }
    let cell = |case: &str, mass: &str| {
        cells
            .iter()
            .find(|c| c["case"] == case && c["mass"] == mass)
            .unwrap()
    };
    // Nothing is under-supported in B2 and B4: both strategies are stable.
    for case in ["b2-nx5", "b4-ppe16-h0.25"] {
        for mass in ["lumped", "partial"] {
            let c = cell(case, mass);
            assert_eq!(c["stable"], true, "{c}");
            assert!(c["error"].as_f64().unwrap().is_finite(), "{c}");
        }
    }
    assert_eq!(cell("b2-nx5", "partial")["measure"], "E_u");
    // Roughness is a column measure.
    assert!(cell("b2-nx5", "partial")["roughness_rms"].is_null());
    assert_eq!(cell("b4-ppe16-h0.25", "lumped")["measure"], "rms-position");
    // Partial lumping has nothing to lump there and equals the consistent mass
    // (docs/results.md: E_u 3.62e-6 and RMS 5.06e-4).
    let e = cell("b2-nx5", "partial")["error"].as_f64().unwrap();
    assert!((e - 3.62e-6).abs() < 0.01e-6, "{e}");
    let e = cell("b4-ppe16-h0.25", "partial")["error"].as_f64().unwrap();
    assert!((e - 5.06e-4).abs() < 0.01e-4, "{e}");
    assert_eq!(cell("b4-ppe16-h0.25", "partial")["lumped_rows"], 0);
    // The column with the empty band: lumped and partial run to the end (their
    // condition estimate breaks the verdict's bound), with a roughness of σ_yy.
    for mass in ["lumped", "partial"] {
        let c = cell("b5b-blocks-1x8-p12", mass);
        assert_eq!(c["completed"], true, "{c}");
        assert!((c["t_end"].as_f64().unwrap() - 2.5).abs() < 1e-3, "{c}");
        assert!(c["roughness"].as_f64().unwrap() > 0.0, "{c}");
        // Over the run, the roughness is lower than at the end (it grows as the
        // undamped column rings) but not zero.
        let rms = c["roughness_rms"].as_f64().unwrap();
        assert!(rms > 0.0 && rms < c["roughness"].as_f64().unwrap(), "{c}");
        assert!(c["lumped_rows"].as_u64().unwrap() > 0, "{c}");
    }
    // The frictionless slide: lumped follows ½ g sin θ t² (relative error).
    let c = cell("free-incline", "lumped");
    assert_eq!(c["measure"], "slide");
    assert_eq!(c["completed"], true, "{c}");
    assert!(c["error"].as_f64().unwrap() < 1e-2, "{c}");
}

#[test]
fn the_same_cells_on_one_and_two_threads_and_in_every_format() {
    let args = [
        "stability",
        "--cases",
        "b4-ppe16-h0.25,b2-nx2",
        "--mass",
        "consistent,partial:0.05",
        "--format",
        "json",
    ];
    let strip = |mut v: Value| {
        for c in v.as_array_mut().unwrap() {
            let c = c.as_object_mut().unwrap();
            c.remove("seconds");
            c.remove("us_per_step");
        }
        v
    };
    let one = strip(json(&[&args[..], &["--jobs", "1"]].concat()));
    let two = strip(json(&[&args[..], &["--jobs", "2"]].concat()));
    assert_eq!(one, two);
    // Rows in case order (the order of the directory, not of the list).
    assert_eq!(one[0]["case"], "b2-nx2");
    assert_eq!(one[1]["mass"], "partial:0.05");
    assert_eq!(one[3]["case"], "b4-ppe16-h0.25");
    let table = cli()
        .args(["stability", "--cases", "b2-nx2", "--mass", "lumped"])
        .output()
        .unwrap();
    let table = String::from_utf8(table.stdout).unwrap();
    let header: Vec<&str> = table.lines().next().unwrap().split_whitespace().collect();
    assert_eq!(header[..5], ["case", "basis", "mass", "stable", "error"]);
    let csv = cli()
        .args([
            "stability",
            "--cases",
            "b2-nx2",
            "--mass",
            "lumped",
            "--format",
            "csv",
        ])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8(csv.stdout).unwrap().lines().count(), 2);
}

#[test]
fn unknown_cases_and_strategies_are_input_errors() {
    for (args, message) in [
        (
            vec!["stability", "--cases", "b9"],
            "error: --cases: unknown case `b9` (known: quick, all, b2-nx2,",
        ),
        (
            vec!["stability", "--mass", "heavy"],
            "error: --mass: unknown mass strategy `heavy`",
        ),
    ] {
        let out = cli().args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(stderr.starts_with(message), "{stderr}");
    }
}

/// A strategy that deactivates every function carrying a sliding block (the
/// thesis' threshold 1e-2 on `M_ii`, above every row of this light block) left it
/// standing still with its energy bounded, caught only by the slide error (1.00).
/// The run now stops at its first step and says why, while the default slides.
#[test]
fn a_block_that_does_not_slide_is_not_stable() {
    let cells = json(&[
        "stability",
        "--cases",
        "free-incline",
        "--mass",
        "deactivate:0.01,default",
        "--format",
        "json",
    ]);
    let cells = cells.as_array().unwrap();
    let (frozen, default) = (&cells[0], &cells[1]);
    assert_eq!(frozen["measure"], "slide");
    assert_eq!(frozen["completed"], false, "{frozen}");
    assert_eq!(frozen["stable"], false, "{frozen}");
    assert!(
        frozen["reason"].as_str().unwrap().contains(
            "step 1: the mass system could not be solved (every function with mass is below the deactivation threshold 0.01"
        ),
        "{frozen}"
    );
    assert_eq!(default["stable"], true, "{default}");
    assert!(default["error"].as_f64().unwrap() < 1e-3, "{default}");
}

/// `--basis ps,pl` runs each case with both bases on its own mesh and particles,
/// basis by basis within the case; the JSON names each cell's basis, and a name
/// that is no basis is refused.
#[test]
fn a_case_runs_with_each_basis_given() {
    let cells = json(&[
        "stability",
        "--cases",
        "b2-nx2",
        "--basis",
        "ps,pl",
        "--mass",
        "lumped",
        "--format",
        "json",
    ]);
    let cells = cells.as_array().unwrap();
    let bases: Vec<&str> = cells.iter().map(|c| c["basis"].as_str().unwrap()).collect();
    assert_eq!(bases, ["ps", "pl"]);
    assert_eq!(cells[0]["particles"], cells[1]["particles"]);
    assert!(cells[0]["functions"].as_u64() > cells[1]["functions"].as_u64());
    let out = cli()
        .args(["stability", "--cases", "b2-nx2", "--basis", "quartic"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--basis"), "{err}");
}
