//! Bodies of every shape, each with its own material and initial velocity: the
//! particles each shape makes (counts exact where the lattice makes them so, total
//! volumes against the exact area within the lattice's discretisation error), the
//! rigid-rotation and linear velocities, a run with a stiff and a soft body whose
//! results show the two materials, and the errors of bad bodies.

use psmpm::scene::{ErrorKind, Scene, SceneError};
use psmpm::simulation::{self, particle_lattice, Lattice, ParticlesRef, RunError};
use std::f64::consts::PI;

/// A 2D scene on `[0, 4]²` (8 × 8 blocks) with `bodies` (TOML) and `rest` (more
/// TOML, e.g. an initial velocity).
fn scene_text(bodies: &str, rest: &str) -> String {
    format!(
        r#"name = "bodies"
dim = 2
basis = "ps"

[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 4.0]
blocks = [8, 8]

[material]
young = 1e4
poisson = 0.3
density = 1.0

{bodies}

{rest}

[time]
dt = 1e-4
t_end = 1e-3
"#
    )
}

fn scene(bodies: &str, rest: &str) -> Scene {
    let text = scene_text(bodies, rest);
    Scene::from_toml(&text, "bodies.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn lattice(bodies: &str) -> Lattice {
    particle_lattice(&scene(bodies, "")).unwrap()
}

fn total(l: &Lattice) -> f64 {
    l.volumes.iter().sum()
}

/// The test mesh with two physical surfaces (see tests/data/README.md).
fn two_surfaces() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/two_surfaces.msh").to_string()
}

/// The error of a scene file, from parsing or from setting it up.
fn error_of(text: &str) -> (String, Option<ErrorKind>, String) {
    match Scene::from_toml(text, "bad.toml") {
        Err(e) => (e.field.unwrap_or_default(), e.kind, e.message),
        Ok(scene) => match particle_lattice(&scene) {
            Err(RunError::Scene(SceneError {
                field,
                kind,
                message,
            })) => (field, Some(kind), message),
            other => panic!("no scene error: {:?}", other.map(|l| l.positions.len())),
        },
    }
}

#[test]
fn a_polygon_with_a_hole_aligned_with_the_lattice_is_filled_exactly() {
    // An L-shape of area 2 with a square hole of area 0.25, edges on lattice lines.
    let l = lattice(
        r#"[[body]]
shape = "polygon"
outline = [[1.0, 1.0], [3.0, 1.0], [3.0, 1.5], [2.0, 1.5], [2.0, 2.5], [1.0, 2.5]]
holes = [[[1.25, 1.75], [1.75, 1.75], [1.75, 2.25], [1.25, 2.25]]]
spacing = [0.05, 0.05]"#,
    );
    assert_eq!(l.positions.len(), 700);
    assert!((total(&l) - 1.75).abs() < 1e-12, "{}", total(&l));
    assert!(l.volumes.iter().all(|&v| (v - 0.0025).abs() < 1e-15));
    for p in &l.positions {
        let in_hole = (1.25..1.75).contains(&p[0]) && (1.75..2.25).contains(&p[1]);
        let in_l = (p[0] < 2.0 || p[1] < 1.5) && (1.0..3.0).contains(&p[0]);
        assert!(in_l && !in_hole, "{p:?}");
    }
    // `count` over the bounding box (2 × 1.5) gives the same lattice.
    let c = lattice(
        r#"[[body]]
shape = "polygon"
outline = [[1.0, 1.0], [3.0, 1.0], [3.0, 1.5], [2.0, 1.5], [2.0, 2.5], [1.0, 2.5]]
holes = [[[1.25, 1.75], [1.75, 1.75], [1.75, 2.25], [1.25, 2.25]]]
count = [40, 30]"#,
    );
    assert_eq!(c.positions.len(), 700);
    assert!((total(&c) - 1.75).abs() < 1e-12);
}

#[test]
fn a_slanted_polygon_converges_to_its_area() {
    // A triangle: its hypotenuse cuts cells, so the volume is off by at most the
    // cells along it, and the error shrinks with the spacing.
    let errors: Vec<f64> = [8, 32, 128]
        .iter()
        .map(|n| {
            let l = lattice(&format!(
                "[[body]]\nshape = \"polygon\"\noutline = [[1.0, 1.0], [3.0, 1.0], [1.0, 3.0]]\ncount = [{n}, {n}]"
            ));
            let h = 2.0 / *n as f64;
            let error = (total(&l) - 2.0).abs();
            // The hypotenuse (length 2√2) crosses at most 2 n cells of area h².
            assert!(error <= 2.0 * *n as f64 * h * h, "n = {n}: {error}");
            error
        })
        .collect();
    assert!(errors[2] < errors[0] / 4.0, "{errors:?}");
}

