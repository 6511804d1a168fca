//! Deterministic sums over particles for any number of threads: particles binned
//! by element ([`Bins`], a stable counting sort), element-local sums in particle
//! order ([`Local`]), and gathers of the element-local values into matrix entries
//! and function coefficients in element order ([`Gather`]). Used by the phases of
//! [`super::phases`]; see its module doc for why.

use super::phases::{Evaluations, CHUNK};
use crate::last_written::LastWritten;
use crate::sparse::{Scalar, SymmetricPattern};
use nalgebra::SVector;
use psmpm_basis::Basis;
use rayon::prelude::*;

/// Elements per parallel task of the element-local sums.
pub(super) const ELEMENT_CHUNK: usize = 64;

/// Matrix entries or coefficients per parallel task of the gathers.
pub(super) const ENTRY_CHUNK: usize = 4096;

/// Number of [`CHUNK`]s for `particles` particles.
pub fn chunks(particles: usize) -> usize {
    particles.div_ceil(CHUNK)
}

/// Particles grouped by element, in particle order within each element (a
/// stable counting sort, refilled every step).
pub struct Bins {
    /// Particles of element `e`: `order[start[e]..start[e + 1]]` (32 bits: the
    /// driver refuses 2³² particles or more).
    pub(super) start: Vec<usize>,
    pub(super) order: Vec<u32>,
    pub(super) cursor: Vec<usize>,
    /// The elements holding a particle, ascending.
    occupied: Vec<u32>,
}

impl Bins {
    /// Buffers for `elements` elements and `particles` particles.
    pub fn new(elements: usize, particles: usize) -> Self {
        Bins {
            start: vec![0; elements + 1],
            order: vec![0; particles],
            cursor: vec![0; elements],
            occupied: Vec::new(),
        }
    }

    /// Sorts the particles by their `element`.
    pub fn fill(&mut self, element: &[usize]) {
        self.fill_with_slots(element, &mut []);
    }

    /// [`fill`](Self::fill), and `slot[p]` = the position of particle `p` in the
    /// order (when `slot` is not empty).
    pub fn fill_with_slots(&mut self, element: &[usize], slot: &mut [u32]) {
        self.start.iter_mut().for_each(|s| *s = 0);
        for &e in element {
            self.start[e + 1] += 1;
        }
        let ne = self.cursor.len();
        self.occupied.clear();
        for e in 0..ne {
            if self.start[e + 1] > 0 {
                self.occupied.push(e as u32);
            }
            self.start[e + 1] += self.start[e];
        }
        self.cursor.copy_from_slice(&self.start[..ne]);
        let with_slots = !slot.is_empty();
        for (p, &e) in element.iter().enumerate() {
            let s = self.cursor[e];
            self.order[s] = p as u32;
            if with_slots {
                slot[p] = s as u32;
            }
            self.cursor[e] += 1;
        }
    }

    /// The particles in element `e`, in increasing order.
    #[inline]
    pub fn particles(&self, e: usize) -> &[u32] {
        &self.order[self.start[e]..self.start[e + 1]]
    }

    /// `true` if element `e` holds a particle.
    #[inline]
    pub fn occupied(&self, e: usize) -> bool {
        self.start[e + 1] > self.start[e]
    }

    /// The elements holding a particle, ascending.
    pub fn occupied_elements(&self) -> &[u32] {
        &self.occupied
    }
}

/// Particles lying on the closure of elements other than their own: on a shared
/// edge, vertex or node ([`Basis::other_elements_at`]), where location picked one
/// of the elements around by round-off. Per particle its other elements, per
/// element its other particles, both in particle order; refilled every step by
/// the strategies whose decisions depend on which elements hold particles, so
/// that those decisions count such a particle in every element around it.
#[derive(Default)]
pub struct Touching {
    /// `(particle, element)` pairs of each [`CHUNK`] of particles, in particle
    /// order: the other elements of a particle.
    pairs: Vec<Vec<(u32, u32)>>,
    /// Pairs in all.
    total: usize,
    /// CSR by element: its other particles.
    element_start: Vec<usize>,
    element_particles: Vec<u32>,
    cursor: Vec<usize>,
}

