//! Effects: the physics a scene asks for beyond elasticity. Only the effects a scene
//! lists are assembled; a scene without gravity never evaluates it.

use crate::particles::Particles;
use crate::sparse::Scalar;
use nalgebra::SVector;

/// Basis values of every particle at the start of a step, as the driver evaluated
/// them: particle `p` has `len[p]` entries at `p * stride ..`.
pub struct ParticleBasis<'a, T: Scalar, const D: usize> {
    /// Entries per particle slot.
    pub stride: usize,
    /// Valid entries per particle.
    pub len: &'a [usize],
    /// Function indices.
    pub index: &'a [usize],
    /// Values `phi_i(x_p)`.
    pub phi: &'a [T],
}

/// A force contribution (and its potential energy, if it has one).
pub trait Effect<T: Scalar, const D: usize>: Send + Sync {
    /// Name for output.
    fn name(&self) -> &'static str;
    /// Adds the effect's force coefficients `F_{k,i}` to `forces[k][i]`.
    fn add_forces(
        &self,
        particles: &Particles<T, D>,
        basis: &ParticleBasis<T, D>,
        forces: &mut [Vec<T>],
    );
    /// Potential energy of the particles in the effect's field (zero if none).
    fn potential_energy(&self, particles: &Particles<T, D>) -> f64;
}

/// Uniform gravity `g`: `F^body_{k,i} = Σ_p m_p phi_i(x_p) g_k` (paper eq. (16)),
/// potential energy `−Σ_p m_p g · x_p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gravity<T: Scalar, const D: usize> {
    /// Acceleration of gravity.
    pub g: SVector<T, D>,
}

impl<T: Scalar, const D: usize> Effect<T, D> for Gravity<T, D> {
    fn name(&self) -> &'static str {
        "gravity"
    }
    fn add_forces(
        &self,
        particles: &Particles<T, D>,
        basis: &ParticleBasis<T, D>,
        forces: &mut [Vec<T>],
    ) {
        for p in 0..particles.len() {
            let base = p * basis.stride;
            for a in 0..basis.len[p] {
                let (i, phi) = (basis.index[base + a], basis.phi[base + a]);
                let w = particles.mass[p] * phi;
                for k in 0..D {
                    forces[k][i] += w * self.g[k];
                }
            }
        }
    }
    fn potential_energy(&self, particles: &Particles<T, D>) -> f64 {
        particles
            .x
            .iter()
            .zip(&particles.mass)
            .map(|(x, m)| -(m.to_f64()) * self.g.dot(x).to_f64())
            .sum()
    }
}
