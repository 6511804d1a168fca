//! Deterministic sums over particles for any number of threads: particles binned
//! by element ([`Bins`], a stable counting sort), element-local sums in particle
//! order ([`Local`]), and gathers of the element-local values into matrix entries
//! and function coefficients in element order ([`Gather`]). Used by the phases of
//! [`super::phases`]; see its module doc for why.

use super::phases::{Evaluations, CHUNK};
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
    /// Particles of element `e`: `order[start[e]..start[e + 1]]`.
    pub(super) start: Vec<usize>,
    pub(super) order: Vec<usize>,
    pub(super) cursor: Vec<usize>,
}

impl Bins {
    /// Buffers for `elements` elements and `particles` particles.
    pub fn new(elements: usize, particles: usize) -> Self {
        Bins {
            start: vec![0; elements + 1],
            order: vec![0; particles],
            cursor: vec![0; elements],
        }
    }

    /// Sorts the particles by their `element`.
    pub fn fill(&mut self, element: &[usize]) {
        self.fill_with_slots(element, &mut []);
    }

    /// [`fill`](Self::fill), and `slot[p]` = the position of particle `p` in the
    /// order (when `slot` is not empty).
    pub fn fill_with_slots(&mut self, element: &[usize], slot: &mut [usize]) {
        self.start.iter_mut().for_each(|s| *s = 0);
        for &e in element {
            self.start[e + 1] += 1;
        }
        let ne = self.cursor.len();
        for e in 0..ne {
            self.start[e + 1] += self.start[e];
        }
        self.cursor.copy_from_slice(&self.start[..ne]);
        let with_slots = !slot.is_empty();
        for (p, &e) in element.iter().enumerate() {
            let s = self.cursor[e];
            self.order[s] = p;
            if with_slots {
                slot[p] = s;
            }
            self.cursor[e] += 1;
        }
    }

    /// The particles in element `e`, in increasing order.
    #[inline]
    pub fn particles(&self, e: usize) -> &[usize] {
        &self.order[self.start[e]..self.start[e + 1]]
    }

    /// `true` if element `e` holds a particle.
    #[inline]
    pub fn occupied(&self, e: usize) -> bool {
        self.start[e + 1] > self.start[e]
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

/// Element-local sums: per element an upper-triangular `stride × stride` block of
/// the mass matrix and `stride × D` coefficients of a vector field (local
/// function `a` is the element's `a`-th function, as evaluated in phase 1).
pub struct Local<T: Scalar, const D: usize> {
    pub(super) stride: usize,
    pub(super) matrix: Vec<T>,
    pub(super) vector: Vec<T>,
}

impl<T: Scalar, const D: usize> Local<T, D> {
    /// Each element's local matrix block and vector, zeroed, in parallel tasks of
    /// at least [`ELEMENT_CHUNK`] elements: `(e, (matrix, vector))`.
    pub(super) fn par_elements(
        &mut self,
    ) -> impl IndexedParallelIterator<Item = (usize, (&mut [T], &mut [T]))> + '_ {
        let stride = self.stride;
        (
            self.matrix.par_chunks_mut(packed_len(stride)),
            self.vector.par_chunks_mut(stride * D),
        )
            .into_par_iter()
            .with_min_len(ELEMENT_CHUNK)
            .enumerate()
            .map(|(e, (lm, lv))| {
                lm.iter_mut().for_each(|v| *v = T::zero());
                lv.iter_mut().for_each(|v| *v = T::zero());
                (e, (lm, lv))
            })
    }

    /// Buffers for `elements` elements of up to `stride` functions.
    pub fn new(elements: usize, stride: usize) -> Self {
        Local {
            stride,
            matrix: vec![T::zero(); elements * packed_len(stride)],
            vector: vec![T::zero(); elements * stride * D],
        }
    }
}

/// Calls its argument with every `(target, source)` pair of a gather map.
type PairVisitor<'a> = dyn Fn(&mut dyn FnMut(usize, usize)) + 'a;

/// Where each matrix entry and each function coefficient finds its element-local
/// contributions, in element order (fixed by the mesh, built once). Offsets in
/// 32 bits (a local buffer of `2³²` entries or more is refused at set-up).
pub struct Gather {
    pub(super) matrix_start: Vec<u32>,
    /// Offsets into [`Local`]'s matrix buffer.
    pub(super) matrix_source: Vec<u32>,
    pub(super) function_start: Vec<u32>,
    /// `e * stride + a`: local function `a` of element `e`.
    pub(super) function_source: Vec<u32>,
}

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
        Gather {
            matrix_start,
            matrix_source,
            function_start,
            function_source,
        }
    }

    /// Whether the local buffers of `elements` elements of `stride` functions
    /// have fewer than `2³²` entries (32-bit offsets).
    pub fn fits(elements: usize, stride: usize) -> bool {
        elements
            .checked_mul(packed_len(stride))
            .is_some_and(|e| e < u32::MAX as usize)
    }

    /// `values_j = Σ` of the local matrix blocks' entries `j`, in element order
    /// (`values_j +=` with `add`).
    pub(super) fn matrix<T: Scalar, const D: usize>(
        &self,
        local: &Local<T, D>,
        add: bool,
        values: &mut [T],
    ) {
        values
            .par_iter_mut()
            .with_min_len(ENTRY_CHUNK)
            .enumerate()
            .for_each(|(j, v)| {
                let mut sum = T::zero();
                let sources = self.matrix_start[j] as usize..self.matrix_start[j + 1] as usize;
                for &s in &self.matrix_source[sources] {
                    sum += local.matrix[s as usize];
                }
                if add {
                    *v += sum;
                } else {
                    *v = sum;
                }
            });
    }

    /// `out_{k,i} += sign · Σ` of the local coefficients of function `i`, in
    /// element order.
    pub(super) fn functions<T: Scalar, const D: usize>(
        &self,
        local: &Local<T, D>,
        negate: bool,
        out: &mut [Vec<T>],
    ) {
        for (k, out) in out.iter_mut().enumerate() {
            out.par_iter_mut()
                .with_min_len(ENTRY_CHUNK)
                .enumerate()
                .for_each(|(i, o)| {
                    let mut sum = T::zero();
                    let sources =
                        self.function_start[i] as usize..self.function_start[i + 1] as usize;
                    for &s in &self.function_source[sources] {
                        sum += local.vector[s as usize * D + k];
                    }
                    if negate {
                        *o -= sum;
                    } else {
                        *o += sum;
                    }
                });
        }
    }
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
    let stride = local.stride;
    local
        .vector
        .par_chunks_mut(stride * D)
        .with_min_len(ELEMENT_CHUNK)
        .enumerate()
        .for_each(|(e, lv)| {
            lv.iter_mut().for_each(|v| *v = T::zero());
            for &p in bins.particles(e) {
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
