//! The phases of one MPM time step (paper eqs. (13)–(31)), each a function over
//! slices named after what it computes. [`Driver::step`](super::Driver::step)
//! calls them in order; none of them knows which basis, mass strategy or
//! material it serves.
//!
//! Per-particle basis data are stored as [`Evaluations`]: the particle in slot
//! `s` has the values `phi` and gradients `grad_phi` of its element's functions at
//! `s * stride ..`, the function indices kept once per element.
//!
//! # Threads and determinism
//!
//! The phases run on the current rayon pool and give bit-identical results for
//! any number of threads. Per-particle work (locate, evaluate, update) is split
//! into chunks of [`CHUNK`] particles, a size independent of the thread count.
//! Sums over particles (the mass matrix, forces, momentum) are never accumulated
//! across threads: particles are binned by element ([`Bins`], stable: particle
//! order within an element); each element sums its own particles into its own
//! local buffer ([`Local`]), in particle order; each matrix entry and function
//! coefficient then sums its elements' local values in element order
//! ([`Gather`]). Every sum therefore has one fixed order, whatever the threads.
//! The binning and the gathers are in `driver/binning.rs`.

use crate::last_written::LastWritten;
use crate::material::det;
use crate::materials::ParticleMaterials;
use crate::particles::Particles;
use crate::sparse::Scalar;
use nalgebra::{SMatrix, SVector};
use psmpm_basis::{Basis, BasisEval};
use rayon::prelude::*;

pub use super::binning::{chunks, scatter_by_elements, Bins, Gather, Local, Touching};
use super::binning::{packed, ElementBlocks};

/// Particles per parallel task of the per-particle phases: fixed, so that the
/// split (and with it every result) does not depend on the number of threads.
pub const CHUNK: usize = 1024;

/// Basis values and gradients of every particle, as evaluated in phase 1.
///
/// The entries are stored by slot, in element order: phase 1 puts particle `p`
/// at slot `slot[p]`, its position in the step's [`Bins`], so that the sums
/// element by element stream through them and the evaluation reads each
/// element's data for all its particles at once. Slot `s` holds the values and
/// gradients of the functions of its element `element[s]` at `s * stride ..`;
/// [`Self::range`] finds a particle's entries and [`Self::functions`] their
/// function indices.
///
/// The function indices are kept once per element, not per particle: every
/// particle of an element has the element's functions, in the order
/// [`Basis::element_functions`] gives and [`Basis::eval`] writes (36 bytes per PS
/// particle fewer than one index per entry).
pub struct Evaluations<T: Scalar, const D: usize> {
    /// Entries per slot (the basis's largest number of functions per element).
    pub stride: usize,
    /// `slot[p]`: the slot of particle `p`.
    pub slot: Vec<u32>,
    /// `element[s]`: the element of the particle in slot `s`.
    pub element: Vec<u32>,
    /// The functions of element `e` at `e * stride ..` (`u32`: the driver refuses a
    /// basis of 2³² functions or more).
    element_functions: Vec<u32>,
    /// The number of functions of element `e`.
    element_len: Vec<u32>,
    /// Values `phi_i(x_p)`.
    pub phi: Vec<T>,
    /// Gradients `grad phi_i(x_p)`.
    pub grad_phi: Vec<SVector<T, D>>,
}

impl<T: Scalar, const D: usize> Evaluations<T, D> {
    /// Buffers for `particles` particles of `basis` (particle `p` in slot `p`, and
    /// every slot in element 0, until phase 1 orders them). The caller bounds the
    /// particles and the functions and elements of the basis below 2³².
    pub fn for_basis<B: Basis<T, D>>(basis: &B, particles: usize) -> Self {
        let stride = basis.max_functions_per_element();
        let elements = basis.num_elements();
        let mut element_functions = vec![0; elements * stride];
        let mut element_len = vec![0; elements];
        for e in 0..elements {
            let functions = basis.element_functions(e);
            element_len[e] = functions.len() as u32;
            for (to, &i) in element_functions[e * stride..].iter_mut().zip(functions) {
                *to = i as u32;
            }
        }
        Self::with_elements(particles, stride, element_functions, element_len)
    }

    /// Buffers for `particles` particles on elements whose functions are
    /// `element_functions` (`stride` per element, `element_len[e]` of them valid).
    pub fn with_elements(
        particles: usize,
        stride: usize,
        element_functions: Vec<u32>,
        element_len: Vec<u32>,
    ) -> Self {
        Evaluations {
            stride,
            slot: (0..particles as u32).collect(),
            element: vec![0; particles],
            element_functions,
            element_len,
            phi: vec![T::zero(); particles * stride],
            grad_phi: vec![SVector::zeros(); particles * stride],
        }
    }

    /// The functions of element `e`.
    #[inline]
    pub fn element_functions(&self, e: usize) -> &[u32] {
        let base = e * self.stride;
        &self.element_functions[base..base + self.element_len[e] as usize]
    }

    /// The entry range of particle `p`.
    #[inline]
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        let s = self.slot[p] as usize;
        let base = s * self.stride;
        base..base + self.element_len[self.element[s] as usize] as usize
    }

    /// The functions of particle `p`, one per entry of [`Self::range`].
    #[inline]
    pub fn functions(&self, p: usize) -> &[u32] {
        self.element_functions(self.element[self.slot[p] as usize] as usize)
    }

    /// The entries `s` of particle `p` with their functions `i`.
    #[inline]
    pub fn entries(&self, p: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.range(p)
            .zip(self.functions(p))
            .map(|(s, &i)| (s, i as usize))
    }
}

/// A particle that phase 1 could not place in the mesh.
pub struct Outside {
    /// The particle.
    pub particle: usize,
}

