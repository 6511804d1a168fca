//! The recipe of `docs/tutorial.md` ("Pin your scene with a snapshot test"), as the
//! docs show it: a scene file of one's own, run and pinned with `insta`. The block
//! between the markers is the one the tutorial prints (a test below checks that
//! they agree).

// recipe: start
use psmpm::scene::Scene;
use psmpm::snapshot::{snapshot, SnapshotOptions};

#[test]
fn settle_does_not_change() {
    let path = "docs/examples/settle.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let scene = Scene::from_toml(&text, path).unwrap();
    let value = snapshot(&scene, &SnapshotOptions::default()).unwrap();
    insta::assert_json_snapshot!("settle", value);
}
// recipe: end

/// The tutorial prints exactly the recipe above.
#[test]
fn the_tutorial_shows_this_recipe() {
    let this = std::fs::read_to_string("tests/snapshot_recipe.rs").unwrap();
    let recipe = this
        .split("// recipe: start\n")
        .nth(1)
        .and_then(|r| r.split("// recipe: end").next())
        .unwrap();
    let tutorial = std::fs::read_to_string("docs/tutorial.md").unwrap();
    assert!(
        tutorial.contains(&format!("```rust\n{recipe}```")),
        "docs/tutorial.md must show the recipe of tests/snapshot_recipe.rs:\n{recipe}"
    );
}
