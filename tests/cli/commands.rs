//! `scenes`, `scene show`, `compare`, `converge`, `basis plot` and the cache of
//! `reproduce`: output pinned with snapshots (wall times removed), round trips, and
//! determinism across threads.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/cli.rs"]
mod common_cli;

use common::temp_dir;
use common_cli::{assert_success, cli, SceneFile, DAMPED_COLUMN_1D};
use serde_json::Value;

fn stdout(args: &[&str]) -> String {
    let out = cli().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Drops the `seconds` values (the only machine-dependent numbers) from JSON.
fn without_seconds(mut v: Value) -> Value {
    match &mut v {
        Value::Object(map) => {
            map.remove("seconds");
            for (_, x) in map.iter_mut() {
                *x = without_seconds(x.take());
            }
        }
        Value::Array(items) => {
            for x in items.iter_mut() {
                *x = without_seconds(x.take());
            }
        }
        _ => {}
    }
    v
}

/// Rounds every float to 4 significant digits so that snapshots are stable.
fn rounded(v: Value) -> Value {
    match v {
        Value::Number(n) if n.is_f64() => {
            let x = n.as_f64().unwrap();
            // Below 1e-12: the round-off of an exact zero (the sideways
            // displacement of a bar that moves along its axis), whose digits
            // follow the order of the sums, not the method.
            let x = if x.abs() < 1e-12 { 0.0 } else { x };
            let r: f64 = format!("{x:.3e}").parse().unwrap();
            serde_json::json!(r)
        }
        Value::Object(map) => {
            Value::Object(map.into_iter().map(|(k, x)| (k, rounded(x))).collect())
        }
        Value::Array(items) => Value::Array(items.into_iter().map(rounded).collect()),
        other => other,
    }
}

#[test]
fn scenes_lists_every_builtin_in_every_format() {
    let table = stdout(&["scenes"]);
    insta::assert_snapshot!("scenes_table", table);
    let json: Value = serde_json::from_str(&stdout(&["scenes", "--format", "json"])).unwrap();
    let names: Vec<&str> = json
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    let expected: Vec<&str> = psmpm::scene::BUILTIN.iter().map(|b| b.0).collect();
    assert_eq!(names, expected);
    let csv = stdout(&["scenes", "--format", "csv"]);
    assert_eq!(csv.lines().count(), expected.len() + 1);
    assert!(csv.starts_with("name,dim,basis,error,description\n"));
}

#[test]
fn scene_show_prints_the_scene_file() {
    insta::assert_snapshot!(
        "scene_show_column_small",
        stdout(&["scene", "show", "column-small"])
    );
    // A file is shown normalised (its own comments dropped, defaults written out)
    // and annotated.
    let dir = temp_dir("show-file");
    let path = dir.join("c.toml");
    std::fs::write(&path, stdout(&["scene", "show", "column-small"])).unwrap();
    insta::assert_snapshot!(
        "scene_show_normalised",
        stdout(&["scene", "show", path.to_str().unwrap()])
    );
}

#[test]
fn scene_show_round_trips_for_every_builtin_scene() {
    let dir = temp_dir("show");
    for (name, _, _) in psmpm::scene::BUILTIN {
        let text = stdout(&["scene", "show", name]);
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, &text).unwrap();
        // `run` accepts it back, and it is the same scene.
        let back = psmpm::scene::Scene::from_toml(&text, "shown").unwrap();
        assert_eq!(back, psmpm::scene::Scene::builtin(name).unwrap(), "{name}");
        // A normalised file shows as TOML that parses to the same scene again.
        let again = stdout(&["scene", "show", path.to_str().unwrap()]);
        assert_eq!(
            psmpm::scene::Scene::from_toml(&again, "again").unwrap(),
            back,
            "{name}"
        );
    }
    let out = cli()
        .args([
            "run",
            dir.join("vibrating-bar-1d.toml").to_str().unwrap(),
            "--t-end",
            "0.01",
            "--diag-every",
            "0",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn compare_ps_and_pl_side_by_side_identically_on_one_and_two_threads() {
    let args = [
        "compare",
        "vibrating-bar",
        "--basis",
        "ps,pl",
        "--t-end",
        "1",
        "--condition",
        "--format",
        "json",
    ];
    let one = without_seconds(
        serde_json::from_str(&stdout(&[&args[..], &["--jobs", "1"]].concat())).unwrap(),
    );
    let two = without_seconds(
        serde_json::from_str(&stdout(&[&args[..], &["--jobs", "2"]].concat())).unwrap(),
    );
    // Bit-identical results whatever the thread count.
    assert_eq!(one, two);
    let rows = one.as_array().unwrap();
    assert_eq!(rows[0]["basis"], "ps");
    assert_eq!(rows[0]["functions"], 42);
    assert_eq!(rows[1]["basis"], "pl");
    assert_eq!(rows[1]["functions"], 38);
    insta::assert_json_snapshot!("compare_vibrating_bar", rounded(one));
    let table = stdout(&[
        "compare",
        "vibrating-bar",
        "--basis",
        "ps,pl",
        "--t-end",
        "1",
    ]);
    let header: Vec<&str> = table.lines().next().unwrap().split_whitespace().collect();
    assert_eq!(
        header,
        [
            "basis",
            "mass",
            "functions",
            "particles",
            "dt",
            "steps",
            "error",
            "max_condition",
            "lumped_rows",
            "energy_drift",
            "stable",
            "seconds"
        ]
    );
    // The scene tracks a particle: its displacement at the end, per variant,
    // in a table of its own below (the same value as tracked.csv's last row).
    let tracked = table
        .split("displacement of the tracked particle that started at (12.37, 1.167), at the end of each run")
        .nth(1)
        .unwrap_or_else(|| panic!("{table}"));
    let rows: Vec<Vec<&str>> = tracked
        .lines()
        .skip(2)
        .take(2)
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(rows[0][0], "ps", "{table}");
    assert_eq!(rows[1][0], "pl", "{table}");
    for row in &rows {
        let u_x: f64 = row[2].parse().unwrap();
        assert!(u_x.is_finite() && u_x != 0.0, "{table}");
        assert_eq!(row[4], "1", "{table}");
    }
    let csv = stdout(&[
        "compare",
        "vibrating-bar",
        "--basis",
        "ps,pl",
        "--t-end",
        "1",
        "--format",
        "csv",
    ]);
    // The table's columns, then the verdict, the time reached, the pieces, the
    // tracked particle and why a run stopped.
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header.len(), 22, "{csv}");
    assert_eq!(
        header[12..],
        [
            "verdict",
            "t_end",
            "pieces_start",
            "pieces_end",
            "stray_end",
            "tracked_x0",
            "tracked_y0",
            "tracked_ux",
            "tracked_uy",
            "failure"
        ]
    );
    let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(records.len(), 2, "{csv}");
    for (record, row) in records.iter().zip(&rows) {
        assert_eq!(&record[12], "yes", "{csv}");
        assert_eq!(record[13].parse::<f64>().unwrap(), 1.0, "{csv}");
        assert_eq!((&record[14], &record[15]), ("1", "1"), "{csv}");
        let x0: [f64; 2] = [record[17].parse().unwrap(), record[18].parse().unwrap()];
        assert!(
            (x0[0] - 12.37).abs() < 1e-2 && (x0[1] - 1.167).abs() < 1e-3,
            "{csv}"
        );
        // The table's displacement, in full.
        let u_x: f64 = record[19].parse().unwrap();
        let shown: f64 = row[2].parse().unwrap();
        assert!((u_x - shown).abs() <= 1e-3 * shown.abs(), "{csv}");
        assert_eq!(&record[21], "", "{csv}");
    }
}

#[test]
fn converge_prints_levels_orders_and_writes_its_plots() {
    let dir = temp_dir("converge");
    let json = stdout(&[
        "converge",
        "vibrating-bar-1d",
        "--levels",
        "3",
        "--t-end",
        "0.02",
        "--dt",
        "1e-5",
        "--particles",
        "16x1",
        "--format",
        "json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let study: Value = without_seconds(serde_json::from_str(&json).unwrap());
    assert_eq!(study["against"], "exact");
    let rows = study["levels"].clone();
    for row in rows.as_array().unwrap() {
        for key in [
            "basis",
            "level",
            "h",
            "functions",
            "particles",
            "error",
            "order",
        ] {
            assert!(row.get(key).is_some(), "missing {key}");
        }
    }
    // Orders: B-spline about 3, 1D PL about 2 (the B2 bar in 1D).
    let order = |basis: &str, level: u64| {
        rows.as_array()
            .unwrap()
            .iter()
            .find(|r| r["basis"] == basis && r["level"] == level)
            .unwrap()["order"]
            .as_f64()
            .unwrap()
    };
    assert!(order("bspline", 2) > 2.7, "{}", order("bspline", 2));
    assert!(
        (1.8..2.3).contains(&order("pl1d", 2)),
        "{}",
        order("pl1d", 2)
    );
    insta::assert_json_snapshot!("converge_vibrating_bar_1d", rounded(rows));
    for file in [
        "converge.csv",
        "converge.json",
        "error-vs-h.svg",
        "work-precision.svg",
    ] {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(!text.is_empty(), "{file}");
        if file.ends_with(".svg") {
            assert!(
                text.contains("BSPLINE") && text.contains("PL1D"),
                "{file}: legend"
            );
            // One data line per basis, in the first two series colours.
            for colour in ["#1F77B4", "#FF7F0E"] {
                let lines = text
                    .split("<polyline")
                    .skip(1)
                    .filter(|l| l.contains(&format!("stroke=\"{colour}\"")))
                    .count();
                assert_eq!(lines, 1, "{file}: {colour}");
            }
            assert!(
                !text.contains("stroke=\"#2CA02C\""),
                "{file}: a third curve"
            );
            // Against h, a grey guide of each basis's theoretical slope (3 for the
            // B-spline, 2 for PL1D) through its finest level; none against time.
            let guides = text
                .split("<polyline")
                .skip(1)
                .filter(|l| l.contains("stroke=\"#000000\"") && l.contains("opacity=\"0.4\""))
                .count();
            let against_h = file == "error-vs-h.svg";
            assert_eq!(guides, if against_h { 2 } else { 0 }, "{file}: guides");
            assert_eq!(
                text.contains("slope 3 (BSPLINE reference)")
                    && text.contains("slope 2 (PL1D reference)"),
                against_h,
                "{file}: guide legend"
            );
        }
    }
    let table = stdout(&[
        "converge",
        "vibrating-bar-1d",
        "--levels",
        "2",
        "--t-end",
        "0.02",
    ]);
    assert!(table.starts_with("  basis  level"), "{table}");
}

/// `docs/results.md` (B4): the ladder's command, cut to two steps, keeps about
/// 1000 particles per element as h halves (the particles double per axis).
#[test]
fn the_b4_ladder_keeps_its_particles_per_element() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/studies/b4-ladder.toml"
    );
    let json = stdout(&[
        "converge",
        scene,
        "--levels",
        "2",
        "--basis",
        "ps",
        "--t-end",
        "5e-5",
        "--threads",
        "1",
        "--target-error",
        "1",
        "--format",
        "json",
    ]);
    let study: Value = serde_json::from_str(&json).unwrap();
    // Every level is below an error of 1 after two steps: reached at the first.
    assert_eq!(study["target"]["error"], 1.0);
    assert_eq!(study["target"]["reaches"][0]["basis"], "ps");
    assert_eq!(study["target"]["reaches"][0]["how"], "at most");
    let rows = study["levels"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    let get = |r: &Value, k: &str| r[k].as_f64().unwrap();
    assert_eq!(get(&rows[0], "particles"), 65536.0);
    assert_eq!(get(&rows[1], "particles"), 262144.0);
    assert_eq!(get(&rows[0], "functions"), 123.0);
    assert_eq!(get(&rows[1], "functions"), 426.0);
    // Particles per function (and so per element) about the same on both levels.
    let per_function = |r: &Value| get(r, "particles") / get(r, "functions");
    let ratio = per_function(&rows[1]) / per_function(&rows[0]);
    assert!((0.8..1.25).contains(&ratio), "{ratio}");
}

/// README: `converge vibrating-bar-1d --levels 4` used to end with a negative order
/// and no word of why. The study now measures why at the level where an order falls.
#[test]
fn converge_explains_a_falling_order_with_two_probes() {
    let json = stdout(&[
        "converge",
        "vibrating-bar-1d",
        "--levels",
        "4",
        "--format",
        "json",
    ]);
    let study: Value = serde_json::from_str(&json).unwrap();
    let diagnoses = study["diagnoses"].as_array().unwrap();
    let of = |basis: &str| diagnoses.iter().find(|d| d["basis"] == basis).unwrap();
    for basis in ["bspline", "pl1d"] {
        let d = of(basis);
        assert_eq!(d["level"], 3, "{d}");
        // Half the time step changes nothing; twice the particles halves the error.
        let half_dt = d["half_dt"].as_f64().unwrap();
        let double = d["double_particles"].as_f64().unwrap();
        assert!((half_dt - 1.0).abs() < 0.05, "{d}");
        assert!(double < 0.6, "{d}");
        assert!(
            d["verdict"]
                .as_str()
                .unwrap()
                .contains("particles per element limit"),
            "{d}"
        );
    }
    let table = stdout(&["converge", "vibrating-bar-1d", "--levels", "4"]);
    assert!(
        table.contains("pl1d level 3: the order falls to -2.46")
            && table.contains("`--particle-growth 2`")
            && table.contains("crossing element edges"),
        "{table}"
    );
}

/// A teacher's 2D bar (1 × 0.125, E = 100, ρ = 1, ν = 0, the vibrating-bar
/// reference): at fixed particles per element PS's error stops falling with h (the
/// particle quadrature: 3.66e-7, 2.54e-7, order 0.5), and `--particle-growth 2`,
/// doubling the particles per element along each axis per level, shows its order
/// (3.66e-7, 3.25e-8: 3.5) and PL's (2.1). Out of range, the flag and the scene key
/// are refused by name.
#[test]
fn converge_grows_the_particles_per_element_when_asked() {
    let bar = SceneFile::new(
        "bar-2d",
        r#"name = "bar-2d"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 1.0]
y = [0.0, 0.125]
blocks = [8, 1]
[material]
young = 100.0
poisson = 0.0
density = 1.0
[[body]]
min = [0.0, 0.0]
max = [1.0, 0.125]
per_block = [4, 4]
[initial_velocity]
kind = "exact"
[[boundary]]
tag = "left"
fix = ["x"]
[[boundary]]
tag = "right"
fix = ["x"]
[time]
dt = 1e-4
t_end = 0.1
[reference]
kind = "vibrating-bar"
v0 = 0.01
"#,
    );
    let orders = |extra: &[&str]| {
        let mut args = vec!["converge", bar.arg(), "--levels", "2", "--format", "json"];
        args.extend_from_slice(extra);
        let study: Value = serde_json::from_str(&stdout(&args)).unwrap();
        // PL at [4, 4] has half its particles on the block diagonals: the study's
        // diagnosis of PL's falling order names that first, as each level's
        // warning does.
        if extra.is_empty() {
            let pl: Vec<&Value> = study["diagnoses"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| d["basis"] == "pl")
                .collect();
            assert_eq!(pl.len(), 1, "{study}");
            assert!(
                pl[0]["verdict"]
                    .as_str()
                    .unwrap()
                    .starts_with("this level's particles start on element edges"),
                "{}",
                pl[0]
            );
        }
        let levels = study["levels"].as_array().unwrap().clone();
        let order = |basis: &str| {
            levels
                .iter()
                .find(|l| l["basis"] == basis && l["level"] == 1)
                .and_then(|l| l["order"].as_f64())
                .unwrap()
        };
        let particles: Vec<u64> = levels
            .iter()
            .filter(|l| l["basis"] == "ps")
            .map(|l| l["particles"].as_u64().unwrap())
            .collect();
        (order("ps"), order("pl"), particles)
    };
    let (ps, _, particles) = orders(&[]);
    assert!(ps < 1.0, "{ps}");
    assert_eq!(particles, [128, 512]);
    let (ps, pl, particles) = orders(&["--particle-growth", "2"]);
    assert!(ps > 3.0, "{ps}");
    assert!(pl > 1.8, "{pl}");
    assert_eq!(particles, [128, 2048]);
    let out = cli()
        .args(["converge", bar.arg(), "--particle-growth", "9"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("--particle-growth must be between 1 and 4, got 9"));
    let keyed = SceneFile::new(
        "bar-2d-keyed",
        &format!(
            "{}[study]\nparticle_growth = 5\n",
            std::fs::read_to_string(&bar.path).unwrap()
        ),
    );
    let out = cli().args(["converge", keyed.arg()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("study.particle_growth: must be a whole number from 1 to 4"),
        "{stderr}"
    );
}

/// A user's damped 1D column (`converge FILE --levels 4 --blocks 4x1 --t-end 1.0`):
/// pl1d's error jumps at level 3 (3.3e-2 to 4.7e-1, order −3.83). Half the time step
/// lowered it × 0.52, and the study said "the time step limits the error: a smaller
/// `courant`", but a quarter of the step gives × 0.54 (and an eighth, a sixteenth
/// × 0.49, × 0.45): the error does not fall with the step. The study now halves the
/// step twice before it blames the step.
#[test]
fn converge_blames_the_time_step_only_if_the_error_falls_with_it() {
    let dir = temp_dir("converge-step");
    let scene = dir.join("col1d.toml");
    std::fs::write(&scene, DAMPED_COLUMN_1D).unwrap();
    let json = stdout(&[
        "converge",
        scene.to_str().unwrap(),
        "--levels",
        "4",
        "--blocks",
        "4x1",
        "--t-end",
        "1.0",
        "--format",
        "json",
    ]);
    let study: Value = serde_json::from_str(&json).unwrap();
    let diagnoses = study["diagnoses"].as_array().unwrap();
    let d = diagnoses.iter().find(|d| d["basis"] == "pl1d").unwrap();
    assert_eq!(d["level"], 3, "{d}");
    let (half, quarter) = (
        d["half_dt"].as_f64().unwrap(),
        d["quarter_dt"].as_f64().unwrap(),
    );
    // One halving lowers the error, the next does not.
    assert!(half < 0.6 && quarter / half > 0.9, "{d}");
    let verdict = d["verdict"].as_str().unwrap();
    assert!(
        !verdict.contains("the time step limits the error")
            && verdict.starts_with("the error does not fall consistently with the step")
            && verdict.contains("a smaller one will not help"),
        "{verdict}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene of the user's own, without an exact solution: a block settling on a fixed
/// floor. Levels are measured against the finest one, and the output says so.
#[test]
fn converge_measures_a_scene_without_exact_solution_against_its_finest_level() {
    let dir = temp_dir("converge-finest");
    let scene = dir.join("settle.toml");
    std::fs::write(
        &scene,
        r#"name = "settle"
dim = 2
basis = "pl"
[mesh]
kind = "blocks"
x = [0.0, 1.0]
y = [0.0, 1.0]
blocks = [2, 2]
[material]
young = 1000.0
poisson = 0.3
density = 1.0
[[body]]
min = [0.0, 0.0]
max = [1.0, 0.5]
per_block = [4, 4]
[[boundary]]
tag = "bottom"
fix = ["x", "y"]
[[effect]]
kind = "gravity"
g = [0.0, -10.0]
[time]
courant = 0.4
t_end = 0.1
"#,
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let json = stdout(&[
        "converge", scene, "--basis", "pl", "--levels", "4", "--format", "json",
    ]);
    let study: Value = serde_json::from_str(&json).unwrap();
    assert_eq!(study["against"], "finest-level");
    let levels = study["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4);
    assert!(
        levels[3]["error"].is_null(),
        "the finest level is the reference"
    );
    let errors: Vec<f64> = levels[..3]
        .iter()
        .map(|l| l["error"].as_f64().unwrap())
        .collect();
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
    // PL converges at about second order in displacement on this smooth problem.
    let order = levels[2]["order"].as_f64().unwrap();
    assert!((1.5..2.6).contains(&order), "{order}");
    let table = stdout(&["converge", scene, "--basis", "pl", "--levels", "3"]);
    assert!(table.contains("E_u against the finest level"), "{table}");
    // Two levels cannot give an order without an exact solution.
    let out = cli()
        .args(["converge", scene, "--levels", "2"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--levels must be at least 3"),
        "{out:?}"
    );
}

#[test]
fn basis_plot_draws_the_ps_mesh_and_a_function() {
    let dir = temp_dir("basis");
    let mesh = dir.join("mesh.svg");
    let function = dir.join("function.svg");
    assert!(stdout(&["basis", "plot", "--out", mesh.to_str().unwrap()]).contains("39 functions"));
    stdout(&[
        "basis",
        "plot",
        "--function",
        "12",
        "--out",
        function.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&mesh).unwrap();
    assert!(text.contains("control triangles"));
    assert_eq!(
        text.matches("<polygon").count(),
        13,
        "one control triangle per vertex"
    );
    assert!(std::fs::read_to_string(&function).unwrap().contains("<svg"));
    let out = cli()
        .args([
            "basis",
            "plot",
            "--function",
            "39",
            "--overwrite",
            "--out",
            function.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("error: --function: basis function index 39 is out of range")
            && stderr.contains("the basis has 39 functions (indices below 39)"),
        "{stderr}"
    );
}

/// `basis plot` of a mesh above 5000 triangles says so and how to draw a part
/// (`--window`), where it wrote a 57 MB SVG; the window draws that part.
#[test]
fn basis_plot_of_a_large_mesh_asks_for_a_window_and_draws_it() {
    let dir = temp_dir("basis-window");
    let picture = dir.join("big.svg");
    // `basis plot ARGS --out PICTURE`.
    let plot = |args: &[&str]| {
        cli()
            .args(["basis", "plot"])
            .args(args)
            .arg("--out")
            .arg(&picture)
            .output()
            .unwrap()
    };
    let out = plot(&["--blocks", "40x40"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with(
            "error: 6400 triangles in view, more than the 5000 a picture shows readably"
        ) && stderr.contains("give --window X0,X1,Y0,Y1 within the mesh's [0, 40] × [0, 40]"),
        "{stderr}"
    );
    assert!(!picture.exists());
    assert!(stdout(&[
        "basis",
        "plot",
        "--blocks",
        "40x40",
        "--window",
        "10.5,12.5,20.5,21.5",
        "--out",
        picture.to_str().unwrap(),
    ])
    .contains("wrote"));
    assert!(std::fs::read_to_string(&picture)
        .unwrap()
        .contains("24 of 6400 triangles shown"));
    // A window that misses the mesh, one that holds too much, and a grid above
    // the whole picture's 64 blocks a side, drawn through a window.
    let out = plot(&["--blocks", "40x40", "--window", "50,60,0,1", "--overwrite"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.starts_with("error: --window: nothing to plot: no triangle of the mesh meets the window: the mesh spans [0, 40] × [0, 40]"),
        "{stderr}"
    );
    let out = plot(&["--blocks", "40x40", "--window", "0,40,0,36", "--overwrite"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.starts_with("error: --window: 5880 triangles in view")
            && stderr.contains("give a smaller window"),
        "{stderr}"
    );
    assert!(stdout(&[
        "basis",
        "plot",
        "--blocks",
        "100x100",
        "--window",
        "10,15.5,10,12",
        "--overwrite",
        "--out",
        picture.to_str().unwrap()
    ])
    .contains("wrote"));
    for (window, why) in [
        ("2,1,0,1", "X0 below X1 and Y0 below Y1"),
        ("0,1,0", "four numbers, not 3"),
        ("0,1,0,inf", "finite numbers"),
    ] {
        let out = plot(&["--window", window, "--overwrite"]);
        assert_eq!(out.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("--window must look like 0,2,0,1") && stderr.contains(why),
            "{stderr}"
        );
    }
}

/// `basis plot --out FILE` replaced an existing file without a word, where `run
/// --out` refuses a folder of an earlier run: it now refuses an existing file unless
/// `--overwrite` is given, and a directory always, before drawing anything.
#[test]
fn basis_plot_refuses_an_existing_file_without_overwrite() {
    let dir = temp_dir("basis-overwrite");
    let picture = dir.join("mine.svg");
    std::fs::write(&picture, "a picture of my own").unwrap();
    let plot = |extra: &[&str], out: &std::path::Path| {
        cli()
            .args(["basis", "plot", "--out"])
            .arg(out)
            .args(extra)
            .output()
            .unwrap()
    };
    let out = plot(&[], &picture);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        format!(
            "error: output file `{}` already exists; pass --overwrite to replace it, or choose another --out\n",
            picture.display()
        )
    );
    assert_eq!(
        std::fs::read_to_string(&picture).unwrap(),
        "a picture of my own"
    );
    let out = plot(&["--overwrite"], &picture);
    assert!(out.status.success(), "{out:?}");
    assert!(std::fs::read_to_string(&picture).unwrap().contains("<svg"));
    let out = plot(&["--overwrite"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("is a directory; choose another --out"),
        "{out:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `reproduce` chooses the UL-FEM cache directory from the environment (the library
/// takes it as an argument): `PSMPM_CACHE_DIR` (if non-empty), else
/// `XDG_CACHE_HOME/psmpm`, else `HOME/.cache/psmpm`, else none; the tables are the
/// same whether the reference is computed or read back.
#[test]
fn reproduce_caches_the_reference_where_the_environment_says() {
    let dir = temp_dir("cache");
    let (own, xdg, home) = (dir.join("own"), dir.join("xdg"), dir.join("home"));
    let figures = dir.join("figures");
    let run = |vars: &[(&str, &std::path::Path)]| {
        let mut cmd = cli();
        cmd.args(["reproduce", "b3", "--quick", "--format", "json", "--out"])
            .arg(&figures);
        for name in ["PSMPM_CACHE_DIR", "XDG_CACHE_HOME", "HOME"] {
            cmd.env_remove(name);
        }
        for (name, value) in vars {
            cmd.env(name, value);
        }
        let out = cmd.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let cached = |d: &std::path::Path| -> Vec<String> {
        std::fs::read_dir(d).map_or_else(
            |_| Vec::new(),
            |entries| {
                entries
                    .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                    .filter(|n| n.starts_with("ulfem-") && n.ends_with(".json"))
                    .collect()
            },
        )
    };
    let empty = std::path::Path::new("");
    let none = run(&[]);
    assert!(cached(&own).is_empty() && cached(&xdg.join("psmpm")).is_empty());
    let first = run(&[
        ("PSMPM_CACHE_DIR", &own),
        ("XDG_CACHE_HOME", &xdg),
        ("HOME", &home),
    ]);
    assert_eq!(cached(&own).len(), 1);
    assert!(cached(&xdg.join("psmpm")).is_empty() && cached(&home.join(".cache")).is_empty());
    let again = run(&[("PSMPM_CACHE_DIR", &own)]);
    let from_xdg = run(&[
        ("PSMPM_CACHE_DIR", empty),
        ("XDG_CACHE_HOME", &xdg),
        ("HOME", &home),
    ]);
    assert_eq!(cached(&xdg.join("psmpm")).len(), 1);
    let from_home = run(&[("HOME", &home)]);
    assert_eq!(cached(&home.join(".cache").join("psmpm")), cached(&own));
    for out in [&first, &again, &from_xdg, &from_home] {
        assert_eq!(out, &none);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `reproduce` writes figures only where `--out` says (nothing in the working
/// directory without it); its JSON cells are numbers, its CSV parses as CSV.
#[test]
fn reproduce_writes_figures_only_into_out_with_numbers_in_json_and_quoted_csv() {
    let dir = temp_dir("reproduce-out");
    let cwd = dir.join("cwd");
    std::fs::create_dir_all(&cwd).unwrap();
    let run = |args: &[&str]| {
        let out = cli()
            .current_dir(&cwd)
            .env("PSMPM_CACHE_DIR", dir.join("cache"))
            .args(["reproduce", "b3", "--quick"])
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let json: Value = serde_json::from_str(&run(&["--format", "json"])).unwrap();
    assert_eq!(
        std::fs::read_dir(&cwd).unwrap().count(),
        0,
        "files in the cwd"
    );
    assert_eq!(json["figures"], serde_json::json!([]));
    let table = &json["tables"][0];
    let row = table["rows"][0].as_array().unwrap();
    assert_eq!(row.len(), table["columns"].as_array().unwrap().len());
    assert_eq!(row[0], "ps");
    assert!(row[1].is_u64() && row[2].is_u64(), "{row:?}");
    // E_u: the unrounded number, not a string such as "6.63e-2".
    let e = row[3].as_f64().unwrap_or_else(|| panic!("{row:?}"));
    assert_ne!(format!("{e:.2e}").parse::<f64>().unwrap(), e);
    assert!(row[7].is_boolean(), "{row:?}");
    for row in table["rows"].as_array().unwrap() {
        for cell in row.as_array().unwrap() {
            if let Some(s) = cell.as_str() {
                assert!(s.parse::<f64>().is_err(), "a number as a string: {s}");
            }
        }
    }

    let figures = dir.join("figures");
    let csv_text = run(&["--format", "csv", "--out", figures.to_str().unwrap()]);
    assert_eq!(
        std::fs::read_dir(&cwd).unwrap().count(),
        0,
        "files in the cwd"
    );
    let svgs = std::fs::read_dir(&figures).unwrap().count();
    assert!(svgs > 0);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .from_reader(csv_text.as_bytes());
    let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let columns: Vec<&str> = table["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(records[0].iter().collect::<Vec<_>>(), columns);
    assert_eq!(records.len(), 1 + table["rows"].as_array().unwrap().len());
    assert!(records.iter().all(|r| r.len() == columns.len()));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `throughput` measures every variant at every size (the numbers are machine
/// dependent: only their presence and sense are checked, no timing is asserted).
#[test]
fn throughput_prints_rates_memory_and_the_scaling_exponent() {
    let json = stdout(&[
        "throughput",
        "--sizes",
        "1000,4000",
        "--variants",
        "pl:lumped,ps:default",
        "--steps",
        "2",
        "--threads",
        "1",
        "--format",
        "json",
    ]);
    let v: Value = serde_json::from_str(&json).unwrap();
    let rows = v["measurements"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for r in rows {
        assert_eq!(r["steps"], 2);
        assert!(r["particle_steps_per_second"].as_f64().unwrap() > 0.0);
        // Particles, their basis evaluations and the matrices take heap memory.
        let per = r["bytes_per_particle"].as_f64().unwrap();
        assert!(per > 100.0 && per < 1e5, "{r}");
    }
    // 1000 and 4000 particles round to 1 × 8 and 3 × 24 blocks of 64.
    assert_eq!(rows[0]["particles"], 512);
    assert_eq!(rows[1]["particles"], 4608);
    for s in v["scaling"].as_array().unwrap() {
        assert!(s["exponent"].as_f64().is_some(), "{s}");
    }
    let out = cli()
        .args(["throughput", "--variants", "bspline:lumped"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("the throughput scene is 2D"));
}

/// `throughput --sizes 1e7` rounds to 140 × 1120 blocks of 64 particles, above the
/// scenes' particle limit, and the error named `body[0]` of the internal scene after
/// the size had been accepted: the size is now checked up front and named.
#[test]
fn throughput_checks_its_sizes_against_the_particle_limit_up_front() {
    let error = |size: &str| {
        let out = cli()
            .args(["throughput", "--sizes", size, "--steps", "1"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{out:?}");
        String::from_utf8(out.stderr).unwrap()
    };
    assert_eq!(
        error("1e7"),
        "error: --sizes: 10000000 particles rounds to 10035200 (140 × 1120 blocks of 8 × 8), above the limit of 10000000 particles; give at most 9892352\n"
    );
    assert_eq!(
        error("2e7"),
        "error: --sizes: 20000000 particles is above the limit of 10000000 particles; give at most 9892352\n"
    );
    assert_eq!(
        error("50"),
        "error: --sizes: 50 particles is outside 100..=9892352\n"
    );
    assert_eq!(
        error("1"),
        "error: --sizes: 1 particle is outside 100..=9892352\n"
    );
}

/// `compare --courant 1.5` said `time.courant: …` without the flag that set it;
/// `run` names the flags (`FILE with --courant 1.5: time.courant: …`), and so does
/// `compare` now.
#[test]
fn compare_names_the_flag_of_a_set_up_error() {
    let out = cli()
        .args(["compare", "column-small-1d", "--courant", "1.5"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("error: column-small-1d with --courant 1.5: time.courant: 1.5 puts the time step at or above the critical step"),
        "{stderr}"
    );
}

/// A student's settling column whose finer PL levels stop before the end time with
/// the consistent mass (the top functions lose their support).
const STOPPING_COLUMN: &str = r#"
name = "stopping-column"
dim = 1
basis = "bspline"
[mesh]
kind = "interval"
x = [0.0, 10.0]
elements = 10
[material]
young = 1e4
density = 2.0
[[body]]
min = [0.0]
max = [10.0]
per_block = [6]
[[boundary]]
tag = "left"
fix = ["x"]
[[effect]]
kind = "gravity"
g = [-9.81]
[time]
courant = 0.4
t_end = 0.5
[reference]
kind = "column-self-weight"
"#;

#[test]
fn converge_gives_no_error_and_no_order_for_a_level_that_stopped_early() {
    let dir = temp_dir("converge-stopped");
    let scene = dir.join("column.toml");
    std::fs::write(&scene, STOPPING_COLUMN).unwrap();
    let out = cli()
        .args(["converge", scene.to_str().unwrap(), "--levels", "4"])
        .args([
            "--basis",
            "pl1d",
            "--mass",
            "consistent",
            "--format",
            "json",
        ])
        .output()
        .unwrap();
    let study: Value = serde_json::from_slice(&out.stdout).unwrap();
    let levels = study["levels"].as_array().unwrap();
    let stopped: Vec<&Value> = levels.iter().filter(|l| l["stopped"] == true).collect();
    assert!(!stopped.is_empty(), "{study}");
    for l in &stopped {
        // An error at another time than the other levels' is not comparable.
        assert!(l["error"].is_null() && l["order"].is_null(), "{l}");
        assert!(l["steps"].as_u64().unwrap() > 0, "{l}");
    }
    // The level after a stopped one takes its order against the last level with
    // an error, never against the stopped one.
    let notes: Vec<&str> = study["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    for l in &stopped {
        let level = l["level"].as_u64().unwrap();
        assert!(
            notes
                .iter()
                .any(|n| n.starts_with(&format!("pl1d level {level}: stopped at t = "))),
            "{notes:?}"
        );
    }
    // With `courant` every level has its own step.
    let dts: Vec<f64> = levels.iter().map(|l| l["dt"].as_f64().unwrap()).collect();
    assert!(dts.windows(2).all(|w| w[1] < w[0]), "{dts:?}");
}

#[test]
fn an_error_of_a_converge_level_names_the_file_the_level_and_the_basis() {
    let dir = temp_dir("converge-level-error");
    let scene = dir.join("column.toml");
    std::fs::write(&scene, STOPPING_COLUMN).unwrap();
    let out = cli()
        .args(["converge", scene.to_str().unwrap(), "--levels", "3"])
        .args(["--basis", "bspline", "--dt", "1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with(&format!(
            "error: {}: level 0 (bspline, h = 1.00e0): time.dt: the time step 1 is ",
            scene.display()
        )),
        "{stderr}"
    );
    assert!(stderr.contains("(from --dt 1)"), "{stderr}");
}

#[test]
fn a_body_far_too_soft_for_its_weight_is_named_as_the_cause() {
    let dir = temp_dir("soft-body");
    let scene = dir.join("soft.toml");
    // E typed in MPa: the column's weight would strain it by about 2e3.
    std::fs::write(
        &scene,
        STOPPING_COLUMN
            .replace("young = 1e4", "young = 1e-2")
            .replace("courant = 0.4", "dt = 1e-3"),
    )
    .unwrap();
    let out = cli()
        .args(["run", scene.to_str().unwrap(), "--basis", "bspline"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        // H is the column's height, 10 (the particles' centres span 10 less a
        // spacing: 1.9e4 with that, found by a user).
        stderr.contains("the body's own weight would strain it by about ρ |g| H / E = 2.0e4")
            && stderr.contains("H = 10.0000 along g"),
        "{stderr}"
    );
    assert!(
        stderr.contains("check the units of `young` (Pa)"),
        "{stderr}"
    );
    // The failure leads with the material's scale, before the step's own advice
    // (a student read "lower `time.courant`" first and missed the units).
    let failure = stderr
        .lines()
        .find(|l| l.starts_with("error: "))
        .expect("the run fails");
    assert!(
        failure.starts_with("error: the body's own weight would strain it")
            && failure.contains("which explains this failure before anything the step saw: step "),
        "{failure}"
    );
}

/// `compare` printed none of the warnings `run` prints (a user's 1D bars with
/// contact between bodies, PL1D with its default mass, which `run` warns about):
/// each variant's warnings now go to standard error, named by the variant.
#[test]
fn compare_prints_each_variants_warnings() {
    let dir = temp_dir("compare-warnings");
    let scene = dir.join("bars.toml");
    std::fs::write(
        &scene,
        "name = \"bars\"\ndim = 1\nbasis = \"bspline\"\n[mesh]\nkind = \"interval\"\nx = [0.0, 12.0]\nelements = 96\n[material]\nyoung = 1e4\ndensity = 1.0\n[[body]]\nmin = [1.0]\nmax = [2.0]\nper_block = [4]\ninitial_velocity = { kind = \"uniform\", value = [2.0] }\n[[body]]\nmin = [3.0]\nmax = [5.0]\nper_block = [4]\n[[effect]]\nkind = \"body-contact\"\n[time]\ncourant = 0.3\nt_end = 0.02\n",
    )
    .unwrap();
    let out = cli()
        .args([
            "compare",
            scene.to_str().unwrap(),
            "--basis",
            "bspline,pl1d",
        ])
        .output()
        .unwrap();
    assert_success(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].starts_with("warning (pl1d extended-hybrid): ")
            && warnings[0].contains("`--mass lumped`"),
        "{stderr}"
    );
}

/// A warning several variants of `compare` give is printed once, naming them
/// (a user's six mass strategies on PL printed PL's lattice warning six times).
#[test]
fn compare_prints_a_warning_shared_by_variants_once() {
    let dir = temp_dir("compare-shared-warnings");
    let scene = dir.join("block.toml");
    // 4 × 4 per block on blocks of four triangles: PL particles on the diagonals.
    std::fs::write(
        &scene,
        "name = \"block\"\ndim = 2\nbasis = \"pl\"\n[mesh]\nkind = \"blocks\"\nx = [0.0, 2.0]\ny = [0.0, 2.0]\nblocks = [8, 8]\n[material]\nyoung = 1e5\ndensity = 1000.0\n[[body]]\nmin = [0.5, 0.5]\nmax = [1.5, 1.0]\nper_block = [4, 4]\n[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n[[boundary]]\ntag = \"bottom\"\nfix = [\"normal\"]\n[time]\ncourant = 0.5\nt_end = 0.02\n",
    )
    .unwrap();
    let out = cli()
        .args([
            "compare",
            scene.to_str().unwrap(),
            "--basis",
            "pl",
            // Two strategies other than the default: their lattice warnings are
            // the same (the default's leaves out what holding a massless vertex
            // at zero does).
            "--mass",
            "lumped,partial",
        ])
        .output()
        .unwrap();
    assert_success(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning"))
        .collect();
    let mut texts: Vec<&str> = warnings
        .iter()
        .map(|w| w.split_once("): ").map_or(*w, |(_, t)| t))
        .collect();
    let all = texts.len();
    texts.sort_unstable();
    texts.dedup();
    assert_eq!(texts.len(), all, "{stderr}");
    assert!(
        warnings
            .iter()
            .any(|w| w.starts_with("warning (every variant): ")),
        "{stderr}"
    );
}

/// `compare --format csv` leaves the y columns of a 1D run's tracked particle
/// empty (a teacher's 1D comparison printed `tracked_y0 = 0`, `tracked_uy = 0`).
#[test]
fn compare_csv_of_a_1d_scene_has_no_tracked_y() {
    let scene = format!(
        "{}/../docs/examples/student-bar-1d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = cli()
        .args([
            "compare",
            &scene,
            "--basis",
            "bspline,pl1d",
            "--format",
            "csv",
            "--t-end",
            "0.001",
        ])
        .output()
        .unwrap();
    assert_success(&out);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let mut lines = stdout.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert_eq!(rows.len(), 2, "{stdout}");
    for row in &rows {
        assert!(!row[column("tracked_x0")].is_empty(), "{stdout}");
        assert!(!row[column("tracked_ux")].is_empty(), "{stdout}");
        assert!(row[column("tracked_y0")].is_empty(), "{stdout}");
        assert!(row[column("tracked_uy")].is_empty(), "{stdout}");
    }
}