impl Touching {
    /// Finds the other elements of every particle at `x` in `element`.
    pub fn fill<T: Scalar, const D: usize, B: Basis<T, D>>(
        &mut self,
        basis: &B,
        x: &[SVector<T, D>],
        element: &[usize],
    ) {
        let n = x.len();
        self.pairs.resize_with(chunks(n), Vec::new);
        self.pairs
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, pairs)| {
                pairs.clear();
                let range = c * CHUNK..((c + 1) * CHUNK).min(n);
                for p in range {
                    basis.other_elements_at(element[p], &x[p], &mut |e| {
                        pairs.push((p as u32, e as u32))
                    });
                }
            });
        self.total = self.pairs.iter().map(Vec::len).sum();
        // By element: a stable counting sort.
        let ne = basis.num_elements();
        self.element_start.clear();
        self.element_start.resize(ne + 1, 0);
        if self.total == 0 {
            return;
        }
        for &(_, e) in self.pairs.iter().flatten() {
            self.element_start[e as usize + 1] += 1;
        }
        for e in 0..ne {
            self.element_start[e + 1] += self.element_start[e];
        }
        self.element_particles.clear();
        self.element_particles.resize(self.total, 0);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.element_start[..ne]);
        for &(p, e) in self.pairs.iter().flatten() {
            self.element_particles[self.cursor[e as usize]] = p;
            self.cursor[e as usize] += 1;
        }
    }

    /// No particle lies on another element's closure (or not filled).
    pub fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// The elements other than its own whose closure holds particle `p`.
    #[inline]
    pub fn elements_of(&self, p: usize) -> impl Iterator<Item = usize> + '_ {
        let pairs = match self.total {
            0 => &[][..],
            _ => &self.pairs[p / CHUNK][..],
        };
        let start = pairs.partition_point(|&(q, _)| (q as usize) < p);
        pairs[start..]
            .iter()
            .take_while(move |&&(q, _)| q as usize == p)
            .map(|&(_, e)| e as usize)
    }

    /// The particles of other elements that lie on the closure of element `e`.
    #[inline]
    pub fn particles_on(&self, e: usize) -> &[u32] {
        if self.total == 0 {
            return &[];
        }
        &self.element_particles[self.element_start[e]..self.element_start[e + 1]]
    }

    /// Element `e` holds a particle of `bins` or one lies on its closure.
    #[inline]
    pub fn occupied(&self, bins: &Bins, e: usize) -> bool {
        bins.occupied(e) || !self.particles_on(e).is_empty()
    }
}

/// Entries of an element's local matrix block of `stride` functions: its upper
/// triangle, row by row (the blocks are symmetric).
#[inline]
pub(super) fn packed_len(stride: usize) -> usize {
    stride * (stride + 1) / 2
}

/// Position of the local pair `(a, b)`, `a ≤ b`, in an element's block
/// ([`packed_len`]): row `r` holds `stride − r` entries, so row `a` starts at
/// `a · stride − a (a − 1) / 2`.
#[inline]
pub(super) fn packed(stride: usize, a: usize, b: usize) -> usize {
    debug_assert!(a <= b && b < stride);
    a * stride - a * a.saturating_sub(1) / 2 + (b - a)
}

/// An element's local blocks: its mass block, vector coefficients, coverage sums
/// and body-force coefficients.
pub(super) type ElementBlocks<'a, T> = (&'a mut [T], &'a mut [T], &'a mut [T], &'a mut [T]);

/// Element-local sums: per element an upper-triangular `stride × stride` block of
/// the mass matrix and `stride × D` coefficients of a vector field (local
/// function `a` is the element's `a`-th function, as evaluated in phase 1).
///
/// The blocks of the elements without particles are kept zero (a block is zeroed
/// when its element empties, `dirty`), so the element loops visit only the
/// occupied elements and the gathers read zeros from the others.
pub struct Local<T: Scalar, const D: usize> {
    pub(super) stride: usize,
    pub(super) matrix: Vec<T>,
    pub(super) vector: Vec<T>,
    /// Per element `2 × stride`, when asked for ([`Local::with_coverage`], else
    /// empty): each local function's particle volume and particle count,
    /// `Σ_p V_p phi_a(x_p)` and `Σ_p phi_a(x_p)` (the coverage), written by the
    /// assembly of phase 2a alongside the mass matrix.
    pub(super) coverage: Vec<T>,
    /// Per element `stride × D`, when asked for ([`Local::with_body_forces`], else
    /// empty): the forces of the effects that act per particle,
    /// `Σ_p phi_a(x_p) f_p`, summed by the assembly of phase 2a in the same pass.
    pub(super) body: Vec<T>,
    /// Per element: its blocks may hold nonzero values.
    dirty: Vec<bool>,
    /// The elements `dirty` flags, ascending (the occupied elements of the last
    /// visit).
    dirty_list: Vec<u32>,
    /// Scratch: the elements a visit through the lists goes to.
    visit: Vec<u32>,
}

/// Below this share of elements occupied (now or at the last visit) the element
/// loops go through the lists of those elements, on one thread, instead of every
/// element on the pool: a body in a mostly empty mesh. Each element's blocks are
/// its own sums either way, so the choice changes no bit. The affine-preserving
/// lumping's tests of the occupied elements take the same choice.
pub(super) const SPARSE_ELEMENTS: f64 = 0.125;

/// Tests: every pass through a list of live functions or occupied elements
/// switched off, to compare a run against the passes over everything (the same
/// bits are the claim, so a test running beside it is only slower).
#[cfg(test)]
pub(crate) static LISTS_OFF: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Whether the passes may run through lists ([`SPARSE_SHARE`], [`SPARSE_ELEMENTS`]).
#[inline]
pub(super) fn lists_allowed() -> bool {
    #[cfg(test)]
    {
        !LISTS_OFF.load(std::sync::atomic::Ordering::Relaxed)
    }
    #[cfg(not(test))]
    {
        true
    }
}

/// The next `len` entries of `rest` from entry `e · len` on (`consumed`: the
/// entries already split off the front), without `unsafe`.
fn carve<'a, T>(rest: &mut &'a mut [T], consumed: &mut usize, e: usize, len: usize) -> &'a mut [T] {
    if len == 0 {
        return &mut [];
    }
    let tail = std::mem::take(rest);
    let (_, tail) = tail.split_at_mut(e * len - *consumed);
    let (block, tail) = tail.split_at_mut(len);
    *rest = tail;
    *consumed = (e + 1) * len;
    block
}

