//! Piecewise-linear Lagrange basis on triangles (PL): one hat function per vertex.
//!
//! On triangle `t` with vertices `V_1, V_2, V_3`, `phi_{V_k}` is the barycentric
//! coordinate `λ_k(x) = λ_k(V_1) + g_k · (x − V_1)`, affine with constant gradient
//! `g_k` (about the first corner: round-off of the element's size). The basis
//! is C⁰ (gradients jump across edges, the source of grid-crossing noise in MPM),
//! non-negative, a partition of unity, and reproduces linear functions with the
//! vertices as [`function_point`](Basis::function_point)s.
//!
//! Since the gradient jumps, a point on a shared edge or vertex takes the gradient
//! of the triangle that holds it. Point location's choice (the lowest-numbered
//! triangle, then the first on the walk from the previous one) keeps vertical
//! mirror lines on the block grids; for a scene symmetric about a horizontal line
//! ([`MirrorAxis::Horizontal`]) [`TriMesh::triangle_kept_at`] keeps one by the
//! mesh's geometry instead, so that the scene stays symmetric where its particles
//! lie on grid diagonals.

use super::{Basis, BasisError, BasisEval, Constraint, Point, Quadratic};
use crate::mesh::{MirrorAxis, TriMesh, Vec2};
use crate::scalar::Real;
use nalgebra::Vector2;

/// A triangle's first corner `V_1` and per local vertex `(λ_k(V_1), g_k)`.
type AboutCorner<T> = (Vector2<T>, [(T, Vector2<T>); 3]);

/// The piecewise-linear Lagrange basis on a [`TriMesh`].
#[derive(Debug, Clone)]
pub struct Linear<T: Real = f64> {
    mesh: TriMesh,
    /// Per triangle its first corner `V_1` and per local vertex `(λ_k(V_1), g_k)`:
    /// `λ_k(x) = λ_k(V_1) + g_k · (x − V_1)`.
    affine: Vec<AboutCorner<T>>,
    /// Flattened vertex → triangles map (CSR).
    support_offsets: Vec<usize>,
    support: Vec<usize>,
    /// The mirror line kept by the choice of triangle for a point on an edge.
    mirror: MirrorAxis,
}

impl<T: Real> Linear<T> {
    /// Builds the basis on `mesh`, keeping vertical mirror lines
    /// ([`with_mirror`](Self::with_mirror)).
    pub fn new(mesh: TriMesh) -> Self {
        Self::with_mirror(mesh, MirrorAxis::Vertical)
    }

    /// Builds the basis on `mesh` for a scene whose mirror line runs along `axis`:
    /// with [`MirrorAxis::Horizontal`] a point on a shared edge or vertex is held
    /// by the triangle [`TriMesh::triangle_kept_at`] keeps.
    pub fn with_mirror(mesh: TriMesh, axis: MirrorAxis) -> Self {
        let affine = (0..mesh.num_triangles())
            .map(|t| {
                let [p1, p2, p3] = mesh.triangle_points(t);
                let d = (p2.x - p1.x) * (p3.y - p1.y) - (p3.x - p1.x) * (p2.y - p1.y);
                let p = [p1, p2, p3];
                let mut out = [(T::zero(), Vector2::zeros()); 3];
                // λ_k(x) = [k = 0] + g_k · (x − p1): about the first corner, so
                // that round-off is that of the element's size, not of `|x|² / d`
                // (in global coordinates, `a_k + g_k · x` gave a particle on an
                // edge a value of 5e-12 instead of 0 at x ≈ 7 on blocks of 0.04).
                for k in 0..3 {
                    let (b, c) = (p[(k + 1) % 3], p[(k + 2) % 3]);
                    let g = Vec2::new(b.y - c.y, c.x - b.x) / d;
                    let a = if k == 0 { 1.0 } else { 0.0 };
                    out[k] = (T::of(a), Vector2::new(T::of(g.x), T::of(g.y)));
                }
                (Vector2::new(T::of(p1.x), T::of(p1.y)), out)
            })
            .collect();
        let mut support_offsets = vec![0];
        let mut support = Vec::new();
        for v in 0..mesh.num_vertices() {
            support.extend_from_slice(mesh.vertex_triangles(v));
            support_offsets.push(support.len());
        }
        Linear {
            mesh,
            affine,
            support_offsets,
            support,
            mirror: axis,
        }
    }

    /// The mesh the basis lives on.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }
}

