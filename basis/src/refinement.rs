//! The Powell–Sabin refinement of a triangulation (paper §3, thesis §3.5.1,
//! `ps-splines.md` §1).
//!
//! Every main triangle `t = (V_0, V_1, V_2)` gets a split point `Z_t` (the incentre
//! by default), every edge an edge point `R` (where the segment `Z_t Z_t'` between
//! the split points of its two triangles crosses it; the midpoint on the boundary),
//! and `t` is cut into six sub-triangles `(V_k, R_k, Z)`. The C¹ continuity of PS
//! splines across main edges rests on `Z_t, R, Z_t'` being collinear.
//!
//! Sub-triangle numbering, counter-clockwise around `Z`, with local edge `m` joining
//! `V_m` and `V_{m+1}`: `2m = (V_m, R_m, Z)`, `2m + 1 = (R_m, V_{m+1}, Z)`.

use crate::basis::BasisError;
use crate::mesh::{TriMesh, Vec2};

/// Where the split point `Z` of each triangle is placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SplitPoint {
    /// The incentre: always valid (the segment between the incentres of two
    /// neighbours crosses their common edge strictly inside it).
    #[default]
    Incentre,
    /// The centroid: valid on the seeds' block grids but not on every mesh.
    Centroid,
}

/// Relative tolerance for an edge point to count as strictly inside its edge.
const EDGE_POINT_MARGIN: f64 = 1e-9;

/// The Powell–Sabin refinement of a [`TriMesh`].
#[derive(Debug, Clone)]
pub struct Refinement {
    /// Split point `Z_t` per triangle.
    pub split: Vec<Vec2>,
    /// Barycentric coordinates `(a, b, c)` of `Z_t` in its triangle.
    pub split_bary: Vec<[f64; 3]>,
    /// Edge point `R_e` per global edge.
    pub edge_point: Vec<Vec2>,
    /// Weight of `edges[e].vertices[0]` in `R_e = λ V_a + (1 − λ) V_b`.
    pub edge_lambda: Vec<f64>,
}

impl Refinement {
    /// Refines `mesh` with split points of the given kind.
    ///
    /// Errors with [`BasisError::InvalidSplitPoint`] when a segment between the split
    /// points of two neighbours misses their common edge (possible for centroids),
    /// and with [`BasisError::SliverSplit`] when incentres do that or cross it next
    /// to an end (a sliver triangle).
    pub fn new(mesh: &TriMesh, kind: SplitPoint) -> Result<Self, BasisError> {
        let mut split = Vec::with_capacity(mesh.num_triangles());
        let mut split_bary = Vec::with_capacity(mesh.num_triangles());
        for t in 0..mesh.num_triangles() {
            let [p0, p1, p2] = mesh.triangle_points(t);
            let w = match kind {
                SplitPoint::Centroid => [1.0, 1.0, 1.0],
                // Incentre: weights are the lengths of the opposite sides.
                SplitPoint::Incentre => [(p2 - p1).norm(), (p0 - p2).norm(), (p1 - p0).norm()],
            };
            let s = w[0] + w[1] + w[2];
            let bary = [w[0] / s, w[1] / s, w[2] / s];
            split.push(p0 * bary[0] + p1 * bary[1] + p2 * bary[2]);
            split_bary.push(bary);
        }
        let vertices = mesh.vertices();
        let mut edge_point = Vec::with_capacity(mesh.edges().len());
        let mut edge_lambda = Vec::with_capacity(mesh.edges().len());
        for edge in mesh.edges() {
            let [a, b] = edge.vertices;
            let (va, vb) = (vertices[a], vertices[b]);
            let s = match edge.triangles {
                (_, None) => 0.5,
                (t1, Some(t2)) => {
                    // V_a + s (V_b − V_a) on the line through Z_t1 and Z_t2.
                    let d = split[t2] - split[t1];
                    let cross = |u: Vec2, v: Vec2| u.x * v.y - u.y * v.x;
                    let s = cross(split[t1] - va, d) / cross(vb - va, d);
                    if !(s > EDGE_POINT_MARGIN && s < 1.0 - EDGE_POINT_MARGIN && s.is_finite()) {
                        let (t1, t2) = (t1.min(t2), t1.max(t2));
                        return Err(match kind {
                            SplitPoint::Centroid => BasisError::InvalidSplitPoint { t1, t2 },
                            _ => BasisError::SliverSplit { t1, t2 },
                        });
                    }
                    s
                }
            };
            edge_point.push(va + (vb - va) * s);
            edge_lambda.push(1.0 - s);
        }
        Ok(Refinement {
            split,
            split_bary,
            edge_point,
            edge_lambda,
        })
    }

