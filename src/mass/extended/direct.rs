//! The direct solve of the reduced system: `Eᵀ M E` assembled explicitly on the
//! free functions of one fixed set and factorised by sparse Cholesky.
//!
//! The product is formed column by column (Gustavson's order): column `j` of
//! `E`, then `M` times it, then `Eᵀ` of that, with dense accumulators and marker
//! lists, so that the work is that of the nonzero products. The pattern of
//! `Eᵀ M E` changes only when the set of extended or active functions does; the
//! symbolic factorisation (ordering, elimination tree) is kept while the pattern
//! holds and redone when it changes, and the numeric factorisation is done every
//! step. Measured against the Jacobi-preconditioned conjugate gradients it
//! replaces in `docs/stability.md`.

use super::solve::Reduced;
use super::Role;
use crate::sparse::{NotPositiveDefinite, Scalar, SparseCholesky};

/// Both triangles of the pattern of `M`: for column `c`, the rows `r` with an
/// entry `(r, c)` or `(c, r)` and the position of that entry in the upper values.
/// Rows and positions are 32-bit: the driver refuses meshes whose element pairs
/// reach 2³¹ (`SetupError::TooManyFunctions`), and the full pattern holds at most
/// as many entries as those pairs.
#[derive(Default)]
pub(super) struct FullPattern {
    ptr: Vec<usize>,
    row: Vec<u32>,
    position: Vec<u32>,
}

impl FullPattern {
    /// From the upper triangle in compressed sparse columns.
    pub(super) fn new(col_ptr: &[usize], row_idx: &[usize]) -> Self {
        let n = col_ptr.len() - 1;
        let mut count = vec![0usize; n + 1];
        for c in 0..n {
            for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                count[c + 1] += 1;
                if r != c {
                    count[r + 1] += 1;
                }
            }
        }
        for c in 0..n {
            count[c + 1] += count[c];
        }
        let mut cursor = count[..n].to_vec();
        let total = count[n];
        let (mut row, mut position) = (vec![0u32; total], vec![0u32; total]);
        let narrow = |i: usize| u32::try_from(i).expect("the driver bounds the pattern below 2³¹");
        for c in 0..n {
            for k in col_ptr[c]..col_ptr[c + 1] {
                let r = row_idx[k];
                row[cursor[c]] = narrow(r);
                position[cursor[c]] = narrow(k);
                cursor[c] += 1;
                if r != c {
                    row[cursor[r]] = narrow(c);
                    position[cursor[r]] = narrow(k);
                    cursor[r] += 1;
                }
            }
        }
        FullPattern {
            ptr: count,
            row,
            position,
        }
    }
}

/// `Eᵀ M E` on the free functions of one fixed set, and its factorisation.
#[derive(Default)]
pub(super) struct Direct<T: Scalar> {
    /// Compact index of each free function (`usize::MAX` for the others).
    slot: Vec<usize>,
    /// The free functions, ascending (compact index → function).
    free: Vec<usize>,
    /// Columns of `E` (the transpose of its rows): for the free function of
    /// compact index `q`, the extended functions `r` with `E_ri ≠ 0` and the weight.
    by_column_ptr: Vec<usize>,
    by_column: Vec<(usize, T)>,
    cursor: Vec<usize>,
    /// `M E e_j` accumulated over functions, with its marker list.
    y: Vec<T>,
    y_mark: Vec<bool>,
    y_rows: Vec<usize>,
    /// Column `j` of `Eᵀ M E` accumulated over compact rows.
    acc: Vec<T>,
    acc_mark: Vec<bool>,
    acc_rows: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<T>,
    factor: Option<SparseCholesky<T>>,
    /// The factorisation of this step succeeded.
    pub(super) ready: bool,
    /// Symbolic factorisations made (the pattern changed), for the report.
    pub(super) symbolic_count: usize,
    b: Vec<T>,
}

impl<T: Scalar> Direct<T> {
    /// Buffers for `n` functions.
    pub(super) fn new(n: usize) -> Self {
        Direct {
            slot: vec![usize::MAX; n],
            by_column_ptr: Vec::with_capacity(n + 1),
            y: vec![T::zero(); n],
            y_mark: vec![false; n],
            acc: vec![T::zero(); n],
            acc_mark: vec![false; n],
            b: vec![T::zero(); n],
            ..Default::default()
        }
    }

