//! The [`Basis`] trait and its implementations.
//!
//! A basis is a finite set of functions `phi_i` on a mesh, each non-zero on a
//! few elements (its support). The MPM driver and the projection study only
//! ever talk to a basis through this trait, so swapping piecewise-linear for
//! Powell–Sabin changes no line of the driver.
//!
//! | implementation | dim | functions | continuity |
//! |---|---|---|---|
//! | [`linear::Linear`] | 2 | one per vertex | C⁰ |
//! | [`powell_sabin::PowellSabin`] | 2 | three per vertex | C¹ |
//! | [`linear1d::Linear1d`] | 1 | one per node | C⁰ |
//! | [`bspline1d::QuadraticBSpline`] | 1 | nodes + 1 | C¹ |
//!
//! Evaluation writes into a caller-owned [`BasisEval`] sized once from
//! [`Basis::max_functions_per_element`]; nothing allocates per call.

pub mod bspline1d;
pub mod linear;
pub mod linear1d;
pub mod powell_sabin;

use crate::scalar::Real;
use nalgebra::SVector;

/// A point (or gradient) in `D` dimensions in scalar type `T`.
pub type Point<T, const D: usize> = SVector<T, D>;

/// Values and gradients of the functions non-zero at one point, written by
/// [`Basis::eval`]. Entries `0..len()` are valid; the buffers keep their capacity.
#[derive(Debug, Clone)]
pub struct BasisEval<T: Real, const D: usize> {
    len: usize,
    /// Global function indices.
    pub index: Vec<usize>,
    /// Values `phi_i(x)`.
    pub phi: Vec<T>,
    /// Gradients `grad phi_i(x)`.
    pub grad_phi: Vec<Point<T, D>>,
    /// What the basis keeps between evaluations in one element
    /// ([`Basis::element_cache_len`]).
    pub cache: ElementCache<T>,
}

impl<T: Real, const D: usize> BasisEval<T, D> {
    /// A buffer for up to `capacity` functions per point.
    pub fn with_capacity(capacity: usize) -> Self {
        BasisEval {
            len: 0,
            index: vec![0; capacity],
            phi: vec![T::zero(); capacity],
            grad_phi: vec![Point::<T, D>::zeros(); capacity],
            cache: ElementCache::default(),
        }
    }
    /// A buffer sized for `basis`, with room for its [`ElementCache`].
    pub fn for_basis<B: Basis<T, D> + ?Sized>(basis: &B) -> Self {
        let mut eval = Self::with_capacity(basis.max_functions_per_element());
        eval.cache = ElementCache::with_len(basis.element_cache_len());
        eval
    }
    /// Number of valid entries.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }
    /// `true` when no entry is valid.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Sets the number of valid entries (implementations of [`Basis::eval`] call this).
    ///
    /// # Panics
    /// If `len` exceeds the capacity: the basis under-reported its maximum support.
    #[inline]
    pub fn set_len(&mut self, len: usize) {
        assert!(len <= self.index.len(), "BasisEval capacity exceeded");
        self.len = len;
    }
    /// `(index, phi, grad_phi)` for each valid entry.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = (usize, T, &Point<T, D>)> + '_ {
        (0..self.len).map(move |k| (self.index[k], self.phi[k], &self.grad_phi[k]))
    }
}

/// Data a basis derives from its stored element data once per element and reuses
/// for the next points of the same element (the PS pieces' monomials, derived from
/// the Bézier ordinates): the driver evaluates the particles element by element, so
/// the data is derived once for all of an element's particles. Held in parts
/// (the PS sub-triangles), each derived on first use; the key is the basis (an id
/// its constructor draws, [`ElementCache::new_owner`]) and the element. Empty
/// (no room) for a buffer made by [`BasisEval::with_capacity`]: the basis then
/// derives what it needs at every point, with the same result.
#[derive(Debug, Clone, Default)]
pub struct ElementCache<T> {
    owner: u64,
    element: usize,
    ready: u64,
    data: Vec<T>,
}

impl<T: Real> ElementCache<T> {
    /// Room for `len` values.
    pub fn with_len(len: usize) -> Self {
        ElementCache {
            owner: 0,
            element: usize::MAX,
            ready: 0,
            data: vec![T::zero(); len],
        }
    }

