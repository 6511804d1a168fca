//! The critical time step of the explicit update for the basis and mass strategy in
//! use: `Δt_crit = 2 / ω_max` with `ω_max² = λ_max(M⁻¹ K)`, `M` the system the mass
//! strategy solves (its own inverse, walls included) and `K` the small-strain
//! stiffness `K v = Σ_p V_p σ(∇v_p) ∇phi_i` with each particle's Lamé constants at
//! the current particle positions. `λ_max` by power iteration: a lower bound, so the
//! estimate is an upper bound on `Δt_crit` that tightens with the iterations.
//! Local damping makes the update up to `1 + α` times stiffer: the step is divided
//! by `√(1 + α)` ([`crate::effect::Effect::force_amplification`]).

use super::{phases, Driver, StepError};
use crate::mass::MassStrategy;
use crate::materials::ParticleMaterials;
use crate::sparse::Scalar;
use nalgebra::SMatrix;
use psmpm_basis::Basis;

/// Power iterations of the critical-step estimate.
pub const CRITICAL_ITERATIONS: usize = 40;

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// The critical time step at the current state (see the module doc). Uses the
    /// step's own buffers; call before a step (e.g. at the start of a run).
    pub fn critical_time_step(&mut self) -> Result<f64, StepError> {
        self.locate_and_evaluate()?;
        self.assemble_mass();
        self.factorize()?;
        let critical = self.power_iteration(None)?;
        self.dt_critical = Some(critical);
        Ok(critical)
    }

    /// The product of the effects' [`Effect::force_amplification`](crate::effect::Effect::force_amplification)
    /// (local damping: `1 + α`): it scales `ω_max²`.
    fn effects_amplification(&self) -> f64 {
        self.effects
            .iter()
            .map(|e| e.force_amplification())
            .product()
    }

    /// The critical time step with the row-sum lumped mass `m_i = Σ_p m_p phi_i(x_p)`
    /// in place of the strategy's system, at the state of the last
    /// [`Driver::critical_time_step`] (whose evaluations it reuses). A strategy's
    /// step far below this one (the consistent mass's is typically within a factor
    /// of 2–4) means its mass matrix is nearly singular: too few particles for the
    /// functions it solves for, or functions with almost no support.
    pub fn lumped_critical_time_step(&mut self) -> Result<f64, StepError> {
        let n = self.basis.num_functions();
        let mut lumped = vec![0.0; n];
        for p in 0..self.particles.len() {
            let m = self.particles.mass[p].to_f64();
            for (s, i) in self.evals.entries(p) {
                lumped[i] += m * self.evals.phi[s].to_f64();
            }
        }
        self.power_iteration(Some(&lumped))
    }

    /// `2 / √(a λ_max(M⁻¹K))` by power iteration, `M` the strategy's system
    /// (`None`) or the diagonal `lumped` (its zero entries, functions without
    /// particles, left out), `a` the effects' amplification of the forces.
    fn power_iteration(&mut self, lumped: Option<&[f64]>) -> Result<f64, StepError> {
        let n = self.basis.num_functions();
        // Start: a fixed, non-smooth field (excites the highest modes).
        let mut v: Vec<Vec<T>> = (0..D)
            .map(|k| {
                (0..n)
                    .map(|i| {
                        T::of(
                            1.0 + ((i * 7 + k * 3) % 11) as f64
                                * 0.1
                                * if i % 2 == 0 { 1.0 } else { -1.0 },
                        )
                    })
                    .collect()
            })
            .collect();
        let norm = |v: &[Vec<T>]| {
            v.iter()
                .flat_map(|c| c.iter())
                .map(|a| (*a * *a).to_f64())
                .sum::<f64>()
                .sqrt()
        };
        let mut f = vec![vec![T::zero(); n]; D];
        let mut estimate = 0.0;
        for _ in 0..CRITICAL_ITERATIONS {
            let nv = norm(&v);
            if nv == 0.0 {
                break;
            }
            v.iter_mut()
                .flat_map(|c| c.iter_mut())
                .for_each(|a| *a /= T::of(nv));
            let material = &self.material;
            stiffness_product(
                &self.evals,
                &self.particles.volume,
                |p| material.elastic(p).lame(D),
                &v,
                &mut f,
            );
            match lumped {
                None => {
                    for k in 0..D {
                        if let Err(source) = self.mass.solve(k, &mut f[k]) {
                            return Err(self.mass_failure(source));
                        }
                    }
                }
                Some(m) => {
                    for fk in f.iter_mut() {
                        for (fi, &mi) in fk.iter_mut().zip(m) {
                            *fi = if mi > 0.0 { *fi / T::of(mi) } else { T::zero() };
                        }
                    }
                }
            }
            self.constraints.project(&mut f);
            estimate = norm(&f);
            std::mem::swap(&mut v, &mut f);
        }
        Ok(if estimate > 0.0 {
            2.0 / (estimate * self.effects_amplification()).sqrt()
        } else {
            f64::INFINITY
        })
    }
}