impl<T: Scalar, const D: usize> Local<T, D> {
    /// Calls `f(e, (matrix, vector))` with the local matrix block and vector of
    /// each element `e` that holds a particle in `bins`, zeroed, in parallel tasks
    /// of at least [`ELEMENT_CHUNK`] elements. The blocks of elements emptied
    /// since the last call are zeroed.
    pub(super) fn for_each_element<F>(&mut self, bins: &Bins, f: F)
    where
        F: Fn(usize, (&mut [T], &mut [T])) + Sync,
    {
        self.each_occupied(bins, true, &|e, (lm, lv, _, _)| f(e, (lm, lv)));
    }

    /// [`Local::for_each_element`] with each element's coverage and body-force
    /// blocks (empty without [`Local::with_coverage`] and
    /// [`Local::with_body_forces`]; not zeroed: their writer overwrites them):
    /// `f(e, (matrix, vector, coverage, body))`.
    pub(super) fn for_each_element_with_coverage<F>(&mut self, bins: &Bins, f: F)
    where
        F: Fn(usize, ElementBlocks<'_, T>) + Sync,
    {
        self.each_occupied(bins, true, &f);
    }

    /// The local vector of each element that holds a particle in `bins`, zeroed
    /// (its matrix block untouched), as [`Local::for_each_element`]: `f(e, vector)`.
    pub(super) fn for_each_vector<F>(&mut self, bins: &Bins, f: F)
    where
        F: Fn(usize, &mut [T]) + Sync,
    {
        self.each_occupied(bins, false, &|e, (_, lv, _, _)| f(e, lv));
    }

    /// The element loop of the three above: through the lists of occupied and
    /// dirty elements when they are few ([`SPARSE_ELEMENTS`]), else every element
    /// on the pool.
    fn each_occupied(
        &mut self,
        bins: &Bins,
        matrix: bool,
        f: &(dyn Fn(usize, ElementBlocks<'_, T>) + Sync),
    ) {
        let elements = self.dirty.len();
        let occupied = bins.occupied_elements();
        if lists_allowed()
            && ((occupied.len() + self.dirty_list.len()) as f64) < SPARSE_ELEMENTS * elements as f64
        {
            self.visit.clear();
            self.visit.extend_from_slice(occupied);
            self.visit.extend_from_slice(&self.dirty_list);
            self.visit.sort_unstable();
            self.visit.dedup();
            let stride = self.stride;
            let lens = [
                packed_len(stride),
                stride * D,
                if self.coverage.is_empty() {
                    0
                } else {
                    2 * stride
                },
                if self.body.is_empty() { 0 } else { stride * D },
            ];
            let mut rest: [&mut [T]; 4] = [
                &mut self.matrix[..],
                &mut self.vector[..],
                &mut self.coverage[..],
                &mut self.body[..],
            ];
            let mut consumed = [0usize; 4];
            for &e in &self.visit {
                let e = e as usize;
                let [lm, lv, lc, lb] =
                    std::array::from_fn(|k| carve(&mut rest[k], &mut consumed[k], e, lens[k]));
                if let Some(blocks) = zero_blocks(
                    bins.occupied(e),
                    &mut self.dirty[e],
                    matrix,
                    (lm, lv, lc, lb),
                ) {
                    f(e, blocks);
                }
            }
        } else {
            self.occupied_blocks(bins, matrix)
                .for_each(|(e, blocks)| f(e, blocks));
        }
        self.dirty_list.clear();
        self.dirty_list.extend_from_slice(occupied);
    }

    /// The blocks of the occupied elements, the vector zeroed and the matrix block
    /// too with `matrix` (the coverage and body-force blocks are left to their
    /// writer); an element
    /// emptied since the last call has all its blocks zeroed and is skipped, so
    /// that every unoccupied element's blocks stay zero.
    fn occupied_blocks<'a>(
        &'a mut self,
        bins: &'a Bins,
        matrix: bool,
    ) -> impl ParallelIterator<Item = (usize, ElementBlocks<'a, T>)> + 'a {
        let stride = self.stride;
        let elements = self.dirty.len();
        // Without coverage sums, an empty coverage block per element.
        let coverage = if self.coverage.is_empty() {
            rayon::iter::Either::Left((0..elements).into_par_iter().map(|_| &mut [][..]))
        } else {
            rayon::iter::Either::Right(self.coverage.par_chunks_mut(2 * stride))
        };
        let body = if self.body.is_empty() {
            rayon::iter::Either::Left((0..elements).into_par_iter().map(|_| &mut [][..]))
        } else {
            rayon::iter::Either::Right(self.body.par_chunks_mut(stride * D))
        };
        (
            self.matrix.par_chunks_mut(packed_len(stride)),
            self.vector.par_chunks_mut(stride * D),
            (coverage, body),
            self.dirty.par_iter_mut(),
        )
            .into_par_iter()
            .with_min_len(ELEMENT_CHUNK)
            .enumerate()
            .filter_map(move |(e, (lm, lv, (lc, lb), dirty))| {
                zero_blocks(bins.occupied(e), dirty, matrix, (lm, lv, lc, lb)).map(|b| (e, b))
            })
    }

    /// Buffers for `elements` elements of up to `stride` functions.
    pub fn new(elements: usize, stride: usize) -> Self {
        Local {
            stride,
            matrix: vec![T::zero(); elements * packed_len(stride)],
            vector: vec![T::zero(); elements * stride * D],
            coverage: Vec::new(),
            body: Vec::new(),
            dirty: vec![false; elements],
            dirty_list: Vec::new(),
            visit: Vec::new(),
        }
    }

    /// With the body-force blocks, for the per-particle forces summed in phase 2a.
    pub fn with_body_forces(mut self) -> Self {
        self.body = vec![T::zero(); self.dirty.len() * self.stride * D];
        self
    }

    /// With the coverage blocks, for the coverage sums of phase 2a.
    pub fn with_coverage(mut self) -> Self {
        self.coverage = vec![T::zero(); self.dirty.len() * 2 * self.stride];
        self
    }
}

/// An element's blocks before its visit: the vector zeroed if occupied or dirty,
/// the matrix block too if occupied and `matrix` or if dirty and no longer
/// occupied, the coverage and body blocks of an element emptied since; `dirty`
/// becomes `occupied`. The blocks of an occupied element, to fill.
fn zero_blocks<'a, T: Scalar>(
    occupied: bool,
    dirty: &mut bool,
    matrix: bool,
    (lm, lv, lc, lb): ElementBlocks<'a, T>,
) -> Option<ElementBlocks<'a, T>> {
    if (occupied && matrix) || (!occupied && *dirty) {
        lm.iter_mut().for_each(|v| *v = T::zero());
    }
    if occupied || *dirty {
        lv.iter_mut().for_each(|v| *v = T::zero());
    }
    if !occupied && *dirty {
        lc.iter_mut().for_each(|v| *v = T::zero());
        lb.iter_mut().for_each(|v| *v = T::zero());
    }
    *dirty = occupied;
    occupied.then_some((lm, lv, lc, lb))
}

/// Calls its argument with every `(target, source)` pair of a gather map.
type PairVisitor<'a> = dyn Fn(&mut dyn FnMut(usize, usize)) + 'a;

/// Where each matrix entry and each function coefficient finds its element-local
/// contributions, in element order (fixed by the mesh, built once). Offsets in
/// 32 bits (a local buffer of `2³²` entries or more is refused at set-up).
///
/// The gathers visit only the *live* functions, those of the elements that hold a
/// particle this step ([`Gather::mark_live`]), and the matrix columns of live
/// functions: every other target has only empty elements' blocks, which are zero,
/// so its sum is `+0` and skipping it changes no bit. A step in a mostly empty
/// mesh then costs what its body covers, not what the mesh holds (measured:
/// `docs/performance.md`, "A body in a mostly empty mesh").
pub struct Gather {
    pub(super) matrix_start: Vec<u32>,
    /// Offsets into [`Local`]'s matrix buffer.
    pub(super) matrix_source: Vec<u32>,
    pub(super) function_start: Vec<u32>,
    /// `e * stride + a`: local function `a` of element `e`.
    pub(super) function_source: Vec<u32>,
    /// The pattern's column pointers (entries of column `c`:
    /// `column_start[c]..column_start[c + 1]`).
    column_start: Vec<u32>,
    /// First column of each block of columns the matrix gather splits into
    /// parallel tasks (about [`ENTRY_CHUNK`] entries each), and the number of
    /// columns at the end.
    block_column: Vec<u32>,
    /// Per function: it belongs to an element that holds a particle.
    live: Vec<bool>,
    /// The live functions, ascending; the gathers run through this list instead
    /// of every function when it holds fewer than [`SPARSE_SHARE`] of them.
    live_list: Vec<u32>,
    /// Per column: its entries may be nonzero in the values last assigned by
    /// [`Gather::matrix_assign`].
    written: Vec<bool>,
    /// The columns `written` flags (after an assignment: the live columns of
    /// that step).
    written_list: LastWritten,
    /// The functions whose coverage sums [`Gather::coverage`] last wrote (the live
    /// ones of that call): the others are zero.
    coverage_written: LastWritten,
}

/// Below this share of live functions the gathers visit the live list (one
/// thread) instead of every function (on the pool): a body in a mostly empty mesh.
/// The sums are the same either way (each target's in element order), so the
/// choice changes no bit.
const SPARSE_SHARE: f64 = 0.125;

impl Gather {
    /// The maps of `basis` with `pattern` (its element scatter maps) and local
    /// blocks of `stride` functions: counted, then filled in element order (no
    /// list of pairs in between).
    ///
    /// # Panics
    /// If the local matrix buffer (`elements · stride²` entries) reaches `2³²`;
    /// the driver refuses such a basis first ([`Gather::fits`]).
    pub fn new<T: Scalar, const D: usize, B: Basis<T, D>>(
        basis: &B,
        pattern: &SymmetricPattern,
        stride: usize,
    ) -> Self {
        let (ne, n) = (basis.num_elements(), basis.num_functions());
        assert!(
            Self::fits(ne, stride),
            "local buffers of 2^32 entries or more"
        );
        // Every (target, source) pair in element order, given to `visit`.
        let each_matrix = |visit: &mut dyn FnMut(usize, usize)| {
            for e in 0..ne {
                let m = basis.element_functions(e).len();
                let scatter = pattern.element_scatter(e);
                for a in 0..m {
                    for b in a..m {
                        visit(
                            scatter[a * m + b] as usize,
                            e * packed_len(stride) + packed(stride, a, b),
                        );
                    }
                }
            }
        };
        let each_function = |visit: &mut dyn FnMut(usize, usize)| {
            for e in 0..ne {
                for (a, &i) in basis.element_functions(e).iter().enumerate() {
                    visit(i, e * stride + a);
                }
            }
        };
        // Stable: element order kept within each target.
        let group = |each: &PairVisitor<'_>, len: usize| {
            let mut start = vec![0u32; len + 1];
            each(&mut |t, _| start[t + 1] += 1);
            for t in 0..len {
                start[t + 1] += start[t];
            }
            let mut cursor = start[..len].to_vec();
            let mut source = vec![0u32; start[len] as usize];
            each(&mut |t, s| {
                source[cursor[t] as usize] = s as u32;
                cursor[t] += 1;
            });
            (start, source)
        };
        let (matrix_start, matrix_source) = group(&each_matrix, pattern.nnz());
        let (function_start, function_source) = group(&each_function, n);
        let column_start: Vec<u32> = pattern.col_ptr().iter().map(|&c| c as u32).collect();
        let mut block_column = vec![0u32];
        for c in 0..n {
            let first = column_start[*block_column.last().unwrap_or(&0) as usize];
            if (column_start[c + 1] - first) as usize >= ENTRY_CHUNK {
                block_column.push(c as u32 + 1);
            }
        }
        if *block_column.last().unwrap_or(&0) as usize != n {
            block_column.push(n as u32);
        }
        Gather {
            matrix_start,
            matrix_source,
            function_start,
            function_source,
            column_start,
            block_column,
            // Until the first `mark_live`, every target is visited.
            live: vec![true; n],
            live_list: (0..n as u32).collect(),
            written: vec![true; n],
            written_list: LastWritten::with_capacity(n),
            coverage_written: LastWritten::with_capacity(n),
        }
    }