    /// Assembles `Eᵀ M E` for the operator `op` (its values, roles, extension
    /// rows and fixed set) and factorises it.
    pub(super) fn factorize(
        &mut self,
        op: &Reduced<'_, T>,
        full: &FullPattern,
    ) -> Result<(), NotPositiveDefinite> {
        self.ready = false;
        // `slot` is `usize::MAX` off the last step's free functions.
        for &i in &self.free {
            self.slot[i] = usize::MAX;
        }
        self.free.clear();
        for &i in op.active {
            if op.free(i) {
                self.slot[i] = self.free.len();
                self.free.push(i);
            }
        }
        let m = self.free.len();
        // Columns of E restricted to the extended rows (the solved rows are the
        // identity), by compact index of the free function.
        self.by_column_ptr.clear();
        self.by_column_ptr.resize(m + 1, 0);
        for &r in op.extended {
            if op.fixed[r] {
                continue;
            }
            for t in op.ext_ptr[r]..op.ext_ptr[r + 1] {
                if op.free(op.ext_idx[t]) {
                    self.by_column_ptr[self.slot[op.ext_idx[t]] + 1] += 1;
                }
            }
        }
        for q in 0..m {
            self.by_column_ptr[q + 1] += self.by_column_ptr[q];
        }
        self.by_column.clear();
        self.by_column.resize(self.by_column_ptr[m], (0, T::zero()));
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.by_column_ptr[..m]);
        for &r in op.extended {
            if op.fixed[r] {
                continue;
            }
            for t in op.ext_ptr[r]..op.ext_ptr[r + 1] {
                let i = op.ext_idx[t];
                if op.free(i) {
                    let q = self.slot[i];
                    self.by_column[self.cursor[q]] = (r, op.ext_w[t]);
                    self.cursor[q] += 1;
                }
            }
        }
        self.col_ptr.clear();
        self.row_idx.clear();
        self.values.clear();
        self.col_ptr.push(0);
        for q in 0..self.free.len() {
            let j = self.free[q];
            // y = M (E e_j): E e_j is e_j plus the extended rows that use j.
            self.add_mass_column(op, full, j, T::one());
            for t in self.by_column_ptr[q]..self.by_column_ptr[q + 1] {
                let (r, w) = self.by_column[t];
                self.add_mass_column(op, full, r, w);
            }
            // Column j of Eᵀ y, upper part (compact rows ≤ q).
            for s in 0..self.y_rows.len() {
                let r = self.y_rows[s];
                let yr = self.y[r];
                self.y[r] = T::zero();
                self.y_mark[r] = false;
                match op.role[r] {
                    Role::Solved if !op.fixed[r] => self.accumulate(self.slot[r], q, yr),
                    Role::Extended if !op.fixed[r] => {
                        for t in op.ext_ptr[r]..op.ext_ptr[r + 1] {
                            let i = op.ext_idx[t];
                            if op.free(i) {
                                self.accumulate(self.slot[i], q, op.ext_w[t] * yr);
                            }
                        }
                    }
                    _ => {}
                }
            }
            self.y_rows.clear();
            // Every diagonal entry present (the factorisation needs it).
            self.accumulate(q, q, T::zero());
            self.acc_rows.sort_unstable();
            for &k in &self.acc_rows {
                self.row_idx.push(k);
                self.values.push(self.acc[k]);
                self.acc[k] = T::zero();
                self.acc_mark[k] = false;
            }
            self.acc_rows.clear();
            self.col_ptr.push(self.row_idx.len());
        }
        if self.free.is_empty() {
            self.ready = true;
            return Ok(());
        }
        let same = self
            .factor
            .as_ref()
            .is_some_and(|f| f.has_pattern(&self.col_ptr, &self.row_idx));
        if !same {
            self.factor = Some(SparseCholesky::from_upper(
                self.col_ptr.clone(),
                self.row_idx.clone(),
                1,
            ));
            self.symbolic_count += 1;
        }
        let factor = self.factor.as_mut().expect("factor made above");
        factor.factorize(&self.values)?;
        self.ready = true;
        Ok(())
    }

    /// `y += w M e_c` over the active rows.
    #[inline]
    fn add_mass_column(&mut self, op: &Reduced<'_, T>, full: &FullPattern, c: usize, w: T) {
        for k in full.ptr[c]..full.ptr[c + 1] {
            let r = full.row[k] as usize;
            if matches!(op.role[r], Role::Inactive | Role::Ghost) || op.fixed[r] {
                continue;
            }
            if !self.y_mark[r] {
                self.y_mark[r] = true;
                self.y_rows.push(r);
            }
            self.y[r] += w * op.values[full.position[k] as usize];
        }
    }

    #[inline]
    fn accumulate(&mut self, row: usize, column: usize, v: T) {
        if row > column {
            return;
        }
        if !self.acc_mark[row] {
            self.acc_mark[row] = true;
            self.acc_rows.push(row);
        }
        self.acc[row] += v;
    }

    /// Solves `Eᵀ M E x = Eᵀ rhs` and writes `E x` into `rhs` (zero off the
    /// active functions). `full_b` and `x` are scratch of the function count.
    pub(super) fn solve(
        &mut self,
        op: &Reduced<'_, T>,
        rhs: &mut [T],
        full_b: &mut [T],
        x: &mut [T],
    ) {
        op.restrict(rhs, full_b);
        let m = self.free.len();
        for q in 0..m {
            self.b[q] = full_b[self.free[q]];
        }
        if m > 0 {
            let factor = self.factor.as_mut().expect("solve after factorize");
            factor.solve_in_place(&mut self.b[..m], 1);
        }
        // `x` is zero between solves: the free entries set, then restored.
        for q in 0..m {
            x[self.free[q]] = self.b[q];
        }
        // `E x` is zero off the active functions: a fill, then the active rows.
        rhs.iter_mut().for_each(|v| *v = T::zero());
        op.expand(x, rhs);
        for &i in &self.free {
            x[i] = T::zero();
        }
    }
}
