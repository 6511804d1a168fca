//! Quadratic Powell–Sabin splines on an arbitrary triangulation (PS): three C¹
//! piecewise-quadratic functions per vertex (paper §3, thesis §3.5,
//! `ps-splines.md`).
//!
//! Construction, each step in one place:
//! 1. the PS refinement, [`crate::refinement`];
//! 2. a control triangle per vertex, [`mod@control_triangle`];
//! 3. the triplets `(α_q, β_q, γ_q)` of each vertex from its control triangle
//!    (`ps-splines.md` §3), here in [`Triplets`];
//! 4. each function as the PS Hermite interpolant of its triplet, stored as
//!    Bézier ordinates per sub-triangle, [`bezier`].
//!
//! Function `3 i + q` belongs to vertex `i` and control point `Q_i^{q+1}`. The basis
//! is a partition of unity, non-negative, C¹ everywhere, and reproduces linear
//! functions with the control points as coefficients: `Σ_i Σ_q Q_i^q phi_i^q = x`.

pub mod bezier;
pub mod control_triangle;

use super::{Basis, BasisError, BasisEval, Constraint, Point};
use crate::mesh::{TriMesh, Vec2};
use crate::refinement::Refinement;
pub use crate::refinement::SplitPoint;
use crate::scalar::Real;
use bezier::{bernstein, hermite_ordinates, MainTriangle};
use control_triangle::{control_triangle, HalfPlane, VertexKind};
use nalgebra::Vector2;

/// The triplets of one vertex: `phi^q` has value `alpha[q]` and gradient
/// `(beta[q], gamma[q])` at the vertex (`ps-splines.md` §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triplets {
    /// Barycentric coordinates of the vertex in its control triangle.
    pub alpha: [f64; 3],
    /// `∂L_q/∂x`.
    pub beta: [f64; 3],
    /// `∂L_q/∂y`.
    pub gamma: [f64; 3],
}

impl Triplets {
    /// The triplets of vertex `v` with control triangle `q` (counter-clockwise).
    pub fn new(v: Vec2, q: &[Vec2; 3]) -> Self {
        let d = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
        let beta = [
            (q[1].y - q[2].y) / d,
            (q[2].y - q[0].y) / d,
            (q[0].y - q[1].y) / d,
        ];
        let gamma = [
            (q[2].x - q[1].x) / d,
            (q[0].x - q[2].x) / d,
            (q[1].x - q[0].x) / d,
        ];
        let alpha = crate::mesh::barycentric(q[0], q[1], q[2], v);
        Triplets { alpha, beta, gamma }
    }
}

/// Barycentric coordinates of a triangle `(P_0, P_1, P_2)` as functions of `x`:
/// `τ_1 = g_1 · (x − P_0)`, `τ_2 = g_2 · (x − P_0)`, `τ_0 = 1 − τ_1 − τ_2`.
/// Measuring from `P_0` keeps round-off relative to the triangle's size, not to `|x|`,
/// and makes the coordinates sum to one exactly.
#[derive(Debug, Clone, Copy)]
struct LocalCoordinates<T: Real> {
    origin: Vector2<T>,
    g1: Vector2<T>,
    g2: Vector2<T>,
}

impl<T: Real> LocalCoordinates<T> {
    fn new(p: [Vec2; 3]) -> Self {
        let d = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
        // τ_1 = ((x − P_0) × (P_2 − P_0)) / d, τ_2 = ((P_1 − P_0) × (x − P_0)) / d.
        let g1 = Vec2::new(p[2].y - p[0].y, p[0].x - p[2].x) / d;
        let g2 = Vec2::new(p[0].y - p[1].y, p[1].x - p[0].x) / d;
        let t = |v: Vec2| Vector2::new(T::of(v.x), T::of(v.y));
        LocalCoordinates {
            origin: t(p[0]),
            g1: t(g1),
            g2: t(g2),
        }
    }

