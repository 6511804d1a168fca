//! What a step and a run report: energies, momentum, what the mass strategy did,
//! the condition of the solved system, phase timings, and the stability verdict
//! of the benchmark definitions of the seeds (paper and thesis, as checked against their tables).

use crate::effect::Effect;
use crate::mass::MassReport;
use crate::materials::ParticleMaterials;
use crate::particles::Particles;
use crate::sparse::Scalar;
use nalgebra::{SMatrix, SVector};

/// Largest growth of the time-centred total energy ([`StepReport::total_centred`],
/// relative to the energy scale of the run) for a run to count as stable.
pub const STABLE_ENERGY_GROWTH: f64 = 0.05;
/// How many terms a particle adds to [`energies`] ([`terms_of`]).
pub const TERMS: usize = 9;

/// Largest condition estimate of the solved mass system for a stable run.
pub const STABLE_CONDITION: f64 = 1e8;

/// Energies, momentum and what the mass strategy did, after a step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepReport {
    /// Step number (1-based after the first step).
    pub step: usize,
    /// Time after the step.
    pub time: f64,
    /// The time step `Δt`.
    pub dt: f64,
    /// The sub-steps the step was taken in (1 but where the watch over the
    /// critical step split it, [`crate::driver::Driver::watch_critical_step`]).
    pub substeps: usize,
    /// The critical time step estimated at the start of the run (power iteration on
    /// `M⁻¹K`), when it was estimated; `Δt / Δt_crit` is the Courant number.
    pub dt_critical: Option<f64>,
    /// The latest estimate of the critical step while the bodies move, when the
    /// watch is on ([`crate::driver::Driver::watch_critical_step`]).
    pub dt_critical_latest: Option<f64>,
    /// Kinetic energy `Σ ½ m_p |v_p|²`.
    pub kinetic: f64,
    /// Kinetic energy of the motion, `Σ ½ m_p |v̂_p|²` with `v̂_p` the velocity
    /// re-projected onto the basis at the particle, the one that moved it in the
    /// step (paper eq. (30)). `v_p` carries from step to step what the basis does
    /// not see (after an impact above all), so `kinetic` can exceed it by much:
    /// that part of `kinetic` moves no particle. The initial state's is `kinetic`.
    pub kinetic_motion: f64,
    /// Strain energy `Σ V_p⁰ W(F_p)`.
    pub strain: f64,
    /// Potential energy of the effects (gravity).
    pub potential: f64,
    /// Work done on the body by the non-conservative effects (body forces,
    /// traction, damping) since the start, `Σ_n Δt F^n · v̂^n`.
    pub work: f64,
    /// The part of `work` done by the effects that can only take energy out
    /// (frictionless contact between bodies, [`crate::effect::Effect::dissipative`]):
    /// where it is positive the discretisation gained that energy, and the
    /// verdict counts it as growth ([`StepReport::unearned_work`]).
    pub dissipated: f64,
    /// Total mass.
    pub mass: f64,
    /// Total momentum, `dim` components ([`StepReport::momentum`]).
    pub(crate) momentum: [f64; 2],
    /// Kinetic energy of the bodies' translations, `Σ_b |P_b|² / (2 M_b)` with
    /// `P_b` and `M_b` the momentum and mass of body `b`'s particles
    /// ([`translational_energy`]; one body unless the driver was told the bodies,
    /// [`crate::driver::Driver::set_body_sizes`]). `K − Σ_b T_b ≥ 0` is the kinetic
    /// energy of the motion about each body's centre of mass, which a steady
    /// translation leaves unchanged: the verdict's scale subtracts the least
    /// translational energy seen ([`Verdict`]).
    pub translational: f64,
    /// Spatial dimension: the number of momentum components.
    pub dim: usize,
    /// Largest particle speed.
    pub max_speed: f64,
    /// What the mass strategy did.
    pub mass_report: MassReport,
    /// The position of the worst-covered function of
    /// [`MassReport::worst_coverage`] (its point of linear precision,
    /// [`psmpm_basis::Basis::function_point`]; `dim` components), when reported.
    pub worst_coverage_at: Option<[f64; 2]>,
    /// Condition-number estimate of the solved mass system, when requested.
    pub condition: Option<f64>,
    /// The time-centred total energy of the state at the start of the step,
    /// `½ Σ_p m_p vⁿ_p · vⁿ⁺¹_p + S(xⁿ) + P(xⁿ) − Wⁿ`: the quantity the symplectic
    /// Euler update conserves exactly on a linear system, so it does not swing with
    /// the `ω Δt` oscillation of [`StepReport::total_energy`] after an impact; what
    /// it gains is gained (`docs/stability.md`, "Slip walls along an axis"). The
    /// total itself in the report of the initial state.
    pub total_centred: f64,
    /// Wall time of the phases of the step.
    pub phases: PhaseTimes,
}

