//! Effects: the physics a scene asks for beyond elasticity, as composable pieces.
//!
//! Only the effects a scene lists are assembled; a scene without gravity never
//! evaluates it (the test `scenes::only_declared_effects_are_evaluated` shows it).
//!
//! An effect contributes to the right-hand side `F` of `M a = F` (paper eq. (17))
//! in one or both of two places of the step:
//! - [`Effect::add_forces`]: external forces `F^ext` from particle quantities
//!   (gravity and prescribed body forces, paper eq. (16); traction, eq. (14));
//! - [`Effect::adjust_forces`]: a correction from the assembled total force
//!   `F = F^trac − F^int + F^body` and the velocity coefficients (local damping,
//!   paper eq. (49)).
//!
//! Energy bookkeeping: a conservative effect reports its potential energy
//! ([`Effect::potential_energy`]); a non-conservative one says so with
//! [`Effect::does_work`], and the driver accumulates its work
//! `W += Δt Σ_i F_i · v̂_i` with the projected velocity coefficients of the step, so
//! that `kinetic + strain + potential − W` is the conserved total.

use crate::driver::phases::Evaluations;
use crate::particles::Particles;
use crate::sparse::Scalar;
use crate::studies::exact::AxisAligned;
use nalgebra::{SMatrix, SVector};

/// Basis values of every particle at the start of a step, as the driver evaluated
/// them: particle `p` has `len[slot[p]]` entries at `slot[p] * stride ..` (the
/// driver stores them in element order; see `driver::phases::Evaluations`).
pub struct ParticleBasis<'a, T: Scalar, const D: usize> {
    /// The step's basis values at the particles.
    pub(crate) evals: &'a Evaluations<T, D>,
}

impl<T: Scalar, const D: usize> ParticleBasis<'_, T, D> {
    /// The functions `i` non-zero at particle `p` with their values `phi_i(x_p)`.
    #[inline]
    pub fn functions(&self, p: usize) -> impl Iterator<Item = (usize, T)> + '_ {
        self.evals.entries(p).map(|(s, i)| (i, self.evals.phi[s]))
    }

    /// The functions `i` non-zero at particle `p` with `phi_i(x_p)` and
    /// `grad phi_i(x_p)`.
    #[inline]
    pub fn functions_with_gradients(
        &self,
        p: usize,
    ) -> impl Iterator<Item = (usize, T, SVector<T, D>)> + '_ {
        self.evals
            .entries(p)
            .map(|(s, i)| (i, self.evals.phi[s], self.evals.grad_phi[s]))
    }

    /// Adds `phi_i(x_p) f` to `forces[k][i]` for the functions of particle `p`.
    #[inline]
    pub fn scatter(&self, p: usize, f: &SVector<T, D>, forces: &mut [Vec<T>]) {
        for (i, phi) in self.functions(p) {
            for k in 0..D {
                forces[k][i] += f[k] * phi;
            }
        }
    }
}

/// Where the step is when an effect is asked for its forces.
pub struct StepState<'a, T: Scalar, const D: usize> {
    /// Time at the start of the step, `t_n`.
    pub time: f64,
    /// Time step `Δt`.
    pub dt: f64,
    /// Basis values at the particles.
    pub basis: ParticleBasis<'a, T, D>,
}

