//! Quadratic Powell–Sabin splines on an arbitrary triangulation (PS): three C¹
//! piecewise-quadratic functions per vertex (paper §3, thesis §3.5,
//! `docs/ps-splines.md`).
//!
//! Construction, each step in one place:
//! 1. the PS refinement (split points `Z`, edge points `R`, six sub-triangles per
//!    triangle), [`crate::refinement`];
//! 2. a control triangle `T_i = (Q_i¹, Q_i², Q_i³)` per vertex containing its PS
//!    points (thesis §3.5.2), [`mod@control_triangle`];
//! 3. the triplets `(α_q, β_q, γ_q) = (L_q(V_i), ∂L_q/∂x, ∂L_q/∂y)` of each vertex,
//!    `L_q` the barycentric coordinates of `T_i` (`ps-splines.md` §3), [`Triplets`];
//! 4. each function `φ_i^q` as the PS Hermite interpolant with value `α_q` and
//!    gradient `(β_q, γ_q)` at `V_i`, zero at the other vertices, stored as the
//!    quadratic Bézier ordinates of each sub-triangle (paper eqs. (37)–(38)),
//!    [`bezier`].
//!
//! Evaluation ([`Basis::eval`]) locates the sub-triangle by three sign tests
//! ([`Refinement::sub_triangle_of`]) and evaluates the nine functions' quadratics
//! on it as monomials in the sub-triangle's barycentric coordinates
//! ([`monomials`]): nine flops for a value and gradient, no allocation, no search.
//! Each element keeps only the nine Bézier ordinates of each function that can be
//! non-zero ([`bezier::VertexOrdinates`], 648 bytes per triangle instead of 2 592
//! for the 6 × 9 × 6 monomials); a sub-triangle's monomials are derived when a
//! point first falls in it and kept in the caller's [`ElementCache`] for the next
//! points of the element (the driver evaluates element by element).
//!
//! Function `3 i + q` belongs to vertex `i` and control point `Q_i^{q+1}`. The basis
//! is a partition of unity, non-negative (every ordinate is a barycentric coordinate
//! of a PS point in the control triangle, or a convex combination of such), C¹
//! everywhere, and reproduces linear functions with the control points as
//! coefficients: `Σ_i Σ_q Q_i^q φ_i^q = x`. Geometry is computed in `f64` and
//! stored in `T`.
//!
//! Homogeneous Dirichlet conditions ([`Basis::dirichlet`]) are exact on straight
//! boundary edges: single-term where the control triangle is aligned with the
//! boundary (straight stretches and convex corners), general two-term-per-vertex
//! constraints otherwise (see `dirichlet` in the [`Basis`] implementation of
//! [`PowellSabin`]).

pub mod bezier;
pub mod control_triangle;

use super::{Basis, BasisError, BasisEval, Constraint, ElementCache, Point, Quadratic};
use crate::mesh::{TriMesh, Vec2};
use crate::refinement::Refinement;
pub use crate::refinement::SplitPoint;
use crate::scalar::Real;
#[cfg(doc)]
use bezier::bernstein;
use bezier::{hermite_ordinates, MainTriangle, VertexOrdinates};
pub use control_triangle::MirrorAxis;
use control_triangle::{control_triangle_with, HalfPlane, VertexKind};
use nalgebra::Vector2;

/// The triplets of one vertex (`ps-splines.md` §3): `φ^q` has value `alpha[q]` and
/// gradient `(beta[q], gamma[q])` at the vertex.
///
/// With `L_q` the barycentric coordinate of the control triangle `(Q¹, Q², Q³)` that
/// is 1 at `Q^q` and `d = (X² − X¹)(Y³ − Y¹) − (X³ − X¹)(Y² − Y¹)`:
/// `(α_q, β_q, γ_q) = (L_q(V), ∂L_q/∂x, ∂L_q/∂y)`, e.g. `β_1 = (Y² − Y³)/d`,
/// `γ_1 = (X³ − X²)/d` (cyclically). Identities: `Σα = 1`, `Σβ = Σγ = 0`,
/// `Σ_q Q^q α_q = V`, `Σ_q Q^q β_q = (1, 0)`, `Σ_q Q^q γ_q = (0, 1)`.
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
    /// The triplets of a vertex at `v` with control triangle `q` (counter-clockwise).
    /// Translation-invariant: [`PowellSabin::new`] passes coordinates relative to the
    /// vertex (`v = 0`), where round-off is smallest.
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
        let [g1, g2] = Self::gradients_f64(p);
        let t = |v: Vec2| Vector2::new(T::of(v.x), T::of(v.y));
        LocalCoordinates {
            origin: t(p[0]),
            g1: t(g1),
            g2: t(g2),
        }
    }

    /// `g_1, g_2` in `f64`.
    fn gradients_f64(p: [Vec2; 3]) -> [Vec2; 2] {
        let d = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
        // τ_1 = ((x − P_0) × (P_2 − P_0)) / d, τ_2 = ((P_1 − P_0) × (x − P_0)) / d.
        [
            Vec2::new(p[2].y - p[0].y, p[0].x - p[2].x) / d,
            Vec2::new(p[0].y - p[1].y, p[1].x - p[0].x) / d,
        ]
    }

    #[inline(always)]
    fn at(&self, x: &Vector2<T>) -> [T; 3] {
        let d = x - self.origin;
        let (t1, t2) = (self.g1.dot(&d), self.g2.dot(&d));
        [T::one() - t1 - t2, t1, t2]
    }

    /// Gradients of `τ_0, τ_1, τ_2` (the tests' conditioning measure).
    #[cfg(test)]
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
    /// `ordinates[f]`: the Bézier ordinates of local function `f` (of vertex
    /// `f / 3`) that can be non-zero ([`bezier::expand`] gives each sub-triangle's).
    ordinates: [VertexOrdinates; 9],
}

/// Values of one sub-triangle's monomials in the [`ElementCache`]: 6 per function.
const PIECE_LEN: usize = 6 * 9;