/// Phase 1: locate every particle (walking from its previous element), bin the
/// particles by element ([`Bins`]), and evaluate the basis at each particle in bin
/// order, into its slot ([`Evaluations`]); [`CHUNK`] particles per task with one
/// scratch buffer each (`scratch` holds [`chunks`]`(x.len())` of them). The
/// number of particles now in another element than before; on failure, the first
/// particle outside.
pub fn locate_and_evaluate<T: Scalar, const D: usize, B: Basis<T, D>>(
    basis: &B,
    x: &[SVector<T, D>],
    element: &mut [usize],
    bins: &mut Bins,
    scratch: &mut [BasisEval<T, D>],
    out: &mut Evaluations<T, D>,
) -> Result<usize, Outside> {
    // The particles that changed element, or the first one outside (integer sums
    // and a minimum: the same for any thread count).
    let located = (x.par_chunks(CHUNK), element.par_chunks_mut(CHUNK))
        .into_par_iter()
        .enumerate()
        .map(|(c, (x, element))| {
            let mut crossed = 0usize;
            for q in 0..x.len() {
                let Some(e) = basis.locate(&x[q], Some(element[q])) else {
                    return Err(c * CHUNK + q);
                };
                crossed += usize::from(e != element[q]);
                element[q] = e;
            }
            Ok(crossed)
        })
        .reduce(
            || Ok(0),
            |a, b| match (a, b) {
                (Err(p), Err(q)) => Err(p.min(q)),
                (Err(p), Ok(_)) | (Ok(_), Err(p)) => Err(p),
                (Ok(a), Ok(b)) => Ok(a + b),
            },
        );
    let crossed = located.map_err(|particle| Outside { particle })?;
    bins.fill_with_slots(element, &mut out.slot);
    let stride = out.stride;
    let (order, element) = (&bins.order, &*element);
    let (functions, lens) = (&out.element_functions, &out.element_len);
    (
        order.par_chunks(CHUNK),
        out.element.par_chunks_mut(CHUNK),
        out.phi.par_chunks_mut(CHUNK * stride),
        out.grad_phi.par_chunks_mut(CHUNK * stride),
        scratch.par_iter_mut(),
    )
        .into_par_iter()
        .for_each(|(order, slot_element, phi, grad_phi, scratch)| {
            for (q, &p) in order.iter().enumerate() {
                let p = p as usize;
                let e = element[p];
                basis.eval(e, &x[p], scratch);
                let base = q * stride;
                let m = scratch.len();
                slot_element[q] = e as u32;
                debug_assert!(
                    m == lens[e] as usize
                        && scratch.index[..m]
                            .iter()
                            .zip(&functions[e * stride..])
                            .all(|(&i, &j)| i == j as usize),
                    "the basis evaluated other functions than its element's"
                );
                copy_entries(&scratch.phi, &mut phi[base..base + m]);
                copy_entries(&scratch.grad_phi, &mut grad_phi[base..base + m]);
            }
        });
    Ok(crossed)
}

/// `out.copy_from_slice(&source[..out.len()])`, with the PS and PL lengths (9 and
/// 3) as fixed-size copies: a copy of a runtime length calls the C library's
/// `memmove` (2 % of a PS step in the profile); phase 1 for PS is about 1.5 %
/// faster (`cargo bench --bench kernels -- eval`, `ps_phase` fastest of 20:
/// 6.03 and 6.10 ms against 6.12 and 6.19 ms, two alternating rounds). The nine
/// PS gradients (144 bytes) are copied in two halves: in one, the compiler still
/// called `memmove` for them (a fixed copy of more than 128 bytes on the baseline
/// x86-64 target); in halves, `ps_phase` 8.36–8.77 ms against 9.65–9.72 ms
/// (fastest of 20, four alternating rounds, `docs/performance.md`).
#[inline(always)]
fn copy_entries<E: Copy>(source: &[E], out: &mut [E]) {
    fn fixed<E: Copy, const N: usize>(source: &[E], out: &mut [E]) {
        let source: &[E; N] = source[..N].try_into().expect("N entries");
        let out: &mut [E; N] = out.try_into().expect("N entries");
        *out = *source;
    }
    match out.len() {
        // In two halves, each copied inline (see above).
        9 => {
            fixed::<E, 4>(source, &mut out[..4]);
            fixed::<E, 5>(&source[4..], &mut out[4..]);
        }
        3 => fixed::<E, 3>(source, out),
        m => out.copy_from_slice(&source[..m]),
    }
}

/// Phase 2a: the mass matrix `M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)` (eq. (13)),
/// upper triangle in the pattern's order, and the internal force
/// `F_{k,i} = −Σ_p V_p σ_{kl} ∂phi_i/∂x_l` (eq. (15)) into `force` (overwritten);
/// summed element by element (see the module's notes on threads).
///
/// With `matrix` = [`MassMatrix::RowSums`] only the diagonal is written, with the
/// row sums `Σ_j M_ij = Σ_p m_p phi_i(x_p)` (the basis is a partition of unity,
/// `Σ_j phi_j = 1`), and every other entry is zero: what the lumped mass reads,
/// at one product per function and particle instead of one per pair.
///
/// With `coverage = Some((volume, count))` (and `local` built
/// [`Local::with_coverage`]) the same pass over the particles' basis data also
/// sums what the coverage of each function reads, `volume_i = Σ_p V_p phi_i(x_p)`
/// and `count_i = Σ_p phi_i(x_p)` (in `f64`, `0` for a function that is not live):
/// the sums [`particle_volume`] gives, element by element.
///
/// With `body = Some((f, out))` (and `local` built [`Local::with_body_forces`]) the
/// pass also sums the particle forces `f_p` of the effects that act per particle,
/// `out_{k,i} = Σ_p phi_i(x_p) f_{p,k}` (paper eq. (16) for gravity), written for
/// the live functions: the sums a separate pass ([`scatter_by_elements`]) gives, in
/// the same order, to the last bit, without reading the basis data again (that
/// pass was 5 % of a PS step under gravity).
#[allow(clippy::too_many_arguments)]
pub fn assemble_mass_and_internal_force<T: Scalar, const D: usize>(
    particles: &Particles<T, D>,
    evals: &Evaluations<T, D>,
    bins: &Bins,
    gather: &mut Gather,
    local: &mut Local<T, D>,
    matrix: MassMatrix,
    values: &mut [T],
    force: &mut [Vec<T>],
    coverage: Option<(&mut [f64], &mut [f64])>,
    body: Option<BodyForces<'_, T, D>>,
) {
    let stride = local.stride;
    let full = matrix == MassMatrix::Full;
    let sums = coverage.is_some();
    assert!(
        !sums || !local.coverage.is_empty(),
        "coverage sums need Local::with_coverage"
    );
    assert!(
        body.is_none() || !local.body.is_empty(),
        "body forces need Local::with_body_forces"
    );
    let (forces, body_out) = match body {
        Some((f, out)) => (f, Some(out)),
        None => (&[][..], None),
    };
    let block = Block {
        full,
        coverage: sums,
        forces,
    };
    local.for_each_element_with_coverage(bins, |e, (lm, lv, lc, lb)| {
        let inside = bins.particles(e);
        // Every particle of an element has the element's functions; with as many
        // as the stride (every PS and PL element) the block is summed in a
        // fixed-size array, in the same order (the same bits).
        let m = inside.first().map_or(0, |&p| evals.range(p as usize).len());
        let out = (lm, lv, lc, lb);
        match (m == stride, m) {
            (true, 9) => return element_block::<T, D, 9, 45>(inside, particles, evals, block, out),
            (true, 3) => return element_block::<T, D, 3, 6>(inside, particles, evals, block, out),
            (true, 2) => return element_block::<T, D, 2, 3>(inside, particles, evals, block, out),
            _ => {}
        }
        element_block_any(inside, particles, evals, stride, block, out);
    });
    gather.matrix_assign(local, values);
    zero(force);
    gather.functions(local, true, force);
    if let Some((volume, count)) = coverage {
        gather.coverage(local, volume, count);
    }
    if let Some(out) = body_out {
        zero(out);
        gather.body_forces(local, out);
    }
}

/// The particle forces `f_p` phase 2a sums, and where their sums go
/// ([`assemble_mass_and_internal_force`]).
pub type BodyForces<'a, T, const D: usize> = (&'a [SVector<T, D>], &'a mut [Vec<T>]);

