//! The phases of one MPM time step (paper eqs. (13)–(31)), each a function over
//! slices named after what it computes. [`Driver::step`](super::Driver::step)
//! calls them in order; none of them knows which basis, mass strategy or
//! material it serves.
//!
//! Per-particle basis data are stored as [`Evaluations`]: particle `p` has
//! `len[p]` entries (function index, `phi`, `grad_phi`) at `p * stride ..`.

use crate::material::{det, Material};
use crate::particles::Particles;
use crate::sparse::{Scalar, SymmetricPattern};
use nalgebra::{SMatrix, SVector};
use psmpm_basis::{Basis, BasisEval};

/// Basis values and gradients of every particle, as evaluated in phase 1.
pub struct Evaluations<T: Scalar, const D: usize> {
    /// Entries per particle slot (the basis's largest number of functions per element).
    pub stride: usize,
    /// Valid entries per particle.
    pub len: Vec<usize>,
    /// Function indices `i`.
    pub index: Vec<usize>,
    /// Values `phi_i(x_p)`.
    pub phi: Vec<T>,
    /// Gradients `grad phi_i(x_p)`.
    pub grad_phi: Vec<SVector<T, D>>,
}

impl<T: Scalar, const D: usize> Evaluations<T, D> {
    /// Buffers for `particles` particles with up to `stride` functions each.
    pub fn new(particles: usize, stride: usize) -> Self {
        Evaluations {
            stride,
            len: vec![0; particles],
            index: vec![0; particles * stride],
            phi: vec![T::zero(); particles * stride],
            grad_phi: vec![SVector::zeros(); particles * stride],
        }
    }

    /// The slot range of particle `p`.
    #[inline]
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        let base = p * self.stride;
        base..base + self.len[p]
    }
}

/// A particle that phase 1 could not place in the mesh.
pub struct Outside {
    /// The particle.
    pub particle: usize,
}

/// Phase 1: locate every particle (walking from its previous element) and
/// evaluate the basis there.
pub fn locate_and_evaluate<T: Scalar, const D: usize, B: Basis<T, D>>(
    basis: &B,
    x: &[SVector<T, D>],
    element: &mut [usize],
    scratch: &mut BasisEval<T, D>,
    out: &mut Evaluations<T, D>,
) -> Result<(), Outside> {
    for p in 0..x.len() {
        let e = basis
            .locate(&x[p], Some(element[p]))
            .ok_or(Outside { particle: p })?;
        element[p] = e;
        basis.eval(e, &x[p], scratch);
        let base = p * out.stride;
        let m = scratch.len();
        out.len[p] = m;
        out.index[base..base + m].copy_from_slice(&scratch.index[..m]);
        out.phi[base..base + m].copy_from_slice(&scratch.phi[..m]);
        out.grad_phi[base..base + m].copy_from_slice(&scratch.grad_phi[..m]);
    }
    Ok(())
}

/// Phase 2a: the mass matrix `M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)` (eq. (13)),
/// upper triangle in the pattern's order, and the internal force
/// `F_{k,i} = −Σ_p V_p σ_{kl} ∂phi_i/∂x_l` (eq. (15)) into `force`.
pub fn assemble_mass_and_internal_force<T: Scalar, const D: usize>(
    pattern: &SymmetricPattern,
    particles: &Particles<T, D>,
    evals: &Evaluations<T, D>,
    values: &mut [T],
    force: &mut [Vec<T>],
) {
    values.iter_mut().for_each(|v| *v = T::zero());
    zero(force);
    for p in 0..particles.len() {
        let base = p * evals.stride;
        let m = evals.len[p];
        let scatter = pattern.element_scatter(particles.element[p]);
        let (mass, vol, sigma) = (particles.mass[p], particles.volume[p], &particles.sigma[p]);
        for a in 0..m {
            let w = mass * evals.phi[base + a];
            for b in a..m {
                values[scatter[a * m + b]] += w * evals.phi[base + b];
            }
            let f_int = sigma * evals.grad_phi[base + a] * vol;
            let i = evals.index[base + a];
            for k in 0..D {
                force[k][i] -= f_int[k];
            }
        }
    }
}

