//! Constitutive models: stress from the deformation gradient, and the strain-energy
//! density for energy diagnostics.
//!
//! Every model returns the **Cauchy** stress `σ(F)`: the driver assembles the
//! internal force with the current particle volume, `F^int_i = Σ_p σ_p ∇φ_i V_p`
//! with `V_p = J_p V_p⁰` (eqs. (15), (28)). A law derived from an energy `W(F)` per
//! unit reference volume is energy-consistent with that force when
//! `σ = (1/J) (∂W/∂F) Fᵀ` (the Kirchhoff stress `τ = J σ` over `J`).
//!
//! The laws:
//! - [`LinearElastic`] (`linear-elastic`, alias `paper-linear`): the paper's law
//!   (eqs. (25)–(26)) on `sym(F) − I`. It is **not objective**: a rigid rotation
//!   `F = R(θ)` gives `sym(F) − I = (cos θ − 1) I ≠ 0`, so a rotating body builds
//!   stress and energy. Kept for the seeds' benchmarks, which use it.
//! - [`Corotational`] (`corotational`, alias `corotated`; the default of scenes
//!   that name no model): the same energy on the stretch `U − I` of the polar
//!   decomposition `F = R U`; objective, equal to the paper's law to first order.
//! - [`NeoHookean`] (`neo-hookean`, paper eq. (27)): objective and hyperelastic.
//!
//! In 2D the models are plane strain (`ε_zz = 0`, so the in-plane formulas are the
//! 3D ones restricted to the plane); in 1D they are uniaxial (`λ = 0`, `μ = E / 2`,
//! so that `σ = E ε` for small strain). In 1D `R = 1` and the co-rotational law is
//! the paper's law exactly.

use crate::sparse::Scalar;
use nalgebra::SMatrix;