    /// A fresh owner id for a basis's cached data (never 0, never repeated in a
    /// process), so that a buffer used with two bases never mixes their data.
    pub fn new_owner() -> u64 {
        use std::sync::atomic::{AtomicU64, Ordering};
        static NEXT: AtomicU64 = AtomicU64::new(1);
        NEXT.fetch_add(1, Ordering::Relaxed)
    }

    /// Part `part` (`len` values, `part < 64`) of the data of `owner`'s `element`:
    /// written by `derive` on first use since the buffer last held another element;
    /// `None` when the buffer has no room for it.
    #[inline]
    pub fn part(
        &mut self,
        owner: u64,
        element: usize,
        part: usize,
        len: usize,
        derive: impl FnOnce(&mut [T]),
    ) -> Option<&[T]> {
        let range = part * len..(part + 1) * len;
        if range.end > self.data.len() || part >= 64 {
            return None;
        }
        if self.owner != owner || self.element != element {
            (self.owner, self.element, self.ready) = (owner, element, 0);
        }
        let data = &mut self.data[range];
        if self.ready & (1 << part) == 0 {
            derive(data);
            self.ready |= 1 << part;
        }
        Some(data)
    }
}

/// One linear constraint on the coefficients `c_i ∈ R^D` of a vector field
/// `v = Σ_i c_i phi_i`: `Σ_k weight_k · (direction · c_{function_k}) = 0`.
///
/// Homogeneous Dirichlet conditions are sets of such constraints
/// ([`Basis::dirichlet`]). Most are single-term (`c_i · n = 0`), which the driver
/// applies by zeroing a component.
#[derive(Debug, Clone, PartialEq)]
pub struct Constraint<T: Real, const D: usize> {
    /// Unit vector `n`: the component `n · v` is constrained.
    pub direction: Point<T, D>,
    /// `(function, weight)` pairs.
    pub terms: Vec<(usize, T)>,
}

impl<T: Real, const D: usize> Constraint<T, D> {
    /// `true` for a constraint `c_i · n = 0` on a single function.
    pub fn is_single(&self) -> bool {
        self.terms.len() == 1
    }
}

/// A polynomial of degree at most two about a centre `m`:
/// `q(x) = c + g · (x − m) + (x − m)ᵀ A (x − m)` (`A` symmetric; the centre keeps
/// round-off relative to the mesh, not to `|x|`). What [`Basis::dual_value`]
/// expands in a basis, and what the quadratic-precision check reproduces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quadratic<const D: usize> {
    /// The centre `m`.
    pub centre: Point<f64, D>,
    /// Value at the centre.
    pub c: f64,
    /// Gradient at the centre.
    pub g: Point<f64, D>,
    /// Half the Hessian (symmetric).
    pub a: nalgebra::SMatrix<f64, D, D>,
}

impl<const D: usize> Quadratic<D> {
    /// `q(x)`.
    pub fn value(&self, x: &Point<f64, D>) -> f64 {
        let d = x - self.centre;
        self.c + self.g.dot(&d) + d.dot(&(self.a * d))
    }
    /// `∇q(x) = g + 2 A (x − m)`.
    pub fn gradient(&self, x: &Point<f64, D>) -> Point<f64, D> {
        self.g + self.a * (x - self.centre) * 2.0
    }
    /// The polar form (blossom) `c + g · ((u + v)/2 − m) + (u − m)ᵀ A (v − m)`:
    /// symmetric, affine in each argument, `polar(x, x) = q(x)`.
    pub fn polar(&self, u: &Point<f64, D>, v: &Point<f64, D>) -> f64 {
        let (du, dv) = (u - self.centre, v - self.centre);
        self.c + self.g.dot(&(du + dv)) * 0.5 + du.dot(&(self.a * dv))
    }
}

/// Errors of basis construction and queries.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BasisError {
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    #[error("the centroid split point is not valid on this mesh: the line between the centroids of triangles {t1} and {t2} does not cross their common edge; use incentres")]
    InvalidSplitPoint { t1: usize, t2: usize },
    #[error("the Powell–Sabin refinement cannot be built on this mesh: the line between the incentres of triangles {t1} and {t2} crosses their common edge at or next to one of its ends, which a sliver (a triangle of almost no area, a vertex nearly on the opposite edge) does; remesh without slivers (Gmsh: `Mesh.Optimize = 1`, or move the stray vertex), or use the `pl` basis, which takes them")]
    SliverSplit { t1: usize, t2: usize },
    #[error("no control triangle found for vertex {vertex}")]
    NoControlTriangle { vertex: usize },
    #[error("the Powell–Sabin functions of triangle {triangle} are not finite: its geometry or a control triangle of its vertices is degenerate (a triangle of almost no area); remesh without it, or use the `pl` basis")]
    NonFiniteElement { triangle: usize },
    #[error("invalid basis parameter: {0}")]
    InvalidParameter(String),
}

