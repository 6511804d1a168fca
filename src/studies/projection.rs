//! L² projection of a function onto a basis: benchmark B1 of the seeds
//! (thesis §3.6, paper §3.5 and Fig. 8).
//!
//! The projection `f_h = Σ_i c_i phi_i` of `f` solves `M c = b` with the Gram
//! ("mass") matrix `M_ij = ∫ phi_i phi_j dΩ` and `b_i = ∫ f phi_i dΩ`. With the
//! lumped option, `M` is replaced by its row sums `M_ii^L = Σ_j M_ij = ∫ phi_i dΩ`
//! (partition of unity), which is what lumped-mass MPM does to the momentum
//! projection; the paper's Fig. 8 shows that this costs the order of convergence
//! (first order in value for every basis, no convergence of `∂f/∂x` for PS).
//!
//! All integrals use a Gauss rule of [`QUADRATURE_DEGREE`] on every polynomial
//! piece of the basis (the six PS sub-triangles, the PL triangle), so quadrature
//! error is far below the projection error at every level of the study.

use crate::bases::{self, BasisKind};
use crate::sparse::{NotPositiveDefinite, Scalar, SparseCholesky, SymmetricPattern};
use nalgebra::Vector2;
use psmpm_basis::mesh::generators;
use psmpm_basis::quadrature::TriangleRule;
use psmpm_basis::{Basis, BasisEval, TriMesh, Vec2};
use serde::Serialize;

/// Polynomial degree of the triangle rule used for the projection integrals.
/// `phi_i phi_j` has degree 4 for PS; the rest of the degree resolves `sin(πx) sin(πy)`
/// on the coarsest level (sub-triangles of size 1/4) to well below the projection error.
pub const QUADRATURE_DEGREE: usize = 14;

/// How the Gram matrix is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MassOption {
    /// The full matrix `M_ij = ∫ phi_i phi_j`, solved with sparse Cholesky.
    Consistent,
    /// Row sums `M_ii = ∫ phi_i` on the diagonal.
    Lumped,
}

impl MassOption {
    /// Name used on the command line and in output.
    pub fn name(self) -> &'static str {
        match self {
            MassOption::Consistent => "consistent",
            MassOption::Lumped => "lumped",
        }
    }
}

/// Why a projection failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectionError {
    #[error(
        "the Gram matrix is not positive definite (non-positive pivot at row {} of the reordered matrix)",
        .0.row
    )]
    NotPositiveDefinite(#[from] NotPositiveDefinite),
    #[error("function {function} has zero integral ∫ phi = {integral:e}; cannot lump")]
    ZeroLumpedRow { function: usize, integral: f64 },
}

/// A scalar field on the plane with its x-derivative, to project and to measure errors against.
pub trait Field2 {
    /// `f(x)`.
    fn value(&self, x: Vec2) -> f64;
    /// `∂f/∂x(x)`.
    fn dx(&self, x: Vec2) -> f64;
}

/// `f(x, y) = sin(πx) sin(πy)`, the function of benchmark B1.
#[derive(Debug, Clone, Copy, Default)]
pub struct SineProduct;

impl Field2 for SineProduct {
    fn value(&self, x: Vec2) -> f64 {
        (std::f64::consts::PI * x.x).sin() * (std::f64::consts::PI * x.y).sin()
    }
    fn dx(&self, x: Vec2) -> f64 {
        let pi = std::f64::consts::PI;
        pi * (pi * x.x).cos() * (pi * x.y).sin()
    }
}

/// Visits every quadrature point of every polynomial piece of `basis`:
/// `visit(element, x, weight)` with `Σ weight = area`.
fn for_each_quadrature_point<T: Scalar, B: Basis<T, 2> + ?Sized>(
    basis: &B,
    rule: &TriangleRule,
    mut visit: impl FnMut(usize, Vec2, f64),
) {
    let mut pieces: Vec<Vector2<f64>> = Vec::with_capacity(18);
    for e in 0..basis.num_elements() {
        pieces.clear();
        basis.polynomial_pieces(e, &mut pieces);
        for piece in pieces.chunks_exact(3) {
            let (a, b, c) = (piece[0], piece[1], piece[2]);
            let area = 0.5 * ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y)).abs();
            for (bary, w) in rule.bary.iter().zip(&rule.weights) {
                let x = a * bary[0] + b * bary[1] + c * bary[2];
                visit(e, x, w * area);
            }
        }
    }
}