#[test]
fn a_disk_has_exact_counts_on_coarse_lattices_and_converges_to_pi_r_squared() {
    // Radius 1: a 2 × 2 lattice keeps all four cells (centres at distance 0.71),
    // a 4 × 4 lattice all but the four corner cells (distance 1.06).
    let disk = |n: usize| {
        lattice(&format!(
            "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 1.0\ncount = [{n}, {n}]"
        ))
    };
    let (two, four) = (disk(2), disk(4));
    assert_eq!(two.positions.len(), 4);
    assert!((total(&two) - 4.0).abs() < 1e-12);
    assert_eq!(four.positions.len(), 12);
    assert!((total(&four) - 3.0).abs() < 1e-12);
    for n in [16, 64, 256] {
        let l = disk(n);
        let h = 2.0 / n as f64;
        // Symmetric about the centre: the four quadrants hold as many particles.
        assert_eq!(l.positions.len() % 4, 0, "n = {n}");
        // Cells cut by the circle lie within h/√2 of it.
        let error = (total(&l) - PI).abs();
        assert!(error <= 2.0 * PI * h * 2f64.sqrt(), "n = {n}: {error}");
        assert!(l
            .positions
            .iter()
            .all(|p| (p[0] - 2.0).hypot(p[1] - 2.0) < 1.0));
    }
    assert!((total(&disk(256)) - PI).abs() < 2e-3);
    // The bounding box of the disk is recorded for the body.
    assert_eq!(two.bounds, vec![([1.0, 1.0], [3.0, 3.0])]);
}

#[test]
fn a_gmsh_surface_gets_quadrature_points_whose_volumes_sum_to_its_area() {
    let body = |surface: &str, per: usize| {
        lattice(&format!(
            "[[body]]\nshape = \"gmsh\"\nfile = \"{}\"\nsurface = {surface}\nper_triangle = {per}",
            two_surfaces()
        ))
    };
    let three = body("\"left\"", 3);
    assert_eq!(three.positions.len(), 6);
    assert!((total(&three) - 0.5).abs() < 1e-15);
    assert!(three
        .positions
        .iter()
        .all(|p| p[0] > 0.0 && p[0] < 0.5 && p[1] > 0.0 && p[1] < 1.0));
    let one = body("\"right\"", 1);
    assert_eq!(one.positions.len(), 2);
    assert!((total(&one) - 0.5).abs() < 1e-15);
    // Centroids of the right half's triangles.
    assert!(
        (one.positions[0][0] - 2.5 / 3.0).abs() < 1e-12,
        "{:?}",
        one.positions
    );
    // By number, and the default rule (3 per triangle).
    let by_tag = lattice(&format!(
        "[[body]]\nshape = \"gmsh\"\nfile = \"{}\"\nsurface = 11",
        two_surfaces()
    ));
    assert_eq!(by_tag.positions.len(), 6);
    assert_eq!(by_tag.bounds, vec![([0.5, 0.0], [1.0, 1.0])]);
    // Split twice: 16 pieces per triangle, one particle each, the same area.
    let split = lattice(&format!(
        "[[body]]\nshape = \"gmsh\"\nfile = \"{}\"\nsurface = \"left\"\nper_triangle = 1\nsubdivide = 2",
        two_surfaces()
    ));
    assert_eq!(split.positions.len(), 32);
    assert!((total(&split) - 0.5).abs() < 1e-15);
    assert!(split
        .volumes
        .iter()
        .all(|&v| (v - 0.25 / 16.0).abs() < 1e-15));
    let mut xs: Vec<[f64; 2]> = split.positions.clone();
    xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
    xs.dedup();
    assert_eq!(xs.len(), 32);
    assert!(xs
        .iter()
        .all(|p| p[0] > 0.0 && p[0] < 0.5 && p[1] > 0.0 && p[1] < 1.0));
    // Both halves as two bodies side by side: they touch, they do not overlap.
    let both = lattice(&format!(
        "[[body]]\nshape = \"gmsh\"\nfile = \"{f}\"\nsurface = \"left\"\n\n[[body]]\nshape = \"gmsh\"\nfile = \"{f}\"\nsurface = \"right\"",
        f = two_surfaces()
    ));
    assert_eq!(both.body_sizes, vec![6, 6]);
}