    /// `(λ_m, λ_{m+1})` with `R_m = λ_m V_m + λ_{m+1} V_{m+1}` for local edge `m` of `t`.
    pub fn local_edge_lambdas(&self, mesh: &TriMesh, t: usize, m: usize) -> (f64, f64) {
        let e = mesh.triangle_edges()[t][m];
        let lambda = self.edge_lambda[e];
        if mesh.edges()[e].vertices[0] == mesh.triangles()[t][m] {
            (lambda, 1.0 - lambda)
        } else {
            (1.0 - lambda, lambda)
        }
    }

    /// Edge point of local edge `m` of triangle `t`.
    pub fn local_edge_point(&self, mesh: &TriMesh, t: usize, m: usize) -> Vec2 {
        self.edge_point[mesh.triangle_edges()[t][m]]
    }

    /// The six sub-triangles of `t`, counter-clockwise, numbered as in the module docs.
    pub fn sub_triangles(&self, mesh: &TriMesh, t: usize) -> [[Vec2; 3]; 6] {
        let v = mesh.triangle_points(t);
        let z = self.split[t];
        let mut out = [[Vec2::zeros(); 3]; 6];
        for m in 0..3 {
            let r = self.local_edge_point(mesh, t, m);
            out[2 * m] = [v[m], r, z];
            out[2 * m + 1] = [r, v[(m + 1) % 3], z];
        }
        out
    }

    /// The sub-triangle of `t` containing the point with barycentric coordinates
    /// `lambda` in `t`, given the split point's `z_bary = (a, b, c)` and the local edge
    /// points' `r_lambda[m] = λ_m` (weight of `V_m` in `R_m`). Three sign tests, no
    /// division, no search over the six:
    ///
    /// - side of the line `Z V_k`: `D_k = z_{k+2} λ_{k+1} − z_{k+1} λ_{k+2}` (the
    ///   determinant `det[z; e_k; λ]`, positive on the `V_{k+1}` side);
    /// - `x` lies in the wedge `(V_m, V_{m+1}, Z)` iff `D_m ≥ 0` and `D_{m+1} ≤ 0`;
    /// - side of the line `Z R_m` with `R_m = λ_m V_m + (1 − λ_m) V_{m+1}`:
    ///   `det[z; r; λ] = λ_m D_m + (1 − λ_m) D_{m+1}`, `≤ 0` on the `V_m` side
    ///   (sub-triangle `2m`), `> 0` on the `V_{m+1}` side (`2m + 1`).
    ///
    /// Points on a sub-edge go to either side (the spline is C¹ there); points
    /// slightly outside `t` (round-off) go to a sub-triangle next to them.
    #[inline]
    pub fn sub_triangle_of<T: crate::Real>(
        lambda: [T; 3],
        z_bary: [T; 3],
        r_lambda: [T; 3],
    ) -> usize {
        let side = |k: usize| {
            let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
            z_bary[k2] * lambda[k1] - z_bary[k1] * lambda[k2]
        };
        let d = [side(0), side(1), side(2)];
        let zero = T::zero();
        let m = if d[0] >= zero && d[1] < zero {
            0
        } else if d[1] >= zero && d[2] < zero {
            1
        } else {
            2
        };
        let n = (m + 1) % 3;
        if r_lambda[m] * d[m] + (T::one() - r_lambda[m]) * d[n] <= zero {
            2 * m
        } else {
            2 * m + 1
        }
    }

