//! The property suite every basis runs (test builds only): the checks of
//! [`crate::check`] with the tolerances each basis claims ([`Claims`]), on shared
//! families of meshes ([`Family`]), every 2D basis (PL, PS) on every 2D family and
//! every 1D basis (PL 1D, B-spline) on every 1D family.
//!
//! A basis joins by implementing [`Subject`] beside its code: how to build it on a
//! mesh, what it claims, the coefficients reproducing quadratics (degree 2) and its
//! own checks (e.g. exact C¹ across the PS sub-triangle edges), which the suite runs
//! on the same meshes.

use super::*;
use crate::basis::bspline1d::QuadraticBSpline;
use crate::basis::linear::Linear;
use crate::basis::linear1d::Linear1d;
use crate::basis::powell_sabin::PowellSabin;
use crate::basis::BasisError;
use crate::mesh::generators::{self, PolygonDomain};
use crate::mesh::{Mesh1d, MeshError, TriMesh, Vec2};
use nalgebra::Vector1;
use proptest::prelude::*;

/// What a basis claims: the tolerance of each check of [`crate::check`].
///
/// Tolerances of gradients grow with the worst aspect of the pieces (`× max(aspect,
/// 100)`, [`worst_aspect`]): gradients, hence their round-off, grow with it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Claims {
    /// `max |Σ φ − 1|` below this.
    pub partition_of_unity: f64,
    /// `min φ` above minus this.
    pub negative: f64,
    /// `max |Σ X φ − x|` below `linear + linear_per_size ·` the diagonal of the
    /// mesh's bounding box.
    pub linear: f64,
    /// See `linear`.
    pub linear_per_size: f64,
    /// The three bounds above are at least this times [`coordinate_conditioning`]:
    /// non-zero for a basis stored in global coordinates (PL), whose round-off grows
    /// with it.
    pub per_conditioning: f64,
    /// `max |Σ X ⊗ ∇φ − I|` below this `× max(aspect, 100)`.
    pub linear_gradient: f64,
    /// For degree 2: bounds of [`quadratic_precision`], values and gradients (the
    /// latter `× max(aspect, 100)`).
    pub quadratic: Option<(f64, f64)>,
    /// [`gradient_error`] below this.
    pub gradient: f64,
    /// [`Jumps::value`] below this.
    pub value_jump: f64,
    /// Gradients across element boundaries.
    pub continuity: Continuity,
    /// Residual of the Dirichlet constraints along each wall.
    pub dirichlet: f64,
}

/// Smoothness across element boundaries.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Continuity {
    /// Gradients jump: [`Jumps::gradient`] is at least this on every mesh (the check
    /// can fail).
    C0 { gradient_jump_above: f64 },
    /// Gradients are continuous: [`Jumps::gradient`] is below this `× max(aspect,
    /// 100)`.
    C1 { gradient_jump_below: f64 },
}

/// A basis under test.
pub(crate) trait Subject<const D: usize>: Basis<f64, D> + Sized {
    /// The mesh it is built on.
    type Mesh;
    /// Its tolerances.
    const CLAIMS: Claims;
    /// The basis on `mesh`.
    fn build(mesh: Self::Mesh) -> Self;
    /// Checks of this basis only, run on every mesh of the suite.
    fn specific_checks(&self) {}
}

/// A mesh of a family and its walls.
#[derive(Clone)]
pub(crate) struct Family<const D: usize, M> {
    pub mesh: M,
    pub walls: Vec<Wall<D>>,
}

/// Points on a straight piece of boundary carrying `tags` (their constraints apply
/// together), with the directions `n` to constrain and the seed of the random field
/// for each, and whether every constraint must be single-term there.
#[derive(Clone)]
pub(crate) struct Wall<const D: usize> {
    pub tags: Vec<String>,
    pub points: Vec<Point<f64, D>>,
    pub directions: Vec<(Point<f64, D>, u64)>,
    pub single: bool,
}

