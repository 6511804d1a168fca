//! Sparse symmetric matrices on a basis, and their Cholesky factorisation.
//!
//! The mass matrix `M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)` (paper eq. (13)) and the
//! L² Gram matrix share one sparsity pattern: `i` and `j` couple when some element
//! carries both functions. [`SymmetricPattern`] builds that pattern once per basis,
//! stores its upper triangle in compressed sparse column form (an `sprs` matrix), and
//! precomputes for every element where each local pair `(a, b)` lands in the value
//! array, so that assembly is a gather–scatter without searching.
//!
//! [`SparseCholesky`] splits the work as faer does: the symbolic factorisation
//! (fill-reducing ordering, elimination tree, factor pattern) once per pattern,
//! the numeric factorisation and the solves on every call, with all scratch memory
//! owned by the struct, so that a time step allocates nothing.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::utils::{permute_self_adjoint_scratch, permute_self_adjoint_to_unsorted};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use psmpm_basis::{Basis, Real};
use std::sync::Arc;

/// The scalar types the solvers accept: a [`Real`] that faer can factorise (`f32`, `f64`).
pub trait Scalar: Real + faer::traits::RealField {}
impl<T: Real + faer::traits::RealField> Scalar for T {}

/// Upper-triangular CSC pattern of a symmetric matrix indexed by basis functions,
/// with per-element scatter maps.
#[derive(Debug, Clone)]
pub struct SymmetricPattern {
    /// Column pointers of the upper triangle (`row ≤ col`) in CSC storage; the
    /// values are kept by the caller. Shared with the factorisations of the
    /// pattern ([`SparseCholesky::new`]), not copied.
    col_ptr: Arc<[usize]>,
    /// Row indices of the upper triangle, sorted within each column.
    row_idx: Arc<[usize]>,
    /// For element `e`, `scatter[scatter_offsets[e]..]` holds, for each local pair
    /// `(a, b)` (row-major over the element's functions), the position of entry
    /// `(min(i,j), max(i,j))` in the value array (32 bits: the scene limits keep
    /// the entries below 2³², checked here).
    scatter: Vec<u32>,
    scatter_offsets: Vec<usize>,
    /// Position of each diagonal entry in the value array.
    diagonal: Vec<usize>,
}

impl SymmetricPattern {
    /// The pattern of all products `phi_i phi_j` of `basis`: column `c` holds the
    /// functions `r ≤ c` that share an element of `c`'s support with it, and `c`.
    ///
    /// # Panics
    /// If the pattern has `2³²` entries or more (about `10⁸` functions; the scene
    /// limits stay far below).
    pub fn new<T: Real, const D: usize, B: Basis<T, D> + ?Sized>(basis: &B) -> Self {
        let n = basis.num_functions();
        // Column by column, the rows marked in `mark` (stamp `c + 1`) as found.
        let mut mark = vec![0usize; n];
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        for c in 0..n {
            let start = row_idx.len();
            mark[c] = c + 1;
            row_idx.push(c);
            for &e in basis.function_support(c) {
                for &r in basis.element_functions(e) {
                    if r < c && mark[r] != c + 1 {
                        mark[r] = c + 1;
                        row_idx.push(r);
                    }
                }
            }
            row_idx[start..].sort_unstable();
            col_ptr.push(row_idx.len());
        }
        row_idx.shrink_to_fit();
        assert!(
            row_idx.len() < u32::MAX as usize,
            "a mass matrix pattern of {} entries (the limit is 2^32)",
            row_idx.len()
        );
        let position = |i: usize, j: usize| -> usize {
            let (r, c) = if i <= j { (i, j) } else { (j, i) };
            let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            col_ptr[c] + rows.binary_search(&r).expect("entry in pattern")
        };
        let total: usize = (0..basis.num_elements())
            .map(|e| basis.element_functions(e).len().pow(2))
            .sum();
        let mut scatter = Vec::with_capacity(total);
        let mut scatter_offsets = Vec::with_capacity(basis.num_elements() + 1);
        scatter_offsets.push(0);
        for e in 0..basis.num_elements() {
            let f = basis.element_functions(e);
            for &i in f {
                for &j in f {
                    scatter.push(position(i, j) as u32);
                }
            }
            scatter_offsets.push(scatter.len());
        }
        let diagonal = (0..n).map(|i| position(i, i)).collect();
        SymmetricPattern {
            col_ptr: col_ptr.into(),
            row_idx: row_idx.into(),
            scatter,
            scatter_offsets,
            diagonal,
        }
    }