/// Wall time (seconds) of the phases of one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhaseTimes {
    /// Locate particles and evaluate the basis.
    pub evaluate: f64,
    /// Assemble the mass matrix and forces.
    pub assemble: f64,
    /// Factorise and solve both mass systems (and the condition estimate, if on).
    pub solve: f64,
    /// Update particle velocities, momentum, deformation, stress and positions.
    pub update: f64,
}

impl PhaseTimes {
    /// Adds `other` phase by phase.
    pub fn accumulate(&mut self, other: &PhaseTimes) {
        self.evaluate += other.evaluate;
        self.assemble += other.assemble;
        self.solve += other.solve;
        self.update += other.update;
    }
}

impl StepReport {
    /// Total momentum `Σ m_p v_p`, one component per dimension.
    pub fn momentum(&self) -> &[f64] {
        &self.momentum[..self.dim]
    }

    /// Kinetic + strain + potential energy minus the work of the non-conservative
    /// effects: constant up to the time-integration error.
    pub fn total_energy(&self) -> f64 {
        self.kinetic + self.strain + self.potential - self.work
    }

    /// What the dissipative effects added over the run, `max(dissipated, 0)`: energy
    /// gained, not work done.
    pub fn unearned_work(&self) -> f64 {
        self.dissipated.max(0.0)
    }

    /// `[time, kinetic, strain, potential, work, total]`: the energy history's row.
    pub fn energy_row(&self) -> [f64; 6] {
        [
            self.time,
            self.kinetic,
            self.strain,
            self.potential,
            self.work,
            self.total_energy(),
        ]
    }
}

/// Energies and momentum of the particles.
pub struct Energies {
    /// Kinetic energy.
    pub kinetic: f64,
    /// Kinetic energy of the velocity that moved the particles
    /// ([`StepReport::kinetic_motion`]).
    pub kinetic_motion: f64,
    /// Strain energy (with the first-order work of an initial stress).
    pub strain: f64,
    /// Potential energy of the effects.
    pub potential: f64,
    /// Total mass.
    pub mass: f64,
    /// Total momentum, per component.
    pub momentum: [f64; 2],
    /// Largest particle speed.
    pub max_speed: f64,
}

/// The energies and momentum of `parts` under `material` and `effects`: the
/// [`particle_terms`] summed per chunk of [`crate::driver::phases::CHUNK`]
/// particles, the chunks then in order, as the driver's step sums them (the same
/// bits).
pub fn energies<T: Scalar, const D: usize, Mat: ParticleMaterials<T, D>>(
    parts: &Particles<T, D>,
    material: &Mat,
    effects: &[Box<dyn Effect<T, D>>],
) -> Energies {
    let chunk = crate::driver::phases::CHUNK;
    let partials = (0..parts.len().div_ceil(chunk)).map(|c| {
        let mut sum = [0.0; TERMS];
        for p in c * chunk..((c + 1) * chunk).min(parts.len()) {
            accumulate_terms(&mut sum, &particle_terms(parts, material, p));
        }
        sum
    });
    energies_from_terms(partials, parts, effects)
}

/// What particle `p` adds to [`energies`]: `½ m |v|²`, `|v|`, `V⁰ W(F)`, the
/// initial stress's work `V⁰ σ⁰ : (sym F − I)`, whether it has an initial stress
/// (1 or 0), `m`, `m v` (up to two components), as [`terms_of`] gives them.
pub fn particle_terms<T: Scalar, const D: usize, Mat: ParticleMaterials<T, D>>(
    parts: &Particles<T, D>,
    material: &Mat,
    p: usize,
) -> [f64; TERMS] {
    terms_of(
        parts.mass[p],
        &parts.v[p],
        &parts.v[p],
        parts.volume0[p],
        &parts.f[p],
        &parts.initial_stress(p),
        material.energy_density(p, &parts.f[p]),
    )
}

