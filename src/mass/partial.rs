//! Partial lumping (thesis §5.3): the rows chosen by a rule are lumped, the rest
//! of `M` is kept (see the module `masked` for why mass, momentum and positive
//! definiteness are kept).

use super::masked::MaskedCholesky;
use super::{MassError, MassReport, MassSetup, MassStrategy, Needs, StepContext, SupportFacts};
use crate::sparse::{Scalar, SymmetricPattern};

/// Which rows a partially lumped strategy lumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LumpRule {
    /// The seeds' rule: rows whose function's support contains an element without
    /// particles (thesis §5.3).
    EmptyElement,
    /// Rows with `M_ii < threshold · max_j M_jj`.
    Threshold(f64),
    /// Rows whose function's support is covered by particle volume below this
    /// fraction of its integral (`Σ_p V_p phi_i(x_p) < c ∫ phi_i`).
    Coverage(f64),
}

/// `M` with the rows chosen by a [`LumpRule`] lumped.
pub struct Partial<T: Scalar> {
    rule: LumpRule,
    solver: MaskedCholesky<T>,
    support_volume: Vec<f64>,
    /// Some row lumped in the system last factorised.
    any_lumped: bool,
}

impl<T: Scalar> Partial<T> {
    /// Partial lumping by `rule`.
    pub fn new(rule: LumpRule) -> Self {
        Partial {
            rule,
            solver: MaskedCholesky::default(),
            support_volume: Vec::new(),
            any_lumped: false,
        }
    }
}

impl<T: Scalar> MassStrategy<T> for Partial<T> {
    fn spec(&self) -> String {
        match self.rule {
            LumpRule::EmptyElement => "partial".into(),
            LumpRule::Threshold(tau) => format!("partial:{tau}"),
            LumpRule::Coverage(c) => format!("partial-coverage:{c}"),
        }
    }
    fn needs(&self) -> Needs {
        Needs {
            empty_elements: self.rule == LumpRule::EmptyElement,
            coverage: matches!(self.rule, LumpRule::Coverage(_)),
            polynomials: false,
            correction: super::Correction::None,
            row_sums_only: false,
        }
    }
    fn prepare(&mut self, setup: &MassSetup) {
        self.solver.prepare(setup);
        if let Some(support) = setup.support {
            self.support_volume = support.volume.clone();
        }
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError> {
        let n = pattern.dim();
        let diag = |i: usize| values[pattern.diagonal_position(i)];
        let max_diag = (0..n)
            .map(diag)
            .fold(T::zero(), |a, b| if b > a { b } else { a });
        let mut report = MassReport::default();
        for i in 0..n {
            let d = diag(i);
            let inactive = d <= T::zero();
            self.solver.inactive[i] = inactive;
            let lumped = !inactive
                && match self.rule {
                    LumpRule::EmptyElement => context.touches_empty[i],
                    LumpRule::Threshold(tau) => d < max_diag * T::of(tau),
                    LumpRule::Coverage(c) => {
                        let coverage = SupportFacts::coverage_of(
                            context.particle_volume[i],
                            self.support_volume[i],
                        );
                        if report.worst_coverage.is_none_or(|(_, w)| coverage < w) {
                            report.worst_coverage = Some((i, coverage));
                        }
                        coverage < c
                    }
                };
            self.solver.lumped[i] = lumped;
            report.lumped_rows += lumped as usize;
            report.active += !inactive as usize;
        }
        self.any_lumped = report.lumped_rows > 0;
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
        !self.any_lumped
    }
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        self.solver.condition_estimate(pattern)
    }
}