    /// Marks the functions of the elements of `bins` that hold a particle as live,
    /// the others not (once per step, after the particles are binned).
    pub fn mark_live<T: Scalar, const D: usize, B: Basis<T, D>>(&mut self, basis: &B, bins: &Bins) {
        if self.sparse() {
            for &i in &self.live_list {
                self.live[i as usize] = false;
            }
        } else {
            self.live.iter_mut().for_each(|l| *l = false);
        }
        self.live_list.clear();
        // Through the occupied elements (ascending, as a pass over every element
        // meets them): the same list, without a pass over a mostly empty mesh.
        for &e in bins.occupied_elements() {
            for &i in basis.element_functions(e as usize) {
                if !self.live[i] {
                    self.live[i] = true;
                    self.live_list.push(i as u32);
                }
            }
        }
        self.live_list.sort_unstable();
    }

    /// Whether the gathers run through the live list ([`SPARSE_SHARE`]).
    fn sparse(&self) -> bool {
        lists_allowed() && (self.live_list.len() as f64) < SPARSE_SHARE * self.live.len() as f64
    }

    /// Which functions are live ([`Gather::mark_live`]).
    pub(super) fn live(&self) -> &[bool] {
        &self.live
    }

    /// The live functions, ascending, when the gathers run through them (the
    /// values of every other function are zero), else `None`.
    pub(super) fn live_list(&self) -> Option<&[u32]> {
        self.sparse().then_some(&self.live_list[..])
    }