/// Invalid material parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    #[error("{name} = {} is out of range: {allowed}", crate::scene::limits::echo_number(*value))]
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
    /// Checks `E > 0`, `ρ > 0`, `−1 < ν < 0.5`, each a finite normal float (`ν`
    /// may be 0): a subnormal `E` or `ρ` (below 2.2e-308) would turn the wave speed
    /// and the time step into 0 or infinity.
    pub fn new(young: f64, poisson: f64, density: f64) -> Result<Self, MaterialError> {
        let out = |name, value, allowed| {
            Err(MaterialError::OutOfRange {
                name,
                value,
                allowed,
            })
        };
        if !(young > 0.0 && young.is_finite()) {
            return out("young", young, "E > 0");
        }
        if !young.is_normal() {
            return out(
                "young",
                young,
                "E ≥ 2.2e-308 (subnormal numbers are refused)",
            );
        }
        if !(density > 0.0 && density.is_finite()) {
            return out("density", density, "ρ > 0");
        }
        if !density.is_normal() {
            return out(
                "density",
                density,
                "ρ ≥ 2.2e-308 (subnormal numbers are refused)",
            );
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            return out("poisson", poisson, "−1 < ν < 0.5");
        }
        if poisson != 0.0 && !poisson.is_normal() {
            return out(
                "poisson",
                poisson,
                "ν = 0 or |ν| ≥ 2.2e-308 (subnormal numbers are refused)",
            );
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
    /// Whether the law is objective: a rigid rotation makes no stress (all laws
    /// here but the paper's [`LinearElastic`]).
    fn is_objective(&self) -> bool {
        true
    }
}

/// The paper's linear elasticity on the symmetric part of `F` (eqs. (25)–(26)):
/// `E = ½ (F + Fᵀ) − I`, `σ = λ tr(E) I + 2 μ E`, `W = μ E:E + ½ λ tr(E)²`.
///
/// **Not objective**: under a rigid rotation `F = R(θ)` (2D) the strain is
/// `E = (cos θ − 1) I`, so `σ = 2 (λ + μ)(cos θ − 1) I ≠ 0` and `W > 0`: a body that
/// rotates builds spurious stress and gains or loses energy. Use [`Corotational`]
/// (the default) or [`NeoHookean`] for anything that rotates; this law is kept for
/// the seeds' benchmarks (scene name `linear-elastic`, alias `paper-linear`).
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
    fn is_objective(&self) -> bool {
        false
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

/// The polar decomposition `F = R U` of a 1×1 or 2×2 matrix with `det F > 0`:
/// the rotation `R` and the symmetric positive definite stretch `U = Rᵀ F`.
///
/// 1D: `R = 1`, `U = F`. 2D, closed form and allocation-free: `R` is the rotation
/// by `θ = atan2(F₂₁ − F₁₂, F₁₁ + F₂₂)`, i.e. `(cos θ, sin θ) = (F₁₁ + F₂₂,
/// F₂₁ − F₁₂) / n` with `n = √((F₁₁ + F₂₂)² + (F₂₁ − F₁₂)²)`: that is the one
/// rotation for which `Rᵀ F` is symmetric with positive trace `n` (and so positive
/// definite when `det F > 0`; `n > 0` then, since `n = 0` forces `det F ≤ 0`).
/// `U` is symmetrised against round-off.
#[inline]
pub fn polar<T: Scalar, const D: usize>(
    f: &SMatrix<T, D, D>,
) -> (SMatrix<T, D, D>, SMatrix<T, D, D>) {
    match D {
        1 => (SMatrix::<T, D, D>::identity(), *f),
        2 => {
            let (a, b) = (f[(0, 0)] + f[(1, 1)], f[(1, 0)] - f[(0, 1)]);
            let n = (a * a + b * b).sqrt();
            let (c, s) = if n > T::zero() {
                (a / n, b / n)
            } else {
                (T::one(), T::zero())
            };
            let mut r = SMatrix::<T, D, D>::identity();
            r[(0, 0)] = c;
            r[(0, 1)] = -s;
            r[(1, 0)] = s;
            r[(1, 1)] = c;
            let u = r.transpose() * f;
            let u = (u + u.transpose()) * T::of(0.5);
            (r, u)
        }
        _ => unreachable!("psmpm works in 1D and 2D"),
    }
}

/// The angle (radians, in `[0, π]`) of the rotation `R` of the polar decomposition
/// `F = R U` (0 in 1D): `|atan2(F₂₁ − F₁₂, F₁₁ + F₂₂)|`. One `atan2` per call.
#[inline]
pub fn rotation_angle<T: Scalar, const D: usize>(f: &SMatrix<T, D, D>) -> f64 {
    match D {
        1 => 0.0,
        2 => {
            let (a, b) = (
                (f[(0, 0)] + f[(1, 1)]).to_f64(),
                (f[(1, 0)] - f[(0, 1)]).to_f64(),
            );
            b.atan2(a).abs()
        }
        _ => unreachable!("psmpm works in 1D and 2D"),
    }
}

/// The largest [`rotation_angle`] over the deformation gradients `fs` (0 for none).
pub fn max_rotation<T: Scalar, const D: usize>(fs: &[SMatrix<T, D, D>]) -> f64 {
    fs.iter().map(rotation_angle).fold(0.0, f64::max)
}

/// The smallest `det F` over the deformation gradients `fs` and its index
/// (`(∞, 0)` for none).
pub fn min_jacobian<T: Scalar, const D: usize>(fs: &[SMatrix<T, D, D>]) -> (f64, usize) {
    fs.iter()
        .enumerate()
        .map(|(p, f)| (det(f).to_f64(), p))
        .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
}

/// The `det F` below which a run's body is judged collapsed: compressed to under
/// 5 % of its volume, where none of the elastic laws here is a model of a solid
/// (the linear and co-rotational stresses stay bounded as `det F → 0`).
pub const COLLAPSED_JACOBIAN: f64 = 0.05;

/// Why a body whose particle `particle`, of law `law`, reached `det F = jacobian`
/// (below [`COLLAPSED_JACOBIAN`]) at `position` by the time `time` collapsed, and
/// what to do about it.
pub fn collapse_reason(
    jacobian: f64,
    particle: usize,
    position: &str,
    time: f64,
    law: &AnyMaterial,
    unstable: Option<(f64, f64)>,
) -> String {
    // The energy grew past the verdict's bound before: the collapse ends an
    // instability of the step (a user's PL block dropped 2 m onto a slip floor
    // at `courant = 0.5` collapsed in the air after its rebound, its energy up by
    // half, and was told to check `young`; at 0.12 it ran stable).
    if let Some((growth, crossed)) = unstable {
        return format!(
            "the body collapsed after its energy grew: det F fell to {jacobian:.1e} at particle {particle} (at {position}, sampled at t = {}), below {COLLAPSED_JACOBIAN}, after the time-centred total had grown by {growth:.2e} of the energy scale (past the verdict's bound of 0.05 at t = {}): an instability of the time integration, not a load the law cannot carry; lower `time.courant` (halve it, and again if the energy still grows; `--courant` on the command line; impacts want 0.25 or less with PS, about 0.12 with PL) or `time.dt`",
            crate::scene::limits::echo_fixed(time, 4),
            crate::scene::limits::echo_fixed(crossed, 4)
        );
    }
    let fix = match law {
        AnyMaterial::NeoHookean(_) => "the neo-Hookean pressure grows without bound as det F → 0, so the collapse is the discretisation's: a step too long for the impact (lower `time.courant`) or too few particles where the body is crushed (raise `per_block` or `count`, or lower `spacing`)".to_string(),
        AnyMaterial::Linear(_) | AnyMaterial::Corotational(_) => {
            let name = if matches!(law, AnyMaterial::Linear(_)) {
                "linear-elastic"
            } else {
                "corotational"
            };
            format!("the `{name}` law's stress stays bounded as det F → 0 (at most about λ + 2μ), so it cannot carry a load beyond that: check `young` (in Pa) and use a stiffer material, or `model = \"neo-hookean\"`, whose pressure grows without bound in compression (at strains near 1 it still needs a short step and many particles per element)")
        }
    };
    format!(
        "the body collapsed: det F fell to {jacobian:.1e} at particle {particle} (at {position}, sampled at t = {}), below {COLLAPSED_JACOBIAN}: compressed to under 5 % of its volume, which no elastic law here models; {fix}",
        crate::scene::limits::echo_fixed(time, 4)
    )
}

/// The rotation angle (radians) above which a run with the paper's non-objective
/// law ([`LinearElastic`]) is warned about: at `θ = 0.05` a rigid rotation already
/// gives the spurious strain `cos θ − 1 ≈ −1.2e-3` in every direction.
pub const ROTATION_WARNING: f64 = 0.05;

/// Co-rotational linear elasticity: the paper's law on the stretch of the polar
/// decomposition `F = R U` (see [`polar`]), objective (a rigid rotation `F = R`
/// gives `U = I`: zero stress and energy).
///
/// With `ε = U − I` and `S = λ tr(ε) I + 2 μ ε` (the paper's law in the rotated
/// frame), the energy per unit reference volume is
/// `W = μ ε:ε + ½ λ tr(ε)²`, its first Piola–Kirchhoff stress `∂W/∂F = R S`,
/// the Kirchhoff stress `τ = R S U Rᵀ` (symmetric: `S` is a polynomial in `U`), and
/// the Cauchy stress the driver uses (with the current volume `J V⁰`) is
///
/// `σ = (1/J) R S U Rᵀ`,  `J = det F = det U`.
///
/// So the law is hyperelastic and energy-consistent with the driver's internal force.
/// For small strain `U / J = I + O(ε)`, so `σ = R S Rᵀ + O(ε²)`, and with `R = I +
/// O(ε)` (no rotation) `σ = λ tr(sym F − I) I + 2 μ (sym F − I) + O(ε²)`: the
/// paper's law to first order. In 1D (`R = 1`, `λ = 0`, `μ = E/2`):
/// `σ = E (F − 1) F / F = E (F − 1)`, the paper's law exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corotational {
    /// Constants.
    pub constants: Elastic,
    lambda: f64,
    mu: f64,
}

impl Corotational {
    /// The model in dimension `d`.
    pub fn new(constants: Elastic, d: usize) -> Self {
        let (lambda, mu) = constants.lame(d);
        Corotational {
            constants,
            lambda,
            mu,
        }
    }
}

impl<T: Scalar, const D: usize> Material<T, D> for Corotational {
    #[inline]
    fn stress(&self, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
        let (r, u) = polar(f);
        let id = SMatrix::<T, D, D>::identity();
        let e = u - id;
        let s = id * (T::of(self.lambda) * e.trace()) + e * T::of(2.0 * self.mu);
        let tau = r * s * u * r.transpose();
        // Symmetric in exact arithmetic; symmetrised against round-off.
        (tau + tau.transpose()) * (T::of(0.5) / det(f))
    }
    fn energy_density(&self, f: &SMatrix<T, D, D>) -> T {
        let (_, u) = polar(f);
        let e = u - SMatrix::<T, D, D>::identity();
        let tr = e.trace();
        T::of(self.mu) * e.component_mul(&e).sum() + T::of(0.5 * self.lambda) * tr * tr
    }
    fn elastic(&self) -> &Elastic {
        &self.constants
    }
}

/// The model a scene chose, dispatched at run time (one `match` per particle
/// evaluation, negligible next to the basis work).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyMaterial {
    /// The paper's linear elastic law (not objective).
    Linear(LinearElastic),
    /// Co-rotational linear elastic.
    Corotational(Corotational),
    /// Neo-Hookean.
    NeoHookean(NeoHookean),
}

