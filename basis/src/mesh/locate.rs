//! Point location: which triangle of a [`TriMesh`] contains a point.
//!
//! Two stages. First a visibility walk from a hint triangle (a particle's previous
//! triangle): from the current triangle step across the edge opposite the most
//! negative barycentric coordinate, up to [`MAX_WALK_STEPS`] steps. For a particle
//! that moved a little this finds the answer in a step or two. The walk may stop
//! without an answer: at a boundary edge (a hole or a concave part of the boundary
//! may lie between hint and point), or when it runs out of steps (walks can cycle in
//! non-Delaunay meshes). Then a global search in a uniform bucket grid over the
//! triangles' bounding boxes decides.
//!
//! A point `p` is inside triangle `t` when all its barycentric coordinates are at
//! least `−INSIDE_TOLERANCE`. Barycentric coordinates are relative to the triangle
//! (`λ_k` = signed distance to the opposite edge / height), so this accepts points
//! within about `1e-12` heights of `t`: points on a shared edge or vertex belong to
//! every triangle around it, even after rounding. A point inside no triangle is
//! outside the mesh (`None`); no triangle is returned that does not contain the
//! point in this sense.
//!
//! Everything is deterministic. The global search returns the lowest-numbered
//! triangle containing the point; a successful walk returns the first containing
//! triangle on its path, so for a point on an edge or vertex the answer may depend
//! on the hint (it always contains the point). Locating allocates nothing.

use super::{TriMesh, Vec2};

/// Barycentric tolerance for "inside": `p` is in triangle `t` when every barycentric
/// coordinate is `≥ −INSIDE_TOLERANCE`, i.e. `p` is at most `1e-12` heights of `t`
/// outside it.
pub const INSIDE_TOLERANCE: f64 = 1e-12;

/// Barycentric tolerance of "on an edge or vertex" for
/// [`TriMesh::other_triangles_at`]: `p` lies on the edge opposite vertex `k` when
/// `λ_k ≤ TOUCH_TOLERANCE`, about `1e-9` heights. Well above the round-off of
/// locating a point that lies on an edge in exact arithmetic (a lattice point on a
/// grid diagonal, computed in floating point), and far below any spacing of
/// particles.
pub const TOUCH_TOLERANCE: f64 = 1e-9;

/// Longest walk (in triangles) before falling back to the global search; caps
/// cycling walks in non-Delaunay meshes.
pub const MAX_WALK_STEPS: usize = 64;

/// Finds the triangle containing a point (walk from a hint, then bucket grid).
///
/// Built once per mesh by [`TriMesh::new`]. `Locator::default()` is an empty
/// placeholder without a grid; it still answers correctly, by testing every triangle.
#[derive(Debug, Clone, Default)]
pub struct Locator {
    origin: Vec2,
    cell: Vec2,
    nx: usize,
    ny: usize,
    /// CSR: triangles whose bounding box touches each bucket.
    offsets: Vec<usize>,
    triangles: Vec<usize>,
}

