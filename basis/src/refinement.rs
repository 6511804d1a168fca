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
    /// points of two neighbours misses their common edge (possible for centroids).
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
                        return Err(BasisError::InvalidSplitPoint {
                            t1: t1.min(t2),
                            t2: t1.max(t2),
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
    /// `lambda` in `t`, given the split point's `z_bary` and the local edge points'
    /// `r_lambda[m] = λ_m` (weight of `V_m` in `R_m`). Points on a sub-edge go to
    /// either side (the spline is C¹ there).
    ///
    /// The point lies in `(V_m, V_{m+1}, Z)` for the `m` whose opposite vertex `o`
    /// minimises `λ_o / z_o`; writing `x = s Z + (1 − s) p` with `p` on edge `m`,
    /// `s = λ_o / z_o`, it lies in the half at `V_m` when `p`'s weight of `V_m` is at
    /// least `R_m`'s.
    #[inline]
    pub fn sub_triangle_of<T: crate::Real>(
        lambda: [T; 3],
        z_bary: [T; 3],
        r_lambda: [T; 3],
    ) -> usize {
        let ratio = [
            lambda[0] / z_bary[0],
            lambda[1] / z_bary[1],
            lambda[2] / z_bary[2],
        ];
        // Opposite vertex o = m + 2 (mod 3).
        let o = if ratio[0] <= ratio[1] && ratio[0] <= ratio[2] {
            0
        } else if ratio[1] <= ratio[2] {
            1
        } else {
            2
        };
        let m = (o + 1) % 3;
        let s = ratio[o];
        let weight_vm = lambda[m] - s * z_bary[m];
        if weight_vm >= r_lambda[m] * (T::one() - s) {
            2 * m
        } else {
            2 * m + 1
        }
    }

    /// The PS points of vertex `v` (`ps-splines.md` §2): `V` itself, the midpoints of
    /// `V R_e` for every incident edge and of `V Z_t` for every incident triangle.
    pub fn ps_points(&self, mesh: &TriMesh, v: usize) -> Vec<Vec2> {
        let p = mesh.vertices()[v];
        let mut out = vec![p];
        let mut edges: Vec<usize> = Vec::new();
        for &t in mesh.vertex_triangles(v) {
            out.push((p + self.split[t]) * 0.5);
            let tri = mesh.triangles()[t];
            for m in 0..3 {
                if tri[m] == v || tri[(m + 1) % 3] == v {
                    edges.push(mesh.triangle_edges()[t][m]);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        out.extend(edges.iter().map(|&e| (p + self.edge_point[e]) * 0.5));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    #[test]
    fn edge_points_lie_on_the_split_point_segments() {
        let mesh =
            generators::jittered_lattice_delaunay(6, 6, (0.0, 1.0, 0.0, 1.0), 0.3, 3).unwrap();
        let r = Refinement::new(&mesh, SplitPoint::Incentre).unwrap();
        for (e, edge) in mesh.edges().iter().enumerate() {
            if let (t1, Some(t2)) = edge.triangles {
                let (z1, z2, p) = (r.split[t1], r.split[t2], r.edge_point[e]);
                let cross = (z2 - z1).x * (p - z1).y - (z2 - z1).y * (p - z1).x;
                assert!(cross.abs() < 1e-14);
            }
        }
    }

    #[test]
    fn sub_triangle_location_agrees_with_geometry() {
        let mesh =
            generators::jittered_lattice_delaunay(5, 5, (0.0, 1.0, 0.0, 1.0), 0.3, 5).unwrap();
        let r = Refinement::new(&mesh, SplitPoint::Incentre).unwrap();
        let mut rng = generators::SplitMix64(1);
        for t in 0..mesh.num_triangles() {
            let subs = r.sub_triangles(&mesh, t);
            let rl = [0, 1, 2].map(|m| r.local_edge_lambdas(&mesh, t, m).0);
            for _ in 0..50 {
                let (u, v) = (rng.next_f64(), rng.next_f64());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let lambda = [1.0 - u - v, u, v];
                let [p0, p1, p2] = mesh.triangle_points(t);
                let x = p0 * lambda[0] + p1 * lambda[1] + p2 * lambda[2];
                let s = Refinement::sub_triangle_of(lambda, r.split_bary[t], rl);
                let [a, b, c] = subs[s];
                let tau = crate::mesh::barycentric(a, b, c, x);
                assert!(tau.iter().all(|&l| l > -1e-12), "t {t} sub {s} tau {tau:?}");
            }
        }
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
        assert!(matches!(
            Refinement::new(&mesh, SplitPoint::Centroid),
            Err(BasisError::InvalidSplitPoint { .. })
        ));
        assert!(Refinement::new(&mesh, SplitPoint::Incentre).is_ok());
        let grid = generators::block_grid(0.0, 25.0, 0.0, 2.0, 8, 1).unwrap();
        assert!(Refinement::new(&grid, SplitPoint::Centroid).is_ok());
    }
}