#[test]
fn box_bodies_are_unchanged_and_spacing_fills_them_row_by_row() {
    let counted = lattice("[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 1.5]\ncount = [4, 2]");
    let spaced = lattice("[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 1.5]\nspacing = [0.25, 0.25]");
    assert_eq!(counted, spaced);
    assert_eq!(counted.positions[0], [1.125, 1.125]);
    assert_eq!(counted.bounds, vec![([1.0, 1.0], [2.0, 1.5])]);
}

/// The particles' initial velocities of `scene`, with their initial positions.
fn initial_velocities(scene: &Scene) -> Vec<([f64; 2], [f64; 2])> {
    let mut out = Vec::new();
    let mut observer = |r: &psmpm::diagnostics::StepReport, p: ParticlesRef<'_>| {
        if r.step == 0 {
            if let ParticlesRef::Two(p) = p {
                out = (0..p.len())
                    .map(|i| ([p.x0[i][0], p.x0[i][1]], [p.v[i][0], p.v[i][1]]))
                    .collect();
            }
        }
    };
    simulation::observe_2d(scene, &mut observer).unwrap();
    out
}

#[test]
fn rigid_rotation_and_linear_velocities_are_those_fields() {
    let s = scene(
        "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 0.5\ncount = [8, 8]",
        "[initial_velocity]\nkind = \"rigid-rotation\"\nomega = 3.0\ncentre = [1.5, 2.5]",
    );
    let v = initial_velocities(&s);
    assert!(!v.is_empty());
    for (x, v) in &v {
        let expected = [-3.0 * (x[1] - 2.5), 3.0 * (x[0] - 1.5)];
        assert!((v[0] - expected[0]).abs() < 1e-12 && (v[1] - expected[1]).abs() < 1e-12);
        // Perpendicular to the arm: a rotation.
        assert!((v[0] * (x[0] - 1.5) + v[1] * (x[1] - 2.5)).abs() < 1e-12);
    }
    let s = scene(
        "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [4, 4]",
        "[initial_velocity]\nkind = \"linear\"\nvalue = [1.0, -2.0]\norigin = [1.5, 1.5]\ngradient = [[0.5, 2.0], [-1.0, 0.25]]",
    );
    for (x, v) in initial_velocities(&s) {
        let d = [x[0] - 1.5, x[1] - 1.5];
        let expected = [1.0 + 0.5 * d[0] + 2.0 * d[1], -2.0 - d[0] + 0.25 * d[1]];
        assert!((v[0] - expected[0]).abs() < 1e-12 && (v[1] - expected[1]).abs() < 1e-12);
    }
    // A body's own velocity wins over the scene's; the other body takes the scene's.
    let s = scene(
        "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [2, 2]\ninitial_velocity = { kind = \"uniform\", value = [0.0, 5.0] }\n\n[[body]]\nmin = [2.0, 1.0]\nmax = [3.0, 2.0]\ncount = [2, 2]",
        "[initial_velocity]\nkind = \"uniform\"\nvalue = [1.0, 0.0]",
    );
    let v = initial_velocities(&s);
    assert_eq!(v.len(), 8);
    assert!(v[..4].iter().all(|(_, v)| *v == [0.0, 5.0]));
    assert!(v[4..].iter().all(|(_, v)| *v == [1.0, 0.0]));
}

/// A stiff and a soft block side by side on a fixed floor, under gravity, each
/// with its own material; the largest mean settlement of each over the run.
fn settlements(soft_young: f64, stiff_young: f64) -> ([f64; 2], simulation::Summary) {
    let text = format!(
        r#"name = "stiff-and-soft"
dim = 2
basis = "ps"

[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 2.0]
blocks = [8, 4]

[[body]]
min = [0.5, 0.0]
max = [1.5, 1.0]
per_block = [3, 3]
material = {{ young = {soft_young}, poisson = 0.3, density = 1.0 }}

[[body]]
min = [2.5, 0.0]
max = [3.5, 1.0]
per_block = [3, 3]
material = {{ young = {stiff_young}, poisson = 0.3, density = 1.0 }}

[[boundary]]
tag = "bottom"
fix = ["x", "y"]

[[effect]]
kind = "gravity"
g = [0.0, -10.0]

[time]
courant = 0.5
t_end = 0.06
"#
    );
    let scene = Scene::from_toml(&text, "stiff-and-soft.toml").unwrap();
    let n = particle_lattice(&scene).unwrap().body_sizes;
    let mut peak = [0.0f64; 2];
    let mut observer = |_: &psmpm::diagnostics::StepReport, p: ParticlesRef<'_>| {
        if let ParticlesRef::Two(p) = p {
            let mean = |range: std::ops::Range<usize>| {
                let k = range.len() as f64;
                range.map(|i| -p.u[i][1]).sum::<f64>() / k
            };
            peak[0] = peak[0].max(mean(0..n[0]));
            peak[1] = peak[1].max(mean(n[0]..n[0] + n[1]));
        }
    };
    let out = simulation::observe_2d(&scene, &mut observer).unwrap();
    (peak, out.summary)
}

