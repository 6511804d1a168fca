//! General linear constraints on the coefficients (a wall whose constraint couples
//! several functions, or both components of one: oblique slip walls), imposed
//! exactly on top of any mass strategy, so that solving means solve and project.

use super::{MassError, MassStrategy};
use crate::sparse::Scalar;

/// A constraint whose Cholesky pivot falls below this fraction of its diagonal is
/// dependent on the earlier ones (or acts on inactive functions) and is dropped.
pub const DEPENDENT_CONSTRAINT: f64 = 1e-10;

/// General linear constraints `Σ_e w_e a[k_e][i_e] = 0` on the coefficients (a
/// wall whose constraint couples several functions or both components of one),
/// imposed exactly: with the step's mass operator `M` (block-diagonal over
/// components, as the strategy modified it), the constrained minimiser of
/// `½ aᵀ M a − aᵀ F` is `a = a₀ − W S⁻¹ C a₀` with `a₀ = M⁻¹ F`, `W = M⁻¹ Cᵀ` and
/// `S = C W`. `W` and `S` are formed once per step (one solve per constraint and
/// component); each projection is then a small dense solve. Buffers are sized
/// once; a constraint whose functions are all inactive (zero pivot) is skipped.
pub struct Constraints<T: Scalar, const D: usize> {
    pub(crate) rows: Vec<Vec<(usize, usize, T)>>,
    /// `W[c][k]`: component `k` of `M⁻¹ Cᵀ e_c`, allocated when first solved
    /// (empty before: a wall far from every body costs no memory).
    w: Vec<Vec<Vec<T>>>,
    /// `W[c][k]` holds this step's solve; otherwise it is zero and not read (the
    /// constraint touches no function with particles), so a step costs what the
    /// constraints near the bodies cost, not the size of the mesh times the walls.
    solved: Vec<[bool; D]>,
    /// Length of each `W[c][k]` (the number of functions).
    n: usize,
    /// `S = C W`, then its Cholesky factor (row-major, lower triangle).
    s: Vec<f64>,
    /// Pivot kept (`false` for constraints on inactive functions).
    keep: Vec<bool>,
    lambda: Vec<f64>,
}

impl<T: Scalar, const D: usize> Constraints<T, D> {
    pub fn new(rows: Vec<Vec<(usize, usize, T)>>, n: usize) -> Self {
        let m = rows.len();
        Constraints {
            w: vec![vec![Vec::new(); D]; m],
            solved: vec![[false; D]; m],
            n,
            s: vec![0.0; m * m],
            keep: vec![false; m],
            lambda: vec![0.0; m],
            rows,
        }
    }

    /// Number of general constraints.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// `true` without general constraints.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Forms `W` and the Cholesky factor of `S` with the strategy's factorisation.
    /// `has_particles(i)`: function `i` has particles in its support (`M_ii > 0`);
    /// a constraint on functions without any needs no solve (its `W` is zero, as
    /// every strategy holds such functions at zero), which keeps the cost of slip
    /// walls to the walls a body touches.
    pub fn prepare<M: MassStrategy<T> + ?Sized>(
        &mut self,
        mass: &mut M,
        has_particles: impl Fn(usize) -> bool,
    ) -> Result<(), MassError> {
        let m = self.rows.len();
        if m == 0 {
            return Ok(());
        }
        for (c, row) in self.rows.iter().enumerate() {
            for k in 0..D {
                let touched = row.iter().any(|&(kk, i, _)| kk == k && has_particles(i));
                self.solved[c][k] = touched;
                if !touched {
                    continue;
                }
                let w = &mut self.w[c][k];
                if w.is_empty() {
                    w.resize(self.n, T::zero());
                } else {
                    w.iter_mut().for_each(|v| *v = T::zero());
                }
                for &(kk, i, weight) in row {
                    if kk == k {
                        w[i] += weight;
                    }
                }
                mass.solve(k, w)?;
            }
        }
        // `S = C W`; a `W[d][k]` not solved this step is zero.
        let (w, solved) = (&self.w, &self.solved);
        for c in 0..m {
            for d in 0..m {
                self.s[c * m + d] = self.rows[c]
                    .iter()
                    .map(|&(k, i, weight)| {
                        if solved[d][k] {
                            (weight * w[d][k][i]).to_f64()
                        } else {
                            0.0
                        }
                    })
                    .sum();
            }
        }
        // In-place Cholesky, skipping the pivots that vanish relative to their own
        // diagonal (constraints on inactive functions, or dependent on earlier ones;
        // the scale differs wildly between rows: `S_cc ~ 1 / M_ii`).
        for j in 0..m {
            let diagonal = self.s[j * m + j];
            let mut d = diagonal;
            for k in 0..j {
                if self.keep[k] {
                    d -= self.s[j * m + k] * self.s[j * m + k];
                }
            }
            self.keep[j] = d > DEPENDENT_CONSTRAINT * diagonal && diagonal > 0.0;
            if !self.keep[j] {
                continue;
            }
            let d = d.sqrt();
            self.s[j * m + j] = d;
            for i in j + 1..m {
                let mut v = self.s[i * m + j];
                for k in 0..j {
                    if self.keep[k] {
                        v -= self.s[i * m + k] * self.s[j * m + k];
                    }
                }
                self.s[i * m + j] = v / d;
            }
        }
        Ok(())
    }

    /// Projects the solved coefficients `a` onto the constraints.
    pub fn project(&mut self, a: &mut [Vec<T>]) {
        let m = self.rows.len();
        if m == 0 {
            return;
        }
        for (c, row) in self.rows.iter().enumerate() {
            self.lambda[c] = row
                .iter()
                .map(|&(k, i, weight)| (weight * a[k][i]).to_f64())
                .sum();
        }
        // S λ = C a: forward and back substitution with the kept pivots.
        for j in 0..m {
            if !self.keep[j] {
                self.lambda[j] = 0.0;
                continue;
            }
            let mut v = self.lambda[j];
            for k in 0..j {
                if self.keep[k] {
                    v -= self.s[j * m + k] * self.lambda[k];
                }
            }
            self.lambda[j] = v / self.s[j * m + j];
        }
        for j in (0..m).rev() {
            if !self.keep[j] {
                continue;
            }
            let mut v = self.lambda[j];
            for i in j + 1..m {
                if self.keep[i] {
                    v -= self.s[i * m + j] * self.lambda[i];
                }
            }
            self.lambda[j] = v / self.s[j * m + j];
        }
        for c in 0..m {
            let l = T::of(self.lambda[c]);
            if self.lambda[c] == 0.0 {
                continue;
            }
            for k in (0..D).filter(|&k| self.solved[c][k]) {
                for (x, w) in a[k].iter_mut().zip(&self.w[c][k]) {
                    *x -= l * *w;
                }
            }
        }
    }
}
