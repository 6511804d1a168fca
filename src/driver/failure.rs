//! What a failing step can see, and the fix that fits its cause: a function with
//! almost no particle support that the strategy solves for, a time step above the
//! critical one, an inversion below it.

use super::{phases, to_f64_point, Driver, UNDER_SUPPORTED_COVERAGE};
use crate::mass::{MassError, MassStrategy, SupportFacts};
use crate::materials::ParticleMaterials;
use crate::sparse::Scalar;
use psmpm_basis::Basis;
use psmpm_basis::BasisError;

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// What the driver can see around a failing particle, and the fix that fits.
    pub(super) fn diagnose_particle(&self, particle: usize) -> String {
        if let Some(critical) = self.dt_critical {
            let dt = self.dt.to_f64();
            if dt > critical {
                let speed = self.particles.v[particle].norm().to_f64();
                return format!(
                    "the element around it inverted (speed {speed:.3e}): Δt = {dt:.3e} is above the critical step {critical:.3e} of this basis, mass strategy and material (estimated at the start): lower `time.dt` below it"
                );
            }
        }
        // The worst-covered function among those the particle sees (the coverage
        // is measured here if the strategy did not need it).
        let computed;
        let (support, particle_volume) = match &self.inputs.support {
            Some(s) if self.inputs.needs.coverage => (s, &self.inputs.particle_volume),
            _ => {
                let mut volume = vec![0.0; self.basis.num_functions()];
                phases::particle_volume(&self.evals, &self.particles.volume, &mut volume);
                computed = (SupportFacts::new(&self.basis, &self.pattern, false), volume);
                (&computed.0, &computed.1)
            }
        };
        let worst = self
            .evals
            .range(particle)
            .map(|s| self.evals.index[s])
            .map(|i| {
                (
                    i,
                    SupportFacts::coverage_of(particle_volume[i], support.volume[i]),
                )
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((i, c)) =
            worst.filter(|&(_, c)| c < UNDER_SUPPORTED_COVERAGE && self.last_report.extended == 0)
        {
            return format!(
                "the particle sits in the support of function {i} at {:?}, which particles cover to only {:.1e} of its support, and the mass strategy `{}` solves for it: use the default mass strategy (`extended`), which expresses such functions through their neighbours",
                to_f64_point(&self.basis.function_point(i)),
                c,
                self.mass.spec()
            );
        }
        if let Some((i, c)) = self.last_report.worst_coverage {
            if c < UNDER_SUPPORTED_COVERAGE && self.last_report.treated() == 0 {
                return format!(
                    "function {i} at {:?} is covered to only {c:.1e} and the mass strategy `{}` treats nothing: use the default mass strategy (`extended`)",
                    to_f64_point(&self.basis.function_point(i)),
                    self.mass.spec()
                );
            }
        }
        let speed = self.particles.v[particle].norm().to_f64();
        if let Some(critical) = self.dt_critical {
            let dt = self.dt.to_f64();
            return format!(
                "the element around it inverted (speed {speed:.3e}) although Δt = {dt:.3e} is below the critical step {critical:.3e} estimated at the start: the deformation is large (a stiffer response than at the start, or a law that is not objective, `linear-elastic`, under rotation); try `neo-hookean` or a smaller `time.dt`"
            );
        }
        format!(
            "the element around it inverted (speed {speed:.3e}, Δt = {:.3e}): the time step is likely above the critical one for this material and mesh, lower `time.dt` or `time.courant`; if the body rotates, a law that is not objective (`linear-elastic`) also builds spurious stress",
            self.dt.to_f64()
        )
    }

    /// The error of a failed mass solve, with what the strategy reported.
    pub(super) fn mass_failure(&self, source: MassError) -> StepError {
        let hint = match (self.last_report.worst_coverage, &self.inputs.support) {
            (Some((i, c)), _) => format!(
                "the worst-covered function {i} at {:?} is covered to {c:.1e} of its support: use the default mass strategy (`extended`), which expresses such functions through their neighbours",
                to_f64_point(&self.basis.function_point(i))
            ),
            _ => format!(
                "functions with almost no particle in their support make `{}` singular: use the default mass strategy (`extended`), or `partial` / `lumped`",
                self.mass.spec()
            ),
        };
        StepError::MassNotPositiveDefinite {
            step: self.step + 1,
            source,
            hint,
        }
    }
}

/// Why a step failed. Each names the step, the cause the driver can see, and a
/// fix that fits that cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    #[error("step {step}: particle {particle} at {position:?} left the mesh; {hint}")]
    ParticleLeftMesh {
        step: usize,
        particle: usize,
        position: Vec<f64>,
        /// What to change.
        hint: String,
    },
    #[error("step {step}: the mass system could not be solved ({source}); {hint}")]
    MassNotPositiveDefinite {
        step: usize,
        source: MassError,
        /// What the driver sees (the worst-covered function) and what to change.
        hint: String,
    },
    #[error("step {step}: {quantity} of particle {particle} at {position:?} is not valid; {hint}")]
    NotFinite {
        step: usize,
        quantity: &'static str,
        particle: usize,
        position: Vec<f64>,
        /// What the driver sees near the particle and what to change.
        hint: String,
    },
}

/// Errors setting up a driver.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetupError {
    #[error(transparent)]
    Basis(#[from] BasisError),
    #[error("boundary condition on `{tag}`: {message}")]
    Boundary { tag: String, message: String },
    #[error("particle {particle} at {position:?} lies outside the mesh")]
    ParticleOutside { particle: usize, position: Vec<f64> },
}