    /// Matrix dimension.
    pub fn dim(&self) -> usize {
        self.col_ptr.len() - 1
    }
    /// Number of stored (upper-triangular) entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
    /// Column pointers of the upper triangle.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }
    /// Row indices of the upper triangle (sorted within each column).
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }
    /// The column pointers and row indices themselves, shared (reference-counted),
    /// for a holder that keeps the pattern without copying it.
    pub fn shared_structure(&self) -> (Arc<[usize]>, Arc<[usize]>) {
        (self.col_ptr.clone(), self.row_idx.clone())
    }
    /// Value positions of the local pairs of element `e`, row-major over its functions.
    #[inline]
    pub fn element_scatter(&self, e: usize) -> &[u32] {
        &self.scatter[self.scatter_offsets[e]..self.scatter_offsets[e + 1]]
    }
    /// Value position of diagonal entry `i`.
    #[inline]
    pub fn diagonal_position(&self, i: usize) -> usize {
        self.diagonal[i]
    }

    /// `y = A x` for the symmetric matrix whose upper triangle has `values`.
    pub fn mul_vec<T: Real>(&self, values: &[T], x: &[T], y: &mut [T]) {
        mul_upper(self.col_ptr(), self.row_idx(), values, x, y);
    }

    /// Row sums `Σ_j A_ij` of the symmetric matrix (the lumped mass).
    pub fn row_sums<T: Real>(&self, values: &[T], out: &mut [T]) {
        out.iter_mut().for_each(|v| *v = T::zero());
        let (ptr, rows) = (self.col_ptr(), self.row_idx());
        for c in 0..self.dim() {
            for k in ptr[c]..ptr[c + 1] {
                let r = rows[k];
                out[r] += values[k];
                if r != c {
                    out[c] += values[k];
                }
            }
        }
    }
}

/// `y = A x` for the symmetric matrix whose upper triangle is stored in compressed
/// sparse columns (`col_ptr`, `row_idx`, `values`).
pub fn mul_upper<T: Real>(
    col_ptr: &[usize],
    row_idx: &[usize],
    values: &[T],
    x: &[T],
    y: &mut [T],
) {
    y.iter_mut().for_each(|v| *v = T::zero());
    for c in 0..col_ptr.len() - 1 {
        for k in col_ptr[c]..col_ptr[c + 1] {
            let r = row_idx[k];
            let a = values[k];
            y[r] += a * x[c];
            if r != c {
                y[c] += a * x[r];
            }
        }
    }
}

/// The factorisation failed: the matrix is not numerically positive definite.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "matrix is not positive definite (non-positive pivot at row {row} of the reordered matrix)"
)]
pub struct NotPositiveDefinite {
    /// Pivot row in the fill-reducing order.
    pub row: usize,
}

/// Systems from this size on are factorised supernodally (dense blocks of columns
/// with the same pattern), smaller ones as faer chooses (simplicial there). Measured
/// side by side (`mpm-cli throughput`, one thread, PS consistent mass on the B5a
/// column): at 9 789 functions the supernodal factorisation and solves take 10 ms
/// per step against 17.6 ms for the simplicial one faer picks (the whole step
/// 40.1 against 48.9 ms); at 879 functions the two are within the machine's noise,
/// and the supernodal scratch costs 4 MB more.
pub const SUPERNODAL_FROM: usize = 4096;