/// What phase 2a sums on an element: the whole mass block or its row sums, the
/// coverage sums or not, and the particle forces `forces` (empty: none).
#[derive(Clone, Copy)]
struct Block<'a, T: Scalar, const D: usize> {
    full: bool,
    coverage: bool,
    forces: &'a [SVector<T, D>],
}

/// Phase 2a on one element, any number of functions per particle (up to
/// `stride`): the sums of [`assemble_mass_and_internal_force`] through the packed
/// index of each pair.
fn element_block_any<T: Scalar, const D: usize>(
    inside: &[u32],
    particles: &Particles<T, D>,
    evals: &Evaluations<T, D>,
    stride: usize,
    Block {
        full,
        coverage,
        forces,
    }: Block<'_, T, D>,
    (lm, lv, lc, lb): ElementBlocks<'_, T>,
) {
    if coverage {
        lc.iter_mut().for_each(|v| *v = T::zero());
    }
    let body = !forces.is_empty();
    if body {
        lb.iter_mut().for_each(|v| *v = T::zero());
    }
    for &p in inside {
        let p = p as usize;
        let range = evals.range(p);
        let (base, m) = (range.start, range.len());
        let (mass, vol, sigma) = (particles.mass[p], particles.volume[p], &particles.sigma[p]);
        for a in 0..m {
            if coverage {
                lc[2 * a] += vol * evals.phi[base + a];
                lc[2 * a + 1] += evals.phi[base + a];
            }
            let w = mass * evals.phi[base + a];
            if full {
                for b in a..m {
                    lm[packed(stride, a, b)] += w * evals.phi[base + b];
                }
            } else {
                lm[packed(stride, a, a)] += w;
            }
            let f_int = sigma * evals.grad_phi[base + a] * vol;
            for k in 0..D {
                lv[a * D + k] += f_int[k];
            }
            if body {
                let f = forces[p] * evals.phi[base + a];
                for k in 0..D {
                    lb[a * D + k] += f[k];
                }
            }
        }
    }
}

/// Phase 2a on one element whose particles have `M` functions each, `M` the
/// stride, `P = M (M + 1) / 2`: the sums of [`assemble_mass_and_internal_force`]
/// in fixed-size arrays (no index arithmetic, unrolled), in the same order and
/// with the same operations, so the result is the same to the last bit.
#[inline(always)]
fn element_block<T: Scalar, const D: usize, const M: usize, const P: usize>(
    inside: &[u32],
    particles: &Particles<T, D>,
    evals: &Evaluations<T, D>,
    Block {
        full,
        coverage,
        forces,
    }: Block<'_, T, D>,
    (lm, lv, lc, lb): ElementBlocks<'_, T>,
) {
    debug_assert_eq!(P, M * (M + 1) / 2);
    let body = !forces.is_empty();
    let mut body_force = [SVector::<T, D>::zeros(); M];
    // The whole square (vectorised rows); the upper triangle is kept.
    let mut square = [[T::zero(); M]; M];
    let mut diagonal = [T::zero(); M];
    let mut vector = [SVector::<T, D>::zeros(); M];
    let mut volume = [T::zero(); M];
    let mut count = [T::zero(); M];
    for &p in inside {
        let p = p as usize;
        let base = evals.range(p).start;
        let phi: &[T; M] = evals.phi[base..base + M].try_into().expect("M functions");
        let grad: &[SVector<T, D>; M] = evals.grad_phi[base..base + M]
            .try_into()
            .expect("M functions");
        let (mass, vol, sigma) = (particles.mass[p], particles.volume[p], &particles.sigma[p]);
        if coverage {
            for a in 0..M {
                volume[a] += vol * phi[a];
                count[a] += phi[a];
            }
        }
        for a in 0..M {
            let w = mass * phi[a];
            if full {
                for b in 0..M {
                    square[a][b] += w * phi[b];
                }
            } else {
                diagonal[a] += w;
            }
            let f_int = sigma * grad[a] * vol;
            vector[a] += f_int;
        }
        if body {
            let f = forces[p];
            for a in 0..M {
                body_force[a] += f * phi[a];
            }
        }
    }
    let mut k = 0;
    for a in 0..M {
        if full {
            lm[k..k + M - a].copy_from_slice(&square[a][a..]);
        } else {
            lm[k] = diagonal[a];
        }
        k += M - a;
    }
    for (a, f) in vector.iter().enumerate() {
        lv[a * D..(a + 1) * D].copy_from_slice(f.as_slice());
    }
    if coverage {
        for a in 0..M {
            lc[2 * a] = volume[a];
            lc[2 * a + 1] = count[a];
        }
    }
    if body {
        for (a, f) in body_force.iter().enumerate() {
            lb[a * D..(a + 1) * D].copy_from_slice(f.as_slice());
        }
    }
}

/// Which part of `M` phase 2a assembles ([`assemble_mass_and_internal_force`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassMatrix {
    /// Every entry `M_ij`.
    Full,
    /// The row sums on the diagonal, zero elsewhere.
    RowSums,
}