impl Locator {
    /// Builds the bucket grid for `mesh`: about as many buckets as triangles (at most
    /// 4096 along a side), shaped like the mesh's bounding box; each bucket lists
    /// the triangles whose bounding box overlaps it, a few per bucket for
    /// well-shaped triangles.
    pub fn new(mesh: &TriMesh) -> Self {
        let (lo, hi) = mesh.bounding_box();
        let n = mesh.num_triangles().max(1) as f64;
        let extent = (hi - lo).map(|v| v.max(f64::MIN_POSITIVE));
        let aspect = extent.x / extent.y;
        let nx = ((n * aspect).sqrt().ceil() as usize).clamp(1, 4096);
        let ny = ((n / aspect).sqrt().ceil() as usize).clamp(1, 4096);
        let cell = Vec2::new(extent.x / nx as f64, extent.y / ny as f64);
        let mut locator = Locator {
            origin: lo,
            cell,
            nx,
            ny,
            offsets: Vec::new(),
            triangles: Vec::new(),
        };
        let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); nx * ny];
        for t in 0..mesh.num_triangles() {
            let p = mesh.triangle_points(t);
            let (a, b) = super::bounding_box(&p);
            let (i0, j0) = locator.bucket(a);
            let (i1, j1) = locator.bucket(b);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    buckets[j * nx + i].push(t);
                }
            }
        }
        locator.offsets.push(0);
        for b in buckets {
            locator.triangles.extend(b);
            locator.offsets.push(locator.triangles.len());
        }
        locator
    }

    /// Bucket indices of a point, clamped to the grid (points outside the bounding
    /// box go to an edge bucket, where no triangle will contain them).
    fn bucket(&self, p: Vec2) -> (usize, usize) {
        let f = |v: f64, o: f64, c: f64, n: usize| -> usize {
            let k = ((v - o) / c).floor();
            if k.is_nan() || k < 0.0 {
                0
            } else {
                (k as usize).min(n - 1)
            }
        };
        (
            f(p.x, self.origin.x, self.cell.x, self.nx),
            f(p.y, self.origin.y, self.cell.y, self.ny),
        )
    }

    /// The triangle containing `p`, or `None` when `p` is outside the mesh (or not
    /// finite). `hint` (ignored when out of range) starts the walk; without it, or
    /// when the walk fails, the bucket grid decides. `mesh` must be the mesh the
    /// locator was built for.
    pub fn locate(&self, mesh: &TriMesh, p: Vec2, hint: Option<usize>) -> Option<usize> {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return None;
        }
        if let Some(t) = hint.filter(|&t| t < mesh.num_triangles()) {
            if let Some(found) = walk(mesh, p, t) {
                return Some(found);
            }
        }
        if self.offsets.is_empty() {
            // The empty placeholder: test every triangle.
            return (0..mesh.num_triangles()).find(|&t| contains(mesh, t, p));
        }
        let (lo, hi) = (
            self.origin,
            self.origin + Vec2::new(self.cell.x * self.nx as f64, self.cell.y * self.ny as f64),
        );
        let margin = 1e-9 * (hi - lo).norm();
        if p.x < lo.x - margin || p.y < lo.y - margin || p.x > hi.x + margin || p.y > hi.y + margin
        {
            return None;
        }
        let (i, j) = self.bucket(p);
        let b = j * self.nx + i;
        // Bucket lists are in increasing triangle order: the lowest containing one wins.
        self.triangles[self.offsets[b]..self.offsets[b + 1]]
            .iter()
            .copied()
            .find(|&t| contains(mesh, t, p))
    }
}

/// Whether `p` is in triangle `t` up to [`INSIDE_TOLERANCE`].
fn contains(mesh: &TriMesh, t: usize, p: Vec2) -> bool {
    mesh.barycentric(t, p)
        .iter()
        .all(|&l| l >= -INSIDE_TOLERANCE)
}