/// A pattern of at most this many upper entries per column on average is a band
/// (1D: three for the quadratic B-spline, two for PL1D) and is factorised as faer
/// chooses (simplicial) at any size: its factor has no fill and no dense blocks,
/// and a supernodal factorisation pays a dense kernel call per column of width 3.
pub const BAND_ENTRIES_PER_COLUMN: f64 = 3.0;

/// The supernodal choice for an `n × n` pattern of `nnz` upper entries
/// ([`SUPERNODAL_FROM`], [`BAND_ENTRIES_PER_COLUMN`]).
fn supernodal_threshold(n: usize, nnz: usize) -> SupernodalThreshold {
    if n >= SUPERNODAL_FROM && nnz as f64 > BAND_ENTRIES_PER_COLUMN * n as f64 {
        SupernodalThreshold::FORCE_SUPERNODAL
    } else {
        SupernodalThreshold::AUTO
    }
}

/// Sparse Cholesky `A = L Lᵀ` of a symmetric positive definite matrix with a fixed
/// [`SymmetricPattern`]: symbolic analysis once, numeric factorisation per call.
///
/// The fill-reducing order (AMD) is found once, and the matrix is handed to faer
/// already in that order: the set-up runs faer's own permutation once on the
/// entries' positions, which gives where each entry of the caller's upper
/// triangle lands in the permuted triangle faer factorises (`gather`), and the
/// factorisation is then analysed in the identity order. Each numeric
/// factorisation gathers the values into place instead of faer permuting the
/// whole matrix (index arrays and values) on every call, 2–3 % of a PS step in the
/// profile (`docs/performance.md`); the factor, and every solve, are the same to
/// the last bit as with faer's own permutation (`same_bits_as_faers_ordering`).
pub struct SparseCholesky<T: Scalar> {
    symbolic: SymbolicCholesky<usize>,
    col_ptr: Arc<[usize]>,
    row_idx: Arc<[usize]>,
    /// `perm_fwd[k]`: the original row at position `k` of the fill-reducing order.
    perm_fwd: Vec<usize>,
    /// The permuted triangle faer factorises (lower for a supernodal factor,
    /// upper for a simplicial one): its pattern, and `gather[t]` = the entry of
    /// the caller's upper triangle at its position `t`.
    permuted_col_ptr: Vec<usize>,
    permuted_row_idx: Vec<usize>,
    gather: Vec<usize>,
    permuted_values: Vec<T>,
    l_values: Vec<T>,
    factorised: bool,
    scratch: MemBuffer,
    /// Right-hand sides in the fill-reducing order.
    permuted_rhs: Vec<T>,
    rhs_columns: usize,
}

impl<T: Scalar> std::fmt::Debug for SparseCholesky<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseCholesky")
            .field("dim", &(self.col_ptr.len() - 1))
            .field("factor_nnz", &self.l_values.len())
            .field("factorised", &self.factorised)
            .finish()
    }
}

impl<T: Scalar> SparseCholesky<T> {
    /// Symbolic factorisation (AMD ordering) of `pattern`, with scratch memory for
    /// solves with up to `rhs_columns` right-hand sides at once.
    pub fn new(pattern: &SymmetricPattern, rhs_columns: usize) -> Self {
        Self::shared(
            pattern.col_ptr.clone(),
            pattern.row_idx.clone(),
            rhs_columns,
        )
    }

    /// Symbolic factorisation (AMD ordering) of the symmetric matrix whose upper
    /// triangle has the compressed sparse columns `col_ptr`, `row_idx` (rows
    /// sorted within each column, every diagonal entry present).
    pub fn from_upper(col_ptr: Vec<usize>, row_idx: Vec<usize>, rhs_columns: usize) -> Self {
        Self::shared(col_ptr.into(), row_idx.into(), rhs_columns)
    }

