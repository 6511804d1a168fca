//! Nothing a user types can crash, hang or be silently changed (issue 13).
//!
//! Extreme and malformed inputs (scene files, meshes, command lines) end with the
//! exit status of the documented rule (`mpm-cli --help`) and a message naming the
//! value and the limit, before any large allocation; a closed stdout ends `run`
//! quietly; SIGINT makes `run` write its files and exit with 130.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/cli.rs"]
mod common_cli;

use common::temp_dir;
use common_cli::{cli, SceneFile};
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::Stdio;

/// A small 2D bar on blocks.
const BAR: &str = r#"name = "bar"
dim = 2
basis = "ps"
mass = "consistent"

[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 1.0]
blocks = [4, 1]

[material]
model = "linear-elastic"
young = 100.0
poisson = 0.25
density = 1.0

[[body]]
min = [0.0, 0.0]
max = [4.0, 1.0]
per_block = [2, 2]

[[boundary]]
tag = "left"
fix = ["x", "y"]

[time]
dt = 1e-3
t_end = 0.01
"#;

/// A small 1D bar.
const ROD: &str = r#"name = "rod"
dim = 1
basis = "bspline"
mass = "consistent"

[mesh]
kind = "interval"
x = [0.0, 4.0]
elements = 4

[material]
model = "linear-elastic"
young = 100.0
density = 1.0

[[body]]
min = [0.0]
max = [4.0]
per_block = [2]

[[boundary]]
tag = "left"
fix = ["x"]

[time]
dt = 1e-3
t_end = 0.01
"#;

/// A square on a polygon mesh.
const SQUARE: &str = r#"name = "square"
dim = 2
basis = "pl"
mass = "consistent"

