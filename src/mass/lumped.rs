//! The lumped (row-sum) mass `M_ii^L = Σ_j M_ij = Σ_p m_p phi_i(x_p)`.
//!
//! A function whose lumped mass is round-off ([`ROUNDOFF_MASS`] of the largest or
//! less) is treated as a function without mass, as it is in exact arithmetic: a
//! particle exactly on an edge that bounds a function's support gives it a value
//! of about 1e-16 instead of 0, and dividing by that mass put the critical step at
//! 1e-10 (a user's PL disk whose lattice put a particle on a block diagonal:
//! `docs/stability.md`, "Round-off masses").

use super::{MassError, MassReport, MassSetup, MassStrategy, Needs, StepContext};
use crate::last_written::LastWritten;
use crate::sparse::{Scalar, SymmetricPattern};

/// Row-sum lumping: a diagonal solve.
#[derive(Default)]
pub struct Lumped<T: Scalar> {
    fixed: Vec<Vec<bool>>,
    diagonal: Vec<T>,
    /// The functions whose lumped mass may be nonzero: the last factorisation's
    /// live list, when it ran through one.
    written: LastWritten,
    /// Scratch of the solve through `written`: its right-hand sides.
    kept: Vec<T>,
}

impl<T: Scalar> Lumped<T> {
    /// The lumped masses of the last factorisation.
    pub fn diagonal(&self) -> &[T] {
        &self.diagonal
    }
}

impl<T: Scalar> MassStrategy<T> for Lumped<T> {
    fn spec(&self) -> String {
        "lumped".into()
    }
    fn needs(&self) -> Needs {
        Needs {
            row_sums_only: true,
            ..Needs::default()
        }
    }
    fn prepare(&mut self, setup: &MassSetup) {
        self.fixed = setup.fixed.to_vec();
        self.diagonal = vec![T::zero(); setup.pattern.dim()];
        self.written = LastWritten::with_capacity(setup.pattern.dim());
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError> {
        if let (true, Some(live)) = (context.diagonal_only, context.live_list) {
            // A body over a small part of the mesh: the masses outside the live
            // list are zero, those of the last list are zeroed (the same masses
            // as the pass over every function, without it).
            for i in self.written.each(self.diagonal.len()) {
                self.diagonal[i] = T::zero();
            }
            for &i in live {
                self.diagonal[i as usize] = values[pattern.diagonal_position(i as usize)];
            }
            let active = without_roundoff_masses_of(&mut self.diagonal, live);
            self.written.record(live);
            return Ok(MassReport {
                active,
                lumped_rows: active,
                ..MassReport::default()
            });
        }
        self.written.record_all();
        if context.diagonal_only {
            // The same sums without the pass over the whole pattern, whose other
            // entries are zero: in a mostly empty mesh that pass was a quarter
            // of the step.
            for (i, d) in self.diagonal.iter_mut().enumerate() {
                *d = values[pattern.diagonal_position(i)];
            }
        } else {
            pattern.row_sums(values, &mut self.diagonal);
        }
        let active = without_roundoff_masses(&mut self.diagonal);
        Ok(MassReport {
            active,
            lumped_rows: active,
            ..MassReport::default()
        })
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        if let Some(written) = self.written.listed() {
            // Every function outside the list has no mass and solves to zero:
            // the list's right-hand sides kept, the rest zeroed at once (the same
            // bits as the division pass over every function, which in a mostly
            // empty mesh was a seventh of the step).
            self.kept.clear();
            self.kept.extend(written.iter().map(|&i| rhs[i as usize]));
            rhs.iter_mut().for_each(|r| *r = T::zero());
            for (&i, &r) in written.iter().zip(&self.kept) {
                let (i, m) = (i as usize, self.diagonal[i as usize]);
                if !self.fixed[k][i] && m > T::zero() {
                    rhs[i] = r / m;
                }
            }
            return Ok(());
        }
        for (i, r) in rhs.iter_mut().enumerate() {
            let m = self.diagonal[i];
            *r = if self.fixed[k][i] || m <= T::zero() {
                T::zero()
            } else {
                *r / m
            };
        }
        Ok(())
    }
    /// `max M_ii / min M_ii` over active rows.
    fn condition_estimate(&mut self, _pattern: &SymmetricPattern) -> f64 {
        diagonal_condition(&self.diagonal)
    }
}

/// Lumped masses at or below this share of the largest are round-off: the value
/// of a function at a particle on the edge of its support, zero in exact
/// arithmetic, is about 1e-16 in floating point. A share of 1e-12 is a particle
/// within about 1e-11 of an element's size of the edge (the masses of the
/// functions a body covers are 10–50 particle masses), where the function's
/// critical step would be a millionth of the others'.
pub const ROUNDOFF_MASS: f64 = 1e-12;

/// Sets the lumped masses at or below [`ROUNDOFF_MASS`] of the largest to zero:
/// functions without mass, which the solves leave at zero. Returns the number of
/// functions with mass left.
pub(super) fn without_roundoff_masses<T: Scalar>(diagonal: &mut [T]) -> usize {
    without_roundoff_masses_in(diagonal, 0..diagonal.len())
}

/// [`without_roundoff_masses`] where only the entries `listed` may be nonzero.
fn without_roundoff_masses_of<T: Scalar>(diagonal: &mut [T], listed: &[u32]) -> usize {
    without_roundoff_masses_in(diagonal, listed.iter().map(|&i| i as usize))
}

/// [`without_roundoff_masses`] over the entries `entries` (the others zero).
fn without_roundoff_masses_in<T: Scalar>(
    diagonal: &mut [T],
    entries: impl Iterator<Item = usize> + Clone,
) -> usize {
    let largest = entries.clone().fold(T::zero(), |a, i| a.max(diagonal[i]));
    let floor = largest * T::of(ROUNDOFF_MASS);
    let mut with_mass = 0;
    for i in entries {
        if diagonal[i] <= floor {
            diagonal[i] = T::zero();
        } else {
            with_mass += 1;
        }
    }
    with_mass
}

/// `max / min` of the positive entries (1 without any).
pub(super) fn diagonal_condition<T: Scalar>(diagonal: &[T]) -> f64 {
    let (lo, hi) = diagonal
        .iter()
        .filter(|&&m| m > T::zero())
        .map(|m| m.to_f64())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
            (lo.min(m), hi.max(m))
        });
    if hi > 0.0 {
        hi / lo
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Masses at round-off of the largest are zero; the others are kept, and
    /// counted.
    #[test]
    fn roundoff_masses_are_no_mass() {
        let mut diagonal = vec![1.0, 1e-16, 0.5, 0.0, 5e-13, 1e-11];
        assert_eq!(without_roundoff_masses(&mut diagonal), 3);
        assert_eq!(diagonal, vec![1.0, 0.0, 0.5, 0.0, 0.0, 1e-11]);
        let mut empty = vec![0.0f64; 3];
        assert_eq!(without_roundoff_masses(&mut empty), 0);
        // Through a list of the entries that may be nonzero: the same.
        let mut diagonal = vec![1.0, 1e-16, 0.5, 0.0, 5e-13, 1e-11];
        assert_eq!(
            without_roundoff_masses_of(&mut diagonal, &[0, 1, 2, 4, 5]),
            3
        );
        assert_eq!(diagonal, vec![1.0, 0.0, 0.5, 0.0, 0.0, 1e-11]);
    }
}
