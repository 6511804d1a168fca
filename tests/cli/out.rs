//! `mpm-cli run --out DIR` (and `converge --out DIR`): every file is written, agrees with the printed
//! diagnostics and summary, and reads back with independent readers (Python's
//! `meshio` for the `.vtu` files, `xml.etree` for the `.pvd` and the SVGs); write
//! errors are input errors; no progress bar reaches a captured stderr.
//!
//! These tests need `python3` with `meshio` (pinned in `tests/requirements.txt`,
//! installed by `.ci/run`); they fail (never skip) without them.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/cli.rs"]
mod common_cli;

use common::meshio::{array, read_back};
use common::TempDir;
use common_cli::{assert_success, cli, stability_scene, DAMPED_COLUMN_1D};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn key(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// Parses a CSV file: the header and the rows as strings.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

/// The colour `psmpm::output::chart` gives series `k`, as it appears in the SVG.
fn series_stroke(k: usize) -> String {
    let (r, g, b) = psmpm::output::chart::series_colour(k);
    format!("#{r:02X}{g:02X}{b:02X}")
}

/// Checks an SVG line plot: the legend names in order, `lines[k]` `<polyline>`s in
/// the colour of series `k` (one per panel it is drawn as a line in), and `markers`
/// circles at least.
/// The series of `energy.svg` for a run whose effects do no work.
const ENERGY_LEGENDS: &[&str] = &[
    "kinetic",
    "strain",
    "potential − P(0)",
    "total − E(0)",
    "centred total − E(0)",
];

fn check_plot(svg: &Value, names: &[&str], lines: &[usize], markers: usize) {
    let texts: Vec<&str> = svg["texts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    let strokes: Vec<&str> = svg["polyline_strokes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|s| s.as_str())
        .collect();
    for (k, (name, &line)) in names.iter().zip(lines).enumerate() {
        assert!(texts.contains(name), "legend `{name}` missing in {texts:?}");
        let count = strokes.iter().filter(|&&s| s == series_stroke(k)).count();
        assert_eq!(count, line, "polylines of series {k} `{name}`");
    }
    assert!(svg["circles"].as_u64().unwrap() as usize >= markers);
}

#[test]
fn a_2d_run_writes_every_file_consistent_with_its_json_output() {
    let dir = TempDir::new("bar");
    std::fs::create_dir_all(dir.path()).unwrap();
    // The vibrating bar with two tracked particles (the built-in scene tracks one).
    let root = format!("{}/..", env!("CARGO_MANIFEST_DIR"));
    let base = std::fs::read_to_string(format!("{root}/scenes/vibrating-bar.toml")).unwrap();
    assert!(base.contains("tracked = [[12.5, 1.0]]"));
    let scene = dir.join("bar.toml");
    std::fs::write(
        &scene,
        base.replace(
            "tracked = [[12.5, 1.0]]",
            "tracked = [[12.4, 0.9], [3.0, 0.5]]",
        ),
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = cli()
        .args([
            "run",
            key(&scene),
            "--t-end",
            "0.5",
            "--diag-every",
            "1",
            "--format",
            "json",
            "--out",
            key(&out_dir),
            "--out-every",
            "100",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // stdout stays JSON; the time step (a `#` line) and the line naming the
    // directory go to stderr.
    assert_eq!(stderr.lines().count(), 2, "{stderr}");
    assert!(
        stderr.starts_with("# time step 1.00e-3 · critical step "),
        "{stderr}"
    );
    assert!(
        stderr.contains(&format!("output written to {}", out_dir.display())),
        "{stderr}"
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let steps = 500;
    assert_eq!(lines.len(), steps + 1);
    let (rows, summary) = (&lines[..steps], &lines[steps]);

    let frames: Vec<String> = (0..6).map(|k| format!("particles_{k:05}.vtu")).collect();
    for file in [
        "diagnostics.csv",
        "summary.json",
        "mesh.vtu",
        "particles.pvd",
        "tracked.csv",
        "tracked.svg",
        "energy.svg",
    ]
    .iter()
    .copied()
    .chain(frames.iter().map(String::as_str))
    {
        assert!(out_dir.join(file).is_file(), "{file} missing");
    }
    assert!(!out_dir.join("particles_00006.vtu").exists());

    // diagnostics.csv: one row per step, the values of --format json, bit for bit.
    let (header, csv) = read_csv(&out_dir.join("diagnostics.csv"));
    assert_eq!(
        header,
        [
            "step",
            "time",
            "kinetic",
            "strain",
            "potential",
            "work",
            "total",
            "total_centred",
            "mass",
            "momentum_x",
            "momentum_y",
            "max_speed",
            "active",
            "lumped_rows",
            "deactivated",
            "extended",
            "worst_coverage",
            "worst_function",
            "worst_x",
            "worst_y",
            "condition",
            "kinetic_motion",
            "substeps",
            "dt_critical"
        ]
    );
    // docs/scenes.md lists exactly these columns, in this order.
    let documented: Vec<String> = include_str!("../../docs/scenes.md")
        .lines()
        .skip_while(|l| !l.starts_with("| column |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .flat_map(|l| {
            let first = l.split(" | ").next().unwrap().to_string();
            first
                .split('`')
                .skip(1)
                .step_by(2)
                .map(String::from)
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(
        documented, header,
        "docs/scenes.md, `What run --out DIR writes`"
    );
    assert_eq!(csv.len(), steps);
    // The rows of --format json have the CSV header's keys, no more and no fewer.
    let mut columns: Vec<&str> = header.iter().map(String::as_str).collect();
    columns.sort_unstable();
    for json in rows {
        let mut keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        keys.sort_unstable();
        assert_eq!(keys, columns, "the keys of a --format json row");
    }
    for (row, json) in csv.iter().zip(rows) {
        assert_eq!(row.len(), header.len());
        for (name, field) in header.iter().zip(row) {
            let want = json[name.as_str()].clone();
            if want.is_null() {
                // Not measured (the condition without --condition, coverage with a
                // strategy that does not measure it): an empty field.
                assert!(field.is_empty(), "{name}: {field}");
                continue;
            }
            match name.as_str() {
                "step" | "active" | "lumped_rows" | "deactivated" | "extended"
                | "worst_function" => {
                    assert_eq!(
                        field.parse::<u64>().unwrap(),
                        want.as_u64().unwrap(),
                        "{name}"
                    )
                }
                _ => assert_eq!(
                    field.parse::<f64>().unwrap().to_bits(),
                    want.as_f64().unwrap().to_bits(),
                    "{name} at step {}: csv {field}, json {want}",
                    json["step"]
                ),
            }
        }
    }

    // summary.json is the printed summary.
    let written: Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(&written, summary);
    assert_eq!(written["steps"], 500);
    // The step is given (`dt`): no Courant number; the critical step is there.
    assert_eq!(written.get("courant"), Some(&Value::Null), "{written}");
    assert!(written["dt_critical"].as_f64().unwrap() > 1e-3, "{written}");
    assert_eq!(written["stable"], true);

    // tracked.csv: per step and particle, with the reference.
    let (header, tracked) = read_csv(&out_dir.join("tracked.csv"));
    assert_eq!(
        header,
        [
            "time",
            "particle",
            "u_x",
            "u_y",
            "v_x",
            "v_y",
            "u_exact_x",
            "u_exact_y",
            "v_exact_x",
            "v_exact_y"
        ]
    );
    assert_eq!(tracked.len(), 2 * steps);
    let particle_of = |row: &Vec<String>| row[1].parse::<usize>().unwrap();
    let (p0, p1) = (particle_of(&tracked[0]), particle_of(&tracked[1]));
    assert_ne!(p0, p1);
    let value = |row: &Vec<String>, k: usize| row[k].parse::<f64>().unwrap();
    for pair in tracked.chunks(2) {
        assert_eq!(pair[0][0], pair[1][0], "both particles at each time");
        assert_eq!((particle_of(&pair[0]), particle_of(&pair[1])), (p0, p1));
    }
    let last = &tracked[2 * steps - 2];
    assert_eq!(value(last, 0), 0.5);
    // The reference is close to the computed displacement (E_u ~ 1e-5) and velocity.
    assert!((value(last, 2) - value(last, 6)).abs() < 1e-3 * value(last, 6).abs().max(1e-3));
    assert!((value(last, 4) - value(last, 8)).abs() < 1e-2 * value(last, 8).abs().max(1e-3));

    // The .vtu files and the collection, read back.
    let files: Vec<PathBuf> = vec![
        out_dir.join("mesh.vtu"),
        out_dir.join(&frames[0]),
        out_dir.join(&frames[5]),
        out_dir.join("particles.pvd"),
        out_dir.join("energy.svg"),
        out_dir.join("tracked.svg"),
    ];
    let json = read_back(&files);
    let mesh = &json["vtu"][key(&files[0])];
    // 4 x 1 blocks of four triangles: 16 triangles on 10 corners + 4 centres.
    assert_eq!(mesh["cell_counts"], serde_json::json!([["triangle", 16]]));
    assert_eq!(array(&mesh["points"]).0, [14, 3]);

    let first = &json["vtu"][key(&files[1])];
    let last = &json["vtu"][key(&files[2])];
    let n = 576;
    let (shape, x0) = array(&first["points"]);
    assert_eq!(shape, [n, 3]);
    let (shape, x) = array(&last["points"]);
    assert_eq!(shape, [n, 3]);
    assert_eq!(last["cell_counts"], serde_json::json!([["vertex", n]]));
    let (shape, u) = array(&last["point_data"]["displacement"]);
    assert_eq!(shape, [n, 3]);
    assert_eq!(array(&last["point_data"]["velocity"]).0, [n, 3]);
    assert_eq!(array(&last["point_data"]["stress"]).0, [n, 9]);
    assert_eq!(array(&last["point_data"]["volume"]).0, [n]);
    // The first frame is the initial state: at rest positions, zero displacement.
    assert!(array(&first["point_data"]["displacement"])
        .1
        .iter()
        .all(|&v| v == 0.0));
    // x = x0 + u, and the bar moves.
    for i in 0..3 * n {
        assert!((x[i] - x0[i] - u[i]).abs() < 1e-12, "component {i}");
    }
    assert!(u.iter().any(|&v| v.abs() > 1e-3));
    // The tracked particle is the nearest to its point at the start, and its last
    // displacement is the frame's.
    let nearest = |p: [f64; 2]| {
        (0..n)
            .min_by(|&a, &b| {
                let d = |i: usize| (x0[3 * i] - p[0]).powi(2) + (x0[3 * i + 1] - p[1]).powi(2);
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    assert_eq!((p0, p1), (nearest([12.4, 0.9]), nearest([3.0, 0.5])));
    assert_eq!(value(&tracked[2 * steps - 2], 2), u[3 * p0]);

    let pvd = json["pvd"][key(&files[3])].as_array().unwrap();
    let entries: Vec<(f64, &str)> = pvd
        .iter()
        .map(|e| {
            (
                e[0].as_str().unwrap().parse().unwrap(),
                e[1].as_str().unwrap(),
            )
        })
        .collect();
    let times: Vec<f64> = entries.iter().map(|e| e.0).collect();
    let expected: Vec<f64> = (0..6).map(|k| (100 * k) as f64 * 1e-3).collect();
    assert_eq!(times, expected);
    for ((_, file), expected) in entries.iter().zip(&frames) {
        assert_eq!(file, expected);
    }

    check_plot(&json["svg"][key(&files[4])], ENERGY_LEGENDS, &[1; 5], 0);
    let names: Vec<String> = [p0, p1]
        .iter()
        .flat_map(|p| {
            [
                format!("particle {p} u_x (MPM)"),
                format!("particle {p} u_x (exact)"),
            ]
        })
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    // The exact curves are lines in both panels (displacement and velocity).
    check_plot(&json["svg"][key(&files[5])], &names, &[0, 2, 0, 2], 100);
    let texts = json["svg"][key(&files[5])]["texts"].to_string();
    // No units on the axes: a scene's are its own consistent system.
    assert!(
        texts.contains("\"time\"") && texts.contains("\"displacement\""),
        "{texts}"
    );
    assert!(!texts.contains("(s)") && !texts.contains("(m)"), "{texts}");
    // The second panel: the velocity, computed as markers and the reference's as a
    // line (the scene has a reference).
    assert!(texts.contains("\"velocity\""), "{texts}");
    for p in [p0, p1] {
        for name in [
            format!("particle {p} v_x (MPM)"),
            format!("particle {p} v_x (exact)"),
        ] {
            assert!(texts.contains(&name), "{texts}");
        }
    }
}

#[test]
fn a_1d_run_writes_about_50_frames_and_no_mesh() {
    let dir = TempDir::new("bar1d");
    let out = cli()
        .args([
            "run",
            "vibrating-bar-1d",
            "--t-end",
            "1",
            "--diag-every",
            "0",
            "--out",
            key(dir.path()),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains("error E_u = "), "{stdout}");
    let line = stdout.lines().last().unwrap();
    assert!(
        line.starts_with(&format!("output written to {}: ", dir.path().display())),
        "{line}"
    );
    assert!(out.stderr.is_empty());
    // 1000 steps: a frame every 20 steps and the initial state.
    for k in 0..=50 {
        assert!(dir.join(format!("particles_{k:05}.vtu")).is_file(), "{k}");
    }
    assert!(!dir.join("particles_00051.vtu").exists());
    for file in ["mesh.vtu", "tracked.csv", "tracked.svg"] {
        assert!(!dir.join(file).exists(), "{file}");
    }
    let (_, rows) = read_csv(&dir.join("diagnostics.csv"));
    assert_eq!(rows.len(), 1000);
    assert_eq!(rows[999][0], "1000");
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["scene"], "vibrating-bar-1d");
    assert_eq!(summary["steps"], 1000);

    let (last, pvd, energy) = (
        dir.join("particles_00050.vtu"),
        dir.join("particles.pvd"),
        dir.join("energy.svg"),
    );
    let json = read_back(&[last.clone(), pvd.clone(), energy.clone()]);
    let frame = &json["vtu"][key(&last)];
    let (shape, x) = array(&frame["points"]);
    assert_eq!(shape, [32, 3]);
    assert!((0..32).all(|i| x[3 * i + 1] == 0.0 && x[3 * i + 2] == 0.0));
    let (shape, u) = array(&frame["point_data"]["displacement"]);
    assert_eq!(shape, [32, 3]);
    assert!(u.iter().any(|&v| v != 0.0));
    let entries = json["pvd"][key(&pvd)].as_array().unwrap();
    assert_eq!(entries.len(), 51);
    assert_eq!(entries[50][0], "1.0");
    check_plot(&json["svg"][key(&energy)], ENERGY_LEGENDS, &[1; 5], 0);
}

/// The `column-equilibrium` reference is the settled state, with no time history:
/// `tracked.csv` had `u_exact_x = 0`, `v_exact_x = 0` columns and `tracked.svg` a
/// flat "exact" line at 0, while the settled displacement is not 0. Both now leave
/// the exact values out, as for a scene without a reference.
#[test]
fn a_column_equilibrium_run_tracks_no_exact_history() {
    let scenes = TempDir::created("column-equilibrium-scene");
    let scene = scenes.join("col1d.toml");
    std::fs::write(
        &scene,
        format!(
            "{}[output]\ntracked = [[1.0], [0.5]]\n",
            DAMPED_COLUMN_1D.replace("t_end = 2.0", "t_end = 0.05")
        ),
    )
    .unwrap();
    let dir = TempDir::new("column-equilibrium-tracked");
    let out = cli()
        .arg("run")
        .arg(&scene)
        .args(["--diag-every", "0", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_success(&out);
    let (header, rows) = read_csv(&dir.join("tracked.csv"));
    assert_eq!(header, ["time", "particle", "u_x", "u_y", "v_x", "v_y"]);
    assert!(!rows.is_empty());
    let svg = std::fs::read_to_string(dir.join("tracked.svg")).unwrap();
    assert!(svg.contains("(MPM)") && !svg.contains("(exact)"), "{svg}");
}

fn input_error(args: &[&str]) -> String {
    let out = cli().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

#[test]
fn an_unwritable_directory_is_an_input_error_naming_it() {
    let dir = TempDir::new("bad");
    std::fs::create_dir_all(dir.path()).unwrap();
    let file = dir.join("plain-file");
    std::fs::write(&file, "not a directory").unwrap();
    let target = file.join("out");
    let stderr = input_error(&[
        "run",
        "vibrating-bar-1d",
        "--t-end",
        "0.01",
        "--out",
        key(&target),
    ]);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.contains(key(&target)), "{stderr}");
    // --out-every needs --out.
    input_error(&["run", "vibrating-bar-1d", "--out-every", "5"]);
    // A control character in the name (a student's TAB) is refused, as in a
    // scene's `name`, and nothing is created.
    let tabbed = dir.join("a\tb");
    let stderr = input_error(&[
        "run",
        "vibrating-bar-1d",
        "--t-end",
        "0.01",
        "--out",
        key(&tabbed),
    ]);
    assert!(
        stderr.contains("contains the control character '\\t' (U+0009)"),
        "{stderr}"
    );
    assert!(!tabbed.exists());
}

#[test]
fn a_failed_run_still_writes_its_files() {
    let dir = TempDir::new("fail");
    // A huge time step throws the bar's particles out of the mesh.
    let out = cli()
        .args([
            "run",
            "vibrating-bar",
            "--dt",
            "100",
            "--t-end",
            "1000",
            "--allow-above-critical",
            "--out",
            key(dir.path()),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["stable"], false);
    assert!(summary["failure"].is_string());
    for file in ["diagnostics.csv", "particles.pvd", "particles_00000.vtu"] {
        assert!(dir.join(file).is_file(), "{file}");
    }
}

#[test]
fn a_long_run_with_a_captured_stderr_shows_no_progress_bar() {
    // About 1.2 s in release: past the bar's 1 s delay.
    let out = cli()
        .args([
            "run",
            "vibrating-bar",
            "--dt",
            "2.5e-4",
            "--t-end",
            "2.5",
            "--diag-every",
            "0",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.is_empty(), "stderr: {stderr:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    for mark in ["\r", "\u{1b}[", "ETA", "=>", "━", "█"] {
        assert!(!stdout.contains(mark), "{mark:?} in {stdout}");
    }
    assert!(stdout.contains("10000 steps"), "{stdout}");
}

/// `run vibrating-bar-1d` for `t_end` into `dir` with extra arguments; the output.
fn run_1d(t_end: &str, dir: &Path, extra: &[&str]) -> std::process::Output {
    cli()
        .args([
            "run",
            "vibrating-bar-1d",
            "--t-end",
            t_end,
            "--diag-every",
            "0",
            "--out",
            key(dir),
        ])
        .args(extra)
        .output()
        .unwrap()
}

fn frames_in(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            let name = name.to_string_lossy();
            name.starts_with("particles_") && name.ends_with(".vtu")
        })
        .count()
}

#[test]
fn a_folder_is_reused_only_with_overwrite_and_never_over_other_files() {
    let dir = TempDir::new("reuse");
    // 100 steps, a frame each: 101 frames.
    let out = run_1d("0.1", dir.path(), &["--out-every", "1"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(frames_in(dir.path()), 101);

    // Again: refused, naming the folder and the flag; nothing touched.
    let out = run_1d("0.1", dir.path(), &["--out-every", "50"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(key(dir.path())), "{stderr}");
    assert!(stderr.contains("--overwrite"), "{stderr}");
    assert_eq!(frames_in(dir.path()), 101);

    // With --overwrite: the earlier run's frames are gone, no stale frame is left.
    let out = run_1d("0.1", dir.path(), &["--out-every", "50", "--overwrite"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(frames_in(dir.path()), 3);
    let pvd = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet ").count(), 3);

    // A file the tool does not write: refused even with --overwrite, nothing removed.
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let out = run_1d("0.1", dir.path(), &["--overwrite"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("notes.txt") && stderr.contains(key(dir.path())),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(frames_in(dir.path()), 3);
    assert!(dir.join("summary.json").is_file());
}

/// `converge vibrating-bar-1d --levels 2 --out DIR` with `extra` arguments.
fn converge_1d(dir: &Path, extra: &[&str]) -> std::process::Output {
    cli()
        .args([
            "converge",
            "vibrating-bar-1d",
            "--levels",
            "2",
            "--format",
            "json",
            "--out",
            key(dir),
        ])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn converge_checks_its_folder_before_the_first_level_with_the_rules_of_run() {
    let dir = TempDir::new("converge-reuse");
    // A regular file as --out: refused before any level runs (nothing printed).
    std::fs::create_dir_all(dir.path()).unwrap();
    let file = dir.join("plain-file");
    std::fs::write(&file, "not a directory").unwrap();
    let out = converge_1d(&file, &[]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(key(&file)), "{stderr}");
    assert!(out.stdout.is_empty(), "a level ran");

    let study = dir.join("study");
    let out = converge_1d(&study, &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files = |d: &Path| {
        let mut names: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    let written = files(&study);
    assert_eq!(
        written,
        [
            "converge.csv",
            "converge.json",
            "error-vs-h.svg",
            "work-precision.svg"
        ]
    );

    // Again: refused up front, naming the folder and the flag; with --overwrite it
    // runs.
    let out = converge_1d(&study, &[]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(key(&study)) && stderr.contains("--overwrite"),
        "{stderr}"
    );
    assert!(out.stdout.is_empty(), "a level ran");
    let out = converge_1d(&study, &["--overwrite"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // A file converge does not write (here a run's): refused even with
    // --overwrite, nothing removed.
    std::fs::write(study.join("summary.json"), "{}").unwrap();
    let out = converge_1d(&study, &["--overwrite"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("summary.json"), "{stderr}");
    assert!(out.stdout.is_empty(), "a level ran");
    assert_eq!(files(&study).len(), 5);
}

#[test]
fn binary_and_ascii_runs_write_the_same_frames() {
    let dir = TempDir::new("encodings");
    let (binary, ascii) = (dir.join("binary"), dir.join("ascii"));
    for (d, extra) in [(&binary, &[][..]), (&ascii, &["--vtu", "ascii"][..])] {
        let out = run_1d("0.05", d, extra);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let frame = "particles_00050.vtu";
    let (b, a) = (binary.join(frame), ascii.join(frame));
    let bytes = std::fs::read(&b).unwrap();
    assert!(String::from_utf8_lossy(&bytes[..300]).contains("compressor=\"vtkZLibDataCompressor\""));
    assert!(std::fs::read_to_string(&a)
        .unwrap()
        .contains("format=\"ascii\""));
    let json = read_back(&[b.clone(), a.clone()]);
    let (vb, va) = (&json["vtu"][key(&b)], &json["vtu"][key(&a)]);
    assert_eq!(array(&vb["points"]).0, [32, 3]);
    assert_eq!(vb, va);
    // --vtu needs --out.
    input_error(&["run", "vibrating-bar-1d", "--vtu", "ascii"]);
}

/// `--format csv` with no row due (`--diag-every 0`) prints the header alone, so
/// that stdout is still a CSV file (it was empty: a user's script failed on it).
#[test]
fn csv_format_without_rows_prints_the_header() {
    let out = cli()
        .args([
            "run",
            "vibrating-bar-1d",
            "--t-end",
            "0.01",
            "--diag-every",
            "0",
            "--format",
            "csv",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header[..3], ["step", "time", "kinetic"]);
    assert_eq!(reader.records().count(), 0);
}

#[test]
fn csv_format_keeps_the_summary_on_stderr() {
    let out = cli()
        .args([
            "run",
            "vibrating-bar-1d",
            "--t-end",
            "0.05",
            "--diag-every",
            "10",
            "--format",
            "csv",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header[..3], ["step", "time", "kinetic"]);
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 5);
    assert_eq!(&rows[4][0], "50");
    let stderr = String::from_utf8(out.stderr).unwrap();
    let comments: Vec<&str> = stderr.lines().collect();
    assert!(
        comments
            .iter()
            .all(|l| l.starts_with("# ") && l.contains('=')),
        "{stderr}"
    );
    for line in [
        "# scene=vibrating-bar-1d",
        "# steps=50",
        "# stable=true",
        "# failure=",
    ] {
        assert!(comments.contains(&line), "{line} missing in {stderr}");
    }
    let error = comments
        .iter()
        .find_map(|l| l.strip_prefix("# error="))
        .unwrap();
    assert!(error.parse::<f64>().unwrap() > 0.0, "{error}");
}

/// The default mass strategy reports, every step, how many functions it extended
/// and the worst-covered function it solves for, with its position: a body in a
/// mostly empty box, read back from `--format csv`.
#[test]
fn the_default_reports_its_worst_covered_solved_function_every_step() {
    let root = format!("{}/..", env!("CARGO_MANIFEST_DIR"));
    let out = cli()
        .args([
            "run",
            &format!("{root}/docs/examples/drop-plate.toml"),
            "--t-end",
            "0.01",
            "--diag-every",
            "1",
            "--format",
            "csv",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut reader = csv::Reader::from_reader(&out.stdout[..]);
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert!(rows.len() > 10);
    for row in &rows {
        let number = |name: &str| row[column(name)].parse::<f64>().unwrap();
        // Extended below coverage 0.02: what is solved for is covered at least that.
        assert!(number("extended") > 0.0);
        let coverage = number("worst_coverage");
        assert!((0.02..0.75).contains(&coverage), "{coverage}");
        let function = number("worst_function");
        assert!(function >= 0.0 && function.fract() == 0.0);
        // The box is [0, 4] x [0, 3]; the plate starts in [1, 2.6] x [1, 2.4].
        let (x, y) = (number("worst_x"), number("worst_y"));
        assert!(
            (0.5..3.1).contains(&x) && (0.5..2.9).contains(&y),
            "({x}, {y})"
        );
    }
}

/// `particles.svg`: the particles at the first, middle and last frame, coloured by
/// the field `--picture` names, on one colour scale over the mesh; an unknown field
/// or one that 1D does not have is an input error.
#[test]
fn particles_svg_shows_the_first_middle_and_last_frame() {
    let dir = TempDir::new("picture");
    let root = format!("{}/..", env!("CARGO_MANIFEST_DIR"));
    let scene = format!("{root}/docs/examples/settle.toml");
    let out_dir = dir.join("out");
    let out = cli()
        .args([
            "run",
            &scene,
            "--out",
            key(&out_dir),
            "--picture",
            "sigma-yy",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("particles.svg"));
    let svg = std::fs::read_to_string(out_dir.join("particles.svg")).unwrap();
    // 2 × 2 blocks of 4 × 4 particles, three panels; 21 steps to t = 0.1 (Courant
    // 0.4), the middle panel at step 10.
    assert_eq!(svg.matches("<circle").count(), 3 * 32);
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    let steps = summary["steps"].as_u64().unwrap();
    let dt = summary["dt"].as_f64().unwrap();
    let middle = (steps / 2) as f64 * dt;
    for title in [
        "t = 0\n".to_string(),
        format!("t = {}\n", format!("{middle:.3e}").parse::<f64>().unwrap()),
        "t = 0.1\n".to_string(),
        "settle: σ_yy (pl, extended-hybrid mass)".to_string(),
        "32 particles".to_string(),
    ] {
        assert!(svg.contains(&title), "{title:?}");
    }
    // The 28 edges of 2 × 2 four-triangle blocks (13 vertices, 16 triangles: Euler's
    // 13 + 16 − 1) under the particles of each panel.
    assert_eq!(svg.matches("stroke=\"#B0B0B0\"").count(), 3 * 28);

    let err = input_error(&[
        "run",
        &scene,
        "--out",
        key(&dir.join("x")),
        "--picture",
        "heat",
    ]);
    assert!(
        err.contains("--picture: unknown particle field `heat`"),
        "{err}"
    );
    let err = input_error(&[
        "run",
        "vibrating-bar-1d",
        "--out",
        key(&dir.join("y")),
        "--picture",
        "sigma-yy",
    ]);
    assert!(err.contains("does not exist in 1D"), "{err}");
}

/// The tutorial's grid-crossing section (docs/tutorial.md §5), as a student types
/// it: the vibrating bar at `v0 = 2.0` with the default law. The tracked particle
/// crosses element edges; PL's velocity is kicked off the exact one there, PS's is
/// not (RMS of `v_x − v_exact_x` from `tracked.csv`: 0.241 and 0.0163 in the docs).
#[test]
fn the_tutorial_grid_crossing_shows_pl_velocity_kicks_and_none_for_ps() {
    let dir = TempDir::new("crossing");
    std::fs::create_dir_all(dir.path()).unwrap();
    let shown = cli()
        .args(["scene", "show", "vibrating-bar"])
        .output()
        .unwrap();
    let text = String::from_utf8(shown.stdout).unwrap();
    let edited: String = text
        .lines()
        .filter(|l| !l.starts_with("model = \"linear-elastic\""))
        .map(|l| {
            if l.starts_with("v0 = 0.1 ") {
                l.replacen("v0 = 0.1 ", "v0 = 2.0 ", 1)
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!(edited.contains("v0 = 2.0 ") && !edited.contains("linear-elastic\""));
    let scene = dir.join("bar.toml");
    std::fs::write(&scene, edited).unwrap();
    let rms = |extra: &[&str], name: &str| -> (f64, String) {
        let out_dir = dir.join(name);
        let mut args = vec!["run", key(&scene), "--out", key(&out_dir)];
        args.extend_from_slice(extra);
        let out = cli().args(&args).output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (header, rows) = read_csv(&out_dir.join("tracked.csv"));
        let col = |n: &str| header.iter().position(|h| h == n).unwrap();
        let (v, exact) = (col("v_x"), col("v_exact_x"));
        let e2: f64 = rows
            .iter()
            .map(|r| (r[v].parse::<f64>().unwrap() - r[exact].parse::<f64>().unwrap()).powi(2))
            .sum();
        // stdout and stderr (where warnings go).
        let text = String::from_utf8(out.stdout).unwrap() + &String::from_utf8_lossy(&out.stderr);
        ((e2 / rows.len() as f64).sqrt(), text)
    };
    let (pl, pl_out) = rms(
        &["--basis", "pl", "--blocks", "12x1", "--particles", "8x6"],
        "pl-bar",
    );
    let (ps, ps_out) = rms(&[], "ps-bar");
    assert!((0.22..0.26).contains(&pl), "PL {pl}");
    assert!((0.014..0.019).contains(&ps), "PS {ps}");
    assert!(pl_out.contains("error E_u = 2.88e-1"), "{pl_out}");
    assert!(ps_out.contains("error E_u = 1.09e-2"), "{ps_out}");
    // No rotation warning with the default law.
    assert!(!ps_out.contains("warning"));
}

/// Every frame of a column run reads back with meshio, with each array its own
/// shape. Written as raw appended bytes, frames 41 and 76 of this run (of 164)
/// came back with an array read as another (meshio 5.3.5: "len(point_data
/// [\"displacement\"]) = 576" for 192 particles): meshio rewrites raw appended
/// data as base64 and finds each array by its old offset, which there equalled an
/// earlier array's new one (`psmpm::output::vtk::VtuEncoding::Binary`).
#[test]
fn every_frame_of_a_column_run_reads_back_with_meshio() {
    let dir = TempDir::new("column-frames");
    let scene = stability_scene("b5b-jitter-1x4-p12");
    let out = cli()
        .args(["run", &scene, "--threads", "1", "--diag-every", "0"])
        .args(["--out-every", "40", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_success(&out);
    let frames = frames_in(dir.path());
    assert!(frames > 150, "{frames} frames");
    let script = r#"
import glob, sys, meshio
files = sorted(glob.glob(sys.argv[1] + "/particles_*.vtu"))
for f in files:
    m = meshio.read(f)
    n = len(m.points)
    shapes = {k: v.shape for k, v in m.point_data.items()}
    assert shapes == {"velocity": (n, 3), "displacement": (n, 3), "stress": (n, 9),
                      "volume": (n,), "mass": (n,)}, (f, shapes)
print(len(files))
"#;
    let read = std::process::Command::new("python3")
        .args(["-c", script])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_success(&read);
    assert_eq!(
        String::from_utf8_lossy(&read.stdout).trim(),
        frames.to_string()
    );
}

/// A scene whose mesh cannot be built is refused at set-up with its file, line and
/// field, and leaves no `--out` folder behind (a user's Gmsh mesh with a duplicated
/// triangle left an empty folder, and the error named no line, since the folder's
/// mesh file was written before the run).
#[test]
fn a_mesh_that_cannot_be_built_leaves_no_out_folder() {
    let dir = TempDir::new("bad-mesh");
    let scene = dir.path().with_extension("toml");
    std::fs::write(
        &scene,
        "name = \"bad-mesh\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"polygon\"\noutline = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]\nedge_length = 0.25\n[material]\nyoung = 1e5\ndensity = 1000.0\n[[body]]\nmin = [0.1, 0.1]\nmax = [0.3, 0.3]\ncount = [4, 4]\n[time]\ncourant = 0.5\nt_end = 0.01\n",
    )
    .unwrap();
    let out = cli()
        .args([
            "run",
            scene.to_str().unwrap(),
            "--out",
            dir.path().to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains(&format!("{}:6:", scene.display())) && stderr.contains("mesh.outline"),
        "{stderr}"
    );
    assert!(!dir.path().exists(), "the folder was left behind");
    std::fs::remove_file(&scene).ok();
}