/// The affine-preserving lumping of the hybrid extension ([`crate::mass::Correction::InMass`]),
/// added to the assembled `values` of `M`.
///
/// Lumping the pair `(i, j)` adds `M_ij (e_i − e_j)(e_i − e_j)ᵀ` to `M`, with
/// `M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)`: the quadratic form grows by
/// `Σ_p m_p phi_i phi_j (c_i − c_j)²`, which does not vanish on an affine field
/// `c_i = A ξ_i + b` (`ξ_i` the points of linear precision), so that a lumped row
/// damps a rigid rotation. Here each particle's pair term measures `c_i − c_j`
/// against the difference the field's own gradient at the particle predicts,
///
/// `M_A = M + Σ_p m_p Σ_{(i,j) lumped} phi_i phi_j g g ᵀ`, `g = e_i − e_j − G_p (ξ_i − ξ_j)`,
///
/// with `(G_p d)_k = grad phi_k(x_p) · d` over the particle's functions `k`
/// (`Σ_k c_k grad phi_k(x_p)` is the field's gradient there). For an affine
/// field `gᵀc = c_i − c_j − A (ξ_i − ξ_j) = 0`: affine fields project exactly,
/// `M_A c = M c`. Since `Σ_k grad phi_k = 0`, `gᵀ 1 = 0`: row sums, total mass and
/// momentum are those of `M`. `M_A − M` is a sum of positive semi-definite
/// terms with weights linear in a poorly covered function's values, as in
/// lumping, so `M_A ⪰ M` keeps such a function away from a zero pivot. `M_A` is
/// symmetric and serves both solves of the step (eqs. (17) and (20)), so the
/// energy balance `Pᵀ M_A⁻¹ F = v̂ᵀ F` of the step holds as with the consistent
/// mass. Every `g` lives on one particle's functions, so `M_A` keeps the
/// pattern of `M`; summed element by element (see the module's notes on threads).
///
/// `M_A` leaves to `M` alone the affine fields that vanish at the particles: an
/// element whose particles do not determine an affine field (fewer than
/// `D + 1`, or nearly on a line) would leave such a field free, and the system
/// singular. The particles of such an element lump their pairs plainly
/// (`g = e_i − e_j`). An element passes when the mass-weighted covariance `S` of
/// its particle positions has `det S ≥ (α s_e)^D`, with `s_e` the mean variance
/// per axis of its functions' points `ξ` (`element_scale`, [`element_scales`])
/// and `α =` [`AFFINE_SPREAD`], counting its particles but those on a vertex of
/// the mesh (on the closure of two or more other elements, [`Touching`]): the
/// argument below needs pairs `(i, j)` with the element's functions, and a
/// particle on a PS vertex sees only the vertex's three functions, whose
/// coefficients are always those of the tangent plane there, so its pairs add
/// nothing. (A particle on an edge sees the six functions of the edge's
/// vertices and still constrains them; counting it out too changed the runs of
/// lattices whose rows lie on the blocks' diagonals.) A user's body sampled at 1.3
/// particles per element with every particle on a vertex or an edge of a block
/// grid (a lattice of half the block size started on a block line) left the
/// default's system singular (condition 2.5e16, the start's critical step not
/// estimated, energy growth 0.19) while every element "passed" by its particles'
/// positions. A particle on an edge or vertex keeps the whole correction only
/// where every element around it passes ([`Touching`]), so that the choice
/// location made among them does not matter (`marks`: one per element, visited
/// through the occupied elements alone for a body in a mostly empty mesh).
///
/// An element that does not pass but shares functions with one that does is
/// pinned by it, and keeps the whole correction too when those shared functions'
/// points `ξ` span an affine field (the same spread test, `pinned_by_neighbours`;
/// `function_pinned`: scratch, one per function, false between calls). Each particle of a passing
/// element `f` with a lumped function `i` makes every field in the null space of
/// `M_A` affine on `f` (`gᵀc = 0` for the pairs `(i, j)`) and vanish at the
/// particle: with `D + 1` particles not on a line, zero on all of `f`'s functions.
/// A field affine on the neighbour and zero at `D + 1` of its points `ξ` not on a
/// line is zero: nothing is left free, and the plain share would only damp. Without
/// the rule the corners of a spinning square, sweeping a block grid at 4 × 4
/// particles per block, left up to 20 of its 28 elements with lumped pairs with
/// one or two particles, and the square lost 10 % of its angular momentum by
/// t = 3 (`docs/stability.md`, "A spinning square's angular momentum").
///
/// A basis whose functions are affine on every element (PL, `functions_affine`)
/// spans exactly the affine fields there: `grad phi_k · (ξ_i − ξ_j) = δ_ki − δ_kj`,
/// so `g ≡ 0` and the affine-preserving term adds nothing, whatever the
/// particles. Every element of such a basis is treated as the degenerate ones
/// are: its lumped pairs keep the share `θ` of the plain term, `M + θ L`
/// (without it PL's default was the consistent mass near the body's edge and
/// gained 18 % energy after a ball struck a post, `docs/stability.md`).
///
/// Evaluated per particle in factored form: with `Ξ` the rows `ξ_k`,
/// `g = H (e_i − e_j)` for `H = I − G_p Ξᵀ`, so the particle's pairs add
/// `H L Hᵀ = L − G_p Aᵀ − A G_pᵀ + G_p B G_pᵀ`, `L` the Laplacian of its lumped
/// pairs (weights `m_p phi_i phi_j`), `A = L Ξ`, `B = Ξᵀ L Ξ`: one pass over the
/// pairs for `L`, `A`, `B`, then one over the upper triangle, instead of an outer
/// product per pair (measured: the default's step 1.3–1.5× faster on the 72
/// particles-per-triangle columns, `docs/stability.md`).
#[allow(clippy::too_many_arguments)]
pub fn add_affine_lumping<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    bins: &Bins,
    touching: &Touching,
    marks: &mut AffineMarks,
    function_pinned: &mut [bool],
    gather: &Gather,
    local: &mut Local<T, D>,
    mass: &[T],
    x: &[SVector<T, D>],
    points: &[SVector<T, D>],
    element_scale: &[T],
    functions_affine: bool,
    lumped: &[bool],
    values: &mut [T],
) {
    let stride = local.stride;
    let theta = T::of(PLAIN_SHARE);
    let touches_lumped = |p: usize| evals.functions(p).iter().any(|&i| lumped[i as usize]);
    if !functions_affine {
        // The particles of element `e` but those on a vertex of the mesh (on the
        // closure of two or more other elements) determine an affine field.
        let own = |e: usize| {
            let inside = bins.particles(e).iter();
            let off_vertices =
                inside.filter(|&&p| touching.elements_of(p as usize).nth(1).is_none());
            determines_affine(off_vertices, mass, x, element_scale[e])
        };
        let occupied = bins.occupied_elements();
        let listed = super::binning::lists_allowed()
            && (occupied.len() as f64)
                < super::binning::SPARSE_ELEMENTS * marks.affine.len() as f64;
        if listed {
            // An element without particles is never affine: only the occupied
            // ones are visited, and the marks of the last step cleared.
            marks.clear();
            for &e in occupied {
                if own(e as usize) {
                    marks.set(e as usize);
                }
            }
        } else {
            marks.marked.record_all();
            marks
                .affine
                .par_iter_mut()
                .enumerate()
                .for_each(|(e, affine)| *affine = own(e));
        }
        pinned_by_neighbours(
            evals,
            bins,
            marks,
            listed,
            function_pinned,
            points,
            element_scale,
            lumped,
        );
    }
    let element_affine = &marks.affine[..];
    local.for_each_element(bins, |e, (lm, g)| {
        let inside = bins.particles(e);
        if !inside.iter().any(|&p| touches_lumped(p as usize)) {
            return;
        }
        for &p in inside {
            let p = p as usize;
            if !touches_lumped(p) {
                continue;
            }
            // A particle on an edge or vertex: affine only if every element
            // around it is (whichever of them location picked).
            let affine = !functions_affine
                && element_affine[e]
                && touching.elements_of(p).all(|f| element_affine[f]);
            let range = evals.range(p);
            let (base, m) = (range.start, range.len());
            let index = evals.functions(p);
            let (phi, grad_phi) = (&evals.phi[base..base + m], &evals.grad_phi[base..base + m]);
            // The pairs' Laplacian `L` goes straight into `lm`; `A = L Ξ` (row `a` in
            // `g[a D..(a + 1) D]`) and `B = Ξᵀ L Ξ` are gathered beside it. With
            // affine functions `g ≡ 0`: the share `θ` of `L` alone.
            let a_rows = &mut g[..m * D];
            a_rows.iter_mut().for_each(|v| *v = T::zero());
            let row = |a: &[T], c: usize| SVector::<T, D>::from_fn(|r, _| a[c * D + r]);
            let mut b_form = SMatrix::<T, D, D>::zeros();
            for a in 0..m {
                for b in a + 1..m {
                    let (i, j) = (index[a] as usize, index[b] as usize);
                    let w = if functions_affine {
                        theta * mass[p] * phi[a] * phi[b]
                    } else {
                        mass[p] * phi[a] * phi[b]
                    };
                    if !(lumped[i] || lumped[j]) || w == T::zero() {
                        continue;
                    }
                    lm[packed(stride, a, a)] += w;
                    lm[packed(stride, b, b)] += w;
                    lm[packed(stride, a, b)] -= w;
                    if functions_affine {
                        continue;
                    }
                    let d = points[i] - points[j];
                    for r in 0..D {
                        a_rows[a * D + r] += d[r] * w;
                        a_rows[b * D + r] -= d[r] * w;
                    }
                    b_form += d * d.transpose() * w;
                }
            }
            if functions_affine {
                continue;
            }
            // `H L Hᵀ − L = −G Aᵀ − A Gᵀ + G B Gᵀ`; where the element's particles do
            // not pin an affine field, a share `θ` of the plain pairs stays.
            let keep = if affine { T::one() } else { T::one() - theta };
            for c in 0..m {
                let (gc, ac) = (grad_phi[c], row(a_rows, c));
                let bgc = b_form * gc;
                for k in c..m {
                    let (gk, ak) = (grad_phi[k], row(a_rows, k));
                    lm[packed(stride, c, k)] += keep * (bgc.dot(&gk) - gc.dot(&ak) - ac.dot(&gk));
                }
            }
        }
    });
    gather.matrix_add(local, values);
}

