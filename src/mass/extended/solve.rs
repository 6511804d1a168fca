//! The solve of the reduced system `Eᵀ M E ã = Eᵀ F`: the operator applied
//! matrix-free over the functions with particles, and Jacobi-preconditioned
//! conjugate gradients.

use super::{Role, CG_MAX_ITERATIONS, CG_TOLERANCE};
use crate::mass::MassError;
use crate::sparse::Scalar;

/// The reduced operator `Eᵀ M E` restricted to the free functions of one fixed set.
pub(super) struct Reduced<'a, T> {
    pub(super) col_ptr: &'a [usize],
    pub(super) row_idx: &'a [usize],
    pub(super) values: &'a [T],
    pub(super) role: &'a [Role],
    pub(super) ext_ptr: &'a [usize],
    pub(super) ext_idx: &'a [usize],
    pub(super) ext_w: &'a [T],
    pub(super) fixed: &'a [bool],
    /// Functions with particles (solved or extended), ascending.
    pub(super) active: &'a [usize],
    /// Extended functions, ascending.
    pub(super) extended: &'a [usize],
}

impl<T: Scalar> Reduced<'_, T> {
    pub(super) fn free(&self, i: usize) -> bool {
        self.role[i] == Role::Solved && !self.fixed[i]
    }
    /// `(E x)_i` for an active function `i`.
    #[inline]
    pub(super) fn expanded(&self, x: &[T], i: usize) -> T {
        match self.role[i] {
            Role::Solved if !self.fixed[i] => x[i],
            Role::Extended if !self.fixed[i] => {
                let mut s = T::zero();
                for t in self.ext_ptr[i]..self.ext_ptr[i + 1] {
                    s += self.ext_w[t] * x[self.ext_idx[t]];
                }
                s
            }
            _ => T::zero(),
        }
    }
    /// `u = E x` on the active functions (the others stay zero).
    pub(super) fn expand(&self, x: &[T], u: &mut [T]) {
        for &i in self.active {
            u[i] = self.expanded(x, i);
        }
    }
    /// `y = Eᵀ w`, zero off the free functions (written on the active ones).
    pub(super) fn restrict(&self, w: &[T], y: &mut [T]) {
        for &i in self.active {
            y[i] = if self.free(i) { w[i] } else { T::zero() };
        }
        for &j in self.extended {
            if !self.fixed[j] {
                for t in self.ext_ptr[j]..self.ext_ptr[j + 1] {
                    let i = self.ext_idx[t];
                    if self.free(i) {
                        y[i] += self.ext_w[t] * w[j];
                    }
                }
            }
        }
    }
    /// `w = M u` over the active columns: `M_ij = 0` as soon as `i` or `j` has no
    /// particle, so the other entries contribute nothing.
    pub(super) fn mass_product(&self, u: &[T], w: &mut [T]) {
        for &c in self.active {
            w[c] = T::zero();
        }
        for &c in self.active {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                let r = self.row_idx[k];
                let a = self.values[k];
                w[r] += a * u[c];
                if r != c {
                    w[c] += a * u[r];
                }
            }
        }
    }
    /// `y = Eᵀ M E x`.
    pub(super) fn apply(&self, x: &[T], y: &mut [T], u: &mut [T], w: &mut [T]) {
        self.expand(x, u);
        self.mass_product(u, w);
        self.restrict(w, y);
    }
    /// `Σ a_i b_i` over the active functions.
    pub(super) fn dot(&self, a: &[T], b: &[T]) -> f64 {
        self.active
            .iter()
            .map(|&i| (a[i] * b[i]).to_f64())
            .sum::<f64>()
    }
}

/// Scratch of the conjugate-gradient solve.
#[derive(Default)]
pub(super) struct Scratch<T> {
    pub(super) x: Vec<T>,
    pub(super) r: Vec<T>,
    pub(super) z: Vec<T>,
    pub(super) p: Vec<T>,
    pub(super) q: Vec<T>,
    pub(super) u: Vec<T>,
    pub(super) w: Vec<T>,
}

impl<T: Scalar> Scratch<T> {
    pub(super) fn new(n: usize) -> Self {
        let v = || vec![T::zero(); n];
        Scratch {
            x: v(),
            r: v(),
            z: v(),
            p: v(),
            q: v(),
            u: v(),
            w: v(),
        }
    }
}

/// Solves `Eᵀ M E x = b` (b zero off the free functions) by preconditioned
/// conjugate gradients from `x = D⁻¹ b`; the result is left in `s.x`.
pub(super) fn conjugate_gradients<T: Scalar>(
    op: &Reduced<T>,
    precond: &[T],
    b: &[T],
    s: &mut Scratch<T>,
) -> Result<usize, MassError> {
    let b_norm = op.dot(b, b).sqrt();
    for &i in op.active {
        s.x[i] = if op.free(i) {
            b[i] / precond[i]
        } else {
            T::zero()
        };
    }
    if b_norm == 0.0 {
        return Ok(0);
    }
    op.apply(&s.x, &mut s.q, &mut s.u, &mut s.w);
    for &i in op.active {
        s.r[i] = b[i] - s.q[i];
        s.z[i] = if op.free(i) {
            s.r[i] / precond[i]
        } else {
            T::zero()
        };
        s.p[i] = s.z[i];
    }
    let mut rz = op.dot(&s.r, &s.z);
    let mut residual = op.dot(&s.r, &s.r).sqrt() / b_norm;
    for iteration in 0..CG_MAX_ITERATIONS {
        if residual <= CG_TOLERANCE {
            return Ok(iteration);
        }
        op.apply(&s.p, &mut s.q, &mut s.u, &mut s.w);
        let pq = op.dot(&s.p, &s.q);
        if pq.is_nan() || pq <= 0.0 {
            break;
        }
        let alpha = T::of(rz / pq);
        for &i in op.active {
            s.x[i] += alpha * s.p[i];
            s.r[i] -= alpha * s.q[i];
            s.z[i] = if op.free(i) {
                s.r[i] / precond[i]
            } else {
                T::zero()
            };
        }
        let rz_new = op.dot(&s.r, &s.z);
        let beta = T::of(rz_new / rz);
        rz = rz_new;
        for &i in op.active {
            s.p[i] = s.z[i] + beta * s.p[i];
        }
        residual = op.dot(&s.r, &s.r).sqrt() / b_norm;
    }
    if residual <= CG_TOLERANCE {
        return Ok(CG_MAX_ITERATIONS);
    }
    Err(MassError::NotConverged {
        iterations: CG_MAX_ITERATIONS,
        residual,
    })
}
