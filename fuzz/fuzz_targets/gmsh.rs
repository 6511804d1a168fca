//! Any UTF-8 text as a Gmsh `.msh` file: `parse_msh` returns a mesh or an error
//! naming the file (and a line in the text for syntax errors), never panics.
#![no_main]

use libfuzzer_sys::fuzz_target;
use psmpm_basis::mesh::gmsh::{parse_msh, GmshError};

fuzz_target!(|text: &str| {
    match parse_msh(text, "fuzz.msh") {
        Ok(mesh) => {
            assert!(mesh.num_triangles() > 0);
            let _ = mesh.require_tagged_boundary();
        }
        Err(e) => {
            if let GmshError::Syntax { line, .. } = &e {
                assert!(*line >= 1 && *line <= text.lines().count() + 1, "{e}");
            }
            assert!(e.to_string().starts_with("fuzz.msh"), "{e}");
        }
    }
});
