//! `docs/scenes.md` cannot drift from the schema: for every section of the
//! reference, the keys its table lists are exactly the keys the parser accepts
//! there, and every TOML example on the page parses and validates.
//!
//! The accepted keys come from the parser itself: a probe puts an unknown key
//! `zzz` into the section's table, and the parser's "unknown field" error lists the
//! keys it expected there.

use psmpm::scene::Scene;
use std::collections::BTreeSet;

const DOC: &str = include_str!("../docs/scenes.md");

/// Each section of the reference: its heading, whether its table is tagged by
/// `kind`, and a fragment that makes that table valid with the unknown key `zzz`.
const PROBES: &[(&str, bool, &str)] = &[
    ("## Top level", false, "zzz = 0"),
    (
        "### `[mesh]` with `kind = \"blocks\"`",
        true,
        "[mesh]\nkind = \"blocks\"\nx = [0.0, 4.0]\ny = [0.0, 4.0]\nblocks = [8, 8]\nzzz = 0",
    ),
    (
        "### `[mesh]` with `kind = \"polygon\"`",
        true,
        "[mesh]\nkind = \"polygon\"\noutline = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]\nedge_length = 0.5\nzzz = 0",
    ),
    (
        "### `[[mesh.holes]]`",
        false,
        "[mesh]\nkind = \"polygon\"\noutline = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]\nedge_length = 0.5\n[[mesh.holes]]\noutline = [[2.0, 1.0], [3.0, 1.0], [3.0, 2.0]]\ntag = \"hole\"\nzzz = 0",
    ),
    (
        "### `[mesh]` with `kind = \"gmsh\"`",
        true,
        "[mesh]\nkind = \"gmsh\"\nfile = \"x.msh\"\nzzz = 0",
    ),
    (
        "### `[mesh]` with `kind = \"interval\"`",
        true,
        "[mesh]\nkind = \"interval\"\nx = [0.0, 1.0]\nelements = 4\nzzz = 0",
    ),
    (
        "## `[material]`",
        false,
        "[material]\nmodel = \"neo-hookean\"\nyoung = 1.0\ndensity = 1.0\nzzz = 0",
    ),
    (
        "## `[[body]]`",
        false,
        "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [2, 2]\nzzz = 0",
    ),
    (
        "### `[initial_velocity]` with `kind = \"rest\"`",
        true,
        "[initial_velocity]\nkind = \"rest\"\nzzz = 0",
    ),
    (
        "### `[initial_velocity]` with `kind = \"uniform\"`",
        true,
        "[initial_velocity]\nkind = \"uniform\"\nvalue = [0.0, 0.0]\nzzz = 0",
    ),
    (
        "### `[initial_velocity]` with `kind = \"sine-mode\"`",
        true,
        "[initial_velocity]\nkind = \"sine-mode\"\nv0 = 0.1\nzzz = 0",
    ),
    (
        "### `[initial_velocity]` with `kind = \"exact\"`",
        true,
        "[initial_velocity]\nkind = \"exact\"\nzzz = 0",
    ),
    (
        "### `[initial_velocity]` with `kind = \"rigid-rotation\"`",
        true,
        "[initial_velocity]\nkind = \"rigid-rotation\"\nomega = 1.0\ncentre = [0.0, 0.0]\nzzz = 0",
    ),
    (
        "### `[initial_velocity]` with `kind = \"linear\"`",
        true,
        "[initial_velocity]\nkind = \"linear\"\nvalue = [0.0, 0.0]\norigin = [0.0, 0.0]\ngradient = [[0.0, 0.0], [0.0, 0.0]]\nzzz = 0",
    ),
    (
        "## `[[boundary]]`",
        false,
        "[[boundary]]\ntag = \"bottom\"\nfix = [\"y\"]\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"gravity\"`",
        true,
        "[[effect]]\nkind = \"gravity\"\ng = [0.0, -1.0]\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"damping\"`",
        true,
        "[[effect]]\nkind = \"damping\"\nalpha = 0.1\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"traction\"`",
        true,
        "[[effect]]\nkind = \"traction\"\nmin = [0.0, 0.0]\nmax = [4.0, 4.0]\ntraction = [0.0, 1.0]\nlength = 1.0\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"body-force\"`",
        true,
        "[[effect]]\nkind = \"body-force\"\nvalue = [0.0, 1.0]\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"manufactured-body-force\"`",
        true,
        "[[effect]]\nkind = \"manufactured-body-force\"\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"body-contact\"`",
        true,
        "[[effect]]\nkind = \"body-contact\"\nzzz = 0",
    ),
    (
        "### `[[effect]]` with `kind = \"geostatic-stress\"`",
        true,
        "[[effect]]\nkind = \"geostatic-stress\"\nsurface = 1.0\nzzz = 0",
    ),
    (
        "## `[time]`",
        false,
        "[time]\ndt = 1e-3\nt_end = 1.0\nzzz = 0",
    ),
    (
        "### `[reference]` with `kind = \"vibrating-bar\"`",
        true,
        "[reference]\nkind = \"vibrating-bar\"\nv0 = 0.1\nzzz = 0",
    ),
    (
        "### `[reference]` with `kind = \"column-self-weight\"`",
        true,
        "[reference]\nkind = \"column-self-weight\"\nzzz = 0",
    ),
    (
        "### `[reference]` with `kind = \"axis-aligned\"`",
        true,
        "[reference]\nkind = \"axis-aligned\"\nu0 = 0.1\nzzz = 0",
    ),
    (
        "### `[reference]` with `kind = \"column-equilibrium\"`",
        true,
        "[reference]\nkind = \"column-equilibrium\"\nzzz = 0",
    ),
    ("## `[output]`", false, "[output]\nzzz = 0"),
    (
        "## `[[resolution]]`",
        false,
        "[[resolution]]\nbasis = \"pl\"\nzzz = 0",
    ),
    ("## `[study]`", false, "[study]\nzzz = 0"),
    (
        "### `[[effect]]` with `kind = \"contact-wall\"`",
        true,
        "[[effect]]\nkind = \"contact-wall\"\ntag = \"bottom\"\nzzz = 0",
    ),
];