/// Runs every check of [`crate::check`] on `S` built on the family's mesh, asserts
/// its claims, and runs its specific checks.
pub(crate) fn assert_properties<const D: usize, S: Subject<D>>(family: Family<D, S::Mesh>) {
    let basis = S::build(family.mesh);
    let claims = S::CLAIMS;
    let name = basis.name();
    let roundoff = claims.per_conditioning * coordinate_conditioning(&basis);
    let pu = partition_of_unity(&basis);
    assert!(
        pu < claims.partition_of_unity.max(roundoff),
        "{name}: partition of unity off by {pu:e}"
    );
    let min = min_value(&basis);
    assert!(
        min > -claims.negative.max(roundoff),
        "{name}: negative basis value {min:e}"
    );
    let size = 2.0 * extent(&basis).1;
    let aspect = worst_aspect(&basis).max(100.0);
    let (lp, lp_grad) = linear_precision(&basis);
    assert!(
        lp < (claims.linear + claims.linear_per_size * size).max(roundoff),
        "{name}: linear precision off by {lp:e}"
    );
    assert!(
        lp_grad < claims.linear_gradient * aspect,
        "{name}: linear precision of the gradients off by {lp_grad:e} (aspect {aspect:e})"
    );
    if let Some((value, gradient)) = claims.quadratic {
        let (qp, qp_grad) = quadratic_precision(&basis);
        assert!(
            qp < value && qp_grad < gradient * aspect,
            "{name}: quadratic precision off by {qp:e}, gradients by {qp_grad:e}"
        );
    }
    let fd = gradient_error(&basis);
    assert!(
        fd < claims.gradient,
        "{name}: gradient vs central differences: {fd:e}"
    );
    let jumps = continuity_jumps(&basis);
    assert!(
        (jumps.points > 0 || basis.num_elements() == 1) && jumps.value < claims.value_jump,
        "{name}: {jumps:?}"
    );
    match claims.continuity {
        Continuity::C0 {
            gradient_jump_above,
        } => assert!(
            jumps.points == 0 || jumps.gradient > gradient_jump_above,
            "{name}: C⁰ basis without gradient jumps: {jumps:?}"
        ),
        Continuity::C1 {
            gradient_jump_below,
        } => assert!(
            jumps.gradient < gradient_jump_below * aspect,
            "{name}: C¹ violated: {jumps:?}"
        ),
    }
    for wall in &family.walls {
        for &(n, seed) in &wall.directions {
            let mut constraints = Vec::new();
            for tag in &wall.tags {
                constraints.extend(basis.dirichlet(tag, &n).unwrap());
            }
            assert!(constraints.iter().all(|c| c.direction == n));
            if wall.single {
                assert!(
                    constraints.iter().all(|c| c.is_single()),
                    "{name}: {:?} general constraints",
                    wall.tags
                );
            }
            let r = constrained_residual(&basis, &constraints, &wall.points, seed);
            assert!(
                r < claims.dirichlet,
                "{name}: {:?} {n:?}: residual {r:e}",
                wall.tags
            );
        }
    }
    assert!(matches!(
        basis.dirichlet("no such wall", &first_axis()),
        Err(BasisError::Mesh(MeshError::UnknownTag { .. }))
    ));
    basis.specific_checks();
}

/// Every 2D basis on one mesh.
fn all_2d(family: Family<2, TriMesh>) {
    assert_properties::<2, Linear<f64>>(family.clone());
    assert_properties::<2, PowellSabin<f64>>(family);
}

/// Every 1D basis on one mesh.
fn all_1d(family: Family<1, Mesh1d>) {
    assert_properties::<1, Linear1d<f64>>(family.clone());
    assert_properties::<1, QuadraticBSpline<f64>>(family);
}