/// The quadratic `Σ_{|ijk|=2} b_ijk B_ijk(τ)` of a triangle in its barycentric
/// coordinates `τ_1, τ_2` (`τ_0 = 1 − τ_1 − τ_2`), as the monomial coefficients
/// `[a_0, …, a_5]` of `a_0 + a_1 τ_1 + a_2 τ_2 + a_3 τ_1² + a_4 τ_1 τ_2 + a_5 τ_2²`. The
/// ordinates `b` are in the order of [`bernstein`] (`τ_0², τ_1², τ_2², 2τ_0τ_1,
/// 2τ_1τ_2, 2τ_0τ_2`); expanding `τ_0` gives `a_0 = b_0`, `a_1 = 2 (b_3 − b_0)`,
/// `a_2 = 2 (b_5 − b_0)`, `a_3 = b_0 + b_1 − 2 b_3`, `a_4 = 2 (b_0 − b_3 + b_4 − b_5)`,
/// `a_5 = b_0 + b_2 − 2 b_5`. In `τ` rather than in `x`, the round-off stays that of
/// the Bernstein form on slender sub-triangles (where `|∇τ|` is large).
pub fn monomials(b: [f64; 6]) -> [f64; 6] {
    [
        b[0],
        2.0 * (b[3] - b[0]),
        2.0 * (b[5] - b[0]),
        b[0] + b[1] - 2.0 * b[3],
        2.0 * (b[0] - b[3] + b[4] - b[5]),
        b[0] + b[2] - 2.0 * b[5],
    ]
}

/// A control point lies on a boundary edge's line when its distance to it is at most
/// this fraction of the control triangle's size (round-off of the construction).
pub const ON_LINE_TOLERANCE: f64 = 1e-9;

/// General Dirichlet rows at a vertex (normalised) that have full column rank, with
/// smallest singular value above this fraction of the largest, fix all its free
/// coefficients (see `dirichlet` of [`PowellSabin`]).
pub const DIRICHLET_RANK_TOLERANCE: f64 = 1e-9;

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
    /// This basis's key in the callers' [`ElementCache`]s.
    cache_owner: u64,
}

impl<T: Real> PowellSabin<T> {
    /// Builds the PS basis on `mesh` with the given split points.
    ///
    /// Errors: [`BasisError::InvalidSplitPoint`] for centroids on a mesh where they
    /// are not valid; [`BasisError::NoControlTriangle`] if no control triangle can be
    /// found (not expected on a valid mesh); [`BasisError::NonFiniteElement`] for a
    /// triangle whose functions are not finite (degenerate geometry).
    pub fn new(mesh: TriMesh, split: SplitPoint) -> Result<Self, BasisError> {
        Self::with_mirror(mesh, split, MirrorAxis::Vertical)
    }

