//! The properties every basis must satisfy, written once, generic over
//! [`Basis<T, D>`](Basis) (any scalar type, 1D and 2D), and run on every basis
//! (PL, PS, 1D PL, 1D B-spline) and the same families of meshes by the test suite
//! (`check/suite.rs`, test builds only).
//!
//! Each check returns the measured worst violation, so the suite states each basis'
//! tolerance next to the property (and a failing test prints how far off it was):
//! - [`partition_of_unity`]: `max |Σ_i phi_i(x) − 1|`;
//! - [`min_value`]: `min phi_i(x)` (non-negativity wants it ≥ −round-off);
//! - [`linear_precision`]: `max |Σ_i X_i phi_i(x) − x|` with the function points
//!   `X_i`, and the same for the gradients, `max |Σ_i X_i ⊗ ∇phi_i − I|`;
//! - [`quadratic_precision`]: the same for quadratic polynomials, with coefficients
//!   the basis provides (for bases of degree 2);
//! - [`gradient_error`]: `max |∇phi_i − central difference|`, relative to `max |∇phi|`;
//! - [`continuity_jumps`]: the largest jumps of values and gradients across the
//!   boundaries between elements (C⁰ bases show gradient jumps, C¹ bases none);
//! - [`dirichlet_residual`], [`constrained_residual`]: `max |n · v|` along a wall
//!   for a random field `v` whose coefficients satisfy the wall's constraints.
//!
//! Sample points are deterministic: fixed barycentric points in every polynomial
//! piece ([`Basis::polynomial_pieces`]), at its corners, edge midpoints and inside.

pub use crate::basis::Quadratic;
use crate::basis::{Basis, BasisEval, Constraint, Point};
use crate::rng::SplitMix64;
use crate::scalar::Real;
use nalgebra::{DMatrix, DVector, SMatrix, SVector};

/// Barycentric sample points inside a piece, at least 0.1 from its boundary:
/// `(1D, 2D)`.
const INTERIOR_1D: [[f64; 2]; 4] = [[0.9, 0.1], [0.63, 0.37], [0.5, 0.5], [0.1, 0.9]];
const INTERIOR_2D: [[f64; 3]; 7] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [0.6, 0.2, 0.2],
    [0.2, 0.6, 0.2],
    [0.15, 0.15, 0.7],
    [0.7, 0.2, 0.1],
    [0.1, 0.7, 0.2],
    [0.2, 0.1, 0.7],
];
/// Barycentric sample points on the boundary of a piece: corners (and in 2D edge
/// midpoints).
const BOUNDARY_1D: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];
const BOUNDARY_2D: [[f64; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.5, 0.0],
    [0.0, 0.5, 0.5],
    [0.5, 0.0, 0.5],
];

/// The barycentric sample points of a `d`-simplex: inside, and also on its boundary
/// when `boundary`.
///
/// # Panics
/// For `d` other than 1 and 2 (the dimensions of the bases).
fn samples(d: usize, boundary: bool) -> Vec<&'static [f64]> {
    let mut out: Vec<&'static [f64]> = match d {
        1 => INTERIOR_1D.iter().map(|b| &b[..]).collect(),
        2 => INTERIOR_2D.iter().map(|b| &b[..]).collect(),
        _ => panic!("the checks sample 1D and 2D pieces, not {d}D"),
    };
    if boundary {
        match d {
            1 => out.extend(BOUNDARY_1D.iter().map(|b| &b[..])),
            _ => out.extend(BOUNDARY_2D.iter().map(|b| &b[..])),
        }
    }
    out
}

/// Barycentric sample points of a facet with `m` corners (a point or a segment).
fn facet_samples(m: usize) -> Vec<Vec<f64>> {
    match m {
        1 => vec![vec![1.0]],
        _ => [0.25, 0.5, 0.75]
            .iter()
            .map(|&w| {
                let mut b = vec![0.0; m];
                b[0] = 1.0 - w;
                b[1] = w;
                b
            })
            .collect(),
    }
}

/// The unit vector `e_1`.
fn first_axis<const D: usize>() -> Point<f64, D> {
    Point::<f64, D>::from_fn(|r, _| if r == 0 { 1.0 } else { 0.0 })
}

fn to_t<T: Real, const D: usize>(x: &Point<f64, D>) -> Point<T, D> {
    x.map(T::of)
}

fn to_f64<T: Real, const D: usize>(x: &Point<T, D>) -> Point<f64, D> {
    x.map(|v| v.to_f64())
}