    fn shared(col_ptr: Arc<[usize]>, row_idx: Arc<[usize]>, rhs_columns: usize) -> Self {
        let n = col_ptr.len() - 1;
        let nnz = row_idx.len();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let threshold = supernodal_threshold(n, nnz);
        let ordered = factorize_symbolic_cholesky(
            sym,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: threshold,
                ..Default::default()
            },
        )
        .expect("symbolic Cholesky of a valid pattern");
        let supernodal = matches!(ordered.raw(), SymbolicCholeskyRaw::Supernodal(_));
        let (perm_fwd, perm_inv) = match ordered.perm() {
            Some(perm) => {
                let (fwd, inv) = perm.arrays();
                (fwd.to_vec(), inv.to_vec())
            }
            None => ((0..n).collect(), (0..n).collect()),
        };
        let perm = PermRef::new_checked(&perm_fwd, &perm_inv, n);
        // faer's permutation of the entries' positions: where each entry lands, in
        // the side the symbolic analysis reads (upper) and the one the numeric
        // factorisation reads (lower for supernodal, as faer does).
        let positions: Vec<f64> = (0..nnz).map(|t| t as f64).collect();
        let source = SparseColMatRef::new(sym, &positions[..]);
        let permuted = |out_side: Side| {
            let (mut values, mut cp, mut ri) =
                (vec![0.0f64; nnz], vec![0usize; n + 1], vec![0usize; nnz]);
            let mut stack = MemBuffer::new(permute_self_adjoint_scratch::<usize>(n));
            permute_self_adjoint_to_unsorted(
                &mut values,
                &mut cp,
                &mut ri,
                source,
                perm,
                Side::Upper,
                out_side,
                MemStack::new(&mut stack),
            );
            (
                cp,
                ri,
                values.into_iter().map(|t| t as usize).collect::<Vec<_>>(),
            )
        };
        let (upper_cp, upper_ri, _) = permuted(Side::Upper);
        let symbolic = factorize_symbolic_cholesky(
            SymbolicSparseColMatRef::new_unsorted_checked(n, n, &upper_cp, None, &upper_ri),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: if supernodal {
                    SupernodalThreshold::FORCE_SUPERNODAL
                } else {
                    SupernodalThreshold::FORCE_SIMPLICIAL
                },
                ..Default::default()
            },
        )
        .expect("symbolic Cholesky of a valid pattern");
        let (permuted_col_ptr, permuted_row_idx, gather) = if supernodal {
            permuted(Side::Lower)
        } else {
            permuted(Side::Upper)
        };
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<T>(par, Default::default()),
            symbolic.solve_in_place_scratch::<T>(rhs_columns.max(1), par),
        ]);
        let l_values = vec![T::zero(); symbolic.len_val()];
        SparseCholesky {
            symbolic,
            col_ptr,
            row_idx,
            perm_fwd,
            permuted_col_ptr,
            permuted_row_idx,
            gather,
            permuted_values: vec![T::zero(); nnz],
            l_values,
            factorised: false,
            scratch: MemBuffer::new(req),
            permuted_rhs: vec![T::zero(); n * rhs_columns.max(1)],
            rhs_columns: rhs_columns.max(1),
        }
    }

    /// Column pointers of the upper triangle this factorisation was made for.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// Row indices of the upper triangle this factorisation was made for.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// [`col_ptr`](Self::col_ptr) and [`row_idx`](Self::row_idx) shared
    /// (reference-counted, no copy), to read while the factorisation is used.
    pub fn shared_pattern(&self) -> (Arc<[usize]>, Arc<[usize]>) {
        (self.col_ptr.clone(), self.row_idx.clone())
    }

    /// Whether this factorisation was made for the upper pattern `col_ptr`, `row_idx`.
    pub fn has_pattern(&self, col_ptr: &[usize], row_idx: &[usize]) -> bool {
        *self.col_ptr == *col_ptr && *self.row_idx == *row_idx
    }

    /// Numeric factorisation of the matrix whose upper triangle has `values`
    /// (in the order of the pattern). Allocation-free.
    pub fn factorize(&mut self, values: &[T]) -> Result<(), NotPositiveDefinite> {
        let n = self.col_ptr.len() - 1;
        for (v, &t) in self.permuted_values.iter_mut().zip(&self.gather) {
            *v = values[t];
        }
        let sym = SymbolicSparseColMatRef::new_unsorted_checked(
            n,
            n,
            &self.permuted_col_ptr,
            None,
            &self.permuted_row_idx,
        );
        let a = SparseColMatRef::new(sym, &self.permuted_values[..]);
        let side = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(_) => Side::Lower,
            SymbolicCholeskyRaw::Simplicial(_) => Side::Upper,
        };
        self.factorised = false;
        let result = self.symbolic.factorize_numeric_llt::<T>(
            &mut self.l_values,
            a,
            side,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.scratch),
            Default::default(),
        );
        match result {
            Ok(_) => {
                self.factorised = true;
                Ok(())
            }
            Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => {
                Err(NotPositiveDefinite { row: index })
            }
        }
    }

    /// Solves `A X = B` in place for the `columns` right-hand sides stored
    /// column-major in `rhs` (length `n · columns`).
    ///
    /// # Panics
    /// If called before a successful [`factorize`](Self::factorize), or with more
    /// columns than the scratch was sized for.
    /// [`solve_in_place`](Self::solve_in_place) of two right-hand sides held
    /// apart, in one pass over the factor (needs `rhs_columns ≥ 2`): the solve
    /// reads the factor from memory once for both.
    pub fn solve_two_in_place(&mut self, first: &mut [T], second: &mut [T]) {
        assert!(self.factorised, "solve before a successful factorisation");
        assert!(
            self.rhs_columns >= 2,
            "two right-hand sides need the scratch for two"
        );
        let n = self.col_ptr.len() - 1;
        let x = &mut self.permuted_rhs[..2 * n];
        let (x0, x1) = x.split_at_mut(n);
        for ((a, b), &f) in x0.iter_mut().zip(x1.iter_mut()).zip(&self.perm_fwd) {
            *a = first[f];
            *b = second[f];
        }
        let b = MatMut::from_column_major_slice_mut(x, n, 2);
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            b,
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        let (x0, x1) = self.permuted_rhs[..2 * n].split_at(n);
        for ((&a, &b), &f) in x0.iter().zip(x1).zip(&self.perm_fwd) {
            first[f] = a;
            second[f] = b;
        }
    }

    pub fn solve_in_place(&mut self, rhs: &mut [T], columns: usize) {
        assert!(self.factorised, "solve before a successful factorisation");
        assert!(
            columns <= self.rhs_columns,
            "more right-hand sides than scratch allows"
        );
        let n = self.col_ptr.len() - 1;
        let x = &mut self.permuted_rhs[..n * columns];
        for j in 0..columns {
            let (b, x) = (&rhs[j * n..(j + 1) * n], &mut x[j * n..(j + 1) * n]);
            for (xi, &f) in x.iter_mut().zip(&self.perm_fwd) {
                *xi = b[f];
            }
        }
        let b = MatMut::from_column_major_slice_mut(x, n, columns);
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            b,
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        for j in 0..columns {
            let (b, x) = (
                &mut rhs[j * n..(j + 1) * n],
                &self.permuted_rhs[j * n..(j + 1) * n],
            );
            for (&xi, &f) in x.iter().zip(&self.perm_fwd) {
                b[f] = xi;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The upper pattern and values of a symmetric positive definite matrix on an
    /// `m × m` grid of nodes with 9-point couplings (diagonally dominant).
    fn grid_matrix(m: usize) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = m * m;
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            let (jx, jy) = (j % m, j / m);
            let mut rows: Vec<usize> = Vec::new();
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (x, y) = (jx as i64 + dx, jy as i64 + dy);
                    if x >= 0 && y >= 0 && (x as usize) < m && (y as usize) < m {
                        let i = y as usize * m + x as usize;
                        if i <= j {
                            rows.push(i);
                        }
                    }
                }
            }
            rows.sort_unstable();
            for i in rows {
                row_idx.push(i);
                values.push(if i == j {
                    9.0 + (j % 7) as f64 * 0.1
                } else {
                    -0.5 - ((i * 31 + j * 17) % 13) as f64 * 0.03
                });
            }
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx, values)
    }

    /// Factor and solve through faer's own AMD permutation, as faer does it.
    fn faer_ordered(
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        b: &mut [f64],
    ) -> Vec<f64> {
        let n = col_ptr.len() - 1;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: supernodal_threshold(n, row_idx.len()),
                ..Default::default()
            },
        )
        .unwrap();
        let mut l = vec![0.0; symbolic.len_val()];
        let mut scratch = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        symbolic
            .factorize_numeric_llt::<f64>(
                &mut l,
                SparseColMatRef::new(sym, values),
                Side::Upper,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .unwrap();
        LltRef::new(&symbolic, &l).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, n, 1),
            Par::Seq,
            MemStack::new(&mut scratch),
        );
        l
    }

    /// The factor and the solution through the gathered, pre-permuted matrix are
    /// those of faer's own permutation to the last bit, simplicial (small) and
    /// supernodal (from `SUPERNODAL_FROM` functions).
    #[test]
    fn same_bits_as_faers_ordering() {
        for m in [12, 70] {
            let (col_ptr, row_idx, values) = grid_matrix(m);
            let n = m * m;
            let b: Vec<f64> = (0..n)
                .map(|i| ((i * 37) % 101) as f64 / 101.0 - 0.4)
                .collect();
            let mut expected = b.clone();
            let l = faer_ordered(&col_ptr, &row_idx, &values, &mut expected);
            let mut ours = SparseCholesky::<f64>::from_upper(col_ptr, row_idx, 1);
            ours.factorize(&values).unwrap();
            assert_eq!(ours.l_values.len(), l.len());
            assert!(ours
                .l_values
                .iter()
                .zip(&l)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            let mut x = b.clone();
            ours.solve_in_place(&mut x, 1);
            assert!(
                x.iter()
                    .zip(&expected)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "m = {m}"
            );
        }
    }

    /// Two right-hand sides solved in one pass give each one's solution (to
    /// round-off: the pass sums them as a block), and solve the system.
    #[test]
    fn two_right_hand_sides_solve_as_each_alone() {
        for m in [12, 70] {
            let (col_ptr, row_idx, values) = grid_matrix(m);
            let n = m * m;
            let b: [Vec<f64>; 2] = [37, 53].map(|s| {
                (0..n)
                    .map(|i| ((i * s) % 101) as f64 / 101.0 - 0.4)
                    .collect()
            });
            let mut solver = SparseCholesky::<f64>::from_upper(col_ptr.clone(), row_idx.clone(), 2);
            solver.factorize(&values).unwrap();
            let [mut x0, mut x1] = b.clone();
            solver.solve_two_in_place(&mut x0, &mut x1);
            for (x, b) in [(&x0, &b[0]), (&x1, &b[1])] {
                let mut alone = b.clone();
                solver.solve_in_place(&mut alone, 1);
                let scale = alone.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let worst = x
                    .iter()
                    .zip(&alone)
                    .fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
                assert!(worst <= 1e-13 * scale, "m = {m}: {worst:e}");
                // M x = b from the upper triangle.
                let mut mx = vec![0.0; n];
                for c in 0..n {
                    for t in col_ptr[c]..col_ptr[c + 1] {
                        let r = row_idx[t];
                        mx[r] += values[t] * x[c];
                        if r != c {
                            mx[c] += values[t] * x[r];
                        }
                    }
                }
                let residual = mx
                    .iter()
                    .zip(b)
                    .fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
                assert!(residual < 1e-12, "m = {m}: residual {residual:e}");
            }
        }
    }
}
