//! FMPM(k): a truncated series for `M⁻¹` preconditioned by the lumped mass,
//! `M⁻¹ ≈ Σ_{j=0}^{K} (I − M_L⁻¹ M)^j M_L⁻¹`, which needs no factorisation.
//!
//! For a non-negative basis `M_L − M` is positive semi-definite, so the
//! eigenvalues of `M_L⁻¹ M` lie in `(0, 1]` and the series converges to `M⁻¹`
//! as `K` grows; `K = 0` is the lumped mass. Every partial sum keeps the row sums
//! of `M_L` (it maps `M 1 = M_L 1` to `1`), so mass and momentum are conserved.
//! It still divides by the lumped mass of nearly empty functions.

use super::{Lumped, MassError, MassReport, MassSetup, MassStrategy, StepContext};
use crate::sparse::{mul_upper, Scalar, SymmetricPattern};

/// The truncated series of order `K`, on top of the lumped solve.
pub struct Fmpm<T: Scalar> {
    order: usize,
    lumped: Lumped<T>,
    values: Vec<T>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    term: Vec<T>,
    product: Vec<T>,
}

impl<T: Scalar> Fmpm<T> {
    /// The series with `order` correction terms.
    pub fn new(order: usize) -> Self {
        Fmpm {
            order,
            lumped: Lumped::default(),
            values: Vec::new(),
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            term: Vec::new(),
            product: Vec::new(),
        }
    }
}

impl<T: Scalar> MassStrategy<T> for Fmpm<T> {
    fn spec(&self) -> String {
        format!("fmpm:{}", self.order)
    }
    fn prepare(&mut self, setup: &MassSetup) {
        let n = setup.pattern.dim();
        self.lumped.prepare(setup);
        self.values = vec![T::zero(); setup.pattern.nnz()];
        self.col_ptr = setup.pattern.col_ptr().to_vec();
        self.row_idx = setup.pattern.row_idx().to_vec();
        self.term = vec![T::zero(); n];
        self.product = vec![T::zero(); n];
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError> {
        self.values.copy_from_slice(values);
        self.lumped.factorize(pattern, values, context)
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        // y₀ = M_L⁻¹ F; t_j = t_{j−1} − M_L⁻¹ M t_{j−1}; y = Σ t_j.
        self.lumped.solve(k, rhs)?;
        self.term.copy_from_slice(rhs);
        for _ in 0..self.order {
            mul_upper(
                &self.col_ptr,
                &self.row_idx,
                &self.values,
                &self.term,
                &mut self.product,
            );
            self.lumped.solve(k, &mut self.product)?;
            for ((t, p), y) in self.term.iter_mut().zip(&self.product).zip(rhs.iter_mut()) {
                *t -= *p;
                *y += *t;
            }
        }
        Ok(())
    }
    /// The system divided by is `M_L`: `max M_ii^L / min M_ii^L`.
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        self.lumped.condition_estimate(pattern)
    }
}