/// The spread `α` of [`add_affine_lumping`]: an element's particles determine an
/// affine field when their covariance has `det S ≥ (α s_e)^D` (a uniform fill of
/// a triangle gives about `0.5 s_e` per axis). At `0.01` a disk of radius 0.05
/// (12 or 112 particles) in triangles of edge 1, a tenth of their size, failed
/// the test and its element's plain share stopped its spin; at `0.001` it turns
/// as a rigid body (`docs/stability.md`, "A body smaller than its elements"),
/// and the cells of the stability matrix are the same to every digit.
pub const AFFINE_SPREAD: f64 = 0.001;

/// The share `θ` of the plain pair term `(e_i − e_j)(e_i − e_j)ᵀ` in the elements
/// whose particles do not determine an affine field ([`add_affine_lumping`]).
pub const PLAIN_SHARE: f64 = 0.1;

/// [`add_affine_lumping`]'s per-element marks: the elements whose particles (or
/// pinning neighbours) determine an affine field. A step over a few occupied
/// elements clears only the marks the last one set.
#[derive(Debug, Default)]
pub struct AffineMarks {
    affine: Vec<bool>,
    /// The elements marked by the last pass through the occupied ones.
    marked: LastWritten,
    /// Scratch: the elements passing by their own particles.
    passing: Vec<u32>,
}

impl AffineMarks {
    /// Marks for `elements` elements, none set.
    pub fn new(elements: usize) -> Self {
        AffineMarks {
            affine: vec![false; elements],
            marked: LastWritten::with_capacity(elements),
            passing: Vec::with_capacity(elements),
        }
    }

    /// Every mark cleared, for a pass that sets them through [`AffineMarks::set`].
    fn clear(&mut self) {
        for e in self.marked.each(self.affine.len()) {
            self.affine[e] = false;
        }
        self.marked.begin();
    }

    /// Element `e` marked affine (after [`AffineMarks::clear`]).
    fn set(&mut self, e: usize) {
        self.affine[e] = true;
        self.marked.push(e);
    }
}

/// `flat[i]` for every function `i`: live (an element holding a particle has it,
/// `Gather::live`) and none of the elements of its support that hold particles has
/// particles that determine an affine field by themselves (`determines_affine`,
/// all of their particles counted). Such a function is sampled along a line at
/// most (its particles on a mesh line, in elements on either side of it), and
/// its consistent row is singular across that line however many particles it
/// has: a user's blocks translating on a mesh of 40:1 slivers, sampled on every
/// other row of elements with each particle row on a mesh line, stopped at step
/// 486 on a singular system. With the gather's live list (a body over a small part
/// of the mesh) only the listed functions are written: the others are not read. The
/// default lumps such rows
/// ([`crate::mass::StepContext::flat`]); their elements fail the affine test, so
/// their pairs keep the share `θ` of the plain term, and
/// `M + θ L = (1 − θ) M + θ M_L` is positive definite.
pub fn mark_flat_functions<T: Scalar, const D: usize, B: Basis<T, D>>(
    basis: &B,
    bins: &Bins,
    mass: &[T],
    x: &[SVector<T, D>],
    element_scale: &[T],
    gather: &Gather,
    flat: &mut [bool],
) {
    match gather.live_list() {
        Some(list) => list.iter().for_each(|&i| flat[i as usize] = true),
        None => {
            for (f, &l) in flat.iter_mut().zip(gather.live()) {
                *f = l;
            }
        }
    }
    for &e in bins.occupied_elements() {
        let e = e as usize;
        if determines_affine(bins.particles(e).iter(), mass, x, element_scale[e]) {
            for &f in basis.element_functions(e) {
                flat[f] = false;
            }
        }
    }
}

/// Whether the particles `inside` one element determine an affine field
/// ([`add_affine_lumping`]).
fn determines_affine<'a, T: Scalar, const D: usize>(
    inside: impl Iterator<Item = &'a u32> + Clone,
    mass: &[T],
    x: &[SVector<T, D>],
    scale: T,
) -> bool {
    if inside.clone().count() < D + 1 {
        return false;
    }
    let (mut total, mut mean) = (T::zero(), SVector::<T, D>::zeros());
    for &p in inside.clone() {
        let p = p as usize;
        total += mass[p];
        mean += x[p] * mass[p];
    }
    mean /= total;
    let mut s = SMatrix::<T, D, D>::zeros();
    for &p in inside {
        let p = p as usize;
        let d = x[p] - mean;
        s += d * d.transpose() * (mass[p] / total);
    }
    let bound = T::of(AFFINE_SPREAD) * scale;
    det(&s) >= (0..D).fold(T::one(), |acc, _| acc * bound)
}

