//! Constitutive models: stress from the deformation gradient, and the strain-energy
//! density for energy diagnostics.
//!
//! In 2D the models are plane strain (`ε_zz = 0`, so the in-plane formulas are the
//! 3D ones restricted to the plane); in 1D they are uniaxial (`λ = 0`, `μ = E / 2`,
//! so that `σ = E ε` for small strain).

use crate::sparse::Scalar;
use nalgebra::SMatrix;

/// Invalid material parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    #[error("{name} = {value} is out of range: {allowed}")]
    OutOfRange {
        name: &'static str,
        value: f64,
        allowed: &'static str,
    },
}

/// Elastic constants shared by the models.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    /// Young's modulus `E`.
    pub young: f64,
    /// Poisson's ratio `ν`.
    pub poisson: f64,
    /// Reference density `ρ_0`.
    pub density: f64,
}

impl Elastic {
    /// Checks `E > 0`, `ρ > 0`, `−1 < ν < 0.5`.
    pub fn new(young: f64, poisson: f64, density: f64) -> Result<Self, MaterialError> {
        if !(young > 0.0 && young.is_finite()) {
            return Err(MaterialError::OutOfRange {
                name: "young",
                value: young,
                allowed: "E > 0",
            });
        }
        if !(density > 0.0 && density.is_finite()) {
            return Err(MaterialError::OutOfRange {
                name: "density",
                value: density,
                allowed: "ρ > 0",
            });
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(MaterialError::OutOfRange {
                name: "poisson",
                value: poisson,
                allowed: "−1 < ν < 0.5",
            });
        }
        Ok(Elastic {
            young,
            poisson,
            density,
        })
    }

    /// Lamé constants `(λ, μ)` for dimension `d`: plane strain in 2D, uniaxial in 1D.
    pub fn lame(&self, d: usize) -> (f64, f64) {
        if d == 1 {
            (0.0, 0.5 * self.young)
        } else {
            let (e, nu) = (self.young, self.poisson);
            (
                e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
                e / (2.0 * (1.0 + nu)),
            )
        }
    }

    /// P-wave modulus `λ + 2μ` (for the wave speed and the Courant number).
    pub fn p_modulus(&self, d: usize) -> f64 {
        let (l, m) = self.lame(d);
        l + 2.0 * m
    }
}

/// Determinant of a 1×1 or 2×2 matrix.
#[inline]
pub fn det<T: Scalar, const D: usize>(m: &SMatrix<T, D, D>) -> T {
    match D {
        1 => m[(0, 0)],
        2 => m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)],
        _ => unreachable!("psmpm works in 1D and 2D"),
    }
}

/// A constitutive model.
pub trait Material<T: Scalar, const D: usize>: Sync {
    /// Cauchy stress `σ(F)`.
    fn stress(&self, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D>;
    /// Strain-energy density per unit reference volume `W(F)`.
    fn energy_density(&self, f: &SMatrix<T, D, D>) -> T;
    /// The elastic constants.
    fn elastic(&self) -> &Elastic;
}

/// Linear elasticity on the symmetric part of `F` (paper eqs. (25)–(26)):
/// `E = ½ (F + Fᵀ) − I`, `σ = λ tr(E) I + 2 μ E`, `W = μ E:E + ½ λ tr(E)²`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Constants.
    pub constants: Elastic,
    lambda: f64,
    mu: f64,
}

impl LinearElastic {
    /// The model in dimension `d`.
    pub fn new(constants: Elastic, d: usize) -> Self {
        let (lambda, mu) = constants.lame(d);
        LinearElastic {
            constants,
            lambda,
            mu,
        }
    }
}

impl<T: Scalar, const D: usize> Material<T, D> for LinearElastic {
    #[inline]
    fn stress(&self, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
        let half = T::of(0.5);
        let e = (f + f.transpose()) * half - SMatrix::<T, D, D>::identity();
        SMatrix::<T, D, D>::identity() * (T::of(self.lambda) * e.trace()) + e * T::of(2.0 * self.mu)
    }
    fn energy_density(&self, f: &SMatrix<T, D, D>) -> T {
        let half = T::of(0.5);
        let e = (f + f.transpose()) * half - SMatrix::<T, D, D>::identity();
        let tr = e.trace();
        T::of(self.mu) * e.component_mul(&e).sum() + half * T::of(self.lambda) * tr * tr
    }
    fn elastic(&self) -> &Elastic {
        &self.constants
    }
}