/// The particle → function scatter `out_{k,i} += Σ_p w_p phi_i(x_p) q_{p,k}`
/// shared by the momentum (eq. (21), `w = m`, `q = v`) and any projection of a
/// particle field onto the basis.
pub fn scatter_to_functions<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    weight: &[T],
    field: &[SVector<T, D>],
    out: &mut [Vec<T>],
) {
    for p in 0..weight.len() {
        for s in evals.range(p) {
            let w = weight[p] * evals.phi[s];
            for k in 0..D {
                out[k][evals.index[s]] += w * field[p][k];
            }
        }
    }
}

/// Phases 4–5: particle velocities `v_p += Δt Σ_i a_i phi_i(x_p)` (eq. (18)) and
/// the momentum `P_i = Σ_p m_p phi_i(x_p) v_p` (eq. (21)) into `momentum`.
pub fn update_velocities_and_momentum<T: Scalar, const D: usize>(
    evals: &Evaluations<T, D>,
    acceleration: &[Vec<T>],
    dt: T,
    mass: &[T],
    v: &mut [SVector<T, D>],
    momentum: &mut [Vec<T>],
) {
    zero(momentum);
    for p in 0..v.len() {
        let mut a = SVector::<T, D>::zeros();
        for s in evals.range(p) {
            let i = evals.index[s];
            for k in 0..D {
                a[k] += acceleration[k][i] * evals.phi[s];
            }
        }
        v[p] += a * dt;
        for s in evals.range(p) {
            let w = mass[p] * evals.phi[s];
            for k in 0..D {
                momentum[k][evals.index[s]] += w * v[p][k];
            }
        }
    }
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
pub fn update_particles<T: Scalar, const D: usize, Mat: Material<T, D>>(
    evals: &Evaluations<T, D>,
    velocity: &[Vec<T>],
    dt: T,
    material: &Mat,
    parts: &mut Particles<T, D>,
) -> Result<(), UpdateFailure> {
    for p in 0..parts.len() {
        let mut grad_v = SMatrix::<T, D, D>::zeros();
        let mut v_hat = SVector::<T, D>::zeros();
        for s in evals.range(p) {
            let i = evals.index[s];
            for k in 0..D {
                let c = velocity[k][i];
                v_hat[k] += c * evals.phi[s];
                for l in 0..D {
                    grad_v[(k, l)] += c * evals.grad_phi[s][l];
                }
            }
        }
        let f = update_deformation_gradient(&parts.f[p], &grad_v, dt);
        let j = det(&f);
        if !(j.to_f64() > 0.0 && j.to_f64().is_finite()) {
            return Err(UpdateFailure::Jacobian {
                particle: p,
                jacobian: j.to_f64(),
            });
        }
        parts.f[p] = f;
        parts.sigma[p] = parts.sigma0[p] + material.stress(&f);
        parts.volume[p] = parts.volume0[p] * j;
        parts.x[p] += v_hat * dt;
        parts.u[p] += v_hat * dt;
        if !parts.x[p].iter().all(|c| c.to_f64().is_finite())
            || !parts.v[p].iter().all(|c| c.to_f64().is_finite())
        {
            return Err(UpdateFailure::NotFinite { particle: p });
        }
    }
    Ok(())
}

/// `touches_empty[i]`: the support of function `i` contains an element without
/// particles (the seeds' partial-lumping rule).
pub fn mark_empty_elements<T: Scalar, const D: usize, B: Basis<T, D>>(
    basis: &B,
    element: &[usize],
    occupied: &mut [bool],
    touches_empty: &mut [bool],
) {
    occupied.iter_mut().for_each(|o| *o = false);
    for &e in element {
        occupied[e] = true;
    }
    touches_empty.iter_mut().for_each(|t| *t = false);
    for (e, &occupied) in occupied.iter().enumerate() {
        if !occupied {
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
        for s in evals.range(p) {
            out[evals.index[s]] += (volume[p] * evals.phi[s]).to_f64();
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
