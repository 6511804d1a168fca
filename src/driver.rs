//! The MPM time step (paper eqs. (13)–(31), thesis Fig. 2.5), generic over the
//! basis, the mass strategy and the material. Nothing here knows which basis it has.
//!
//! One step, in order:
//! 1. locate every particle (walking from its previous element) and evaluate the basis;
//! 2. assemble `M` (eq. (13)), `F^int` (eq. (15)) and the effects' forces (eqs. (14), (16));
//! 3. solve `M a = F` (eq. (17)) with the Dirichlet conditions;
//! 4. update particle velocities `v_p += Δt Σ a_i phi_i(x_p)` (eq. (18));
//! 5. project velocities `M v̂ = P` (eqs. (20)–(21));
//! 6. update `F_p ← (I + Δt ∇v_p) F_p` with the full velocity gradient, `σ_p`,
//!    `V_p = J_p V_p⁰` (eqs. (22)–(29));
//! 7. move particles `x_p += Δt Σ v̂_i phi_i(x_p)` and `u_p` likewise (eqs. (30)–(31)).
//!
//! The paper (eq. (24)) updates `F` with the symmetric part of the velocity gradient,
//! which ignores rotation: a rigidly rotating body would accumulate spurious strain.
//! We use the full gradient `∇v`, which is exact for rigid rotation to first order
//! (see the test `rigid_rotation_creates_no_stress`).
//!
//! All buffers are allocated once in [`Driver::new`]; a step allocates nothing.

use crate::effect::{Effect, ParticleBasis, StepState};
use crate::mass::{MassKind, MassReport, MassStrategy, StepContext};
use crate::material::{det, Material};
use crate::particles::Particles;
use crate::sparse::{NotPositiveDefinite, Scalar, SymmetricPattern};
use nalgebra::{SMatrix, SVector};
use psmpm_basis::{Basis, BasisError, BasisEval};