    #[inline(always)]
    fn at(&self, x: &Vector2<T>) -> [T; 3] {
        let d = x - self.origin;
        let (t1, t2) = (self.g1.dot(&d), self.g2.dot(&d));
        [T::one() - t1 - t2, t1, t2]
    }

    /// Gradients of `τ_0, τ_1, τ_2`.
    #[inline(always)]
    fn gradients(&self) -> [Vector2<T>; 3] {
        [-(self.g1 + self.g2), self.g1, self.g2]
    }
}

/// Precomputed evaluation data of one main triangle.
#[derive(Debug, Clone)]
struct ElementData<T: Real> {
    /// Main-triangle barycentric coordinates.
    lambda: LocalCoordinates<T>,
    z_bary: [T; 3],
    r_lambda: [T; 3],
    /// Sub-triangle barycentric coordinates.
    tau: [LocalCoordinates<T>; 6],
    /// `ordinates[s][f]`: the six Bézier ordinates of local function `f` on sub-triangle `s`.
    ordinates: [[[T; 6]; 9]; 6],
}

/// The quadratic Powell–Sabin spline basis on a [`TriMesh`].
#[derive(Debug, Clone)]
pub struct PowellSabin<T: Real = f64> {
    mesh: TriMesh,
    refinement: Refinement,
    control: Vec<[Vec2; 3]>,
    triplets: Vec<Triplets>,
    element_functions: Vec<[usize; 9]>,
    elements: Vec<ElementData<T>>,
    support_offsets: Vec<usize>,
    support: Vec<usize>,
}

impl<T: Real> PowellSabin<T> {
    /// Builds the PS basis on `mesh` with the given split points.
    ///
    /// Errors: [`BasisError::InvalidSplitPoint`] for centroids on a mesh where they
    /// are not valid; [`BasisError::NoControlTriangle`] if no control triangle can be
    /// found (not expected on a valid mesh).
    pub fn new(mesh: TriMesh, split: SplitPoint) -> Result<Self, BasisError> {
        let refinement = Refinement::new(&mesh, split)?;
        let nv = mesh.num_vertices();
        let mut control = Vec::with_capacity(nv);
        let mut triplets = Vec::with_capacity(nv);
        for v in 0..nv {
            let p = mesh.vertices()[v];
            let points = refinement.ps_points(&mesh, v);
            let kind = vertex_kind(&mesh, v);
            let q = control_triangle(p, &points, kind)
                .or_else(|| control_triangle(p, &points, VertexKind::Interior))
                .ok_or(BasisError::NoControlTriangle { vertex: v })?;
            let tr = Triplets::new(p, &q);
            debug_check_triplets(p, &q, &tr);
            control.push(q);
            triplets.push(tr);
        }
        let mut element_functions = Vec::with_capacity(mesh.num_triangles());
        let mut elements = Vec::with_capacity(mesh.num_triangles());
        for t in 0..mesh.num_triangles() {
            let tri = mesh.triangles()[t];
            element_functions.push(std::array::from_fn(|f| 3 * tri[f / 3] + f % 3));
            let geometry = MainTriangle {
                v: mesh.triangle_points(t),
                z: refinement.split[t],
                z_bary: refinement.split_bary[t],
                r: std::array::from_fn(|m| refinement.local_edge_point(&mesh, t, m)),
                r_lambda: std::array::from_fn(|m| refinement.local_edge_lambdas(&mesh, t, m).0),
            };
            let mut ordinates = [[[T::zero(); 6]; 9]; 6];
            for k in 0..3 {
                let tr = &triplets[tri[k]];
                for q in 0..3 {
                    let mut f = [0.0; 3];
                    let mut g = [Vec2::zeros(); 3];
                    f[k] = tr.alpha[q];
                    g[k] = Vec2::new(tr.beta[q], tr.gamma[q]);
                    let b = hermite_ordinates(&geometry, f, g);
                    for s in 0..6 {
                        ordinates[s][3 * k + q] = b[s].map(T::of);
                    }
                }
            }
            let subs = refinement.sub_triangles(&mesh, t);
            elements.push(ElementData {
                lambda: LocalCoordinates::new(geometry.v),
                z_bary: geometry.z_bary.map(T::of),
                r_lambda: geometry.r_lambda.map(T::of),
                tau: std::array::from_fn(|s| LocalCoordinates::new(subs[s])),
                ordinates,
            });
        }
        let mut support_offsets = vec![0];
        let mut support = Vec::new();
        for v in 0..nv {
            for _ in 0..3 {
                support.extend_from_slice(mesh.vertex_triangles(v));
                support_offsets.push(support.len());
            }
        }
        Ok(PowellSabin {
            mesh,
            refinement,
            control,
            triplets,
            element_functions,
            elements,
            support_offsets,
            support,
        })
    }

