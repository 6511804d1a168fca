//! The sparse Cholesky solve shared by the strategies that modify `M` row by row
//! (consistent, partial lumping, deactivation): rows held at zero (fixed or
//! inactive) leave the system (it is factorised on its kept rows alone, and they
//! solve to zero), lumped rows move every off-diagonal entry onto both diagonals,
//! `M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ`. Row sums
//! are kept, so mass and momentum are conserved, and since `M_ij ≥ 0`
//! (non-negative bases) `M' ⪰ M` stays symmetric positive definite.

use super::condition::{estimate, Operator};
use super::{distinct_fixed_sets, MassError, MassSetup};
use crate::last_written::LastWritten;
use crate::sparse::{mul_upper, NotPositiveDefinite, Scalar, SparseCholesky, SymmetricPattern};
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
            } else {
                off_diagonal(r, c, values[k], lumped, diagonal_add)
            };
        }
    }
    for (i, add) in diagonal_add.iter().enumerate() {
        out[pattern.diagonal_position(i)] += *add;
    }
}

/// One fixed set's system restricted to its kept rows (neither fixed nor
/// inactive): the same entries as the masked system's kept block
/// (`modify_rows`' rules, in the same order), factorised without the masked
/// rows, whose solution is zero anyway. The symbolic factorisation is kept while
/// the kept rows stay the same.
///
/// The whole pattern with the masked rows on the diagonal was factorised instead
/// until 2026-12-08 whenever a quarter or more of the functions were kept; the
/// kept rows alone cost less at every share measured (`docs/performance.md`, "The
/// kept rows alone, at every share"), a cantilever over 30 % of its mesh 1.6×
/// per step, a block over 40 % 1.4–2.3× with `partial`.
struct Compact<T: Scalar> {
    /// The kept rows, ascending.
    rows: Vec<usize>,
    /// Per compact entry, the position of its entry in the full pattern (the
    /// pattern holds fewer than `u32::MAX` entries: `SymmetricPattern::new`).
    source: Vec<u32>,
    values: Vec<T>,
    /// The factorisation of the upper triangle over the kept rows, which holds
    /// that triangle's pattern (`col_ptr`, `row_idx`).
    solver: SparseCholesky<T>,
    /// Right-hand side and work vectors over the kept rows.
    rhs: Vec<T>,
    work: [Vec<T>; 2],
}

impl<T: Scalar> Compact<T> {
    /// The compact pattern of `rows` (ascending) in `pattern`; `slot` maps a
    /// function to its compact index (`usize::MAX` when not kept), restored to
    /// `usize::MAX` before returning.
    fn new(pattern: &SymmetricPattern, rows: Vec<usize>, slot: &mut [usize]) -> Self {
        for (q, &i) in rows.iter().enumerate() {
            slot[i] = q;
        }
        let (ptr, idx) = (pattern.col_ptr(), pattern.row_idx());
        let mut col_ptr = Vec::with_capacity(rows.len() + 1);
        let (mut row_idx, mut source) = (Vec::new(), Vec::new());
        col_ptr.push(0);
        for &c in &rows {
            // Rows are sorted within a column and `slot` grows with the index, so
            // the compact rows stay sorted.
            for k in ptr[c]..ptr[c + 1] {
                let q = slot[idx[k]];
                if q != usize::MAX {
                    row_idx.push(q);
                    source.push(k as u32);
                }
            }
            col_ptr.push(row_idx.len());
        }
        for &i in &rows {
            slot[i] = usize::MAX;
        }
        let m = rows.len();
        let solver = SparseCholesky::from_upper(col_ptr, row_idx, 2);
        Compact {
            values: vec![T::zero(); source.len()],
            rhs: vec![T::zero(); 2 * m],
            work: [vec![T::zero(); m], vec![T::zero(); m]],
            rows,
            source,
            solver,
        }
    }