    /// `values_j = Σ` of the local matrix blocks' entries `j`, in element order,
    /// over the live columns; the entries of a column that is no longer live are
    /// set to zero (what the sum over its empty elements gives).
    pub(super) fn matrix_assign<T: Scalar, const D: usize>(
        &mut self,
        local: &Local<T, D>,
        values: &mut [T],
    ) {
        if self.sparse() && self.written_list.listed().is_some() {
            self.matrix_assign_listed(local, values);
            return;
        }
        let mut written = std::mem::take(&mut self.written);
        let this = &*self;
        split_columns(
            &this.block_column,
            &this.column_start,
            values,
            &mut written,
            &|columns, first, values, written| {
                for (w, c) in written.iter_mut().zip(columns) {
                    let entries = this.column_start[c] as usize..this.column_start[c + 1] as usize;
                    let slice = &mut values[entries.start - first..entries.end - first];
                    if this.live[c] {
                        for (v, j) in slice.iter_mut().zip(entries) {
                            *v = this.entry_sum(local, j);
                        }
                        *w = true;
                    } else if *w {
                        slice.iter_mut().for_each(|v| *v = T::zero());
                        *w = false;
                    }
                }
            },
        );
        self.written = written;
        self.written_list.record(&self.live_list);
    }

    /// [`Gather::matrix_assign`] through the live list: the columns written last
    /// that are no longer live are zeroed, the live ones assigned.
    fn matrix_assign_listed<T: Scalar, const D: usize>(
        &mut self,
        local: &Local<T, D>,
        values: &mut [T],
    ) {
        for c in self.written_list.each(self.live.len()) {
            if !self.live[c] {
                let entries = self.column_start[c] as usize..self.column_start[c + 1] as usize;
                values[entries].iter_mut().for_each(|v| *v = T::zero());
                self.written[c] = false;
            }
        }
        for &c in &self.live_list {
            let c = c as usize;
            let entries = self.column_start[c] as usize..self.column_start[c + 1] as usize;
            for j in entries {
                values[j] = self.entry_sum(local, j);
            }
            self.written[c] = true;
        }
        self.written_list.record(&self.live_list);
    }

