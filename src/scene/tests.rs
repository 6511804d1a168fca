use super::*;

#[test]
fn every_builtin_scene_parses_and_round_trips() {
    for (name, _, _) in BUILTIN {
        let scene = Scene::builtin(name).unwrap();
        let text = scene.to_toml();
        let back = Scene::from_toml(&text, "shown.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(scene, back, "{name}");
    }
}

#[test]
fn jitter_is_validated_and_moves_particles_inside_their_cells_deterministically() {
    let text = Scene::builtin("column-small").unwrap().to_toml();
    let jittered = text.replace("per_block = [6, 8]", "per_block = [6, 8]\njitter = 0.3");
    let scene = Scene::from_toml(&jittered, "j.toml").unwrap();
    assert_eq!(
        Scene::from_toml(&scene.to_toml(), "back.toml").unwrap(),
        scene
    );
    for bad_value in ["0.5", "-0.1", "nan"] {
        let broken = text.replace(
            "per_block = [6, 8]",
            &format!("per_block = [6, 8]\njitter = {bad_value}"),
        );
        let e = Scene::from_toml(&broken, "j.toml").unwrap_err();
        assert!(
            e.message.starts_with("body[0].jitter: must be in [0, 0.5)"),
            "{e}"
        );
    }
    let regular =
        crate::simulation::particle_lattice(&Scene::builtin("column-small").unwrap()).unwrap();
    let moved = crate::simulation::particle_lattice(&scene).unwrap();
    assert_eq!(moved, crate::simulation::particle_lattice(&scene).unwrap());
    let (hx, hy) = (2.0 / 6.0, 25.0 / 8.0 / 8.0);
    let mut largest: f64 = 0.0;
    for (p, q) in regular.positions.iter().zip(&moved.positions) {
        let (dx, dy) = ((q[0] - p[0]) / hx, (q[1] - p[1]) / hy);
        assert!(dx.abs() <= 0.3 && dy.abs() <= 0.3, "{p:?} -> {q:?}");
        largest = largest.max(dx.abs()).max(dy.abs());
    }
    assert!(largest > 0.25, "{largest}");
    let mut other = scene.clone();
    other.bodies[0].seed = Some(7);
    assert_ne!(crate::simulation::particle_lattice(&other).unwrap(), moved);
}

#[test]
fn errors_name_line_column_and_field() {
    let text = Scene::builtin("column-small").unwrap().to_toml();
    let broken = text.replace("t_end = 1.0", "t_end = -1.0");
    let e = Scene::from_toml(&broken, "c.toml").unwrap_err();
    let line = broken.lines().position(|l| l.starts_with("t_end")).unwrap() + 1;
    assert_eq!((e.file.as_str(), e.line), ("c.toml", line), "{e}");
    assert!(e.message.starts_with("time.t_end: must be positive"), "{e}");
}

/// A field missing from the last of several `[[effect]]` is named there, not at the first
/// effect (the parser reports every tagged table's missing field at the first).
#[test]
fn a_missing_field_of_a_later_effect_names_that_effect() {
    let text = Scene::builtin("column-small").unwrap().to_toml();
    let broken = format!(
        "{text}\n[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n\n[[effect]]\nkind = \"damping\"\nalpha = 0.1\n\n[[effect]]\nkind = \"gravity\"\n"
    );
    let e = Scene::from_toml(&broken, "e.toml").unwrap_err();
    let headers: Vec<usize> = broken
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim() == "[[effect]]")
        .map(|(i, _)| i + 1)
        .collect();
    assert!(headers.len() >= 3);
    assert_eq!(e.line, *headers.last().unwrap(), "{e}");
    let field = format!("effect[{}].g", headers.len() - 1);
    assert_eq!(e.field.as_deref(), Some(field.as_str()), "{e}");
}

/// A field missing from a `[[mesh.holes]]` table is named at that hole (the parser
/// reports it at `[mesh]`, as `mesh.tag`, which does not exist; found by a user).
#[test]
fn a_missing_field_of_a_hole_names_that_hole() {
    let text = "name = \"h\"\ndim = 2\n[mesh]\nkind = \"polygon\"\noutline = [[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]]\nedge_length = 0.5\n\n[[mesh.holes]]\ntag = \"a\"\noutline = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]\n\n[[mesh.holes]]\noutline = [[3.0, 1.0], [3.5, 1.0], [3.5, 2.0]]\n\n[material]\nyoung = 1e5\npoisson = 0.3\ndensity = 1.0\n[[body]]\nmin = [0.2, 0.2]\nmax = [0.8, 0.8]\ncount = [4, 4]\n[time]\ncourant = 0.5\nt_end = 0.1\n";
    let e = Scene::from_toml(text, "h.toml").unwrap_err();
    let header = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim() == "[[mesh.holes]]")
        .map(|(i, _)| i + 1)
        .nth(1)
        .unwrap();
    assert_eq!(e.line, header, "{e}");
    assert_eq!(e.field.as_deref(), Some("mesh.holes[1].tag"), "{e}");
}