    /// `M'` on the kept rows (`modify_rows` restricted to them: a lumped row's
    /// off-diagonal entries onto both diagonals), then its factorisation.
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        lumped: &[bool],
        diagonal_add: &mut [T],
    ) -> Result<(), NotPositiveDefinite> {
        let idx = pattern.row_idx();
        for &i in &self.rows {
            diagonal_add[i] = T::zero();
        }
        let col_ptr = self.solver.col_ptr();
        for (q, &c) in self.rows.iter().enumerate() {
            for t in col_ptr[q]..col_ptr[q + 1] {
                let k = self.source[t] as usize;
                let r = idx[k];
                self.values[t] = if r == c {
                    values[k]
                } else {
                    off_diagonal(r, c, values[k], lumped, diagonal_add)
                };
            }
        }
        for (q, &i) in self.rows.iter().enumerate() {
            // The diagonal is the last entry of its (upper) column.
            self.values[col_ptr[q + 1] - 1] += diagonal_add[i];
        }
        self.solver.factorize(&self.values)
    }

    /// Solves for the kept rows of `rhs` and sets its other rows to zero (what
    /// the masked system gives them).
    fn solve(&mut self, rhs: &mut [T]) {
        for (v, &i) in self.rhs.iter_mut().zip(&self.rows) {
            *v = rhs[i];
        }
        rhs.iter_mut().for_each(|v| *v = T::zero());
        let m = self.rows.len();
        self.solver.solve_in_place(&mut self.rhs[..m], 1);
        for (v, &i) in self.rhs.iter().zip(&self.rows) {
            rhs[i] = *v;
        }
    }

    /// [`solve`](Self::solve) of two right-hand sides in one pass over the factor.
    fn solve_two(&mut self, first: &mut [T], second: &mut [T]) {
        let m = self.rows.len();
        let (r0, r1) = self.rhs.split_at_mut(m);
        for ((a, b), &i) in r0.iter_mut().zip(r1.iter_mut()).zip(&self.rows) {
            *a = first[i];
            *b = second[i];
        }
        first.iter_mut().for_each(|v| *v = T::zero());
        second.iter_mut().for_each(|v| *v = T::zero());
        self.solver.solve_in_place(&mut self.rhs, 2);
        let (r0, r1) = self.rhs.split_at(m);
        for ((&a, &b), &i) in r0.iter().zip(r1).zip(&self.rows) {
            first[i] = a;
            second[i] = b;
        }
    }

    /// The condition estimate of the kept system.
    fn condition_estimate(&mut self) -> f64 {
        // The pattern is the solver's, shared for the products while the inverse
        // iteration uses the solver.
        let (col_ptr, row_idx) = self.solver.shared_pattern();
        let values = &self.values;
        let solver = &mut self.solver;
        let mut op = Operator {
            apply: &mut |x: &[T], y: &mut [T]| mul_upper(&col_ptr, &row_idx, values, x, y),
            solve: &mut |y: &mut [T]| {
                solver.solve_in_place(y, 1);
                Ok(())
            },
        };
        let [x, y] = &mut self.work;
        estimate(&mut op, x, y)
    }
}

/// The entry `(r, c)`, `r ≠ c`, of `M'` for `M_rc = value`: moved onto both
/// diagonals (`diagonal_add`) when either row is lumped, else kept.
#[inline]
fn off_diagonal<T: Scalar>(
    r: usize,
    c: usize,
    value: T,
    lumped: &[bool],
    diagonal_add: &mut [T],
) -> T {
    if lumped[r] || lumped[c] {
        diagonal_add[r] += value;
        diagonal_add[c] += value;
        T::zero()
    } else {
        value
    }
}

/// One factorisation per distinct set of fixed coefficients, each of its kept
/// rows alone ([`Compact`]).
#[derive(Default)]
pub(super) struct MaskedCholesky<T: Scalar> {
    fixed: Vec<Vec<bool>>,
    /// `solver_of[k]`: index of the factorisation used by component `k`.
    solver_of: Vec<usize>,
    /// Rows held at zero in every component (no particle, or deactivated).
    pub inactive: Vec<bool>,
    /// Rows replaced by their lumped value.
    pub lumped: Vec<bool>,
    /// `off_diagonal`'s buffer, one per distinct fixed set.
    diagonal_add: Vec<Vec<T>>,
    /// The failure of each set's last factorisation.
    failed: Vec<Option<NotPositiveDefinite>>,
    /// Per fixed set, its kept rows' system (`None` before the first
    /// factorisation).
    compact: Vec<Option<Compact<T>>>,
    /// Function → compact index, `usize::MAX` between uses; kept rows of a set.
    slot: Vec<usize>,
    kept: Vec<usize>,
    /// The functions the last [`factorize_listed`](Self::factorize_listed)
    /// marked, while its marks hold: every other row is inactive and not lumped
    /// (any row may be marked after [`factorize`](Self::factorize)).
    marked: LastWritten,
}

impl<T: Scalar> MaskedCholesky<T> {
    pub fn prepare(&mut self, setup: &MassSetup) {
        let pattern = setup.pattern;
        let (distinct, solver_of) = distinct_fixed_sets(setup.fixed);
        let n = pattern.dim();
        self.fixed = distinct;
        self.solver_of = solver_of;
        self.inactive = vec![false; n];
        self.lumped = vec![false; n];
        self.diagonal_add = vec![vec![T::zero(); n]; self.fixed.len()];
        self.failed = vec![None; self.fixed.len()];
        self.compact = self.fixed.iter().map(|_| None).collect();
        self.slot = vec![usize::MAX; n];
        self.kept = Vec::with_capacity(n);
        self.marked = LastWritten::with_capacity(n);
    }

    /// For each fixed set, (re)builds the compact pattern of its kept rows when
    /// they changed. `listed`: the only rows that may be kept, ascending (else
    /// every row may).
    fn choose_compact(&mut self, pattern: &SymmetricPattern, listed: Option<&[u32]>) {
        let n = pattern.dim();
        for s in 0..self.fixed.len() {
            let fixed = &self.fixed[s];
            self.kept.clear();
            let kept = |&i: &usize| !(fixed[i] || self.inactive[i]);
            match listed {
                Some(list) => self
                    .kept
                    .extend(list.iter().map(|&i| i as usize).filter(kept)),
                None => self.kept.extend((0..n).filter(kept)),
            }
            if self.compact[s].as_ref().is_none_or(|c| c.rows != self.kept) {
                self.compact[s] = Some(Compact::new(pattern, self.kept.clone(), &mut self.slot));
            }
        }
    }