/// The walls of the unit square, each with both components and an oblique one, and
/// the corner of `left` and `bottom` constrained together: all single-term (straight
/// walls meeting at right angles).
fn unit_square_walls() -> Vec<Wall<2>> {
    let directions = vec![
        (Vec2::new(1.0, 0.0), 0),
        (Vec2::new(0.0, 1.0), 1),
        (Vec2::new(0.6, 0.8), 2),
    ];
    let segment = |a: (f64, f64), b: (f64, f64), count| {
        points_on_segment(Vec2::new(a.0, a.1), Vec2::new(b.0, b.1), count)
    };
    let mut walls: Vec<Wall<2>> = [
        ("left", (0.0, 0.0), (0.0, 1.0)),
        ("right", (1.0, 0.0), (1.0, 1.0)),
        ("bottom", (0.0, 0.0), (1.0, 0.0)),
        ("top", (0.0, 1.0), (1.0, 1.0)),
    ]
    .into_iter()
    .map(|(tag, a, b)| Wall {
        tags: vec![tag.into()],
        points: segment(a, b, 100),
        directions: directions.clone(),
        single: true,
    })
    .collect();
    let mut corner = segment((0.0, 1.0), (0.0, 0.0), 100);
    corner.extend(segment((0.0, 0.0), (1.0, 0.0), 100));
    walls.push(Wall {
        tags: vec!["left".into(), "bottom".into()],
        points: corner,
        directions: vec![(Vec2::new(1.0, 0.0), 5)],
        single: true,
    });
    walls
}

fn unit_square(mesh: TriMesh) -> Family<2, TriMesh> {
    Family {
        mesh,
        walls: unit_square_walls(),
    }
}

/// The unit square cut into two triangles by hand, sides tagged.
pub(crate) fn two_triangles() -> TriMesh {
    let v = vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ];
    let mut mesh = TriMesh::new(v, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
    mesh.tag_box_sides(0.0, 1.0, 0.0, 1.0);
    mesh
}

/// The unit square with a 10-gon hole of radius 0.2 (edge length 0.15); the hole's
/// corners are reflex, their constraints from both edges single-term.
fn square_with_hole() -> Family<2, TriMesh> {
    let mut domain = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
    let hole: Vec<Vec2> = (0..10)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 10.0;
            Vec2::new(0.5 + 0.2 * a.cos(), 0.5 + 0.2 * a.sin())
        })
        .collect();
    domain.holes.push((hole.clone(), "hole".into()));
    let mut family = unit_square(generators::polygon_mesh(&domain, 0.15).unwrap());
    family.walls.push(Wall {
        tags: vec!["hole".into()],
        points: (0..10)
            .flat_map(|i| points_on_segment(hole[i], hole[(i + 1) % 10], 10))
            .collect(),
        directions: vec![(Vec2::new(1.0, 0.0), 3), (Vec2::new(0.0, 1.0), 3)],
        single: true,
    });
    family
}

/// Walls of a [`polygon`]: tags constrained together, the corners of the path along
/// them, the seed of the random field.
type PolygonWall<'a> = (&'a [&'a str], &'a [(f64, f64)], u64);

/// A polygon with one tag per side (edge length 0.3) and its `walls`, constrained in
/// direction `n`.
fn polygon(
    corners: &[(f64, f64)],
    tags: &[&str],
    n: Vec2,
    walls: &[PolygonWall],
) -> Family<2, TriMesh> {
    let p = |(x, y): (f64, f64)| Vec2::new(x, y);
    let domain = PolygonDomain {
        outer: corners.iter().map(|&c| p(c)).collect(),
        outer_tags: tags.iter().map(|t| t.to_string()).collect(),
        holes: Vec::new(),
    };
    Family {
        mesh: generators::polygon_mesh(&domain, 0.3).unwrap(),
        walls: walls
            .iter()
            .map(|&(tags, path, seed)| Wall {
                tags: tags.iter().map(|t| t.to_string()).collect(),
                points: path
                    .windows(2)
                    .flat_map(|w| points_on_segment(p(w[0]), p(w[1]), 100))
                    .collect(),
                directions: vec![(n, seed)],
                single: false,
            })
            .collect(),
    }
}