/// Compressible neo-Hookean model (paper eq. (27)):
/// `σ = (λ ln J / J) I + (μ / J)(F Fᵀ − I)`,
/// `W = ½ μ (tr(FᵀF) − d) − μ ln J + ½ λ (ln J)²`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    /// Constants.
    pub constants: Elastic,
    lambda: f64,
    mu: f64,
}

impl NeoHookean {
    /// The model in dimension `d`.
    pub fn new(constants: Elastic, d: usize) -> Self {
        let (lambda, mu) = constants.lame(d);
        NeoHookean {
            constants,
            lambda,
            mu,
        }
    }
}

impl<T: Scalar, const D: usize> Material<T, D> for NeoHookean {
    #[inline]
    fn stress(&self, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
        let j = det(f);
        let id = SMatrix::<T, D, D>::identity();
        id * (T::of(self.lambda) * j.ln() / j) + (f * f.transpose() - id) * (T::of(self.mu) / j)
    }
    fn energy_density(&self, f: &SMatrix<T, D, D>) -> T {
        let j = det(f);
        let lnj = j.ln();
        let half = T::of(0.5);
        half * T::of(self.mu) * (f.component_mul(f).sum() - T::of(D as f64)) - T::of(self.mu) * lnj
            + half * T::of(self.lambda) * lnj * lnj
    }
    fn elastic(&self) -> &Elastic {
        &self.constants
    }
}

/// The model a scene chose, dispatched at run time (one `match` per particle
/// evaluation, negligible next to the basis work).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyMaterial {
    /// Linear elastic.
    Linear(LinearElastic),
    /// Neo-Hookean.
    NeoHookean(NeoHookean),
}

impl<T: Scalar, const D: usize> Material<T, D> for AnyMaterial {
    #[inline]
    fn stress(&self, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
        match self {
            AnyMaterial::Linear(m) => m.stress(f),
            AnyMaterial::NeoHookean(m) => m.stress(f),
        }
    }
    fn energy_density(&self, f: &SMatrix<T, D, D>) -> T {
        match self {
            AnyMaterial::Linear(m) => Material::<T, D>::energy_density(m, f),
            AnyMaterial::NeoHookean(m) => Material::<T, D>::energy_density(m, f),
        }
    }
    fn elastic(&self) -> &Elastic {
        match self {
            AnyMaterial::Linear(m) => &m.constants,
            AnyMaterial::NeoHookean(m) => &m.constants,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix2;

    #[test]
    fn parameters_are_validated() {
        assert!(Elastic::new(0.0, 0.0, 1.0).is_err());
        assert!(Elastic::new(1.0, 0.5, 1.0).is_err());
        assert!(Elastic::new(1.0, -1.0, 1.0).is_err());
        assert!(Elastic::new(1.0, 0.3, -1.0).is_err());
        assert!(Elastic::new(1.0, 0.3, 1.0).is_ok());
    }

    #[test]
    fn stress_is_the_derivative_of_energy_for_small_strain_and_models_agree() {
        let c = Elastic::new(100.0, 0.3, 1.0).unwrap();
        let (lin, neo) = (LinearElastic::new(c, 2), NeoHookean::new(c, 2));
        let eps = 1e-6;
        let f = Matrix2::new(1.0 + eps, 0.3 * eps, 0.1 * eps, 1.0 - 0.5 * eps);
        let (s1, s2): (Matrix2<f64>, Matrix2<f64>) = (lin.stress(&f), neo.stress(&f));
        assert!((s1 - s2).norm() < 1e-9 * 100.0);
        // Zero stress and energy at rest.
        let id = Matrix2::<f64>::identity();
        assert!(Material::<f64, 2>::energy_density(&neo, &id).abs() < 1e-15);
        assert!(Material::<f64, 2>::stress(&neo, &id).norm() < 1e-15);
        // Uniaxial 1D: σ = E ε.
        let one = nalgebra::Matrix1::new(1.0 + eps);
        let s: nalgebra::Matrix1<f64> = LinearElastic::new(c, 1).stress(&one);
        assert!((s[(0, 0)] - 100.0 * eps).abs() < 1e-12);
    }
}