[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
edge_length = 0.25

[material]
model = "linear-elastic"
young = 100.0
poisson = 0.25
density = 1.0

[[body]]
min = [0.1, 0.1]
max = [0.9, 0.9]
count = [4, 4]

[[boundary]]
tag = "boundary"
fix = ["x", "y"]

[time]
dt = 1e-3
t_end = 0.01
"#;

/// A Gmsh scene whose mesh file is `FILE`.
const GMSH: &str = r#"name = "gmsh"
dim = 2
basis = "pl"

[mesh]
kind = "gmsh"
file = "FILE"

[material]
model = "linear-elastic"
young = 100.0
density = 1.0

[[body]]
min = [0.1, 0.1]
max = [0.9, 0.9]
count = [4, 4]

[time]
dt = 1e-3
t_end = 0.01
"#;

/// `base` with each `(from, to)` replaced once (`from` must occur).
fn edited(base: &str, edits: &[(&str, &str)]) -> String {
    let mut text = base.to_string();
    for (from, to) in edits {
        assert!(text.contains(from), "`{from}` is not in the base scene");
        text = text.replacen(from, to, 1);
    }
    text
}

/// One malformed or extreme input: a scene file (written as `scene.toml`, the `@`
/// in `args`) and a command line, with the exit status and a fragment of stderr.
struct Case {
    name: &'static str,
    scene: Option<String>,
    args: Vec<String>,
    status: i32,
    fragment: String,
}

fn scene_case(name: &'static str, scene: String, fragment: &str) -> Case {
    Case {
        name,
        scene: Some(scene),
        args: vec!["run".into(), "@".into()],
        status: 2,
        fragment: fragment.into(),
    }
}

fn args_case(name: &'static str, scene: Option<String>, args: &[&str], fragment: &str) -> Case {
    Case {
        name,
        scene,
        args: args.iter().map(|a| a.to_string()).collect(),
        status: 2,
        fragment: fragment.into(),
    }
}

fn scene_cases() -> Vec<Case> {
    let bar = |edits: &[(&str, &str)]| edited(BAR, edits);
    let rod = |edits: &[(&str, &str)]| edited(ROD, edits);
    let square = |edits: &[(&str, &str)]| edited(SQUARE, edits);
    let many_corners: String = (0..100_001)
        .map(|i| {
            let a = i as f64 * 2.0 * std::f64::consts::PI / 100_001.0;
            format!("[{:.6}, {:.6}]", a.cos(), a.sin())
        })
        .collect::<Vec<_>>()
        .join(", ");
    vec![
        scene_case(
            "steps-over-the-limit",
            bar(&[("t_end = 0.01", "t_end = 1e5")]),
            "steps is above the limit of 10000000",
        ),
        scene_case(
            "tiny-dt",
            bar(&[("dt = 1e-3", "dt = 1e-300")]),
            "time.dt: t_end / dt",
        ),
        scene_case(
            "subnormal-dt",
            bar(&[("dt = 1e-3", "dt = 5e-324")]),
            "above the limit of 10000000",
        ),
        scene_case(
            "end-before-one-step",
            bar(&[("t_end = 0.01", "t_end = 1e-4")]),
            "time.dt: 0.001 exceeds t_end = 0.0001",
        ),
        scene_case(
            "courant-end-before-one-step",
            bar(&[
                ("dt = 1e-3", "courant = 0.5"),
                ("t_end = 0.01", "t_end = 1e-9"),
            ]),
            "time.t_end: is shorter than one time step",
        ),
        scene_case(
            "courant-too-many-steps",
            bar(&[
                ("dt = 1e-3", "courant = 1e-9"),
                ("t_end = 0.01", "t_end = 1e3"),
            ]),
            "above the limit of 10000000",
        ),
        scene_case(
            "array-of-the-wrong-length-in-a-tagged-table",
            bar(&[("blocks = [4, 1]", "blocks = [4, 1, 1]")]),
            ".toml:10:1: mesh.blocks: invalid length 3",
        ),
        scene_case(
            "missing-field-named-with-its-table",
            bar(&[("young = 100.0\n", "")]),
            "material.young: missing field `young`",
        ),
        scene_case(
            "a-tagged-table-given-as-a-number",
            bar(&[(
                "[mesh]\nkind = \"blocks\"\nx = [0.0, 4.0]\ny = [0.0, 1.0]\nblocks = [4, 1]\n",
                "mesh = 5\n",
            )]),
            "mesh: invalid type: integer `5`, expected a table with a `kind` key",
        ),
        scene_case(
            "courant-at-or-above-one",
            bar(&[("dt = 1e-3", "courant = 1.5")]),
            "time.courant: 1.5 puts the time step at or above the critical step",
        ),
        scene_case(
            "control-character-in-the-name",
            bar(&[("name = \"bar\"", "name = \"a\\u001b[31mred\\u0007\"")]),
            "name: contains the control character",
        ),
        scene_case(
            "blocks-per-axis",
            bar(&[("blocks = [4, 1]", "blocks = [5000, 1]")]),
            "mesh.blocks: each count must be in 1..=4096",
        ),
        scene_case(
            "blocks-in-all",
            bar(&[("blocks = [4, 1]", "blocks = [4096, 4096]")]),
            "blocks in all is above the limit of 1000000",
        ),
        scene_case(
            "no-blocks",
            bar(&[("blocks = [4, 1]", "blocks = [0, 1]")]),
            "mesh.blocks",
        ),
        scene_case(
            "interval-elements",
            rod(&[("elements = 4", "elements = 2000000")]),
            "mesh.elements: must be in 1..=1000000",
        ),
        scene_case(
            "particles-per-block",
            bar(&[
                ("blocks = [4, 1]", "blocks = [64, 64]"),
                ("per_block = [2, 2]", "per_block = [1000, 1000]"),
            ]),
            "above the limit of 10000000",
        ),
        scene_case(
            "particle-count",
            square(&[("count = [4, 4]", "count = [100000, 100000]")]),
            "particles, above the limit of 10000000",
        ),
        scene_case(
            "polygon-edge-length",
            square(&[("edge_length = 0.25", "edge_length = 1e-6")]),
            "mesh.edge_length: edge length 1e-6",
        ),
        scene_case(
            "polygon-edge-length-tiny",
            square(&[("edge_length = 0.25", "edge_length = 1e-300")]),
            "triangles, above the limit of 4000000",
        ),
        scene_case(
            "polygon-corners",
            square(&[(
                "outline = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]",
                &format!("outline = [{many_corners}]"),
            )]),
            "100001 corners (outline and holes) is above the limit of 100000",
        ),
        scene_case(
            "polygon-nan-corner",
            square(&[("[1.0, 1.0]", "[1.0, nan]")]),
            "mesh.outline[2]: must be finite",
        ),
        scene_case(
            "density-underflows",
            bar(&[("density = 1.0", "density = 5e-324")]),
            "material.density: density = 5e-324 is out of range: ρ ≥ 2.2e-308 (subnormal numbers are refused)",
        ),
        scene_case(
            "body-volume-underflows",
            square(&[
                ("max = [0.9, 0.9]", "max = [1e-200, 1e-200]"),
                ("min = [0.1, 0.1]", "min = [0.0, 0.0]"),
            ]),
            "body[0].max: the particles of body[0] would have mass 0e0",
        ),
        scene_case(
            "resolution-basis-of-another-dimension",
            format!("{BAR}\n[[resolution]]\nbasis = \"bspline\"\nblocks = [4, 1]\n"),
            "resolution[0].basis: `bspline` is a 1D basis but the scene is 2D",
        ),
        scene_case(
            "resolution-blocks-on-polygon",
            format!("{SQUARE}\n[[resolution]]\nbasis = \"ps\"\nblocks = [4, 4]\n"),
            "resolution[0].blocks: the scene's mesh has no blocks",
        ),
        scene_case(
            "resolution-edge-length-on-blocks",
            format!("{BAR}\n[[resolution]]\nbasis = \"pl\"\nedge_length = 0.1\n"),
            "resolution[0].edge_length: the scene's mesh is not a polygon",
        ),
        scene_case(
            "resolution-blocks-over-the-limit",
            format!("{BAR}\n[[resolution]]\nbasis = \"pl\"\nblocks = [5000, 1]\n"),
            "resolution[0].blocks: each count must be in 1..=4096",
        ),
        scene_case(
            "resolution-per-block-length",
            format!("{BAR}\n[[resolution]]\nbasis = \"pl\"\nper_block = [4]\n"),
            "resolution[0].per_block: needs 2 counts",
        ),
        scene_case(
            "resolution-negative-edge-length",
            format!("{SQUARE}\n[[resolution]]\nbasis = \"ps\"\nedge_length = -1.0\n"),
            "resolution[0].edge_length: must be positive and finite",
        ),
        scene_case(
            "resolution-tiny-edge-length",
            format!("{SQUARE}\n[[resolution]]\nbasis = \"ps\"\nedge_length = 1e-9\n"),
            "resolution[0].edge_length: edge length",
        ),
        scene_case(
            "resolution-1d-second-number",
            format!("{ROD}\n[[resolution]]\nbasis = \"pl1d\"\nblocks = [9, 3]\n"),
            "resolution[0].blocks: a 1D scene has one count of elements",
        ),
        scene_case(
            "study-refine-y-in-1d",
            format!("{ROD}\n[study]\nrefine = [\"y\"]\n"),
            "study.refine: `y` does not exist in a 1D scene",
        ),
        scene_case(
            "study-refine-normal",
            format!("{BAR}\n[study]\nrefine = [\"normal\"]\n"),
            "study.refine: unknown variant `normal`, expected `x` or `y`",
        ),
        scene_case(
            "boundary-tag-with-control-characters",
            bar(&[("tag = \"left\"", "tag = \"left\\nx\\u001b[31m\"")]),
            "unknown boundary tag `left\\nx\\u{1b}[31m`",
        ),
        scene_case(
            "long-boundary-tag",
            bar(&[("tag = \"left\"", &format!("tag = \"{}\"", "t".repeat(5000)))]),
            &format!("`{}…`", "t".repeat(80)),
        ),
    ]
}

fn command_line_cases() -> Vec<Case> {
    let rod = Some(ROD.to_string());
    let bar = Some(BAR.to_string());
    let long_bar = Some(edited(BAR, &[("t_end = 0.01", "t_end = 200.0")]));
    let bad_resolution = Some(format!(
        "{BAR}\n[[resolution]]\nbasis = \"pl\"\nblocks = [5000, 1]\n"
    ));
    let refine_y = Some(format!("{ROD}\n[study]\nrefine = [\"y\"]\n"));
    let long = "m".repeat(1000);
    // A block mesh whose only body is a Gmsh body: no lattice for --particles.
    let gmsh_body = format!(
        "name = \"g\"\ndim = 2\nbasis = \"pl\"\n\n[mesh]\nkind = \"blocks\"\nx = [0.0, 1.0]\ny = [0.0, 1.0]\nblocks = [4, 4]\n\n[material]\nyoung = 100.0\ndensity = 1.0\n\n[[body]]\nshape = \"gmsh\"\nfile = \"{}/../tests/data/square.msh\"\nsurface = \"domain\"\n\n[time]\ndt = 1e-3\nt_end = 0.01\n",
        env!("CARGO_MANIFEST_DIR")
    );
    let gmsh_resolution = Some(format!(
        "{gmsh_body}\n[[resolution]]\nbasis = \"pl\"\nper_block = [2, 2]\n"
    ));
    let gmsh_body = Some(gmsh_body);
    vec![
        // Two bases to `run` (a student's `compare` command): `compare` named.
        args_case(
            "run-two-bases",
            bar.clone(),
            &["run", "@", "--basis", "ps,pl"],
            "--basis: unknown basis `ps,pl` (known: ps, pl, bspline, pl1d); `run` takes one basis: to run several side by side, `mpm-cli compare SCENE --basis ps,pl`",
        ),
        args_case("particles-with-gmsh-bodies-only", gmsh_body.clone(), &["run", "@", "--particles", "2x2"], "--particles 2x2: every body is a Gmsh body (`shape = \"gmsh\"`), whose particles `per_triangle` and `subdivide` set"),
        args_case("converge-particles-with-gmsh-bodies-only", gmsh_body, &["converge", "@", "--particles", "2x2"], "--particles 2x2: every body is a Gmsh body"),
        args_case("resolution-per-block-with-gmsh-bodies-only", gmsh_resolution, &["run", "@"], "resolution[0].per_block: every body is a Gmsh body"),
        args_case("1d-blocks-second-number", rod.clone(), &["run", "@", "--blocks", "8x3"], "--blocks 8x3: a 1D scene has one count; the second number must be 1"),
        args_case("blocks-on-a-polygon-mesh", Some(SQUARE.to_string()), &["run", "@", "--blocks", "8x8"], "--blocks 8x8: mesh.blocks: the scene's mesh is a `polygon` mesh, which has no blocks: refine or coarsen it with `mesh.edge_length` in the scene file"),
        args_case("1d-particles-second-number", rod.clone(), &["run", "@", "--particles", "4x2"], "--particles 4x2: a 1D scene has one count"),
        args_case("1d-builtin-blocks", None, &["run", "vibrating-bar-1d", "--blocks", "8x2"], "the second number must be 1"),
        args_case("compare-1d-blocks", rod.clone(), &["compare", "@", "--blocks", "8x3"], "--blocks 8x3"),
        args_case("converge-1d-particles", None, &["converge", "vibrating-bar-1d", "--particles", "4x9"], "--particles 4x9"),
        args_case("compare-a-basis-twice", None, &["compare", "vibrating-bar", "--basis", "ps,pl,ps"], "--basis: `ps` is listed twice"),
        args_case("compare-a-mass-twice", None, &["compare", "vibrating-bar", "--mass", "lumped,partial,lumped"], "--mass: `lumped` is listed twice"),
        args_case("blocks-per-axis", None, &["run", "vibrating-bar", "--blocks", "5000x1"], "--blocks 5000x1: mesh.blocks: each count must be in 1..=4096"),
        args_case("blocks-in-all", None, &["run", "vibrating-bar", "--blocks", "4096x4096"], "above the limit of 1000000"),
        args_case("blocks-overflow", None, &["run", "vibrating-bar", "--blocks", "99999999999999999999999x1"], "--blocks must look like 4x1"),
        args_case("blocks-control-characters", None, &["run", "vibrating-bar", "--blocks", "4\u{1b}x1"], "got `4\\u{1b}x1`"),
        args_case("particles-over-the-limit", None, &["run", "vibrating-bar", "--blocks", "64x64", "--particles", "1000x1000"], "--particles 1000x1000"),
        args_case("dt-over-the-limit", None, &["run", "vibrating-bar", "--dt", "1e-12"], "--dt 1e-12: time.dt: t_end / dt = 5 / 1e-12 = 5.000e12 steps is above the limit of 10000000"),
        args_case("t-end-over-the-limit", None, &["run", "vibrating-bar", "--t-end", "1e9"], "--t-end 1000000000: "),
        // Numbers of flags are echoed in their shortest form (`-1`, not `-1.0`).
        args_case("negative-t-end", None, &["run", "vibrating-bar", "--t-end", "-1"], "--t-end -1: time.t_end: must be positive and finite, got -1"),
        // Particles per block on a mesh without blocks: said in the flag's words.
        args_case("particles-on-a-polygon-mesh", Some(SQUARE.to_string()), &["run", "@", "--particles", "4x4"], "--particles 4x4: sets the particles per block, which needs a `blocks` or `interval` mesh"),
        args_case("subnormal-dt", None, &["run", "vibrating-bar", "--dt", "5e-324"], "above the limit of 10000000"),
        args_case("nan-dt", None, &["run", "vibrating-bar", "--dt", "NaN"], "time.dt: must be positive and finite"),
        args_case("infinite-dt", None, &["run", "vibrating-bar", "--dt", "inf"], "time.dt: must be positive and finite"),
        args_case("infinite-t-end", None, &["run", "vibrating-bar", "--t-end", "inf"], "time.t_end: must be positive and finite"),
        args_case("t-end-before-one-step", None, &["run", "vibrating-bar", "--t-end", "1e-9"], "--t-end 1e-9: time.dt: 0.001 exceeds t_end = 1e-9"),
        args_case("compare-dt-over-the-limit", None, &["compare", "vibrating-bar", "--dt", "1e-12"], "--dt 1e-12"),
        args_case("converge-dt-over-the-limit", None, &["converge", "vibrating-bar", "--dt", "1e-12"], "above the limit of 10000000"),
        args_case("converge-target-error-not-positive", None, &["converge", "vibrating-bar", "--target-error", "0"], "--target-error must be a positive error, got 0"),
        args_case("converge-threads-zero", None, &["converge", "vibrating-bar", "--threads", "0"], "--threads"),
        args_case("frames-over-the-limit", long_bar.clone(), &["run", "@", "--out", "OUT", "--out-every", "1"], "--out-every 1: 200000 steps give 200002 particle frames, above the limit of 100000"),
        args_case("table-rows-over-the-limit", long_bar.clone(), &["run", "@", "--diag-every", "1"], "--diag-every 1: 200000 steps give 200000 table rows, above the limit of 100000"),
        args_case("long-layout", None, &["run", "vibrating-bar", "--layout", &long], &format!("unknown layout `{}…`", "m".repeat(80))),
        args_case("mass-with-escape", None, &["run", "vibrating-bar", "--mass", "lumped\u{1b}[2J"], "unknown mass strategy `lumped\\u{1b}[2J`"),
        args_case("mass-threshold-with-newline", None, &["run", "vibrating-bar", "--mass", "partial:1\n2"], "got `1\\n2`"),
        args_case("basis-with-bell", None, &["run", "vibrating-bar", "--basis", "ps\u{7}"], "unknown basis `ps\\u{7}`"),
        args_case("split-with-newline", None, &["run", "vibrating-bar", "--split", "in\ncentre"], "unknown split point `in\\ncentre`"),
        args_case("scene-name-with-escape", None, &["run", "bar\u{1b}[31m"], "unknown scene `bar\\u{1b}[31m`"),
        args_case("long-scene-name", None, &["run", &long], &format!("unknown scene `{}…`", "m".repeat(80))),
        args_case("scene-show-long-name", None, &["scene", "show", &long], "…`"),
        args_case("run-validates-resolution", bad_resolution.clone(), &["run", "@"], "resolution[0].blocks"),
        args_case("compare-validates-resolution", bad_resolution.clone(), &["compare", "@"], "resolution[0].blocks"),
        args_case("converge-validates-resolution", bad_resolution, &["converge", "@"], "resolution[0].blocks"),
        args_case("converge-refine-y-in-1d", refine_y.clone(), &["converge", "@"], "study.refine"),
        args_case("run-refine-y-in-1d", refine_y, &["run", "@"], "study.refine"),
        args_case("scene-show-file", bar.clone(), &["scene", "show", "nothing\u{1b}"], "nothing\\u{1b}"),
        args_case("project-mesh-dev-zero", None, &["project", "--mesh", "/dev/zero"], "/dev/zero: cannot read: not a regular file"),
        args_case("reproduce-study-with-escape", None, &["reproduce", "b9\u{1b}[1m"], "unknown study `b9\\u{1b}[1m`"),
        args_case("stability-case-with-escape", None, &["stability", "--dir", concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/stability"), "--cases", "b2\u{1b}"], "unknown case `b2\\u{1b}`"),
        args_case("project-mesh-directory", None, &["project", "--mesh", "/tmp"], "/tmp: cannot read"),
        args_case("threads-over-the-limit", None, &["run", "vibrating-bar", "--threads", "5000"], "--threads 5000 is above the limit of 1024"),
        args_case("compare-threads-over-the-limit", None, &["compare", "vibrating-bar", "--threads", "100000000"], "--threads 100000000 is above the limit of 1024"),
        args_case("stability-threads-over-the-limit", None, &["stability", "--threads", "2000"], "--threads 2000 is above the limit of 1024"),
        args_case("converge-level-refused-before-any-run", None, &["converge", "vibrating-bar", "--levels", "7", "--blocks", "1024x1"], "level 3: mesh.blocks: each count must be in 1..=4096, got [8192, 1]"),
        args_case(
            "converge-gmsh-mesh",
            Some(GMSH.replace("FILE", concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/square.msh"))),
            &["converge", "@", "--levels", "3"],
            "converge-gmsh-mesh.toml:6:8: mesh.kind: a Gmsh mesh cannot be refined by a study: `converge` refines `blocks`, `polygon` and `interval` meshes",
        ),
        args_case(
            "basis-plot-scene-names-its-file",
            Some(GMSH.replace("FILE", "none.msh")),
            &["basis", "plot", "--scene", "@", "--out", "OUT/plot.svg"],
            "basis-plot-scene-names-its-file.toml:7:8: mesh.file:",
        ),
    ]
}

/// Runs `case` in `dir`: `@` is the scene file, `OUT` an output directory.
fn run_case(dir: &Path, case: &Case) -> Result<(), String> {
    let scene = dir.join(format!("{}.toml", case.name));
    if let Some(text) = &case.scene {
        std::fs::write(&scene, text).unwrap();
    }
    let out_dir = dir.join(format!("{}-out", case.name));
    let args: Vec<String> = case
        .args
        .iter()
        .map(|a| match a.as_str() {
            "@" => scene.to_string_lossy().into_owned(),
            "OUT" => out_dir.to_string_lossy().into_owned(),
            _ => a.clone(),
        })
        .collect();
    let out = cli().args(&args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let mut problems = Vec::new();
    if out.status.code() != Some(case.status) {
        problems.push(format!(
            "status {:?}, expected {}",
            out.status.code(),
            case.status
        ));
    }
    if !stderr.contains(&case.fragment) {
        problems.push(format!("stderr lacks `{}`", case.fragment));
    }
    if stderr.contains("panicked") {
        problems.push("a panic".into());
    }
    if stderr.contains('\u{1b}') || stderr.lines().count() > 3 {
        problems.push("raw control characters or several lines echoed".into());
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{}: {}\n  stderr: {stderr}",
            case.name,
            problems.join("; ")
        ))
    }
}

fn check_all(test: &str, cases: Vec<Case>) {
    let dir = temp_dir(test);
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|c| run_case(&dir, c).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn extreme_scenes_are_rejected_naming_the_value_and_the_limit() {
    let cases = scene_cases();
    assert!(cases.len() >= 30);
    check_all("scenes", cases);
}

#[test]
fn extreme_command_lines_are_rejected_naming_the_flag() {
    let cases = command_line_cases();
    assert!(cases.len() >= 30);
    check_all("args", cases);
}

#[test]
fn mesh_and_scene_files_must_be_bounded_regular_files() {
    let dir = temp_dir("files");
    let gmsh = |file: &Path| GMSH.replace("FILE", &file.to_string_lossy());
    let mut cases = Vec::new();
    // Devices, FIFOs, directories and huge (sparse) files, as the mesh of a scene.
    let fifo = dir.join("mesh.fifo");
    let made_fifo = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    let big = dir.join("big.msh");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(300 * 1024 * 1024)
        .unwrap();
    cases.push(scene_case(
        "mesh-dev-zero",
        gmsh(Path::new("/dev/zero")),
        "mesh.file: /dev/zero: cannot read: not a regular file",
    ));
    cases.push(scene_case("mesh-directory", gmsh(&dir), "cannot read"));
    cases.push(scene_case(
        "mesh-too-big",
        gmsh(&big),
        "is 314572800 bytes, above the limit of 268435456 bytes",
    ));
    cases.push(scene_case(
        "mesh-missing",
        gmsh(&dir.join("none.msh")),
        "cannot read: No such file",
    ));
    if made_fifo {
        cases.push(scene_case("mesh-fifo", gmsh(&fifo), "not a regular file"));
    }
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|c| run_case(&dir, c).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The same files as `basis plot --mesh` (it read them unbounded, and a FIFO
    // blocked it).
    let mut meshes = vec![
        (std::path::PathBuf::from("/dev/zero"), "not a regular file"),
        (big.clone(), "above the limit of 268435456 bytes"),
    ];
    if made_fifo {
        meshes.push((fifo.clone(), "not a regular file"));
    }
    for (file, fragment) in meshes {
        let out = cli()
            .args(["basis", "plot", "--mesh"])
            .arg(&file)
            .arg("--out")
            .arg(dir.join("plot.svg"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{}: {stderr}", file.display());
        assert!(stderr.contains(fragment), "{}: {stderr}", file.display());
    }
    // The scene file itself.
    let big_scene = dir.join("big.toml");
    std::fs::File::create(&big_scene)
        .unwrap()
        .set_len(5 * 1024 * 1024)
        .unwrap();
    let zero_scene = dir.join("zero.toml");
    std::os::unix::fs::symlink("/dev/zero", &zero_scene).unwrap();
    let mut scenes = vec![
        (big_scene, "above the limit of 4194304 bytes"),
        (zero_scene, "cannot read: not a regular file"),
    ];
    let fifo_scene = dir.join("fifo.toml");
    if std::process::Command::new("mkfifo")
        .arg(&fifo_scene)
        .status()
        .is_ok_and(|s| s.success())
    {
        scenes.push((fifo_scene, "not a regular file"));
    }
    for (file, fragment) in scenes {
        let out = cli().arg("run").arg(&file).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{}: {stderr}", file.display());
        assert!(stderr.contains(fragment), "{}: {stderr}", file.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_exit_status_rule_is_in_the_help() {
    for args in [
        vec!["--help"],
        vec!["run", "--help"],
        vec!["compare", "--help"],
        vec!["reproduce", "--help"],
    ] {
        let out = cli().args(&args).output().unwrap();
        assert!(out.status.success());
        let help = String::from_utf8(out.stdout).unwrap();
        for fragment in ["Exit status", "130", "--strict", "bad input"] {
            assert!(
                help.contains(fragment),
                "{args:?} lacks {fragment}:\n{help}"
            );
        }
    }
}

#[test]
fn a_study_with_failed_variants_exits_0_unless_strict() {
    // A huge time step throws every variant's particles out of the mesh.
    let args = [
        "compare",
        "vibrating-bar",
        "--dt",
        "100",
        "--t-end",
        "1000",
        "--allow-above-critical",
        "--jobs",
        "1",
    ];
    let out = cli().args(args).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Each variant stopped early: the table says so.
    assert!(String::from_utf8_lossy(&out.stdout).contains("stopped"));
    let out = cli().args(args).arg("--strict").output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--strict: 2 of 2 variants"));
    // The same run alone is a failed run.
    let out = cli()
        .args(["run", "vibrating-bar", "--dt", "100", "--t-end", "1000"])
        .arg("--allow-above-critical")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn reproduce_exits_0_with_unstable_runs_unless_strict() {
    // The quick b4 has 4 unstable runs of 16 (its tables mark them), b5c none.
    let out = cli().args(["reproduce", "b4", "--quick"]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("- 4 of 16 runs failed or are unstable"),
        "{stdout}"
    );
    let out = cli()
        .args([
            "reproduce",
            "b5c,b4",
            "--quick",
            "--strict",
            "--format",
            "json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "error: --strict: 4 of 18 variants failed or are unstable (see the table)\n"
    );
    // Both studies were printed before the verdict, with their counts.
    let stdout = String::from_utf8(out.stdout).unwrap();
    let counts: Vec<(u64, u64)> = stdout
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            (
                v["runs"].as_u64().unwrap(),
                v["failed_runs"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(counts, [(2, 0), (16, 4)]);
    let out = cli()
        .args(["reproduce", "b5c", "--quick", "--strict"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn binary() -> std::process::Command {
    std::process::Command::new(assert_cmd::cargo::cargo_bin("mpm-cli"))
}

#[test]
fn a_reader_that_closes_early_ends_the_run_quietly() {
    let mut child = binary()
        .args([
            "run",
            "vibrating-bar",
            "--t-end",
            "50",
            "--diag-every",
            "1",
            "--format",
            "csv",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    assert!(lines.next().unwrap().unwrap().starts_with("step,"));
    assert!(lines.next().unwrap().unwrap().starts_with("1,"));
    drop(lines);
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(141), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // (the summary's `# error=` line is on stderr with --format csv)
    assert!(!stderr.contains("error:"), "{stderr}");
}

/// Sends `signal` (`INT`, `TERM`) to the process `pid`.
fn send(signal: &str, pid: u32) {
    let sent = std::process::Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(pid.to_string())
        .status()
        .unwrap();
    assert!(sent.success());
}

/// Starts a long run, waits for its first rows, sends `signal` and returns the exit
/// status and stderr.
fn interrupt(signal: &str, extra: &[&str]) -> (Option<i32>, String) {
    let mut child = binary()
        .args([
            "run",
            "vibrating-bar",
            "--t-end",
            "500",
            "--diag-every",
            "10",
            "--format",
            "csv",
        ])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    lines.next().unwrap().unwrap();
    lines.next().unwrap().unwrap();
    send(signal, child.id());
    // Read on until the run ends.
    for line in lines {
        line.unwrap();
    }
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    (child.wait().unwrap().code(), stderr)
}

#[test]
fn sigint_writes_the_files_and_exits_130() {
    let dir = temp_dir("sigint");
    let out = dir.join("out");
    let (code, stderr) = interrupt("INT", &["--out", &out.to_string_lossy()]);
    assert_eq!(code, Some(130), "{stderr}");
    assert!(stderr.contains("error: interrupted"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["interrupted"], true);
    let steps = summary["steps"].as_u64().unwrap();
    assert!(steps > 0 && steps < 500_000, "{steps}");
    let pvd = std::fs::read_to_string(out.join("particles.pvd")).unwrap();
    assert!(pvd.trim_start().starts_with("<?xml"), "{pvd}");
    assert!(pvd.trim_end().ends_with("</VTKFile>"), "{pvd}");
    let files: Vec<&str> = pvd
        .split("file=\"")
        .skip(1)
        .map(|rest| &rest[..rest.find('"').unwrap()])
        .collect();
    assert!(files.len() >= 2, "{pvd}");
    for file in &files {
        assert!(out.join(file).is_file(), "{file}");
    }
    // The last frame is the state where the run stopped.
    let last_time: f64 = pvd
        .rsplit("timestep=\"")
        .next()
        .map(|rest| rest[..rest.find('"').unwrap()].parse().unwrap())
        .unwrap();
    assert_eq!(last_time, summary["t_end"].as_f64().unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sigterm_stops_a_run_with_130_and_says_so() {
    let (code, stderr) = interrupt("TERM", &[]);
    assert_eq!(code, Some(130), "{stderr}");
    assert!(stderr.contains("error: interrupted"), "{stderr}");
}

/// A signal during the set-up exits at once, saying that nothing was run: the
/// set-up of a large mesh takes seconds to minutes (a user's 1000 × 1000 PS mesh
/// for 36 particles), which a stop after it made the user wait out. This mesh's
/// set-up takes several seconds; the signal comes after half a second.
#[test]
fn a_signal_during_the_set_up_exits_at_once() {
    let scene = SceneFile::new(
        "set-up-signal",
        "name = \"big-mesh\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"blocks\"\nx = [0.0, 10.0]\ny = [0.0, 10.0]\nblocks = [200, 200]\n[material]\nyoung = 1e4\npoisson = 0.3\ndensity = 1.0\n[[body]]\nmin = [4.0, 4.0]\nmax = [4.5, 4.5]\nper_block = [3, 3]\n[time]\ncourant = 0.5\nt_end = 1.0\n",
    );
    let child = binary()
        .args(["run", scene.arg(), "--threads", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(500));
    let signalled = std::time::Instant::now();
    send("INT", child.id());
    let out = child.wait_with_output().unwrap();
    let waited = signalled.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert_eq!(
        stderr, "interrupted during the set-up: nothing was run\n",
        "{stderr}"
    );
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(waited < 2.0, "exited {waited} s after the signal");
}

/// An interrupted `compare` prints the table of what ran (a student's printed
/// nothing): the variant running stops after its step and is marked
/// `interrupted`, those not started are left out and counted, and the exit
/// status is 130.
#[test]
fn an_interrupted_comparison_prints_what_ran() {
    let child = binary()
        .args([
            "compare",
            "vibrating-bar",
            "--basis",
            "ps,pl",
            "--t-end",
            "500",
            "--jobs",
            "1",
            "--threads",
            "1",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    send("INT", child.id());
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    // The PS variant's row (and its tracked displacement), none for PL.
    let rows = |basis: &str| {
        stdout
            .lines()
            .filter(|l| l.trim_start().starts_with(basis))
            .collect::<Vec<_>>()
    };
    assert!(
        rows("ps ")
            .first()
            .is_some_and(|row| row.contains("interrupted"))
            && rows("pl ").is_empty(),
        "{stdout}"
    );
    assert!(
        stderr.contains(
            "interrupted: 0 of the 2 variants ran to their end, 1 stopped early (`interrupted` in the table), 1 not started"
        ),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// `mpm_cli::check` (what the `cli_args` fuzz target drives) validates a command
/// line as the command would, without running it.
#[test]
fn check_validates_command_lines_without_running_them() {
    use mpm_cli::{check, Checked};
    let checked = |args: &[&str]| check(std::iter::once("mpm-cli").chain(args.iter().copied()));
    match checked(&["run", "vibrating-bar", "--dt", "1e-4", "--blocks", "8x1"]) {
        Ok(Checked::Run(s)) => {
            assert_eq!(s.time.dt, Some(1e-4));
            assert_eq!(s.blocks(), Some([8, 1]));
        }
        other => panic!("{other:?}"),
    }
    match checked(&["compare", "vibrating-bar", "--mass", "lumped,consistent"]) {
        Ok(Checked::Scenes(s)) => assert_eq!(s.len(), 4),
        other => panic!("{other:?}"),
    }
    match checked(&[
        "converge",
        "vibrating-bar",
        "--levels",
        "2",
        "--basis",
        "ps",
    ]) {
        Ok(Checked::Scenes(s)) => {
            assert_eq!(s.len(), 2);
            assert_eq!(s[1].blocks().unwrap()[0], 2 * s[0].blocks().unwrap()[0]);
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(checked(&["scenes"]), Ok(Checked::Parsed)));
    for (args, fragment) in [
        (&["run", "vibrating-bar", "--dt=-1"][..], "time.dt"),
        (
            &["run", "vibrating-bar", "--threads", "0"],
            "--threads must be at least 1",
        ),
        (&["run", "vibrating-bar", "--bogus"], "--bogus"),
        (&["--help"], "Usage"),
        (
            &["compare", "vibrating-bar", "--jobs", "0"],
            "--jobs must be at least 1",
        ),
        (&["run", "no-such-scene"], "unknown scene"),
    ] {
        match checked(args) {
            Err(e) => {
                assert_eq!(e.exit_code(), 2, "{args:?}: {e}");
                assert!(e.to_string().contains(fragment), "{args:?}: {e}");
            }
            Ok(other) => panic!("{args:?}: {other:?}"),
        }
    }
}

/// A scene that fails at set-up (its body reaches outside the mesh) is bad input:
/// exit status 2, "nothing was run", and `--out` holds nothing of it (a new
/// directory is not left behind, an existing empty one stays empty), so that the
/// corrected scene runs into the same directory without `--overwrite`.
#[test]
fn a_scene_error_leaves_nothing_in_out() {
    let dir = temp_dir("scene-error-out");
    let good = edited(BAR, &[("mass = \"consistent\"", "mass = \"lumped\"")]);
    let bad = edited(&good, &[("max = [4.0, 1.0]", "max = [4.5, 1.0]")]);
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, &bad).unwrap();
    let fresh = dir.join("fresh");
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    for out in [&fresh, &empty] {
        let o = cli()
            .arg("run")
            .arg(&scene)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("lies outside the mesh"), "{stderr}");
    }
    assert!(!fresh.exists(), "{} was left behind", fresh.display());
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0);
    // The corrected scene runs into the same directory.
    std::fs::write(&scene, &good).unwrap();
    let o = cli()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&empty)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(empty.join("diagnostics.csv").exists());
    // A Courant number of 1 or more runs only when asked to.
    let fast = edited(&good, &[("dt = 1e-3", "courant = 1.5")]);
    std::fs::write(&scene, fast).unwrap();
    let o = cli()
        .arg("run")
        .arg(&scene)
        .args(["--allow-above-critical", "--diag-every", "0"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("time.courant"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `mpm-cli ARGS` run under an address-space limit of `kilobytes` (`ulimit -v`, set
/// for the child alone).
#[cfg(target_os = "linux")]
fn under_address_space_limit(kilobytes: u32, args: &[&str]) -> std::process::Output {
    std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kilobytes} && exec \"$0\" \"$@\""))
        .arg(assert_cmd::cargo::cargo_bin("mpm-cli"))
        .args(args)
        .output()
        .unwrap()
}

/// A valid scene (9e6 PS particles, under the particle limit) that needs more
/// memory than the process may use is refused before anything large is allocated,
/// naming the file, line and field, the memory needed and the limit, instead of
/// aborting at an allocation ("memory allocation of … bytes failed", status 134,
/// as a user found with `ulimit -v 1500000`). The limit is set for the child alone.
#[test]
#[cfg(target_os = "linux")]
fn a_scene_that_cannot_fit_in_the_memory_allowed_is_refused_with_the_reason() {
    let file = SceneFile::new(
        "huge",
        r#"name = "huge"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 4.0]
blocks = [64, 64]
[material]
model = "linear-elastic"
young = 1e5
poisson = 0.3
density = 1000.0
[[body]]
min = [1.0, 1.0]
max = [3.0, 3.0]
per_block = [94, 94]
[time]
courant = 0.5
t_end = 1.0
"#,
    );
    let out = under_address_space_limit(1500000, &["run", file.arg()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "huge.toml:17:13: body[0].per_block: the run would need about 4.8 GB (9048064 particles",
        "this process may still use by its address-space limit (`ulimit -v`)",
        "give fewer particles",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }

    // With `--out`, the buffers of the compressed frames count too: 1.44e6
    // particles that fit in 1 GB without output are refused with it (they aborted
    // at the first frame before).
    let file = SceneFile::new(
        "framed",
        r#"name = "framed"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 2.0]
y = [0.0, 2.0]
blocks = [8, 8]
[material]
young = 1e5
poisson = 0.3
density = 100.0
[[body]]
min = [0.75, 1.0]
max = [1.25, 1.5]
count = [1200, 1200]
[time]
courant = 0.4
t_end = 0.8
"#,
    );
    let dir = std::env::temp_dir().join(format!("psmpm-framed-out-{}", std::process::id()));
    let out = under_address_space_limit(
        1000000,
        &["run", file.arg(), "--out", dir.to_str().unwrap()],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "framed.toml:16:9: body[0].count: the run would need about 1.3 GB (1440000 particles at 754 B each, 304 of them to write the output, 256 triangles",
        "by its address-space limit (`ulimit -v`)",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A `polygon` mesh too large for the memory allowed is refused before the mesher
/// runs, from the fewest triangles it can make (the domain's area over the largest
/// triangle it leaves): under `ulimit -v 150000` this scene aborted inside the
/// mesher ("memory allocation of … bytes failed", status 134; a user found it at
/// 0.8 × a run's peak), since the memory check counted a polygon mesh only once
/// built.
#[test]
#[cfg(target_os = "linux")]
fn a_polygon_mesh_too_large_for_the_memory_allowed_is_refused_before_meshing() {
    let file = SceneFile::new(
        "fine-polygon",
        r#"name = "fine-polygon"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
tags = ["floor", "right", "top", "left"]
edge_length = 0.04
[material]
young = 1e4
poisson = 0.3
density = 1.0
[[body]]
min = [4.0, 4.0]
max = [4.5, 4.5]
count = [12, 12]
[time]
courant = 0.5
t_end = 0.01
"#,
    );
    let out = under_address_space_limit(150000, &["run", file.arg()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "fine-polygon.toml:8:15: mesh.edge_length: the run would need about 711 MB (144 particles",
        "at least 144337 triangles (the domain's area over the largest triangle the mesher leaves",
        "counted before meshing",
        "give a coarser mesh",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
}

/// Under an address-space limit each thread's allocator reserves up to 64 MB that
/// the limit counts: a user's 64-triangle scene under `ulimit -v 400000` with
/// `--threads 8` was refused and told to coarsen its mesh (with 2 threads it
/// ran). It runs, or is refused naming the threads as the fix, never the mesh.
#[test]
#[cfg(target_os = "linux")]
fn a_run_refused_for_its_threads_address_space_names_the_threads() {
    let file = SceneFile::new(
        "tiny",
        r#"name = "tiny"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 1.0]
y = [0.0, 1.0]
blocks = [4, 4]
[material]
young = 1e4
poisson = 0.3
density = 1.0
[[body]]
min = [0.25, 0.25]
max = [0.75, 0.75]
per_block = [2, 2]
[time]
courant = 0.5
t_end = 0.01
"#,
    );
    for threads in ["8", "16"] {
        let out = under_address_space_limit(
            400000,
            &["run", file.arg(), "--threads", threads, "--diag-every", "0"],
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        match out.status.code() {
            Some(0) => {}
            Some(2) => assert!(
                stderr.contains("run with fewer threads")
                    && !stderr.contains(": give a coarser mesh"),
                "{threads} threads: {stderr}"
            ),
            _ => panic!("{threads} threads: {out:?}"),
        }
    }
}

/// A 1D bar whose fixed `dt` is far above any 1D critical step (1000 crossings of
/// an element by the P-wave; the largest critical step of a 1D basis and mass
/// strategy is 1.4 crossings) is refused before its mesh and basis are built: a
/// user's 1e6 elements took 7 s and 1.2 GB of set-up to be told so. A step of
/// three crossings, which no basis takes either but which this check lets pass,
/// gets the estimated critical step's error after the set-up.
#[test]
fn a_1d_step_far_above_any_critical_step_is_refused_before_the_set_up() {
    let bar = |elements: usize, dt: &str| {
        format!(
            r#"name = "long-bar"
dim = 1
basis = "bspline"
[mesh]
kind = "interval"
x = [0.0, 2.0]
elements = {elements}
[material]
young = 200.0
density = 2.0
[[body]]
min = [0.0]
max = [2.0]
per_block = [1]
[[boundary]]
tag = "left"
fix = ["x"]
[time]
dt = {dt}
t_end = 0.4
"#
        )
    };
    let file = SceneFile::new("long-bar", &bar(1_000_000, "2e-4"));
    let out = cli().args(["run", file.arg()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "long-bar.toml:19:6: time.dt: the time step 0.0002 is 1000 times the 2e-7 the fastest P-wave",
        "no 1D basis or mass strategy has a critical step above 4 such crossings (8e-7;",
        "give `courant = 0.5` instead of `dt`",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
    // Not a timing assertion: a set-up of 1e6 elements would have printed the
    // estimated critical step's message instead.
    assert!(!stderr.contains("estimated at the start"), "{stderr}");
    let file = SceneFile::new("short-bar", &bar(100, "6e-3"));
    let out = cli().args(["run", file.arg()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("is above the critical step") && stderr.contains("estimated at the start"),
        "{stderr}"
    );
}

/// A critical step far below the lumped mass's comes from a row of the mass
/// strategy's system with almost no particle mass (a user's `partial` on a disk of
/// 28 particles over 700 triangles), not from the units: the error too many steps
/// gives names the nearly singular mass and points to the default mass strategy,
/// as the error for a fixed `dt` above the critical step does, where it said to
/// check `young` and `density`.
#[test]
fn a_critical_step_set_by_the_mass_strategy_is_named_so_not_the_units() {
    let file = SceneFile::new(
        "sparse-disk",
        r#"name = "sparse-disk"
dim = 2
basis = "ps"
mass = "partial"
[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 4.0]
blocks = [50, 50]
[material]
model = "neo-hookean"
young = 2e3
poisson = 0.3
density = 1.0
[[body]]
shape = "disk"
centre = [2.0, 0.4]
radius = 0.15
count = [6, 6]
[time]
courant = 0.5
t_end = 1e6
"#,
    );
    let out = cli().args(["run", file.arg()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "time.t_end: t_end = 1000000 with courant = 0.5",
        "The critical step is that small because the mass matrix is nearly singular",
        "times below the lumped mass's",
        "the default mass strategy (`mass = \"default\"`)",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
    assert!(!stderr.contains("system of units"), "{stderr}");
}

/// A body far too soft for its density (E = 0.1 Pa, typed in MPa): its critical
/// step is seconds long, and a step of it carries the body, at rest at the start,
/// tens of elements under gravity. The watch counts the speed the loads add over
/// the step and refuses the step, naming the soft material; without the watch the
/// run is not reported complete with its body fallen out of the mesh in its last
/// (and only) step (it was: "stable", exit 0).
#[test]
fn a_body_carried_out_of_the_mesh_by_one_long_step_fails_the_run() {
    let scene = r#"name = "soft-drop"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 4.0]
blocks = [16, 16]
[material]
model = "neo-hookean"
young = 0.1
poisson = 0.3
density = 1000.0
[[body]]
min = [1.5, 2.0]
max = [2.5, 3.0]
per_block = [4, 4]
[[boundary]]
tag = "bottom"
fix = ["normal"]
[[effect]]
kind = "gravity"
g = [0.0, -9.81]
[time]
courant = 0.5
t_end = 1.0
"#;
    let file = SceneFile::new("soft-drop", scene);
    let out = cli().args(["run", file.arg()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for part in [
        "step 1: particle",
        "within the step",
        "from the loads' acceleration, 9.810e0",
        "the material is very soft for its density",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
    let out = cli()
        .args(["run", file.arg(), "--no-watch"])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stdout.contains("FAILED"), "{stdout}");
    for part in [
        "step 1: particle",
        "left the mesh; it moved 9.810e0 in the last step",
        "widths of its element",
        "the watch over the step is off (`--no-watch`)",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
}

/// A scene file named without its `.toml` (`run drop` for `drop.toml`): the
/// message names the file that is there.
#[test]
fn a_scene_file_named_without_its_extension_is_pointed_at() {
    let file = SceneFile::new("lab-drop", &edited(BAR, &[]));
    let dir = file.path.parent().unwrap();
    let out = cli()
        .current_dir(dir)
        .args(["run", "lab-drop"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("unknown scene `lab-drop` (known: ")
            && stderr
                .contains("; a scene file `lab-drop.toml` is here: give the file's whole name"),
        "{stderr}"
    );
}

/// A disk thrown through a mostly empty polygon mesh with `deactivate`: the
/// functions it drops hold the moving disk's edge at zero velocity and an element
/// inverts in free flight, at 7 particles per triangle as at 28. The message
/// names the dropped functions and the default strategy (it advised more
/// particles, which did not help).
#[test]
fn an_element_inverted_by_dropped_functions_names_the_default_strategy() {
    let scene = r#"name = "disk-throw"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [3.0, 0.0], [3.0, 2.0], [0.0, 2.0]]
tags = ["bottom", "right", "top", "left"]
edge_length = 0.1
[[mesh.holes]]
outline = [[2.0, 0.8], [2.4, 0.8], [2.4, 1.2], [2.0, 1.2]]
tag = "post"
[material]
young = 1e5
poisson = 0.3
density = 1000.0
[[body]]
shape = "disk"
centre = [0.8, 1.0]
radius = 0.3
spacing = [0.025, 0.025]
initial_velocity = { kind = "uniform", value = [3.0, 0.0] }
[[boundary]]
tag = "post"
fix = ["x", "y"]
[time]
courant = 0.5
t_end = 0.8
"#;
    let file = SceneFile::new("disk-throw", scene);
    let out = cli()
        .args([
            "run",
            file.arg(),
            "--mass",
            "deactivate",
            "--diag-every",
            "0",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for part in [
        "the Jacobian det F",
        "`deactivate:0.01` dropped",
        "use the default mass strategy (`extended-hybrid`: remove `mass`, or `--mass default`)",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
    assert!(
        !stderr.contains("use more particles per element"),
        "{stderr}"
    );
}

/// A wall tagged with the name of the Gmsh file's physical surface (the domain's
/// triangles, not boundary curves): the message says so and what a wall needs.
#[test]
fn a_wall_tagged_with_a_physical_surface_is_told_it_needs_a_curve() {
    let scene = format!(
        "name = \"g\"\ndim = 2\nbasis = \"pl\"\n[mesh]\nkind = \"gmsh\"\nfile = \"{}/../tests/data/square.msh\"\n[material]\nyoung = 100.0\ndensity = 1.0\n[[body]]\nmin = [0.25, 0.25]\nmax = [0.75, 0.75]\nspacing = [0.1, 0.1]\n[[boundary]]\ntag = \"domain\"\nfix = [\"normal\"]\n[time]\ndt = 1e-3\nt_end = 0.01\n",
        env!("CARGO_MANIFEST_DIR")
    );
    let file = SceneFile::new("surface-wall", &scene);
    let out = cli().args(["run", file.arg()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for part in [
        "boundary[0].tag: unknown boundary tag `domain`",
        "`domain` is a physical surface of",
        "not a curve; a wall is on boundary edges, tagged by a physical curve",
    ] {
        assert!(stderr.contains(part), "{part:?} not in {stderr}");
    }
}