/// L² projection of `f` onto `basis`: the coefficients `c` of `f_h = Σ c_i phi_i`.
///
/// Consistent: `M c = b` (thesis eq. (3.24)); lumped: `c_i = b_i / Σ_j M_ij`.
pub fn project<T: Scalar, B: Basis<T, 2> + ?Sized>(
    basis: &B,
    f: &impl Field2,
    mass: MassOption,
) -> Result<Vec<T>, ProjectionError> {
    let rule = TriangleRule::with_degree(QUADRATURE_DEGREE);
    let pattern = SymmetricPattern::new(basis);
    let n = basis.num_functions();
    let mut values = vec![T::zero(); pattern.nnz()];
    let mut rhs = vec![T::zero(); n];
    let mut eval = BasisEval::<T, 2>::for_basis(basis);
    for_each_quadrature_point(basis, &rule, |e, x, w| {
        let xt = Vector2::new(T::of(x.x), T::of(x.y));
        basis.eval(e, &xt, &mut eval);
        let (w, fx) = (T::of(w), T::of(f.value(x)));
        let scatter = pattern.element_scatter(e);
        let m = basis.element_functions(e).len();
        debug_assert_eq!(&eval.index[..eval.len()], basis.element_functions(e));
        for a in 0..m {
            let wa = w * eval.phi[a];
            rhs[eval.index[a]] += wa * fx;
            // Upper triangle: each unordered pair of local functions once.
            for b in a..m {
                values[scatter[a * m + b] as usize] += wa * eval.phi[b];
            }
        }
    });
    match mass {
        MassOption::Consistent => {
            let mut cholesky = SparseCholesky::<T>::new(&pattern, 1);
            cholesky.factorize(&values)?;
            cholesky.solve_in_place(&mut rhs, 1);
            Ok(rhs)
        }
        MassOption::Lumped => {
            let mut lumped = vec![T::zero(); n];
            pattern.row_sums(&values, &mut lumped);
            for (i, (c, m)) in rhs.iter_mut().zip(&lumped).enumerate() {
                if *m <= T::zero() {
                    return Err(ProjectionError::ZeroLumpedRow {
                        function: i,
                        integral: m.to_f64(),
                    });
                }
                *c /= *m;
            }
            Ok(rhs)
        }
    }
}

/// L² errors `(‖f − f_h‖, ‖∂f/∂x − ∂f_h/∂x‖)` of `f_h = Σ c_i phi_i`, accumulated in f64.
pub fn l2_errors<T: Scalar, B: Basis<T, 2> + ?Sized>(
    basis: &B,
    coefficients: &[T],
    f: &impl Field2,
) -> (f64, f64) {
    let rule = TriangleRule::with_degree(QUADRATURE_DEGREE);
    let mut eval = BasisEval::<T, 2>::for_basis(basis);
    let (mut e0, mut e1) = (0.0, 0.0);
    for_each_quadrature_point(basis, &rule, |e, x, w| {
        let xt = Vector2::new(T::of(x.x), T::of(x.y));
        basis.eval(e, &xt, &mut eval);
        let (mut fh, mut fh_dx) = (0.0, 0.0);
        for (i, phi, grad) in eval.iter() {
            let c = coefficients[i].to_f64();
            fh += c * phi.to_f64();
            fh_dx += c * grad.x.to_f64();
        }
        e0 += w * (f.value(x) - fh).powi(2);
        e1 += w * (f.dx(x) - fh_dx).powi(2);
    });
    (e0.sqrt(), e1.sqrt())
}

/// Largest number of refinement levels of the study (PS n = 65, PL n = 129).
pub const MAX_LEVELS: usize = 6;

/// One row of the projection study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudyRow {
    /// Basis name (`ps`, `pl`).
    pub basis: &'static str,
    /// Mass option (`consistent`, `lumped`).
    pub mass: &'static str,
    /// Vertices per side of the unit-square lattice (`None` for a given mesh).
    pub n: Option<usize>,
    /// Number of basis functions.
    pub functions: usize,
    /// `‖f − f_h‖_L²`.
    pub error: f64,
    /// `‖∂f/∂x − ∂f_h/∂x‖_L²`.
    pub error_dx: f64,
    /// Observed order `log(E_prev / E) / log(h_prev / h)` against the previous level.
    pub order: Option<f64>,
    /// The same for `error_dx`.
    pub order_dx: Option<f64>,
    /// Wall time of mesh generation, basis construction, assembly and solve
    /// (not of error evaluation).
    pub seconds: f64,
}