    /// [`PowellSabin::new`], with the control triangles of the vertices whose PS
    /// points are mirror-symmetric about both axis-aligned lines through them
    /// keeping the line `axis` ([`MirrorAxis`]): a scene symmetric about a
    /// horizontal line of a block grid asks for [`MirrorAxis::Horizontal`].
    pub fn with_mirror(
        mesh: TriMesh,
        split: SplitPoint,
        axis: MirrorAxis,
    ) -> Result<Self, BasisError> {
        let refinement = Refinement::new(&mesh, split)?;
        let nv = mesh.num_vertices();
        let mut control = Vec::with_capacity(nv);
        let mut triplets = Vec::with_capacity(nv);
        for v in 0..nv {
            let p = mesh.vertices()[v];
            // In coordinates relative to V (see `Refinement::ps_offsets`).
            let points = refinement.ps_offsets(&mesh, v);
            let kind = vertex_kind(&mesh, v);
            let origin = Vec2::zeros();
            let local = control_triangle_with(origin, &points, kind, axis)
                .or_else(|| control_triangle_with(origin, &points, VertexKind::Interior, axis))
                .ok_or(BasisError::NoControlTriangle { vertex: v })?;
            let tr = Triplets::new(origin, &local);
            debug_check_triplets(origin, &local, &tr);
            let q = local.map(|q| p + q);
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
            let subs = refinement.sub_triangles(&mesh, t);
            let mut ordinates = [[0.0; 9]; 9];
            for k in 0..3 {
                let tr = &triplets[tri[k]];
                for q in 0..3 {
                    let mut f = [0.0; 3];
                    let mut g = [Vec2::zeros(); 3];
                    f[k] = tr.alpha[q];
                    g[k] = Vec2::new(tr.beta[q], tr.gamma[q]);
                    let b = hermite_ordinates(&geometry, f, g);
                    // Hermite data at V_k alone: the other ordinates are +0.0 (not
                    // where the geometry is not finite: 0 · ∞).
                    ordinates[3 * k + q] = bezier::compact(&b, k)
                        .ok_or(BasisError::NonFiniteElement { triangle: t })?;
                }
            }
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
            cache_owner: ElementCache::<T>::new_owner(),
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

    /// The constraints of [`Basis::dirichlet`] at vertex `v` from its `edges` with
    /// the tag (rules in the documentation of `dirichlet` for [`PowellSabin`]).
    fn vertex_dirichlet(
        &self,
        v: usize,
        edges: &[[usize; 2]],
        single: &mut Vec<usize>,
        general: &mut Vec<Vec<(usize, f64)>>,
    ) {
        let p = self.mesh.vertices();
        let q = &self.control[v];
        let scale = (q[1] - q[0]).norm().max((q[2] - q[1]).norm());
        let mut fixed = [false; 3];
        let mut tangents: Vec<Vec2> = Vec::new();
        for &[a, b] in edges {
            let tangent = (p[b] - p[a]).normalize();
            let normal = Vec2::new(-tangent.y, tangent.x);
            let on_line: Vec<usize> = (0..3)
                .filter(|&k| normal.dot(&(q[k] - p[v])).abs() <= ON_LINE_TOLERANCE * scale)
                .collect();
            if on_line.len() >= 2 {
                on_line.iter().for_each(|&k| fixed[k] = true);
            } else if !tangents
                .iter()
                .any(|t| (t.x * tangent.y - t.y * tangent.x).abs() <= ON_LINE_TOLERANCE)
            {
                tangents.push(tangent);
            }
        }
        let free: Vec<usize> = (0..3).filter(|&k| !fixed[k]).collect();
        single.extend((0..3).filter(|&k| fixed[k]).map(|k| 3 * v + k));
        if tangents.is_empty() || free.is_empty() {
            return;
        }
        let t = &self.triplets[v];
        // The value row, then one row per tangent, over all three coefficients.
        let mut full: Vec<[f64; 3]> = vec![t.alpha];
        full.extend(
            tangents
                .iter()
                .map(|d| std::array::from_fn(|k| t.beta[k] * d.x + t.gamma[k] * d.y)),
        );
        // Restricted to the free coefficients; rows that the fixed ones already satisfy
        // (nothing left but round-off) are dropped.
        let norm = |r: &[f64]| r.iter().map(|w| w * w).sum::<f64>().sqrt();
        let rows: Vec<Vec<f64>> = full
            .iter()
            .map(|r| (r, free.iter().map(|&k| r[k]).collect::<Vec<f64>>()))
            .filter(|(r, restricted)| norm(restricted) > ON_LINE_TOLERANCE * norm(&r[..]))
            .map(|(_, restricted)| restricted)
            .collect();
        if rows.is_empty() {
            return;
        }
        let a =
            nalgebra::DMatrix::from_fn(rows.len(), free.len(), |r, c| rows[r][c] / norm(&rows[r]));
        let sv = a.singular_values();
        let (max, min) = (sv.max(), sv.min());
        if rows.len() >= free.len() && min > DIRICHLET_RANK_TOLERANCE * max {
            single.extend(free.iter().map(|&k| 3 * v + k));
            return;
        }
        for row in rows {
            general.push(free.iter().zip(row).map(|(&k, w)| (3 * v + k, w)).collect());
        }
    }

    /// Evaluates the nine functions of `element` at `x` with the quadratic polynomial
    /// of sub-triangle `piece` (numbered as in [`crate::refinement`]), also where `x`
    /// lies outside that sub-triangle (the polynomial is extended). With `τ_1, τ_2`
    /// the barycentric coordinates of `x` in the sub-triangle and `a_f` the
    /// [`monomials`] of function `f` on it (its Bézier ordinates `b_f,ijk`
    /// converted, so that `φ_f(x) = Σ_{|ijk|=2} b_f,ijk B_ijk(τ)`; derived once per
    /// element and piece into `out`'s [`ElementCache`], [`PowellSabin::piece_monomials`]):
    ///
    /// `φ_f = a_0 + τ_1 (a_1 + a_3 τ_1 + a_4 τ_2) + τ_2 (a_2 + a_5 τ_2)`,
    /// `∇φ_f = (a_1 + 2 a_3 τ_1 + a_4 τ_2) ∇τ_1 + (a_2 + a_4 τ_1 + 2 a_5 τ_2) ∇τ_2`.
    ///
    /// Used by [`Basis::eval`] after locating the sub-triangle, and by the C¹ tests to
    /// compare the two pieces meeting at an edge at the same point.
    #[inline]
    pub fn eval_piece(
        &self,
        element: usize,
        piece: usize,
        x: &Point<T, 2>,
        out: &mut BasisEval<T, 2>,
    ) {
        let tau = &self.elements[element].tau[piece];
        let [_, t1, t2] = tau.at(x);
        let functions = &self.element_functions[element];
        let BasisEval {
            index,
            phi,
            grad_phi,
            cache,
            ..
        } = out;
        let derive = |poly: &mut [T]| self.piece_monomials(element, piece, poly);
        let mut evaluate = |poly: &[T]| {
            for (f, a) in poly.chunks_exact(6).enumerate() {
                let h1 = a[1] + a[3] * t1 + a[4] * t2;
                let h2 = a[2] + a[5] * t2;
                index[f] = functions[f];
                phi[f] = a[0] + t1 * h1 + t2 * h2;
                let (d1, d2) = (h1 + a[3] * t1, h2 + a[4] * t1 + a[5] * t2);
                grad_phi[f] = tau.g1 * d1 + tau.g2 * d2;
            }
        };
        match cache.part(self.cache_owner, element, piece, PIECE_LEN, derive) {
            Some(poly) => evaluate(poly),
            None => {
                let mut own = [T::zero(); PIECE_LEN];
                self.piece_monomials(element, piece, &mut own);
                evaluate(&own);
            }
        }
        out.set_len(9);
    }

    /// The [`monomials`] of the nine functions of `element` on sub-triangle `piece`
    /// (`out[6 f .. 6 f + 6]` for function `f`), from the kept ordinates
    /// ([`bezier::expand`]); in `f64`, then stored in `T`.
    pub fn piece_monomials(&self, element: usize, piece: usize, out: &mut [T]) {
        let ordinates = &self.elements[element].ordinates;
        for (f, a) in out.chunks_exact_mut(6).enumerate().take(9) {
            let b = bezier::expand(&ordinates[f], f / 3, piece);
            for (a, m) in a.iter_mut().zip(monomials(b)) {
                *a = T::of(m);
            }
        }
    }
}

/// Two boundary edges at a vertex form a straight stretch when the sine of the angle
/// between their directions is below this (collinear up to round-off).
const STRAIGHT_TURN: f64 = 1e-10;

/// Classifies vertex `v` by its boundary edges (domain to the left of each): straight
/// stretch, convex corner, or interior (also for reflex corners). The boundary lines
/// are returned relative to the vertex, like [`Refinement::ps_offsets`].
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
    // Boundary lines in coordinates relative to V, like the PS points.
    let p = mesh.vertices();
    let (da, db) = (p[a] - p[v], p[b] - p[v]);
    let origin = Vec2::zeros();
    let (u, w) = ((-da).normalize(), db.normalize());
    let turn = u.x * w.y - u.y * w.x;
    if turn.abs() < STRAIGHT_TURN && u.dot(&w) > 0.0 {
        VertexKind::Straight(HalfPlane::left_of(origin, db))
    } else if turn > 0.0 {
        VertexKind::Corner(
            HalfPlane::left_of(da, origin),
            HalfPlane::left_of(origin, db),
        )
    } else {
        // Reflex corner (e.g. on a hole): no boundary-aligned triangle contains the
        // PS points; the general choice, and general Dirichlet constraints (which
        // become single-term when both edges at the corner are constrained).
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
    fn element_cache_len(&self) -> usize {
        6 * PIECE_LEN
    }
    fn locate(&self, x: &Point<T, 2>, hint: Option<usize>) -> Option<usize> {
        self.mesh
            .locate(Vec2::new(x.x.to_f64(), x.y.to_f64()), hint)
    }
    fn other_elements_at(&self, element: usize, x: &Point<T, 2>, visit: &mut dyn FnMut(usize)) {
        self.mesh
            .other_triangles_at(element, Vec2::new(x.x.to_f64(), x.y.to_f64()), visit)
    }
    /// Locates the sub-triangle ([`Refinement::sub_triangle_of`]) and evaluates its
    /// polynomial ([`PowellSabin::eval_piece`]).
    #[inline]
    fn eval(&self, element: usize, x: &Point<T, 2>, out: &mut BasisEval<T, 2>) {
        let e = &self.elements[element];
        let lambda = e.lambda.at(x);
        let s = Refinement::sub_triangle_of(lambda, e.z_bary, e.r_lambda);
        self.eval_piece(element, s, x, out);
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
    /// Homogeneous Dirichlet constraints on the boundary tagged `tag`
    /// (`ps-splines.md` §5), vertex by vertex over the tagged edges' end vertices.
    /// A field `Σ c φ` vanishes on a straight edge iff, at both end vertices, its value
    /// and its derivative along the edge's tangent `t` vanish:
    ///
    /// `Σ_q c_q α_q = 0` and `Σ_q c_q (β_q t_x + γ_q t_y) = 0`.
    ///
    /// - Control points on the edge's line (distance ≤ [`ON_LINE_TOLERANCE`] × the
    ///   control triangle's size; two of them for a boundary-aligned control
    ///   triangle): both constraints say exactly that their coefficients vanish
    ///   (`α_q = 0` and `∇L_q · t = 0` for the third point, off the line), so they
    ///   are fixed with single-term constraints.
    /// - Otherwise (reflex corners, flat corners, see
    ///   [`control_triangle::CORNER_AREA_RATIO`]) the two general rows are kept,
    ///   restricted to the coefficients not already fixed. If they determine those
    ///   coefficients completely (full column rank, e.g. both edges at a reflex corner
    ///   constrained: value and full gradient vanish), the coefficients are fixed with
    ///   single-term constraints instead, which is exact and what the MPM driver
    ///   supports; otherwise the rows are returned as general constraints.
    ///
    /// Constraints are deduplicated: single-term ones sorted by function, then the
    /// general ones by vertex. Errors with [`BasisError::Mesh`] for an unknown tag.
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, 2>,
    ) -> Result<Vec<Constraint<T, 2>>, BasisError> {
        let id = self.mesh.tag_id(tag)?;
        // Edges of the tag at each vertex (BTreeMap: deterministic output order).
        let mut at_vertex: std::collections::BTreeMap<usize, Vec<[usize; 2]>> = Default::default();
        for edge in self.mesh.edges().iter().filter(|e| e.tag == Some(id)) {
            for v in edge.vertices {
                at_vertex.entry(v).or_default().push(edge.vertices);
            }
        }
        let mut single: Vec<usize> = Vec::new();
        let mut general: Vec<Vec<(usize, f64)>> = Vec::new();
        for (&v, edges) in &at_vertex {
            self.vertex_dirichlet(v, edges, &mut single, &mut general);
        }
        single.sort_unstable();
        single.dedup();
        let mut out: Vec<Constraint<T, 2>> = single
            .into_iter()
            .map(|f| Constraint {
                direction: *direction,
                terms: vec![(f, T::one())],
            })
            .collect();
        out.extend(general.into_iter().map(|terms| Constraint {
            direction: *direction,
            terms: terms.into_iter().map(|(f, w)| (f, T::of(w))).collect(),
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
    /// `λ_{i,q}(p) = p(V_i) + grad p(V_i) · (Q_i^q − V_i)`: the spline with these
    /// coefficients has, at `V_i`, the value `Σ_q λ_q α_q` and gradient
    /// `Σ_q λ_q (β_q, γ_q)` of the plane tangent to `p` there (the `L_q` are the
    /// barycentric coordinates of the control triangle, so they reproduce that
    /// plane), and the PS Hermite interpolant of a quadratic's values and
    /// gradients is the quadratic itself (`ps-splines.md` §4).
    fn dual_value(&self, function: usize, p: &Quadratic<2>) -> Option<f64> {
        let v = self.mesh.vertices()[function / 3];
        let q = self.control[function / 3][function % 3];
        Some(p.value(&v) + p.gradient(&v).dot(&(q - v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check;
    use crate::check::suite::{self, Claims, Continuity, Subject};
    use crate::mesh::generators;
    use crate::mesh::signed_area;

    /// Barycentric sample points of a piece: corners, edge midpoints, interior points
    /// (for [`piece_gradient_error`]).
    const SAMPLES: [[f64; 3]; 10] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [0.7, 0.2, 0.1],
        [0.1, 0.7, 0.2],
        [0.2, 0.1, 0.7],
    ];

    /// Largest jumps `(value, gradient)` across every interior edge of the PS
    /// refinement, found by evaluating the polynomials of the two pieces meeting there
    /// at the same points of the edge ([`PowellSabin::eval_piece`]), function by
    /// function (a function absent on one side counts as zero there). Both are
    /// relative to the round-off scale of the two pieces: the value jump to
    /// `max diam · |∇τ|` (≥ 1, large on slivers), the gradient jump to the largest
    /// gradient at the point times that factor.
    fn c1_jumps(ps: &PowellSabin<f64>) -> (f64, f64) {
        let mesh = ps.mesh();
        let (mut a, mut b) = (BasisEval::for_basis(ps), BasisEval::for_basis(ps));
        let (mut value, mut gradient) = (0.0f64, 0.0f64);
        let conditioning = |t: usize, s: usize| {
            let p = ps.refinement().sub_triangles(mesh, t)[s];
            let diam = (p[1] - p[0])
                .norm()
                .max((p[2] - p[1]).norm())
                .max((p[0] - p[2]).norm());
            ps.elements[t].tau[s]
                .gradients()
                .iter()
                .fold(1.0f64, |m, g| m.max(diam * g.norm()))
        };
        let mut compare = |(t1, s1): (usize, usize), (t2, s2): (usize, usize), p: Vec2, q: Vec2| {
            let cond = conditioning(t1, s1).max(conditioning(t2, s2));
            for w in [0.0, 0.2, 0.5, 0.8, 1.0] {
                let x = p + (q - p) * w;
                ps.eval_piece(t1, s1, &x, &mut a);
                ps.eval_piece(t2, s2, &x, &mut b);
                let find = |ev: &BasisEval<f64, 2>, i: usize| {
                    (0..ev.len())
                        .find(|&k| ev.index[k] == i)
                        .map_or((0.0, Vec2::zeros()), |k| (ev.phi[k], ev.grad_phi[k]))
                };
                let scale = a.grad_phi[..9]
                    .iter()
                    .chain(&b.grad_phi[..9])
                    .fold(0.0f64, |m, g| m.max(g.norm()));
                for &i in a.index[..9].iter().chain(&b.index[..9]) {
                    let ((va, ga), (vb, gb)) = (find(&a, i), find(&b, i));
                    value = value.max((va - vb).abs() / cond);
                    gradient = gradient.max((ga - gb).norm() / (scale * cond));
                }
            }
        };
        for t in 0..mesh.num_triangles() {
            let v = mesh.triangle_points(t);
            let z = ps.refinement().split[t];
            for m in 0..3 {
                let r = ps.refinement().local_edge_point(mesh, t, m);
                // Inside t: R_m–Z between pieces 2m and 2m + 1, V_m–Z between 2m and
                // 2(m − 1) + 1.
                compare((t, 2 * m), (t, 2 * m + 1), r, z);
                compare((t, 2 * m), (t, 2 * ((m + 2) % 3) + 1), v[m], z);
                // Across main edge m (orientation reversed in the neighbour).
                if let Some(u) = mesh.neighbours()[t][m] {
                    let m2 = (0..3)
                        .find(|&k| mesh.neighbours()[u][k] == Some(t))
                        .unwrap();
                    compare((t, 2 * m), (u, 2 * m2 + 1), v[m], r);
                    compare((t, 2 * m + 1), (u, 2 * m2), r, v[(m + 1) % 3]);
                }
            }
        }
        (value, gradient)
    }

    /// Triplet identities (`ps-splines.md` §3), containment of the PS points in the
    /// control triangles, and the Hermite property of §4: at its vertex `φ_i^q` has
    /// value `α_q` and gradient `(β_q, γ_q)`, at the other vertices of its triangles
    /// value and gradient zero.
    fn assert_control_triangles_and_triplets(ps: &PowellSabin<f64>) {
        let mesh = ps.mesh();
        for v in 0..mesh.num_vertices() {
            let (q, t, x) = (
                &ps.control_triangles()[v],
                &ps.triplets()[v],
                mesh.vertices()[v],
            );
            let size = (q[1] - q[0]).norm().max((q[2] - q[0]).norm());
            assert!(signed_area(q[0], q[1], q[2]) > 0.0);
            // The identities of §3 with the stored (global) control points, to the
            // round-off of their coordinates times |∇L|.
            let grad = t
                .beta
                .iter()
                .zip(&t.gamma)
                .fold(0.0f64, |m, (b, g)| m.max(b.hypot(*g)));
            let sum = |w: &[f64; 3]| w.iter().sum::<f64>();
            let moment = |w: &[f64; 3]| (0..3).map(|k| (q[k] - x) * w[k]).sum::<Vec2>();
            let tol = 1e-14 * (1.0 + (x.norm() + size) * grad);
            assert!((sum(&t.alpha) - 1.0).abs() < tol, "vertex {v}: {t:?}");
            assert!(sum(&t.beta).abs() * size < tol && sum(&t.gamma).abs() * size < tol);
            assert!(moment(&t.alpha).norm() < tol * size, "vertex {v}: {t:?}");
            assert!(
                (moment(&t.beta) - Vec2::new(1.0, 0.0)).norm() < tol,
                "vertex {v}: {t:?}"
            );
            assert!(
                (moment(&t.gamma) - Vec2::new(0.0, 1.0)).norm() < tol,
                "vertex {v}: {t:?}"
            );
            for p in ps.refinement().ps_points(mesh, v) {
                let l = crate::mesh::barycentric(q[0], q[1], q[2], p);
                assert!(
                    l.iter().all(|&l| l > -1e-12),
                    "vertex {v}: PS point {p:?} outside, {l:?}"
                );
            }
            // Boundary alignment (§2): the control triangle has an edge on the line of
            // each boundary edge (except at reflex and flat corners).
            let kind = vertex_kind(mesh, v);
            let on = |h: &control_triangle::HalfPlane| {
                // The boundary lines are relative to the vertex.
                q.iter()
                    .filter(|p| (h.n.dot(&(*p - x)) - h.c).abs() < 1e-12 * size)
                    .count()
            };
            match kind {
                VertexKind::Straight(h) => assert_eq!(on(&h), 2, "vertex {v}"),
                VertexKind::Corner(a, b) if q[0] == x => {
                    assert_eq!((on(&a), on(&b)), (2, 2), "vertex {v}")
                }
                VertexKind::Corner(a, b) => assert!(on(&a) == 2 || on(&b) == 2, "vertex {v}"),
                VertexKind::Interior => {}
            }
        }
        let mut eval = BasisEval::for_basis(ps);
        for t in 0..mesh.num_triangles() {
            let tri = mesh.triangles()[t];
            for (k, &v) in tri.iter().enumerate() {
                // V_k is a corner of pieces 2k and 2(k − 1) + 1.
                for piece in [2 * k, 2 * ((k + 2) % 3) + 1] {
                    ps.eval_piece(t, piece, &mesh.vertices()[v], &mut eval);
                    for (i, phi, grad) in eval.iter() {
                        let (value, gradient) = if i / 3 == v {
                            let tr = &ps.triplets()[v];
                            let q = i % 3;
                            (tr.alpha[q], Vec2::new(tr.beta[q], tr.gamma[q]))
                        } else {
                            (0.0, Vec2::zeros())
                        };
                        // Round-off: ordinates O(1) times the gradients of the
                        // piece's barycentric coordinates.
                        let scale = ps.elements[t].tau[piece]
                            .gradients()
                            .iter()
                            .fold(1.0f64, |m, g| m.max(g.norm()));
                        assert!((phi - value).abs() < 1e-13, "t {t} vertex {v} function {i}");
                        assert!(
                            (grad - gradient).norm() < 1e-13 * scale,
                            "t {t} vertex {v} function {i}: {grad:?} vs {gradient:?}"
                        );
                    }
                }
            }
        }
    }

    /// `max |∇φ − central difference|` relative to `max |∇φ|`, differentiating the
    /// quadratic of each piece ([`PowellSabin::eval_piece`]) at its [`SAMPLES`] with
    /// step `10⁻³ ×` its diameter: central differences are exact for quadratics, so
    /// only round-off remains, whatever the shape of the piece.
    fn piece_gradient_error(ps: &PowellSabin<f64>) -> f64 {
        let (mut e0, mut ep, mut em) = (
            BasisEval::for_basis(ps),
            BasisEval::for_basis(ps),
            BasisEval::for_basis(ps),
        );
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for t in 0..ps.mesh().num_triangles() {
            for (s, p) in ps
                .refinement()
                .sub_triangles(ps.mesh(), t)
                .iter()
                .enumerate()
            {
                let diam = (p[1] - p[0])
                    .norm()
                    .max((p[2] - p[1]).norm())
                    .max((p[0] - p[2]).norm());
                let h = 1e-3 * diam;
                for w in SAMPLES {
                    let x = p[0] * w[0] + p[1] * w[1] + p[2] * w[2];
                    ps.eval_piece(t, s, &x, &mut e0);
                    for axis in 0..2 {
                        let mut d = Vec2::zeros();
                        d[axis] = h;
                        ps.eval_piece(t, s, &(x + d), &mut ep);
                        ps.eval_piece(t, s, &(x - d), &mut em);
                        for k in 0..9 {
                            let fd = (ep.phi[k] - em.phi[k]) / (2.0 * h);
                            scale = scale.max(e0.grad_phi[k][axis].abs());
                            worst = worst.max((fd - e0.grad_phi[k][axis]).abs());
                        }
                    }
                }
            }
        }
        worst / scale
    }

    /// PS in the property suite ([`crate::check::suite`]): C¹, quadratic precision
    /// with the Hermite data of the quadratic at the vertices as coefficients, and the
    /// checks below on every mesh of the suite.
    impl Subject<2> for PowellSabin<f64> {
        type Mesh = TriMesh;
        const CLAIMS: Claims = Claims {
            partition_of_unity: 1e-13,
            negative: 1e-13,
            linear: 0.0,
            linear_per_size: 1e-13,
            per_conditioning: 0.0,
            linear_gradient: 1e-13,
            quadratic: Some((1e-12, 1e-13)),
            gradient: 1e-6,
            value_jump: 1e-9,
            continuity: Continuity::C1 {
                gradient_jump_below: 1e-11,
            },
            dirichlet: 1e-13,
        };
        fn build(mesh: TriMesh) -> Self {
            PowellSabin::new(mesh, SplitPoint::Incentre).unwrap()
        }
        /// Exact C¹ across every edge of the refinement, the control triangles and
        /// triplets, gradients of each piece's own quadratic against central
        /// differences, and, on the unit square, the corner fixed by `left` and
        /// `bottom` together.
        fn specific_checks(&self) {
            let (jump, grad_jump) = c1_jumps(self);
            assert!(jump < 1e-13, "value jump {jump:e}");
            assert!(
                grad_jump < 1e-9,
                "relative gradient jump {grad_jump:e} (C¹ violated)"
            );
            assert_control_triangles_and_triplets(self);
            let fd = piece_gradient_error(self);
            assert!(
                fd < 1e-9,
                "gradient vs central differences on the pieces: {fd:e}"
            );
            let mesh = self.mesh();
            let corner = mesh.vertices().iter().position(|p| p.norm() == 0.0);
            if let (Ok(_), Ok(_), Some(corner)) =
                (mesh.tag_id("left"), mesh.tag_id("bottom"), corner)
            {
                let n = Vec2::new(1.0, 0.0);
                let mut constraints = self.dirichlet("left", &n).unwrap();
                constraints.extend(self.dirichlet("bottom", &n).unwrap());
                for q in 0..3 {
                    assert!(constraints
                        .iter()
                        .any(|c| c.terms == vec![(3 * corner + q, 1.0)]));
                }
            }
        }
    }

    /// The element cache changes no bit: one buffer used for two bases of the same
    /// element count, each point of one basis's element followed by a point of the
    /// other's element of the same number and by another of the first, gives what a
    /// buffer without room for a cache (every piece derived at every point) gives.
    #[test]
    fn the_element_cache_gives_the_same_bits_and_never_mixes_bases() {
        use crate::mesh::generators::jittered_lattice_delaunay;
        let mesh = |seed| jittered_lattice_delaunay(5, 5, (0.0, 1.0, 0.0, 1.0), 0.3, seed);
        let a = PowellSabin::<f64>::new(mesh(1).unwrap(), SplitPoint::Incentre).unwrap();
        let b = PowellSabin::<f64>::new(mesh(2).unwrap(), SplitPoint::Incentre).unwrap();
        assert_eq!(a.num_elements(), b.num_elements());
        let mut cached = BasisEval::for_basis(&a);
        let mut plain = BasisEval::with_capacity(9);
        let mut rng = crate::rng::SplitMix64(5);
        let mut point_in = |ps: &PowellSabin<f64>, e: usize| {
            let [p, q, r] = ps.mesh().triangle_points(e);
            let (s, t) = (rng.next_f64(), rng.next_f64());
            let (s, t) = if s + t > 1.0 {
                (1.0 - s, 1.0 - t)
            } else {
                (s, t)
            };
            let x = p + (q - p) * s + (r - p) * t;
            Vector2::new(x.x, x.y)
        };
        for e in 0..a.num_elements() {
            for ps in [&a, &b, &a, &a] {
                let x = point_in(ps, e);
                ps.eval(e, &x, &mut cached);
                ps.eval(e, &x, &mut plain);
                assert_eq!(cached.len(), 9);
                for k in 0..9 {
                    assert_eq!(cached.index[k], plain.index[k]);
                    assert_eq!(cached.phi[k].to_bits(), plain.phi[k].to_bits());
                    let bits = |g: &Vector2<f64>| [g.x.to_bits(), g.y.to_bits()];
                    assert_eq!(bits(&cached.grad_phi[k]), bits(&plain.grad_phi[k]));
                }
            }
        }
    }

    #[test]
    fn basis_api_on_a_hand_built_mesh() {
        let ps = PowellSabin::<f64>::new(suite::two_triangles(), SplitPoint::Incentre).unwrap();
        assert_eq!((ps.name(), ps.degree()), ("ps", 2));
        assert_eq!((ps.num_functions(), ps.num_elements()), (12, 2));
        assert_eq!(ps.max_functions_per_element(), 9);
        // Functions 3i + q, in the order eval writes them.
        assert_eq!(ps.element_functions(1), &[0, 1, 2, 6, 7, 8, 9, 10, 11]);
        let mut eval = BasisEval::for_basis(&ps);
        ps.eval(1, &Vector2::new(0.2, 0.6), &mut eval);
        assert_eq!(&eval.index[..eval.len()], ps.element_functions(1));
        // Support: the triangles at the vertex.
        assert_eq!(ps.function_support(0), &[0, 1]);
        assert_eq!(ps.function_support(5), &[0]);
        assert_eq!(ps.function_point(4), ps.control_triangles()[1][1]);
        assert_eq!(ps.locate(&Vector2::new(0.9, 0.1), None), Some(0));
        assert_eq!(ps.locate(&Vector2::new(1.5, 0.1), None), None);
        let mut pieces = Vec::new();
        ps.polynomial_pieces(0, &mut pieces);
        assert_eq!(pieces.len(), 18);
        let area: f64 = pieces
            .chunks(3)
            .map(|p| signed_area(p[0], p[1], p[2]))
            .sum();
        assert!((area - 0.5).abs() < 1e-15);
        let mut tags = ps.boundary_tags();
        tags.sort();
        assert_eq!(tags, ["bottom", "left", "right", "top"]);
        assert!(matches!(
            ps.dirichlet("lid", &Vector2::new(1.0, 0.0)),
            Err(BasisError::Mesh(crate::mesh::MeshError::UnknownTag { .. }))
        ));
    }

    #[test]
    fn block_grid_function_count_and_corner_control_points() {
        let ps = <PowellSabin<f64> as Subject<2>>::build(
            generators::block_grid(0.0, 1.0, 0.0, 1.0, 3, 2).unwrap(),
        );
        assert_eq!(ps.num_functions(), 3 * (12 + 6));
        // Corners: Q¹ = V.
        for (v, p) in ps.mesh().vertices().iter().enumerate() {
            if (p.x == 0.0 || p.x == 1.0) && (p.y == 0.0 || p.y == 1.0) {
                assert_eq!(ps.control_triangles()[v][0], *p);
            }
        }
    }

    #[test]
    fn general_constraints_at_a_reflex_corner_between_two_tags() {
        // L-shape with the two walls at the reflex corner (1, 1) tagged apart: each
        // wall alone constrains value and one tangential derivative there (the suite
        // checks that both walls, alone and together, are exact).
        let ps = <PowellSabin<f64> as Subject<2>>::build(suite::l_shape_two_tags().mesh);
        let n = Vec2::new(0.6, -0.8);
        let c = ps.dirichlet("c", &n).unwrap();
        let d = ps.dirichlet("d", &n).unwrap();
        let general = |k: &[Constraint<f64, 2>]| k.iter().filter(|c| !c.is_single()).count();
        assert_eq!((general(&c), general(&d)), (2, 2));
    }

    #[test]
    fn nearly_flat_convex_corner_gets_a_boundary_aligned_control_triangle() {
        // The corner at (1, −0.03) turns by 3.4°: the apex construction would give a
        // control triangle ~40 times too large; one boundary line is used instead
        // (the suite checks its walls).
        let ps = <PowellSabin<f64> as Subject<2>>::build(suite::nearly_flat_corner().mesh);
        let p = Vec2::new(1.0, -0.03);
        let v = ps.mesh().vertices().iter().position(|x| *x == p).unwrap();
        assert!(matches!(vertex_kind(ps.mesh(), v), VertexKind::Corner(..)));
        assert_ne!(ps.control_triangles()[v][0], p);
    }

    #[test]
    fn centroid_split_points_accepted_on_the_block_grid_rejected_elsewhere() {
        let mesh = generators::block_grid(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
        let ps = PowellSabin::<f64>::new(mesh, SplitPoint::Centroid).unwrap();
        let (pu, min) = (check::partition_of_unity(&ps), check::min_value(&ps));
        assert!(pu < 1e-13 && min > -1e-13);
        let (jump, grad_jump) = c1_jumps(&ps);
        assert!(jump < 1e-14 && grad_jump < 1e-12);
        // The thesis' 42-function PS grid of the vibrating bar.
        assert_eq!(ps.num_functions(), 42);
        // Two triangles leaning the same way: the centroid segment misses the edge.
        let v = [(0.0, 0.0), (1.0, 0.0), (3.0, 1.0), (2.5, -1.0)].map(|(x, y)| Vec2::new(x, y));
        let mesh = TriMesh::new(v.to_vec(), vec![[0, 1, 2], [1, 0, 3]]).unwrap();
        assert_eq!(
            PowellSabin::<f64>::new(mesh.clone(), SplitPoint::Centroid).unwrap_err(),
            BasisError::InvalidSplitPoint { t1: 0, t2: 1 }
        );
        assert!(PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).is_ok());
    }

    /// Whether `ps` on the block grid `[0, 4] × [0, 3]` is mirror-symmetric about
    /// the line `x = 2` (`axis = 0`) or `y = 1.5` (`axis = 1`): every function has a
    /// mirror image among the functions (the one whose control point is the
    /// mirrored one, at the mirrored vertex) with the mirrored values and
    /// gradients. `Err` names the first function that has none.
    fn mirror_symmetric(ps: &PowellSabin<f64>, axis: usize) -> Result<(), String> {
        let mirror = |p: Vec2| {
            let mut m = p;
            m[axis] = [4.0, 3.0][axis] - p[axis];
            m
        };
        symmetric_under(ps, [4.0, 3.0], mirror)
    }

    /// Whether `ps` on a grid of `size` is symmetric under the reflection
    /// `mirror` (see [`mirror_symmetric`]).
    fn symmetric_under(
        ps: &PowellSabin<f64>,
        size: [f64; 2],
        mirror: impl Fn(Vec2) -> Vec2,
    ) -> Result<(), String> {
        let vertices = ps.mesh().vertices();
        let mut image = Vec::with_capacity(ps.num_functions());
        for i in 0..ps.num_functions() {
            let v = i / 3;
            let w = vertices
                .iter()
                .position(|p| (p - mirror(vertices[v])).norm() < 1e-12)
                .ok_or(format!("vertex {v}: no mirror image"))?;
            let q = mirror(ps.function_point(i));
            image.push(
                (3 * w..3 * w + 3)
                    .find(|&j| (ps.function_point(j) - q).norm() < 1e-12)
                    .ok_or(format!("function {i} at vertex {v}: no mirror image"))?,
            );
        }
        let (mut a, mut b) = (BasisEval::for_basis(ps), BasisEval::for_basis(ps));
        for k in 0..400 {
            // A deterministic scatter over the domain (additive recurrence).
            let x = Vec2::new(
                size[0] * (0.5 + k as f64 * 0.618_033_988_749_895).fract(),
                size[1] * (0.5 + k as f64 * 0.754_877_666_246_693).fract(),
            );
            let (ea, eb) = (
                ps.locate(&x, None).unwrap(),
                ps.locate(&mirror(x), None).unwrap(),
            );
            ps.eval(ea, &x, &mut a);
            ps.eval(eb, &mirror(x), &mut b);
            for s in 0..a.len() {
                let j = image[a.index[s]];
                // On an edge the two points may lie in elements that do not share
                // every function: one absent there is zero with its gradient (C¹).
                let (phi_b, gb) = (0..b.len())
                    .find(|&t| b.index[t] == j)
                    .map_or((0.0, Vec2::zeros()), |t| (b.phi[t], b.grad_phi[t]));
                let ga = a.grad_phi[s];
                let gb = mirror(gb) - mirror(Vec2::zeros());
                if (a.phi[s] - phi_b).abs() >= 1e-13 || (ga - gb).norm() >= 1e-12 {
                    return Err(format!(
                        "function {} at {x:?}: {} {ga:?} against its image {j}: {} {gb:?}",
                        a.index[s], a.phi[s], phi_b
                    ));
                }
            }
        }
        Ok(())
    }

    /// A grid symmetric about a line has a basis symmetric about it. The interior
    /// vertices of the block grid (valence 8) have PS points symmetric about both
    /// axis-aligned lines, and a triangle keeps one: the vertical by default, the
    /// horizontal when asked for ([`MirrorAxis`]). Without the symmetric choice of
    /// `control_triangle::Mirror` those vertices get triangles leaning left or
    /// right, and a block dropped onto the middle of a floor comes back turning.
    #[test]
    fn a_mirror_symmetric_grid_has_a_basis_symmetric_about_the_axis_asked_for() {
        let mesh = generators::block_grid(0.0, 4.0, 0.0, 3.0, 4, 3).unwrap();
        let vertical = PowellSabin::<f64>::new(mesh.clone(), SplitPoint::Incentre).unwrap();
        let horizontal =
            PowellSabin::<f64>::with_mirror(mesh, SplitPoint::Incentre, MirrorAxis::Horizontal)
                .unwrap();
        mirror_symmetric(&vertical, 0).unwrap();
        mirror_symmetric(&horizontal, 1).unwrap();
        // Each keeps only its own line.
        assert!(mirror_symmetric(&vertical, 1).is_err());
        assert!(mirror_symmetric(&horizontal, 0).is_err());
    }

    /// A square block grid is symmetric about its diagonals too: with
    /// [`MirrorAxis::Diagonal`] (or `AntiDiagonal`) the basis keeps that line (two
    /// disks striking each other along the diagonal of a square). The block
    /// centres' control triangles come from `control_triangle`'s isosceles
    /// candidates, which the hull lines do not give there.
    #[test]
    fn a_square_grid_has_a_basis_symmetric_about_the_diagonal_asked_for() {
        let mesh = generators::block_grid(0.0, 3.0, 0.0, 3.0, 3, 3).unwrap();
        let diagonal = |p: Vec2| Vec2::new(p.y, p.x);
        let anti = |p: Vec2| Vec2::new(3.0 - p.y, 3.0 - p.x);
        for (axis, keeps) in [(MirrorAxis::Diagonal, 0), (MirrorAxis::AntiDiagonal, 1)] {
            let ps =
                PowellSabin::<f64>::with_mirror(mesh.clone(), SplitPoint::Incentre, axis).unwrap();
            let result = [
                symmetric_under(&ps, [3.0, 3.0], diagonal),
                symmetric_under(&ps, [3.0, 3.0], anti),
            ];
            if let Err(e) = &result[keeps] {
                panic!("{axis:?}: {e}");
            }
            assert!(result[1 - keeps].is_err(), "{axis:?}");
            let (pu, min) = (check::partition_of_unity(&ps), check::min_value(&ps));
            assert!(pu < 1e-12 && min > -1e-12, "{pu:e} {min:e}");
            assert!(check::linear_precision(&ps).0 < 1e-12);
        }
        let vertical = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
        assert!(symmetric_under(&vertical, [3.0, 3.0], diagonal).is_err());
    }

    #[test]
    fn f32_basis_is_a_partition_of_unity_to_single_precision() {
        let mesh =
            generators::jittered_lattice_delaunay(6, 6, (0.0, 1.0, 0.0, 1.0), 0.3, 9).unwrap();
        let ps = PowellSabin::<f32>::new(mesh, SplitPoint::Incentre).unwrap();
        let (pu, min) = (check::partition_of_unity(&ps), check::min_value(&ps));
        let lp = check::linear_precision(&ps).0;
        assert!(pu < 1e-6, "f32 partition of unity off by {pu:e}");
        // Single-precision ordinates and coordinates: ~1e-7 per term.
        assert!(min > -1e-5 && lp < 1e-6, "{min:e} {lp:e}");
    }
}
