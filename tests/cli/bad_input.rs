//! Malformed input reaches the user as one line with exit status 2, never as a panic.
//!
//! `mpm-cli run FILE.toml` is fed malformed scenes (syntax errors, unknown fields,
//! wrong types, out-of-range values, inconsistent scenes, missing fields, unknown
//! kinds) and malformed Gmsh meshes (`tests/data/bad/*.msh`, read through a scene's
//! `mesh.file` and through `mpm-cli project --mesh`). Each case checks the whole of
//! stderr: `error: FILE:LINE:COLUMN: FIELD: what is wrong` for scene-file errors,
//! the value and the allowed range for out-of-range values, and the mesh file and
//! line for mesh errors.
//!
//! Each malformed scene is one of the small base scenes below with a few edits. In
//! an edit, `@@` marks where the error is located (`FILE:LINE:COLUMN`); it is
//! removed before the file is written. A case without `@@` expects no location.
//!
//! `known_library_gaps` keeps the gaps these cases first found (errors without a
//! location or a field name, locations that were off) closed.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/cli.rs"]
mod common_cli;

use common::temp_dir;
use common_cli::cli;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A 2D elastic bar on blocks with every optional table.
const BAR: &str = r#"# A small bar: the base of most malformed scenes.
name = "bar"
description = "a bar fixed at both ends"
dim = 2
basis = "ps"
split = "incentre"
mass = "consistent"

[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 1.0]
blocks = [4, 1]
layout = "four-triangles"

[material]
model = "linear-elastic"
young = 100.0
poisson = 0.25
density = 1.0

[[body]]
min = [0.0, 0.0]
max = [4.0, 1.0]
per_block = [4, 4]

[initial_velocity]
kind = "exact"

[[boundary]]
tag = "left"
fix = ["x", "y"]

[[boundary]]
tag = "right"
fix = ["x", "y"]

[time]
dt = 1e-3
t_end = 0.01

[reference]
kind = "vibrating-bar"
v0 = 0.1

[output]
tracked = [[2.0, 0.5]]
diagnostics_every = 5

[[resolution]]
basis = "pl"
blocks = [8, 1]

[study]
refine = ["x"]
"#;

/// A 2D column under gravity with damping and a Courant number.
const COLUMN: &str = r#"name = "column"
dim = 2
basis = "pl"
mass = "lumped"

[mesh]
kind = "blocks"
x = [0.0, 1.0]
y = [0.0, 4.0]
blocks = [1, 4]

[material]
model = "linear-elastic"
young = 5e4
density = 1.0

[[body]]
min = [0.0, 0.0]
max = [1.0, 4.0]
per_block = [2, 2]

[[boundary]]
tag = "bottom"
fix = ["x", "y"]

[[effect]]
kind = "gravity"
g = [0.0, -9.81]

[[effect]]
kind = "damping"
alpha = 0.1

[[effect]]
kind = "traction"
min = [0.0, 3.5]
max = [1.0, 4.0]
traction = [0.0, -1.0]
length = 1.0
ramp = 0.1

[time]
courant = 0.5
t_end = 0.01

[reference]
kind = "column-self-weight"
"#;

/// A 1D bar.
const BAR_1D: &str = r#"name = "bar-1d"
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

/// The neo-Hookean manufactured solution on a polygon mesh.
const SQUARE: &str = r#"name = "square"
dim = 2
basis = "ps"
mass = "consistent"