    /// The mesh.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }
    /// The PS refinement (split and edge points).
    pub fn refinement(&self) -> &Refinement {
        &self.refinement
    }
    /// Control triangle of each vertex.
    pub fn control_triangles(&self) -> &[[Vec2; 3]] {
        &self.control
    }
    /// Triplets of each vertex.
    pub fn triplets(&self) -> &[Triplets] {
        &self.triplets
    }
}

/// Classifies vertex `v` by its boundary edges (domain to the left of each).
fn vertex_kind(mesh: &TriMesh, v: usize) -> VertexKind {
    let (mut incoming, mut outgoing) = (None, None);
    for &t in mesh.vertex_triangles(v) {
        let tri = mesh.triangles()[t];
        for m in 0..3 {
            if mesh.neighbours()[t][m].is_some() {
                continue;
            }
            let (a, b) = (tri[m], tri[(m + 1) % 3]);
            if b == v {
                incoming = Some(a);
            } else if a == v {
                outgoing = Some(b);
            }
        }
    }
    let (Some(a), Some(b)) = (incoming, outgoing) else {
        return VertexKind::Interior;
    };
    let p = mesh.vertices();
    let (u, w) = ((p[v] - p[a]).normalize(), (p[b] - p[v]).normalize());
    let turn = u.x * w.y - u.y * w.x;
    if turn.abs() < 1e-10 && u.dot(&w) > 0.0 {
        VertexKind::Straight(HalfPlane::left_of(p[v], p[b]))
    } else if turn > 0.0 {
        VertexKind::Corner(
            HalfPlane::left_of(p[a], p[v]),
            HalfPlane::left_of(p[v], p[b]),
        )
    } else {
        // Reflex corner (e.g. on a hole): no boundary-aligned triangle contains the
        // PS points; the general choice and general Dirichlet constraints apply.
        VertexKind::Interior
    }
}

/// Checks `Σα = 1`, `Σβ = Σγ = 0`, `Σ Q α = V`, `Σ Q β = e_x`, `Σ Q γ = e_y` in debug builds.
fn debug_check_triplets(v: Vec2, q: &[Vec2; 3], t: &Triplets) {
    if cfg!(debug_assertions) {
        let scale = (q[1] - q[0]).norm() + (q[2] - q[0]).norm();
        let sum = |w: &[f64; 3]| w.iter().sum::<f64>();
        let moment = |w: &[f64; 3]| q[0] * w[0] + q[1] * w[1] + q[2] * w[2];
        debug_assert!((sum(&t.alpha) - 1.0).abs() < 1e-10);
        debug_assert!(sum(&t.beta).abs() * scale < 1e-10);
        debug_assert!(sum(&t.gamma).abs() * scale < 1e-10);
        debug_assert!((moment(&t.alpha) - v).norm() < 1e-10 * scale);
        debug_assert!((moment(&t.beta) - Vec2::new(1.0, 0.0)).norm() < 1e-10);
        debug_assert!((moment(&t.gamma) - Vec2::new(0.0, 1.0)).norm() < 1e-10);
    }
}

