//! The sparse Cholesky solve shared by the strategies that modify `M` row by row
//! (consistent, partial lumping, deactivation): rows held at zero (fixed or
//! inactive) are replaced by a diagonal entry, lumped rows move every off-diagonal
//! entry onto both diagonals, `M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ`. Row sums
//! are kept, so mass and momentum are conserved, and since `M_ij ≥ 0`
//! (non-negative bases) `M' ⪰ M` stays symmetric positive definite.

use super::condition::{estimate, Operator};
use super::{distinct_fixed_sets, MassError, MassSetup};
use crate::sparse::{NotPositiveDefinite, Scalar, SparseCholesky, SymmetricPattern};
use rayon::prelude::*;

/// `out = M'`: `values` (`M` in `pattern`) with the rows and columns where
/// `masked(i)` replaced by the diagonal entry `masked_diagonal`, and every
/// off-diagonal entry of a `lumped` row (or column) moved onto both diagonals.
/// `diagonal_add` is the caller's buffer (`n` entries). Shared by the row-wise
/// strategies and the hybrid extension.
pub(super) fn modify_rows<T: Scalar>(
    pattern: &SymmetricPattern,
    values: &[T],
    lumped: &[bool],
    masked: impl Fn(usize) -> bool,
    masked_diagonal: T,
    diagonal_add: &mut [T],
    out: &mut [T],
) {
    let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
    diagonal_add.iter_mut().for_each(|v| *v = T::zero());
    for c in 0..pattern.dim() {
        for k in ptr[c]..ptr[c + 1] {
            let r = rows[k];
            out[k] = if r == c {
                if masked(r) {
                    masked_diagonal
                } else {
                    values[k]
                }
            } else if masked(r) || masked(c) {
                T::zero()
            } else if lumped[r] || lumped[c] {
                diagonal_add[r] += values[k];
                diagonal_add[c] += values[k];
                T::zero()
            } else {
                values[k]
            };
        }
    }
    for (i, add) in diagonal_add.iter().enumerate() {
        out[pattern.diagonal_position(i)] += *add;
    }
}

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
    /// `modify_rows`' buffer, one per distinct fixed set.
    diagonal_add: Vec<Vec<T>>,
    /// The failure of each set's last factorisation.
    failed: Vec<Option<NotPositiveDefinite>>,
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
        self.diagonal_add = vec![vec![T::zero(); n]; self.fixed.len()];
        self.failed = vec![None; self.fixed.len()];
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
        // The distinct fixed sets are independent systems: factorised side by side
        // on the pool (each result is the same for any thread count), the first
        // failure in set order reported.
        let (inactive, lumped) = (&self.inactive, &self.lumped);
        (
            self.fixed.par_iter(),
            self.diagonal_add.par_iter_mut(),
            self.modified.par_iter_mut(),
            self.solvers.par_iter_mut(),
            self.failed.par_iter_mut(),
        )
            .into_par_iter()
            .for_each(|(fixed, diagonal_add, modified, solver, failed)| {
                modify_rows(
                    pattern,
                    values,
                    lumped,
                    |i| fixed[i] || inactive[i],
                    scale,
                    diagonal_add,
                    modified,
                );
                *failed = solver.factorize(modified).err();
            });
        if let Some(failure) = self.failed.iter().flatten().next() {
            return Err(MassError::from(failure.clone()));
        }
        Ok(())
    }

    pub fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        self.mask(k, rhs);
        self.solvers[self.solver_of[k]].solve_in_place(rhs, 1);
        Ok(())
    }

    /// Zeroes the entries of component `k` held at zero (fixed or inactive).
    fn mask(&self, k: usize, rhs: &mut [T]) {
        let fixed = &self.fixed[self.solver_of[k]];
        for (i, r) in rhs.iter_mut().enumerate() {
            if fixed[i] || self.inactive[i] {
                *r = T::zero();
            }
        }
    }

    /// [`solve`](Self::solve) for every component; two components with different
    /// fixed sets (two factorisations) are solved side by side on the pool.
    pub fn solve_all(&mut self, rhs: &mut [Vec<T>]) -> Result<(), MassError> {
        for (k, r) in rhs.iter_mut().enumerate() {
            self.mask(k, r);
        }
        match (rhs, self.solver_of.as_slice()) {
            ([r0, r1], &[a, b]) if a != b => {
                let (low, high) = self.solvers.split_at_mut(a.max(b));
                let (s0, s1) = if a < b {
                    (&mut low[a], &mut high[0])
                } else {
                    (&mut high[0], &mut low[b])
                };
                rayon::join(|| s0.solve_in_place(r0, 1), || s1.solve_in_place(r1, 1));
            }
            (rhs, _) => {
                for (k, r) in rhs.iter_mut().enumerate() {
                    self.solvers[self.solver_of[k]].solve_in_place(r, 1);
                }
            }
        }
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
