//! Property checks that every 2D basis must pass, written once and run on every
//! basis and mesh by the test suites (PL, PS; block grids, random Delaunay meshes,
//! Gmsh meshes).
//!
//! Each check returns the measured worst violation, so tests state their tolerance
//! next to the property (and a failing test prints how far off it was):
//! - [`partition_of_unity`]: `max |Σ_i phi_i(x) − 1|`;
//! - [`min_value`]: `min phi_i(x)` (non-negativity wants it ≥ −round-off);
//! - [`linear_precision`]: `max |Σ_i X_i phi_i(x) − x|` with the function points `X_i`;
//! - [`gradient_error`]: `max |grad phi_i − central difference|`, relative to `max |grad phi|`;
//! - [`continuity_jumps`]: the largest jumps of values and gradients across every
//!   interior edge of the polynomial pieces (main edges and PS sub-triangle edges);
//! - [`dirichlet_residual`]: `max |n · v|` along a wall for a random field `v` with the
//!   wall's constraints applied.
//!
//! Sample points are deterministic: fixed barycentric points in every polynomial piece.

use crate::basis::{Basis, BasisEval, Constraint, Point};
use crate::mesh::Vec2;
use crate::rng::SplitMix64;
use crate::scalar::Real;
use nalgebra::{DMatrix, DVector, Vector2};

/// Barycentric sample points inside a piece (all at least 0.1 from its edges).
const INTERIOR_SAMPLES: [[f64; 3]; 4] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [0.6, 0.2, 0.2],
    [0.2, 0.6, 0.2],
    [0.15, 0.15, 0.7],
];

fn to_t<T: Real>(x: Vec2) -> Point<T, 2> {
    Vector2::new(T::of(x.x), T::of(x.y))
}

/// Calls `visit(element, x, piece_diameter)` for every interior sample point.
fn for_each_sample<T: Real, B: Basis<T, 2> + ?Sized>(
    basis: &B,
    mut visit: impl FnMut(usize, Vec2, f64),
) {
    let mut pieces = Vec::new();
    for e in 0..basis.num_elements() {
        pieces.clear();
        basis.polynomial_pieces(e, &mut pieces);
        for p in pieces.chunks_exact(3) {
            let diam = (p[1] - p[0])
                .norm()
                .max((p[2] - p[1]).norm())
                .max((p[0] - p[2]).norm());
            for b in INTERIOR_SAMPLES {
                visit(e, p[0] * b[0] + p[1] * b[1] + p[2] * b[2], diam);
            }
        }
    }
}

/// `max |Σ_i phi_i(x) − 1|` over the sample points.
pub fn partition_of_unity<T: Real, B: Basis<T, 2> + ?Sized>(basis: &B) -> f64 {
    let mut eval = BasisEval::for_basis(basis);
    let mut worst = 0.0f64;
    for_each_sample(basis, |e, x, _| {
        basis.eval(e, &to_t(x), &mut eval);
        let sum: f64 = eval.iter().map(|(_, phi, _)| phi.to_f64()).sum();
        worst = worst.max((sum - 1.0).abs());
    });
    worst
}

/// `min_i phi_i(x)` over the sample points.
pub fn min_value<T: Real, B: Basis<T, 2> + ?Sized>(basis: &B) -> f64 {
    let mut eval = BasisEval::for_basis(basis);
    let mut worst = f64::INFINITY;
    for_each_sample(basis, |e, x, _| {
        basis.eval(e, &to_t(x), &mut eval);
        for (_, phi, _) in eval.iter() {
            worst = worst.min(phi.to_f64());
        }
    });
    worst
}