/// An L-shape whose two walls at the reflex corner (1, 1) are tagged apart: each
/// alone gives general constraints there.
pub(crate) fn l_shape_two_tags() -> Family<2, TriMesh> {
    let (c, r, d) = ((2.0, 1.0), (1.0, 1.0), (1.0, 2.0));
    polygon(
        &[(0.0, 0.0), (2.0, 0.0), c, r, d, (0.0, 2.0)],
        &["a", "b", "c", "d", "e", "f"],
        Vec2::new(0.6, -0.8),
        &[
            (&["c"], &[c, r], 1),
            (&["d"], &[r, d], 2),
            (&["c", "d"], &[c, r, d], 3),
        ],
    )
}

/// A convex corner at (1, −0.03) turning by 3.4°.
pub(crate) fn nearly_flat_corner() -> Family<2, TriMesh> {
    let (o, p, q) = ((0.0, 0.0), (1.0, -0.03), (2.0, 0.0));
    polygon(
        &[o, p, q, (2.0, 1.0), (0.0, 1.0)],
        &["a", "b", "c", "d", "e"],
        Vec2::new(0.0, 1.0),
        &[
            (&["a"], &[o, p], 1),
            (&["b"], &[p, q], 2),
            (&["a", "b"], &[o, p, q], 3),
        ],
    )
}

fn read_gmsh(name: &str) -> TriMesh {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data");
    crate::mesh::gmsh::read_msh(&data.join(name)).unwrap()
}

/// `square_hole.msh`: the unit square with a hole inscribed in the circle of radius
/// 0.2 about (0.5, 0.5), sampled on its own (polygon) edges.
fn gmsh_square_hole() -> Family<2, TriMesh> {
    let mut family = unit_square(read_gmsh("square_hole.msh"));
    let mesh = &family.mesh;
    let hole = mesh.tag_id("hole").unwrap();
    let points: Vec<Vec2> = mesh
        .edges()
        .iter()
        .filter(|e| e.tag == Some(hole))
        .flat_map(|e| {
            let [a, b] = e.vertices.map(|v| mesh.vertices()[v]);
            points_on_segment(a, b, 5)
        })
        .collect();
    let circle: Vec<Vec2> = (0..=400)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 400.0;
            Vec2::new(0.5 + 0.2 * a.cos(), 0.5 + 0.2 * a.sin())
        })
        .collect();
    assert!(points
        .iter()
        .all(|p| circle.iter().any(|c| (p - c).norm() < 0.05)));
    family.walls.push(Wall {
        tags: vec!["hole".into()],
        points,
        directions: vec![(Vec2::new(1.0, 0.0), 4), (Vec2::new(0.0, 1.0), 4)],
        single: false,
    });
    family
}

/// `lshape.msh`, along both walls meeting at the reflex corner (0.5, 0.5).
fn gmsh_lshape() -> Family<2, TriMesh> {
    let (a, r, b) = (
        Vec2::new(1.0, 0.5),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.5, 1.0),
    );
    let mut points = points_on_segment(a, r, 50);
    points.extend(points_on_segment(r, b, 50));
    Family {
        mesh: read_gmsh("lshape.msh"),
        walls: vec![Wall {
            tags: vec!["wall".into()],
            points,
            directions: vec![(Vec2::new(1.0, 0.0), 5), (Vec2::new(0.0, 1.0), 5)],
            single: true,
        }],
    }
}

/// A random Delaunay mesh of the unit square: its corners and `count` random points.
pub(crate) fn random_points_mesh(seed: u64, count: usize) -> TriMesh {
    let mut rng = SplitMix64(seed);
    let mut points = vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ];
    points.extend(
        (0..count).map(|_| Vec2::new(0.05 + 0.9 * rng.next_f64(), 0.05 + 0.9 * rng.next_f64())),
    );
    let mut mesh = generators::delaunay(&points).unwrap();
    mesh.tag_box_sides(0.0, 1.0, 0.0, 1.0);
    mesh
}