/// The [`particle_terms`] of a particle of mass `m`, velocity `v`, moved by the
/// velocity `v_motion`, of initial volume `volume0`, deformation gradient `f`,
/// initial stress `sigma0` and strain energy density `w = W(F)`.
#[inline]
pub fn terms_of<T: Scalar, const D: usize>(
    m: T,
    v: &SVector<T, D>,
    v_motion: &SVector<T, D>,
    volume0: T,
    f: &SMatrix<T, D, D>,
    sigma0: &SMatrix<T, D, D>,
    w: T,
) -> [f64; TERMS] {
    let m = m.to_f64();
    let speed2 = v.norm_squared().to_f64();
    let mut terms = [0.0; TERMS];
    terms[0] = 0.5 * m * speed2;
    terms[1] = speed2.sqrt();
    terms[2] = volume0.to_f64() * w.to_f64();
    if *sigma0 != SMatrix::<T, D, D>::zeros() {
        // First-order work of the initial stress: V⁰ σ⁰ : (sym F − I).
        let e = (f + f.transpose()) * T::of(0.5) - SMatrix::<T, D, D>::identity();
        terms[3] = volume0.to_f64() * sigma0.dot(&e).to_f64();
        terms[4] = 1.0;
    }
    terms[5] = m;
    for k in 0..D {
        terms[6 + k] = m * v[k].to_f64();
    }
    terms[8] = 0.5 * m * v_motion.norm_squared().to_f64();
    terms
}

/// `sum += terms` in the order [`energies_from_terms`] reads them: entry 1 (the
/// speed) as a maximum, the others summed. Partial sums of consecutive particles,
/// read in their order, give [`energies_from_terms`] a fixed summation order.
#[inline]
pub fn accumulate_terms(sum: &mut [f64; TERMS], terms: &[f64; TERMS]) {
    for (k, (s, t)) in sum.iter_mut().zip(terms).enumerate() {
        if k == 1 {
            *s = s.max(*t);
        } else {
            *s += *t;
        }
    }
}

/// [`energies`] from the [`particle_terms`] of every particle, in particle order.
pub fn energies_from_terms<T: Scalar, const D: usize>(
    terms: impl Iterator<Item = [f64; TERMS]>,
    parts: &Particles<T, D>,
    effects: &[Box<dyn Effect<T, D>>],
) -> Energies {
    let (mut kinetic, mut strain, mut mass, mut max_speed) = (0.0, 0.0, 0.0, 0.0f64);
    let mut kinetic_motion = 0.0;
    let mut momentum = [0.0; 2];
    for t in terms {
        kinetic += t[0];
        max_speed = max_speed.max(t[1]);
        strain += t[2];
        if t[4] != 0.0 {
            strain += t[3];
        }
        mass += t[5];
        for k in 0..D {
            momentum[k] += t[6 + k];
        }
        kinetic_motion += t[8];
    }
    Energies {
        kinetic,
        kinetic_motion,
        strain,
        potential: effects
            .iter()
            .map(|e| e.potential_energy(parts))
            .fold(0.0, |a, b| a + b),
        mass,
        momentum,
        max_speed,
    }
}

/// The kinetic energy `|P|² / (2 M)` of the translation of a body of mass `mass`
/// and momentum `momentum`: its kinetic energy less that of the motion about its
/// centre of mass (König). Zero for a body without mass.
pub fn translational_energy(mass: f64, momentum: &[f64]) -> f64 {
    if mass > 0.0 {
        momentum.iter().map(|p| p * p).sum::<f64>() / (2.0 * mass)
    } else {
        0.0
    }
}

/// The elastic energy stored in the particles' initial stresses,
/// `Σ_p V⁰_p ½ σ⁰_p : ε⁰_p` with `ε⁰ = C⁻¹ σ⁰` the small strain of each particle's
/// law that carries `σ⁰` (`σ = λ tr(ε) I + 2μ ε`, plane strain in 2D): the strain
/// energy a stress-free body would store once settled into that state. Zero
/// without initial stresses.
pub fn initial_stress_energy<T: Scalar, const D: usize, Mat: ParticleMaterials<T, D>>(
    parts: &Particles<T, D>,
    material: &Mat,
) -> f64 {
    (0..parts.sigma0.len())
        .map(|p| {
            let sigma = parts.initial_stress(p).map(|v| v.to_f64());
            let (lambda, mu) = material.elastic(p).lame(D);
            let trace_strain = sigma.trace() / (D as f64 * lambda + 2.0 * mu);
            let strain =
                (sigma - SMatrix::<f64, D, D>::identity() * (lambda * trace_strain)) / (2.0 * mu);
            parts.volume0[p].to_f64() * 0.5 * sigma.dot(&strain)
        })
        .sum()
}