#[test]
fn errors_are_typed_values_with_field_and_kind() {
    let text = Scene::builtin("column-small").unwrap().to_toml();
    // A value out of range: its field and kind, not read back from the message.
    let e = Scene::from_toml(&text.replace("t_end = 1.0", "t_end = -1.0"), "c.toml").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("time.t_end"));
    assert_eq!(e.kind, Some(ErrorKind::Value));
    // Fields that cannot hold together.
    let mut scene = Scene::builtin("column-small").unwrap();
    scene.reference = None;
    scene.initial_velocity = InitialVelocity::Exact {};
    let e = scene.validate().unwrap_err();
    assert_eq!(
        (e.field.as_str(), e.kind),
        ("initial_velocity.kind", ErrorKind::Conflict)
    );
    // Located in the file where the field is written.
    let located = e.in_file(&scene.to_toml(), "s.toml");
    let line = scene
        .to_toml()
        .lines()
        .position(|l| l.starts_with("[initial_velocity]"))
        .unwrap();
    assert!(located.line > line, "{located}");
    assert_eq!(located.field.as_deref(), Some("initial_velocity.kind"));
    // A syntax error has a location but no field.
    let e = Scene::from_toml("[time\n", "x.toml").unwrap_err();
    assert_eq!((e.field, e.kind), (None, None));
}

#[test]
fn set_up_errors_keep_their_field_and_kind() {
    let mut scene = Scene::builtin("column-small").unwrap();
    scene.boundaries[0].tag = "nowhere".into();
    match crate::simulation::run(&scene, &mut |_| {}) {
        Err(crate::simulation::RunError::Scene(e)) => {
            assert_eq!(
                (e.field.as_str(), e.kind),
                ("boundary[0].tag", ErrorKind::Unknown)
            );
            assert!(e.message.contains("nowhere"), "{e}");
        }
        other => panic!("expected a scene error, got {other:?}"),
    }
}

#[test]
fn the_material_model_defaults_to_the_objective_law_and_the_papers_law_keeps_its_names() {
    let text = Scene::builtin("column-small").unwrap().to_toml();
    assert!(text.contains("model = \"linear-elastic\""), "{text}");
    // The built-in benchmarks name the paper's law explicitly.
    for (name, _, _) in BUILTIN {
        let scene = Scene::builtin(name).unwrap();
        assert_ne!(scene.material.model, MaterialModel::Corotational, "{name}");
    }
    let without = text.replace("model = \"linear-elastic\"\n", "");
    let scene = Scene::from_toml(&without, "m.toml").unwrap();
    assert_eq!(scene.material.model, MaterialModel::Corotational);
    assert!(scene.to_toml().contains("model = \"corotational\""));
    for (name, model) in [
        ("paper-linear", MaterialModel::LinearElastic),
        ("linear-elastic", MaterialModel::LinearElastic),
        ("corotated", MaterialModel::Corotational),
        ("corotational", MaterialModel::Corotational),
        ("neo-hookean", MaterialModel::NeoHookean),
    ] {
        let named = text.replace("\"linear-elastic\"", &format!("\"{name}\""));
        assert_eq!(
            Scene::from_toml(&named, "m.toml").unwrap().material.model,
            model,
            "{name}"
        );
    }
    let e =
        Scene::from_toml(&text.replace("\"linear-elastic\"", "\"plastic\""), "m.toml").unwrap_err();
    println!("{e}");
    assert!(e.message.contains("corotational"), "{e}");
}