    /// `values_j += Σ` of the local matrix blocks' entries `j`, in element order,
    /// over the live columns (the others would add `+0`).
    pub(super) fn matrix_add<T: Scalar, const D: usize>(
        &self,
        local: &Local<T, D>,
        values: &mut [T],
    ) {
        if self.sparse() {
            for &c in &self.live_list {
                let c = c as usize;
                for j in self.column_start[c] as usize..self.column_start[c + 1] as usize {
                    values[j] += self.entry_sum(local, j);
                }
            }
            return;
        }
        split_columns(
            &self.block_column,
            &self.column_start,
            values,
            &mut [],
            &|columns, first, values, _| {
                for c in columns {
                    if !self.live[c] {
                        continue;
                    }
                    let entries = self.column_start[c] as usize..self.column_start[c + 1] as usize;
                    for j in entries {
                        values[j - first] += self.entry_sum(local, j);
                    }
                }
            },
        );
    }

    /// `Σ` of the local matrix blocks' entries `j`, in element order.
    #[inline]
    fn entry_sum<T: Scalar, const D: usize>(&self, local: &Local<T, D>, j: usize) -> T {
        let mut sum = T::zero();
        let sources = self.matrix_start[j] as usize..self.matrix_start[j + 1] as usize;
        for &s in &self.matrix_source[sources] {
            sum += local.matrix[s as usize];
        }
        sum
    }

    /// Whether the local buffers of `elements` elements of `stride` functions
    /// have fewer than `2³²` entries (32-bit offsets).
    pub fn fits(elements: usize, stride: usize) -> bool {
        elements
            .checked_mul(packed_len(stride))
            .is_some_and(|e| e < u32::MAX as usize)
    }

    /// `volume_i = Σ` of the local particle volumes of function `i` and
    /// `count_i` likewise of the particle counts ([`Local::with_coverage`]), in
    /// element order, in `f64`; `0` for a function that is not live. `volume` and
    /// `count` are the same buffers at every call (through the live list, only
    /// the functions the last call wrote are zeroed).
    pub(super) fn coverage<T: Scalar, const D: usize>(
        &mut self,
        local: &Local<T, D>,
        volume: &mut [f64],
        count: &mut [f64],
    ) {
        self.coverage_sums(local, volume, count);
        self.coverage_written.record(&self.live_list);
    }

    /// [`Gather::coverage`]'s sums.
    fn coverage_sums<T: Scalar, const D: usize>(
        &self,
        local: &Local<T, D>,
        volume: &mut [f64],
        count: &mut [f64],
    ) {
        if self.sparse() {
            // Every function that is not live sums `+0`: those the last call
            // wrote zeroed, then the live assigned.
            for i in self.coverage_written.each(volume.len()) {
                volume[i] = 0.0;
                count[i] = 0.0;
            }
            for &i in &self.live_list {
                let i = i as usize;
                [volume[i], count[i]] = self.coverage_sum(local, i);
            }
            return;
        }
        (volume, count)
            .into_par_iter()
            .with_min_len(ENTRY_CHUNK)
            .enumerate()
            .for_each(|(i, (volume, count))| {
                // A function that is not live sums `+0`.
                [*volume, *count] = if self.live[i] {
                    self.coverage_sum(local, i)
                } else {
                    [0.0; 2]
                };
            });
    }

    /// The particle volume and count of function `i` ([`Gather::coverage`]).
    #[inline]
    fn coverage_sum<T: Scalar, const D: usize>(&self, local: &Local<T, D>, i: usize) -> [f64; 2] {
        let mut sum = [0.0; 2];
        let sources = self.function_start[i] as usize..self.function_start[i + 1] as usize;
        for &s in &self.function_source[sources] {
            let s = s as usize * 2;
            sum[0] += local.coverage[s].to_f64();
            sum[1] += local.coverage[s + 1].to_f64();
        }
        sum
    }

    /// `out_{k,i} += sign · Σ` of the local coefficients of function `i`, in
    /// element order.
    pub(super) fn functions<T: Scalar, const D: usize>(
        &self,
        local: &Local<T, D>,
        negate: bool,
        out: &mut [Vec<T>],
    ) {
        self.functions_of::<T, D>(&local.vector, negate, out);
    }

    /// [`Gather::functions`] of the body-force blocks ([`Local::with_body_forces`]).
    pub(super) fn body_forces<T: Scalar, const D: usize>(
        &self,
        local: &Local<T, D>,
        out: &mut [Vec<T>],
    ) {
        self.functions_of::<T, D>(&local.body, false, out);
    }

