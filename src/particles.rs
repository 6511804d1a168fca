//! Material points, stored as a struct of arrays so that each phase of a step
//! streams through the quantities it needs.

use crate::sparse::Scalar;
use nalgebra::{SMatrix, SVector};

/// The particles of a simulation.
#[derive(Debug, Clone, Default)]
pub struct Particles<T: Scalar, const D: usize> {
    /// Current positions `x_p`.
    pub x: Vec<SVector<T, D>>,
    /// Initial positions `x_p⁰` (where exact solutions are evaluated).
    pub x0: Vec<SVector<T, D>>,
    /// Velocities `v_p`.
    pub v: Vec<SVector<T, D>>,
    /// Displacements `u_p`, updated with eq. (31).
    pub u: Vec<SVector<T, D>>,
    /// Deformation gradients `F_p`.
    pub f: Vec<SMatrix<T, D, D>>,
    /// Cauchy stresses `σ_p`.
    pub sigma: Vec<SMatrix<T, D, D>>,
    /// Initial stresses `σ⁰_p`, added to the material's stress; empty when no
    /// particle has one (a scene without an initial-stress state), which saves
    /// their bytes: read them with [`Particles::initial_stress`].
    pub sigma0: Vec<SMatrix<T, D, D>>,
    /// Initial volumes `V_p⁰`.
    pub volume0: Vec<T>,
    /// Current volumes `V_p = J_p V_p⁰` (eq. (28)).
    pub volume: Vec<T>,
    /// Masses `m_p = ρ_0 V_p⁰`, constant (eq. (13)).
    pub mass: Vec<T>,
    /// Element containing each particle (the hint for the next location).
    pub element: Vec<usize>,
}

impl<T: Scalar, const D: usize> Particles<T, D> {
    /// Particles at rest and unstressed at `positions` with volumes `volumes` and density `rho`.
    pub fn new(positions: Vec<SVector<T, D>>, volumes: Vec<T>, rho: T) -> Self {
        let n = positions.len();
        Particles {
            x0: positions.clone(),
            x: positions,
            v: vec![SVector::zeros(); n],
            u: vec![SVector::zeros(); n],
            f: vec![SMatrix::identity(); n],
            sigma: vec![SMatrix::zeros(); n],
            sigma0: Vec::new(),
            mass: volumes.iter().map(|&v| v * rho).collect(),
            volume0: volumes.clone(),
            volume: volumes,
            element: vec![0; n],
        }
    }

    /// The initial stress `σ⁰_p` of particle `p` (zero when [`Particles::sigma0`]
    /// is empty).
    #[inline]
    pub fn initial_stress(&self, p: usize) -> SMatrix<T, D, D> {
        initial_stress(&self.sigma0, p)
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// `true` without particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// `σ⁰_p` from [`Particles::sigma0`] (zero when it is empty), for loops that
/// borrow the particles' fields apart.
#[inline]
pub fn initial_stress<T: Scalar, const D: usize>(
    sigma0: &[SMatrix<T, D, D>],
    p: usize,
) -> SMatrix<T, D, D> {
    sigma0.get(p).copied().unwrap_or_else(SMatrix::zeros)
}