/// Why a step failed. Each names the step and says what to try.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    #[error("step {step}: particle {particle} at {position:?} left the mesh; try a smaller time step or a larger mesh")]
    ParticleLeftMesh {
        step: usize,
        particle: usize,
        position: Vec<f64>,
    },
    #[error("step {step}: the mass matrix is not positive definite ({source}); try a lumped or partially lumped mass strategy")]
    MassNotPositiveDefinite {
        step: usize,
        source: NotPositiveDefinite,
    },
    #[error("step {step}: {quantity} of particle {particle} is not finite; the run is unstable: try a smaller time step or another mass strategy")]
    NotFinite {
        step: usize,
        quantity: &'static str,
        particle: usize,
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

/// A homogeneous Dirichlet condition: velocity component `component` vanishes on `tag`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fix {
    /// Boundary tag.
    pub tag: String,
    /// Velocity component (0 = x, 1 = y).
    pub component: usize,
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

/// Energies, momentum and what the mass strategy did, after a step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepReport {
    /// Step number (1-based after the first step).
    pub step: usize,
    /// Time after the step.
    pub time: f64,
    /// Kinetic energy `Σ ½ m_p |v_p|²`.
    pub kinetic: f64,
    /// Strain energy `Σ V_p⁰ W(F_p)`.
    pub strain: f64,
    /// Potential energy of the effects (gravity).
    pub potential: f64,
    /// Work done on the body by the non-conservative effects (body forces,
    /// traction, damping) since the start, `Σ_n Δt F^n · v̂^n`.
    pub work: f64,
    /// Total mass.
    pub mass: f64,
    /// Total momentum (x, and y in 2D).
    pub momentum: [f64; 2],
    /// Largest particle speed.
    pub max_speed: f64,
    /// What the mass strategy did.
    pub mass_report: MassReport,
    /// Condition-number estimate of the solved mass system, when requested.
    pub condition: Option<f64>,
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

impl StepReport {
    /// Kinetic + strain + potential energy minus the work of the non-conservative
    /// effects: constant up to the time-integration error.
    pub fn total_energy(&self) -> f64 {
        self.kinetic + self.strain + self.potential - self.work
    }
}

/// The MPM driver.
pub struct Driver<T, const D: usize, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: Material<T, D>,
{
    /// The basis.
    pub basis: B,
    /// The particles.
    pub particles: Particles<T, D>,
    material: Mat,
    mass: M,
    effects: Vec<Box<dyn Effect<T, D>>>,
    pattern: SymmetricPattern,
    dt: T,
    step: usize,
    time: f64,
    // Buffers, sized once.
    stride: usize,
    len: Vec<usize>,
    index: Vec<usize>,
    phi: Vec<T>,
    grad: Vec<SVector<T, D>>,
    eval: BasisEval<T, D>,
    values: Vec<T>,
    rhs: Vec<Vec<T>>,
    velocity: Vec<Vec<T>>,
    /// Forces of the non-conservative effects (for their work); empty without any.
    work_force: Vec<Vec<T>>,
    /// Scratch for [`Effect::adjust_forces`]; empty without effects.
    adjust: Vec<Vec<T>>,
    work: f64,
    constraints: Constraints<T, D>,
    occupied: Vec<bool>,
    touches_empty: Vec<bool>,
    last_report: MassReport,
    last_condition: Option<f64>,
    phases: PhaseTimes,
    /// Estimate the condition number every step.
    pub estimate_condition: bool,
}

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: Material<T, D>,
{
    /// Sets up a run: symbolic work of the mass strategy, Dirichlet sets, particle
    /// location, initial stress from the initial deformation gradients.
    pub fn new(
        basis: B,
        mut particles: Particles<T, D>,
        material: Mat,
        mass_kind: MassKind,
        fixes: &[Fix],
        effects: Vec<Box<dyn Effect<T, D>>>,
        dt: f64,
    ) -> Result<Self, SetupError> {
        let n = basis.num_functions();
        let mut fixed = vec![vec![false; n]; D];
        let mut general: Vec<Vec<(usize, usize, T)>> = Vec::new();
        for fix in fixes {
            if fix.component >= D {
                return Err(SetupError::Boundary {
                    tag: fix.tag.clone(),
                    message: format!("component {} does not exist in {D}D", fix.component),
                });
            }
            let mut direction = SVector::<T, D>::zeros();
            direction[fix.component] = T::one();
            let constraints = basis.dirichlet(&fix.tag, &direction)?;
            for c in constraints {
                if c.is_single() {
                    fixed[fix.component][c.terms[0].0] = true;
                } else {
                    general.push(
                        c.terms
                            .iter()
                            .map(|&(i, w)| (fix.component, i, w))
                            .collect(),
                    );
                }
            }
        }
        for p in 0..particles.len() {
            match basis.locate(&particles.x[p], None) {
                Some(e) => particles.element[p] = e,
                None => {
                    return Err(SetupError::ParticleOutside {
                        particle: p,
                        position: particles.x[p].iter().map(|v| v.to_f64()).collect(),
                    })
                }
            }
            particles.sigma[p] = particles.sigma0[p] + material.stress(&particles.f[p]);
        }
        let scratch = |needed: bool| {
            if needed {
                vec![vec![T::zero(); n]; D]
            } else {
                Vec::new()
            }
        };
        let work_force = scratch(effects.iter().any(|e| e.does_work()));
        let adjust = scratch(!effects.is_empty());
        let pattern = SymmetricPattern::new(&basis);
        let mass = M::prepare(&pattern, &fixed, mass_kind);
        let stride = basis.max_functions_per_element();
        let np = particles.len();
        Ok(Driver {
            eval: BasisEval::for_basis(&basis),
            values: vec![T::zero(); pattern.nnz()],
            rhs: vec![vec![T::zero(); n]; D],
            velocity: vec![vec![T::zero(); n]; D],
            work_force,
            adjust,
            work: 0.0,
            constraints: Constraints::new(general, n),
            len: vec![0; np],
            occupied: vec![false; basis.num_elements()],
            touches_empty: vec![false; n],
            last_condition: None,
            phases: PhaseTimes::default(),
            estimate_condition: false,
            index: vec![0; np * stride],
            phi: vec![T::zero(); np * stride],
            grad: vec![SVector::zeros(); np * stride],
            stride,
            basis,
            particles,
            material,
            mass,
            effects,
            pattern,
            dt: T::of(dt),
            step: 0,
            time: 0.0,
            last_report: MassReport::default(),
        })
    }

    /// Adds a slip wall: the velocity component along the unit vector `normal`
    /// vanishes on the boundary tagged `tag` (for an oblique straight wall, its
    /// normal). The constraints couple the components of each coefficient and are
    /// imposed exactly by projection in the mass-matrix norm (see [`Constraints`]).
    pub fn add_slip_wall(&mut self, tag: &str, normal: &SVector<T, D>) -> Result<(), SetupError> {
        let constraints = self.basis.dirichlet(tag, normal)?;
        let mut general = std::mem::take(&mut self.constraints.rows);
        for c in constraints {
            let mut row = Vec::new();
            for &(i, w) in &c.terms {
                for k in 0..D {
                    if normal[k] != T::zero() {
                        row.push((k, i, w * normal[k]));
                    }
                }
            }
            general.push(row);
        }
        self.constraints = Constraints::new(general, self.basis.num_functions());
        Ok(())
    }

    /// Current time.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn steps(&self) -> usize {
        self.step
    }
    /// The material.
    pub fn material(&self) -> &Mat {
        &self.material
    }
    /// The mass strategy.
    pub fn mass_strategy(&self) -> &M {
        &self.mass
    }
    /// Projected velocity coefficients `v̂` of the last step, per component.
    pub fn velocity_coefficients(&self) -> &[Vec<T>] {
        &self.velocity
    }

    /// Phase 1: locate and evaluate every particle.
    fn evaluate(&mut self) -> Result<(), StepError> {
        let p_all = &mut self.particles;
        for p in 0..p_all.len() {
            let x = p_all.x[p];
            let e = self
                .basis
                .locate(&x, Some(p_all.element[p]))
                .ok_or_else(|| StepError::ParticleLeftMesh {
                    step: self.step + 1,
                    particle: p,
                    position: x.iter().map(|v| v.to_f64()).collect(),
                })?;
            p_all.element[p] = e;
            self.basis.eval(e, &x, &mut self.eval);
            let base = p * self.stride;
            let m = self.eval.len();
            self.len[p] = m;
            self.index[base..base + m].copy_from_slice(&self.eval.index[..m]);
            self.phi[base..base + m].copy_from_slice(&self.eval.phi[..m]);
            self.grad[base..base + m].copy_from_slice(&self.eval.grad_phi[..m]);
        }
        Ok(())
    }

    /// Phase 2: `M` (eq. (13)) and `F = −F^int + effects` (eqs. (14)–(16)) into `rhs`.
    fn assemble(&mut self) {
        self.values.iter_mut().for_each(|v| *v = T::zero());
        for r in &mut self.rhs {
            r.iter_mut().for_each(|v| *v = T::zero());
        }
        let parts = &self.particles;
        for p in 0..parts.len() {
            let base = p * self.stride;
            let m = self.len[p];
            let scatter = self.pattern.element_scatter(parts.element[p]);
            let (mass, vol, sigma) = (parts.mass[p], parts.volume[p], &parts.sigma[p]);
            for a in 0..m {
                let w = mass * self.phi[base + a];
                for b in a..m {
                    self.values[scatter[a * m + b]] += w * self.phi[base + b];
                }
                // F^int_{k,i} = Σ_p V_p σ_{kl} ∂phi_i/∂x_l (eq. (15)).
                let f_int = sigma * self.grad[base + a] * vol;
                let i = self.index[base + a];
                for k in 0..D {
                    self.rhs[k][i] -= f_int[k];
                }
            }
        }
        if self.effects.is_empty() {
            return;
        }
        let state = StepState {
            time: self.time,
            dt: self.dt.to_f64(),
            basis: ParticleBasis {
                stride: self.stride,
                len: &self.len,
                index: &self.index,
                phi: &self.phi,
            },
        };
        let tracks_work = !self.work_force.is_empty();
        if tracks_work {
            zero(&mut self.work_force);
        }
        for effect in &self.effects {
            if effect.does_work() {
                effect.add_forces(&self.particles, &state, &mut self.work_force);
            } else {
                effect.add_forces(&self.particles, &state, &mut self.rhs);
            }
        }
        if tracks_work {
            add_into(&mut self.rhs, &self.work_force);
        }
        // Corrections from the total force (damping, eq. (49)), all from the same total.
        zero(&mut self.adjust);
        for effect in &self.effects {
            if effect.does_work() {
                effect.adjust_forces(&self.rhs, &self.velocity, &mut self.work_force);
            }
            effect.adjust_forces(&self.rhs, &self.velocity, &mut self.adjust);
        }
        add_into(&mut self.rhs, &self.adjust);
    }

    /// Marks the functions whose support contains an element without particles.
    fn mark_empty_elements(&mut self) {
        self.occupied.iter_mut().for_each(|o| *o = false);
        for &e in &self.particles.element {
            self.occupied[e] = true;
        }
        self.touches_empty.iter_mut().for_each(|t| *t = false);
        for (e, &occupied) in self.occupied.iter().enumerate() {
            if !occupied {
                for &i in self.basis.element_functions(e) {
                    self.touches_empty[i] = true;
                }
            }
        }
    }

    /// Projects the particle velocities onto the basis, `M v̂ = Σ_p m_p phi_i v_p`
    /// (eqs. (20)–(21)), with the factorised mass of the step.
    fn project_velocities(&mut self) {
        zero(&mut self.velocity);
        let parts = &self.particles;
        for p in 0..parts.len() {
            let base = p * self.stride;
            for s in base..base + self.len[p] {
                let w = parts.mass[p] * self.phi[s];
                for k in 0..D {
                    self.velocity[k][self.index[s]] += w * parts.v[p][k];
                }
            }
        }
        for k in 0..D {
            self.mass.solve(k, &mut self.velocity[k]);
        }
        self.constraints.project(&mut self.velocity);
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        let dt = self.dt;
        let clock = std::time::Instant::now();
        self.evaluate()?;
        let t_evaluate = clock.elapsed().as_secs_f64();
        self.assemble();
        let t_assemble = clock.elapsed().as_secs_f64();
        // eq. (17): M a = F.
        self.mark_empty_elements();
        let context = StepContext {
            touches_empty: &self.touches_empty,
        };
        let report = self
            .mass
            .factorize(&self.pattern, &self.values, context)
            .map_err(|source| StepError::MassNotPositiveDefinite {
                step: self.step + 1,
                source,
            })?;
        self.last_report = report;
        self.last_condition = self
            .estimate_condition
            .then(|| self.mass.condition_estimate(&self.pattern));
        // Power of the non-conservative forces with the velocity at the start of the
        // step, v̂ⁿ (at the first step projected from the initial particle velocities).
        self.constraints.prepare(&mut self.mass);
        let power_start = if self.work_force.is_empty() {
            0.0
        } else {
            if self.step == 0 {
                self.project_velocities();
            }
            power(&self.work_force, &self.velocity)
        };
        for k in 0..D {
            self.mass.solve(k, &mut self.rhs[k]);
        }
        self.constraints.project(&mut self.rhs);
        let mut t_solve = clock.elapsed().as_secs_f64() - t_assemble;
        // eq. (18): particle velocities; eq. (21): momentum P into `velocity`.
        for v in &mut self.velocity {
            v.iter_mut().for_each(|x| *x = T::zero());
        }
        let parts = &mut self.particles;
        for p in 0..parts.len() {
            let base = p * self.stride;
            let mut a = SVector::<T, D>::zeros();
            for s in base..base + self.len[p] {
                let i = self.index[s];
                for k in 0..D {
                    a[k] += self.rhs[k][i] * self.phi[s];
                }
            }
            parts.v[p] += a * dt;
            for s in base..base + self.len[p] {
                let w = parts.mass[p] * self.phi[s];
                for k in 0..D {
                    self.velocity[k][self.index[s]] += w * parts.v[p][k];
                }
            }
        }
        // eq. (20): M v̂ = P.
        let before_projection = clock.elapsed().as_secs_f64();
        for k in 0..D {
            self.mass.solve(k, &mut self.velocity[k]);
        }
        self.constraints.project(&mut self.velocity);
        let after_projection = clock.elapsed().as_secs_f64();
        // Work of the non-conservative effects over the step with the mean of the
        // start and end velocities, the rule under which the kinetic energy of the
        // symplectic Euler update changes: `W += Δt F · (v̂ⁿ + v̂ⁿ⁺¹) / 2`.
        if !self.work_force.is_empty() {
            self.work +=
                0.5 * (power_start + power(&self.work_force, &self.velocity)) * dt.to_f64();
        }
        t_solve += after_projection - before_projection;
        // eqs. (22)–(31).
        for p in 0..parts.len() {
            let base = p * self.stride;
            let mut grad_v = SMatrix::<T, D, D>::zeros();
            let mut v_hat = SVector::<T, D>::zeros();
            for s in base..base + self.len[p] {
                let i = self.index[s];
                for k in 0..D {
                    let c = self.velocity[k][i];
                    v_hat[k] += c * self.phi[s];
                    for l in 0..D {
                        grad_v[(k, l)] += c * self.grad[s][l];
                    }
                }
            }
            let f = update_deformation_gradient(&parts.f[p], &grad_v, dt);
            let j = det(&f);
            if !(j.to_f64() > 0.0 && j.to_f64().is_finite()) {
                return Err(StepError::NotFinite {
                    step: self.step + 1,
                    quantity: "the Jacobian det F (non-positive or NaN)",
                    particle: p,
                });
            }
            parts.f[p] = f;
            parts.sigma[p] = parts.sigma0[p] + self.material.stress(&f);
            parts.volume[p] = parts.volume0[p] * j;
            parts.x[p] += v_hat * dt;
            parts.u[p] += v_hat * dt;
            if !parts.x[p].iter().all(|c| c.to_f64().is_finite())
                || !parts.v[p].iter().all(|c| c.to_f64().is_finite())
            {
                return Err(StepError::NotFinite {
                    step: self.step + 1,
                    quantity: "position or velocity",
                    particle: p,
                });
            }
        }
        self.phases = PhaseTimes {
            evaluate: t_evaluate,
            assemble: t_assemble - t_evaluate,
            solve: t_solve,
            update: clock.elapsed().as_secs_f64() - t_assemble - t_solve,
        };
        self.step += 1;
        // Time from the step count, so that it does not accumulate round-off.
        self.time = self.step as f64 * dt.to_f64();
        Ok(self.report())
    }

    /// Energies and momentum of the current state.
    pub fn report(&self) -> StepReport {
        let parts = &self.particles;
        let (mut kinetic, mut strain, mut mass, mut max_speed) = (0.0, 0.0, 0.0, 0.0f64);
        let mut momentum = [0.0; 2];
        for p in 0..parts.len() {
            let m = parts.mass[p].to_f64();
            let speed2 = parts.v[p].norm_squared().to_f64();
            kinetic += 0.5 * m * speed2;
            max_speed = max_speed.max(speed2.sqrt());
            strain +=
                parts.volume0[p].to_f64() * self.material.energy_density(&parts.f[p]).to_f64();
            if parts.sigma0[p] != SMatrix::<T, D, D>::zeros() {
                // First-order work of the initial stress: V⁰ σ⁰ : (sym F − I).
                let f = &parts.f[p];
                let e = (f + f.transpose()) * T::of(0.5) - SMatrix::<T, D, D>::identity();
                strain += parts.volume0[p].to_f64() * parts.sigma0[p].dot(&e).to_f64();
            }
            mass += m;
            for k in 0..D {
                momentum[k] += m * parts.v[p][k].to_f64();
            }
        }
        StepReport {
            step: self.step,
            time: self.time,
            kinetic,
            strain,
            potential: self
                .effects
                .iter()
                .map(|e| e.potential_energy(parts))
                .fold(0.0, |a, b| a + b),
            work: self.work,
            mass,
            momentum,
            max_speed,
            mass_report: self.last_report,
            condition: self.last_condition,
            phases: self.phases,
        }
    }
}