    /// `out_{k,i} += source_{k,i}` for the live functions `i` (the others are
    /// left alone, as a gather leaves them).
    pub(super) fn add_live<T: Scalar>(&self, source: &[Vec<T>], out: &mut [Vec<T>]) {
        if self.sparse() {
            for (out, source) in out.iter_mut().zip(source) {
                for &i in &self.live_list {
                    out[i as usize] += source[i as usize];
                }
            }
            return;
        }
        for (out, source) in out.iter_mut().zip(source) {
            out.par_iter_mut()
                .with_min_len(ENTRY_CHUNK)
                .zip(source.par_iter())
                .enumerate()
                .for_each(|(i, (o, s))| {
                    if self.live[i] {
                        *o += *s;
                    }
                });
        }
    }

    /// `out_{k,i} += sign · Σ` of the local coefficients `source` (`stride × D`
    /// per element) of function `i`, in element order.
    fn functions_of<T: Scalar, const D: usize>(
        &self,
        source: &[T],
        negate: bool,
        out: &mut [Vec<T>],
    ) {
        if self.sparse() {
            for (k, out) in out.iter_mut().enumerate() {
                for &i in &self.live_list {
                    let i = i as usize;
                    add_signed(&mut out[i], self.function_sum::<T, D>(source, i, k), negate);
                }
            }
            return;
        }
        for (k, out) in out.iter_mut().enumerate() {
            out.par_iter_mut()
                .with_min_len(ENTRY_CHUNK)
                .enumerate()
                .for_each(|(i, o)| {
                    // A function that is not live would add `+0`.
                    if self.live[i] {
                        add_signed(o, self.function_sum::<T, D>(source, i, k), negate);
                    }
                });
        }
    }

    /// `Σ` of component `k` of the local coefficients `source` of function `i`, in
    /// element order.
    #[inline]
    fn function_sum<T: Scalar, const D: usize>(&self, source: &[T], i: usize, k: usize) -> T {
        let mut sum = T::zero();
        let sources = self.function_start[i] as usize..self.function_start[i + 1] as usize;
        for &s in &self.function_source[sources] {
            sum += source[s as usize * D + k];
        }
        sum
    }
}

/// `out ± sum`.
#[inline]
fn add_signed<T: Scalar>(out: &mut T, sum: T, negate: bool) {
    if negate {
        *out -= sum;
    } else {
        *out += sum;
    }
}

/// The work on one block of columns: `(columns, first entry, the columns' values,
/// their flags)`.
type ColumnBlockTask<'a, T> =
    dyn Fn(std::ops::Range<usize>, usize, &mut [T], &mut [bool]) + Sync + 'a;

/// Calls `f(columns, first entry, values of those columns, their flags)` on the
/// blocks of columns `blocks` (first columns, and the number of columns at the
/// end) in parallel: the slices are split at the blocks' first entries
/// (`column_start`) by recursive halving, without allocation. `flags` is either
/// one per column or empty.
fn split_columns<T: Send>(
    blocks: &[u32],
    column_start: &[u32],
    values: &mut [T],
    flags: &mut [bool],
    f: &ColumnBlockTask<'_, T>,
) {
    let (c0, c1) = (blocks[0] as usize, blocks[blocks.len() - 1] as usize);
    if blocks.len() <= 2 {
        f(c0..c1, column_start[c0] as usize, values, flags);
        return;
    }
    let mid = blocks.len() / 2;
    let cm = blocks[mid] as usize;
    let (va, vb) = values.split_at_mut((column_start[cm] - column_start[c0]) as usize);
    let (fa, fb) = if flags.is_empty() {
        (&mut [][..], &mut [][..])
    } else {
        flags.split_at_mut(cm - c0)
    };
    rayon::join(
        || split_columns(&blocks[..=mid], column_start, va, fa, f),
        || split_columns(&blocks[mid..], column_start, vb, fb, f),
    );
}