/// A finite-dimensional function space on a mesh in `D` dimensions, evaluated in
/// scalar type `T`.
///
/// Elements are the mesh cells (triangles, or intervals in 1D). Functions are
/// numbered `0..num_functions()`. Properties every implementation satisfies
/// (and the test suites check): partition of unity `Σ_i phi_i = 1`,
/// non-negativity, linear precision `Σ_i X_i phi_i = x` with the
/// [`function_point`](Basis::function_point)s `X_i`.
pub trait Basis<T: Real, const D: usize>: Sync {
    /// Short name for output (`"pl"`, `"ps"`, `"bspline"`, `"pl1d"`).
    fn name(&self) -> &'static str;
    /// Number of basis functions.
    fn num_functions(&self) -> usize;
    /// Number of elements.
    fn num_elements(&self) -> usize;
    /// Largest number of functions non-zero on one element (the [`BasisEval`] capacity).
    fn max_functions_per_element(&self) -> usize;
    /// Values the basis keeps in an [`ElementCache`] between evaluations in one
    /// element (0: none).
    fn element_cache_len(&self) -> usize {
        0
    }
    /// The element containing `x`, starting the search at `hint` (e.g. a particle's
    /// previous element). `None` when `x` lies outside the mesh.
    fn locate(&self, x: &Point<T, D>, hint: Option<usize>) -> Option<usize>;
    /// Calls `visit` with every element other than `element` whose closure holds
    /// `x` (which lies in `element`) up to round-off: a point on a shared edge,
    /// vertex or node lies in every element around it, and
    /// [`locate`](Basis::locate) picks one of them by round-off. Decisions that
    /// depend on which elements hold particles (empty elements, the particles that
    /// pin an affine field) count the point in all of them, so that they do not
    /// depend on that choice (a mirror-symmetric scene stays symmetric on any grid).
    fn other_elements_at(&self, element: usize, x: &Point<T, D>, visit: &mut dyn FnMut(usize));
    /// Writes index, value and gradient of every function non-zero on `element`
    /// at `x` (which must lie in the element, up to round-off) into `out`.
    fn eval(&self, element: usize, x: &Point<T, D>, out: &mut BasisEval<T, D>);
    /// The functions non-zero on `element`, in the order in which [`eval`](Basis::eval)
    /// writes them (assembly relies on it).
    fn element_functions(&self, element: usize) -> &[usize];
    /// The elements forming the support of `function`.
    fn function_support(&self, function: usize) -> &[usize];
    /// The point identifying `function` for output and for linear precision
    /// (the vertex for Lagrange bases, the control point for PS, the Greville
    /// abscissa for B-splines).
    fn function_point(&self, function: usize) -> Point<f64, D>;
    /// Names of the boundary tags the basis knows.
    fn boundary_tags(&self) -> Vec<String>;
    /// Linear constraints making the component `direction · v` of any vector
    /// field `v = Σ c_i phi_i` vanish identically on the boundary tagged `tag`.
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, D>,
    ) -> Result<Vec<Constraint<T, D>>, BasisError>;
    /// Appends to `out` the simplices (`D + 1` points each) of `element` on each of
    /// which every function is a polynomial: the quadrature cells (the six PS
    /// sub-triangles, or the element itself).
    fn polynomial_pieces(&self, element: usize, out: &mut Vec<Point<f64, D>>);
    /// Polynomial degree of the functions on each piece.
    fn degree(&self) -> usize;
    /// The coefficient `λ_i(p)` of `function` in the expansion `p = Σ_i λ_i(p) phi_i`
    /// of a polynomial `p` of degree at most [`degree`](Basis::degree) (which the
    /// basis reproduces), where the basis has it in closed form: the value at the
    /// vertex for Lagrange bases, the tangent plane at the vertex evaluated at the
    /// control point for Powell–Sabin, the blossom at the interior knots for
    /// B-splines. `None` (the default) leaves it to the caller, which projects `p`
    /// onto the basis.
    fn dual_value(&self, function: usize, p: &Quadratic<D>) -> Option<f64> {
        let _ = (function, p);
        None
    }
}
