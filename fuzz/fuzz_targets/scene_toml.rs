//! Any UTF-8 text as a scene file: `Scene::from_toml` returns a scene or a located
//! error, never panics; a scene that validates is written back with `to_toml` and
//! must read back equal (and write back the same text).
#![no_main]

use libfuzzer_sys::fuzz_target;
use psmpm::scene::Scene;

fuzz_target!(|text: &str| {
    match Scene::from_toml(text, "fuzz.toml") {
        Ok(scene) => {
            let shown = scene.to_toml();
            let back = Scene::from_toml(&shown, "shown.toml")
                .unwrap_or_else(|e| panic!("a valid scene does not read back: {e}\n{shown}"));
            // NaN is not equal to itself; the text must round-trip regardless.
            assert_eq!(shown, back.to_toml(), "the text does not round-trip");
            assert!(
                scene == back || shown.to_lowercase().contains("nan"),
                "the scene does not round-trip:\n{shown}"
            );
            // What the commands derive from a valid scene does not panic either.
            let _ = scene.steps();
            let _ = scene.dt(0.1);
            let _ = scene.mesh_size();
            for level in 0..3 {
                let _ = scene.refined(level);
            }
            for basis in ["ps", "pl", "bspline", "pl1d"] {
                let kind = psmpm::bases::BasisKind::parse(basis).unwrap();
                let _ = scene.with_basis(kind);
            }
        }
        Err(e) => {
            // The location lies in the text.
            assert!(e.line >= 1 && e.column >= 1, "{e}");
            assert!(e.line <= text.lines().count() + 1, "{e}");
            assert!(!e.message.is_empty(), "{e}");
            let _ = e.to_string();
        }
    }
});