    /// The sub-triangle of `t` containing `x` and the barycentric coordinates of `x`
    /// in it (with respect to its corners as listed by
    /// [`sub_triangles`](Refinement::sub_triangles)).
    pub fn locate_sub_triangle(&self, mesh: &TriMesh, t: usize, x: Vec2) -> (usize, [f64; 3]) {
        let lambda = mesh.barycentric(t, x);
        let r_lambda = [0, 1, 2].map(|m| self.local_edge_lambdas(mesh, t, m).0);
        let s = Self::sub_triangle_of(lambda, self.split_bary[t], r_lambda);
        let [a, b, c] = self.sub_triangles(mesh, t)[s];
        (s, crate::mesh::barycentric(a, b, c, x))
    }

    /// The PS points of vertex `v` (`ps-splines.md` §2): `V` itself, the midpoints of
    /// `V R_e` for every incident edge `e` and of `V Z_t` for every incident triangle
    /// `t` (triangles first, in [`TriMesh::vertex_triangles`] order, then edges by id).
    pub fn ps_points(&self, mesh: &TriMesh, v: usize) -> Vec<Vec2> {
        let p = mesh.vertices()[v];
        self.ps_offsets(mesh, v)
            .into_iter()
            .map(|d| p + d)
            .collect()
    }