impl<T: Real> Basis<T, 2> for PowellSabin<T> {
    fn name(&self) -> &'static str {
        "ps"
    }
    fn num_functions(&self) -> usize {
        3 * self.mesh.num_vertices()
    }
    fn num_elements(&self) -> usize {
        self.mesh.num_triangles()
    }
    fn max_functions_per_element(&self) -> usize {
        9
    }
    fn locate(&self, x: &Point<T, 2>, hint: Option<usize>) -> Option<usize> {
        self.mesh
            .locate(Vec2::new(x.x.to_f64(), x.y.to_f64()), hint)
    }
    /// Locates the sub-triangle, evaluates the six Bernstein polynomials and combines
    /// them with the stored ordinates of the nine functions.
    #[inline]
    fn eval(&self, element: usize, x: &Point<T, 2>, out: &mut BasisEval<T, 2>) {
        let e = &self.elements[element];
        let lambda = e.lambda.at(x);
        let s = Refinement::sub_triangle_of(lambda, e.z_bary, e.r_lambda);
        let tau = e.tau[s].at(x);
        let grad_tau = e.tau[s].gradients();
        let (b, db) = bernstein(tau);
        let grad_b: [Vector2<T>; 6] = std::array::from_fn(|k| {
            grad_tau[0] * db[k][0] + grad_tau[1] * db[k][1] + grad_tau[2] * db[k][2]
        });
        let ordinates = &e.ordinates[s];
        let functions = &self.element_functions[element];
        for f in 0..9 {
            let c = &ordinates[f];
            let mut phi = T::zero();
            let mut grad = Vector2::zeros();
            for k in 0..6 {
                phi += c[k] * b[k];
                grad += grad_b[k] * c[k];
            }
            out.index[f] = functions[f];
            out.phi[f] = phi;
            out.grad_phi[f] = grad;
        }
        out.set_len(9);
    }
    fn element_functions(&self, element: usize) -> &[usize] {
        &self.element_functions[element]
    }
    fn function_support(&self, function: usize) -> &[usize] {
        &self.support[self.support_offsets[function]..self.support_offsets[function + 1]]
    }
    fn function_point(&self, function: usize) -> Point<f64, 2> {
        self.control[function / 3][function % 3]
    }
    fn boundary_tags(&self) -> Vec<String> {
        self.mesh.tags().to_vec()
    }
    /// For every edge tagged `tag` and each end vertex: the coefficients of the
    /// control points lying on the edge's line are fixed (`c · n = 0`); where fewer
    /// than two lie on it (a control triangle not aligned with the boundary), the two
    /// general constraints `Σ_q c_q α_q = 0` and `Σ_q c_q (β_q t_x + γ_q t_y) = 0`
    /// (value and tangential derivative at the vertex) are imposed instead
    /// (`ps-splines.md` §5).
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, 2>,
    ) -> Result<Vec<Constraint<T, 2>>, BasisError> {
        let id = self.mesh.tag_id(tag)?;
        let mut single: Vec<usize> = Vec::new();
        // (vertex, tangent key: None for the value constraint, terms)
        type General<T> = (usize, Option<(i64, i64)>, Vec<(usize, T)>);
        let mut general: Vec<General<T>> = Vec::new();
        let p = self.mesh.vertices();
        for edge in self.mesh.edges().iter().filter(|e| e.tag == Some(id)) {
            let [a, b] = edge.vertices;
            let tangent = (p[b] - p[a]).normalize();
            let normal = Vec2::new(-tangent.y, tangent.x);
            for v in [a, b] {
                let q = &self.control[v];
                let scale = (q[1] - q[0]).norm() + (q[2] - q[0]).norm();
                let on_line: Vec<usize> = (0..3)
                    .filter(|&k| normal.dot(&(q[k] - p[v])).abs() <= 1e-9 * scale)
                    .collect();
                if on_line.len() >= 2 {
                    single.extend(on_line.iter().map(|k| 3 * v + k));
                } else {
                    let t = &self.triplets[v];
                    general.push((
                        v,
                        None,
                        (0..3).map(|k| (3 * v + k, T::of(t.alpha[k]))).collect(),
                    ));
                    // Key the tangential constraint by the (quantised) tangent direction.
                    let key = ((tangent.x * 1e9) as i64, (tangent.y * 1e9) as i64);
                    general.push((
                        v,
                        Some(key),
                        (0..3)
                            .map(|k| {
                                (
                                    3 * v + k,
                                    T::of(t.beta[k] * tangent.x + t.gamma[k] * tangent.y),
                                )
                            })
                            .collect(),
                    ));
                }
            }
        }
        single.sort_unstable();
        single.dedup();
        general.sort_by_key(|x| (x.0, x.1));
        general.dedup_by(|x, y| x.0 == y.0 && x.1 == y.1);
        let mut out: Vec<Constraint<T, 2>> = single
            .into_iter()
            .map(|f| Constraint {
                direction: *direction,
                terms: vec![(f, T::one())],
            })
            .collect();
        out.extend(general.into_iter().map(|(_, _, terms)| Constraint {
            direction: *direction,
            terms,
        }));
        Ok(out)
    }
    fn polynomial_pieces(&self, element: usize, out: &mut Vec<Point<f64, 2>>) {
        for sub in self.refinement.sub_triangles(&self.mesh, element) {
            out.extend(sub);
        }
    }
    fn degree(&self) -> usize {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check;
    use crate::mesh::generators::{self, PolygonDomain};
    use proptest::prelude::*;

    /// The properties of `ps-splines.md` §6 on one mesh.
    fn assert_ps_properties(mesh: TriMesh) -> PowellSabin<f64> {
        let (lo, hi) = mesh.bounding_box();
        let scale = (hi - lo).norm();
        let ps = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
        let pu = check::partition_of_unity(&ps);
        assert!(pu < 1e-13, "partition of unity off by {pu:e}");
        let min = check::min_value(&ps);
        assert!(min > -1e-13, "negative basis value {min:e}");
        let (lp, lp_grad) = check::linear_precision(&ps);
        assert!(lp < 1e-13 * scale, "linear precision off by {lp:e}");
        assert!(
            lp_grad < 1e-11,
            "gradient of linear precision off by {lp_grad:e}"
        );
        let fd = check::gradient_error(&ps);
        assert!(fd < 1e-6, "gradient vs finite differences: {fd:e}");
        let jumps = check::continuity_jumps(&ps);
        assert!(jumps.points > 0);
        assert!(jumps.value < 1e-9, "value jump {:e}", jumps.value);
        assert!(
            jumps.gradient < 1e-4,
            "gradient jump {:e} (C¹ violated)",
            jumps.gradient
        );
        ps
    }

    fn unit_square_walls() -> [(&'static str, Vec2, Vec2); 4] {
        [
            ("left", Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0)),
            ("right", Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0)),
            ("bottom", Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0)),
            ("top", Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)),
        ]
    }

    /// Dirichlet exactness on each wall of the unit square, both components, and on a
    /// corner with two walls constrained together.
    fn assert_dirichlet_exact(ps: &PowellSabin<f64>) {
        for (tag, a, b) in unit_square_walls() {
            let points = check::points_on_segment(a, b, 100);
            for direction in [Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)] {
                let r = check::dirichlet_residual(ps, tag, direction, &points, 11);
                assert!(r < 1e-13, "{tag} {direction:?}: residual {r:e}");
            }
        }
        // Corner: left and bottom constrained for v_x at once.
        let n = Vec2::new(1.0, 0.0);
        let mut constraints = ps.dirichlet("left", &n).unwrap();
        constraints.extend(ps.dirichlet("bottom", &n).unwrap());
        let mut rng = generators::SplitMix64(5);
        let mut c: Vec<Vec2> = (0..ps.num_functions())
            .map(|_| Vec2::new(rng.next_f64(), rng.next_f64()))
            .collect();
        check::apply_constraints(&mut c, &constraints);
        let mut eval = BasisEval::for_basis(ps);
        for p in check::points_on_segment(Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), 100)
            .into_iter()
            .chain(check::points_on_segment(
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                100,
            ))
        {
            let e = ps.locate(&p, None).unwrap();
            ps.eval(e, &p, &mut eval);
            let v: Vec2 = eval.iter().map(|(i, phi, _)| c[i] * phi).sum();
            assert!(v.x.abs() < 1e-13, "corner residual {:e} at {p:?}", v.x);
        }
    }

    #[test]
    fn block_grid_properties_and_dirichlet() {
        let ps = assert_ps_properties(generators::block_grid(0.0, 1.0, 0.0, 1.0, 3, 2).unwrap());
        assert_dirichlet_exact(&ps);
        // Boundary-aligned control triangles: every wall constraint is single-term.
        for tag in ["left", "bottom"] {
            let k = ps.dirichlet(tag, &Vec2::new(1.0, 0.0)).unwrap();
            assert!(k.iter().all(|c| c.is_single()));
        }
        assert_eq!(ps.num_functions(), 3 * (12 + 6));
    }

    #[test]
    fn lattice_properties_and_dirichlet() {
        let ps = assert_ps_properties(generators::lattice_delaunay(6, 0.0, 1.0, 0.0, 1.0).unwrap());
        assert_dirichlet_exact(&ps);
    }

    #[test]
    fn polygon_with_hole_properties_and_general_constraints() {
        let mut domain = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        let hole: Vec<Vec2> = (0..10)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 10.0;
                Vec2::new(0.5 + 0.2 * a.cos(), 0.5 + 0.2 * a.sin())
            })
            .collect();
        domain.holes.push((hole.clone(), "hole".into()));
        let ps = assert_ps_properties(generators::polygon_mesh(&domain, 0.15).unwrap());
        assert_dirichlet_exact(&ps);
        // The hole's corners are reflex: their constraints are general ones, and the
        // field still vanishes along every hole segment.
        let k = ps.dirichlet("hole", &Vec2::new(0.0, 1.0)).unwrap();
        assert!(k.iter().any(|c| !c.is_single()));
        let points: Vec<Vec2> = (0..10)
            .flat_map(|i| check::points_on_segment(hole[i], hole[(i + 1) % 10], 10))
            .collect();
        for direction in [Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)] {
            let r = check::dirichlet_residual(&ps, "hole", direction, &points, 3);
            // General constraints are imposed by a least-squares projection: round-off
            // of that solve, not of the basis, sets this tolerance.
            assert!(r < 1e-11, "hole residual {r:e}");
        }
    }

    #[test]
    fn gmsh_meshes() {
        let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data");
        let square = crate::mesh::gmsh::read_msh(&data.join("square.msh")).unwrap();
        let ps = assert_ps_properties(square);
        assert_dirichlet_exact(&ps);
        let hole = crate::mesh::gmsh::read_msh(&data.join("square_hole.msh")).unwrap();
        let ps = assert_ps_properties(hole);
        assert_dirichlet_exact(&ps);
        let l = crate::mesh::gmsh::read_msh(&data.join("lshape.msh")).unwrap();
        let ps = assert_ps_properties(l);
        // The L-shape's reflex corner (0.5, 0.5) has general constraints; the field
        // still vanishes along both edges meeting there.
        let points: Vec<Vec2> =
            check::points_on_segment(Vec2::new(1.0, 0.5), Vec2::new(0.5, 0.5), 50)
                .into_iter()
                .chain(check::points_on_segment(
                    Vec2::new(0.5, 0.5),
                    Vec2::new(0.5, 1.0),
                    50,
                ))
                .collect();
        for direction in [Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)] {
            assert!(check::dirichlet_residual(&ps, "wall", direction, &points, 2) < 1e-11);
        }
    }

    #[test]
    fn centroid_split_points_on_the_block_grid() {
        let mesh = generators::block_grid(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
        let ps = PowellSabin::<f64>::new(mesh, SplitPoint::Centroid).unwrap();
        assert!(check::partition_of_unity(&ps) < 1e-13);
        assert!(check::continuity_jumps(&ps).gradient < 1e-4);
        // The thesis' 42-function PS grid of the vibrating bar.
        assert_eq!(ps.num_functions(), 42);
    }

    #[test]
    fn f32_basis_is_a_partition_of_unity_to_single_precision() {
        let mesh = generators::lattice_delaunay(5, 0.0, 1.0, 0.0, 1.0).unwrap();
        let ps = PowellSabin::<f32>::new(mesh, SplitPoint::Incentre).unwrap();
        assert!(check::partition_of_unity(&ps) < 1e-5);
    }

    #[test]
    fn pl_fails_the_c1_check_that_ps_passes() {
        // The continuity check can fail: PL gradients jump across edges.
        let mesh = generators::lattice_delaunay(4, 0.0, 1.0, 0.0, 1.0).unwrap();
        let pl = crate::basis::linear::Linear::<f64>::new(mesh);
        let j = check::continuity_jumps(&pl);
        assert!(j.value < 1e-9);
        assert!(j.gradient > 0.1);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 12, .. ProptestConfig::default() })]

        #[test]
        fn jittered_delaunay_meshes(seed in 0u64..1_000_000, n in 3usize..7, jitter in 0.0f64..0.4) {
            let mesh = generators::jittered_lattice_delaunay(n, n + 1, (0.0, 1.0, 0.0, 1.0), jitter, seed).unwrap();
            let ps = assert_ps_properties(mesh);
            assert_dirichlet_exact(&ps);
        }

        #[test]
        fn random_star_polygons(seed in 0u64..1_000_000, corners in 5usize..10) {
            // A random star-shaped polygon (convex and reflex corners), meshed with
            // the quality mesher; every wall tagged separately.
            let mut rng = generators::SplitMix64(seed);
            let outer: Vec<Vec2> = (0..corners)
                .map(|k| {
                    let a = std::f64::consts::TAU * (k as f64 + 0.3 * rng.next_f64()) / corners as f64;
                    let r = 0.5 + 0.5 * rng.next_f64();
                    Vec2::new(r * a.cos(), r * a.sin())
                })
                .collect();
            let domain = PolygonDomain {
                outer_tags: (0..corners).map(|k| format!("wall{k}")).collect(),
                outer: outer.clone(),
                holes: Vec::new(),
            };
            let ps = assert_ps_properties(generators::polygon_mesh(&domain, 0.25).unwrap());
            for k in 0..corners {
                let points = check::points_on_segment(outer[k], outer[(k + 1) % corners], 20);
                let r = check::dirichlet_residual(&ps, &format!("wall{k}"), Vec2::new(0.6, 0.8), &points, k as u64);
                prop_assert!(r < 1e-11, "wall{} residual {:e}", k, r);
            }
        }

        #[test]
        fn random_point_delaunay_meshes(seed in 0u64..1_000_000, count in 8usize..40) {
            let mut rng = generators::SplitMix64(seed);
            let mut points = vec![
                Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0),
            ];
            points.extend((0..count).map(|_| Vec2::new(0.05 + 0.9 * rng.next_f64(), 0.05 + 0.9 * rng.next_f64())));
            let mut mesh = generators::delaunay(&points).unwrap();
            mesh.tag_box_sides(0.0, 1.0, 0.0, 1.0);
            let ps = assert_ps_properties(mesh);
            assert_dirichlet_exact(&ps);
        }
    }
}