/// `(k − 1)`-dimensional volume of the simplex with the `k` corners `p` (1 for a point).
fn simplex_volume<const D: usize>(p: &[Point<f64, D>]) -> f64 {
    let k = p.len() - 1;
    if k == 0 {
        return 1.0;
    }
    let e = DMatrix::from_fn(D, k, |r, c| p[c + 1][r] - p[0][r]);
    let factorial: f64 = (1..=k).map(|i| i as f64).product();
    (e.transpose() * e).determinant().max(0.0).sqrt() / factorial
}

/// A polynomial piece: corners, diameter and smallest height.
struct Piece<const D: usize> {
    corners: Vec<Point<f64, D>>,
    diam: f64,
    min_height: f64,
}

impl<const D: usize> Piece<D> {
    fn new(corners: &[Point<f64, D>]) -> Self {
        let mut diam = 0.0f64;
        for (i, a) in corners.iter().enumerate() {
            for b in &corners[i + 1..] {
                diam = diam.max((a - b).norm());
            }
        }
        let volume = simplex_volume(corners);
        let min_height = (0..corners.len())
            .map(|k| {
                let facet: Vec<_> = (0..corners.len())
                    .filter(|&j| j != k)
                    .map(|j| corners[j])
                    .collect();
                D as f64 * volume / simplex_volume(&facet)
            })
            .fold(f64::INFINITY, f64::min);
        Piece {
            corners: corners.to_vec(),
            diam,
            min_height,
        }
    }

    fn point(&self, bary: &[f64]) -> Point<f64, D> {
        self.corners
            .iter()
            .zip(bary)
            .fold(Point::<f64, D>::zeros(), |x, (p, w)| x + p * *w)
    }

    /// Barycentric coordinates of `x`.
    fn barycentric(&self, x: &Point<f64, D>) -> Vec<f64> {
        let p = &self.corners;
        let e = DMatrix::from_fn(D, D, |r, c| p[c + 1][r] - p[0][r]);
        let rhs = DVector::from_fn(D, |r, _| x[r] - p[0][r]);
        let l = e.lu().solve(&rhs).unwrap_or_else(|| DVector::zeros(D));
        let mut out = vec![1.0 - l.sum()];
        out.extend(l.iter());
        out
    }

    /// Unit vector across the facet opposite corner `k`, pointing out of the piece.
    fn outward_normal(&self, k: usize) -> Point<f64, D> {
        let facet: Vec<_> = (0..self.corners.len())
            .filter(|&j| j != k)
            .map(|j| self.corners[j])
            .collect();
        let mut n = facet[0] - self.corners[k];
        let mut basis: Vec<Point<f64, D>> = Vec::new();
        for q in &facet[1..] {
            let mut u = q - facet[0];
            for b in &basis {
                u -= b * b.dot(&u);
            }
            basis.push(u.normalize());
        }
        for b in &basis {
            n -= b * b.dot(&n);
        }
        n.normalize()
    }
}

/// The polynomial pieces of `element`.
fn pieces<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(
    basis: &B,
    element: usize,
) -> Vec<Piece<D>> {
    let mut corners = Vec::new();
    basis.polynomial_pieces(element, &mut corners);
    corners.chunks_exact(D + 1).map(Piece::new).collect()
}

/// Calls `visit(element, x, piece)` for every sample point (inside the pieces, and
/// also on their boundaries when `boundary`).
fn for_each_sample<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(
    basis: &B,
    boundary: bool,
    mut visit: impl FnMut(usize, Point<f64, D>, &Piece<D>),
) {
    let bary = samples(D, boundary);
    for e in 0..basis.num_elements() {
        for piece in pieces(basis, e) {
            for b in &bary {
                visit(e, piece.point(b), &piece);
            }
        }
    }
}

/// `max |Σ_i phi_i(x) − 1|` over the sample points.
pub fn partition_of_unity<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> f64 {
    let mut eval = BasisEval::for_basis(basis);
    let mut worst = 0.0f64;
    for_each_sample(basis, true, |e, x, _| {
        basis.eval(e, &to_t(&x), &mut eval);
        let sum: f64 = eval.iter().map(|(_, phi, _)| phi.to_f64()).sum();
        worst = worst.max((sum - 1.0).abs());
    });
    worst
}