/// `Σ_k Σ_i F_{k,i} v̂_{k,i}`.
fn power<T: Scalar>(force: &[Vec<T>], velocity: &[Vec<T>]) -> f64 {
    let mut power = 0.0;
    for (f, v) in force.iter().zip(velocity) {
        for (a, b) in f.iter().zip(v) {
            power += (*a * *b).to_f64();
        }
    }
    power
}

/// General linear constraints `Σ_e w_e a[k_e][i_e] = 0` on the coefficients (a
/// wall whose constraint couples several functions or both components of one),
/// imposed exactly: with the step's mass operator `M` (block-diagonal over
/// components, as the strategy modified it), the constrained minimiser of
/// `½ aᵀ M a − aᵀ F` is `a = a₀ − W S⁻¹ C a₀` with `a₀ = M⁻¹ F`, `W = M⁻¹ Cᵀ` and
/// `S = C W`. `W` and `S` are formed once per step (one solve per constraint and
/// component); each projection is then a small dense solve. Buffers are sized
/// once; a constraint whose functions are all inactive (zero pivot) is skipped.
pub struct Constraints<T: Scalar, const D: usize> {
    rows: Vec<Vec<(usize, usize, T)>>,
    /// `W[c][k]`: component `k` of `M⁻¹ Cᵀ e_c`.
    w: Vec<Vec<Vec<T>>>,
    /// `S = C W`, then its Cholesky factor (row-major, lower triangle).
    s: Vec<f64>,
    /// Pivot kept (`false` for constraints on inactive functions).
    keep: Vec<bool>,
    lambda: Vec<f64>,
}