impl AnyMaterial {
    /// Whether the law is objective (zero stress under a rigid rotation): all but
    /// the paper's [`LinearElastic`].
    pub fn is_objective(&self) -> bool {
        !matches!(self, AnyMaterial::Linear(_))
    }
}

impl<T: Scalar, const D: usize> Material<T, D> for AnyMaterial {
    #[inline]
    fn stress(&self, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
        match self {
            AnyMaterial::Linear(m) => m.stress(f),
            AnyMaterial::Corotational(m) => m.stress(f),
            AnyMaterial::NeoHookean(m) => m.stress(f),
        }
    }
    fn energy_density(&self, f: &SMatrix<T, D, D>) -> T {
        match self {
            AnyMaterial::Linear(m) => Material::<T, D>::energy_density(m, f),
            AnyMaterial::Corotational(m) => Material::<T, D>::energy_density(m, f),
            AnyMaterial::NeoHookean(m) => Material::<T, D>::energy_density(m, f),
        }
    }
    fn elastic(&self) -> &Elastic {
        match self {
            AnyMaterial::Linear(m) => &m.constants,
            AnyMaterial::Corotational(m) => &m.constants,
            AnyMaterial::NeoHookean(m) => &m.constants,
        }
    }
    fn is_objective(&self) -> bool {
        AnyMaterial::is_objective(self)
    }
}