/// `min_i phi_i(x)` over the sample points.
pub fn min_value<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> f64 {
    let mut eval = BasisEval::for_basis(basis);
    let mut worst = f64::INFINITY;
    for_each_sample(basis, true, |e, x, _| {
        basis.eval(e, &to_t(&x), &mut eval);
        for (_, phi, _) in eval.iter() {
            worst = worst.min(phi.to_f64());
        }
    });
    worst
}

/// `max |Σ_i X_i phi_i(x) − x|` over the sample points, and `max |Σ_i X_i ⊗ ∇phi_i − I|`.
pub fn linear_precision<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> (f64, f64) {
    let mut eval = BasisEval::for_basis(basis);
    let (mut worst, mut worst_grad) = (0.0f64, 0.0f64);
    for_each_sample(basis, true, |e, x, _| {
        basis.eval(e, &to_t(&x), &mut eval);
        let mut sum = Point::<f64, D>::zeros();
        let mut jac = SMatrix::<f64, D, D>::zeros();
        for (i, phi, grad) in eval.iter() {
            let xi = basis.function_point(i);
            sum += xi * phi.to_f64();
            jac += xi * to_f64(grad).transpose();
        }
        worst = worst.max((sum - x).norm());
        worst_grad = worst_grad.max((jac - SMatrix::<f64, D, D>::identity()).norm());
    });
    (worst, worst_grad)
}

/// The extent of the mesh: centre and half the diagonal of the bounding box of all
/// pieces.
fn extent<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> (Point<f64, D>, f64) {
    let mut corners = Vec::new();
    for e in 0..basis.num_elements() {
        basis.polynomial_pieces(e, &mut corners);
    }
    let lo = corners.iter().fold(corners[0], |m, p| m.inf(p));
    let hi = corners.iter().fold(corners[0], |m, p| m.sup(p));
    ((lo + hi) * 0.5, (hi - lo).norm() * 0.5)
}

/// Quadratic precision: for every product `q = (x_i − m_i)(x_j − m_j) / s²` (`m` the
/// centre of the mesh's bounding box, `s` half its diagonal, so `|q| ≤ 1`), the field
/// `Σ_k λ_k(q) phi_k` with the basis's dual values ([`Basis::dual_value`]: Hermite
/// data at the vertices for PS, the polar form at the knots for B-splines) against
/// `q`: `max |Σ c φ − q|` and `s · max |Σ c ∇φ − ∇q|` over the sample points.
///
/// # Panics
/// If the basis gives no dual value for a function.
pub fn quadratic_precision<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(
    basis: &B,
) -> (f64, f64) {
    let (m, s) = extent(basis);
    let mut eval = BasisEval::for_basis(basis);
    let (mut worst, mut worst_grad) = (0.0f64, 0.0f64);
    for i in 0..D {
        for j in i..D {
            let mut a = SMatrix::<f64, D, D>::zeros();
            a[(i, j)] += 0.5 / (s * s);
            a[(j, i)] += 0.5 / (s * s);
            let q = Quadratic {
                centre: m,
                c: 0.0,
                g: SVector::zeros(),
                a,
            };
            let c: Vec<f64> = (0..basis.num_functions())
                .map(|k| basis.dual_value(k, &q).expect("a basis with dual values"))
                .collect();
            for_each_sample(basis, true, |e, x, _| {
                basis.eval(e, &to_t(&x), &mut eval);
                let mut value = 0.0;
                let mut grad = SVector::<f64, D>::zeros();
                for (k, phi, dphi) in eval.iter() {
                    value += c[k] * phi.to_f64();
                    grad += to_f64(dphi) * c[k];
                }
                worst = worst.max((value - q.value(&x)).abs());
                worst_grad = worst_grad.max((grad - q.gradient(&x)).norm() * s);
            });
        }
    }
    (worst, worst_grad)
}

/// Largest difference between analytic gradients and central differences, relative
/// to the largest gradient seen. The step is `1e-4 ·` the piece's smallest height, so
/// from the interior sample points it stays inside the piece, where every function
/// is a polynomial of degree ≤ 2 and central differences are exact up to round-off,
/// whatever the shape of the piece.
pub fn gradient_error<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> f64 {
    let n = basis.max_functions_per_element();
    let (mut e0, mut ep, mut em) = (
        BasisEval::<T, D>::with_capacity(n),
        BasisEval::<T, D>::with_capacity(n),
        BasisEval::<T, D>::with_capacity(n),
    );
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for_each_sample(basis, false, |e, x, piece| {
        basis.eval(e, &to_t(&x), &mut e0);
        let h = 1e-4 * piece.min_height;
        for axis in 0..D {
            let mut d = Point::<f64, D>::zeros();
            d[axis] = h;
            basis.eval(e, &to_t(&(x + d)), &mut ep);
            basis.eval(e, &to_t(&(x - d)), &mut em);
            for k in 0..e0.len() {
                let fd = (ep.phi[k].to_f64() - em.phi[k].to_f64()) / (2.0 * h);
                let g = e0.grad_phi[k][axis].to_f64();
                scale = scale.max(g.abs());
                worst = worst.max((fd - g).abs());
            }
        }
    });
    worst / scale.max(f64::MIN_POSITIVE)
}