/// The TOML examples of the page, in order.
fn examples() -> Vec<String> {
    let mut out = Vec::new();
    let mut current: Option<String> = None;
    for line in DOC.lines() {
        match (&mut current, line.trim_end()) {
            (None, "```toml") => current = Some(String::new()),
            (Some(_), "```") => out.extend(current.take()),
            (Some(block), l) => {
                block.push_str(l);
                block.push('\n');
            }
            (None, _) => {}
        }
    }
    out
}

/// `fragment`'s top-level entries put into the complete scene `base` (replacing
/// what it had there), as TOML text.
fn merged(base: &str, fragment: &str) -> String {
    let mut table: toml::Table = base.parse().expect("the complete example is TOML");
    let part: toml::Table = fragment.parse().expect("the fragment is TOML");
    for (key, value) in part {
        table.insert(key, value);
    }
    toml::to_string(&table).unwrap()
}

/// The keys listed in the table under `heading` (first column, in backticks).
fn documented_keys(heading: &str) -> BTreeSet<String> {
    let start = DOC
        .lines()
        .position(|l| l.trim_end() == heading)
        .unwrap_or_else(|| panic!("docs/scenes.md has no section `{heading}`"));
    // Only the rows of a key table (headed `| key |`): a section may also hold
    // other tables, such as the columns a run writes.
    let mut in_key_table = false;
    let mut keys = BTreeSet::new();
    for line in DOC
        .lines()
        .skip(start + 1)
        .take_while(|l| !l.starts_with('#'))
    {
        if !line.starts_with('|') {
            in_key_table = false;
        } else if line.starts_with("| key |") {
            in_key_table = true;
        } else if in_key_table && line.starts_with("| `") {
            keys.insert(line[3..].split('`').next().unwrap().to_string());
        }
    }
    keys
}

/// The keys the parser accepts where the probe put `zzz`, read from its error.
fn accepted_keys(base: &str, probe: &str) -> BTreeSet<String> {
    let text = merged(base, probe);
    let e = Scene::from_toml(&text, "probe.toml").expect_err("the probe has an unknown key");
    let message = e.message;
    assert!(message.contains("unknown field `zzz`"), "{message}");
    if message.contains("there are no fields") {
        return BTreeSet::new();
    }
    let (_, expected) = message
        .split_once("expected ")
        .unwrap_or_else(|| panic!("no list of expected fields: {message}"));
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(String::from)
        .collect()
}

#[test]
fn every_section_lists_exactly_the_keys_the_parser_accepts() {
    let base = &examples()[0];
    let mut failures = Vec::new();
    for &(heading, tagged, probe) in PROBES {
        let mut accepted = accepted_keys(base, probe);
        if tagged {
            accepted.insert("kind".to_string());
        }
        let documented = documented_keys(heading);
        if accepted != documented {
            failures.push(format!(
                "{heading}\n  parser accepts {accepted:?}\n  docs list      {documented:?}"
            ));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn every_section_of_the_page_is_checked() {
    let checked: BTreeSet<&str> = PROBES.iter().map(|p| p.0).collect();
    for heading in DOC
        .lines()
        .filter(|l| l.starts_with("## ") || l.starts_with("### "))
    {
        let has_table = !documented_keys(heading).is_empty();
        assert!(
            !has_table || checked.contains(heading),
            "section `{heading}` has a key table that no probe checks"
        );
    }
}

#[test]
fn every_example_parses_and_validates() {
    let all = examples();
    assert!(all.len() >= 6, "the page has {} examples", all.len());
    let base = &all[0];
    for fragment in &all {
        let text = merged(base, fragment);
        let mut scene = Scene::from_toml(&text, "docs/scenes.md")
            .unwrap_or_else(|e| panic!("example\n{fragment}\nfails: {e}"));
        // and sets up and runs (a few steps): the mesh, tags and bodies fit.
        scene.time.t_end = 1e-3;
        let summary = psmpm::simulation::run(&scene, &mut |_| {})
            .unwrap_or_else(|e| panic!("example\n{fragment}\ndoes not run: {e}"));
        assert!(
            summary.failure.is_none(),
            "{fragment}: {:?}",
            summary.failure
        );
    }
}