    /// The PS points of vertex `v` relative to it, `P − V`: `0`, `(R_e − V)/2` and
    /// `(Z_t − V)/2`, in the order of [`ps_points`](Refinement::ps_points).
    ///
    /// Control triangles are built from these: relative to `V` the round-off is that
    /// of the small offsets, not of the coordinates, and they are exactly the vectors
    /// `½ (R − V)`, `½ (Z − V)` of the Bézier ordinates (`bezier::hermite_ordinates`),
    /// so an ordinate is the control triangle's barycentric coordinate of the very
    /// point that the triangle was built to contain.
    pub fn ps_offsets(&self, mesh: &TriMesh, v: usize) -> Vec<Vec2> {
        let p = mesh.vertices()[v];
        let mut out = vec![Vec2::zeros()];
        let mut edges: Vec<usize> = Vec::new();
        for &t in mesh.vertex_triangles(v) {
            out.push((self.split[t] - p) * 0.5);
            let tri = mesh.triangles()[t];
            for m in 0..3 {
                if tri[m] == v || tri[(m + 1) % 3] == v {
                    edges.push(mesh.triangle_edges()[t][m]);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        out.extend(edges.iter().map(|&e| (self.edge_point[e] - p) * 0.5));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{barycentric, generators, signed_area};
    use crate::rng::SplitMix64;
    use proptest::prelude::*;

    /// A random Delaunay mesh of the unit square: its corners plus `count` random
    /// interior points.
    fn random_points_mesh(seed: u64, count: usize) -> TriMesh {
        let mut rng = SplitMix64(seed);
        let mut points = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        points.extend(
            (0..count)
                .map(|_| Vec2::new(0.02 + 0.96 * rng.next_f64(), 0.02 + 0.96 * rng.next_f64())),
        );
        let mut mesh = generators::delaunay(&points).unwrap();
        mesh.tag_box_sides(0.0, 1.0, 0.0, 1.0);
        mesh
    }

    /// The geometric facts of the refinement: split points inside with consistent
    /// barycentric coordinates, edge points on their edges and on the `Z_t Z_t'`
    /// segments (midpoints on the boundary), six counter-clockwise sub-triangles
    /// tiling each triangle, PS points counted right.
    fn assert_refinement(mesh: &TriMesh, kind: SplitPoint) -> Refinement {
        let r = Refinement::new(mesh, kind).unwrap();
        let h = (mesh.bounding_box().1 - mesh.bounding_box().0).norm();
        for t in 0..mesh.num_triangles() {
            let v = mesh.triangle_points(t);
            let z = r.split_bary[t];
            assert!(z.iter().all(|&w| w > 0.0) && (z.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert!((v[0] * z[0] + v[1] * z[1] + v[2] * z[2] - r.split[t]).norm() < 1e-15 * h);
            if kind == SplitPoint::Incentre {
                // Equidistant from the three sides.
                let dist = |m: usize| {
                    let (a, b) = (v[m], v[(m + 1) % 3]);
                    2.0 * signed_area(a, b, r.split[t]) / (b - a).norm()
                };
                assert!((dist(0) - dist(1)).abs() < 1e-13 * h);
                assert!((dist(1) - dist(2)).abs() < 1e-13 * h);
            }
            let subs = r.sub_triangles(mesh, t);
            let total: f64 = subs.iter().map(|s| signed_area(s[0], s[1], s[2])).sum();
            assert!(subs.iter().all(|s| signed_area(s[0], s[1], s[2]) > 0.0));
            // Round-off of the coordinates (not of the area: slivers occur).
            let diam = (v[1] - v[0])
                .norm()
                .max((v[2] - v[1]).norm())
                .max((v[0] - v[2]).norm());
            assert!((total - mesh.area(t)).abs() < 1e-14 * diam * (diam + h));
            for m in 0..3 {
                let (lm, ln) = r.local_edge_lambdas(mesh, t, m);
                assert!(lm > 0.0 && ln > 0.0 && (lm + ln - 1.0).abs() < 1e-15);
                let p = r.local_edge_point(mesh, t, m);
                assert!((v[m] * lm + v[(m + 1) % 3] * ln - p).norm() < 1e-14 * h);
                match mesh.neighbours()[t][m] {
                    None => assert!((lm - 0.5).abs() < 1e-15),
                    Some(u) => {
                        let (z1, z2) = (r.split[t], r.split[u]);
                        assert!(signed_area(z1, z2, p).abs() < 1e-14 * (z2 - z1).norm() * h);
                        // The neighbour sees the same point with the weights swapped.
                        let m2 = (0..3)
                            .find(|&k| mesh.neighbours()[u][k] == Some(t))
                            .unwrap();
                        let (a, b) = r.local_edge_lambdas(mesh, u, m2);
                        assert!((a - ln).abs() < 1e-15 && (b - lm).abs() < 1e-15);
                    }
                }
            }
        }
        for v in 0..mesh.num_vertices() {
            let tris = mesh.vertex_triangles(v).len();
            let boundary = mesh
                .edges()
                .iter()
                .any(|e| e.is_boundary() && e.vertices.contains(&v));
            let edges = tris + usize::from(boundary);
            assert_eq!(r.ps_points(mesh, v).len(), 1 + tris + edges, "vertex {v}");
        }
        r
    }

    /// [`Refinement::locate_sub_triangle`] against the brute-force search over the
    /// six sub-triangles, at random points and at the special points `V_k`, `R`, `Z`.
    fn assert_sub_triangle_location(mesh: &TriMesh, r: &Refinement, seed: u64) {
        let mut rng = SplitMix64(seed);
        for t in 0..mesh.num_triangles() {
            let [p0, p1, p2] = mesh.triangle_points(t);
            let subs = r.sub_triangles(mesh, t);
            let mut points: Vec<Vec2> = (0..40)
                .map(|_| {
                    let (u, v) = (rng.next_f64(), rng.next_f64());
                    let (u, v) = if u + v > 1.0 {
                        (1.0 - u, 1.0 - v)
                    } else {
                        (u, v)
                    };
                    p0 * (1.0 - u - v) + p1 * u + p2 * v
                })
                .collect();
            points.extend([p0, p1, p2, r.split[t]]);
            points.extend((0..3).map(|m| r.local_edge_point(mesh, t, m)));
            // Round-off of barycentric coordinates in a sub-triangle: that of the
            // coordinates divided by its smallest height (slivers occur).
            let tol = |k: usize, x: Vec2| {
                let [a, b, c] = subs[k];
                let diam = (b - a).norm().max((c - b).norm()).max((a - c).norm());
                64.0 * f64::EPSILON * (x.norm() + diam) * diam / (2.0 * signed_area(a, b, c))
            };
            for x in points {
                let (s, tau) = r.locate_sub_triangle(mesh, t, x);
                assert!(
                    tau.iter().all(|&l| l > -tol(s, x)),
                    "t {t} sub {s} tau {tau:?}"
                );
                let [a, b, c] = subs[s];
                let diam = (b - a).norm().max((c - b).norm()).max((a - c).norm());
                assert!((a * tau[0] + b * tau[1] + c * tau[2] - x).norm() < tol(s, x) * diam);
                // Brute force: the containing sub-triangles (more than one on a sub-edge).
                let inside: Vec<usize> = (0..6)
                    .filter(|&k| {
                        let [a, b, c] = subs[k];
                        barycentric(a, b, c, x).iter().all(|&l| l > -tol(k, x))
                    })
                    .collect();
                assert!(inside.contains(&s), "t {t}: {s} not in {inside:?}");
            }
        }
    }

    #[test]
    fn block_grid_refinement_with_both_split_points() {
        let mesh = generators::block_grid(0.0, 2.0, 0.0, 1.0, 3, 2).unwrap();
        for kind in [SplitPoint::Incentre, SplitPoint::Centroid] {
            let r = assert_refinement(&mesh, kind);
            assert_sub_triangle_location(&mesh, &r, 1);
        }
        // Centroids: by symmetry the edge point of every block side (both ends block
        // corners, vertices 0..12) is its midpoint.
        let r = Refinement::new(&mesh, SplitPoint::Centroid).unwrap();
        for (e, edge) in mesh.edges().iter().enumerate() {
            if edge.vertices.iter().all(|&v| v < 12) {
                assert!((r.edge_lambda[e] - 0.5).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn hand_built_mesh_refinement() {
        // Two triangles sharing the diagonal of the unit square, sides tagged.
        let v = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        let mut mesh = TriMesh::new(v, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        mesh.tag_box_sides(0.0, 1.0, 0.0, 1.0);
        let r = assert_refinement(&mesh, SplitPoint::Incentre);
        assert_sub_triangle_location(&mesh, &r, 2);
        // Mirror-symmetric triangles: the diagonal's edge point is its midpoint.
        let e = mesh.find_edge(0, 2).unwrap();
        assert!((r.edge_point[e] - Vec2::new(0.5, 0.5)).norm() < 1e-15);
    }

    #[test]
    fn centroids_are_rejected_where_the_split_line_misses_the_edge() {
        // Two triangles sharing the edge (0,0)–(1,0), both leaning to the right, so
        // the segment between their centroids crosses the edge's line at x = 1.25.
        let v = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(3.0, 1.0),
            Vec2::new(2.5, -1.0),
        ];
        let mesh = TriMesh::new(v, vec![[0, 1, 2], [1, 0, 3]]).unwrap();
        assert_eq!(
            Refinement::new(&mesh, SplitPoint::Centroid).unwrap_err(),
            BasisError::InvalidSplitPoint { t1: 0, t2: 1 }
        );
        assert_refinement(&mesh, SplitPoint::Incentre);
        let grid = generators::block_grid(0.0, 25.0, 0.0, 2.0, 8, 1).unwrap();
        assert!(Refinement::new(&grid, SplitPoint::Centroid).is_ok());
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

        #[test]
        fn incentre_refinement_of_jittered_lattices(seed in 0u64..1_000_000, n in 3usize..9, jitter in 0.0f64..0.45) {
            let mesh = generators::jittered_lattice_delaunay(n, n + 1, (0.0, 1.0, 0.0, 1.0), jitter, seed).unwrap();
            let r = assert_refinement(&mesh, SplitPoint::Incentre);
            assert_sub_triangle_location(&mesh, &r, seed);
        }

        #[test]
        fn incentre_refinement_of_random_points(seed in 0u64..1_000_000, count in 5usize..60) {
            let mesh = random_points_mesh(seed, count);
            let r = assert_refinement(&mesh, SplitPoint::Incentre);
            assert_sub_triangle_location(&mesh, &r, seed);
        }
    }
}