/// The warning for a run with the paper's non-objective law whose particles rotated
/// by up to `max_rotation` radians: `Some` above [`ROTATION_WARNING`].
pub fn rotation_warning(max_rotation: f64) -> Option<String> {
    (max_rotation > ROTATION_WARNING).then(|| {
        format!(
            "material `linear-elastic` (the paper's law on sym(F) − I) is not objective and the body rotated by up to {max_rotation:.3} rad (> {ROTATION_WARNING}): the rotation builds spurious stress and energy; use `model = \"corotational\"` (the default) or `\"neo-hookean\"`"
        )
    })
}

/// Why bodies of the paper's non-objective law that turned by up to
/// `max_rotation` radians over a run gained energy or failed, and the fix:
/// `Some` above [`ROTATION_WARNING`]. The spurious strain of the rotation is no
/// error of the time step: the two disks of Sulsky et al. (1994) colliding along
/// a diagonal with `linear-elastic` (a user's scene, 2026-12-08) grew 13.8 % of
/// their energy at `courant` 0.5 and failed at 0.15, which the growth's advice
/// had offered; with `corotational` they grew 0.8 % at 0.5.
pub fn non_objective_growth_cause(max_rotation: f64) -> Option<String> {
    (max_rotation > ROTATION_WARNING).then(|| {
        format!(
            "the law `linear-elastic` is not objective and the bodies turned by up to {max_rotation:.3} rad in the run: the rotation builds spurious strain energy, which a smaller step does not remove (two disks colliding along a diagonal grew 13.8 % at `courant` 0.5 and failed at 0.15), so use `model = \"corotational\"` (the default) or `\"neo-hookean\"` first"
        )
    })
}