/// Visibility walk from `start` towards `p`: `Some(t)` when a triangle containing
/// `p` is reached within [`MAX_WALK_STEPS`], `None` when the walk leaves the mesh or
/// runs out of steps.
fn walk(mesh: &TriMesh, p: Vec2, start: usize) -> Option<usize> {
    let mut t = start;
    for _ in 0..MAX_WALK_STEPS {
        let l = mesh.barycentric(t, p);
        let mut k_min = 0;
        for k in 1..3 {
            if l[k] < l[k_min] {
                k_min = k;
            }
        }
        if l[k_min] >= -INSIDE_TOLERANCE {
            return Some(t);
        }
        // Local edge k joins vertices k and k + 1: the edge opposite vertex k_min is k_min + 1.
        t = mesh.neighbours()[t][(k_min + 1) % 3]?;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators::{self, PolygonDomain};
    use crate::mesh::gmsh;
    use crate::rng::SplitMix64;

    /// Locates, with every kind of hint, random interior points of each triangle, edge
    /// midpoints, vertices, points 1e-9 outside each boundary edge and `outside`.
    /// In a convex Delaunay mesh (`delaunay_convex`) the walk alone must succeed.
    fn check_mesh(m: &TriMesh, outside: &[Vec2], delaunay_convex: bool) {
        let mut rng = SplitMix64(42);
        let n = m.num_triangles();
        let hints = [None, Some(0), Some(n / 2), Some(n - 1), Some(n + 5)];
        let placeholder = Locator::default();
        for t in 0..n {
            let [a, b, c] = m.triangle_points(t);
            let (u, v) = (rng.next_f64(), rng.next_f64());
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let p = a + (b - a) * u + (c - a) * v;
            for hint in hints.into_iter().chain([Some(t)]) {
                assert_eq!(m.locate(p, hint), Some(t), "{p:?} from {hint:?}");
            }
            assert_eq!(placeholder.locate(m, p, None), Some(t));
            if delaunay_convex {
                for start in [0, n / 2, n - 1] {
                    assert_eq!(walk(m, p, start), Some(t), "walk from {start} to {p:?}");
                }
            }
        }
        // On an edge: one of its triangles, the lowest without a hint.
        for e in m.edges() {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            let p = (a + b) * 0.5;
            let (t0, t1) = e.triangles;
            let lowest = t1.map_or(t0, |t1| t0.min(t1));
            assert_eq!(m.locate(p, None), Some(lowest), "edge midpoint {p:?}");
            for hint in hints {
                let found = m.locate(p, hint).expect("edge midpoint inside");
                assert!(
                    found == t0 || Some(found) == t1,
                    "{p:?} from {hint:?}: {found}"
                );
            }
        }
        // On a vertex: one of its triangles, the lowest without a hint.
        for (v, &p) in m.vertices().iter().enumerate() {
            let fan = m.vertex_triangles(v);
            let lowest = *fan.iter().min().unwrap();
            assert_eq!(m.locate(p, None), Some(lowest), "vertex {v}");
            for hint in hints {
                let found = m.locate(p, hint).expect("vertex inside");
                assert!(fan.contains(&found), "vertex {v} from {hint:?}: {found}");
            }
        }
        // Just outside each boundary edge (to the right of a → b, counter-clockwise inside).
        for e in m.edges().iter().filter(|e| e.is_boundary()) {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            let d = (b - a).normalize();
            let p = (a + b) * 0.5 + Vec2::new(d.y, -d.x) * 1e-9;
            for hint in hints.into_iter().chain([Some(e.triangles.0)]) {
                assert_eq!(m.locate(p, hint), None, "{p:?} outside, from {hint:?}");
            }
            assert_eq!(placeholder.locate(m, p, None), None);
        }
        for &p in outside {
            for hint in hints {
                assert_eq!(m.locate(p, hint), None, "{p:?} should be outside");
            }
        }
    }

    const UNIT_BOX_OUTSIDE: [Vec2; 7] = [
        Vec2::new(-1e-9, 0.5),
        Vec2::new(1.0 + 1e-9, 0.5),
        Vec2::new(0.5, -1e-9),
        Vec2::new(0.3, 1.0 + 1e-9),
        Vec2::new(5.0, 5.0),
        Vec2::new(f64::NAN, 0.5),
        Vec2::new(0.5, f64::INFINITY),
    ];

    /// Every triangle whose closure holds `p` up to the touch tolerance, by brute force.
    fn closure_triangles(mesh: &TriMesh, p: Vec2) -> Vec<usize> {
        (0..mesh.num_triangles())
            .filter(|&t| {
                mesh.barycentric(t, p)
                    .iter()
                    .all(|&l| l >= -TOUCH_TOLERANCE)
            })
            .collect()
    }

    #[test]
    fn a_point_on_an_edge_or_vertex_touches_every_triangle_around_it() {
        // h = 1/3: lattice points on the diagonals and the block corners are on
        // edges and vertices only up to round-off.
        let mesh = generators::block_grid(0.0, 4.0, 0.0, 4.0, 12, 12).unwrap();
        let h = 4.0 / 12.0;
        let mut seen = [0usize; 4];
        for i in 0..36 {
            for j in 0..36 {
                // Per-block lattices of 3 × 3 (on the diagonals and the centres) and
                // points on the block edges and corners.
                for p in [
                    Vec2::new(
                        1.0 + (i as f64 + 0.5) * h / 3.0,
                        0.5 + (j as f64 + 0.5) * h / 3.0,
                    ),
                    Vec2::new((i as f64) * h / 3.0, (j as f64) * h / 3.0),
                ] {
                    if p.x > 4.0 || p.y > 4.0 {
                        continue;
                    }
                    let t = mesh.locate(p, None).unwrap();
                    let mut all = vec![t];
                    mesh.other_triangles_at(t, p, &mut |n| all.push(n));
                    all.sort_unstable();
                    assert_eq!(all, closure_triangles(&mesh, p), "at {p:?}");
                    seen[(all.len() - 1).min(3)] += 1;
                }
            }
        }
        // Interior points, edge points, vertex points all occurred.
        assert!(seen[0] > 0 && seen[1] > 0 && seen[3] > 0, "{seen:?}");
    }

    #[test]
    fn a_point_on_a_node_touches_both_intervals() {
        let mesh = crate::mesh::Mesh1d::uniform(0.0, 1.0, 10).unwrap();
        for (x, other) in [
            (0.3, Some(2)),
            (0.35, None),
            (0.0, None),
            (1.0, None),
            (0.7 + 1e-13, Some(6)),
        ] {
            let e = mesh.locate(x, None).unwrap();
            assert_eq!(mesh.other_element_at(e, x), other, "at {x}");
        }
    }

    #[test]
    fn locates_on_every_generator() {
        check_mesh(
            // Blocks taller than wide: not Delaunay.
            &generators::block_grid(0.0, 1.0, 0.0, 1.0, 4, 3).unwrap(),
            &UNIT_BOX_OUTSIDE,
            false,
        );
        check_mesh(
            &generators::block_delaunay(0.0, 1.0, 0.0, 1.0, 8, 2).unwrap(),
            &UNIT_BOX_OUTSIDE,
            true,
        );
        for d in [generators::Diagonal::Left, generators::Diagonal::Right] {
            check_mesh(
                &generators::two_triangle_grid(0.0, 1.0, 0.0, 1.0, 3, 3, d).unwrap(),
                &UNIT_BOX_OUTSIDE,
                true,
            );
        }
        check_mesh(
            &generators::lattice_delaunay(7, 0.0, 1.0, 0.0, 1.0).unwrap(),
            &UNIT_BOX_OUTSIDE,
            true,
        );
        check_mesh(
            &generators::jittered_lattice_delaunay(8, 6, (0.0, 1.0, 0.0, 1.0), 0.3, 9).unwrap(),
            &UNIT_BOX_OUTSIDE,
            true,
        );
        let mut rng = SplitMix64(1);
        let points: Vec<Vec2> = (0..200)
            .map(|_| Vec2::new(rng.next_f64(), rng.next_f64()))
            .collect();
        check_mesh(
            &generators::delaunay(&points).unwrap(),
            &[Vec2::new(2.0, 0.5)],
            true,
        );
    }

    #[test]
    fn locates_in_polygons_with_holes_and_reflex_corners() {
        let mut domain = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        domain.holes.push((
            vec![
                Vec2::new(0.4, 0.4),
                Vec2::new(0.6, 0.4),
                Vec2::new(0.6, 0.6),
                Vec2::new(0.4, 0.6),
            ],
            "hole".into(),
        ));
        let mut outside = UNIT_BOX_OUTSIDE.to_vec();
        outside.extend([Vec2::new(0.5, 0.5), Vec2::new(0.4 + 1e-9, 0.5)]);
        check_mesh(
            &generators::polygon_mesh(&domain, 0.1).unwrap(),
            &outside,
            false,
        );
        // A U shape: walks from one arm to the other must go round or fall back.
        let u = PolygonDomain {
            outer: [
                (0.0, 0.0),
                (3.0, 0.0),
                (3.0, 3.0),
                (2.0, 3.0),
                (2.0, 1.0),
                (1.0, 1.0),
                (1.0, 3.0),
                (0.0, 3.0),
            ]
            .map(|(x, y)| Vec2::new(x, y))
            .to_vec(),
            outer_tags: vec!["wall".into(); 8],
            holes: Vec::new(),
        };
        let m = generators::polygon_mesh(&u, 0.25).unwrap();
        check_mesh(
            &m,
            &[Vec2::new(1.5, 2.0), Vec2::new(1.5, 1.0 + 1e-9)],
            false,
        );
        let left_arm = m.locate(Vec2::new(0.5, 2.9), None).unwrap();
        let right = m.locate(Vec2::new(2.5, 2.9), None);
        assert_eq!(m.locate(Vec2::new(2.5, 2.9), Some(left_arm)), right);
    }

    #[test]
    fn locates_on_the_gmsh_meshes() {
        let data = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data"));
        let read = |name: &str| gmsh::read_msh(&data.join(name)).unwrap();
        check_mesh(&read("square.msh"), &UNIT_BOX_OUTSIDE, false);
        let mut outside = UNIT_BOX_OUTSIDE.to_vec();
        outside.extend([
            Vec2::new(0.5, 0.5),
            Vec2::new(0.5, 0.69),
            Vec2::new(0.31, 0.5),
        ]);
        check_mesh(&read("square_hole.msh"), &outside, false);
        let mut outside = UNIT_BOX_OUTSIDE.to_vec();
        outside.extend([Vec2::new(0.75, 0.75), Vec2::new(0.5 + 1e-9, 0.5 + 1e-9)]);
        check_mesh(&read("lshape.msh"), &outside, false);
    }

    #[test]
    fn long_walks_fall_back_to_the_global_search() {
        // A strip of 2 × 300 triangles: from triangle 0 the far end is beyond the step cap.
        let m = generators::two_triangle_grid(
            0.0,
            300.0,
            0.0,
            1.0,
            300,
            1,
            generators::Diagonal::Right,
        )
        .unwrap();
        let p = Vec2::new(299.7, 0.2);
        let expected = m.locate(p, None).unwrap();
        assert!(walk(&m, p, 0).is_none());
        assert_eq!(m.locate(p, Some(0)), Some(expected));
        assert_eq!(walk(&m, p, expected - 4), Some(expected));
    }
}