/// Why a study failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StudyError {
    #[error(transparent)]
    Mesh(#[from] psmpm_basis::MeshError),
    #[error(transparent)]
    Basis(#[from] psmpm_basis::BasisError),
    #[error(transparent)]
    Projection(#[from] ProjectionError),
    #[error("{0}")]
    Parameter(String),
}

/// The lattice sizes `n` (vertices per side) of the thesis' tables 3.1–3.2, extended:
/// PS 3, 5, 9, 17, 33, 65 and PL 5, 9, 17, 33, 65, 129 (PL one level finer, since a
/// PS basis has three functions per vertex). Returns the first `count` of them.
pub fn default_levels(kind: BasisKind, count: usize) -> Result<Vec<usize>, StudyError> {
    if count == 0 || count > MAX_LEVELS {
        return Err(StudyError::Parameter(format!(
            "levels must be between 1 and {MAX_LEVELS}, got {count}"
        )));
    }
    let first_exponent = match kind {
        BasisKind::Ps => 1,
        BasisKind::Pl => 2,
        other => {
            return Err(StudyError::Parameter(format!(
                "the projection study is two-dimensional; basis `{}` is not",
                other.name()
            )))
        }
    };
    Ok((0..count)
        .map(|k| (1usize << (first_exponent + k)) + 1)
        .collect())
}

/// Measured outcome of one projection.
struct Measured {
    functions: usize,
    error: f64,
    error_dx: f64,
    /// From `start` (before mesh and basis construction) to the solved coefficients.
    seconds: f64,
}

/// Projects [`SineProduct`] onto `basis` and measures the errors.
fn project_and_measure<T: Scalar, B: Basis<T, 2>>(
    basis: &B,
    mass: MassOption,
    start: std::time::Instant,
) -> Result<Measured, StudyError> {
    let c = project(basis, &SineProduct, mass)?;
    let seconds = start.elapsed().as_secs_f64();
    let (error, error_dx) = l2_errors(basis, &c, &SineProduct);
    Ok(Measured {
        functions: basis.num_functions(),
        error,
        error_dx,
        seconds,
    })
}

/// Builds `kind` on `mesh`, projects and measures.
fn run_on_mesh<T: Scalar>(
    kind: BasisKind,
    mass: MassOption,
    mesh: TriMesh,
    start: std::time::Instant,
) -> Result<Measured, StudyError> {
    match kind {
        BasisKind::Ps => project_and_measure(&bases::powell_sabin::<T>(mesh)?, mass, start),
        BasisKind::Pl => project_and_measure(&bases::linear::<T>(mesh)?, mass, start),
        other => Err(StudyError::Parameter(format!(
            "the projection study is two-dimensional; basis `{}` is not",
            other.name()
        ))),
    }
}

/// The B1 study on the unit square: the Delaunay triangulation of the `n × n` lattice
/// for each `n` of `levels`, with observed orders between consecutive levels
/// (`h = 1/(n − 1)`).
pub fn unit_square_study<T: Scalar>(
    kind: BasisKind,
    mass: MassOption,
    levels: &[usize],
) -> Result<Vec<StudyRow>, StudyError> {
    let mut rows: Vec<StudyRow> = Vec::with_capacity(levels.len());
    for &n in levels {
        if n < 2 {
            return Err(StudyError::Parameter(format!(
                "a lattice needs at least 2 vertices per side, got {n}"
            )));
        }
        let start = std::time::Instant::now();
        let mesh = generators::lattice_delaunay(n, 0.0, 1.0, 0.0, 1.0)?;
        let Measured {
            functions,
            error,
            error_dx,
            seconds,
        } = run_on_mesh::<T>(kind, mass, mesh, start)?;
        let order_against = |prev: &StudyRow, e: f64, e_prev: f64| {
            let (h_prev, h) = (1.0 / (prev.n? as f64 - 1.0), 1.0 / (n as f64 - 1.0));
            Some((e_prev / e).ln() / (h_prev / h).ln())
        };
        let (order, order_dx) = match rows.last() {
            Some(prev) => (
                order_against(prev, error, prev.error),
                order_against(prev, error_dx, prev.error_dx),
            ),
            None => (None, None),
        };
        rows.push(StudyRow {
            basis: kind.name(),
            mass: mass.name(),
            n: Some(n),
            functions,
            error,
            error_dx,
            order,
            order_dx,
            seconds,
        });
    }
    Ok(rows)
}

/// The projection on a given mesh (one level, no orders). `seconds` excludes reading the mesh.
pub fn mesh_study<T: Scalar>(
    kind: BasisKind,
    mass: MassOption,
    mesh: TriMesh,
) -> Result<StudyRow, StudyError> {
    let m = run_on_mesh::<T>(kind, mass, mesh, std::time::Instant::now())?;
    Ok(StudyRow {
        basis: kind.name(),
        mass: mass.name(),
        n: None,
        functions: m.functions,
        error: m.error,
        error_dx: m.error_dx,
        order: None,
        order_dx: None,
        seconds: m.seconds,
    })
}