/// A force contribution (and its potential energy, if it has one).
pub trait Effect<T: Scalar, const D: usize>: Send + Sync {
    /// Name for output.
    fn name(&self) -> &'static str;
    /// Adds the effect's external force coefficients `F_{k,i}` to `forces[k][i]`.
    fn add_forces(
        &self,
        _particles: &Particles<T, D>,
        _state: &StepState<T, D>,
        _forces: &mut [Vec<T>],
    ) {
    }
    /// The force `f_p` this effect puts on particle `p` at time `time`, for an
    /// effect whose forces are `F_{k,i} = Σ_p phi_i(x_p) f_{p,k}`: the driver then
    /// scatters them itself, in parallel, instead of calling
    /// [`add_forces`](Self::add_forces). `None` (the default): not such an effect.
    fn particle_force(
        &self,
        _particles: &Particles<T, D>,
        _p: usize,
        _time: f64,
    ) -> Option<SVector<T, D>> {
        None
    }
    /// `true` if [`particle_force`](Self::particle_force) gives the forces.
    fn acts_per_particle(&self) -> bool {
        false
    }
    /// Adds a correction computed from the total force `total` (everything assembled
    /// so far) and the velocity coefficients `velocity` of the previous step to
    /// `forces`. Called after every effect's [`add_forces`](Self::add_forces).
    fn adjust_forces(&self, _total: &[Vec<T>], _velocity: &[Vec<T>], _forces: &mut [Vec<T>]) {}
    /// Potential energy of the particles in the effect's field (zero if none).
    fn potential_energy(&self, _particles: &Particles<T, D>) -> f64 {
        0.0
    }
    /// A bound on the acceleration the effect alone gives every particle, the same
    /// for all (gravity's `|g|`, a uniform body force's `|b|`): the watch adds the
    /// speed it gives in a step to the particles' own when it bounds how far a
    /// step moves them (`Driver::advection_substeps`). 0 (the default): none known.
    fn acceleration_bound(&self) -> f64 {
        0.0
    }
    /// How much the effect can scale the grid forces of a step: the critical time
    /// step is divided by the square root of it (1: not at all).
    fn force_amplification(&self) -> f64 {
        1.0
    }
    /// `true` for a non-conservative effect whose work the driver accumulates.
    fn does_work(&self) -> bool {
        false
    }
    /// `true` for an effect whose forces can only take energy out (frictionless
    /// contact between bodies): the driver also accumulates its work apart
    /// ([`StepReport::dissipated`](crate::diagnostics::StepReport::dissipated)), and
    /// what it adds over the run is energy the discretisation gained, which the
    /// verdict counts as growth rather than as work done.
    fn dissipative(&self) -> bool {
        false
    }
    /// The run's time step is `dt` (called when the driver is built and whenever
    /// its step changes), for effects whose forces depend on it.
    fn set_time_step(&mut self, _dt: f64) {}
    /// `true` if the effect is a wall at the particles with a part within its reach
    /// of `element` (a contact wall): a particle that left the mesh from there
    /// went through it.
    fn walls_element(&self, _element: usize) -> bool {
        false
    }
    /// `true` if the effect is a wall at the particles that a particle now at `x`,
    /// outside the mesh, went through from `element`: `x` lies behind one of its
    /// edges listed for `element`, or within reach of one of its reflex corners.
    fn went_through(&self, _element: usize, _x: [f64; 2]) -> bool {
        false
    }
    /// For a wall at the particles, the distance from it at which it starts to
    /// push `particle` (a contact wall's `d_p`, smaller for a particle placed
    /// closer); `None` for other effects.
    fn contact_distance(&self, _particle: usize) -> Option<f64> {
        None
    }
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
        state: &StepState<T, D>,
        forces: &mut [Vec<T>],
    ) {
        for p in 0..particles.len() {
            state
                .basis
                .scatter(p, &(self.g * particles.mass[p]), forces);
        }
    }
    fn particle_force(
        &self,
        particles: &Particles<T, D>,
        p: usize,
        _time: f64,
    ) -> Option<SVector<T, D>> {
        Some(self.g * particles.mass[p])
    }
    fn acts_per_particle(&self) -> bool {
        true
    }
    fn acceleration_bound(&self) -> f64 {
        self.g.norm().to_f64()
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

/// A prescribed body force per unit mass `b(x⁰, t)`, evaluated at each particle's
/// reference position and the start-of-step time: `F_{k,i} = Σ_p m_p phi_i(x_p) b_k`
/// (paper eq. (16)). The fields a scene can declare, chosen by a `match` once per
/// step (no call through a pointer per particle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BodyForce<T: Scalar, const D: usize> {
    /// The same force everywhere, at all times.
    Uniform(SVector<T, D>),
    /// The body force that makes the B4 manufactured solution exact (paper eqs.
    /// (42)–(46)): [`AxisAligned::body_force`].
    Manufactured(AxisAligned),
}

