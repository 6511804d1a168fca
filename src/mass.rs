//! Mass strategies: how the system `M a = F` (paper eq. (17)) and the velocity
//! projection `M v̂ = P` (eq. (20)) are solved.
//!
//! A strategy is prepared once per mesh ([`MassStrategy::prepare`]: symbolic work),
//! factorises the assembled mass matrix once per step ([`MassStrategy::factorize`]:
//! numeric work, reused by both solves of the step), and solves one velocity
//! component at a time ([`MassStrategy::solve`]). Homogeneous Dirichlet conditions
//! come as a set of fixed coefficients per component: their rows and columns are
//! replaced by the identity, so the constrained system is solved exactly.
//! Functions with no particle in their support have an all-zero row; they are
//! decoupled (unit diagonal, zero right-hand side) without changing the pattern.
//! What a strategy did is returned as a [`MassReport`], never printed.

use crate::sparse::{NotPositiveDefinite, Scalar, SparseCholesky, SymmetricPattern};

/// What a strategy did in one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MassReport {
    /// Functions with particles in their support (non-zero mass row).
    pub active: usize,
    /// Rows replaced by their lumped value.
    pub lumped_rows: usize,
}

/// How to solve the mass systems of a step.
pub trait MassStrategy<T: Scalar> {
    /// Name for output (`consistent`, `lumped`).
    fn name(&self) -> &'static str;
    /// Set-up once per mesh: `fixed[k][i]` says whether component `k` of coefficient
    /// `i` is held at zero by a Dirichlet condition.
    fn prepare(pattern: &SymmetricPattern, fixed: &[Vec<bool>]) -> Self
    where
        Self: Sized;
    /// Numeric work for the matrix whose upper triangle has `values`
    /// (`M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)`, eq. (13)).
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
    ) -> Result<MassReport, NotPositiveDefinite>;
    /// Solves component `k` in place: `rhs` becomes the coefficients, zero at fixed
    /// and inactive functions.
    fn solve(&mut self, k: usize, rhs: &mut [T]);
}

/// Rows whose diagonal is exactly zero: no particle in the function's support.
fn inactive<T: Scalar>(pattern: &SymmetricPattern, values: &[T], i: usize) -> bool {
    values[pattern.diagonal_position(i)] <= T::zero()
}

/// The consistent mass matrix, solved by sparse Cholesky (one factorisation per
/// distinct set of fixed coefficients; the symbolic analysis is done once).
pub struct Consistent<T: Scalar> {
    fixed: Vec<Vec<bool>>,
    /// `solver_of[k]`: index of the factorisation used by component `k`.
    solver_of: Vec<usize>,
    solvers: Vec<SparseCholesky<T>>,
    /// Per distinct fixed set, the modified values.
    scratch: Vec<T>,
    inactive: Vec<bool>,
    rows: Vec<usize>,
}

impl<T: Scalar> MassStrategy<T> for Consistent<T> {
    fn name(&self) -> &'static str {
        "consistent"
    }
    fn prepare(pattern: &SymmetricPattern, fixed: &[Vec<bool>]) -> Self {
        let mut distinct: Vec<&Vec<bool>> = Vec::new();
        let solver_of = fixed
            .iter()
            .map(|f| match distinct.iter().position(|d| *d == f) {
                Some(i) => i,
                None => {
                    distinct.push(f);
                    distinct.len() - 1
                }
            })
            .collect();
        // Row index of every stored entry, for masking rows and columns.
        let rows = pattern.row_idx().to_vec();
        Consistent {
            solvers: distinct
                .iter()
                .map(|_| SparseCholesky::new(pattern, 1))
                .collect(),
            fixed: distinct.into_iter().cloned().collect(),
            solver_of,
            scratch: vec![T::zero(); pattern.nnz()],
            inactive: vec![false; pattern.dim()],
            rows,
        }
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
    ) -> Result<MassReport, NotPositiveDefinite> {
        let n = pattern.dim();
        for i in 0..n {
            self.inactive[i] = inactive(pattern, values, i);
        }
        let ptr = pattern.col_ptr();
        for (s, fixed) in self.fixed.iter().enumerate() {
            for c in 0..n {
                for k in ptr[c]..ptr[c + 1] {
                    let r = self.rows[k];
                    let masked = fixed[r] || fixed[c] || self.inactive[r] || self.inactive[c];
                    self.scratch[k] = match (masked, r == c) {
                        (false, _) => values[k],
                        (true, true) => T::one(),
                        (true, false) => T::zero(),
                    };
                }
            }
            self.solvers[s].factorize(&self.scratch)?;
        }
        Ok(MassReport {
            active: self.inactive.iter().filter(|&&x| !x).count(),
            lumped_rows: 0,
        })
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) {
        let s = self.solver_of[k];
        for (i, r) in rhs.iter_mut().enumerate() {
            if self.fixed[s][i] || self.inactive[i] {
                *r = T::zero();
            }
        }
        self.solvers[s].solve_in_place(rhs, 1);
    }
}

/// The lumped (row-sum) mass matrix `M_ii = Σ_j M_ij = Σ_p m_p phi_i(x_p)`.
pub struct Lumped<T: Scalar> {
    fixed: Vec<Vec<bool>>,
    diagonal: Vec<T>,
}

impl<T: Scalar> MassStrategy<T> for Lumped<T> {
    fn name(&self) -> &'static str {
        "lumped"
    }
    fn prepare(pattern: &SymmetricPattern, fixed: &[Vec<bool>]) -> Self {
        Lumped {
            fixed: fixed.to_vec(),
            diagonal: vec![T::zero(); pattern.dim()],
        }
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
    ) -> Result<MassReport, NotPositiveDefinite> {
        pattern.row_sums(values, &mut self.diagonal);
        let active = self.diagonal.iter().filter(|&&m| m > T::zero()).count();
        Ok(MassReport {
            active,
            lumped_rows: active,
        })
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) {
        for (i, r) in rhs.iter_mut().enumerate() {
            let m = self.diagonal[i];
            *r = if self.fixed[k][i] || m <= T::zero() {
                T::zero()
            } else {
                *r / m
            };
        }
    }
}