#[test]
fn a_stiff_and_a_soft_body_settle_by_their_own_stiffness() {
    // A block suddenly loaded by its weight settles by about ρ g H² / E at its
    // peak (twice the static mean settlement ρ g H² / (2E) for a uniaxial
    // column): a quarter as much for four times the stiffness. The soft block's
    // period 4 H / c ≈ 0.04 fits in the run.
    let (peak, summary) = settlements(1e4, 4e4);
    assert!(summary.failure.is_none(), "{:?}", summary.failure);
    assert!(summary.energy_drift < 0.05, "{}", summary.energy_drift);
    let ratio = peak[0] / peak[1];
    assert!(
        (3.0..5.0).contains(&ratio),
        "settlements {peak:?}, ratio {ratio}"
    );
    let expected = 1.0 * 10.0 * 1.0 / 1e4;
    assert!(
        (0.5 * expected..1.5 * expected).contains(&peak[0]),
        "soft block settles {} (about {expected})",
        peak[0]
    );
    // With equal materials, the two blocks (mirror images in the mesh) settle
    // alike.
    let (same, soft_only) = settlements(1e4, 1e4);
    assert!((same[0] / same[1] - 1.0).abs() < 1e-3, "{same:?}");
    // The critical step is the stiff block's: with twice the wave speed, the same
    // Courant number gives about half the time step.
    let ratio = summary.dt / soft_only.dt;
    assert!(
        (0.4..0.6).contains(&ratio),
        "{} / {}",
        summary.dt,
        soft_only.dt
    );
}