impl<T: Real> Basis<T, 2> for Linear<T> {
    fn name(&self) -> &'static str {
        "pl"
    }
    fn num_functions(&self) -> usize {
        self.mesh.num_vertices()
    }
    fn num_elements(&self) -> usize {
        self.mesh.num_triangles()
    }
    fn max_functions_per_element(&self) -> usize {
        3
    }
    fn locate(&self, x: &Point<T, 2>, hint: Option<usize>) -> Option<usize> {
        let p = Vec2::new(x.x.to_f64(), x.y.to_f64());
        let t = self.mesh.locate(p, hint)?;
        Some(match self.mirror {
            // Location's own choice (the lowest-numbered triangle, then the walk's
            // first) keeps vertical mirror lines on the block grids
            // (`tests/symmetry.rs`), and scenes keep the results they had.
            MirrorAxis::Vertical | MirrorAxis::Diagonal | MirrorAxis::AntiDiagonal => t,
            MirrorAxis::Horizontal => self.mesh.triangle_kept_at(t, p, self.mirror),
        })
    }
    fn other_elements_at(&self, element: usize, x: &Point<T, 2>, visit: &mut dyn FnMut(usize)) {
        self.mesh
            .other_triangles_at(element, Vec2::new(x.x.to_f64(), x.y.to_f64()), visit)
    }
    #[inline]
    fn eval(&self, element: usize, x: &Point<T, 2>, out: &mut BasisEval<T, 2>) {
        let tri = &self.mesh.triangles()[element];
        let (corner, affine) = &self.affine[element];
        let local = x - corner;
        for (k, &vertex) in tri.iter().enumerate() {
            let (a, g) = &affine[k];
            out.index[k] = vertex;
            out.phi[k] = *a + g.dot(&local);
            out.grad_phi[k] = *g;
        }
        out.set_len(3);
    }
    fn element_functions(&self, element: usize) -> &[usize] {
        &self.mesh.triangles()[element]
    }
    fn function_support(&self, function: usize) -> &[usize] {
        &self.support[self.support_offsets[function]..self.support_offsets[function + 1]]
    }
    fn function_point(&self, function: usize) -> Point<f64, 2> {
        self.mesh.vertices()[function]
    }
    fn boundary_tags(&self) -> Vec<String> {
        self.mesh.tags().to_vec()
    }
    /// `c_i · n = 0` for every vertex `i` of an edge tagged `tag`: the hat functions of
    /// the other vertices vanish on the edge.
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, 2>,
    ) -> Result<Vec<Constraint<T, 2>>, BasisError> {
        let id = self.mesh.tag_id(tag)?;
        let mut vertices: Vec<usize> = self
            .mesh
            .edges()
            .iter()
            .filter(|e| e.tag == Some(id))
            .flat_map(|e| e.vertices)
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        Ok(vertices
            .into_iter()
            .map(|v| Constraint {
                direction: *direction,
                terms: vec![(v, T::one())],
            })
            .collect())
    }
    fn polynomial_pieces(&self, element: usize, out: &mut Vec<Point<f64, 2>>) {
        out.extend(self.mesh.triangle_points(element));
    }
    fn degree(&self) -> usize {
        1
    }
    /// `λ_i(p) = p(V_i)`, the nodal value (a linear `p`).
    fn dual_value(&self, function: usize, p: &Quadratic<2>) -> Option<f64> {
        Some(p.value(&self.mesh.vertices()[function]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check;
    use crate::check::suite::{Claims, Continuity, Subject};
    use crate::mesh::generators;
    use proptest::prelude::*;

    /// PL in the property suite ([`crate::check::suite`]): C⁰, linear.
    impl Subject<2> for Linear<f64> {
        type Mesh = TriMesh;
        const CLAIMS: Claims = Claims {
            partition_of_unity: 1e-14,
            negative: 1e-14,
            linear: 1e-14,
            linear_per_size: 0.0,
            // On slivers, up to ~0.95 ε times the conditioning (9000 random meshes).
            per_conditioning: 2.0 * f64::EPSILON,
            linear_gradient: 1e-13,
            quadratic: None,
            gradient: 1e-8,
            value_jump: 1e-9,
            continuity: Continuity::C0 {
                gradient_jump_above: 0.1,
            },
            dirichlet: 1e-13,
        };
        fn build(mesh: TriMesh) -> Self {
            Linear::new(mesh)
        }
    }

    /// On these well-shaped meshes PL is a partition of unity, non-negative and
    /// linearly precise within 1e-14.
    fn assert_within_1e_14(mesh: TriMesh) {
        let pl = Linear::<f64>::new(mesh);
        assert!(check::partition_of_unity(&pl) < 1e-14);
        assert!(check::min_value(&pl) > -1e-14);
        assert!(check::linear_precision(&pl).0 < 1e-14);
    }

    #[test]
    fn block_and_lattice_grids_to_1e_14() {
        assert_within_1e_14(generators::block_grid(0.0, 1.0, 0.0, 1.0, 3, 2).unwrap());
        // Far from the origin the functions keep the round-off of the sample
        // points' positions (`|x| ε / h`, 1e-12 here): they are evaluated about each
        // triangle's corner (in global coordinates, a value on an edge was off by
        // `|x|² ε / area`, 4e-10 here).
        let far = Linear::<f64>::new(
            generators::block_grid(1e3, 1e3 + 1.0, 1e3, 1e3 + 1.0, 3, 2).unwrap(),
        );
        assert!(check::partition_of_unity(&far) < 1e-12);
        assert!(
            check::min_value(&far) > -1e-12,
            "{:e}",
            check::min_value(&far)
        );
        assert_within_1e_14(generators::lattice_delaunay(5, 0.0, 1.0, 0.0, 1.0).unwrap());
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 12, rng_seed: proptest::test_runner::RngSeed::Fixed(20261122), .. ProptestConfig::default() })]
        #[test]
        fn jittered_lattices_to_1e_14(seed in 0u64..1_000_000, jitter in 0.0f64..0.4) {
            assert_within_1e_14(generators::jittered_lattice_delaunay(5, 6, (0.0, 1.0, 0.0, 1.0), jitter, seed).unwrap());
        }
    }

    #[test]
    fn f32_basis_is_a_partition_of_unity_to_single_precision() {
        let pl = Linear::<f32>::new(generators::lattice_delaunay(5, 0.0, 1.0, 0.0, 1.0).unwrap());
        assert!(check::partition_of_unity(&pl) < 1e-6);
    }
}
