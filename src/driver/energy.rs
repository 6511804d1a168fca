//! The energy balance of a step: the energies and momentum of the state (the
//! particle terms summed per chunk of particles in phase 6, the chunks then in
//! order), and the work of the non-conservative effects booked with the mean of
//! the start and end velocities.

use super::{phases, Driver, StepError};
use crate::diagnostics::{
    energies, energies_from_terms, translational_energy, Energies, StepReport,
};
use crate::mass::MassStrategy;
use crate::materials::ParticleMaterials;
use crate::sparse::Scalar;
use psmpm_basis::Basis;

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// [`energies`] of the state after phase 6, from the per-chunk sums of the
    /// particle terms that [`phases::update_particles`] accumulated (a fixed
    /// order for any number of threads).
    pub(super) fn step_energies(&self) -> Energies {
        energies_from_terms(
            self.energy_terms.iter().copied(),
            &self.particles,
            &self.effects,
        )
    }

    /// Power of the non-conservative forces with the velocity at the start of the
    /// step, `v̂ⁿ`; before the first step `v̂⁰` is the projection of the initial
    /// particle velocities with this step's mass matrix.
    /// The second: that of the dissipative effects' forces alone.
    pub(super) fn power_at_start(&mut self) -> Result<[f64; 2], StepError> {
        if self.work_force.is_empty() {
            return Ok([0.0; 2]);
        }
        if !self.velocity_known {
            self.project_initial_velocity()?;
        }
        Ok([
            phases::power(&self.work_force, &self.velocity),
            self.dissipative_power(),
        ])
    }

    fn dissipative_power(&self) -> f64 {
        if self.dissipative_force.is_empty() {
            0.0
        } else {
            phases::power(&self.dissipative_force, &self.velocity)
        }
    }

    /// `v̂⁰`: the projection of the initial particle velocities with this step's
    /// mass matrix.
    pub(super) fn project_initial_velocity(&mut self) -> Result<(), StepError> {
        self.scatter_momentum();
        self.solve_projection()?;
        self.velocity_known = true;
        Ok(())
    }

    /// Work of the non-conservative effects over the step with the mean of the
    /// start and end velocities, the rule under which the kinetic energy of the
    /// symplectic Euler update changes: `W += Δt F · (v̂ⁿ + v̂ⁿ⁺¹) / 2`.
    /// The dissipative effects' part the same way, into `dissipated`.
    ///
    /// The time-centred total pairs with a work shifted by half a step
    /// ([`Driver::step`]).
    pub(super) fn book_work(&mut self, power_start: [f64; 2]) {
        self.velocity_known = true;
        if !self.work_force.is_empty() {
            let dt = self.dt.to_f64();
            self.work +=
                0.5 * (power_start[0] + phases::power(&self.work_force, &self.velocity)) * dt;
            self.dissipated += 0.5 * (power_start[1] + self.dissipative_power()) * dt;
        }
    }

    /// Energies and momentum of the current state.
    pub fn report(&self) -> StepReport {
        self.report_with(energies(&self.particles, &self.material, &self.effects))
    }

    /// `Σ_b |P_b|² / (2 M_b)` over the bodies ([`Driver::set_body_sizes`]): for one
    /// body from the total mass and momentum of `e`; for several, each body's sums
    /// in particle order, one pass without allocation and in a fixed order (the same
    /// bits for any number of threads). That pass reads the particles' mass and
    /// velocity once, a few operations per particle against the hundreds of a
    /// step's phases.
    fn translational(&self, e: &Energies) -> f64 {
        if self.body_ends.is_empty() {
            return translational_energy(e.mass, &e.momentum[..D]);
        }
        let parts = &self.particles;
        let mut first = 0;
        let mut sum = 0.0;
        for &end in &self.body_ends {
            let (mut mass, mut momentum) = (0.0, [0.0; 2]);
            for p in first..end {
                let m = parts.mass[p].to_f64();
                mass += m;
                for (k, pk) in momentum.iter_mut().enumerate().take(D) {
                    *pk += m * parts.v[p][k].to_f64();
                }
            }
            sum += translational_energy(mass, &momentum[..D]);
            first = end;
        }
        sum
    }

    pub(super) fn report_with(&self, e: Energies) -> StepReport {
        StepReport {
            translational: self.translational(&e),
            step: self.step,
            time: self.time,
            dt: self.dt_outer,
            substeps: 1,
            dt_critical: self.dt_critical,
            dt_critical_latest: self.watch.as_ref().and_then(|w| w.latest),
            kinetic: e.kinetic,
            kinetic_motion: e.kinetic_motion,
            strain: e.strain,
            potential: e.potential,
            work: self.work,
            dissipated: self.dissipated,
            mass: e.mass,
            momentum: e.momentum,
            dim: D,
            max_speed: e.max_speed,
            mass_report: self.last_report,
            worst_coverage_at: self.last_report.worst_coverage.map(|(i, _)| {
                let x = self.basis.function_point(i);
                let mut at = [0.0; 2];
                at[..D].copy_from_slice(&x.as_slice()[..D]);
                at
            }),
            condition: self.last_condition,
            // The initial state's; a step's report replaces it with the centred total.
            total_centred: e.kinetic + e.strain + e.potential - self.work,
            phases: self.phases,
        }
    }
}