/// A random star-shaped polygon (convex and reflex corners) meshed by the quality
/// mesher, every wall tagged separately and constrained in an oblique direction.
fn star_polygon(seed: u64, corners: usize) -> Family<2, TriMesh> {
    let mut rng = SplitMix64(seed);
    let outer: Vec<Vec2> = (0..corners)
        .map(|k| {
            let a = std::f64::consts::TAU * (k as f64 + 0.3 * rng.next_f64()) / corners as f64;
            let r = 0.5 + 0.5 * rng.next_f64();
            Vec2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    let tags: Vec<String> = (0..corners).map(|k| format!("wall{k}")).collect();
    let domain = PolygonDomain {
        outer_tags: tags.clone(),
        outer: outer.clone(),
        holes: Vec::new(),
    };
    Family {
        mesh: generators::polygon_mesh(&domain, 0.25).unwrap(),
        walls: (0..corners)
            .map(|k| Wall {
                tags: vec![tags[k].clone()],
                points: points_on_segment(outer[k], outer[(k + 1) % corners], 100),
                directions: vec![(Vec2::new(0.6, 0.8), k as u64)],
                single: false,
            })
            .collect(),
    }
}

/// A 1D mesh on `nodes`, both ends constrained.
fn nodes_1d(nodes: Vec<f64>) -> Family<1, Mesh1d> {
    let ends = [
        (*nodes.first().unwrap(), "left", 0),
        (*nodes.last().unwrap(), "right", 1),
    ];
    Family {
        mesh: Mesh1d::new(nodes).unwrap(),
        walls: ends
            .into_iter()
            .map(|(x, tag, seed)| Wall {
                tags: vec![tag.into()],
                points: vec![Vector1::new(x)],
                directions: vec![(Vector1::new(1.0), seed)],
                single: true,
            })
            .collect(),
    }
}

#[test]
fn two_triangles_by_hand() {
    all_2d(unit_square(two_triangles()));
}

#[test]
fn block_grid() {
    all_2d(unit_square(
        generators::block_grid(0.0, 1.0, 0.0, 1.0, 3, 2).unwrap(),
    ));
}

#[test]
fn lattices() {
    for n in [4, 5, 6] {
        all_2d(unit_square(
            generators::lattice_delaunay(n, 0.0, 1.0, 0.0, 1.0).unwrap(),
        ));
    }
}

#[test]
fn polygons() {
    all_2d(square_with_hole());
    all_2d(l_shape_two_tags());
    all_2d(nearly_flat_corner());
}

#[test]
fn gmsh_meshes() {
    all_2d(unit_square(read_gmsh("square.msh")));
    all_2d(gmsh_square_hole());
    all_2d(gmsh_lshape());
}

#[test]
fn uniform_1d() {
    all_1d(nodes_1d(
        Mesh1d::uniform(0.0, 25.0, 8).unwrap().nodes().to_vec(),
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    #[test]
    fn jittered_lattices(seed in 0u64..1_000_000, n in 3usize..8, jitter in 0.0f64..0.45) {
        all_2d(unit_square(generators::jittered_lattice_delaunay(n, n + 1, (0.0, 1.0, 0.0, 1.0), jitter, seed).unwrap()));
    }

    #[test]
    fn random_point_sets(seed in 0u64..1_000_000, count in 8usize..50) {
        all_2d(unit_square(random_points_mesh(seed, count)));
    }

    #[test]
    fn random_star_polygons(seed in 0u64..1_000_000, corners in 5usize..10) {
        all_2d(star_polygon(seed, corners));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, rng_seed: proptest::test_runner::RngSeed::Fixed(20261122), .. ProptestConfig::default() })]

    #[test]
    fn jittered_5x6_lattices(seed in 0u64..1_000_000, jitter in 0.0f64..0.4) {
        all_2d(unit_square(generators::jittered_lattice_delaunay(5, 6, (0.0, 1.0, 0.0, 1.0), jitter, seed).unwrap()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, rng_seed: proptest::test_runner::RngSeed::Fixed(20261122), .. ProptestConfig::default() })]

    #[test]
    fn non_uniform_1d(steps in proptest::collection::vec(0.05f64..1.0, 1..12), start in -5.0f64..5.0) {
        let mut nodes = vec![start];
        for s in &steps {
            nodes.push(nodes.last().unwrap() + s);
        }
        all_1d(nodes_1d(nodes));
    }
}