[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
tags = ["bottom", "right", "top", "left"]
edge_length = 0.25

[material]
model = "neo-hookean"
young = 1e7
poisson = 0.3
density = 1e3

[[body]]
min = [0.0, 0.0]
max = [1.0, 1.0]
count = [16, 16]

[initial_velocity]
kind = "exact"

[[boundary]]
tag = "left"
fix = ["x"]

[[boundary]]
tag = "bottom"
fix = ["y"]

[[effect]]
kind = "manufactured-body-force"

[time]
dt = 1e-4
t_end = 1e-3

[reference]
kind = "axis-aligned"
u0 = 0.05
"#;

/// A Gmsh mesh next to the scene file (in `meshes/`).
const GMSH: &str = r#"name = "gmsh-square"
dim = 2
basis = "pl"
mass = "lumped"

[mesh]
kind = "gmsh"
file = "meshes/square.msh"

[material]
model = "linear-elastic"
young = 100.0
density = 1.0

[[body]]
min = [0.0, 0.0]
max = [1.0, 1.0]
count = [8, 8]

[[boundary]]
tag = "bottom"
fix = ["x", "y"]

[time]
dt = 1e-3
t_end = 0.01
"#;

const BASES: [(&str, &str); 5] = [
    ("bar", BAR),
    ("column", COLUMN),
    ("bar-1d", BAR_1D),
    ("square", SQUARE),
    ("gmsh", GMSH),
];

/// A malformed scene and the message it must give.
struct Case {
    name: &'static str,
    text: String,
    message: String,
}

fn case(name: &'static str, base: &str) -> Case {
    Case {
        name,
        text: base.to_string(),
        message: String::new(),
    }
}

impl Case {
    /// Replaces the one occurrence of `from` by `to`.
    fn edit(mut self, from: &str, to: &str) -> Case {
        let n = self.text.matches(from).count();
        assert_eq!(n, 1, "case {}: `{from}` occurs {n} times", self.name);
        self.text = self.text.replacen(from, to, 1);
        self
    }

    /// Applies `f` to the whole text.
    fn map(mut self, f: impl Fn(&str) -> String) -> Case {
        self.text = f(&self.text);
        self
    }

    /// Puts the location mark at `line`, `column` (1-based) of the text without marks.
    fn at(mut self, line: usize, column: usize) -> Case {
        let text = self.text.replace("@@", "");
        let start: usize = text
            .split_inclusive('\n')
            .take(line - 1)
            .map(str::len)
            .sum();
        let offset = start
            + text[start..]
                .char_indices()
                .nth(column - 1)
                .map_or(text.len() - start, |(i, _)| i);
        self.text = format!("{}@@{}", &text[..offset], &text[offset..]);
        self
    }

    /// The message after `FILE:LINE:COLUMN: ` (`{dir}`: the scene's directory).
    fn expect(mut self, message: &str) -> Case {
        self.message = message.to_string();
        self
    }

    /// The text to write and the expected stderr for the scene file `path`.
    fn resolve(&self, path: &Path) -> (String, String) {
        let dir = path.parent().unwrap().display().to_string();
        let message = self.message.replace("{dir}", &dir);
        match self.text.find("@@") {
            Some(at) => {
                let before = &self.text[..at];
                let line = before.matches('\n').count() + 1;
                let column = at - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                let expected = format!("error: {}:{line}:{column}: {message}\n", path.display());
                (self.text.replacen("@@", "", 1), expected)
            }
            None => (self.text.clone(), format!("error: {message}\n")),
        }
    }
}

/// Runs `args`, checks status 2, one `error: ` line and no panic; returns stderr.
fn input_error(args: &[&str]) -> Result<String, String> {
    let out = cli().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if stderr.contains("panicked") {
        return Err(format!("panicked:\n{stderr}"));
    }
    if out.status.code() != Some(2) {
        return Err(format!("exit status {:?}:\n{stderr}", out.status.code()));
    }
    if !stderr.starts_with("error: ") || stderr.lines().count() != 1 {
        return Err(format!("not one `error: ` line:\n{stderr}"));
    }
    Ok(stderr)
}

/// The 1-based line of the first line of `file` that starts with `needle`.
fn line_of(file: &Path, needle: &str) -> usize {
    let text = std::fs::read_to_string(file).unwrap();
    1 + text
        .lines()
        .position(|l| l.starts_with(needle))
        .unwrap_or_else(|| panic!("`{needle}` not in {}", file.display()))
}

fn syntax_cases() -> Vec<Case> {
    vec![
        case("unterminated-string", BAR)
            .edit("name = \"bar\"", "name = \"bar@@")
            .expect("name: invalid basic string, expected `\"`"),
        case("unterminated-array", BAR)
            .edit("x = [0.0, 4.0]\n", "x = [0.0, 4.0\n@@")
            .expect("missing comma between array elements, expected `,`"),
        case("bad-table-header", BAR)
            .edit("[material]", "[material@@")
            .expect("unclosed table, expected `]`"),
        case("bad-array-of-tables-header", BAR)
            .edit("[[resolution]]", "[[resolution]@@")
            .expect("unclosed array table, expected `]`"),
        case("duplicate-key", BAR)
            .edit("density = 1.0", "density = 1.0\n@@density = 2.0")
            .expect("material.density: duplicate key"),
        case("duplicate-table", BAR)
            .edit("[time]", "@@[material]\nyoung = 5.0\ndensity = 1.0\n\n[time]")
            .expect("material: duplicate table `[material]`: give each table once"),
        case("key-without-value", BAR)
            .edit("young = 100.0", "young @@100.0")
            .expect("key with no value, expected `=`"),
        case("bad-escape", BAR)
            .edit("description = \"a bar", "description = \"a \\@@q bar")
            .expect("description: missing escaped value, expected `b`, `e`, `f`, `n`, `r`, `\\`, `\"`, `x`, `u`, `U`"),
        case("trailing-garbage", BAR)
            .edit("name = \"bar\"", "name = \"bar\" @@x")
            .expect("name: unexpected key or value, expected newline, `#`"),
        // Line endings and a byte-order mark do not shift the location.
        case("crlf-line-endings", BAR)
            .edit("dt = 1e-3", "dt = @@-1e-3")
            .map(|t| t.replace('\n', "\r\n"))
            .expect("time.dt: must be positive and finite, got -0.001"),
        case("byte-order-mark", BAR)
            .edit("dt = 1e-3", "dt = @@-1e-3")
            .map(|t| format!("\u{feff}{t}"))
            .expect("time.dt: must be positive and finite, got -0.001"),
    ]
}

fn unknown_field_cases() -> Vec<Case> {
    vec![
        case("unknown-top-level-field", BAR)
            .edit("dim = 2\n", "dim = 2\n@@colour = \"red\"\n")
            .expect("colour: unknown field `colour`, expected one of `name`, `description`, `dim`, `basis`, `split`, `mirror_line`, `mass`, `mesh`, `material`, `body`, `initial_velocity`, `boundary`, `effect`, `time`, `reference`, `output`, `resolution`, `study`"),
        case("unknown-top-level-table", BAR)
            .edit("[study]", "[@@solver]")
            .expect("unknown field `solver`, expected one of `name`, `description`, `dim`, `basis`, `split`, `mirror_line`, `mass`, `mesh`, `material`, `body`, `initial_velocity`, `boundary`, `effect`, `time`, `reference`, `output`, `resolution`, `study`"),
        case("unknown-field-in-mesh", BAR)
            .edit("[mesh]", "@@[mesh]")
            .edit("blocks = [4, 1]", "blocks = [4, 1]\nblock = [4, 1]")
            .at(14, 1).expect("mesh.block: unknown field `block` (did you mean `blocks`?), expected one of `x`, `y`, `blocks`, `layout`"),
        case("unknown-field-in-inline-mesh", BAR)
            .edit("[mesh]\nkind = \"blocks\"\nx = [0.0, 4.0]\ny = [0.0, 1.0]\nblocks = [4, 1]\nlayout = \"four-triangles\"\n\n", "")
            .edit("mass = \"consistent\"\n", "mass = \"consistent\"\nmesh = @@{ kind = \"blocks\", x = [0.0, 4.0], y = [0.0, 1.0], blocks = [4, 1], nx = 4 }\n")
            .expect("mesh: unknown field `nx`, expected one of `x`, `y`, `blocks`, `layout`"),
        case("unknown-field-in-material", BAR)
            .edit("density = 1.0", "density = 1.0\n@@young_modulus = 3.0")
            .expect("material.young_modulus: unknown field `young_modulus` (did you mean `young`?), expected one of `model`, `young`, `poisson`, `density`"),
        case("unknown-field-in-body", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\n@@speed = 1.0")
            .expect("body[0].speed: unknown field `speed` (did you mean `seed`?), expected one of `shape`, `min`, `max`, `outline`, `holes`, `centre`, `radius`, `file`, `surface`, `per_triangle`, `subdivide`, `per_block`, `count`, `spacing`, `jitter`, `seed`, `material`, `initial_velocity`"),
        case("unknown-field-in-boundary", BAR)
            .edit("tag = \"right\"", "tag = \"right\"\n@@fixed = true")
            .expect("boundary[1].fixed: unknown field `fixed`, expected `tag` or `fix`"),
        case("unknown-field-in-effect", COLUMN)
            .edit("[[effect]]\nkind = \"gravity\"", "@@[[effect]]\nkind = \"gravity\"")
            .edit("alpha = 0.1", "alpha = 0.1\nbeta = 0.2")
            .at(33, 1).expect("effect[1].beta: unknown field `beta`, expected `alpha`"),
        case("unknown-field-in-time", BAR)
            .edit("dt = 1e-3", "dt = 1e-3\n@@steps = 10")
            .expect("time.steps: unknown field `steps`, expected one of `dt`, `courant`, `t_end`, `allow_above_critical`, `watch`"),
        case("unknown-field-in-reference", BAR)
            .edit("[reference]", "@@[reference]")
            .edit("v0 = 0.1", "v0 = 0.1\namplitude = 2.0")
            .at(45, 1).expect("reference.amplitude: unknown field `amplitude`, expected `v0`"),
        case("unknown-field-in-output", BAR)
            .edit("diagnostics_every = 5", "diagnostics_every = 5\n@@every = 3")
            .expect("output.every: unknown field `every`, expected one of `tracked`, `diagnostics_every`, `condition`"),
        case("unknown-field-in-resolution", BAR)
            .edit("blocks = [8, 1]", "blocks = [8, 1]\n@@colour = 1")
            .expect("resolution[0].colour: unknown field `colour`, expected one of `basis`, `blocks`, `edge_length`, `per_block`"),
        case("unknown-field-in-study", BAR)
            .edit("refine = [\"x\"]", "refine = [\"x\"]\n@@levels = 3")
            .expect("study.levels: unknown field `levels`, expected `refine` or `particle_growth`"),
        case("unknown-field-in-initial-velocity", BAR)
            .edit("[initial_velocity]", "@@[initial_velocity]")
            .edit("kind = \"exact\"", "kind = \"sine-mode\"\nv0 = 1.0\nv1 = 2.0")
            .at(30, 1).expect("initial_velocity.v1: unknown field `v1`, expected `v0`"),
    ]
}

fn type_cases() -> Vec<Case> {
    vec![
        case("string-for-integer", BAR)
            .edit("dim = 2", "dim = @@\"two\"")
            .expect("dim: invalid type: string \"two\", expected 1 or 2"),
        case("bare-word-for-integer", BAR)
            .edit("dim = 2", "dim = @@two")
            .expect("dim: invalid boolean, expected `true`"),
        case("string-for-number", BAR)
            .edit("young = 100.0", "young = @@\"stiff\"")
            .expect("material.young: invalid type: string \"stiff\", expected a number"),
        case("integer-for-string", BAR)
            .edit("name = \"bar\"", "name = @@3")
            .expect("name: invalid type: integer `3`, expected a string"),
        case("string-for-boolean", BAR)
            .edit(
                "diagnostics_every = 5",
                "diagnostics_every = 5\ncondition = @@\"yes\"",
            )
            .expect("output.condition: invalid type: string \"yes\", expected a boolean"),
        case("string-for-list", BAR)
            .edit(
                "fix = [\"x\", \"y\"]\n\n[[boundary]]\ntag = \"right\"",
                "fix = @@\"x\"\n\n[[boundary]]\ntag = \"right\"",
            )
            .expect("boundary[0].fix: invalid type: string \"x\", expected a sequence"),
        case("negative-count", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, @@-2]")
            .expect("body[0].per_block: invalid value: integer `-2`, expected a whole number in 1..=1000 along each axis"),
        case("float-for-block-count", BAR)
            .edit("[mesh]", "@@[mesh]")
            .edit("blocks = [4, 1]", "blocks = [4.5, 1]")
            .at(13, 11).expect("mesh.blocks: invalid type: floating point `4.5`, expected a whole number in 1..=4096 along each axis"),
        // The float also written in a key above (`y = [0.0, 1.5]`): the key that
        // takes whole numbers is named (a user was pointed at `mesh.y`).
        case("float-for-block-count-written-above", BAR)
            .edit("y = [0.0, 1.0]", "y = [0.0, 1.5]")
            .edit("blocks = [4, 1]", "blocks = [@@1.5, 1]")
            .expect("mesh.blocks: invalid type: floating point `1.5`, expected a whole number in 1..=4096 along each axis"),
        // An integer's range is the field's, not its type's: no block count of 0.
        case("negative-block-count", BAR)
            .edit("blocks = [4, 1]", "blocks = [4, @@-1]")
            .expect("mesh.blocks: invalid value: integer `-1`, expected a whole number in 1..=4096 along each axis"),
        case("negative-resolution-block-count", BAR)
            .edit("blocks = [8, 1]", "blocks = [@@-8, 1]")
            .expect("resolution[0].blocks: invalid value: integer `-8`, expected a whole number, 1 or more, along each axis (as `mesh.blocks`)"),
        case("negative-element-count", BAR_1D)
            .edit("elements = 4", "elements = @@-4")
            .expect("mesh.elements: invalid value: integer `-4`, expected a whole number in 1..=1000000"),
        case("negative-count-of-a-body", SQUARE)
            .edit("count = [16, 16]", "count = [16, @@-16]")
            .expect("body[0].count: invalid value: integer `-16`, expected a whole number in 1..=100000 along each axis"),
        case("three-block-counts", BAR)
            .edit("blocks = [4, 1]", "@@blocks = [4, 1, 1]")
            .expect("mesh.blocks: invalid length 3, expected 2 elements in sequence"),
        // Inside an array of tagged tables the parser reports a value error at
        // the first table's header: the message names the element and its field,
        // at the value.
        case("string-in-the-second-effect", COLUMN)
            .edit("alpha = 0.1", "alpha = @@\"0.1\"")
            .expect("effect[1].alpha: invalid type: string \"0.1\", expected a number"),
        case("string-in-an-effect-array", COLUMN)
            .edit("g = [0.0, -9.81]", "g = [0.0, @@\"-9.81\"]")
            .expect("effect[0].g: invalid type: string \"-9.81\", expected a number"),
        case("string-in-the-third-effect", COLUMN)
            .edit("traction = [0.0, -1.0]", "traction = [0.0, @@\"down\"]")
            .expect("effect[2].traction: invalid type: string \"down\", expected a number"),
        // A number where a vector was expected, after a vector that holds the same
        // number (a user's 1D traction after `max = [2.0]`): at its own key.
        case("number-for-a-vector-after-the-same-number", COLUMN)
            .edit("traction = [0.0, -1.0]", "traction = @@4.0")
            .expect("effect[2].traction: invalid type: floating point `4.0`, expected a sequence: write it as a list of its x and y entries, e.g. `[0.0, 4.0]`"),
        // A student's 2D gravity as one number: the list it wants has two entries.
        case("number-for-gravity-in-2d", COLUMN)
            .edit("g = [0.0, -9.81]", "g = @@-9.81")
            .expect("effect[0].g: invalid type: floating point `-9.81`, expected a sequence: write it as a list of its x and y entries, e.g. `[0.0, -9.81]`"),
        case("array-of-arrays-for-a-vector", COLUMN)
            .edit("traction = [0.0, -1.0]", "traction = @@[[0.0, -1.0]]")
            .expect("effect[2].traction: invalid type: sequence, expected a number"),
        case("huge-integer", BAR)
            .edit("blocks = [4, 1]", "blocks = [@@99999999999999999999, 1]")
            .expect("mesh.blocks: the integer `99999999999999999999` is out of range (integers in a scene file are 64-bit)"),
    ]
}

/// A table written as an array of tables, or the reverse (by header or inline):
/// the field, at its (first) header or its value, and how it is written.
fn table_form_cases() -> Vec<Case> {
    let bar_material =
        "[material]\nmodel = \"linear-elastic\"\nyoung = 100.0\npoisson = 0.25\ndensity = 1.0\n\n";
    let bar_body = "[[body]]\nmin = [0.0, 0.0]\nmax = [4.0, 1.0]\nper_block = [4, 4]\n\n";
    vec![
        case("array-of-tables-for-material", BAR)
            .edit("[material]", "@@[[material]]")
            .expect("material: a table, written `[material]`, not an array of tables `[[material]]`"),
        // Two entries: the first header is pointed at.
        case("two-materials", BAR)
            .edit("[material]", "@@[[material]]")
            .edit("[[body]]", "[[material]]\nyoung = 1.0\ndensity = 1.0\n\n[[body]]")
            .expect("material: a table, written `[material]`, not an array of tables `[[material]]`"),
        case("table-for-array-of-tables", BAR)
            .edit("[[body]]", "@@[body]")
            .expect("body: an array of tables, written `[[body]]` for each body, not `[body]`"),
        case("array-of-tables-for-mesh", BAR)
            .edit("[mesh]", "@@[[mesh]]")
            .expect("mesh: a table, written `[mesh]`, not an array of tables `[[mesh]]`"),
        case("array-of-tables-for-initial-velocity", BAR)
            .edit("[initial_velocity]", "@@[[initial_velocity]]")
            .expect("initial_velocity: a table, written `[initial_velocity]`, not an array of tables `[[initial_velocity]]`"),
        case("array-of-tables-for-time", BAR)
            .edit("[time]", "@@[[time]]")
            .expect("time: a table, written `[time]`, not an array of tables `[[time]]`"),
        case("array-of-tables-for-reference", BAR)
            .edit("[reference]", "@@[[reference]]")
            .expect("reference: a table, written `[reference]`, not an array of tables `[[reference]]`"),
        case("array-of-tables-for-output", BAR)
            .edit("[output]", "@@[[output]]")
            .expect("output: a table, written `[output]`, not an array of tables `[[output]]`"),
        case("array-of-tables-for-study", BAR)
            .edit("[study]", "@@[[study]]")
            .expect("study: a table, written `[study]`, not an array of tables `[[study]]`"),
        case("table-for-boundaries", BAR_1D)
            .edit("[[boundary]]", "@@[boundary]")
            .expect("boundary: an array of tables, written `[[boundary]]` for each boundary, not `[boundary]`"),
        case("table-for-effects", SQUARE)
            .edit("[[effect]]", "@@[effect]")
            .expect("effect: an array of tables, written `[[effect]]` for each effect, not `[effect]`"),
        case("table-for-resolutions", BAR)
            .edit("[[resolution]]", "@@[resolution]")
            .expect("resolution: an array of tables, written `[[resolution]]` for each resolution, not `[resolution]`"),
        case("table-for-mesh-holes", SQUARE)
            .edit("edge_length = 0.25", "edge_length = 0.25\n\n@@[mesh.holes]\noutline = [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6]]\ntag = \"hole\"")
            .expect("mesh.holes: an array of tables, written `[[mesh.holes]]` for each hole, not `[mesh.holes]`"),
        case("array-of-tables-for-a-body-material", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\n\n@@[[body.material]]\nyoung = 100.0\ndensity = 1.0")
            .expect("body[0].material: a table, written `[body.material]`, not an array of tables `[[body.material]]`"),
        case("array-of-tables-for-a-second-body-initial-velocity", BAR)
            .edit("[initial_velocity]", "[[body]]\nmin = [1.0, 0.0]\nmax = [2.0, 1.0]\ncount = [2, 2]\n\n@@[[body.initial_velocity]]\nkind = \"rest\"\n\n[initial_velocity]")
            .expect("body[1].initial_velocity: a table, written `[body.initial_velocity]`, not an array of tables `[[body.initial_velocity]]`"),
        // Inline forms: at the value.
        case("inline-array-for-material", BAR)
            .edit(bar_material, "")
            .edit("mass = \"consistent\"", "mass = \"consistent\"\nmaterial = @@[{ young = 100.0, density = 1.0 }]")
            .expect("material: a table, written `[material]` or `material = { … }`, not an array `material = [{ … }]`"),
        case("inline-table-for-body", BAR)
            .edit(bar_body, "")
            .edit("mass = \"consistent\"", "mass = \"consistent\"\nbody = @@{ min = [0.0, 0.0], max = [4.0, 1.0], per_block = [4, 4] }")
            .expect("body: an array of tables, written `body = [{ … }]` or `[[body]]` for each body, not one table `body = { … }`"),
        case("inline-array-for-a-body-material", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\nmaterial = @@[{ young = 100.0, density = 1.0 }]")
            .expect("body[0].material: a table, written `[body.material]` or `material = { … }`, not an array `material = [{ … }]`"),
    ]
}

fn unknown_name_cases() -> Vec<Case> {
    vec![
        case("unknown-basis", BAR)
            .edit("basis = \"ps\"", "basis = @@\"cubic\"")
            .expect("basis: unknown basis `cubic` (known: ps, pl, bspline, pl1d)"),
        case("unknown-mass-strategy", BAR)
            .edit("mass = \"consistent\"", "mass = @@\"heavy\"")
            .expect("mass: unknown mass strategy `heavy` (known: default, consistent, lumped, partial, partial:TAU, partial-coverage:C, deactivate, deactivate:THRESHOLD, extended, extended:C, extended-hybrid, extended-hybrid:C1:C2[:W], extended-hybrid-apic[:C1:C2], extended-hybrid-rpic[:C1:C2], extended-hybrid-plain[:C1:C2], fmpm:K)"),
        case("negative-partial-threshold", BAR)
            .edit("mass = \"consistent\"", "mass = @@\"partial:-1\"")
            .expect("mass: `partial:-1`: the threshold must be a positive number, got `-1`"),
        case("unknown-split-point", BAR)
            .edit("split = \"incentre\"", "split = @@\"orthocentre\"")
            .expect("split: unknown split point `orthocentre` (known: incentre, centroid)"),
        case("unknown-mirror-line", BAR)
            .edit("split = \"incentre\"", "split = \"incentre\"\nmirror_line = @@\"oblique\"")
            .expect("mirror_line: unknown mirror line `oblique` (known: vertical, horizontal, diagonal, anti-diagonal)"),
        case("unknown-resolution-basis", BAR)
            .edit("basis = \"pl\"", "basis = @@\"quadratic\"")
            .expect("resolution[0].basis: unknown basis `quadratic` (known: ps, pl, bspline, pl1d)"),
        case("unknown-mesh-kind", BAR)
            .edit("kind = \"blocks\"", "kind = @@\"grid\"")
            .expect("mesh.kind: unknown variant `grid`, expected one of `blocks`, `polygon`, `gmsh`, `interval`"),
        case("unknown-effect-kind", COLUMN)
            .edit("kind = \"damping\"", "kind = @@\"magnetism\"")
            .expect("effect[1].kind: unknown variant `magnetism`, expected one of `gravity`, `damping`, `traction`, `body-force`, `manufactured-body-force`, `contact-wall`, `body-contact`, `geostatic-stress`"),
        case("body-contact-with-one-body", COLUMN)
            .edit("kind = \"damping\"\nalpha = 0.1", "kind = @@\"body-contact\"")
            .expect("effect[1].kind: contact between bodies needs two or more `[[body]]` tables, this scene has 1: add the other body, or remove this effect"),
        case("unknown-reference-kind", BAR)
            .edit("kind = \"vibrating-bar\"", "kind = @@\"pendulum\"")
            .expect("reference.kind: unknown variant `pendulum`, expected one of `vibrating-bar`, `column-self-weight`, `axis-aligned`, `column-equilibrium`"),
        // In a body's own table, the body is named with its index (the second's).
        case("unknown-velocity-kind-of-the-second-body", BAR)
            .edit("[initial_velocity]", "[[body]]\nmin = [1.0, 0.0]\nmax = [2.0, 1.0]\ncount = [2, 2]\n\n[body.initial_velocity]\nkind = @@\"spin\"\n\n[initial_velocity]")
            .expect("body[1].initial_velocity.kind: unknown variant `spin`, expected one of `rest`, `uniform`, `sine-mode`, `exact`, `rigid-rotation`, `linear`"),
        case("string-omega-of-the-second-body", BAR)
            .edit("[initial_velocity]", "[[body]]\nmin = [1.0, 0.0]\nmax = [2.0, 1.0]\ncount = [2, 2]\n\n[body.initial_velocity]\nkind = \"rigid-rotation\"\nomega = @@\"fast\"\ncentre = [1.5, 0.5]\n\n[initial_velocity]")
            .expect("body[1].initial_velocity.omega: invalid type: string \"fast\", expected a number"),
        case("unknown-initial-velocity-kind", BAR)
            .edit("kind = \"exact\"", "kind = @@\"spinning\"")
            .expect("initial_velocity.kind: unknown variant `spinning`, expected one of `rest`, `uniform`, `sine-mode`, `exact`, `rigid-rotation`, `linear`"),
        case("unknown-material-model", BAR)
            .edit("model = \"linear-elastic\"", "model = @@\"plastic\"")
            .expect("material.model: unknown variant `plastic`, expected one of `linear-elastic`, `paper-linear`, `corotated`, `corotational`, `neo-hookean`"),
        case("unknown-block-layout", BAR)
            .edit("[mesh]", "@@[mesh]")
            .edit("layout = \"four-triangles\"", "layout = \"hexagons\"")
            .at(14, 11).expect("mesh.layout: unknown variant `hexagons`, expected `four-triangles` or `delaunay`"),
        case("unknown-component", BAR)
            .edit("fix = [\"x\", \"y\"]\n\n[[boundary]]\ntag = \"right\"", "fix = [@@\"z\"]\n\n[[boundary]]\ntag = \"right\"")
            .expect("boundary[0].fix: unknown variant `z`, expected one of `x`, `y`, `normal`"),
    ]
}

fn range_cases() -> Vec<Case> {
    vec![
        case("empty-name", BAR)
            .edit("name = \"bar\"", "name = @@\" \"")
            .expect("name: is empty: the scene's name is printed and names its output files"),
        case("long-name", BAR)
            .edit("name = \"bar\"", &format!("name = @@\"{}\"", "n".repeat(201)))
            .expect("name: is 201 characters long, above the limit of 200"),
        case("long-description", BAR)
            .edit("description = \"a bar fixed at both ends\"", &format!("description = @@\"{}\"", "d".repeat(2001)))
            .expect("description: is 2001 characters long, above the limit of 2000"),
        case("tiny-t-end-in-short-form", COLUMN)
            .edit("t_end = 0.01", "t_end = @@1e-300")
            .expect("time.t_end: is shorter than one time step (t_end = 1e-300, courant = 0.5 gives dt = 1.137e-3): give `t_end` of at least 0.00114, or a fixed `dt` below it (the critical step grows as h √(ρ / E): E = 50000 here)"),
        // Each tracked point is recorded every step: their count is bounded, and so
        // is points × steps (10 000 points over 100 steps took 357 MB).
        case("too-many-tracked-points", BAR)
            .edit("tracked = [[2.0, 0.5]]", &format!("tracked = @@[{}]", vec!["[2.0, 0.5]"; 1001].join(", ")))
            .expect("output.tracked: lists 1001 points, above the limit of 1000: each is recorded every step; track fewer points, or write the particle frames (`run --out DIR`, every particle at every `--out-every` steps)"),
        case("tracked-history-too-long", BAR)
            .edit("t_end = 0.01", "t_end = 10.001")
            .edit("tracked = [[2.0, 0.5]]", &format!("tracked = @@[{}]", vec!["[2.0, 0.5]"; 1000].join(", ")))
            .expect("output.tracked: 1000 tracked points over 10001 steps (t_end / dt) record 10001000 samples, above the limit of 10000000 (points × steps, each kept in memory for tracked.csv): track fewer points, or take fewer steps (a shorter `t_end` or a longer step)"),
        // With `courant` the steps are known at the start of the run, which checks them.
        case("tracked-history-too-long-with-courant", COLUMN)
            .edit("t_end = 0.01", "t_end = 100.0")
            .map(|t| format!("{t}\n[output]\ntracked = @@[{}]\n", vec!["[0.5, 2.0]"; 1000].join(", ")))
            .expect("output.tracked: 1000 tracked points over 87915 steps (t_end / (courant × the critical step)) record 87915000 samples, above the limit of 10000000 (points × steps, each kept in memory for tracked.csv): track fewer points, or take fewer steps (a shorter `t_end` or a longer step)"),
        case("dim-3", BAR)
            .edit("dim = 2", "dim = @@3")
            .expect("dim: must be 1 or 2, got 3"),
        case("negative-young", BAR)
            .edit("young = 100.0", "young = @@-100.0")
            .expect("material.young: young = -100 is out of range: E > 0"),
        case("poisson-one-half", BAR)
            .edit("poisson = 0.25", "poisson = @@0.5")
            .expect("material.poisson: poisson = 0.5 is out of range: −1 < ν < 0.5"),
        case("poisson-minus-one", BAR)
            .edit("poisson = 0.25", "poisson = @@-1.0")
            .expect("material.poisson: poisson = -1 is out of range: −1 < ν < 0.5"),
        case("zero-density", BAR)
            .edit("density = 1.0", "density = @@0.0")
            .expect("material.density: density = 0 is out of range: ρ > 0"),
        // Subnormal constants are named, not blamed on the time step they break.
        case("subnormal-density", COLUMN)
            .edit("density = 1.0", "density = @@1e-320")
            .expect("material.density: density = 1e-320 is out of range: ρ ≥ 2.2e-308 (subnormal numbers are refused)"),
        case("subnormal-young", COLUMN)
            .edit("young = 5e4", "young = @@1e-310")
            .expect("material.young: young = 1e-310 is out of range: E ≥ 2.2e-308 (subnormal numbers are refused)"),
        case("subnormal-poisson", BAR)
            .edit("poisson = 0.25", "poisson = @@-1e-315")
            .expect("material.poisson: poisson = -1e-315 is out of range: ν = 0 or |ν| ≥ 2.2e-308 (subnormal numbers are refused)"),
        case("infinite-wave-speed", COLUMN)
            .edit("young = 5e4", "young = @@1e300")
            .edit("density = 1.0", "density = 1e-300")
            .expect("material.young: young = 1e300, poisson = 0 and density = 1e-300 give a P-wave speed √((λ + 2μ) / ρ) of inf, which sets no time step: `material.young`, `material.poisson` and `material.density` must give a speed between 1e-300 and 1e300 or so"),
        case("courant-step-overflows", BAR_1D)
            .edit("x = [0.0, 4.0]", "x = [0.0, 4e200]")
            .edit("max = [4.0]", "max = [4e200]")
            .edit("young = 100.0", "young = 1e-290")
            .edit("density = 1.0", "density = 1e10")
            .edit("dt = 1e-3", "courant = @@0.5")
            .expect("time.courant: the time step C h / c = inf from courant = 0.5, element size h = 1e200 and P-wave speed c = 1e-150 (of the materials' young, poisson and density) is not a finite positive number: the element size and the materials' constants are too far apart"),
        case("body-material-zero-wave-speed", BAR_1D)
            .edit("per_block = [2]\n", "per_block = [2]\n\n[body.material]\nyoung = @@1e-300\ndensity = 1e300\n")
            .expect("body[0].material.young: young = 1e-300, poisson = 0 and density = 1e300 give a P-wave speed √((λ + 2μ) / ρ) of 0, which sets no time step: `body[0].material.young`, `body[0].material.poisson` and `body[0].material.density` must give a speed between 1e-300 and 1e300 or so"),
        case("zero-dt", BAR)
            .edit("dt = 1e-3", "dt = @@0.0")
            .expect("time.dt: must be positive and finite, got 0"),
        case("negative-dt", BAR)
            .edit("dt = 1e-3", "dt = @@-1e-3")
            .expect("time.dt: must be positive and finite, got -0.001"),
        case("nan-dt", BAR)
            .edit("dt = 1e-3", "dt = @@nan")
            .expect("time.dt: must be positive and finite, got NaN"),
        case("jitter-one-half", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\njitter = @@0.5")
            .expect(
                "body[0].jitter: must be in [0, 0.5) (a fraction of the lattice cell), got 0.5",
            ),
        case("negative-jitter", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\njitter = @@-0.1")
            .expect(
                "body[0].jitter: must be in [0, 0.5) (a fraction of the lattice cell), got -0.1",
            ),
        case("negative-courant", COLUMN)
            .edit("courant = 0.5", "courant = @@-0.5")
            .expect("time.courant: must be positive and finite, got -0.5"),
        case("dt-and-courant", COLUMN)
            .edit("courant = 0.5", "courant = 0.5\ndt = @@1e-3")
            .expect("time.dt: give exactly one of `dt` and `courant`"),
        case("neither-dt-nor-courant", BAR)
            .edit("[time]\ndt = 1e-3\n", "@@[time]\n")
            .expect("time.dt: give exactly one of `dt` and `courant`"),
        case("zero-t-end", BAR)
            .edit("t_end = 0.01", "t_end = @@0.0")
            .expect("time.t_end: must be positive and finite, got 0"),
        case("negative-t-end", BAR)
            .edit("t_end = 0.01", "t_end = @@-1.0")
            .expect("time.t_end: must be positive and finite, got -1"),
        case("t-end-below-one-step", BAR)
            .edit("dt = 1e-3", "dt = @@1e-3")
            .edit("t_end = 0.01", "t_end = 1e-5")
            .expect("time.dt: 0.001 exceeds t_end = 1e-5: the run takes t_end / dt steps, rounded, and that is none; give a `dt` of at most t_end, or a longer `t_end`"),
        // A user's `dt = 10` named only `t_end`: the step is named, at its line, with
        // both values.
        case("dt-above-t-end", BAR)
            .edit("dt = 1e-3", "dt = @@10.0")
            .edit("t_end = 0.01", "t_end = 1.0")
            .expect("time.dt: 10 exceeds t_end = 1: the run takes t_end / dt steps, rounded, and that is none; give a `dt` of at most t_end, or a longer `t_end`"),
        case("zero-blocks", BAR)
            .edit("blocks = [4, 1]", "blocks = @@[4, 0]")
            .expect("mesh.blocks: each count must be in 1..=4096, got [4, 0]"),
        case("too-many-blocks", BAR)
            .edit("blocks = [4, 1]", "blocks = @@[5000, 1]")
            .expect("mesh.blocks: each count must be in 1..=4096, got [5000, 1]"),
        case("zero-per-block", BAR)
            .edit("per_block = [4, 4]", "per_block = @@[0, 4]")
            .expect("body[0].per_block: needs 2 counts in 1..=1000, got [0, 4]"),
        case("too-many-per-block", BAR)
            .edit("per_block = [4, 4]", "per_block = @@[4, 1001]")
            .expect("body[0].per_block: needs 2 counts in 1..=1000, got [4, 1001]"),
        case("zero-count", SQUARE)
            .edit("count = [16, 16]", "count = @@[0, 8]")
            .expect("body[0].count: needs 2 counts in 1..=100000, got [0, 8]"),
        case("damping-alpha-1.5", COLUMN)
            .edit("alpha = 0.1", "alpha = @@1.5")
            .expect("effect[1].alpha: must be in [0, 1), got 1.5"),
        case("negative-damping-alpha", COLUMN)
            .edit("alpha = 0.1", "alpha = @@-0.1")
            .expect("effect[1].alpha: must be in [0, 1), got -0.1"),
        case("negative-traction-ramp", COLUMN)
            .edit("ramp = 0.1", "ramp = @@-1.0")
            .expect("effect[2].ramp: must be ≥ 0, got -1"),
        case("zero-traction-length", COLUMN)
            .edit("length = 1.0", "length = @@0.0")
            .expect("effect[2].length: must be positive and finite, got 0"),
        case("nan-gravity", COLUMN)
            .edit("g = [0.0, -9.81]", "g = @@[0.0, nan]")
            .expect("effect[0].g: must be finite, got NaN"),
        case("reversed-mesh-x", BAR)
            .edit("x = [0.0, 4.0]", "x = @@[4.0, 0.0]")
            .expect("mesh.x: needs min < max, got [4, 0]"),
        case("infinite-mesh-y", BAR)
            .edit("y = [0.0, 1.0]", "y = @@[0.0, inf]")
            .expect("mesh.y: must be finite, got inf"),
        case("zero-elements", BAR_1D)
            .edit("elements = 4", "elements = @@0")
            .expect("mesh.elements: must be in 1..=1000000, got 0"),
        case("zero-edge-length", SQUARE)
            .edit("edge_length = 0.25", "edge_length = @@0.0")
            .expect("mesh.edge_length: must be positive and finite, got 0"),
        case("mesh-hole-as-a-list-of-corners", SQUARE)
            .edit("edge_length = 0.25", "edge_length = 0.25\n@@holes = [[[0.4, 0.4], [0.6, 0.4], [0.6, 0.6]]]")
            .expect("mesh.holes: each hole of a mesh is a table with `outline` (its corners) and `tag` (its boundary's tag), written `[[mesh.holes]]`, not a list of corners as a body's `holes`"),
        case("infinite-reference-v0", BAR)
            .edit("v0 = 0.1", "v0 = @@inf")
            .expect("reference.v0: must be finite, got inf"),
        case("nan-reference-u0", SQUARE)
            .edit("u0 = 0.05", "u0 = @@nan")
            .expect("reference.u0: must be finite, got NaN"),
    ]
}

fn inconsistent_cases() -> Vec<Case> {
    vec![
        case("1d-basis-in-2d", BAR)
            .edit("basis = \"ps\"", "basis = @@\"bspline\"")
            .expect("basis: `bspline` is a 1D basis but the scene is 2D (2D: ps, pl; 1D: bspline, pl1d)"),
        case("2d-basis-in-1d", BAR_1D)
            .edit("basis = \"bspline\"", "basis = @@\"ps\"")
            .expect("basis: `ps` is a 2D basis but the scene is 1D (2D: ps, pl; 1D: bspline, pl1d)"),
        case("blocks-mesh-in-1d", BAR)
            .edit("dim = 2", "dim = 1")
            .edit("basis = \"ps\"", "basis = \"bspline\"")
            .edit("kind = \"blocks\"", "kind = @@\"blocks\"")
            .expect("mesh.kind: `blocks` is a 2D mesh; use `interval` in 1D"),
        case("interval-mesh-in-2d", BAR_1D)
            .edit("dim = 1", "dim = 2")
            .edit("basis = \"bspline\"", "basis = \"pl\"")
            .edit("kind = \"interval\"", "kind = @@\"interval\"")
            .expect("mesh.kind: `interval` is a 1D mesh; use `blocks` in 2D"),
        case("gmsh-mesh-in-1d", GMSH)
            .edit("dim = 2", "dim = 1")
            .edit("basis = \"pl\"", "basis = \"pl1d\"")
            .edit("kind = \"gmsh\"", "kind = @@\"gmsh\"")
            .expect("mesh.kind: `gmsh` meshes are 2D"),
        case("body-with-one-coordinate", BAR)
            .edit("min = [0.0, 0.0]", "min = @@[0.0]")
            .expect("body[0].min: needs 2 entries, got 1"),
        case("body-with-three-coordinates", BAR)
            .edit("max = [4.0, 1.0]", "max = @@[4.0, 1.0, 1.0]")
            .expect("body[0].max: needs 2 entries, got 3"),
        // A point of the plane read as `[x, y]` took the first two of three.
        case("disk-centre-with-three-coordinates", BAR)
            .edit("min = [0.0, 0.0]", "centre = @@[2.0, 0.5, 0.0]\nmin = [0.0, 0.0]")
            .expect("body[0].centre: a point has 2 entries, x and y, got 3"),
        // In 1D the count is one: "needs 1 entry", not "needs 1 entries".
        case("1d-body-with-two-coordinates", BAR_1D)
            .edit("max = [4.0]", "max = @@[4.0, 1.0]")
            .expect("body[0].max: needs 1 entry, got 2"),
        case("1d-gravity-with-two-components", BAR_1D)
            .edit("[time]", "[[effect]]\nkind = \"gravity\"\ng = @@[0.0, -9.81]\n\n[time]")
            .expect("effect[0].g: needs 1 entry, got 2"),
        case("1d-spacing-with-two-lengths", BAR_1D)
            .edit("per_block = [2]", "spacing = @@[0.5, 0.5]")
            .expect("body[0].spacing: needs 1 positive finite length, got [0.5, 0.5]"),
        case("linear-velocity-gradient-with-one-row", BAR)
            .edit("kind = \"exact\"", "kind = \"linear\"\nvalue = [0.0, 0.0]\norigin = [0.0, 0.0]\ngradient = @@[[0.0, 1.0]]")
            .expect("initial_velocity.gradient: needs 2 rows of 2 entries, got 1 row"),
        case("body-min-not-below-max", BAR)
            .edit("max = [4.0, 1.0]", "max = @@[4.0, 0.0]")
            .expect("body[0].max: needs min < max on every axis, got min = [0.0, 0.0], max = [4.0, 0.0]"),
        case("second-body-min-not-below-max", BAR)
            .edit("[initial_velocity]", "[[body]]\nmin = [1.0, 1.0]\nmax = @@[2.0, 1.0]\ncount = [2, 2]\n\n[initial_velocity]")
            .expect("body[1].max: needs min < max on every axis, got min = [1.0, 1.0], max = [2.0, 1.0]"),
        // Two lattice fields: the message names those given, at the later one.
        case("per-block-and-count", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\ncount = @@[8, 2]")
            .expect("body[0].count: `per_block` and `count` are given together, but each sets the particle lattice alone: give one of them"),
        case("count-and-spacing", BAR)
            .edit("per_block = [4, 4]", "count = [16, 4]\nspacing = @@[0.25, 0.25]")
            .expect("body[0].spacing: `count` and `spacing` are given together, but each sets the particle lattice alone: give one of them"),
        case("per-block-count-and-spacing", BAR)
            .edit("per_block = [4, 4]", "per_block = [4, 4]\ncount = [16, 4]\nspacing = @@[0.25, 0.25]")
            .expect("body[0].spacing: `per_block`, `count` and `spacing` are given together, but each sets the particle lattice alone: give one of them"),
        case("neither-per-block-nor-count", BAR)
            .edit("[[body]]", "@@[[body]]")
            .edit("per_block = [4, 4]\n", "")
            .expect("body[0]: a `box` body needs a particle lattice and gives none: give one of `per_block` (particles per mesh block along each axis), `count` (particles along each axis of the body) and `spacing` (the lattice spacing along each axis)"),
        case("per-block-on-a-polygon-mesh", SQUARE)
            .edit("count = [16, 16]", "per_block = @@[2, 2]")
            .expect("body[0].per_block: needs a `blocks` or `interval` mesh; use `count` or `spacing` on other meshes"),
        case("component-y-in-1d", BAR_1D)
            .edit("fix = [\"x\"]", "fix = @@[\"y\"]")
            .expect("boundary[0].fix: component `y` does not exist in 1D: a 1D bar moves along x only; hold its end with `fix = [\"x\"]` (or `[\"normal\"]`, the same in 1D)"),
        case("no-component", BAR)
            .edit("fix = [\"x\", \"y\"]\n\n[[boundary]]\ntag = \"right\"", "fix = @@[]\n\n[[boundary]]\ntag = \"right\"")
            .expect("boundary[0].fix: lists no component"),
        case("normal-with-another-component", BAR)
            .edit("fix = [\"x\", \"y\"]\n\n[time]", "fix = @@[\"normal\", \"x\"]\n\n[time]")
            .expect("boundary[1].fix: `normal` fixes the normal component alone; list it on its own"),
        case("column-reference-without-gravity", COLUMN)
            .edit("[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n\n", "")
            .edit("kind = \"column-self-weight\"", "kind = @@\"column-self-weight\"")
            .expect("reference.kind: a column reference needs a gravity effect"),
        // The physics would sum them, but the references and the geostatic stress
        // take the first gravity, and two dampings may add up to α ≥ 1.
        case("two-gravity-effects", COLUMN)
            .edit("[[effect]]\nkind = \"traction\"", "[[effect]]\nkind = @@\"gravity\"\ng = [0.0, -1.0]\n\n[[effect]]\nkind = \"traction\"")
            .expect("effect[2].kind: `gravity` is already declared by effect[0]; give one `gravity` effect with the sum of their `g` (the references and the geostatic stress use the first gravity alone)"),
        case("two-damping-effects", COLUMN)
            .edit("[[effect]]\nkind = \"traction\"", "[[effect]]\nkind = @@\"damping\"\nalpha = 0.6\n\n[[effect]]\nkind = \"traction\"")
            .expect("effect[2].kind: `damping` is already declared by effect[1]; give one `damping` effect with the sum of their `alpha`, below 1 (the damping of two is that of their sum, and from 1 on it pushes along the velocity)"),
        case("column-self-weight-from-a-geostatic-state", COLUMN)
            .edit("[[effect]]\nkind = \"traction\"", "[[effect]]\nkind = \"geostatic-stress\"\nsurface = 4.0\n\n[[effect]]\nkind = \"traction\"")
            .edit("kind = \"column-self-weight\"", "kind = @@\"column-self-weight\"")
            .expect("reference.kind: `column-self-weight` is the column settling from a stress-free start, but effect[2] gives it a geostatic initial stress, which holds it at rest: use `column-equilibrium` (whose error is then measured against the geostatic profile), or leave out the geostatic stress"),
        case("geostatic-stress-without-gravity", BAR)
            .edit("[time]", "[[effect]]\nkind = @@\"geostatic-stress\"\nsurface = 1.0\n\n[time]")
            .expect("effect[0].kind: geostatic stress needs a gravity effect"),
        case("initial-speed-beyond-continuum-mechanics", BAR)
            .edit("[initial_velocity]\nkind = \"exact\"", "[initial_velocity]\nkind = \"uniform\"\nvalue = @@[1e200, 0.0]")
            .expect("initial_velocity.value: a speed of 1e200 m/s is beyond continuum mechanics (the limit is 1e8, a third of the speed of light): give it in m/s"),
        case("geostatic-surface-below-the-body", BAR)
            .edit("[time]", "[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n\n[[effect]]\nkind = \"geostatic-stress\"\nsurface = @@0.5\n\n[time]")
            .expect("effect[1].surface: the free surface y = 0.5 lies below the highest particle (y = 0.875): the particles above it would start without stress; give the top of the bodies, or a height above it for a load on them"),
        case("geostatic-surface-far-above-the-body", BAR)
            .edit("[time]", "[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n\n[[effect]]\nkind = \"geostatic-stress\"\nsurface = @@1e300\n\n[time]")
            .expect("effect[1].surface: the geostatic stress at the lowest particle (y = 0.125), ρ g (surface − y) = 9.8e300, exceeds the Young's modulus 100 of body[0]: it would be crushed at once; is `surface` 1e300 in the scene's units, and near the highest particle (y = 0.875)?"),
        case("manufactured-force-without-axis-aligned", BAR)
            .edit("[time]", "[[effect]]\nkind = @@\"manufactured-body-force\"\n\n[time]")
            .expect("effect[0].kind: `manufactured-body-force` needs reference kind `axis-aligned`"),
        case("axis-aligned-with-linear-elasticity", SQUARE)
            .edit("model = \"neo-hookean\"", "model = \"linear-elastic\"")
            .edit("kind = \"axis-aligned\"", "kind = @@\"axis-aligned\"")
            .expect("reference.kind: `axis-aligned` is a 2D neo-Hookean solution"),
        case("vibrating-bar-reference-against-another-sine-mode", BAR)
            .edit("kind = \"exact\"", "kind = \"sine-mode\"\nv0 = 0.2")
            .edit("kind = \"vibrating-bar\"\nv0 = 0.1", "kind = \"vibrating-bar\"\nv0 = @@0.1")
            .expect("reference.v0: is 0.1, but the bar starts in the sine mode with v0 = 0.2 ([initial_velocity]): the reference would be another motion; give both the same v0, or `kind = \"exact\"` in [initial_velocity] to start from the reference"),
        case("vibrating-bar-reference-from-rest", BAR)
            .edit("[initial_velocity]\nkind = \"exact\"\n", "")
            .edit("kind = \"vibrating-bar\"", "kind = @@\"vibrating-bar\"")
            .expect("reference.kind: `vibrating-bar` is the first mode of a bar started with v_x = v0 sin(π x / L), but the bar starts otherwise: give [initial_velocity] `kind = \"exact\"` (or `kind = \"sine-mode\"` with the reference's v0)"),
        case("vibrating-bar-reference-on-a-shorter-body", BAR)
            .edit("max = [4.0, 1.0]", "max = @@[3.0, 1.0]")
            .expect("body[0].max: the `vibrating-bar` reference is a bar fixed at both ends, but body[0] spans [0, 3] along x and the mesh, whose ends carry the walls, [0, 4]: make the body span the mesh, or leave out [reference]"),
        case("exact-velocity-without-reference", BAR)
            .edit("[reference]\nkind = \"vibrating-bar\"\nv0 = 0.1\n", "")
            .edit("kind = \"exact\"", "kind = @@\"exact\"")
            .expect("initial_velocity.kind: `exact` needs a [reference] solution"),
        // A body's own initial velocity is named with the body's index.
        case("body-velocity-with-one-entry", BAR)
            .edit("per_block = [4, 4]\n", "per_block = [4, 4]\n\n[body.initial_velocity]\nkind = \"uniform\"\nvalue = @@[1.0]\n")
            .expect("body[0].initial_velocity.value: needs 2 entries, got 1"),
        case("uniform-velocity-with-one-entry", BAR)
            .edit("kind = \"exact\"", "kind = \"uniform\"\nvalue = @@[1.0]")
            .expect("initial_velocity.value: needs 2 entries, got 1"),
        case("polygon-with-two-corners", SQUARE)
            .edit("outline = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]", "outline = @@[[0.0, 0.0], [1.0, 0.0]]")
            .edit("tags = [\"bottom\", \"right\", \"top\", \"left\"]\n", "")
            .expect("mesh.outline: needs at least 3 corners"),
        case("polygon-with-two-tags", SQUARE)
            .edit("tags = [\"bottom\", \"right\", \"top\", \"left\"]", "tags = @@[\"bottom\", \"right\"]")
            .expect("mesh.tags: needs one tag per outline segment (4), got 2"),
        // A polygon mesh's faults name the part at fault, at its line.
        case("hole-crossing-the-outline", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n[[mesh.holes]]\noutline = @@[[0.8, 0.4], [1.2, 0.4], [1.2, 0.6], [0.8, 0.6]]\ntag = \"a\"\n")
            .expect("mesh.holes[0].outline: invalid mesh parameter: the boundary intersects itself: segment (1, 0)–(1, 1) of the outer polygon meets segment (0.8, 0.4)–(1.2, 0.4) of hole `a`"),
        case("second-hole-inside-the-first", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n[[mesh.holes]]\noutline = [[0.2, 0.2], [0.8, 0.2], [0.8, 0.8], [0.2, 0.8]]\ntag = \"a\"\n\n[[mesh.holes]]\noutline = @@[[0.4, 0.4], [0.6, 0.4], [0.6, 0.6]]\ntag = \"b\"\n")
            .expect("mesh.holes[1].outline: invalid mesh parameter: holes `a` and `b` are nested (one lies inside the other)"),
        // Holes that nearly touch: the mesher would grade its triangles down to
        // their gap (a user's 1e-5 gave 66 000 triangles silently, 1e-6 a
        // degenerate triangle named on `mesh.outline`).
        case("holes-nearly-touching", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n[[mesh.holes]]\noutline = [[0.2, 0.4], [0.4, 0.4], [0.4, 0.6], [0.2, 0.6]]\ntag = \"a\"\n\n[[mesh.holes]]\noutline = @@[[0.40001, 0.4], [0.6, 0.4], [0.6, 0.6], [0.40001, 0.6]]\ntag = \"b\"\n")
            .expect("mesh.holes[1].outline: segment (0.40001, 0.4)–(0.6, 0.4) of hole `b` comes within 1e-5 of segment (0.2, 0.4)–(0.4, 0.4) of hole `a`, 4e-5 of `mesh.edge_length` (0.25): the mesher grades its triangles down to the gap (two holes 1e-5 apart at an edge length of 0.25 gave 66 000 triangles; closer, no mesh); if the two are meant to touch, write them as one (a hole whose outline is their union, or a notch of the outline); else move them 0.025 or more apart (a tenth of the edge length)"),
        case("hole-without-a-tag", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n@@[[mesh.holes]]\noutline = [[0.2, 0.4], [0.4, 0.4], [0.4, 0.6], [0.2, 0.6]]\n")
            .expect("mesh.holes[0].tag: missing field `tag`"),
        case("hole-with-two-corners", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n[[mesh.holes]]\noutline = @@[[0.4, 0.4], [0.6, 0.4]]\ntag = \"a\"\n")
            .expect("mesh.holes[0].outline: invalid mesh parameter: hole `a` needs at least 3 corners, got 2"),
        case("hole-with-an-empty-tag", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n[[mesh.holes]]\noutline = [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6]]\ntag = @@\"\"\n")
            .expect("mesh.holes[0].tag: invalid mesh parameter: boundary tags must not be empty"),
        case("outline-with-an-empty-tag", SQUARE)
            .edit("tags = [\"bottom\", \"right\", \"top\", \"left\"]", "tags = @@[\"bottom\", \"\", \"top\", \"left\"]")
            .expect("mesh.tags: invalid mesh parameter: boundary tags must not be empty"),
        case("outline-on-one-line", SQUARE)
            .edit("outline = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]", "outline = @@[[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]]")
            .edit("tags = [\"bottom\", \"right\", \"top\", \"left\"]\n", "")
            .expect("mesh.outline: invalid mesh parameter: the outer polygon encloses no area (its corners lie on one line)"),
        case("refine-normal", BAR)
            .edit("refine = [\"x\"]", "refine = [@@\"normal\"]")
            .expect("study.refine: unknown variant `normal`, expected `x` or `y`"),
        case("refine-z", BAR)
            .edit("refine = [\"x\"]", "refine = [@@\"z\"]")
            .expect("study.refine: unknown variant `z`, expected `x` or `y`"),
        case("refine-nothing", BAR)
            .edit("refine = [\"x\"]", "refine = @@[]")
            .expect("study.refine: lists no axis: list `x`, `y` or both, or leave `refine` out to refine every axis"),
        case("refine-an-axis-twice", BAR)
            .edit("refine = [\"x\"]", "refine = @@[\"x\", \"y\", \"x\"]")
            .expect("study.refine: `x` is listed twice (entries 0 and 2)"),
        case("fix-a-component-twice", BAR)
            .edit("tag = \"right\"\nfix = [\"x\", \"y\"]", "tag = \"right\"\nfix = @@[\"y\", \"y\"]")
            .expect("boundary[1].fix: `y` is listed twice (entries 0 and 1)"),
        case("a-tag-in-two-boundaries", BAR)
            .edit("tag = \"right\"\nfix = [\"x\", \"y\"]", "tag = \"right\"\nfix = [\"x\", \"y\"]\n\n[[boundary]]\ntag = @@\"left\"\nfix = [\"normal\"]")
            .expect("boundary[2].tag: `left` is already held by boundary[0]: give each tag one [[boundary]] listing all it holds (`fix = [\"x\", \"y\"]`, or `[\"normal\"]` alone)"),
        // The 1D suggestions are valid in 1D: no `y`, and the frictionless end of a
        // contact wall is the slip wall `fix = ["normal"]` (the axis) on its tag.
        case("a-tag-in-two-boundaries-in-1d", BAR_1D)
            .edit("tag = \"left\"\nfix = [\"x\"]", "tag = \"left\"\nfix = [\"x\"]\n\n[[boundary]]\ntag = @@\"left\"\nfix = [\"normal\"]")
            .expect("boundary[1].tag: `left` is already held by boundary[0]: give each tag one [[boundary]] (in 1D `fix = [\"normal\"]`: the axis, an end's only component)"),
        case("contact-wall-in-1d", BAR_1D)
            .edit("[time]", "[[effect]]\nkind = @@\"contact-wall\"\ntag = \"right\"\n\n[time]")
            .expect("effect[0].kind: a contact wall needs a 2D scene; in 1D hold the end with a `[[boundary]]` in place of this effect: `tag = \"right\"` and `fix = [\"normal\"]` (in 1D the normal is the axis)"),
        case("a-basis-in-two-resolutions", BAR)
            .edit("[study]", "[[resolution]]\nbasis = @@\"pl\"\nblocks = [16, 2]\n\n[study]")
            .expect("resolution[1].basis: `pl` already has a resolution (resolution[0]): give each basis one [[resolution]]"),
        case("tracked-point-with-one-coordinate", BAR)
            .edit("tracked = [[2.0, 0.5]]", "tracked = @@[[2.0]]")
            .expect("output.tracked[0]: needs 2 entries, got 1"),
        case("empty-gmsh-file-name", GMSH)
            .edit("file = \"meshes/square.msh\"", "file = @@\"\"")
            .expect("mesh.file: is empty"),
        case("unknown-boundary-tag", BAR)
            .edit("tag = \"right\"", "tag = \"west\"")
            .at(35, 7).expect("boundary[1].tag: unknown boundary tag `west`; the mesh has tags `bottom`, `top`, `left`, `right`"),
        case("unknown-boundary-tag-on-a-gmsh-mesh", GMSH)
            .edit("tag = \"bottom\"", "tag = \"wall\"")
            .at(21, 7).expect("boundary[0].tag: unknown boundary tag `wall`; the mesh has tags `bottom`, `right`, `top`, `left`: the tags of `{dir}/meshes/square.msh` are its physical curves (1D physical groups) on boundary edges, a physical curve on interior edges is none; add `Physical Curve(\"wall\") = {...};` for the wall's boundary curves to the .geo and mesh it again"),
        case("body-outside-the-mesh", BAR)
            .edit("max = [4.0, 1.0]", "max = [4.0, 2.0]")
            .at(22, 1).at(24, 7).expect("body[0].max: the particle at [0.125, 1.125] lies outside the mesh, which spans [0, 4] × [0, 1]; the body must lie inside the meshed domain"),
        case("body-partly-above-the-mesh-off-its-lattice", BAR)
            .edit("max = [4.0, 1.0]", "max = @@[4.0, 1.1]")
            .expect("body[0].max: the body's box [0, 1.1] along axis 1 reaches beyond the mesh's [0, 1]: a body must lie inside the mesh; make `max` at most 1, or enlarge the mesh"),
        case("body-below-the-mesh", BAR)
            .edit("min = [0.0, 0.0]", "min = [0.0, -1.0]")
            .at(23, 7).expect("body[0].min: the particle at [0.125, -0.875] lies outside the mesh, which spans [0, 4] × [0, 1]; the body must lie inside the meshed domain"),
        case("body-in-a-hole-of-the-mesh", SQUARE)
            .edit("edge_length = 0.25\n", "edge_length = 0.25\n\n[[mesh.holes]]\noutline = [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]\ntag = \"post\"\n")
            .at(22, 1).expect("body[0]: the particle at [0.40625, 0.40625] lies in a hole or notch of the mesh (inside its bounding box [0, 1] × [0, 1], but in no element); the body must not overlap the mesh's holes (`[[mesh.holes]]`) or the parts of its outline cut away"),
        case("body-not-a-whole-number-of-cells", BAR)
            .edit("max = [4.0, 1.0]", "max = [4.0, 0.9]")
            .at(24, 7).expect("body[0].max: the body's extent 0.9 along axis 1 is not a whole number of lattice cells of size 0.25 (the mesh's block size along that axis over `per_block`): make the extent a multiple of it, choose `blocks` (or `--blocks`) so that it is, or give `count` instead of `per_block`"),
        // A body off the mesh is named, not its traction (a user's finding: the
        // traction box selecting nothing was reported first).
        case("body-off-the-mesh-with-a-traction", COLUMN)
            .edit("min = [0.0, 0.0]\nmax = [1.0, 4.0]", "min = [10.0, 10.0]\nmax = [11.0, 14.0]")
            .at(19, 7).expect("body[0].max: the particle at [10.25, 10.25] lies outside the mesh, which spans [0, 1] × [0, 4]; the body must lie inside the meshed domain"),
        case("traction-box-selects-nothing", COLUMN)
            .edit("min = [0.0, 3.5]\nmax = [1.0, 4.0]", "min = [5.0, 5.0]\nmax = [6.0, 6.0]")
            .at(36, 7).expect("effect[2].min: the traction box [5, 5] to [6, 6] selects no particle: the particles' centres span [0.25, 0.75] × [0.25, 3.75]; give `min` and `max` a box around the centres of the particles to load (the outer ones lie half a spacing inside the body's outline)"),
        case("self-intersecting-polygon", SQUARE)
            .edit("outline = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]", "outline = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]")
            .at(8, 11).expect("mesh.outline: invalid mesh parameter: the boundary intersects itself: segment (0, 0)–(1, 1) of the outer polygon meets segment (1, 0)–(0, 1) of the outer polygon"),
        case("edge-length-below-the-mesher-limit", SQUARE)
            .edit("edge_length = 0.25", "edge_length = 1e-5")
            .at(10, 15).expect("mesh.edge_length: edge length 1e-5 on an outline of extent 1 × 1 gives about 2.309e10 triangles, above the limit of 4000000"),
        case("block-grid-beyond-the-generator-limit", BAR)
            .edit("blocks = [4, 1]", "blocks = [4096, 4096]")
            .edit("per_block = [4, 4]", "per_block = [1, 1]")
            .at(13, 10).expect("mesh.blocks: 16777216 blocks in all is above the limit of 1000000"),
        // A lattice too coarse for a contact wall: the error points at the key
        // that sets the body's lattice, not at the wall (a student looked there).
        case("lattice-too-coarse-for-a-contact-wall", SQUARE)
            .edit("count = [16, 16]", "count = @@[1, 1]")
            .edit("[[boundary]]\ntag = \"bottom\"\nfix = [\"y\"]", "[[effect]]\nkind = \"contact-wall\"\ntag = \"bottom\"")
            .expect("body[0].count: the particles of body[0] are coarser than the mesh for the contact wall on `bottom` (effect[0]): their contact distance, half a particle spacing, is 5.0000e-1, above the longest edge 2.7951e-1; give the body a spacing below 5.5902e-1, twice that edge (3 or more particles per element want far less: `per_block = [4, 4]` on block meshes), with `per_block`, `count` or `spacing`"),
    ]
}

fn missing_cases() -> Vec<Case> {
    vec![
        case("box-without-max", BAR)
            .edit("[[body]]", "@@[[body]]")
            .edit("max = [4.0, 1.0]\n", "")
            .expect("body[0].max: is missing (or empty): a `box` body (the default shape) needs `max`, its upper corner (2 numbers)"),
        case("box-without-min-in-1d", BAR_1D)
            .edit("[[body]]", "@@[[body]]")
            .edit("min = [0.0]\n", "")
            .expect("body[0].min: is missing (or empty): a `box` body (the default shape) needs `min`, its lower corner (1 number)"),
        case("missing-value-of-a-body-velocity", BAR)
            .edit("per_block = [4, 4]\n", "per_block = [4, 4]\n\n@@[body.initial_velocity]\nkind = \"uniform\"\n")
            .expect("body[0].initial_velocity.value: missing field `value`"),
        case("missing-name", BAR)
            .edit("# A small", "@@# A small")
            .edit("name = \"bar\"\n", "")
            .expect("the scene has no `name`: add `name = \"my-scene\"` (docs/scenes.md lists every key; `mpm-cli scene show column-small` prints a whole scene)"),
        case("missing-material", BAR)
            .edit("[material]\nmodel = \"linear-elastic\"\nyoung = 100.0\npoisson = 0.25\ndensity = 1.0\n", "")
            .edit("[[body]]", "@@[[body]]")
            .expect("body[0].material: the scene has no [material] for the bodies without their own, and body[0] has no `material` table: give it one, or add a scene-level [material]"),
        case("missing-body", BAR)
            .edit("# A small", "@@# A small")
            .edit("[[body]]\nmin = [0.0, 0.0]\nmax = [4.0, 1.0]\nper_block = [4, 4]\n", "")
            .expect("the scene has no [[body]]: add a `[[body]]` section per body (`min`, `max` and `per_block`, or a `shape`) (docs/scenes.md lists every key; `mpm-cli scene show column-small` prints a whole scene)"),
        case("missing-time", BAR)
            .edit("# A small", "@@# A small")
            .edit("[time]\ndt = 1e-3\nt_end = 0.01\n", "")
            .expect("the scene has no [time]: add a `[time]` section (`t_end`, and `courant = 0.5` or `dt`) (docs/scenes.md lists every key; `mpm-cli scene show column-small` prints a whole scene)"),
        case("missing-time-and-body", BAR)
            .edit("# A small", "@@# A small")
            .edit("[[body]]\nmin = [0.0, 0.0]\nmax = [4.0, 1.0]\nper_block = [4, 4]\n", "")
            .edit("[time]\ndt = 1e-3\nt_end = 0.01\n", "")
            .expect("the scene has no [[body]] and [time]: add a `[[body]]` section per body (`min`, `max` and `per_block`, or a `shape`); a `[time]` section (`t_end`, and `courant = 0.5` or `dt`) (docs/scenes.md lists every key; `mpm-cli scene show column-small` prints a whole scene)"),
        case("missing-young", BAR)
            .edit("[material]", "@@[material]")
            .edit("young = 100.0\n", "")
            .expect("material.young: missing field `young`"),
        case("missing-t-end", BAR)
            .edit("[time]", "@@[time]")
            .edit("t_end = 0.01\n", "")
            .expect("time.t_end: missing field `t_end`"),
        case("missing-boundary-fix", BAR)
            .edit("[[boundary]]\ntag = \"right\"", "@@[[boundary]]\ntag = \"right\"")
            .edit("fix = [\"x\", \"y\"]\n\n[time]", "\n[time]")
            .expect("boundary[1].fix: missing field `fix`"),
        case("missing-mesh-kind", BAR)
            .edit("[mesh]", "@@[mesh]")
            .edit("kind = \"blocks\"\n", "")
            .expect("mesh.kind: missing field `kind`"),
        case("missing-gmsh-file", GMSH)
            .edit("[mesh]", "@@[mesh]")
            .edit("file = \"meshes/square.msh\"\n", "")
            .expect("mesh.file: missing field `file`"),
        case("missing-gravity-g", COLUMN)
            .edit("[[effect]]\nkind = \"gravity\"", "@@[[effect]]\nkind = \"gravity\"")
            .edit("g = [0.0, -9.81]\n", "")
            .expect("effect[0].g: missing field `g`"),
        case("empty-file", "")
            .map(|_| "@@".into())
            .expect("the file holds none of a scene's keys and sections (`name`, `dim`, `basis`, [mesh], [material], [[body]], [time]): start from a whole scene, `mpm-cli scene show column-small` (docs/scenes.md lists every key)"),
    ]
}

/// Scenes reading a malformed mesh from `meshes/` next to the scene file.
fn mesh_cases() -> Vec<Case> {
    let bad = |name: &'static str, msh: &str, message: &str| {
        case(name, GMSH)
            .edit("\"meshes/square.msh\"", &format!("@@\"meshes/{msh}\""))
            .expect(&format!("mesh.file: {{dir}}/meshes/{msh}{message}"))
    };
    let data = repo().join("tests/data");
    let at = |file: &str, needle: &str| format!(":{}", line_of(&data.join(file), needle));
    vec![
        bad(
            "gmsh-missing",
            "nothere.msh",
            ": cannot read: No such file or directory (os error 2)",
        ),
        bad(
            "gmsh-binary",
            "square_binary.msh",
            ":2: binary .msh is not supported: save as ASCII (Mesh.Binary = 0)",
        ),
        bad(
            "gmsh-quadrilaterals",
            "quads.msh",
            &format!(
                "{}: quadrilateral elements (type 3) are not supported: psmpm reads first-order triangle meshes",
                at("quads.msh", "2 1 3 78")
            ),
        ),
        bad(
            "gmsh-second-order",
            "second_order.msh",
            &format!(
                "{}: second-order triangle elements (type 9) are not supported: psmpm reads first-order triangle meshes",
                at("bad/second_order.msh", "33 9 ")
            ),
        ),
        bad(
            "gmsh-undefined-node",
            "undefined_node.msh",
            &format!(
                "{}: element refers to undefined node 999",
                at("bad/undefined_node.msh", "33 37 68 999")
            ),
        ),
        bad(
            "gmsh-truncated-4.1",
            "truncated.msh",
            ":101: unexpected end of file, expected a node tag",
        ),
        bad(
            "gmsh-truncated-2.2",
            "truncated_v22.msh",
            ":201: unexpected end of file, expected an element (tag type numTags tags… nodes…)",
        ),
        bad(
            "gmsh-version-3",
            "version3.msh",
            ":2: unsupported .msh format version 3.0 (supported: 4.1 and 2.2 ASCII)",
        ),
        bad(
            "gmsh-no-triangles",
            "no_triangles.msh",
            ": no triangles (element type 2) in the file",
        ),
        bad(
            "gmsh-not-planar",
            "nonplanar.msh",
            ": node 50 has z = 0.5 but others have z = 0: only planar meshes in a z = const plane are supported",
        ),
        bad(
            "gmsh-duplicate-node",
            "duplicate_node.msh",
            &format!(
                "{}: node 5 is defined twice",
                at("bad/duplicate_node.msh", "5 0.374999999999046")
            ),
        ),
        bad(
            "gmsh-decimal-comma",
            "bad_number.msh",
            &format!(
                "{}: expected a finite number for x, found `0,1249999999997731`",
                at("bad/bad_number.msh", "5 0,12")
            ),
        ),
        bad(
            "gmsh-inverted-triangle",
            "inverted.msh",
            &format!(
                "{}: invalid mesh: the triangle of nodes 37 79 68 runs clockwise while other triangles run counter-clockwise (surfaces meshed with opposite normals): reverse that surface's mesh in Gmsh (`ReverseMesh`) or list the element's nodes the other way round",
                at("bad/inverted.msh", "33 2 2 5 1 37 79 68")
            ),
        ),
        bad(
            "gmsh-misspelt-end",
            "misspelt_end.msh",
            &format!(
                "{}: expected $EndNodes, found `$EndNode`",
                at("bad/misspelt_end.msh", "$EndNode")
            ),
        ),
        bad(
            "gmsh-not-a-mesh",
            "not_a_mesh.msh",
            ":1: expected $MeshFormat at the start of the file, found `name = \"vibrating-bar\"`",
        ),
        bad(
            "gmsh-control-characters-and-a-long-line",
            "control_characters.msh",
            &format!(
                ":1: expected $MeshFormat at the start of the file, found `\\u{{1b}}[31m\\u{{7}}{}…`",
                "Y".repeat(74)
            ),
        ),
        bad(
            "gmsh-empty",
            "empty.msh",
            ":1: unexpected end of file, expected a section",
        ),
        bad(
            "gmsh-parametric",
            "parametric.msh",
            &format!(
                "{}: parametric nodes are not supported",
                at("bad/parametric.msh", "1 1 1 7")
            ),
        ),
        bad(
            "gmsh-too-few-tags",
            "too_few_tags.msh",
            &format!(
                "{}: element lists fewer tags than it announces",
                at("bad/too_few_tags.msh", "194 2 9")
            ),
        ),
        bad(
            "gmsh-huge-node-count",
            "huge_count.msh",
            &format!(
                "{}: the number of nodes is 9223372036854775807, above the limit of 10000000",
                at("bad/huge_count.msh", "9223372036854775807")
            ),
        ),
        bad(
            "gmsh-huge-element-block",
            "huge_block.msh",
            &format!(
                "{}: the number of elements in the block is 1000000000000, above the limit of 20000000",
                at("bad/huge_block.msh", "1 1 1 1000000000000")
            ),
        ),
        bad(
            "gmsh-huge-entity-count",
            "huge_entities.msh",
            &format!(
                "{}: an entity count is 4000000000, above the limit of 1000000",
                at("bad/huge_entities.msh", "4 4 1 4000000000")
            ),
        ),
        bad(
            "gmsh-physical-names-beyond-u64",
            "huge_names.msh",
            &format!(
                "{}: the number of physical names is 18446744073709551615, above the limit of 100000",
                at("bad/huge_names.msh", "18446744073709551615")
            ),
        ),
        bad(
            "gmsh-huge-tag-count",
            "huge_tags.msh",
            &format!(
                "{}: the number of element tags is 1000000, above the limit of 1000",
                at("bad/huge_tags.msh", "100 2 1000000 5 1 27 28 37")
            ),
        ),
        bad(
            "gmsh-negative-element-count",
            "negative_count.msh",
            &format!(
                "{}: the number of elements must be non-negative, found -194",
                at("bad/negative_count.msh", "-194")
            ),
        ),
        // A slip wall on a curved boundary.
        case("gmsh-slip-wall-on-a-curve", GMSH)
            .edit("meshes/square.msh", "meshes/square_hole.msh")
            .edit("tag = \"bottom\"\nfix = [\"x\", \"y\"]", "tag = \"hole\"\nfix = [\"normal\"]")
            .edit("min = [0.0, 0.0]\nmax = [1.0, 1.0]", "min = [0.0, 0.0]\nmax = [1.0, 0.25]")
            .at(22, 7).expect("boundary[0].fix: `normal` needs a straight wall, but `hole` bends (a hole's or a corner's edges share one tag): for a frictionless wall that bends, make it a contact wall (`[[effect]]` with `kind = \"contact-wall\"` and `tag = \"hole\"`, in place of this `[[boundary]]`); for a sticking one, `fix = [\"x\", \"y\"]`; or give each straight side its own tag"),
    ]
}

/// Writes the bases and the meshes into `dir`.
/// Numbers far from 1 (`1e300`, `1e-300`) are echoed in their shortest form, in
/// exponent notation, not as hundreds of digits.
fn extreme_number_cases() -> Vec<Case> {
    vec![
        case("huge-mesh-extent-against-the-bar", BAR)
            .edit("x = [0.0, 4.0]", "x = [0.0, 1e300]")
            .at(24, 7).expect("body[0].max: the `vibrating-bar` reference is a bar fixed at both ends, but body[0] spans [0, 4] along x and the mesh, whose ends carry the walls, [0, 1e300]: make the body span the mesh, or leave out [reference]"),
        case("huge-mesh-extent-reversed", BAR)
            .edit("y = [0.0, 1.0]", "y = [1e300, 1.0]")
            .at(12, 5).expect("mesh.y: needs min < max, got [1e300, 1]"),
        case("huge-polygon-extent", SQUARE)
            .edit("outline = [[0.0, 0.0], [1.0, 0.0]", "outline = [[0.0, 0.0], [1e300, 0.0]")
            .at(10, 15).expect("mesh.edge_length: edge length 0.25 on an outline of extent 1e300 × 1 gives about 3.695e301 triangles, above the limit of 4000000"),
        case("tiny-edge-length", SQUARE)
            .edit("edge_length = 0.25", "edge_length = 1e-300")
            .at(10, 15).expect("mesh.edge_length: edge length 1e-300 on an outline of extent 1 × 1 gives about inf triangles, above the limit of 4000000"),
        case("huge-body-outside-the-mesh", SQUARE)
            .edit("max = [1.0, 1.0]", "max = [1e300, 1.0]")
            .at(20, 7).expect("body[0].max: the particle at [3.125e298, 0.03125] lies outside the mesh, which spans [0, 1] × [0, 1]; the body must lie inside the meshed domain"),
        case("huge-time-step", BAR)
            .edit("dt = 1e-3\nt_end = 0.01", "dt = 1e300\nt_end = 1e301")
            .at(39, 6).expect("time.dt: the time step 1e300 is above the critical step 1.196e-2 estimated at the start for this mesh, basis (`ps`) and mass strategy (`consistent`): its Courant number is 8.36e301; lower `time.dt` below 1.196e-2, or give `courant = 0.5` instead of `dt`, or set `allow_above_critical = true` in `[time]` (`--allow-above-critical`) to run anyway"),
    ]
}

fn setup(dir: &Path) {
    let meshes = dir.join("meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    let data = repo().join("tests/data");
    for sub in [data.clone(), data.join("bad")] {
        for entry in std::fs::read_dir(&sub).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "msh") {
                std::fs::copy(&path, meshes.join(path.file_name().unwrap())).unwrap();
            }
        }
    }
}

#[test]
fn the_base_scenes_are_valid() {
    // Every malformed scene is a base with a few edits: the bases themselves run.
    let dir = temp_dir("bases");
    setup(&dir);
    for (name, text) in BASES {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let out = cli()
            .args(["run", path.to_str().unwrap(), "--diag-every", "0"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn malformed_scenes_name_file_line_column_and_field() {
    let dir = temp_dir("scenes");
    setup(&dir);
    let cases: Vec<Case> = [
        syntax_cases(),
        unknown_field_cases(),
        type_cases(),
        table_form_cases(),
        unknown_name_cases(),
        range_cases(),
        inconsistent_cases(),
        missing_cases(),
        mesh_cases(),
        extreme_number_cases(),
    ]
    .into_iter()
    .flatten()
    .collect();
    assert!(cases.len() >= 140, "{} cases", cases.len());
    let mut names = std::collections::HashSet::new();
    let mut failures = String::new();
    for c in &cases {
        assert!(names.insert(c.name), "two cases named {}", c.name);
        let path = dir.join(format!("{}.toml", c.name));
        let (text, expected) = c.resolve(&path);
        std::fs::write(&path, text).unwrap();
        match input_error(&["run", path.to_str().unwrap()]) {
            Ok(stderr) if stderr == expected => {}
            Ok(stderr) => {
                let _ = write!(
                    failures,
                    "\n{}:\n  expected {expected}  got      {stderr}",
                    c.name
                );
            }
            Err(e) => {
                let _ = write!(failures, "\n{}: {e}", c.name);
            }
        }
    }
    assert!(failures.is_empty(), "{failures}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_absolute_gmsh_path_is_used_as_is() {
    let dir = temp_dir("absolute");
    let mesh = repo().join("tests/data/bad/empty.msh");
    let mesh = mesh.canonicalize().unwrap();
    let scene = GMSH.replace("meshes/square.msh", mesh.to_str().unwrap());
    let path = dir.join("absolute.toml");
    std::fs::write(&path, scene).unwrap();
    let stderr = input_error(&["run", path.to_str().unwrap()]).unwrap();
    assert_eq!(
        stderr,
        format!(
            "error: {}:8:8: mesh.file: {}:1: unexpected end of file, expected a section\n",
            path.display(),
            mesh.display()
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unreadable_scene_files_are_named() {
    let dir = temp_dir("unreadable");
    let missing = dir.join("missing.toml");
    let missing = missing.to_str().unwrap();
    assert_eq!(
        input_error(&["run", missing]).unwrap(),
        format!("error: {missing}: cannot read: No such file or directory (os error 2)\n")
    );
    let binary = dir.join("binary.toml");
    std::fs::write(&binary, b"name = \"\xff\xfe\"\n").unwrap();
    let binary = binary.to_str().unwrap();
    assert_eq!(
        input_error(&["run", binary]).unwrap(),
        format!("error: {binary}:1:9: cannot read: byte 0xff is not UTF-8; save the scene as UTF-8 text\n")
    );
    let folder = dir.join("folder.toml");
    std::fs::create_dir_all(&folder).unwrap();
    let folder = folder.to_str().unwrap();
    assert_eq!(
        input_error(&["run", folder]).unwrap(),
        format!("error: {folder}: cannot read: Is a directory (os error 21)\n")
    );
    // `scene show` reads files the same way.
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, BAR.replace("dt = 1e-3", "dt = -1e-3")).unwrap();
    let bad = bad.to_str().unwrap();
    let line = 1 + BAR.lines().position(|l| l == "dt = 1e-3").unwrap();
    assert_eq!(
        input_error(&["scene", "show", bad]).unwrap(),
        format!("error: {bad}:{line}:6: time.dt: must be positive and finite, got -0.001\n")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn project_names_the_bad_mesh_and_its_line() {
    let data = repo().join("tests/data");
    let cases = [
        (
            "bad/undefined_node.msh",
            format!(
                ":{}: element refers to undefined node 999",
                line_of(&data.join("bad/undefined_node.msh"), "33 37 68 999")
            ),
        ),
        (
            "square_binary.msh",
            ":2: binary .msh is not supported: save as ASCII (Mesh.Binary = 0)".into(),
        ),
        (
            "quads.msh",
            format!(
                ":{}: quadrilateral elements (type 3) are not supported: psmpm reads first-order triangle meshes",
                line_of(&data.join("quads.msh"), "2 1 3 78")
            ),
        ),
        (
            "bad/truncated_v22.msh",
            ":201: unexpected end of file, expected an element (tag type numTags tags… nodes…)"
                .into(),
        ),
        (
            "bad/huge_block.msh",
            format!(
                ":{}: the number of elements in the block is 1000000000000, above the limit of 20000000",
                line_of(&data.join("bad/huge_block.msh"), "1 1 1 1000000000000")
            ),
        ),
        (
            "bad/nonplanar.msh",
            ": node 50 has z = 0.5 but others have z = 0: only planar meshes in a z = const plane are supported".into(),
        ),
        (
            "bad/missing.msh",
            ": cannot read: No such file or directory (os error 2)".into(),
        ),
    ];
    let mut failures = String::new();
    for (file, message) in cases {
        let path = data.join(file);
        let path = path.to_str().unwrap();
        let expected = format!("error: {path}{message}\n");
        match input_error(&["project", "--mesh", path, "--levels", "1"]) {
            Ok(stderr) if stderr == expected => {}
            Ok(stderr) => {
                let _ = write!(
                    failures,
                    "\n{file}:\n  expected {expected}  got      {stderr}"
                );
            }
            Err(e) => {
                let _ = write!(failures, "\n{file}: {e}");
            }
        }
    }
    assert!(failures.is_empty(), "{failures}");
}

#[test]
fn an_unknown_scene_lists_the_known_ones() {
    let stderr = input_error(&["run", "pendulum"]).unwrap();
    let known: Vec<&str> = psmpm::scene::BUILTIN.iter().map(|(n, _, _)| *n).collect();
    assert_eq!(
        stderr,
        format!(
            "error: unknown scene `pendulum` (known: {})\n",
            known.join(", ")
        )
    );
    // A name with an extension is a path: to no file here (a file name must end
    // in `.toml` to be read as a file), with the built-in scenes beside.
    let stderr = input_error(&["run", "scene.TOML"]).unwrap();
    assert!(
        stderr.starts_with("error: scene.TOML: no such file; give a scene file FILE.toml or a built-in scene (known: vibrating-bar, "),
        "{stderr}"
    );
}

#[test]
fn unknown_flags_follow_clap_conventions() {
    let out = cli()
        .args(["run", "vibrating-bar", "--frobnicate"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.starts_with("error: unexpected argument '--frobnicate' found\n"),
        "{stderr}"
    );
    assert!(stderr.contains("\nUsage: mpm-cli run "), "{stderr}");
    assert!(stderr.contains("For more information, try '--help'."));
    assert!(!stderr.contains("panicked"));

    for (args, first) in [
        (
            &["frobnicate"][..],
            "error: unrecognized subcommand 'frobnicate'",
        ),
        (
            &["run"][..],
            "error: the following required arguments were not provided:",
        ),
        (
            &["run", "vibrating-bar", "--dt", "small"][..],
            "error: invalid value 'small' for '--dt <DT>': must be a number",
        ),
        (
            &["run", "vibrating-bar", "--format", "xml"][..],
            "error: invalid value 'xml' for '--format <FORMAT>'",
        ),
    ] {
        let out = cli().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(stderr.lines().next(), Some(first), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"));
    }
}

#[test]
fn a_run_that_fails_numerically_exits_with_1_and_names_the_step() {
    // A step above the critical one is refused before the run, naming both steps.
    let out = cli()
        .args(["run", "vibrating-bar", "--dt", "100", "--t-end", "1000"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.starts_with(
            "error: vibrating-bar with --dt 100: time.dt: the time step 100 is above the critical step 4.32"
        ),
        "{stderr}"
    );
    assert!(stderr.contains("--allow-above-critical"), "{stderr}");
    // A flag that does not set the field leaves the error located in the file.
    let file = common_cli::SceneFile::new(
        "big-step",
        &psmpm::scene::Scene::builtin("vibrating-bar")
            .unwrap()
            .to_toml()
            .lines()
            .map(|l| {
                if l.starts_with("dt = ") {
                    "dt = 1.0"
                } else {
                    l
                }
            })
            .collect::<Vec<_>>()
            .join("\n"),
    );
    let out = cli()
        .args(["run", file.arg(), "--t-end", "1000"])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(
        stderr.contains("big-step.toml:") && stderr.contains(": time.dt: the time step 1 is above"),
        "{stderr}"
    );
    // Run anyway: it fails at step 1 and says why.
    let out = cli()
        .args(["run", "vibrating-bar", "--dt", "100", "--t-end", "1000"])
        .arg("--allow-above-critical")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: step 1: "), "{stderr}");
    assert!(stderr.contains("lower `time.dt`"), "{stderr}");
    // The summary on stdout says where the run stopped.
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains("stopped: step 1: "), "{stdout}");
}

/// Gaps found while writing these cases, now closed: each entry is a malformed scene
/// and the strings its error must contain (`{file}`: the scene file).
#[test]
fn known_library_gaps() {
    let dir = temp_dir("gaps");
    setup(&dir);
    let bar_line = |needle: &str| 1 + BAR.lines().position(|l| l.starts_with(needle)).unwrap();
    let gaps: Vec<(&str, String, Vec<String>)> = vec![
        (
            "duplicate key names the key",
            BAR.replace("density = 1.0", "density = 1.0\ndensity = 2.0"),
            vec!["density".into()],
        ),
        (
            "unknown field in [mesh] located at the key",
            BAR.replace("blocks = [4, 1]", "blocks = [4, 1]\nblock = [4, 1]"),
            vec![format!("{{file}}:{}:1: ", bar_line("blocks") + 1)],
        ),
        (
            "unknown field in [reference] located at the key",
            BAR.replace("v0 = 0.1", "v0 = 0.1\namplitude = 2.0"),
            vec![format!("{{file}}:{}:1: ", bar_line("v0 = 0.1") + 1)],
        ),
        (
            "unknown field in the second [[effect]] located at its key",
            COLUMN.replace("alpha = 0.1", "alpha = 0.1\nbeta = 0.2"),
            vec![format!(
                "{{file}}:{}:1: ",
                1 + COLUMN.lines().position(|l| l == "alpha = 0.1").unwrap() + 1
            )],
        ),
        (
            "type errors name the field",
            BAR.replace("dim = 2", "dim = \"two\""),
            vec!["dim".into(), "{file}:4:7: ".into()],
        ),
        (
            "type errors in [mesh] name the field and its line",
            BAR.replace("blocks = [4, 1]", "blocks = [4.5, 1]"),
            vec![
                "mesh.blocks".into(),
                format!("{{file}}:{}:", bar_line("blocks")),
            ],
        ),
        (
            "unknown basis names the field",
            BAR.replace("basis = \"ps\"", "basis = \"cubic\""),
            vec!["basis: unknown basis `cubic`".into()],
        ),
        (
            "unknown mass strategy names the field",
            BAR.replace("mass = \"consistent\"", "mass = \"heavy\""),
            vec!["mass: unknown mass strategy `heavy`".into()],
        ),
        (
            "unknown boundary tag is located and names the field",
            BAR.replace("tag = \"right\"", "tag = \"west\""),
            vec![
                format!("{{file}}:{}:", bar_line("tag = \"right\"")),
                "boundary[1].tag".into(),
            ],
        ),
        (
            "a body outside the mesh is located",
            BAR.replace("max = [4.0, 1.0]", "max = [4.0, 2.0]"),
            vec![format!("{{file}}:{}:", bar_line("max = [4.0, 1.0]"))],
        ),
        (
            "mesher errors are located and name the field",
            SQUARE.replace("edge_length = 0.25", "edge_length = 1e-5"),
            vec!["mesh.edge_length".into(), "{file}:".into()],
        ),
        (
            "columns count characters, not bytes",
            BAR.replace("name = \"bar\"", "name = \"bär\" x"),
            vec!["{file}:2:14: ".into()],
        ),
        (
            "1D is spelt 1D",
            BAR_1D.replace("fix = [\"x\"]", "fix = [\"y\"]"),
            vec!["in 1D".into()],
        ),
        (
            "unknown fields of a unit reference kind are rejected",
            COLUMN.replace(
                "kind = \"column-self-weight\"",
                "kind = \"column-self-weight\"\nv0 = 0.1",
            ),
            vec!["unknown field `v0`".into()],
        ),
        (
            "unknown fields of the manufactured body force are rejected",
            SQUARE.replace(
                "kind = \"manufactured-body-force\"",
                "kind = \"manufactured-body-force\"\nvalue = [1.0, 0.0]",
            ),
            vec!["unknown field `value`".into()],
        ),
        (
            "unknown fields of a unit initial velocity are rejected",
            BAR.replace("kind = \"exact\"", "kind = \"rest\"\nvalue = [1.0, 0.0]"),
            vec!["unknown field `value`".into()],
        ),
    ];
    let mut failures = String::new();
    for (k, (what, text, wanted)) in gaps.iter().enumerate() {
        let path = dir.join(format!("gap{k}.toml"));
        std::fs::write(&path, text).unwrap();
        let file = path.to_str().unwrap();
        match input_error(&["run", file]) {
            Ok(stderr) => {
                for w in wanted {
                    let w = w.replace("{file}", file);
                    if !stderr.contains(&w) {
                        let _ = write!(failures, "\n{what}: `{w}` not in {stderr}");
                    }
                }
            }
            Err(e) => {
                let _ = write!(failures, "\n{what}: {e}");
            }
        }
    }
    assert!(failures.is_empty(), "{failures}");
}

#[test]
fn a_block_sliding_into_slivers_is_warned_about_and_completes_with_the_watch() {
    // A block sliding at 2 m/s across a column of triangles 100 times longer than
    // high: the critical step falls 45 times as it enters them, within a step.
    // The mesh's slivers are warned about at the start; the watch checks the
    // critical step again within a split step when particles change element,
    // and the run completes (it inverted a sliver at step 270 before). Without
    // the watch the failure names the sliver, and the watch as the fix.
    let dir = temp_dir("sliver");
    let scene = dir.join("slide.toml");
    let mesh = repo().join("tests/data/sliver.msh");
    std::fs::write(
        &scene,
        format!(
            r#"
name = "slide-sliver"
dim = 2
basis = "ps"
[mesh]
kind = "gmsh"
file = "{}"
[material]
model = "neo-hookean"
young = 1e5
poisson = 0.3
density = 1e3
[[body]]
min = [0.3, 0.0]
max = [0.6, 0.2]
spacing = [0.01, 0.01]
[initial_velocity]
kind = "uniform"
value = [2.0, 0.0]
[[boundary]]
tag = "floor"
fix = ["normal"]
[[effect]]
kind = "gravity"
g = [0.0, -9.81]
[time]
courant = 0.3
t_end = 0.6
"#,
            mesh.display()
        ),
    )
    .unwrap();
    let run = |extra: &[&str]| {
        cli()
            .args(["run", scene.to_str().unwrap(), "--diag-every", "0"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("warning: the mesh holds 60 triangles longer than 10 times their height (the worst 100 times"),
        "{stderr}"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("critical step watched as the bodies moved"),
        "{stdout}"
    );
    let out = run(&["--no-watch"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("it is a sliver (its pieces' longest edge is")
            && stderr.contains("turn the watch on (`time.watch = true`")
            && stderr.contains("lower `time.courant` from 0.3 to 0.075"),
        "{stderr}"
    );
}

#[test]
fn an_inversion_in_a_spinning_linear_elastic_body_names_the_law_first() {
    // A soft `linear-elastic` plate spinning freely at 4 rad/s: the law is not
    // objective, so the rotation alone compresses it (cos θ − 1) until an element
    // inverts at t ≈ 0.19. The message names the law and the objective ones
    // before what else it sees (too few particles per triangle); with
    // `corotational` the same plate spins to t = 1.
    let dir = temp_dir("spin-linear");
    let scene = dir.join("spin.toml");
    let text = r#"
name = "spin-linear"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0]]
edge_length = 0.25
[material]
model = "linear-elastic"
young = 1e3
poisson = 0.3
density = 1.0
[[body]]
min = [1.0, 1.0]
max = [2.0, 2.0]
count = [10, 10]
[initial_velocity]
kind = "rigid-rotation"
omega = 4.0
centre = [1.5, 1.5]
[time]
courant = 0.5
t_end = 1.0
"#;
    std::fs::write(&scene, text).unwrap();
    // With the watch over the critical step the steps are split as the body turns,
    // and the body fails later (an inverted element, or particles flung out of the
    // mesh): the law is named either way.
    let out = cli()
        .args(["run", scene.to_str().unwrap(), "--diag-every", "0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr
            .lines()
            .any(|l| l.starts_with("error: ") && l.contains("its law, `linear-elastic`")),
        "{stderr}"
    );
    // With every step whole, an element inverts.
    let out = cli()
        .args([
            "run",
            scene.to_str().unwrap(),
            "--diag-every",
            "0",
            "--no-watch",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    // After the warnings, the error.
    let error = stderr
        .lines()
        .find(|l| l.starts_with("error: "))
        .unwrap_or_else(|| panic!("no error: {stderr}"));
    let law = error
        .find("its law, `linear-elastic` (the paper's law on sym(F) − I), is not objective and the body turned by about")
        .unwrap_or_else(|| panic!("the law is not named: {error}"));
    assert!(
        error.starts_with("error: step ")
            && error.contains("the Jacobian det F (non-positive or NaN)")
            && error.contains(
                "use `model = \"corotational\"` (the default, objective) or `\"neo-hookean\"`"
            ),
        "{error}"
    );
    let other = error
        .find("; if it still fails with an objective law: it holds")
        .unwrap_or_else(|| panic!("the other cause is not named: {error}"));
    assert!(law < other, "{error}");
    std::fs::write(
        &scene,
        text.replace("\"linear-elastic\"", "\"corotational\""),
    )
    .unwrap();
    let out = cli()
        .args(["run", scene.to_str().unwrap(), "--diag-every", "0"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