    /// Factorises `M'` for the current [`inactive`](Self::inactive) and
    /// [`lumped`](Self::lumped) marks.
    pub fn factorize(&mut self, pattern: &SymmetricPattern, values: &[T]) -> Result<(), MassError> {
        self.marked.record_all();
        self.factorize_marked(pattern, values, None)
    }

    /// [`factorize`](Self::factorize) for a body over a small part of the mesh:
    /// every function outside `list` (ascending) has no mass and is marked
    /// inactive, a listed one where `inactive(i)`; no row is lumped. The marks
    /// and sums pass through the list (and the last call's), not every function;
    /// the factor is the same.
    pub fn factorize_listed(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        list: &[u32],
        inactive: impl Fn(usize) -> bool,
    ) -> Result<(), MassError> {
        for i in self.marked.each(self.inactive.len()) {
            self.inactive[i] = true;
            self.lumped[i] = false;
        }
        for &i in list {
            self.inactive[i as usize] = inactive(i as usize);
        }
        self.marked.record(list);
        self.factorize_marked(pattern, values, Some(list))
    }

    /// The factorisation for the marks; `listed`: the rows outside it are inactive.
    fn factorize_marked(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        listed: Option<&[u32]>,
    ) -> Result<(), MassError> {
        self.choose_compact(pattern, listed);
        // The distinct fixed sets are independent systems: factorised side by side
        // on the pool (each result is the same for any thread count), the first
        // failure in set order reported.
        let lumped = &self.lumped;
        (
            self.diagonal_add.par_iter_mut(),
            self.failed.par_iter_mut(),
            self.compact.par_iter_mut(),
        )
            .into_par_iter()
            .for_each(|(diagonal_add, failed, compact)| {
                let compact = compact.as_mut().expect("built by choose_compact");
                *failed = compact
                    .factorize(pattern, values, lumped, diagonal_add)
                    .err();
            });
        if let Some(failure) = self.failed.iter().flatten().next() {
            return Err(MassError::from(failure.clone()));
        }
        Ok(())
    }

    /// The compact system of component `k`'s fixed set.
    fn compact_of(&mut self, k: usize) -> &mut Compact<T> {
        self.compact[self.solver_of[k]]
            .as_mut()
            .expect("solve before a successful factorisation")
    }

    /// Solves component `k`; the rows held at zero (fixed or inactive) solve to
    /// zero.
    pub fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        self.compact_of(k).solve(rhs);
        Ok(())
    }

    /// The compact systems of the distinct fixed sets `a ≠ b`, borrowed apart (to
    /// solve them side by side).
    fn two_sets(&mut self, a: usize, b: usize) -> (&mut Compact<T>, &mut Compact<T>) {
        let (low, high) = self.compact.split_at_mut(a.max(b));
        let lower = low[a.min(b)].as_mut();
        let higher = high[0].as_mut();
        let (lower, higher) = (
            lower.expect("solve before a successful factorisation"),
            higher.expect("solve before a successful factorisation"),
        );
        if a < b {
            (lower, higher)
        } else {
            (higher, lower)
        }
    }

    /// [`solve`](Self::solve) for every component; two components with different
    /// fixed sets (two factorisations) are solved side by side on the pool.
    pub fn solve_all(&mut self, rhs: &mut [Vec<T>]) -> Result<(), MassError> {
        match (rhs, self.solver_of.as_slice()) {
            ([r0, r1], &[a, b]) if a != b => {
                let (c0, c1) = self.two_sets(a, b);
                rayon::join(|| c0.solve(r0), || c1.solve(r1));
            }
            (rhs, _) => {
                for (k, r) in rhs.iter_mut().enumerate() {
                    self.compact_of(k).solve(r);
                }
            }
        }
        Ok(())
    }

    /// [`solve_all`](Self::solve_all) of two sets of right-hand sides, each
    /// component's pair in one pass over its factor.
    pub fn solve_all_two(
        &mut self,
        first: &mut [Vec<T>],
        second: &mut [Vec<T>],
    ) -> Result<(), MassError> {
        match (first, second, self.solver_of.as_slice()) {
            ([a0, a1], [b0, b1], &[a, b]) if a != b => {
                let (c0, c1) = self.two_sets(a, b);
                rayon::join(|| c0.solve_two(a0, b0), || c1.solve_two(a1, b1));
            }
            (first, second, _) => {
                for (k, (a, b)) in first.iter_mut().zip(second.iter_mut()).enumerate() {
                    self.compact_of(k).solve_two(a, b);
                }
            }
        }
        Ok(())
    }

    /// `λ_max` of `M'` on the kept rows by power iteration, `λ_min` by inverse
    /// iteration with the factorisation; the largest ratio over the fixed sets.
    pub fn condition_estimate(&mut self, _pattern: &SymmetricPattern) -> f64 {
        self.compact
            .iter_mut()
            .flatten()
            .map(|c| c.condition_estimate())
            .fold(0.0, f64::max)
    }
}