impl<T: Scalar, const D: usize> Constraints<T, D> {
    fn new(rows: Vec<Vec<(usize, usize, T)>>, n: usize) -> Self {
        let m = rows.len();
        Constraints {
            w: vec![vec![vec![T::zero(); n]; D]; m],
            s: vec![0.0; m * m],
            keep: vec![false; m],
            lambda: vec![0.0; m],
            rows,
        }
    }

    /// Number of general constraints.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// `true` without general constraints.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Forms `W` and the Cholesky factor of `S` with the strategy's factorisation.
    fn prepare<M: MassStrategy<T>>(&mut self, mass: &mut M) {
        let m = self.rows.len();
        if m == 0 {
            return;
        }
        for (c, row) in self.rows.iter().enumerate() {
            for k in 0..D {
                let w = &mut self.w[c][k];
                w.iter_mut().for_each(|v| *v = T::zero());
                let mut any = false;
                for &(kk, i, weight) in row {
                    if kk == k {
                        w[i] += weight;
                        any = true;
                    }
                }
                if any {
                    mass.solve(k, w);
                }
            }
        }
        for c in 0..m {
            for d in 0..m {
                self.s[c * m + d] = self.rows[c]
                    .iter()
                    .map(|&(k, i, weight)| (weight * self.w[d][k][i]).to_f64())
                    .sum();
            }
        }
        // In-place Cholesky, skipping the pivots that vanish relative to their own
        // diagonal (constraints on inactive functions, or dependent on earlier ones;
        // the scale differs wildly between rows: `S_cc ~ 1 / M_ii`).
        for j in 0..m {
            let diagonal = self.s[j * m + j];
            let mut d = diagonal;
            for k in 0..j {
                if self.keep[k] {
                    d -= self.s[j * m + k] * self.s[j * m + k];
                }
            }
            self.keep[j] = d > 1e-10 * diagonal && diagonal > 0.0;
            if !self.keep[j] {
                continue;
            }
            let d = d.sqrt();
            self.s[j * m + j] = d;
            for i in j + 1..m {
                let mut v = self.s[i * m + j];
                for k in 0..j {
                    if self.keep[k] {
                        v -= self.s[i * m + k] * self.s[j * m + k];
                    }
                }
                self.s[i * m + j] = v / d;
            }
        }
    }