/// The floor of the energy scale, relative to the largest `K + S` seen
/// ([`Verdict::scale`]): the scale of a body in pure rigid translation, whose
/// `max (K + S) − min Σ_b T_b` is round-off (a difference of nearly equal
/// numbers, about `1e-16 K`) while the round-off its time-centred total gathers
/// over 1e4–1e5 steps is about `1e-12 K`. With the floor such a run needs a growth
/// of `5e-8 K` to be judged unstable, 4–5 orders of magnitude above round-off; a
/// vibration of less than `1e-6` of the body's translational energy is judged
/// against the floor, not against its own energy (`docs/stability.md`, "A steady
/// translation does not widen the scale").
pub const ROUND_OFF_SCALE: f64 = 1e-6;

/// Tracks the energy balance and the condition of a run, and gives the verdict.
///
/// The drift and growth of the total energy `E = K + S + P − W` are measured
/// against the *energy scale* ([`Verdict::scale`]), the largest of
///
/// - `max (K + S) − min Σ_b T_b + E_σ`: the largest kinetic plus strain energy seen
///   less the least translational energy of the bodies seen
///   (`T_b = |P_b|² / (2 M_b)`, [`StepReport::translational`]), plus the elastic
///   energy `E_σ` stored in an initial stress (below);
/// - the range the potential energy `P` or the work `W` of the effects has swept;
/// - [`ROUND_OFF_SCALE`] `× (max (K + S) + E_σ)`: a floor at round-off.
///
/// Unlike `|E|` or `|P|`, these do not change when the scene is moved or gravity's
/// zero level is put elsewhere, or when gravity is written as a body force: the
/// verdict of a run is that of its motion (`docs/stability.md`, "The energy scale
/// of the verdict"). Nor when the bodies are given a common steady velocity
/// (Galilean invariance): by König's theorem `K = I + Σ_b T_b`, with `I ≥ 0` the
/// kinetic energy about each body's centre of mass, so with `T = Σ_b T_b`
/// steady the first term is `max (I + S)`, the internal energy's, whatever the
/// velocity; a change of translation (a fall, an impact on a wall, bodies striking
/// each other) still counts, as the range of `T` it sweeps. The term lies between
/// `max(max (I + S), max T − min T)` and their sum, and never above the former
/// scale `max (K + S)`, which it equals whenever the bodies pass through a state
/// without translation (a drop from rest, a collision of equal bodies, a bar
/// vibrating between fixed ends): the energy a falling body's translation hands to
/// its vibration at an impact is not counted twice. Until 2026-12-05 the scale was
/// the largest `K + S`, which holds the translation: a 1D bar vibrating while it
/// crossed the mesh at 1 m/s gained 48 % of its vibration energy and was judged
/// stable at 3.7e-2 of the translation's energy (`docs/stability.md`, "A steady
/// translation does not widen the scale").
///
/// A run that starts from an initial stress `σ⁰` (a geostatic column) counts its
/// strain energy from that state, so `K + S` leaves out the elastic energy the
/// state stores, which the same column settled from a stress-free start counts
/// in `S`: [`Verdict::with_initial_stress_energy`] adds it to the scale, so that
/// a column at rest under its geostatic stress is judged as the settled one is
/// (its small oscillation about equilibrium is not the scale of the run).
#[derive(Debug, Clone, Copy)]
pub struct Verdict {
    e0: f64,
    /// The elastic energy stored in the initial stress ([`initial_stress_energy`]).
    stored: f64,
    /// Largest `K + S` seen.
    motion: f64,
    /// Least translational energy `Σ_b T_b` seen.
    translational: f64,
    /// Least and largest potential energy seen.
    potential: (f64, f64),
    /// Least and largest work of the effects seen.
    work: (f64, f64),
    drift: f64,
    growth: f64,
    /// Largest growth of [`StepReport::total_centred`].
    growth_centred: f64,
    /// The step (and its time) since which the growth of the time-centred total
    /// has stayed at or above [`STABLE_ENERGY_GROWTH`] of the energy scale seen so
    /// far.
    pub growth_crossed: Option<(usize, f64)>,
    /// The step (and its time) in which the largest growth of the time-centred
    /// total so far rose most, and by how much (absolute): an impact's growth
    /// comes in a few steps, which the crossing of the bound, reached by a
    /// smaller growth on a smaller scale earlier, need not name.
    pub largest_rise: Option<(usize, f64, f64)>,
    /// Largest condition estimate seen.
    pub max_condition: Option<f64>,
}

impl Verdict {
    /// Starts from the initial state.
    pub fn new(start: &StepReport) -> Self {
        Verdict {
            e0: start.total_energy(),
            stored: 0.0,
            motion: start.kinetic + start.strain,
            translational: start.translational,
            potential: (start.potential, start.potential),
            work: (start.work, start.work),
            drift: 0.0,
            growth: 0.0,
            growth_centred: 0.0,
            growth_crossed: None,
            largest_rise: None,
            max_condition: None,
        }
    }