#[test]
fn bad_bodies_are_errors_naming_the_field() {
    let cases: Vec<(String, &str, ErrorKind, &str)> = vec![
        (
            scene_text(
                "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [2, 2]\nmaterial = { young = 1.0, density = 1.0 }\n\n[[body]]\nmin = [2.0, 1.0]\nmax = [3.0, 2.0]\ncount = [2, 2]",
                "",
            )
            .replace("[material]\nyoung = 1e4\npoisson = 0.3\ndensity = 1.0\n", ""),
            "body[1].material",
            ErrorKind::Conflict,
            "no [material]",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"polygon\"\noutline = [[1.0, 1.0], [2.0, 2.0], [2.0, 1.0], [1.0, 2.0]]\ncount = [4, 4]",
                "",
            ),
            "body[0].outline",
            ErrorKind::Value,
            "intersects itself",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"polygon\"\noutline = [[1.0, 1.0], [2.0, 1.0]]\ncount = [4, 4]",
                "",
            ),
            "body[0].outline",
            ErrorKind::Value,
            "at least 3 corners",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"polygon\"\noutline = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]\nholes = [[[3.0, 3.0], [3.5, 3.0], [3.5, 3.5]]]\ncount = [4, 4]",
                "",
            ),
            "body[0].holes[0]",
            ErrorKind::Value,
            "outside the outer polygon",
        ),
        (
            scene_text(
                &format!(
                    "[[body]]\nshape = \"gmsh\"\nfile = \"{}\"\nsurface = \"middle\"",
                    two_surfaces()
                ),
                "",
            ),
            "body[0].surface",
            ErrorKind::Unknown,
            "no physical surface `middle` with triangles (it has: left, right)",
        ),
        (
            scene_text(
                &format!(
                    "[[body]]\nshape = \"gmsh\"\nfile = \"{}\"\nsurface = \"left\"\nsubdivide = 9",
                    two_surfaces()
                ),
                "",
            ),
            "body[0].subdivide",
            ErrorKind::Value,
            "must be in 0..=8",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"gmsh\"\nfile = \"/nonexistent/mesh.msh\"\nsurface = 1",
                "",
            ),
            "body[0].file",
            ErrorKind::File,
            "cannot read",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 0.5\nmin = [1.0, 1.0]\ncount = [4, 4]",
                "",
            ),
            "body[0].min",
            ErrorKind::Conflict,
            "is not a field of a `disk` body (it belongs to box)",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = -0.5\ncount = [4, 4]",
                "",
            ),
            "body[0].radius",
            ErrorKind::Value,
            "must be positive",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 1.0\nspacing = [1e-4, 1e-4]",
                "",
            ),
            "body[0].spacing",
            ErrorKind::Value,
            "above the limit of 10000000 (body[0] about 4.000e8): give a larger `spacing`",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 1e-200\nspacing = [1e-200, 1e-200]",
                "",
            ),
            "body[0].spacing",
            ErrorKind::Value,
            "would have mass 0e0",
        ),
        (
            scene_text(
                "[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 0.1\nspacing = [0.5, 0.5]",
                "",
            ),
            "body[0].spacing",
            ErrorKind::Conflict,
            "too coarse",
        ),
        (
            scene_text(
                "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [4, 4]\n\n[[body]]\nshape = \"disk\"\ncentre = [2.0, 2.0]\nradius = 0.5\ncount = [4, 4]",
                "",
            ),
            "body[1]",
            ErrorKind::Conflict,
            "body[0] and body[1] overlap",
        ),
        (
            scene_text(
                "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [4, 4]\n\n[body.material]\nyoung = -1.0\ndensity = 1.0",
                "",
            ),
            "body[0].material.young",
            ErrorKind::Value,
            "young = -1",
        ),
        (
            scene_text(
                "[[body]]\nmin = [1.0, 1.0]\nmax = [2.0, 2.0]\ncount = [4, 4]\n\n[body.initial_velocity]\nkind = \"linear\"\nvalue = [0.0, 0.0]\norigin = [0.0, 0.0]\ngradient = [[1.0, 0.0]]",
                "",
            ),
            "body[0].initial_velocity.gradient",
            ErrorKind::Value,
            "needs 2 rows",
        ),
    ];
    for (text, field, kind, message) in cases {
        let (f, k, m) = error_of(&text);
        assert_eq!(f, field, "{m}");
        assert_eq!(k, Some(kind), "{m}");
        assert!(m.contains(message), "{field}: `{m}` lacks `{message}`");
    }
}

#[test]
fn a_1d_scene_has_intervals_only() {
    let mut text = Scene::builtin("vibrating-bar-1d").unwrap().to_toml();
    let at = text.find("[[body]]").unwrap();
    text.insert_str(at + "[[body]]\n".len(), "shape = \"disk\"\n");
    let e = Scene::from_toml(&text, "bar.toml").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("body[0].shape"), "{e}");
    assert!(e.message.contains("a 1D scene has intervals only"), "{e}");
    let mut scene = Scene::builtin("vibrating-bar-1d").unwrap();
    scene.initial_velocity = psmpm::scene::InitialVelocity::RigidRotation {
        omega: 1.0,
        centre: vec![0.0, 0.0],
    };
    let e = scene.validate().unwrap_err();
    assert_eq!(e.field, "initial_velocity.kind", "{e}");
    assert!(e.message.contains("needs a 2D scene"), "{e}");
    // With a 1D centre, as a user of a 1D scene writes it: the same reason, not a
    // length error.
    let mut text = Scene::builtin("vibrating-bar-1d").unwrap().to_toml();
    let at = text.find("[[body]]").unwrap();
    text.insert_str(
        at + "[[body]]\n".len(),
        "initial_velocity = { kind = \"rigid-rotation\", omega = 1.0, centre = [1.0] }\n",
    );
    let e = Scene::from_toml(&text, "bar.toml").unwrap_err();
    assert!(
        e.message.contains("a rigid rotation needs a 2D scene"),
        "{e}"
    );
}