/// The elements that hold particles but do not determine an affine field
/// themselves and are pinned by a neighbour that does ([`add_affine_lumping`]):
/// the mark of element `e` is set for those whose functions shared with a passing
/// element (one whose particles see a lumped function) have points `ξ` that pass
/// the spread test of [`determines_affine`] (equal weights). Only the elements
/// that passed by their own particles pin (one ring, no chain). Nothing is done
/// in a step where every element holding particles passes. `listed`: only the
/// occupied elements are visited (their marks were set through `marks.set`).
#[allow(clippy::too_many_arguments)]
fn pinned_by_neighbours<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    bins: &Bins,
    marks: &mut AffineMarks,
    listed: bool,
    function_pinned: &mut [bool],
    points: &[SVector<T, D>],
    element_scale: &[T],
    lumped: &[bool],
) {
    let first = |e: usize| bins.particles(e).first().map(|&p| p as usize);
    let occupied = bins.occupied_elements();
    let degenerate = if listed {
        occupied.iter().any(|&e| !marks.affine[e as usize])
    } else {
        marks
            .affine
            .par_iter()
            .enumerate()
            .any(|(e, &affine)| !affine && first(e).is_some())
    };
    if !degenerate {
        return;
    }
    // The functions of the passing elements whose particles see a lumped function
    // are set to pinned, and cleared again at the end (`function_pinned` is false
    // between calls, so that a step over a few elements touches only theirs).
    let mut passing = std::mem::take(&mut marks.passing);
    passing.clear();
    if listed {
        passing.extend(occupied.iter().filter(|&&e| marks.affine[e as usize]));
    } else {
        passing.extend((0..marks.affine.len() as u32).filter(|&e| marks.affine[e as usize]));
    }
    let pins = |e: u32| {
        let p = first(e as usize)?;
        let functions = evals.functions(p);
        functions
            .iter()
            .any(|&i| lumped[i as usize])
            .then_some(functions)
    };
    for functions in passing.iter().filter_map(|&e| pins(e)) {
        for &i in functions {
            function_pinned[i as usize] = true;
        }
    }
    {
        let function_pinned = &*function_pinned;
        let pinned = |e: usize| {
            let Some(p) = first(e) else { return false };
            let shared = evals
                .functions(p)
                .iter()
                .map(|&i| i as usize)
                .filter(|&i| function_pinned[i])
                .map(|i| points[i]);
            spans_affine(shared, element_scale[e])
        };
        if listed {
            for &e in occupied {
                let e = e as usize;
                if !marks.affine[e] && pinned(e) {
                    marks.set(e);
                }
            }
        } else {
            marks
                .affine
                .par_iter_mut()
                .enumerate()
                .for_each(|(e, affine)| {
                    if !*affine {
                        *affine = pinned(e);
                    }
                });
        }
    }
    for functions in passing.iter().filter_map(|&e| pins(e)) {
        for &i in functions {
            function_pinned[i as usize] = false;
        }
    }
    marks.passing = passing;
}

/// The points `ξ` (equal weights) pass the spread test of [`determines_affine`]:
/// at least `D + 1`, with `det S ≥ (α s_e)^D` for their covariance `S`.
fn spans_affine<T: Scalar, const D: usize>(
    points: impl Iterator<Item = SVector<T, D>> + Clone,
    scale: T,
) -> bool {
    let count = points.clone().count();
    if count < D + 1 {
        return false;
    }
    let n = T::of(count as f64);
    let mean = points.clone().fold(SVector::<T, D>::zeros(), |m, q| m + q) / n;
    let s = points.fold(SMatrix::<T, D, D>::zeros(), |s, q| {
        let d = q - mean;
        s + d * d.transpose() / n
    });
    let bound = T::of(AFFINE_SPREAD) * scale;
    det(&s) >= (0..D).fold(T::one(), |acc, _| acc * bound)
}

/// `s_e`: the mean variance per axis of the points of linear precision `ξ` of each
/// element's functions, the element's size in [`add_affine_lumping`].
pub fn element_scales<T: Scalar, const D: usize, B: Basis<T, D>>(
    basis: &B,
    points: &[SVector<T, D>],
) -> Vec<T> {
    (0..basis.num_elements())
        .map(|e| {
            let f = basis.element_functions(e);
            let count = T::of(f.len() as f64);
            let mean = f
                .iter()
                .fold(SVector::<T, D>::zeros(), |m, &i| m + points[i])
                / count;
            let spread = f
                .iter()
                .fold(T::zero(), |s, &i| s + (points[i] - mean).norm_squared());
            spread / (count * T::of(D as f64))
        })
        .collect()
}

/// The particle → function scatter `out_{k,i} += Σ_p w_p phi_i(x_p) q_{p,k}`
/// shared by the momentum (eq. (21), `w = m`, `q = v`) and any projection of a
/// particle field onto the basis.
pub fn scatter_to_functions<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    bins: &Bins,
    gather: &Gather,
    local: &mut Local<T, D>,
    weight: &[T],
    field: &[SVector<T, D>],
    out: &mut [Vec<T>],
) {
    scatter_by_elements(bins, evals, gather, local, out, |p, s| {
        field[p] * (weight[p] * evals.phi[s])
    });
}

/// The affine correction of the momentum for lumped rows (APIC and RPIC, Jiang et
/// al. 2015, on the pairs a lumping decouples).
///
/// Lumping the pair `(i, j)` moves `M_ij` onto both diagonals,
/// `M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ`; then `M' c = P` no longer returns the
/// coefficients `c_i = v(ξ_i)` of an affine field `v` that the particles carry
/// (`ξ_i` the points of linear precision, `Σ_i phi_i(x) ξ_i = x`), and a rigid
/// rotation decays. Adding to `P` the same pair terms applied to each particle's
/// affine field `v_p + C_p (x − x_p)`,
///
/// `P'_i = P_i + Σ_p m_p phi_i(x_p) Σ_{j decoupled from i} phi_j(x_p) C_p (ξ_i − ξ_j)`,
///
/// gives `M' c = P'` exactly for affine fields. Each pair term enters `i` and `j`
/// with opposite signs, so the total momentum is unchanged. With `rigid`, `C_p` is
/// replaced by its skew part `(C_p − C_pᵀ)/2` (RPIC): rigid motions project exactly
/// and the lumped rows still smooth the straining modes; measured unstable on a
/// jittered column (`docs/stability.md`), so `extended-hybrid-apic` takes the whole `C_p`.
///
/// `C_p` must be the gradient of the field the particle velocity follows: from
/// `v̂ⁿ` alone (without `Δt ∇a`) the column of B5b blows up.
pub struct Affine<'a, T: Scalar, const D: usize> {
    /// `decoupled[i]`: the row of function `i` is lumped ([`crate::mass::MassStrategy::lumped_rows`]).
    pub decoupled: &'a [bool],
    /// `ξ_i`, the points of linear precision ([`psmpm_basis::Basis::function_point`]).
    pub points: &'a [SVector<T, D>],
    /// `C_p`, written here: the gradient of `v̂ⁿ + Δt a` at the particle, the
    /// field whose values the particle velocity update (eq. (18)) follows.
    pub gradient: &'a mut [SMatrix<T, D, D>],
    /// Keep only the skew part of `C_p` (rigid motions; RPIC).
    pub rigid: bool,
}