/// The cause to name first when a particle of the paper's non-objective law
/// inverted in a body whose particles of that law rotated by about `rotation`
/// radians (their median): `Some` above [`ROTATION_WARNING`] (where the run warns).
/// A rigid rotation by `θ` alone gives this law the strain `(cos θ − 1) I` (−0.46
/// at 1 rad), a compression that no motion of the body explains: a body spinning
/// at a few rad/s crushes itself.
pub fn non_objective_cause(rotation: f64) -> Option<String> {
    (rotation > ROTATION_WARNING).then(|| {
        format!(
            "its law, `linear-elastic` (the paper's law on sym(F) − I), is not objective and the body turned by about {rotation:.2} rad (the median over its particles): a rotation θ alone gives it the spurious strain cos θ − 1 (here {:.2}) in every direction, which can invert or crush a spinning or turning body; use `model = \"corotational\"` (the default, objective) or `\"neo-hookean\"`",
            rotation.min(std::f64::consts::PI).cos() - 1.0
        )
    })
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

    fn laws(d: usize) -> [(&'static str, AnyMaterial); 3] {
        let c = Elastic::new(1e6, 0.3, 1e3).unwrap();
        [
            (
                "linear-elastic",
                AnyMaterial::Linear(LinearElastic::new(c, d)),
            ),
            (
                "corotational",
                AnyMaterial::Corotational(Corotational::new(c, d)),
            ),
            (
                "neo-hookean",
                AnyMaterial::NeoHookean(NeoHookean::new(c, d)),
            ),
        ]
    }

    fn rotation(theta: f64) -> Matrix2<f64> {
        let (s, c) = theta.sin_cos();
        Matrix2::new(c, -s, s, c)
    }

    /// A rigid rotation `F = R(θ)`: the objective laws give zero stress and energy
    /// (to round-off); the paper's law gives `σ = 2 (λ + μ)(cos θ − 1) I`, which is
    /// why it is not objective.
    #[test]
    fn rigid_rotation_stresses_only_the_papers_law() {
        let young = 1e6;
        for theta in [
            1e-3,
            0.05,
            0.3,
            0.7,
            std::f64::consts::FRAC_PI_4,
            1.2,
            std::f64::consts::FRAC_PI_2,
        ] {
            for sign in [1.0, -1.0] {
                let f = rotation(sign * theta);
                assert!((rotation_angle(&f) - theta).abs() < 1e-12);
                for (name, law) in laws(2) {
                    let s: Matrix2<f64> = law.stress(&f);
                    let w = Material::<f64, 2>::energy_density(&law, &f);
                    if law.is_objective() {
                        assert!(s.norm() < 1e-9 * young, "{name} θ = {theta}: σ = {s}");
                        assert!(w.abs() < 1e-9 * young, "{name} θ = {theta}: W = {w}");
                    } else {
                        let (l, m) = Material::<f64, 2>::elastic(&law).lame(2);
                        let expected = Matrix2::identity() * (2.0 * (l + m) * (theta.cos() - 1.0));
                        assert!(
                            (s - expected).norm() < 1e-9 * young,
                            "{name} θ = {theta}: σ = {s}"
                        );
                        assert!(s.norm() > 0.1 * young * (1.0 - theta.cos()));
                        assert!(w > 0.0);
                    }
                }
            }
        }
        // And on top of a stretch: rotating a deformed state rotates the stress
        // (σ(R F) = R σ(F) Rᵀ) for the objective laws only.
        let f = Matrix2::new(1.02, 0.01, -0.005, 0.97);
        let r = rotation(0.6);
        for (name, law) in laws(2) {
            let (s, sr): (Matrix2<f64>, Matrix2<f64>) = (law.stress(&f), law.stress(&(r * f)));
            let gap = (sr - r * s * r.transpose()).norm() / s.norm();
            if law.is_objective() {
                assert!(gap < 1e-12, "{name}: {gap}");
            } else {
                assert!(gap > 0.1, "{name}: {gap}");
            }
        }
    }

    #[test]
    fn polar_decomposition_is_a_rotation_times_a_symmetric_stretch() {
        for f in [
            Matrix2::new(1.0, 0.0, 0.0, 1.0),
            Matrix2::new(1.3, 0.4, -0.2, 0.8),
            Matrix2::new(0.1, -2.0, 1.5, 0.3),
            rotation(3.0) * Matrix2::new(2.0, 0.3, 0.3, 0.5),
        ] {
            let (r, u): (Matrix2<f64>, Matrix2<f64>) = polar(&f);
            assert!((r * u - f).norm() < 1e-14 * f.norm().max(1.0));
            assert!((r.transpose() * r - Matrix2::identity()).norm() < 1e-14);
            assert!((r.determinant() - 1.0).abs() < 1e-14);
            assert!((u - u.transpose()).norm() < 1e-14);
            assert!(u.trace() > 0.0 && u.determinant() > 0.0);
        }
        assert!(
            (rotation_angle(&(rotation(3.0) * Matrix2::new(2.0, 0.3, 0.3, 0.5))) - 3.0).abs()
                < 1e-12
        );
        let one = nalgebra::Matrix1::new(1.2);
        assert_eq!(polar(&one), (nalgebra::Matrix1::new(1.0), one));
        assert_eq!(rotation_angle(&one), 0.0);
        assert_eq!(max_rotation::<f64, 2>(&[]), 0.0);
        assert!((max_rotation(&[rotation(0.2), rotation(-0.4)]) - 0.4).abs() < 1e-12);
        assert!(rotation_warning(0.04).is_none());
        assert!(rotation_warning(0.06).unwrap().contains("corotational"));
    }

    /// The objective law matches the paper's law to first order in the strain: the
    /// gap is `O(ε²)` (it shrinks 100-fold when ε shrinks 10-fold); in 1D the laws
    /// are equal.
    #[test]
    fn corotational_law_is_the_papers_law_to_first_order() {
        let c = Elastic::new(1e6, 0.3, 1e3).unwrap();
        let (lin, co) = (LinearElastic::new(c, 2), Corotational::new(c, 2));
        let gap = |eps: f64| {
            let f = Matrix2::new(1.0 + eps, 0.7 * eps, -0.4 * eps, 1.0 - 0.5 * eps);
            let (a, b): (Matrix2<f64>, Matrix2<f64>) = (lin.stress(&f), co.stress(&f));
            let (wa, wb) = (
                Material::<f64, 2>::energy_density(&lin, &f),
                Material::<f64, 2>::energy_density(&co, &f),
            );
            (
                (a - b).norm() / (1e6 * eps),
                (wa - wb).abs() / (1e6 * eps * eps),
            )
        };
        let (s1, w1) = gap(1e-3);
        let (s2, w2) = gap(1e-4);
        assert!(s1 < 1e-2 && s2 < 1e-3 && s2 < 0.2 * s1, "{s1} {s2}");
        assert!(w1 < 1e-1 && w2 < 0.2 * w1.max(1e-12) + 1e-6, "{w1} {w2}");
        let (lin1, co1) = (LinearElastic::new(c, 1), Corotational::new(c, 1));
        for x in [0.5, 0.9, 1.0, 1.1, 2.0] {
            let f = nalgebra::Matrix1::new(x);
            let (a, b): (nalgebra::Matrix1<f64>, nalgebra::Matrix1<f64>) =
                (lin1.stress(&f), co1.stress(&f));
            assert!((a - b).norm() < 1e-9, "{x}");
        }
    }

    /// The hyperelastic laws are energy-consistent with the driver's Cauchy stress
    /// on the current volume: `J σ = (∂W/∂F) Fᵀ` (central differences of `W`).
    #[test]
    fn objective_laws_are_energy_consistent_with_the_cauchy_stress() {
        let f = Matrix2::new(1.15, 0.2, -0.1, 0.9);
        for (name, law) in laws(2) {
            if !law.is_objective() {
                continue;
            }
            let h = 1e-6;
            let mut p = Matrix2::zeros();
            for i in 0..2 {
                for j in 0..2 {
                    let mut e = Matrix2::zeros();
                    e[(i, j)] = h;
                    p[(i, j)] = (Material::<f64, 2>::energy_density(&law, &(f + e))
                        - Material::<f64, 2>::energy_density(&law, &(f - e)))
                        / (2.0 * h);
                }
            }
            let s: Matrix2<f64> = law.stress(&f);
            let gap = (s * f.determinant() - p * f.transpose()).norm() / s.norm();
            assert!(gap < 1e-6, "{name}: {gap}");
        }
    }
}