/// The rotation warning of a run with a spinning disk of law `disk` next to a block
/// at rest of law `block`.
fn rotation_warnings(disk: &str, block: &str) -> Vec<String> {
    let mut s = scene(
        &format!(
            "[[body]]\nshape = \"disk\"\ncentre = [1.5, 1.5]\nradius = 0.5\ncount = [8, 8]\nmaterial = {{ model = \"{disk}\", young = 1e4, poisson = 0.3, density = 1.0 }}\ninitial_velocity = {{ kind = \"rigid-rotation\", omega = 4.0, centre = [1.5, 1.5] }}\n\n[[body]]\nmin = [3.0, 3.0]\nmax = [3.5, 3.5]\ncount = [2, 2]\nmaterial = {{ model = \"{block}\", young = 1e4, poisson = 0.3, density = 1.0 }}"
        ),
        "",
    );
    s.time.t_end = 0.03;
    let summary = simulation::run(&s, &mut |_| {}).unwrap();
    assert!(summary.failure.is_none(), "{:?}", summary.failure);
    assert!(summary.max_rotation > 0.1, "{}", summary.max_rotation);
    // The disk's 8 × 8 lattice is also below 3 particles per triangle (2.95), and
    // the block's 2 × 2 about one per triangle under it: the sampling warnings.
    summary
        .warnings
        .into_iter()
        .filter(|w| !w.contains(" sampled by "))
        .collect()
}

#[test]
fn the_rotation_warning_concerns_the_bodies_of_the_papers_law_only() {
    let warned = rotation_warnings("linear-elastic", "corotational");
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(warned[0].contains("not objective"), "{warned:?}");
    assert!(rotation_warnings("corotational", "linear-elastic").is_empty());
}

#[test]
fn scenes_with_shaped_bodies_and_own_materials_round_trip() {
    let text = scene_text(
        &format!(
            "[[body]]\nshape = \"polygon\"\noutline = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]\nholes = [[[1.7, 1.2], [1.9, 1.2], [1.9, 1.4]]]\nspacing = [0.1, 0.1]\nmaterial = {{ young = 2e4, density = 3.0 }}\n\n[[body]]\nshape = \"disk\"\ncentre = [3.0, 3.0]\nradius = 0.5\ncount = [8, 8]\njitter = 0.2\nmaterial = {{ model = \"neo-hookean\", young = 1e3, poisson = 0.2, density = 1.0 }}\ninitial_velocity = {{ kind = \"rigid-rotation\", omega = 1.0, centre = [3.0, 3.0] }}\n\n[[body]]\nshape = \"gmsh\"\nfile = \"{}\"\nsurface = 10\nmaterial = {{ young = 5e3, density = 1.0 }}",
            two_surfaces()
        ),
        "",
    )
    .replace("[material]\nyoung = 1e4\npoisson = 0.3\ndensity = 1.0\n", "");
    let scene = Scene::from_toml(&text, "shapes.toml").unwrap();
    // Without [material], the first body's is the scene's (unused) default.
    assert_eq!(scene.material, scene.bodies[0].material.unwrap());
    let back = Scene::from_toml(&scene.to_toml(), "back.toml").unwrap();
    assert_eq!(back, scene);
    let l = particle_lattice(&scene).unwrap();
    assert_eq!(l.body_sizes.len(), 3);
    assert_eq!(l.body_sizes[2], 6);
}

/// Placing a polygon body's particles (and checking the other bodies against it)
/// tests particles against corners: a detailed outline over a fine lattice is
/// refused before any work, naming the outline, the counts and the limit.
#[test]
fn a_polygon_body_too_costly_to_fill_is_refused_before_any_work() {
    let corners = |n: usize| -> String {
        let points: Vec<String> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                format!("[{:.6}, {:.6}]", 2.0 + 1.5 * a.cos(), 2.0 + 1.5 * a.sin())
            })
            .collect();
        format!("[{}]", points.join(", "))
    };
    // 20 000 corners × about 2 × 10⁶ cells: 4 × 10¹⁰ tests.
    let text = scene_text(
        &format!(
            "[[body]]\nshape = \"polygon\"\noutline = {}\ncount = [1000, 1000]\n",
            corners(20_000)
        ),
        "",
    );
    let started = std::time::Instant::now();
    let (field, kind, message) = error_of(&text);
    assert_eq!(field, "body[0].outline");
    assert_eq!(kind, Some(ErrorKind::Value));
    assert!(
        message.contains("20000 corners") && message.contains("above the limit of 1e10"),
        "{message}"
    );
    // Refused by counting, not after trying (a generous bound, not a timing claim).
    assert!(started.elapsed().as_secs() < 60);
    // The same outline over a coarse lattice is filled.
    let fine = lattice(&format!(
        "[[body]]\nshape = \"polygon\"\noutline = {}\ncount = [40, 40]\n",
        corners(20_000)
    ));
    assert!(!fine.positions.is_empty());
}