/// `max |Σ_i X_i phi_i(x) − x|` over the sample points, and `max |Σ_i X_i ⊗ grad phi_i − I|`.
pub fn linear_precision<T: Real, B: Basis<T, 2> + ?Sized>(basis: &B) -> (f64, f64) {
    let mut eval = BasisEval::for_basis(basis);
    let (mut worst, mut worst_grad) = (0.0f64, 0.0f64);
    for_each_sample(basis, |e, x, _| {
        basis.eval(e, &to_t(x), &mut eval);
        let mut sum = Vec2::zeros();
        let mut jac = nalgebra::Matrix2::<f64>::zeros();
        for (i, phi, grad) in eval.iter() {
            let xi = basis.function_point(i);
            sum += xi * phi.to_f64();
            jac += xi * Vector2::new(grad.x.to_f64(), grad.y.to_f64()).transpose();
        }
        worst = worst.max((sum - x).norm());
        worst_grad = worst_grad.max((jac - nalgebra::Matrix2::identity()).norm());
    });
    (worst, worst_grad)
}

/// Largest difference between analytic gradients and central differences with step
/// `1e-4 ·` piece diameter (exact for quadratics up to round-off), relative to the
/// largest gradient seen.
pub fn gradient_error<T: Real, B: Basis<T, 2> + ?Sized>(basis: &B) -> f64 {
    let n = basis.max_functions_per_element();
    let (mut e0, mut ep, mut em) = (
        BasisEval::<T, 2>::with_capacity(n),
        BasisEval::<T, 2>::with_capacity(n),
        BasisEval::<T, 2>::with_capacity(n),
    );
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for_each_sample(basis, |e, x, diam| {
        basis.eval(e, &to_t(x), &mut e0);
        let h = 1e-4 * diam;
        for axis in 0..2 {
            let mut d = Vec2::zeros();
            d[axis] = h;
            basis.eval(e, &to_t(x + d), &mut ep);
            basis.eval(e, &to_t(x - d), &mut em);
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

/// Relative jumps across the interior edges of all polynomial pieces.
///
/// Both sides are evaluated at `x ± δ n` with `δ = 1e-8 ·` piece diameter. The value
/// jump is corrected to first order (`φ_a − φ_b − ½ (∇φ_a + ∇φ_b) · 2δ n`), so a smooth
/// function leaves only round-off; the gradient jump is divided by the largest
/// gradient at the point, so a smooth function leaves `O(δ |H| / |∇φ|)` while a kink
/// (as in PL) leaves `O(1)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jumps {
    /// Largest corrected value jump, relative to `max |φ| + diam · max |∇φ|` at the point.
    pub value: f64,
    /// Largest gradient jump, relative to `max |∇φ|` at the point.
    pub gradient: f64,
    /// Number of edge points compared.
    pub points: usize,
}

/// Evaluates every function at points just either side (offset `1e-8 ·` diameter) of
/// three points on every edge of every polynomial piece, and reports the largest
/// jumps. Points whose offset leaves the domain are skipped (boundary edges).
pub fn continuity_jumps<T: Real, B: Basis<T, 2> + ?Sized>(basis: &B) -> Jumps {
    let n = basis.max_functions_per_element();
    let (mut a, mut b) = (
        BasisEval::<T, 2>::with_capacity(n),
        BasisEval::<T, 2>::with_capacity(n),
    );
    let mut pieces = Vec::new();
    let mut jumps = Jumps::default();
    let mut ids: Vec<usize> = Vec::new();
    for e in 0..basis.num_elements() {
        pieces.clear();
        basis.polynomial_pieces(e, &mut pieces);
        for p in pieces.chunks_exact(3) {
            let diam = (p[1] - p[0])
                .norm()
                .max((p[2] - p[1]).norm())
                .max((p[0] - p[2]).norm());
            for k in 0..3 {
                let (s, t) = (p[k], p[(k + 1) % 3]);
                let tangent = (t - s).normalize();
                let normal = Vector2::new(tangent.y, -tangent.x);
                for w in [0.25, 0.5, 0.75] {
                    let x = s + (t - s) * w;
                    let delta = normal * (1e-8 * diam);
                    let (xa, xb) = (x + delta, x - delta);
                    let (Some(ea), Some(eb)) = (
                        basis.locate(&to_t(xa), Some(e)),
                        basis.locate(&to_t(xb), Some(e)),
                    ) else {
                        continue;
                    };
                    basis.eval(ea, &to_t(xa), &mut a);
                    basis.eval(eb, &to_t(xb), &mut b);
                    ids.clear();
                    ids.extend(a.index[..a.len()].iter().chain(&b.index[..b.len()]));
                    ids.sort_unstable();
                    ids.dedup();
                    let find = |ev: &BasisEval<T, 2>, i: usize| {
                        (0..ev.len()).find(|&k| ev.index[k] == i).map_or(
                            (0.0, Vec2::zeros()),
                            |k| {
                                (
                                    ev.phi[k].to_f64(),
                                    Vec2::new(ev.grad_phi[k].x.to_f64(), ev.grad_phi[k].y.to_f64()),
                                )
                            },
                        )
                    };
                    let (mut value_scale, mut grad_scale) = (0.0f64, 0.0f64);
                    for &i in &ids {
                        let (va, ga) = find(&a, i);
                        value_scale = value_scale.max(va.abs());
                        grad_scale = grad_scale.max(ga.norm());
                    }
                    let value_scale = value_scale + diam * grad_scale;
                    for &i in &ids {
                        let (va, ga) = find(&a, i);
                        let (vb, gb) = find(&b, i);
                        let corrected = va - vb - 0.5 * (ga + gb).dot(&(delta * 2.0));
                        jumps.value = jumps.value.max(corrected.abs() / value_scale);
                        jumps.gradient = jumps.gradient.max((ga - gb).norm() / grad_scale);
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
/// all constraint rows together, `u ← u − A⁺ A u` with the SVD pseudo-inverse, so
/// single-term and general constraints that share functions are satisfied at once.
pub fn apply_constraints(c: &mut [Vec2], constraints: &[Constraint<f64, 2>]) {
    if constraints.is_empty() {
        return;
    }
    let n = constraints[0].direction;
    let ncoef = c.len();
    // Only the coefficients that some constraint touches take part.
    let mut touched: Vec<usize> = constraints
        .iter()
        .flat_map(|k| k.terms.iter().map(|t| t.0))
        .collect();
    touched.sort_unstable();
    touched.dedup();
    let column = |i: usize| touched.binary_search(&i).expect("touched");
    let mut a = DMatrix::<f64>::zeros(constraints.len(), touched.len());
    for (r, k) in constraints.iter().enumerate() {
        for &(i, w) in &k.terms {
            a[(r, column(i))] += w;
        }
    }
    let u = DVector::from_iterator(touched.len(), touched.iter().map(|&i| n.dot(&c[i])));
    let pinv = a.clone().pseudo_inverse(1e-12).expect("pseudo-inverse");
    let correction = pinv * (&a * &u);
    for (k, &i) in touched.iter().enumerate() {
        c[i] -= n * correction[k];
    }
    debug_assert!(ncoef >= touched.len());
}

/// `max |n · v(x)|` over `points` (which must lie on the wall tagged `tag`) for a
/// random vector field `v = Σ c_i phi_i` whose coefficients satisfy the wall's
/// Dirichlet constraints for `direction`.
pub fn dirichlet_residual<B: Basis<f64, 2> + ?Sized>(
    basis: &B,
    tag: &str,
    direction: Vec2,
    points: &[Vec2],
    seed: u64,
) -> f64 {
    let constraints = basis.dirichlet(tag, &direction).expect("known tag");
    let mut rng = SplitMix64(seed);
    let mut c: Vec<Vec2> = (0..basis.num_functions())
        .map(|_| Vec2::new(2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0))
        .collect();
    apply_constraints(&mut c, &constraints);
    let mut eval = BasisEval::for_basis(basis);
    let mut worst = 0.0f64;
    for x in points {
        let e = basis.locate(x, None).expect("wall point inside the mesh");
        basis.eval(e, x, &mut eval);
        let v: Vec2 = eval.iter().map(|(i, phi, _)| c[i] * phi).sum();
        worst = worst.max(direction.dot(&v).abs());
    }
    worst
}

/// `count` points evenly spread along the segment from `a` to `b`, end points included.
pub fn points_on_segment(a: Vec2, b: Vec2, count: usize) -> Vec<Vec2> {
    (0..count)
        .map(|k| a + (b - a) * (k as f64 / (count - 1).max(1) as f64))
        .collect()
}