impl<T: Scalar, const D: usize> BodyForce<T, D> {
    /// `b(x⁰, t)`.
    #[inline]
    pub fn at(&self, x0: &SVector<T, D>, t: f64) -> SVector<T, D> {
        match self {
            BodyForce::Uniform(b) => *b,
            BodyForce::Manufactured(a) => manufactured(a, x0, t),
        }
    }
}

/// [`AxisAligned::body_force`] at `x0` (the second coordinate 0 in 1D).
#[inline]
fn manufactured<T: Scalar, const D: usize>(
    a: &AxisAligned,
    x0: &SVector<T, D>,
    t: f64,
) -> SVector<T, D> {
    let mut p = [0.0; 2];
    for k in 0..D {
        p[k] = x0[k].to_f64();
    }
    let b = a.body_force(p, t);
    SVector::<T, D>::from_fn(|k, _| T::of(b[k]))
}

impl<T: Scalar, const D: usize> Effect<T, D> for BodyForce<T, D> {
    fn name(&self) -> &'static str {
        match self {
            BodyForce::Uniform(_) => "body-force",
            BodyForce::Manufactured(_) => "manufactured-body-force",
        }
    }
    fn add_forces(
        &self,
        particles: &Particles<T, D>,
        state: &StepState<T, D>,
        forces: &mut [Vec<T>],
    ) {
        match self {
            BodyForce::Uniform(b) => {
                for p in 0..particles.len() {
                    state.basis.scatter(p, &(*b * particles.mass[p]), forces);
                }
            }
            BodyForce::Manufactured(a) => {
                for p in 0..particles.len() {
                    let b = manufactured(a, &particles.x0[p], state.time);
                    state.basis.scatter(p, &(b * particles.mass[p]), forces);
                }
            }
        }
    }
    fn particle_force(
        &self,
        particles: &Particles<T, D>,
        p: usize,
        time: f64,
    ) -> Option<SVector<T, D>> {
        Some(match self {
            BodyForce::Uniform(b) => *b * particles.mass[p],
            BodyForce::Manufactured(a) => {
                manufactured(a, &particles.x0[p], time) * particles.mass[p]
            }
        })
    }
    fn acts_per_particle(&self) -> bool {
        true
    }
    fn acceleration_bound(&self) -> f64 {
        match self {
            BodyForce::Uniform(b) => b.norm().to_f64(),
            // A field that varies in space and time, with no uniform bound known
            // here: the particles' own speeds, which follow it, bound the move.
            BodyForce::Manufactured(_) => 0.0,
        }
    }
    fn does_work(&self) -> bool {
        true
    }
}

/// A traction on boundary particles (paper eq. (14) with the boundary integral
/// carried by particles): each selected particle carries the force
/// `t · length / n` (the traction `t` per unit length over the loaded boundary
/// length, shared equally by the `n` selected particles), scaled by a linear ramp
/// from 0 at `t = 0` to 1 at `t = ramp` (sudden load for `ramp = 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Traction<T: Scalar, const D: usize> {
    /// Selected particles.
    pub particles: Vec<usize>,
    /// Force per particle at full load.
    pub force: SVector<T, D>,
    /// Ramp time.
    pub ramp: f64,
}

impl<T: Scalar, const D: usize> Effect<T, D> for Traction<T, D> {
    fn name(&self) -> &'static str {
        "traction"
    }
    fn add_forces(
        &self,
        _particles: &Particles<T, D>,
        state: &StepState<T, D>,
        forces: &mut [Vec<T>],
    ) {
        let scale = if self.ramp > 0.0 {
            (state.time / self.ramp).min(1.0)
        } else {
            1.0
        };
        let f = self.force * T::of(scale);
        for &p in &self.particles {
            state.basis.scatter(p, &f, forces);
        }
    }
    fn does_work(&self) -> bool {
        true
    }
}