#[test]
fn refinement_multiplies_count_and_divides_spacing_along_the_refined_axes() {
    let scene = |mesh: &str, sampling: &str, refine: &str| {
        let (dim, min, max) = if mesh.contains("interval") {
            (1, "[0.0]", "[2.0]")
        } else {
            (2, "[0.0, 0.0]", "[2.0, 2.0]")
        };
        let text = format!(
            "name = \"r\"\ndim = {dim}\nbasis = \"{}\"\n\n[mesh]\n{mesh}\n\n[material]\nyoung = 1.0\ndensity = 1.0\n\n[[body]]\nmin = {min}\nmax = {max}\n{sampling}\n\n[time]\ndt = 1e-3\nt_end = 1e-2\n\n[study]\nrefine = {refine}\n",
            if dim == 1 { "bspline" } else { "pl" }
        );
        Scene::from_toml(&text, "r.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
    };
    let particles = |s: &Scene| {
        crate::simulation::particle_lattice(s)
            .unwrap()
            .positions
            .len()
    };
    let blocks = "kind = \"blocks\"\nx = [0.0, 2.0]\ny = [0.0, 2.0]\nblocks = [2, 2]";
    let both = scene(blocks, "count = [6, 4]", "[\"x\", \"y\"]");
    let counts: Vec<usize> = (0..3)
        .map(|l| particles(&both.refined(l).unwrap()))
        .collect();
    assert_eq!(counts, [24, 96, 384]);
    let x_only = scene(blocks, "count = [6, 4]", "[\"x\"]")
        .refined(2)
        .unwrap();
    assert_eq!(x_only.bodies[0].count, Some(vec![24, 4]));
    let spacing = scene(blocks, "spacing = [0.5, 0.25]", "[\"y\"]")
        .refined(1)
        .unwrap();
    assert_eq!(spacing.bodies[0].spacing, Some(vec![0.5, 0.125]));
    let interval = scene(
        "kind = \"interval\"\nx = [0.0, 2.0]\nelements = 4",
        "count = [8]",
        "[\"x\"]",
    );
    assert_eq!(particles(&interval.refined(2).unwrap()), 32);
    let polygon = scene(
        "kind = \"polygon\"\noutline = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]\nedge_length = 0.5",
        "spacing = [0.5, 0.5]",
        "[\"x\"]",
    );
    assert_eq!(
        polygon.refined(1).unwrap().bodies[0].spacing,
        Some(vec![0.25, 0.25])
    );
}

/// In 1D a traction loads a point: `length` other than 1 scaled the load in silence
/// (a user's bar settled at half the stress asked for).
#[test]
fn a_1d_traction_takes_length_one() {
    let text = |length: f64| {
        format!(
            "name = \"bar\"\ndim = 1\nbasis = \"pl1d\"\n[mesh]\nkind = \"interval\"\nx = [0.0, 1.0]\nelements = 8\n[material]\nyoung = 100.0\ndensity = 1.0\n[[body]]\nmin = [0.0]\nmax = [1.0]\nper_block = [2]\n[[boundary]]\ntag = \"left\"\nfix = [\"x\"]\n[[effect]]\nkind = \"traction\"\nmin = [0.9]\nmax = [1.0]\ntraction = [20.0]\nlength = {length:?}\n[time]\ncourant = 0.5\nt_end = 0.1\n"
        )
    };
    assert!(Scene::from_toml(&text(1.0), "bar.toml").is_ok());
    let error = Scene::from_toml(&text(0.5), "bar.toml")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("effect[0].length: in 1D the loaded boundary is a point: give `length = 1`"),
        "{error}"
    );
}

/// A Gmsh body's `surface` of the wrong type is named in the user's terms.
#[test]
fn a_surface_of_the_wrong_type_says_what_it_takes() {
    for value in ["5.0", "true", "[1]"] {
        let text = format!(
            "name = \"g\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"gmsh\"\nfile = \"m.msh\"\n[material]\nyoung = 1.0\ndensity = 1.0\n[[body]]\nshape = \"gmsh\"\nfile = \"m.msh\"\nsurface = {value}\n[time]\ndt = 0.1\nt_end = 1.0\n"
        );
        let error = Scene::from_toml(&text, "g.toml").unwrap_err().to_string();
        assert!(
            error.contains("body[0].surface")
                && error.contains("expected the name of a physical surface (a string")
                && !error.contains("untagged"),
            "{value}: {error}"
        );
    }
}

/// A traction box with min above max, a traction whose force overflows, and a
/// lateral coefficient outside [0, 10] are named at their field (a user got "selects
/// no particle" and advice about particles per element).
#[test]
fn traction_boxes_loads_and_k0_are_checked() {
    let scene = |effects: &str| {
        let text = format!(
            "name = \"t\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"blocks\"\nx = [0.0, 4.0]\ny = [0.0, 2.0]\nblocks = [4, 2]\n[material]\nyoung = 1e4\ndensity = 1.0\n[[body]]\nmin = [1.0, 0.0]\nmax = [2.0, 1.0]\nper_block = [2, 2]\n{effects}[time]\ncourant = 0.5\nt_end = 0.1\n"
        );
        Scene::from_toml(&text, "t.toml").map_err(|e| e.to_string())
    };
    let traction = |min: &str, max: &str, t: &str, length: &str| {
        format!("[[effect]]\nkind = \"traction\"\nmin = {min}\nmax = {max}\ntraction = {t}\nlength = {length}\n")
    };
    assert!(scene(&traction("[1.0, 0.9]", "[2.0, 1.0]", "[0.0, -1.0]", "1.0")).is_ok());
    let inverted = scene(&traction("[2.0, 0.9]", "[1.0, 1.0]", "[0.0, -1.0]", "1.0")).unwrap_err();
    assert!(
        inverted.contains("effect[0].max: the traction box needs min ≤ max"),
        "{inverted}"
    );
    let huge = scene(&traction(
        "[1.0, 0.9]",
        "[2.0, 1.0]",
        "[0.0, -1e300]",
        "1e300",
    ))
    .unwrap_err();
    assert!(
        huge.contains("effect[0].length: the force `traction × length` overflows"),
        "{huge}"
    );
    let geostatic = |k0: &str| {
        scene(&format!("[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n[[effect]]\nkind = \"geostatic-stress\"\nsurface = 1.0\nk0 = {k0}\n"))
    };
    assert!(geostatic("0.5").is_ok());
    for k0 in ["-0.1", "1e300", "11.0"] {
        let e = geostatic(k0).unwrap_err();
        assert!(e.contains("effect[1].k0: must be in [0, 10]"), "{k0}: {e}");
    }
}