/// Phases 4–5: particle velocities `v_p += Δt Σ_i a_i phi_i(x_p)` (eq. (18)) and
/// the momentum `P_i = Σ_p m_p phi_i(x_p) v_p` (eq. (21)) into `momentum`, which
/// holds `v̂ⁿ` on entry; with `affine`, corrected for the lumped rows ([`Affine`]).
/// `centred[c]` receives `Σ_p m_p vⁿ_p · Δv_p` over the particles of chunk `c`, in
/// particle order (the time-centred kinetic energy of
/// [`crate::diagnostics::StepReport::total_centred`]).
#[allow(clippy::too_many_arguments)]
pub fn update_velocities_and_momentum<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    bins: &Bins,
    gather: &Gather,
    local: &mut Local<T, D>,
    acceleration: &[Vec<T>],
    dt: T,
    mass: &[T],
    v: &mut [SVector<T, D>],
    momentum: &mut [Vec<T>],
    affine: Option<Affine<'_, T, D>>,
    centred: &mut [f64],
) {
    let increment = |p: usize| {
        let mut a = SVector::<T, D>::zeros();
        for (s, i) in evals.entries(p) {
            for k in 0..D {
                a[k] += acceleration[k][i] * evals.phi[s];
            }
        }
        a * dt
    };
    let Some(Affine {
        decoupled,
        points,
        gradient,
        rigid,
    }) = affine
    else {
        (v.par_chunks_mut(CHUNK), centred.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .for_each(|(c, (v, centred))| {
                *centred = 0.0;
                for (q, v) in v.iter_mut().enumerate() {
                    let p = c * CHUNK + q;
                    let dv = increment(p);
                    *centred += mass[p].to_f64() * v.dot(&dv).to_f64();
                    *v += dv;
                }
            });
        zero(momentum);
        let v = &*v;
        scatter_by_elements(bins, evals, gather, local, momentum, |p, s| {
            let w = mass[p] * evals.phi[s];
            SVector::<T, D>::from_fn(|k, _| w * v[p][k])
        });
        return;
    };
    let old = &*momentum;

    (
        v.par_chunks_mut(CHUNK),
        gradient.par_chunks_mut(CHUNK),
        centred.par_iter_mut(),
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(c, (v, gradient, centred))| {
            *centred = 0.0;
            for (q, (v, g)) in v.iter_mut().zip(gradient.iter_mut()).enumerate() {
                let p = c * CHUNK + q;
                let dv = increment(p);
                *centred += mass[p].to_f64() * v.dot(&dv).to_f64();
                *v += dv;
                *g = SMatrix::zeros();
                for (s, i) in evals.entries(p) {
                    for k in 0..D {
                        let c = old[k][i] + dt * acceleration[k][i];
                        for l in 0..D {
                            g[(k, l)] += c * evals.grad_phi[s][l];
                        }
                    }
                }
                if rigid {
                    *g = (*g - g.transpose()) * T::of(0.5);
                }
            }
        });
    zero(momentum);
    let (v, gradient) = (&*v, &*gradient);
    scatter_by_elements(bins, evals, gather, local, momentum, |p, s| {
        let w = mass[p] * evals.phi[s];
        let mut out = v[p] * w;
        let i = evals.functions(p)[s - evals.range(p).start] as usize;
        let mut lever = SVector::<T, D>::zeros();
        for (t, j) in evals.entries(p) {
            if j != i && (decoupled[i] || decoupled[j]) {
                lever += (points[i] - points[j]) * evals.phi[t];
            }
        }
        out += gradient[p] * lever * w;
        out
    });
}

/// Why phase 6 stopped.
pub enum UpdateFailure {
    /// `det F ≤ 0` or not finite.
    Jacobian {
        /// The particle.
        particle: usize,
        /// Its `det F`.
        jacobian: f64,
    },
    /// Position or velocity not finite.
    NotFinite {
        /// The particle.
        particle: usize,
    },
}

/// Paper eq. (22) with the full velocity gradient: `F ← (I + Δt ∇v) F`.
///
/// The paper uses the symmetric part `ε = ½ (∇v + ∇vᵀ)` (eq. (24)), which drops the
/// spin: under a rigid rotation `∇v` is skew, `ε = 0`, and `F` would stay the
/// identity while the body turns. With the full gradient `F` follows the rotation
/// (to first order in `Δt` per step).
#[inline]
pub fn update_deformation_gradient<T: Scalar, const D: usize>(
    f: &SMatrix<T, D, D>,
    grad_v: &SMatrix<T, D, D>,
    dt: T,
) -> SMatrix<T, D, D> {
    (SMatrix::<T, D, D>::identity() + grad_v * dt) * f
}

/// Phase 6: from the projected velocity `v̂`, the deformation gradient (eq. (22)),
/// stress (eqs. (25)–(27)), volume `V_p = det F_p V_p⁰` (eqs. (28)–(29)), and the
/// positions and displacements `x_p += Δt Σ_i v̂_i phi_i(x_p)` (eqs. (30)–(31)).
/// [`CHUNK`] particles per task; on failure, that of the first failing particle
/// (the particles of other chunks are updated all the same).
///
/// `energy[c]` receives the [`crate::diagnostics::particle_terms`] of the updated
/// particles of chunk `c`, accumulated in particle order
/// ([`crate::diagnostics::accumulate_terms`]), for the step's energies.
#[allow(clippy::too_many_arguments)]
pub fn update_particles<T: Scalar, const D: usize, Mat: ParticleMaterials<T, D>>(
    evals: &Evaluations<T, D>,
    velocity: &[Vec<T>],
    acceleration: Option<&[Vec<T>]>,
    dt: T,
    material: &Mat,
    parts: &mut Particles<T, D>,
    (energy, centred): (&mut [[f64; crate::diagnostics::TERMS]], &mut [f64]),
) -> Result<(), UpdateFailure> {
    // Empty when no particle has an initial stress (then it is zero).
    let sigma0 = &parts.sigma0;
    let failure = (
        (
            parts.f.par_chunks_mut(CHUNK),
            parts.sigma.par_chunks_mut(CHUNK),
            parts.volume.par_chunks_mut(CHUNK),
            parts.x.par_chunks_mut(CHUNK),
            parts.u.par_chunks_mut(CHUNK),
        ),
        (
            parts.volume0.par_chunks(CHUNK),
            parts.v.par_chunks_mut(CHUNK),
            parts.mass.par_chunks(CHUNK),
            energy.par_iter_mut(),
            centred.par_iter_mut(),
        ),
    )
        .into_par_iter()
        .enumerate()
        .filter_map(
            |(c, ((fs, sigma, volume, x, u), (volume0, v, mass, energy, centred)))| {
                *energy = [0.0; crate::diagnostics::TERMS];
                if acceleration.is_some() {
                    *centred = 0.0;
                }
                for q in 0..fs.len() {
                    let p = c * CHUNK + q;
                    if let Some(acceleration) = acceleration {
                        let mut a = SVector::<T, D>::zeros();
                        for (s, i) in evals.entries(p) {
                            for k in 0..D {
                                a[k] += acceleration[k][i] * evals.phi[s];
                            }
                        }
                        let dv = a * dt;
                        *centred += mass[q].to_f64() * v[q].dot(&dv).to_f64();
                        v[q] += dv;
                    }
                    let mut grad_v = SMatrix::<T, D, D>::zeros();
                    let mut v_hat = SVector::<T, D>::zeros();
                    for (s, i) in evals.entries(p) {
                        for k in 0..D {
                            let c = velocity[k][i];
                            v_hat[k] += c * evals.phi[s];
                            for l in 0..D {
                                grad_v[(k, l)] += c * evals.grad_phi[s][l];
                            }
                        }
                    }
                    let f = update_deformation_gradient(&fs[q], &grad_v, dt);
                    let j = det(&f);
                    if !(j.to_f64() > 0.0 && j.to_f64().is_finite()) {
                        return Some(UpdateFailure::Jacobian {
                            particle: p,
                            jacobian: j.to_f64(),
                        });
                    }
                    fs[q] = f;
                    let s0 = crate::particles::initial_stress(sigma0, p);
                    sigma[q] = s0 + material.stress(p, &f);
                    volume[q] = volume0[q] * j;
                    x[q] += v_hat * dt;
                    u[q] += v_hat * dt;
                    let w = material.energy_density(p, &f);
                    let terms = crate::diagnostics::terms_of(
                        mass[q], &v[q], &v_hat, volume0[q], &f, &s0, w,
                    );
                    crate::diagnostics::accumulate_terms(energy, &terms);
                    if !x[q].iter().all(|c| c.to_f64().is_finite())
                        || !v[q].iter().all(|c| c.to_f64().is_finite())
                    {
                        return Some(UpdateFailure::NotFinite { particle: p });
                    }
                }
                None
            },
        )
        .min_by_key(UpdateFailure::particle);
    match failure {
        Some(f) => Err(f),
        None => Ok(()),
    }
}

impl UpdateFailure {
    /// The particle that failed.
    pub fn particle(&self) -> usize {
        match *self {
            UpdateFailure::Jacobian { particle, .. } | UpdateFailure::NotFinite { particle } => {
                particle
            }
        }
    }
}

/// `touches_empty[i]`: the support of function `i` contains an element without
/// particles (the seeds' partial-lumping rule). A particle on an edge or vertex
/// counts in every element around it ([`Touching`]).
pub fn mark_empty_elements<T: Scalar, const D: usize, B: Basis<T, D>>(
    basis: &B,
    bins: &Bins,
    touching: &Touching,
    touches_empty: &mut [bool],
) {
    touches_empty.iter_mut().for_each(|t| *t = false);
    for e in 0..basis.num_elements() {
        if !touching.occupied(bins, e) {
            for &i in basis.element_functions(e) {
                touches_empty[i] = true;
            }
        }
    }
}

/// `Σ_p V_p phi_i(x_p)`: the particle volume each function sees (its coverage
/// numerator).
pub fn particle_volume<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    volume: &[T],
    out: &mut [f64],
) {
    out.iter_mut().for_each(|v| *v = 0.0);
    for p in 0..volume.len() {
        for (s, i) in evals.entries(p) {
            out[i] += (volume[p] * evals.phi[s]).to_f64();
        }
    }
}