    /// Projects the solved coefficients `a` onto the constraints.
    fn project(&mut self, a: &mut [Vec<T>]) {
        let m = self.rows.len();
        if m == 0 {
            return;
        }
        for (c, row) in self.rows.iter().enumerate() {
            self.lambda[c] = row
                .iter()
                .map(|&(k, i, weight)| (weight * a[k][i]).to_f64())
                .sum();
        }
        // S λ = C a: forward and back substitution with the kept pivots.
        for j in 0..m {
            if !self.keep[j] {
                self.lambda[j] = 0.0;
                continue;
            }
            let mut v = self.lambda[j];
            for k in 0..j {
                if self.keep[k] {
                    v -= self.s[j * m + k] * self.lambda[k];
                }
            }
            self.lambda[j] = v / self.s[j * m + j];
        }
        for j in (0..m).rev() {
            if !self.keep[j] {
                continue;
            }
            let mut v = self.lambda[j];
            for i in j + 1..m {
                if self.keep[i] {
                    v -= self.s[i * m + j] * self.lambda[i];
                }
            }
            self.lambda[j] = v / self.s[j * m + j];
        }
        for c in 0..m {
            let l = T::of(self.lambda[c]);
            if self.lambda[c] == 0.0 {
                continue;
            }
            for k in 0..D {
                for (x, w) in a[k].iter_mut().zip(&self.w[c][k]) {
                    *x -= l * *w;
                }
            }
        }
    }
}