    /// The same, with the elastic energy `stored` in the run's initial stress
    /// ([`initial_stress_energy`]) added to the energy scale.
    pub fn with_initial_stress_energy(mut self, stored: f64) -> Self {
        self.stored = stored.max(0.0);
        self
    }

    /// Takes the report of a step.
    pub fn observe(&mut self, r: &StepReport) {
        self.motion = self.motion.max(r.kinetic + r.strain);
        self.translational = self.translational.min(r.translational);
        self.potential = (
            self.potential.0.min(r.potential),
            self.potential.1.max(r.potential),
        );
        self.work = (self.work.0.min(r.work), self.work.1.max(r.work));
        let unearned = r.unearned_work();
        let change = r.total_energy() + unearned - self.e0;
        self.drift = self.drift.max(change.abs());
        self.growth = self.growth.max(change);
        let centred = r.total_centred + unearned - self.e0;
        let rise = centred - self.growth_centred;
        if rise > 0.0 && self.largest_rise.is_none_or(|(_, _, most)| rise > most) {
            self.largest_rise = Some((r.step, r.time, rise));
        }
        self.growth_centred = self.growth_centred.max(centred);
        // The scale widens over the run (it starts at the round-off floor for a
        // body thrown in pure translation): a crossing that a wider scale undoes is
        // forgotten, so the step reported is the one since which the growth has
        // stayed at or above the bound.
        let above =
            self.growth_centred > 0.0 && self.growth_centred >= STABLE_ENERGY_GROWTH * self.scale();
        if !above {
            self.growth_crossed = None;
        } else if self.growth_crossed.is_none() {
            self.growth_crossed = Some((r.step, r.time));
        }
        if let Some(c) = r.condition {
            self.max_condition = Some(self.max_condition.map_or(c, |m: f64| m.max(c)));
        }
    }

    /// The energy scale (see [`Verdict`]):
    /// `max(max (K + S) − min Σ_b T_b + E_σ, ΔP, ΔW, ε_r (max (K + S) + E_σ))`,
    /// with `ε_r` = [`ROUND_OFF_SCALE`].
    pub fn scale(&self) -> f64 {
        (self.motion - self.translational + self.stored)
            .max(self.potential.1 - self.potential.0)
            .max(self.work.1 - self.work.0)
            .max(ROUND_OFF_SCALE * (self.motion + self.stored))
    }

    /// Initial total energy.
    pub fn initial_energy(&self) -> f64 {
        self.e0
    }

    /// `(drift, growth)` of the total energy relative to the energy scale (0 for
    /// a run in which nothing moved and nothing changed).
    pub fn energy_drift_and_growth(&self) -> (f64, f64) {
        let scale = self.scale();
        let relative = |e: f64| {
            if e == 0.0 {
                0.0
            } else if scale > 0.0 {
                e / scale
            } else {
                f64::INFINITY
            }
        };
        (relative(self.drift), relative(self.growth))
    }

    /// The step and time of [`Verdict::largest_rise`] and its share of the
    /// largest growth of the time-centred total (`None` when it never grew).
    pub fn largest_rise_share(&self) -> Option<(usize, f64, f64)> {
        let (step, time, rise) = self.largest_rise?;
        (self.growth_centred > 0.0).then(|| (step, time, rise / self.growth_centred))
    }

    /// The largest growth of the time-centred total
    /// ([`StepReport::total_centred`]) relative to the energy scale: the part of
    /// the growth that is not the explicit step's oscillation.
    pub fn centred_growth(&self) -> f64 {
        let scale = self.scale();
        if self.growth_centred <= 0.0 {
            0.0
        } else if scale > 0.0 {
            self.growth_centred / scale
        } else {
            f64::INFINITY
        }
    }

    /// Stable: no failure, growth of the time-centred total
    /// ([`Verdict::centred_growth`]) below [`STABLE_ENERGY_GROWTH`], every condition
    /// estimate below [`STABLE_CONDITION`]. The total itself swings by about `ω Δt`
    /// of the energy of the modes an impact excites, first order in the step, and
    /// that swing is not energy gained: a thin plate that lost 30 % of its energy
    /// bouncing on a contact floor was judged UNSTABLE by its total's 19 % swing
    /// (centred growth 3e-3; `docs/stability.md`).
    pub fn stable(&self, failed: bool) -> bool {
        !failed
            && !self.energy_bound_broken()
            && self.max_condition.is_none_or(|c| c < STABLE_CONDITION)
    }