/// `Σ_k Σ_i F_{k,i} v̂_{k,i}`.
pub fn power<T: Scalar>(force: &[Vec<T>], velocity: &[Vec<T>]) -> f64 {
    let mut power = 0.0;
    for (f, v) in force.iter().zip(velocity) {
        for (a, b) in f.iter().zip(v) {
            power += (*a * *b).to_f64();
        }
    }
    power
}

/// Sets every entry to zero.
pub fn zero<T: Scalar>(buffers: &mut [Vec<T>]) {
    for b in buffers {
        b.iter_mut().for_each(|v| *v = T::zero());
    }
}

/// `target += source`.
pub fn add_into<T: Scalar>(target: &mut [Vec<T>], source: &[Vec<T>]) {
    for (t, s) in target.iter_mut().zip(source) {
        for (a, b) in t.iter_mut().zip(s) {
            *a += *b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    /// The fixed-size element block gives the general loop's sums to the last bit,
    /// for the full matrix and for the row sums, and the coverage sums (PS: 9
    /// functions, PL: 3).
    #[test]
    fn element_blocks_equal_the_general_loop_bit_for_bit() {
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        fn check<const M: usize, const P: usize>(next: &mut dyn FnMut() -> f64) {
            let n = 7;
            let positions = (0..n).map(|_| Vector2::new(next(), next())).collect();
            let volumes = (0..n).map(|_| 0.5 + next()).collect();
            let mut particles = Particles::<f64, 2>::new(positions, volumes, 1.3);
            for s in &mut particles.sigma {
                let off = next() - 0.5;
                *s = Matrix2::new(next() - 0.5, off, off, next() - 0.5);
            }
            let mut evals =
                Evaluations::<f64, 2>::with_elements(n, M, (0..M as u32).collect(), vec![M as u32]);
            evals.phi.iter_mut().for_each(|v| *v = next());
            evals
                .grad_phi
                .iter_mut()
                .for_each(|g| *g = Vector2::new(next() - 0.5, next() - 0.5));
            let inside: Vec<u32> = vec![3, 0, 6, 1, 5, 2, 4];
            let forces: Vec<Vector2<f64>> = (0..n)
                .map(|_| Vector2::new(next() - 0.5, -9.81 * next()))
                .collect();
            for (full, coverage, body) in [
                (true, false, false),
                (false, false, true),
                (true, true, false),
                (true, true, true),
            ] {
                let forces = if body { &forces[..] } else { &[][..] };
                let block = Block {
                    full,
                    coverage,
                    forces,
                };
                let [mut lm, mut rm] = [0, 1].map(|_| vec![0.0; P]);
                let [mut lv, mut rv] = [0, 1].map(|_| vec![0.0; M * 2]);
                // Stale values in the coverage and body blocks: the element's sums
                // overwrite them.
                let [mut lc, mut rc] = [0, 1].map(|_| vec![0.25; M * 2]);
                let [mut lb, mut rb] = [0, 1].map(|_| vec![0.75; M * 2]);
                let out = (&mut lm[..], &mut lv[..], &mut lc[..], &mut lb[..]);
                element_block::<f64, 2, M, P>(&inside, &particles, &evals, block, out);
                let out = (&mut rm[..], &mut rv[..], &mut rc[..], &mut rb[..]);
                element_block_any(&inside, &particles, &evals, M, block, out);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&lm), bits(&rm), "M = {M}, full = {full}");
                assert_eq!(bits(&lv), bits(&rv), "M = {M}, full = {full}");
                assert_eq!(bits(&lc), bits(&rc), "M = {M}, coverage = {coverage}");
                assert_eq!(bits(&lb), bits(&rb), "M = {M}, body = {body}");
                assert!(rm.iter().any(|&x| x != 0.0));
                if body {
                    // What the separate scatter (`scatter_by_elements`) sums: per
                    // particle in bin order, `f_p phi_a` from zero.
                    for a in 0..M {
                        let mut sum = Vector2::<f64>::zeros();
                        for &p in &inside {
                            let p = p as usize;
                            let f = forces[p] * evals.phi[evals.range(p).start + a];
                            for k in 0..2 {
                                sum[k] += f[k];
                            }
                        }
                        assert_eq!(lb[2 * a].to_bits(), sum[0].to_bits());
                        assert_eq!(lb[2 * a + 1].to_bits(), sum[1].to_bits());
                    }
                }
                if coverage {
                    // The volume and the count each function sees, in particle order.
                    for a in 0..M {
                        let (mut volume, mut count) = (0.0, 0.0);
                        for &p in &inside {
                            let phi = evals.phi[evals.range(p as usize).start + a];
                            volume += particles.volume[p as usize] * phi;
                            count += phi;
                        }
                        assert_eq!(lc[2 * a].to_bits(), volume.to_bits());
                        assert_eq!(lc[2 * a + 1].to_bits(), count.to_bits());
                    }
                }
            }
        }
        check::<9, 45>(&mut next);
        check::<3, 6>(&mut next);
        check::<2, 3>(&mut next);
    }
}