/// Local non-viscous damping, paper eq. (49), per coefficient:
/// `F^damp_{k,i} = −α |F_{k,i}| sign(v̂_{k,i})` with `F = F^trac − F^int + F^body`.
///
/// The paper prints `−α sign(v̂) F`. Read literally, that multiplies `F` by `1 − α`
/// whether it points along the motion or against it: it rescales `F` (a change of
/// mass) and dissipates nothing. The dissipative form, which we implement, always
/// opposes the velocity: `−α |F| sign(v̂)` (Cundall's local damping). `v̂` is the
/// projected velocity of the previous step (zero at the first step: no damping).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalDamping {
    /// Damping factor `α ∈ [0, 1)`.
    pub alpha: f64,
}

impl<T: Scalar, const D: usize> Effect<T, D> for LocalDamping {
    fn name(&self) -> &'static str {
        "damping"
    }
    fn adjust_forces(&self, total: &[Vec<T>], velocity: &[Vec<T>], forces: &mut [Vec<T>]) {
        let alpha = T::of(self.alpha);
        for k in 0..D {
            for ((f, &t), &v) in forces[k].iter_mut().zip(&total[k]).zip(&velocity[k]) {
                if v > T::zero() {
                    *f -= alpha * t.abs();
                } else if v < T::zero() {
                    *f += alpha * t.abs();
                }
            }
        }
    }
    fn does_work(&self) -> bool {
        true
    }
    /// Where the velocity opposes the force, the damped force is `(1 + α)` times
    /// the undamped one: to the explicit update the system is up to `1 + α` times
    /// stiffer, and its critical step `√(1 + α)` times shorter (measured on a
    /// damped 1D column: stable up to a Courant number of the undamped step of
    /// 0.80, 0.75, 0.70 for α = 0.3, 0.6, 0.9, against `1/√(1 + α)` = 0.88, 0.79,
    /// 0.73).
    fn force_amplification(&self) -> f64 {
        1.0 + self.alpha
    }
}

/// An initial stress state `σ⁰(x⁰)`, added to the material stress of each particle:
/// `σ_p = σ⁰_p + σ(F_p)` (e.g. a geostatic state). Set up once by the driver; the
/// strain energy includes its first-order work `V⁰ σ⁰ : (sym F − I)`.
pub trait InitialStress<T: Scalar, const D: usize> {
    /// `σ⁰` at reference position `x0`.
    fn sigma0(&self, x0: &SVector<T, D>) -> SMatrix<T, D, D>;
}

/// Geostatic initial stress: `σ⁰_vv = ρ g (surface − x_v)` along the last axis
/// (`g` negative downwards, so compression is negative) and `σ⁰_hh = k0 σ⁰_vv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geostatic {
    /// Height of the free surface.
    pub surface: f64,
    /// Density.
    pub density: f64,
    /// Gravity along the last axis (negative downwards).
    pub gravity: f64,
    /// Lateral earth-pressure coefficient.
    pub k0: f64,
}

impl<T: Scalar, const D: usize> InitialStress<T, D> for Geostatic {
    fn sigma0(&self, x0: &SVector<T, D>) -> SMatrix<T, D, D> {
        let depth = self.surface - x0[D - 1].to_f64();
        let vertical = -self.density * self.gravity.abs() * depth.max(0.0);
        let mut s = SMatrix::<T, D, D>::zeros();
        for k in 0..D - 1 {
            s[(k, k)] = T::of(self.k0 * vertical);
        }
        s[(D - 1, D - 1)] = T::of(vertical);
        s
    }
}

/// A uniform initial stress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformStress<const D: usize>(pub SMatrix<f64, D, D>);

impl<T: Scalar, const D: usize> InitialStress<T, D> for UniformStress<D> {
    fn sigma0(&self, _x0: &SVector<T, D>) -> SMatrix<T, D, D> {
        SMatrix::<T, D, D>::from_fn(|i, j| T::of(self.0[(i, j)]))
    }
}