/// The largest `(max |corner|)² / (diameter · smallest height)` of the pieces
/// (`|x|² / (2 area)` for a triangle): the size, relative to the values, of the terms
/// that an affine function stored in global coordinates sums (PL's barycentric
/// coordinates `(b × c + …) / (2 area)`), hence its round-off in units of `ε`.
pub fn coordinate_conditioning<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> f64 {
    (0..basis.num_elements())
        .flat_map(|e| pieces(basis, e))
        .map(|p| {
            let r = p.corners.iter().map(|c| c.norm()).fold(0.0, f64::max);
            r * r / (p.diam * p.min_height)
        })
        .fold(0.0, f64::max)
}

/// The largest `diameter / smallest height` of the pieces (`diam² / (2 area)` for a
/// triangle, 1 for an interval): the conditioning of their barycentric coordinates.
pub fn worst_aspect<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> f64 {
    (0..basis.num_elements())
        .flat_map(|e| pieces(basis, e))
        .map(|p| p.diam / p.min_height)
        .fold(0.0, f64::max)
}

/// The largest jumps across the boundaries between elements (see [`continuity_jumps`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jumps {
    /// Largest value jump `|phi_i⁺ − phi_i⁻|`.
    pub value: f64,
    /// Largest gradient jump `|∇phi_i⁺ − ∇phi_i⁻|` times the sum of the diameters of
    /// the two pieces (dimensionless: O(1) at a kink, round-off for C¹).
    pub gradient: f64,
    /// Number of points compared.
    pub points: usize,
}

/// Evaluates every function at points on the facets of every piece (three per edge
/// in 2D, the end points in 1D) in both elements meeting there, at the same point,
/// and reports the largest jumps. The element on each side is found by locating
/// points offset by `±1e-8 ·` the piece's diameter across the facet; facets inside
/// an element and on the domain boundary are skipped.
pub fn continuity_jumps<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> Jumps {
    let n = basis.max_functions_per_element();
    let (mut a, mut b) = (
        BasisEval::<T, D>::with_capacity(n),
        BasisEval::<T, D>::with_capacity(n),
    );
    let mut jumps = Jumps::default();
    let mut ids: Vec<usize> = Vec::new();
    for e in 0..basis.num_elements() {
        for piece in pieces(basis, e) {
            for k in 0..=D {
                let facet: Vec<_> = (0..=D)
                    .filter(|&j| j != k)
                    .map(|j| piece.corners[j])
                    .collect();
                let delta = piece.outward_normal(k) * (1e-8 * piece.diam);
                for w in facet_samples(D) {
                    let x = facet
                        .iter()
                        .zip(&w)
                        .fold(Point::<f64, D>::zeros(), |x, (p, w)| x + p * *w);
                    let (Some(ea), Some(eb)) = (
                        basis.locate(&to_t(&(x + delta)), Some(e)),
                        basis.locate(&to_t(&(x - delta)), Some(e)),
                    ) else {
                        continue;
                    };
                    if ea == eb {
                        continue;
                    }
                    // The diameter of the piece of `ea` across the facet.
                    let other = pieces(basis, ea)
                        .into_iter()
                        .map(|p| {
                            let l = p.barycentric(&(x + delta));
                            (l.iter().copied().fold(f64::INFINITY, f64::min), p.diam)
                        })
                        .fold(
                            (f64::NEG_INFINITY, 0.0),
                            |m, c| if c.0 > m.0 { c } else { m },
                        )
                        .1;
                    basis.eval(ea, &to_t(&x), &mut a);
                    basis.eval(eb, &to_t(&x), &mut b);
                    ids.clear();
                    ids.extend(a.index[..a.len()].iter().chain(&b.index[..b.len()]));
                    ids.sort_unstable();
                    ids.dedup();
                    let find = |ev: &BasisEval<T, D>, i: usize| {
                        (0..ev.len())
                            .find(|&k| ev.index[k] == i)
                            .map_or((0.0, Point::<f64, D>::zeros()), |k| {
                                (ev.phi[k].to_f64(), to_f64(&ev.grad_phi[k]))
                            })
                    };
                    for &i in &ids {
                        let ((va, ga), (vb, gb)) = (find(&a, i), find(&b, i));
                        jumps.value = jumps.value.max((va - vb).abs());
                        jumps.gradient =
                            jumps.gradient.max((ga - gb).norm() * (piece.diam + other));
                    }
                    jumps.points += 1;
                }
            }
        }
    }
    jumps
}

