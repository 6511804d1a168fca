//! The consistent mass matrix (paper eq. (13)), solved by sparse Cholesky.

use super::masked::MaskedCholesky;
use super::{MassError, MassReport, MassSetup, MassStrategy, StepContext};
use crate::sparse::{Scalar, SymmetricPattern};

/// `M` itself; functions without particles are held at zero.
#[derive(Default)]
pub struct Consistent<T: Scalar> {
    solver: MaskedCholesky<T>,
}

impl<T: Scalar> MassStrategy<T> for Consistent<T> {
    fn spec(&self) -> String {
        "consistent".into()
    }
    fn prepare(&mut self, setup: &MassSetup) {
        self.solver.prepare(setup);
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        _context: StepContext,
    ) -> Result<MassReport, MassError> {
        let mut report = MassReport::default();
        for i in 0..pattern.dim() {
            let empty = values[pattern.diagonal_position(i)] <= T::zero();
            self.solver.inactive[i] = empty;
            report.active += !empty as usize;
        }
        self.solver.factorize(pattern, values)?;
        Ok(report)
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        self.solver.solve(k, rhs)
    }
    fn solve_all(&mut self, rhs: &mut [Vec<T>]) -> Result<(), MassError> {
        self.solver.solve_all(rhs)
    }
    fn solve_all_two(
        &mut self,
        first: &mut [Vec<T>],
        second: &mut [Vec<T>],
    ) -> Result<(), MassError> {
        self.solver.solve_all_two(first, second)
    }
    fn solves_mass_itself(&self) -> bool {
        true
    }
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        self.solver.condition_estimate(pattern)
    }
}