/// The element-local sums `Σ_{p in e} q(p, s)` of a per-slot vector `q` (slot
/// `s` of particle `p`), then gathered: `out_{k,i} += Σ_p q_k(p, s_i)`.
pub fn scatter_by_elements<T: Scalar, const D: usize, Q>(
    bins: &Bins,
    evals: &Evaluations<T, D>,
    gather: &Gather,
    local: &mut Local<T, D>,
    out: &mut [Vec<T>],
    q: Q,
) where
    Q: Fn(usize, usize) -> SVector<T, D> + Sync,
{
    local.for_each_vector(bins, |e, lv| {
        for &p in bins.particles(e) {
            let p = p as usize;
            for (a, s) in evals.range(p).enumerate() {
                let f = q(p, s);
                for k in 0..D {
                    lv[a * D + k] += f[k];
                }
            }
        }
    });
    gather.functions(local, false, out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};

    /// Fills the blocks of the occupied elements with values that depend on the
    /// element, the entry and the round, then gathers the matrix and the vector.
    #[allow(clippy::too_many_arguments)]
    fn round(
        basis: &PowellSabin<f64>,
        gather: &mut Gather,
        local: &mut Local<f64, 2>,
        bins: &Bins,
        round: f64,
        values: &mut [f64],
        out: &mut [Vec<f64>],
        coverage: [&mut [f64]; 2],
    ) {
        gather.mark_live(basis, bins);
        let vector = |e: usize, lv: &mut [f64]| {
            for (k, v) in lv.iter_mut().enumerate() {
                *v = (e as f64 + 2.0) * 0.23 - k as f64 * 0.017 + round;
            }
        };
        // The odd rounds visit the vectors first, as a step's first scatter does.
        if round as usize % 2 == 1 {
            local.for_each_vector(bins, |e, lv| vector(e, lv));
        }
        local.for_each_element_with_coverage(bins, |e, (lm, lv, lc, _)| {
            for (k, v) in lm.iter_mut().enumerate() {
                *v = (e as f64 + 1.0) * 0.37 + k as f64 * 0.011 + round;
            }
            vector(e, lv);
            for (k, v) in lc.iter_mut().enumerate() {
                *v = (e as f64 + 3.0) * 0.19 + k as f64 * 0.013 + round;
            }
        });
        gather.matrix_assign(local, values);
        out.iter_mut()
            .for_each(|o| o.iter_mut().for_each(|v| *v = 0.0));
        gather.functions(local, false, out);
        let [volume, count] = coverage;
        gather.coverage(local, volume, count);
    }

    /// The gathers over the live functions give, bit for bit, the sums over every
    /// element of the blocks of the occupied ones, also after elements empty and
    /// others fill (their blocks and entries are zeroed, not left stale).
    #[test]
    fn live_gathers_equal_the_full_sums_as_elements_empty_and_fill() {
        let mesh = psmpm_basis::mesh::generators::block_grid(0.0, 1.0, 0.0, 1.0, 6, 6).unwrap();
        let basis = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
        let pattern = SymmetricPattern::new(&basis);
        let (ne, n) = (basis.num_elements(), basis.num_functions());
        let stride = basis.max_functions_per_element();
        let mut gather = Gather::new(&basis, &pattern, stride);
        let mut local = Local::<f64, 2>::new(ne, stride).with_coverage();
        let mut bins = Bins::new(ne, 6);
        let mut values = vec![0.0; pattern.nnz()];
        let mut out = vec![vec![0.0; n]; 2];
        let mut coverage = [vec![0.0; n], vec![0.0; n]];
        // Whether each round's gathers ran through the live list: both ways, and
        // from each to the other.
        let mut listed = Vec::new();
        for (r, elements) in [
            [0, 0, 1, 5, 5, 7],
            [5, 9, 9, 30, 31, 31],
            [40, 41, 42, 43, 44, 45],
            [2, 20, 60, 80, 100, 140],
            [3, 3, 3, 3, 3, 3],
        ]
        .iter()
        .enumerate()
        {
            bins.fill(elements);
            gather.mark_live(&basis, &bins);
            listed.push(gather.sparse());
            round(
                &basis,
                &mut gather,
                &mut local,
                &bins,
                r as f64,
                &mut values,
                &mut out,
                coverage.each_mut().map(|c| &mut c[..]),
            );
            // The full sums, from the blocks of the occupied elements alone.
            let occupied = |s: usize, per: usize| bins.occupied(s / per);
            let per = packed_len(stride);
            for (j, v) in values.iter().enumerate() {
                let mut sum = 0.0;
                for &s in &gather.matrix_source
                    [gather.matrix_start[j] as usize..gather.matrix_start[j + 1] as usize]
                {
                    if occupied(s as usize, per) {
                        sum += local.matrix[s as usize];
                    }
                }
                assert_eq!(v.to_bits(), sum.to_bits(), "round {r}, entry {j}");
            }
            // Component `k` of function `i` summed over the occupied elements'
            // blocks of `blocks` (two entries per local function).
            let function_sum = |blocks: &[f64], i: usize, k: usize| {
                let mut sum = 0.0;
                for &s in &gather.function_source
                    [gather.function_start[i] as usize..gather.function_start[i + 1] as usize]
                {
                    if occupied(s as usize, stride) {
                        sum += blocks[s as usize * 2 + k];
                    }
                }
                sum
            };
            for (k, o) in out.iter().enumerate() {
                for (i, v) in o.iter().enumerate() {
                    let sum = function_sum(&local.vector, i, k);
                    assert_eq!(v.to_bits(), sum.to_bits(), "round {r}, function {i}");
                }
            }
            for (k, o) in coverage.iter().enumerate() {
                for (i, v) in o.iter().enumerate() {
                    let sum = function_sum(&local.coverage, i, k);
                    assert_eq!(v.to_bits(), sum.to_bits(), "round {r}, coverage {k} of {i}");
                }
            }
            assert!(values.iter().any(|&v| v != 0.0));
        }
        assert_eq!(listed, [true, true, true, false, true]);
        // The blocks of the elements emptied in the last round are zero.
        for e in [0, 1, 5, 7, 9, 30, 31] {
            assert!(local.coverage[e * 2 * stride..(e + 1) * 2 * stride]
                .iter()
                .all(|&v| v == 0.0));
            assert!(
                local.matrix[e * packed_len(stride)..(e + 1) * packed_len(stride)]
                    .iter()
                    .all(|&v| v == 0.0)
            );
        }
    }
}
