//! Quadratic Powell–Sabin splines on an arbitrary triangulation (PS): three C¹
//! piecewise-quadratic functions per vertex (paper §3, thesis §3.5,
//! `ps-splines.md`).
//!
//! Construction, each step in one place:
//! 1. the PS refinement, [`crate::refinement`];
//! 2. a control triangle per vertex, [`control_triangle`];
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

/// Affine function `a + g · x`.
type Affine<T> = (T, Vector2<T>);

/// Precomputed evaluation data of one main triangle.
#[derive(Debug, Clone)]
struct ElementData<T: Real> {
    /// Main-triangle barycentric coordinates as affine functions.
    lambda: [Affine<T>; 3],
    z_bary: [T; 3],
    r_lambda: [T; 3],
    /// Sub-triangle barycentric coordinates as affine functions.
    tau: [[Affine<T>; 3]; 6],
    /// `ordinates[s][f]`: the six Bézier ordinates of local function `f` on sub-triangle `s`.
    ordinates: [[[T; 6]; 9]; 6],
}

/// Barycentric coordinates of triangle `p` as affine functions of `x`.
fn barycentric_affine<T: Real>(p: [Vec2; 3]) -> [Affine<T>; 3] {
    let d = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
    std::array::from_fn(|k| {
        let (b, c) = (p[(k + 1) % 3], p[(k + 2) % 3]);
        let g = Vec2::new(b.y - c.y, c.x - b.x) / d;
        let a = (b.x * c.y - c.x * b.y) / d;
        (T::of(a), Vector2::new(T::of(g.x), T::of(g.y)))
    })
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
                lambda: barycentric_affine(geometry.v),
                z_bary: geometry.z_bary.map(T::of),
                r_lambda: geometry.r_lambda.map(T::of),
                tau: std::array::from_fn(|s| barycentric_affine(subs[s])),
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
        let lambda = e.lambda.map(|(a, g)| a + g.dot(x));
        let s = Refinement::sub_triangle_of(lambda, e.z_bary, e.r_lambda);
        let tau_affine = &e.tau[s];
        let tau = tau_affine.map(|(a, g)| a + g.dot(x));
        let (b, db) = bernstein(tau);
        let grad_b: [Vector2<T>; 6] = std::array::from_fn(|k| {
            tau_affine[0].1 * db[k][0] + tau_affine[1].1 * db[k][1] + tau_affine[2].1 * db[k][2]
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
        let mut general: Vec<(usize, Option<(i64, i64)>, Vec<(usize, T)>)> = Vec::new();
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
        general.sort_by(|x, y| (x.0, x.1).cmp(&(y.0, y.1)));
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