fn zero<T: Scalar>(buffers: &mut [Vec<T>]) {
    for b in buffers {
        b.iter_mut().for_each(|v| *v = T::zero());
    }
}

fn add_into<T: Scalar>(target: &mut [Vec<T>], source: &[Vec<T>]) {
    for (t, s) in target.iter_mut().zip(source) {
        for (a, b) in t.iter_mut().zip(s) {
            *a += *b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Elastic, Material, NeoHookean};
    use nalgebra::Matrix2;

    /// A rigid rotation at angular velocity ω has `∇v = [[0, −ω], [ω, 0]]`. The full
    /// update turns `F` with the body and leaves a hyperelastic material unstressed;
    /// the symmetric-part update of paper eq. (24) leaves `F = I` behind.
    #[test]
    fn rigid_rotation_creates_no_stress() {
        let omega = 1.0;
        let (steps, dt) = (10_000, 1e-4); // one radian in total
        let grad_v = Matrix2::new(0.0, -omega, omega, 0.0);
        let sym = (grad_v + grad_v.transpose()) * 0.5;
        let (mut full, mut symmetric) = (Matrix2::<f64>::identity(), Matrix2::<f64>::identity());
        for _ in 0..steps {
            full = update_deformation_gradient(&full, &grad_v, dt);
            symmetric = update_deformation_gradient(&symmetric, &sym, dt);
        }
        let theta: f64 = omega * dt * steps as f64;
        let rotation = Matrix2::new(theta.cos(), -theta.sin(), theta.sin(), theta.cos());
        assert!((full - rotation).norm() < 1e-3, "full update: {full}");
        assert!(
            (symmetric - rotation).norm() > 0.5,
            "the symmetric update misses the rotation"
        );
        let neo = NeoHookean::new(Elastic::new(1e4, 0.3, 1.0).unwrap(), 2);
        let sigma: Matrix2<f64> = neo.stress(&full);
        // Forward Euler stretches by (1 + ω²Δt²)^(n/2): stress of order E ω² Δt t.
        assert!(sigma.norm() < 1e4 * 2e-4, "stress {sigma}");
    }
}