    /// The energy part of the verdict: the time-centred total grew by
    /// [`STABLE_ENERGY_GROWTH`] of the energy scale or more (NaN counts as grown).
    pub fn energy_bound_broken(&self) -> bool {
        self.centred_growth().partial_cmp(&STABLE_ENERGY_GROWTH) != Some(std::cmp::Ordering::Less)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body falling and bouncing: `(kinetic, strain, potential)` per step, with a
    /// total that creeps up by 9 of a motion of about 100.
    fn falling(shift: f64) -> Vec<StepReport> {
        [
            (0.0, 0.0, 100.0),
            (50.0, 0.0, 50.5),
            (99.0, 3.0, 1.0),
            (20.0, 83.0, 0.0),
            (60.0, 1.0, 48.0),
        ]
        .iter()
        .enumerate()
        .map(|(step, &(kinetic, strain, potential))| {
            centred(StepReport {
                step,
                time: step as f64,
                kinetic,
                strain,
                potential: potential + shift,
                ..StepReport::default()
            })
        })
        .collect()
    }

    /// `r` with its time-centred total equal to its total (no swing).
    fn centred(mut r: StepReport) -> StepReport {
        r.total_centred = r.total_energy();
        r
    }

    fn verdict(reports: &[StepReport]) -> Verdict {
        let mut v = Verdict::new(&reports[0]);
        reports[1..].iter().for_each(|r| v.observe(r));
        v
    }

    /// The verdict is that of the motion: moving gravity's zero level (or the
    /// scene) changes no number of it, and writing gravity as a body force (its
    /// work instead of its potential) changes none either.
    #[test]
    fn the_energy_verdict_does_not_depend_on_the_potential_zero_or_its_form() {
        let base = verdict(&falling(0.0));
        assert_eq!(base.scale(), 103.0);
        let (drift, growth) = base.energy_drift_and_growth();
        assert!((drift - 9.0 / 103.0).abs() < 1e-15 && drift == growth);
        for shift in [1e3, -5e4, 1e7] {
            let moved = verdict(&falling(shift));
            assert_eq!(moved.scale(), base.scale(), "shift {shift}");
            let (d, g) = moved.energy_drift_and_growth();
            assert!(
                (d - drift).abs() < 1e-9 && (g - growth).abs() < 1e-9,
                "shift {shift}"
            );
        }
        let as_work: Vec<StepReport> = falling(0.0)
            .into_iter()
            .map(|r| {
                centred(StepReport {
                    potential: 0.0,
                    work: 100.0 - r.potential,
                    ..r
                })
            })
            .collect();
        let worked = verdict(&as_work);
        assert_eq!(worked.scale(), base.scale());
        assert_eq!(worked.energy_drift_and_growth(), (drift, growth));
        assert_eq!(worked.growth_crossed, Some((4, 4.0)));
    }

    /// The stored energy of an initial stress is `½ σ⁰ : C⁻¹ σ⁰` per unit volume
    /// (1D: `σ² / 2E`; 2D plane strain under a uniaxial `σ_yy`:
    /// `(1 − ν²) σ² / 2E`), and it widens the scale against which a small
    /// oscillation about that state is judged.
    #[test]
    fn an_initial_stress_stores_energy_that_widens_the_scale() {
        use crate::material::{Elastic, LinearElastic};
        let elastic = Elastic::new(1e6, 0.3, 1000.0).unwrap();
        let (sigma, volume) = (-3e4, 0.5);
        let mut bar =
            Particles::<f64, 1>::new(vec![nalgebra::Vector1::new(0.2)], vec![volume], 1.0);
        bar.sigma0 = vec![SMatrix::<f64, 1, 1>::new(sigma)];
        let law = LinearElastic::new(elastic, 1);
        let stored = initial_stress_energy(&bar, &law);
        let expected = volume * sigma * sigma / (2.0 * 1e6);
        assert!(
            (stored - expected).abs() < 1e-12 * expected,
            "{stored} {expected}"
        );
        let mut column =
            Particles::<f64, 2>::new(vec![SVector::<f64, 2>::new(0.2, 0.3)], vec![volume], 1.0);
        column.sigma0 = vec![SMatrix::<f64, 2, 2>::new(0.0, 0.0, 0.0, sigma)];
        let stored = initial_stress_energy(&column, &LinearElastic::new(elastic, 2));
        let expected = volume * (1.0 - 0.09) * sigma * sigma / (2.0 * 1e6);
        assert!(
            (stored - expected).abs() < 1e-12 * expected,
            "{stored} {expected}"
        );
        // Without an initial stress: nothing stored.
        column.sigma0.clear();
        assert_eq!(
            initial_stress_energy(&column, &LinearElastic::new(elastic, 2)),
            0.0
        );

        // A start at rest whose total rises to 1.1: UNSTABLE against the motion's
        // own scale (1.1), stable against a stored energy of 100.
        let state = |k: f64, s: f64| {
            centred(StepReport {
                kinetic: k,
                strain: s,
                ..StepReport::default()
            })
        };
        let history = [state(0.0, 0.0), state(1.0, 0.1), state(0.5, 0.5)];
        let judge = |stored: f64| {
            let mut v = Verdict::new(&history[0]).with_initial_stress_energy(stored);
            history[1..].iter().for_each(|r| v.observe(r));
            v.stable(false)
        };
        assert!(!judge(0.0));
        assert!(judge(100.0));
    }

    /// The verdict judges the time-centred total: a total that swings 10 % above its
    /// start after an impact while the centred total stays put is stable (and its
    /// growth is still reported); a centred total that gains 6 % is not.
    #[test]
    fn the_verdict_judges_the_time_centred_total_not_the_swing() {
        let swing = |total_gain: f64, centred_gain: f64| {
            let start = centred(StepReport {
                kinetic: 100.0,
                ..StepReport::default()
            });
            let after = StepReport {
                step: 1,
                time: 1.0,
                kinetic: 100.0 + total_gain,
                total_centred: 100.0 + centred_gain,
                ..StepReport::default()
            };
            verdict(&[start, after])
        };
        let v = swing(10.0, 0.0);
        assert!(v.stable(false));
        assert!((v.energy_drift_and_growth().1 - 10.0 / 110.0).abs() < 1e-15);
        assert_eq!(v.growth_crossed, None);
        let v = swing(0.0, 6.0);
        assert!(!v.stable(false));
        assert!((v.centred_growth() - 0.06).abs() < 1e-15);
        assert_eq!(v.growth_crossed, Some((1, 1.0)));
    }

    /// The step in which the centred total rose most is kept with its share of
    /// the growth: a slow gain of 1 over ten steps, then 3 in one step (an
    /// impact), then a fall (which is no rise).
    #[test]
    fn the_largest_rise_of_the_centred_total_is_named() {
        let at = |step: usize, gain: f64| StepReport {
            step,
            time: 0.1 * step as f64,
            kinetic: 100.0,
            total_centred: 100.0 + gain,
            ..StepReport::default()
        };
        let mut history: Vec<StepReport> = (0..=10).map(|k| at(k, 0.1 * k as f64)).collect();
        history.push(at(11, 4.0));
        history.push(at(12, 2.0));
        let v = verdict(&history);
        let (step, time, share) = v.largest_rise_share().unwrap();
        assert_eq!((step, time), (11, 1.1));
        assert!((share - 0.75).abs() < 1e-12, "{share}");
    }

    /// A body vibrating with energy 0.1 that gains 30 % of it over the run,
    /// translating with the translational energy `translation` (constant: a steady
    /// translation), as `(kinetic, strain)` swapping a quarter period per step.
    fn vibrating(translation: f64) -> Vec<StepReport> {
        (0..=40)
            .map(|step| {
                let vibration = 0.1 * (1.0 + 0.3 * step as f64 / 40.0);
                let phase = step as f64 * std::f64::consts::FRAC_PI_4;
                centred(StepReport {
                    step,
                    time: step as f64,
                    kinetic: translation + vibration * phase.cos().powi(2),
                    strain: vibration * phase.sin().powi(2),
                    translational: translation,
                    ..StepReport::default()
                })
            })
            .collect()
    }

    /// A steady translation does not widen the scale: the vibrating body that
    /// gains 30 % of its energy is UNSTABLE whether it is at rest or translating
    /// with 100 times its vibration energy, with the same scale and growth (the
    /// former scale, `max (K + S)`, held the translation and saw 3e-3).
    #[test]
    fn a_translating_body_whose_vibration_grows_is_unstable() {
        let rest = verdict(&vibrating(0.0));
        assert!((rest.scale() - 0.13).abs() < 1e-12, "{}", rest.scale());
        assert!((rest.centred_growth() - 0.03 / 0.13).abs() < 1e-9);
        assert!(!rest.stable(false));
        let moving = verdict(&vibrating(10.0));
        assert!((moving.scale() - rest.scale()).abs() < 1e-12);
        assert!((moving.centred_growth() - rest.centred_growth()).abs() < 1e-9);
        assert!(!moving.stable(false));
        assert!(moving.growth_crossed.is_some());
        // Against the former scale, the largest K + S = 10.13: 3e-3, "stable".
        assert!(0.03 / moving.motion < STABLE_ENERGY_GROWTH);
    }

    /// A body in pure rigid translation: its `max (K + S) − min T` is round-off
    /// (here `T` a few ulps off `K`), its time-centred total gathers
    /// round-off of 1e-12 of `K` over the run. The scale's floor
    /// ([`ROUND_OFF_SCALE`]) keeps it stable; a growth of 1e-6 of `K` still counts.
    #[test]
    fn a_pure_translation_stays_stable() {
        let kinetic = 12.5;
        let history = |drift_per_step: f64| -> Vec<StepReport> {
            (0..=1000)
                .map(|step| {
                    let ulps = [-2.0, 1.0, 0.0, 3.0][step % 4] * f64::EPSILON * kinetic;
                    StepReport {
                        step,
                        time: step as f64,
                        kinetic,
                        translational: kinetic + ulps,
                        total_centred: kinetic + drift_per_step * step as f64,
                        momentum: [5.0, 0.0],
                        mass: 1.0,
                        dim: 1,
                        ..StepReport::default()
                    }
                })
                .collect()
        };
        let v = verdict(&history(1e-15 * kinetic));
        assert!(v.stable(false), "{}", v.centred_growth());
        assert!((v.scale() - ROUND_OFF_SCALE * kinetic).abs() < 1e-12 * v.scale());
        assert!(v.centred_growth() < 2e-6);
        let v = verdict(&history(1e-9 * kinetic));
        assert!(!v.stable(false), "{}", v.centred_growth());
    }

    /// A body falling under gravity onto a wall and bouncing keeps the scale of its
    /// motion: it starts at rest (no translational energy), so the scale is the
    /// former one, the largest `K + S`; the largest internal energy plus the range
    /// of the translational energy would count the energy the impact turns from
    /// translation into vibration twice (101 + 97 = 198 here). The same holds with
    /// gravity written as a body force, and for a body thrown at a wall without
    /// gravity (its translation stops at the impact).
    #[test]
    fn a_body_falling_and_bouncing_off_a_wall_keeps_the_scale_of_its_motion() {
        // (kinetic, translational, strain, potential)
        let states = [
            (0.0, 0.0, 0.0, 100.0),
            (50.0, 50.0, 0.0, 50.5),
            (99.0, 97.0, 3.0, 1.0),
            (20.0, 2.0, 83.0, 0.0),
            (60.0, 58.0, 1.0, 48.0),
        ];
        let reports = |gravity_as_work: bool| -> Vec<StepReport> {
            states
                .iter()
                .enumerate()
                .map(|(step, &(kinetic, translational, strain, potential))| {
                    let (potential, work) = if gravity_as_work {
                        (0.0, 100.0 - potential)
                    } else {
                        (potential, 0.0)
                    };
                    centred(StepReport {
                        step,
                        time: step as f64,
                        kinetic,
                        translational,
                        strain,
                        potential,
                        work,
                        ..StepReport::default()
                    })
                })
                .collect()
        };
        let v = verdict(&reports(false));
        // max (K + S) = 103, min T = 0; P swept 100.
        assert_eq!(v.scale(), 103.0);
        assert_eq!(verdict(&reports(true)).scale(), 103.0);
        // Thrown at a wall at 10 m/s (mass 1), no gravity: the translation's 50 J
        // become strain and come back.
        let thrown: Vec<StepReport> = [
            (50.0, 50.0, 0.0),
            (30.0, 10.0, 20.0),
            (2.0, 0.0, 48.0),
            (30.0, 28.0, 20.0),
            (49.0, 48.0, 1.0),
        ]
        .iter()
        .enumerate()
        .map(|(step, &(kinetic, translational, strain))| {
            centred(StepReport {
                step,
                time: step as f64,
                kinetic,
                translational,
                strain,
                ..StepReport::default()
            })
        })
        .collect();
        let v = verdict(&thrown);
        assert_eq!(v.scale(), 50.0);
        assert_eq!(v.motion, 50.0);
    }

    /// Nothing moving and nothing changing is no growth, not 0/0.
    #[test]
    fn a_run_at_rest_has_no_drift() {
        let rest = StepReport::default();
        let mut v = Verdict::new(&rest);
        v.observe(&rest);
        assert_eq!(v.energy_drift_and_growth(), (0.0, 0.0));
        assert!(v.stable(false));
    }
}