/// Applies constraints (all with the same direction `n`) to the coefficients `c`: the
/// component vector `u_i = n · c_i` is projected orthogonally onto the null space of
/// all constraint rows together, `u ← u − U Uᵀ u` with `U` an orthonormal basis of
/// the range of `Aᵀ` (from the SVD of `Aᵀ`; the normal equations `A Aᵀ` lose too much
/// to round-off), so single-term and general constraints that share functions are
/// satisfied at once.
///
/// # Panics
/// If the constraints have different directions.
pub fn apply_constraints<const D: usize>(
    c: &mut [Point<f64, D>],
    constraints: &[Constraint<f64, D>],
) {
    let Some(n) = constraints.first().map(|k| k.direction) else {
        return;
    };
    let mut at = DMatrix::<f64>::zeros(c.len(), constraints.len());
    for (r, k) in constraints.iter().enumerate() {
        assert_eq!(k.direction, n, "constraints with different directions");
        for &(i, w) in &k.terms {
            at[(i, r)] += w;
        }
    }
    let svd = at.svd(true, false);
    let u = svd.u.expect("left singular vectors");
    let smax = svd.singular_values.max();
    let mut x = DVector::from_iterator(c.len(), c.iter().map(|ci| n.dot(ci)));
    for (k, &sigma) in svd.singular_values.iter().enumerate() {
        if sigma > 1e-12 * smax {
            let col = u.column(k);
            let d = col.dot(&x);
            x -= col * d;
        }
    }
    for (ci, xi) in c.iter_mut().zip(x.iter()) {
        *ci += n * (xi - n.dot(ci));
    }
}

/// `max |n · v(x)|` over `points` for a random vector field `v = Σ c_i phi_i`
/// (coefficients uniform in `[−1, 1]^D` from a [`SplitMix64`] seeded with `seed`)
/// whose coefficients satisfy `constraints` (all with direction `n`; `e_1` when
/// there are none).
pub fn constrained_residual<const D: usize, B: Basis<f64, D> + ?Sized>(
    basis: &B,
    constraints: &[Constraint<f64, D>],
    points: &[Point<f64, D>],
    seed: u64,
) -> f64 {
    let n = constraints.first().map_or(first_axis(), |c| c.direction);
    let mut rng = SplitMix64(seed);
    let mut c: Vec<Point<f64, D>> = (0..basis.num_functions())
        .map(|_| Point::<f64, D>::from_fn(|_, _| 2.0 * rng.next_f64() - 1.0))
        .collect();
    apply_constraints(&mut c, constraints);
    let mut eval = BasisEval::for_basis(basis);
    let mut worst = 0.0f64;
    for x in points {
        let e = basis.locate(x, None).expect("wall point inside the mesh");
        basis.eval(e, x, &mut eval);
        let v: Point<f64, D> = eval.iter().map(|(i, phi, _)| c[i] * phi).sum();
        worst = worst.max(n.dot(&v).abs());
    }
    worst
}

/// [`constrained_residual`] for the Dirichlet constraints of the wall tagged `tag`
/// (`points` must lie on it) in `direction`.
pub fn dirichlet_residual<const D: usize, B: Basis<f64, D> + ?Sized>(
    basis: &B,
    tag: &str,
    direction: Point<f64, D>,
    points: &[Point<f64, D>],
    seed: u64,
) -> f64 {
    let constraints = basis.dirichlet(tag, &direction).expect("known tag");
    constrained_residual(basis, &constraints, points, seed)
}

/// `count` points evenly spread along the segment from `a` to `b`, end points included.
pub fn points_on_segment<const D: usize>(
    a: Point<f64, D>,
    b: Point<f64, D>,
    count: usize,
) -> Vec<Point<f64, D>> {
    (0..count)
        .map(|k| a + (b - a) * (k as f64 / (count - 1).max(1) as f64))
        .collect()
}

#[cfg(test)]
pub(crate) mod suite;
