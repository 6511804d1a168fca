//! Deactivation (thesis §5.2): functions with a small diagonal mass are removed
//! from the system.

use super::masked::MaskedCholesky;
use super::{MassError, MassReport, MassSetup, MassStrategy, StepContext};
use crate::sparse::{Scalar, SymmetricPattern};

/// `M` without the functions whose `M_ii` is below an absolute threshold.
pub struct Deactivate<T: Scalar> {
    threshold: f64,
    solver: MaskedCholesky<T>,
    /// Functions removed (with particles) in the last factorisation.
    deactivated: Vec<bool>,
    /// [`MassStrategy::held_force_share`] of the last solve of forces.
    held_force_share: f64,
}

impl<T: Scalar> Deactivate<T> {
    /// Removes functions with `0 < M_ii < threshold` (the thesis uses 1e-2).
    pub fn new(threshold: f64) -> Self {
        Deactivate {
            threshold,
            solver: MaskedCholesky::default(),
            deactivated: Vec::new(),
            held_force_share: 0.0,
        }
    }
}

impl<T: Scalar> MassStrategy<T> for Deactivate<T> {
    fn spec(&self) -> String {
        format!(
            "deactivate:{}",
            crate::scene::limits::echo_number(self.threshold)
        )
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
        let mut largest = 0.0f64;
        self.deactivated.resize(pattern.dim(), false);
        for i in 0..pattern.dim() {
            let d = values[pattern.diagonal_position(i)];
            largest = largest.max(d.to_f64());
            let empty = d <= T::zero();
            let deactivated = !empty && d.to_f64() < self.threshold;
            self.solver.inactive[i] = empty || deactivated;
            self.deactivated[i] = deactivated;
            report.deactivated += deactivated as usize;
            report.active += !self.solver.inactive[i] as usize;
        }
        if report.active == 0 && report.deactivated > 0 {
            return Err(MassError::NothingActive {
                threshold: self.threshold,
                // Three digits: enough to choose a threshold below it.
                largest: crate::scene::limits::significant(largest, 3),
            });
        }
        report.largest_mass = largest;
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
        // The forces before the solve drops the deactivated rows' share.
        let (mut held, mut total) = (0.0, 0.0);
        for i in 0..self.deactivated.len() {
            let f = first
                .iter()
                .map(|c| c[i].to_f64() * c[i].to_f64())
                .sum::<f64>()
                .sqrt();
            total += f;
            if self.deactivated[i] {
                held += f;
            }
        }
        self.held_force_share = if total > 0.0 { held / total } else { 0.0 };
        self.solver.solve_all_two(first, second)
    }
    fn held_force_share(&self) -> f64 {
        self.held_force_share
    }
    /// The active rows' own system: deactivated rows are held at zero.
    fn solves_mass_itself(&self) -> bool {
        true
    }
    fn deactivation_threshold(&self) -> Option<f64> {
        Some(self.threshold)
    }
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        self.solver.condition_estimate(pattern)
    }
}
