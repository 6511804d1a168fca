//! Condition-number estimate of the system a strategy solves: `λ_max` by power
//! iteration with the operator, `λ_min` by inverse iteration with the strategy's
//! own solve, from fixed starting vectors (deterministic).

use super::MassError;
use crate::sparse::Scalar;

/// The Lanczos recurrence stops when the new off-diagonal falls below this
/// fraction of the diagonal (an invariant subspace was found).
const LANCZOS_BREAKDOWN: f64 = 1e-14;

/// Number of power and inverse iterations of the condition estimate.
pub const CONDITION_ITERATIONS: usize = 30;

/// The operator `A` and its inverse, as closures over the strategy's state.
pub(super) struct Operator<'a, T> {
    /// `y = A x`.
    pub apply: &'a mut dyn FnMut(&[T], &mut [T]),
    /// `y ← A⁻¹ y`.
    pub solve: &'a mut dyn FnMut(&mut [T]) -> Result<(), MassError>,
}

/// `λ_max · (1 / λ_min)` after [`CONDITION_ITERATIONS`] iterations each; `∞` when
/// the inverse iteration fails.
pub(super) fn estimate<T: Scalar>(op: &mut Operator<T>, x: &mut Vec<T>, y: &mut Vec<T>) -> f64 {
    let norm = |v: &[T]| v.iter().map(|a| (*a * *a).to_f64()).sum::<f64>().sqrt();
    let dot = |a: &[T], b: &[T]| {
        a.iter()
            .zip(b)
            .map(|(a, b)| (*a * *b).to_f64())
            .sum::<f64>()
    };
    x.iter_mut()
        .enumerate()
        .for_each(|(i, v)| *v = T::of(1.0 + (i % 7) as f64 * 0.1));
    let mut lambda_max = 0.0;
    for _ in 0..CONDITION_ITERATIONS {
        let nx = norm(x);
        x.iter_mut().for_each(|v| *v /= T::of(nx));
        (op.apply)(x, y);
        lambda_max = dot(x, y);
        std::mem::swap(x, y);
    }
    x.iter_mut()
        .enumerate()
        .for_each(|(i, v)| *v = T::of(1.0 + (i % 5) as f64 * 0.1));
    let mut mu = 0.0;
    for _ in 0..CONDITION_ITERATIONS {
        let nx = norm(x);
        x.iter_mut().for_each(|v| *v /= T::of(nx));
        y.copy_from_slice(x);
        if (op.solve)(y).is_err() {
            return f64::INFINITY;
        }
        mu = dot(x, y);
        std::mem::swap(x, y);
    }
    lambda_max * mu
}

/// `λ_max / λ_min` of the symmetric positive definite operator `apply` from the
/// extreme Ritz values of [`CONDITION_ITERATIONS`] Lanczos steps (one matrix
/// product each, no solve): a lower bound that is sharp at the ends of the
/// spectrum. `x` is the start vector (zero entries stay outside the subspace);
/// `q` and `w` are scratch.
pub(super) fn lanczos_estimate<T: Scalar>(
    apply: &mut dyn FnMut(&[T], &mut [T]),
    x: &mut [T],
    q: &mut [T],
    w: &mut [T],
) -> f64 {
    let norm = |v: &[T]| v.iter().map(|a| (*a * *a).to_f64()).sum::<f64>().sqrt();
    let mut alpha = [0.0f64; CONDITION_ITERATIONS];
    let mut beta = [0.0f64; CONDITION_ITERATIONS];
    let nx = norm(x);
    if nx == 0.0 {
        return 1.0;
    }
    // x holds q_{j−1} (initially zero after scaling into q), q holds q_j.
    for (qi, xi) in q.iter_mut().zip(x.iter_mut()) {
        *qi = *xi / T::of(nx);
        *xi = T::zero();
    }
    let mut steps = 0;
    for j in 0..CONDITION_ITERATIONS {
        apply(q, w);
        let a: f64 = q
            .iter()
            .zip(w.iter())
            .map(|(a, b)| (*a * *b).to_f64())
            .sum();
        alpha[j] = a;
        let b_prev = if j > 0 { beta[j - 1] } else { 0.0 };
        for i in 0..w.len() {
            w[i] -= T::of(a) * q[i] + T::of(b_prev) * x[i];
        }
        steps = j + 1;
        let b = norm(w);
        beta[j] = b;
        if b.is_nan() || b <= LANCZOS_BREAKDOWN * a.abs() {
            break;
        }
        for i in 0..w.len() {
            x[i] = q[i];
            q[i] = w[i] / T::of(b);
        }
    }
    let (lo, hi) = tridiagonal_extremes(&alpha[..steps], &beta[..steps]);
    if lo > 0.0 {
        hi / lo
    } else {
        f64::INFINITY
    }
}

/// Smallest and largest eigenvalue of the symmetric tridiagonal matrix with
/// diagonal `a` and off-diagonal `b` (`b[j]` couples `j` and `j + 1`), by
/// bisection on the Sturm count; `(0, 0)` for an empty matrix. The Lanczos
/// estimates of the condition number here and of the critical step
/// (`driver::critical`) read it.
pub(crate) fn tridiagonal_extremes(a: &[f64], b: &[f64]) -> (f64, f64) {
    let m = a.len();
    if m == 0 {
        return (0.0, 0.0);
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for j in 0..m {
        let r = if j > 0 { b[j - 1].abs() } else { 0.0 } + if j + 1 < m { b[j].abs() } else { 0.0 };
        lo = lo.min(a[j] - r);
        hi = hi.max(a[j] + r);
    }
    // Number of eigenvalues below `x`.
    let below = |x: f64| {
        let mut count = 0;
        let mut d = 1.0;
        for j in 0..m {
            let off = if j > 0 { b[j - 1] * b[j - 1] } else { 0.0 };
            d = a[j] - x - if j > 0 { off / d } else { 0.0 };
            if d == 0.0 {
                d = -1e-300;
            }
            if d < 0.0 {
                count += 1;
            }
        }
        count
    };
    let bisect = |k: usize| {
        let (mut l, mut h) = (lo, hi);
        for _ in 0..200 {
            let mid = 0.5 * (l + h);
            if below(mid) > k {
                h = mid;
            } else {
                l = mid;
            }
            if h - l <= 1e-15 * h.abs().max(l.abs()) {
                break;
            }
        }
        0.5 * (l + h)
    };
    (bisect(0), bisect(m - 1))
}
