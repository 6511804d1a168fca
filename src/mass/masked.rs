//! The sparse Cholesky solve shared by the strategies that modify `M` row by row
//! (consistent, partial lumping, deactivation): rows held at zero (fixed or
//! inactive) are replaced by a diagonal entry, lumped rows move every off-diagonal
//! entry onto both diagonals, `M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ`. Row sums
//! are kept, so mass and momentum are conserved, and since `M_ij ≥ 0`
//! (non-negative bases) `M' ⪰ M` stays symmetric positive definite.

use super::condition::{estimate, Operator};
use super::{distinct_fixed_sets, MassError, MassSetup};
use crate::sparse::{Scalar, SparseCholesky, SymmetricPattern};

/// One factorisation per distinct set of fixed coefficients.
#[derive(Default)]
pub(super) struct MaskedCholesky<T: Scalar> {
    fixed: Vec<Vec<bool>>,
    /// `solver_of[k]`: index of the factorisation used by component `k`.
    solver_of: Vec<usize>,
    solvers: Vec<SparseCholesky<T>>,
    /// Modified values per distinct fixed set.
    modified: Vec<Vec<T>>,
    /// Rows held at zero in every component (no particle, or deactivated).
    pub inactive: Vec<bool>,
    /// Rows replaced by their lumped value.
    pub lumped: Vec<bool>,
    diagonal_add: Vec<T>,
    work: [Vec<T>; 2],
}

impl<T: Scalar> MaskedCholesky<T> {
    pub fn prepare(&mut self, setup: &MassSetup) {
        let pattern = setup.pattern;
        let (distinct, solver_of) = distinct_fixed_sets(setup.fixed);
        let n = pattern.dim();
        self.solvers = distinct
            .iter()
            .map(|_| SparseCholesky::new(pattern, 1))
            .collect();
        self.modified = distinct
            .iter()
            .map(|_| vec![T::zero(); pattern.nnz()])
            .collect();
        self.fixed = distinct;
        self.solver_of = solver_of;
        self.inactive = vec![false; n];
        self.lumped = vec![false; n];
        self.diagonal_add = vec![T::zero(); n];
        self.work = [vec![T::zero(); n], vec![T::zero(); n]];
    }

    /// Factorises `M'` for the current [`inactive`](Self::inactive) and
    /// [`lumped`](Self::lumped) marks.
    pub fn factorize(&mut self, pattern: &SymmetricPattern, values: &[T]) -> Result<(), MassError> {
        let n = pattern.dim();
        // Masked rows get the mean active diagonal: the value does not matter for the
        // solution (their right-hand side is zero) but keeps the condition estimate
        // about the active system.
        let (mut scale, mut count) = (T::zero(), 0usize);
        for i in (0..n).filter(|&i| !self.inactive[i]) {
            scale += values[pattern.diagonal_position(i)];
            count += 1;
        }
        let scale = if count > 0 {
            scale / T::of(count as f64)
        } else {
            T::one()
        };
        let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
        for (s, fixed) in self.fixed.iter().enumerate() {
            let out = &mut self.modified[s];
            self.diagonal_add.iter_mut().for_each(|v| *v = T::zero());
            let masked = |i: usize| fixed[i] || self.inactive[i];
            for c in 0..n {
                for k in ptr[c]..ptr[c + 1] {
                    let r = rows[k];
                    out[k] = if r == c {
                        if masked(r) {
                            scale
                        } else {
                            values[k]
                        }
                    } else if masked(r) || masked(c) {
                        T::zero()
                    } else if self.lumped[r] || self.lumped[c] {
                        self.diagonal_add[r] += values[k];
                        self.diagonal_add[c] += values[k];
                        T::zero()
                    } else {
                        values[k]
                    };
                }
            }
            for i in 0..n {
                out[pattern.diagonal_position(i)] += self.diagonal_add[i];
            }
            self.solvers[s].factorize(out)?;
        }
        Ok(())
    }

    pub fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        let s = self.solver_of[k];
        for (i, r) in rhs.iter_mut().enumerate() {
            if self.fixed[s][i] || self.inactive[i] {
                *r = T::zero();
            }
        }
        self.solvers[s].solve_in_place(rhs, 1);
        Ok(())
    }

    /// `λ_max` of `M'` by power iteration, `λ_min` by inverse iteration with the
    /// factorisation; the largest ratio over the fixed sets.
    pub fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        let mut worst = 0.0f64;
        for s in 0..self.solvers.len() {
            let (values, solver) = (&self.modified[s], &mut self.solvers[s]);
            let mut op = Operator {
                apply: &mut |x: &[T], y: &mut [T]| pattern.mul_vec(values, x, y),
                solve: &mut |y: &mut [T]| {
                    solver.solve_in_place(y, 1);
                    Ok(())
                },
            };
            let [x, y] = &mut self.work;
            worst = worst.max(estimate(&mut op, x, y));
        }
        worst
    }
}