/// `f_i = Σ_p V_p σ(∇v_p) ∇phi_i(x_p)` with the small-strain law
/// `σ = λ_p tr(ε) I + 2 μ_p ε`, `ε = sym ∇v`, and the Lamé constants `lame(p)` of
/// each particle's material (the stiffness applied to `v`; with bodies of several
/// materials, each particle's own, so the estimate is that of the stiffest mode of
/// the whole system).
fn stiffness_product<T: Scalar, const D: usize>(
    evals: &phases::Evaluations<T, D>,
    volume: &[T],
    lame: impl Fn(usize) -> (f64, f64),
    v: &[Vec<T>],
    f: &mut [Vec<T>],
) {
    phases::zero(f);
    for p in 0..volume.len() {
        let (lambda, mu) = lame(p);
        let mut grad = SMatrix::<T, D, D>::zeros();
        for (s, i) in evals.entries(p) {
            for k in 0..D {
                for l in 0..D {
                    grad[(k, l)] += v[k][i] * evals.grad_phi[s][l];
                }
            }
        }
        let eps = (grad + grad.transpose()) * T::of(0.5);
        let sigma =
            SMatrix::<T, D, D>::identity() * (T::of(lambda) * eps.trace()) + eps * T::of(2.0 * mu);
        for (s, i) in evals.entries(p) {
            let g = sigma * evals.grad_phi[s] * volume[p];
            for k in 0..D {
                f[k][i] += g[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::stiffness_product;
    use crate::driver::Driver;
    use crate::mass::{MassKind, MassStrategy};
    use crate::material::{Elastic, LinearElastic};
    use crate::particles::Particles;
    use nalgebra::{DMatrix, SVector};
    use psmpm_basis::basis::linear::Linear;
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    use psmpm_basis::mesh::generators::block_grid;
    use psmpm_basis::Basis;

    /// `λ_max(M⁻¹K)` computed densely: `M` and `K` assembled column by column from
    /// the driver's own evaluations, then the symmetric eigenvalues of `L⁻¹ K L⁻ᵀ`.
    fn dense_critical<B: Basis<f64, 2>>(basis: B) -> (f64, f64) {
        let (nx, ny) = (12, 12);
        let mut positions = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                positions.push(SVector::<f64, 2>::new(
                    (i as f64 + 0.5) / nx as f64 * 2.0,
                    (j as f64 + 0.5) / ny as f64,
                ));
            }
        }
        let n_p = positions.len();
        let volume = 2.0 / n_p as f64;
        let particles = Particles::new(positions, vec![volume; n_p], 3.0);
        let material = LinearElastic::new(Elastic::new(100.0, 0.3, 3.0).unwrap(), 2);
        let mut driver: Driver<f64, 2, B, Box<dyn MassStrategy<f64>>, _> = Driver::new(
            basis,
            particles,
            material,
            MassKind::Consistent.build(),
            &[],
            Vec::new(),
            1e-3,
        )
        .unwrap();
        let estimate = driver.critical_time_step().unwrap();
        let n = driver.basis.num_functions();
        let e = &driver.evals;
        let mut m = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for p in 0..n_p {
            let mass = driver.particles.mass[p];
            for (s, i) in e.entries(p) {
                for (r, j) in e.entries(p) {
                    let v = mass * e.phi[s] * e.phi[r];
                    for k in 0..2 {
                        m[(k * n + i, k * n + j)] += v;
                    }
                }
            }
        }
        let (lambda, mu) = Elastic::new(100.0, 0.3, 3.0).unwrap().lame(2);
        let mut k = DMatrix::<f64>::zeros(2 * n, 2 * n);
        let mut f = vec![vec![0.0; n]; 2];
        for col in 0..2 * n {
            let mut v = vec![vec![0.0; n]; 2];
            v[col / n][col % n] = 1.0;
            stiffness_product(
                &driver.evals,
                &driver.particles.volume,
                |_| (lambda, mu),
                &v,
                &mut f,
            );
            for row in 0..2 * n {
                k[(row, col)] = f[row / n][row % n];
            }
        }
        let l = m
            .cholesky()
            .expect("the consistent mass of a filled mesh")
            .l();
        let l_inv = l.clone().try_inverse().unwrap();
        let a = &l_inv * &k * l_inv.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let lambda_max = a.symmetric_eigenvalues().max();
        (estimate, 2.0 / lambda_max.sqrt())
    }

    #[test]
    fn the_critical_step_matches_a_dense_eigenvalue_computation() {
        let mesh = || block_grid(0.0, 2.0, 0.0, 1.0, 4, 2).unwrap();
        for (name, (estimate, exact)) in [
            (
                "PS",
                dense_critical(PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap()),
            ),
            ("PL", dense_critical(Linear::<f64>::new(mesh()))),
        ] {
            println!("{name}: power iteration {estimate:.6e}, dense {exact:.6e}");
            // The estimate is never below the true critical step by more than the
            // iteration's round-off, and within 5 % of it after 40 iterations.
            assert!(
                estimate >= exact * (1.0 - 1e-9),
                "{name}: {estimate} < {exact}"
            );
            assert!(estimate <= exact * 1.05, "{name}: {estimate} vs {exact}");
        }
    }
}
